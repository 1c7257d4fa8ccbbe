//! A tablecloth dropped onto a table: `cargo run --example recipe_tablecloth`.
//! The whole file is the recipe in `docs/recipes.md` (a test keeps the two equal).

use bevy::prelude::*;
use bevy_cloth::prelude::*;

fn main() {
    App::new().add_plugins((DefaultPlugins, recipe)).run();
}

/// The recipe as a plugin: the cloth plugin and the scene.
pub fn recipe(app: &mut App) {
    app.add_plugins(ClothPlugin::default())
        .add_systems(Startup, setup);
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    // The table top: 1.2 × 0.8 m, 4 cm thick, its top at 0.75 m; a collider the size of
    // the mesh, which the cloth keeps 1.5 cm off (so the straight edges between its
    // particles, 4 cm apart, do not cut the table's corners), with friction's grip.
    let top = Vec3::new(1.2, 0.04, 0.8);
    commands.spawn((
        ClothCollider::cuboid(top.x, top.y, top.z)
            .with_thickness(0.015)
            .with_friction(0.6),
        Mesh3d(meshes.add(Cuboid::from_size(top))),
        MeshMaterial3d(materials.add(Color::srgb(0.45, 0.3, 0.2))),
        Transform::from_xyz(0.0, 0.73, 0.0),
    ));
    // A 1.6 × 1.4 m cotton tablecloth. The grid lies in its XY plane, hanging down −y from
    // the middle of its top row: turned a quarter round x it lies level, its rows running
    // along +z from the entity's origin, so the origin goes at the middle of the far edge,
    // 5 cm above the table. Nothing holds it: no pins. XPBD holds its length at the
    // drop's speed; self-collision keeps the folds at the corners apart.
    let (width, height, spacing) = (41, 36, 0.04);
    let depth = (height - 1) as f32 * spacing;
    commands.spawn((
        Cloth::grid(width, height, spacing)
            .with_pins(ClothPins::None)
            .with_params(ClothParams {
                model: Model::Xpbd(XpbdParams::default()),
                fabric: Some(Fabric::TABLECLOTH),
                self_collision: SelfCollision::on(),
                ..default()
            }),
        Transform::from_xyz(0.0, 0.8, -depth * 0.5)
            .with_rotation(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2)),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.9, 0.88, 0.8),
            double_sided: true,
            cull_mode: None,
            ..default()
        })),
    ));
    // The floor, a collider too.
    commands.spawn((
        ClothCollider::plane(),
        Mesh3d(meshes.add(Plane3d::default().mesh().size(6.0, 6.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.55, 0.6, 0.5))),
    ));
    commands.spawn((
        DirectionalLight::default(),
        Transform::from_xyz(2.0, 5.0, 3.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((
        Camera3d::default(),
        Transform::from_xyz(0.0, 1.9, 2.6).looking_at(Vec3::new(0.0, 0.6, 0.0), Vec3::Y),
    ));
}
