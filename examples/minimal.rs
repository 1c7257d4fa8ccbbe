//! The least a game needs: the plugin, a camera, a light and one cloth hanging from its
//! top corners. Public API only.
//!
//! `cargo run --example minimal`
use bevy::prelude::*;
use bevy_cloth::prelude::*;

fn main() {
    App::new()
        .add_plugins((DefaultPlugins, ClothPlugin::default()))
        .add_systems(Startup, setup)
        .run();
}

fn setup(mut commands: Commands, mut materials: ResMut<Assets<StandardMaterial>>) {
    commands.spawn((
        Camera3d::default(),
        Transform::from_xyz(0.0, 1.2, 3.5).looking_at(Vec3::new(0.0, 1.2, 0.0), Vec3::Y),
    ));
    commands.spawn((
        DirectionalLight::default(),
        Transform::from_xyz(1.0, 3.0, 2.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((
        // 32×32 particles 5 cm apart; the transform places the middle of the top edge.
        Cloth::grid(32, 32, 0.05).with_pins(ClothPins::TopCorners),
        MeshMaterial3d(materials.add(StandardMaterial {
            double_sided: true,
            cull_mode: None,
            ..default()
        })),
        Transform::from_xyz(0.0, 2.0, 0.0),
    ));
}
