//! The README's quick start: a cloth hung by its two top corners from a bar, swinging
//! down past a ball. Public API only.
//!
//! `cargo run --example quickstart`
use bevy::prelude::*;
use bevy_cloth::prelude::*;

fn main() {
    App::new()
        .add_plugins((DefaultPlugins, ClothPlugin::default()))
        .add_systems(Startup, setup)
        .run();
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let look = Vec3::new(0.0, 1.2, 0.0);
    commands.spawn((
        Camera3d::default(),
        Transform::from_xyz(3.0, 2.0, 3.0).looking_at(look, Vec3::Y),
    ));
    commands.spawn((
        DirectionalLight::default(),
        Transform::from_xyz(2.0, 4.0, 1.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    // A ball in the cloth's way: a collider is a component beside a transform.
    commands.spawn((
        ClothCollider::sphere(0.3),
        Mesh3d(meshes.add(Sphere::new(0.29))),
        MeshMaterial3d(materials.add(Color::srgb(0.8, 0.3, 0.2))),
        Transform::from_xyz(0.0, 1.1, 0.0),
    ));
    // The bar the cloth hangs from: move its transform and the cloth follows.
    let bar = commands.spawn(Transform::from_xyz(0.0, 2.0, -0.8)).id();
    commands.spawn((
        // 32×32 particles 5 cm apart, laid out level from the bar.
        Cloth::grid(32, 32, 0.05),
        ClothAttachments(vec![
            ClothAttachment::nearest(bar, Vec3::new(-0.8, 0.0, 0.0), 1),
            ClothAttachment::nearest(bar, Vec3::new(0.8, 0.0, 0.0), 1),
        ]),
        MeshMaterial3d(materials.add(StandardMaterial {
            double_sided: true,
            cull_mode: None,
            ..default()
        })),
        Transform::from_xyz(0.0, 2.0, -0.8)
            .with_rotation(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2)),
    ));
}
