//! A skirt on a skinned character: `cargo run --example recipe_skirt`.
//! The whole file is the recipe in `docs/recipes.md` (a test keeps the two equal).

use bevy::asset::RenderAssetUsages;
use bevy::mesh::skinning::{SkinnedMesh, SkinnedMeshInverseBindposes};
use bevy::mesh::{Indices, PrimitiveTopology, VertexAttributeValues};
use bevy::prelude::*;
use bevy_cloth::ATTRIBUTE_MAX_DISTANCE;
use bevy_cloth::prelude::*;

fn main() {
    App::new().add_plugins((DefaultPlugins, recipe)).run();
}

/// The recipe as a plugin: the cloth plugin, the character and its dance.
pub fn recipe(app: &mut App) {
    app.add_plugins(ClothPlugin::default())
        // The hips move in `FixedUpdate` and are drawn where the last step left them: so
        // is the skirt, or its waist would trail the hips by a step.
        .insert_resource(ClothInterpolation(false))
        .add_systems(Startup, setup)
        .add_systems(FixedUpdate, dance);
}

/// The hips: the skirt's one joint, and a capsule the skirt is kept out of.
#[derive(Component)]
struct Hips;

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut bindposes: ResMut<Assets<SkinnedMeshInverseBindposes>>,
) {
    let hips = commands
        .spawn((
            Hips,
            ClothCollider::capsule(0.17, 0.7),
            Mesh3d(meshes.add(Capsule3d::new(0.17, 0.7))),
            MeshMaterial3d(materials.add(Color::srgb(0.8, 0.65, 0.55))),
            Transform::from_xyz(0.0, 0.9, 0.0),
        ))
        .id();
    // A skirt in the bind pose, skinned wholly to the hips, as a glTF gives it. The
    // plugin skins it every step and keeps each vertex within its painted maximum
    // distance of where the skin puts it: 0 at the waist (held), 12 cm at the hem (free
    // to swing). A glTF's skirt takes the same `Cloth::from_mesh()` on its mesh entity.
    commands.spawn((
        Mesh3d(meshes.add(skirt_mesh())),
        SkinnedMesh {
            inverse_bindposes: bindposes.add(SkinnedMeshInverseBindposes::from(vec![
                Mat4::from_translation(Vec3::new(0.0, -0.9, 0.0)),
            ])),
            joints: vec![hips],
        },
        Cloth::from_mesh().with_params(ClothParams {
            model: Model::Xpbd(XpbdParams::default()),
            fabric: Some(Fabric::INTERLOCK),
            ..default()
        }),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.15, 0.35, 0.75),
            double_sided: true,
            cull_mode: None,
            ..default()
        })),
    ));
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(6.0, 6.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.55, 0.6, 0.5))),
    ));
    commands.spawn((
        DirectionalLight::default(),
        Transform::from_xyz(2.0, 5.0, 3.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((
        Camera3d::default(),
        Transform::from_xyz(0.0, 1.3, 2.8).looking_at(Vec3::new(0.0, 0.7, 0.0), Vec3::Y),
    ));
}

/// An A-line skirt from the waist (0.95 m) to above the knee (0.5 m), 32 vertices round,
/// skinned to joint 0, with its maximum distance painted as the square of the way down.
fn skirt_mesh() -> Mesh {
    let (around, rows) = (32, 12);
    let (mut positions, mut normals, mut distance) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..rows {
        let down = j as f32 / (rows - 1) as f32;
        let (y, radius) = (0.95 - 0.45 * down, 0.19 + 0.13 * down);
        for i in 0..around {
            let a = i as f32 / around as f32 * std::f32::consts::TAU;
            let out = Vec3::new(a.cos(), 0.0, a.sin());
            positions.push(out * radius + Vec3::Y * y);
            normals.push(out);
            distance.push(0.12 * down * down);
        }
    }
    let mut indices = Vec::new();
    for j in 0..rows - 1 {
        for i in 0..around {
            let (a, b) = (j * around + i, j * around + (i + 1) % around);
            indices.extend([a, a + around, b, b, a + around, b + around]);
        }
    }
    let n = positions.len();
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, normals)
    .with_inserted_attribute(
        Mesh::ATTRIBUTE_JOINT_INDEX,
        VertexAttributeValues::Uint16x4(vec![[0; 4]; n]),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_JOINT_WEIGHT, vec![[1.0, 0.0, 0.0, 0.0]; n])
    .with_inserted_attribute(ATTRIBUTE_MAX_DISTANCE, distance)
    .with_inserted_indices(Indices::U32(indices))
}

/// The hips sway from side to side and twist half a turn back and forth, once a second:
/// the skirt's hem swings out and lags behind the turn.
fn dance(time: Res<Time>, mut hips: Query<&mut Transform, With<Hips>>) {
    let t = time.elapsed_secs() * std::f32::consts::TAU;
    for mut body in &mut hips {
        body.translation.x = 0.15 * t.sin();
        body.rotation = Quat::from_rotation_y(1.5 * t.sin());
    }
}
