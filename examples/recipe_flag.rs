//! A flag on a pole in the wind: `cargo run --example recipe_flag`.
//! The whole file is the recipe in `docs/recipes.md` (a test keeps the two equal).

use bevy::prelude::*;
use bevy_cloth::params::WindField;
use bevy_cloth::prelude::*;

fn main() {
    App::new().add_plugins((DefaultPlugins, recipe)).run();
}

/// The recipe as a plugin: the cloth plugin, a gusting wind and the scene.
pub fn recipe(app: &mut App) {
    app.add_plugins(ClothPlugin::default())
        // Air at 3 m/s along the flag, with gusts: it acts on every triangle of a cloth
        // with a fabric, by the triangle's area and its angle to the flow.
        .insert_resource(ClothEnvironment(Environment {
            air: Some(Air {
                velocity: Vec3::new(3.0, 0.0, 0.5),
                field: WindField::Trigonometric,
                ..default()
            }),
            ..default()
        }))
        .add_systems(Startup, setup);
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    // The pole: 3 m tall, 3 cm thick; the flag wraps against its collider.
    let pole = commands
        .spawn((
            ClothCollider::capsule(0.03, 2.94),
            Mesh3d(meshes.add(Capsule3d::new(0.03, 2.94))),
            MeshMaterial3d(materials.add(Color::srgb(0.6, 0.6, 0.62))),
            Transform::from_xyz(0.0, 1.5, 0.0),
        ))
        .id();
    // A 1.2 × 0.8 m flag of polyester. The grid hangs in its XY plane from the middle of
    // its top row: put that 0.6 m out from 4 cm off the pole, near the top. Its first column is
    // held to the pole (each particle at the point it has in the pole's frame now); being
    // attached, it has no world pins.
    let (width, height, spacing) = (31, 21, 0.04);
    let edge: Vec<u32> = (0..height).map(|j| j * width).collect();
    commands.spawn((
        Cloth::grid(width, height, spacing).with_params(ClothParams {
            model: Model::Xpbd(XpbdParams::default()),
            fabric: Some(Fabric::POLYESTER),
            ..default()
        }),
        Transform::from_xyz(0.07 + 0.6, 2.9, 0.0),
        ClothAttachments(vec![ClothAttachment::indices(pole, edge)]),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.8, 0.15, 0.1),
            double_sided: true,
            cull_mode: None,
            ..default()
        })),
    ));
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(8.0, 8.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.55, 0.6, 0.5))),
    ));
    commands.spawn((
        DirectionalLight::default(),
        Transform::from_xyz(3.0, 6.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((
        Camera3d::default(),
        Transform::from_xyz(0.6, 1.9, 3.2).looking_at(Vec3::new(0.6, 2.4, 0.0), Vec3::Y),
    ));
}
