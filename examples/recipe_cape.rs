//! A cape on a body you move yourself, without avian: `cargo run --example recipe_cape`.
//! The whole file is the recipe in `docs/recipes.md` (a test keeps the two equal).

use bevy::prelude::*;
use bevy_cloth::prelude::*;

fn main() {
    App::new().add_plugins((DefaultPlugins, recipe)).run();
}

/// The recipe as a plugin: the cloth plugin, the scene and the run.
pub fn recipe(app: &mut App) {
    app.add_plugins(ClothPlugin::default())
        // The body moves in `FixedUpdate` and is drawn where the last step left it: so is
        // the cape, or its collar would trail the body by a step.
        .insert_resource(ClothInterpolation(false))
        .add_systems(Startup, setup)
        .add_systems(FixedUpdate, run_in_a_circle);
}

/// The runner: a capsule the cloth is kept out of.
#[derive(Component)]
struct Runner;

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let at = pose(0.0);
    let body = commands
        .spawn((
            Runner,
            ClothCollider::capsule(0.3, 0.6),
            Mesh3d(meshes.add(Capsule3d::new(0.3, 0.6))),
            MeshMaterial3d(materials.add(Color::srgb(0.35, 0.4, 0.5))),
            at,
        ))
        .id();
    let cape = spawn_cape(&mut commands, body, &at);
    // The plugin gives the cloth its mesh; its look is yours.
    let cloth = StandardMaterial {
        base_color: Color::srgb(0.6, 0.1, 0.12),
        double_sided: true,
        cull_mode: None,
        ..default()
    };
    commands
        .entity(cape)
        .insert(MeshMaterial3d(materials.add(cloth)));
    commands.spawn((
        ClothCollider::plane(),
        Mesh3d(meshes.add(Plane3d::default().mesh().size(8.0, 8.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.55, 0.6, 0.5))),
    ));
    commands.spawn((
        DirectionalLight::default(),
        Transform::from_xyz(3.0, 6.0, 2.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((
        Camera3d::default(),
        Transform::from_xyz(0.0, 6.0, 4.5).looking_at(Vec3::new(0.0, 0.5, 0.0), Vec3::Y),
    ));
}

/// A cape on `body` (now at `at`, facing −z): its top row on an arc 3 cm behind a
/// 0.3 m capsule's back at shoulder height, in the body's frame.
fn spawn_cape(commands: &mut Commands, body: Entity, at: &Transform) -> Entity {
    let collar = Vec3::new(0.0, 0.42, 0.0);
    let (width, spacing, radius) = (14, 0.045, 0.33);
    let points: Vec<(u32, Vec3)> = (0..width)
        .map(|i| {
            let a = (i as f32 - (width - 1) as f32 * 0.5) * spacing / radius;
            (
                i,
                collar + Vec3::new(radius * a.sin(), 0.0, radius * a.cos()),
            )
        })
        .collect();
    commands
        .spawn((
            // The grid hangs in its XY plane from the middle of its top row; being attached,
            // it has no world pins. Denim meets still air (drag and lift on every
            // triangle), so the running cape streams back.
            Cloth::grid(width, 17, spacing).with_params(ClothParams {
                model: Model::Xpbd(XpbdParams::default()),
                fabric: Some(Fabric::DENIM),
                self_collision: SelfCollision::on(),
                ..default()
            }),
            // The grid's origin (the middle of its top row) at the middle of the arc.
            at.mul_transform(Transform::from_translation(collar + Vec3::Z * radius)),
            ClothAttachments(vec![ClothAttachment::at(body, points)]),
        ))
        .id()
}

/// Runs the body round its circle, so the cape streams out behind it.
fn run_in_a_circle(time: Res<Time>, mut runner: Query<&mut Transform, With<Runner>>) {
    for mut body in &mut runner {
        *body = pose(time.elapsed_secs());
    }
}

/// Where the body is `t` s into its run: on a circle of 1.5 m radius at 4 m/s, facing
/// where it goes (−z forward). The cape is spawned on this pose at `t` = 0, so the first
/// step does not turn the body under it.
fn pose(t: f32) -> Transform {
    let (radius, speed) = (1.5, 4.0);
    let angle = t * speed / radius;
    let ahead = Vec3::new(-angle.sin(), 0.0, angle.cos());
    Transform::from_xyz(radius * angle.cos(), 1.0, radius * angle.sin()).looking_to(ahead, Vec3::Y)
}
