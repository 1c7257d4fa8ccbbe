//! Wind zones: a field of twelve flags on poles in a light global breeze, and a gusty,
//! turbulent sphere of wind (drawn as a faint glass ball) that sweeps back and forth across
//! the field. Flags inside it fly out and flutter; those it has left fall back to
//! hanging in the breeze. Each zone is a `ClothWindZone` entity, acting on every cloth it
//! reaches through the air model. Orbit camera, mouse tools and the inspector as in the
//! other examples.
//!
//! `cargo run --example wind_zones [-- --screenshot out.png --frames 120]`

// The shared example code; this example builds its own scene, so it uses part of it.
#[allow(dead_code)]
mod common;

use bevy::light::NotShadowCaster;
use bevy::prelude::*;
use bevy_cloth::prelude::*;

/// Each flag: particles across and down, and their spacing (m).
const WIDTH: u32 = 16;
const HEIGHT: u32 = 10;
const SPACING: f32 = 0.05;
/// The poles' radius and height (m).
const POLE_RADIUS: f32 = 0.03;
const POLE_TOP: f32 = 2.0;

/// The sweeping zone: how far it swings either side of the field's middle (m) and how
/// fast (rad/s).
#[derive(Component)]
struct Sweeps {
    reach: f32,
    speed: f32,
}

fn main() {
    let args = common::ExampleArgs::parse("");
    common::app("bevy_cloth — wind zones", args)
        .add_plugins(common::tools::ToolsPlugin)
        .add_systems(Startup, setup)
        .add_systems(FixedUpdate, sweep.before(ClothSystems::Prepare))
        .run();
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let pole_mesh = meshes.add(Cylinder::new(POLE_RADIUS, POLE_TOP));
    let pole_material = materials.add(Color::srgb(0.55, 0.5, 0.45));
    let colours = [
        Color::srgb(0.75, 0.15, 0.15),
        Color::srgb(0.15, 0.35, 0.75),
        Color::srgb(0.9, 0.7, 0.15),
        Color::srgb(0.2, 0.6, 0.3),
    ];
    // The flag's grid hangs from the middle of its top edge; its first column, by the
    // pole, is pinned.
    let half = (WIDTH - 1) as f32 * SPACING * 0.5;
    let edge: Vec<u32> = (0..HEIGHT).map(|j| j * WIDTH).collect();
    for (row, z) in [-2.0f32, 0.0, 2.0].into_iter().enumerate() {
        for (column, x) in [-3.0f32, -1.0, 1.0, 3.0].into_iter().enumerate() {
            commands.spawn((
                Transform::from_xyz(x, POLE_TOP * 0.5, z),
                Mesh3d(pole_mesh.clone()),
                MeshMaterial3d(pole_material.clone()),
                ClothCollider::capsule(POLE_RADIUS, POLE_TOP - 2.0 * POLE_RADIUS),
            ));
            commands.spawn((
                Cloth::grid(WIDTH, HEIGHT, SPACING)
                    .with_pins(ClothPins::Indices(edge.clone()))
                    .with_params(ClothParams {
                        node_mass: 3e-4,
                        ..ClothParams::seeds()
                    }),
                Transform::from_xyz(x + POLE_RADIUS + 0.015 + half, POLE_TOP - 0.02, z),
                MeshMaterial3d(materials.add(StandardMaterial {
                    base_color: colours[(row + column) % colours.len()],
                    double_sided: true,
                    cull_mode: None,
                    perceptual_roughness: 0.8,
                    ..default()
                })),
                Name::new(format!("flag {row}.{column}")),
            ));
        }
    }
    // A light breeze everywhere, gusting: the global wind as a zone.
    commands.spawn((
        ClothWindZone::global(Vec3::new(1.0, 0.0, 0.4)).with_turbulence(Turbulence {
            gust: 0.5,
            gust_period: 1.5,
            ..default()
        }),
        Name::new("breeze"),
    ));
    // A strong, gusty, turbulent sphere of wind sweeping across the field.
    commands.spawn((
        ClothWindZone::sphere(2.2, Vec3::new(9.0, 0.0, 2.0)).with_turbulence(Turbulence {
            gust: 0.3,
            gust_period: 0.6,
            noise: 0.4,
            scale: 0.5,
            seed: 3,
        }),
        Transform::from_xyz(0.0, 1.6, 0.0),
        Sweeps {
            reach: 3.5,
            speed: 0.35,
        },
        // Drawn as a faint ball of its size.
        Mesh3d(meshes.add(Sphere::new(2.2).mesh().ico(4).unwrap())),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgba(0.9, 0.95, 1.0, 0.12),
            alpha_mode: AlphaMode::Blend,
            unlit: true,
            ..default()
        })),
        NotShadowCaster,
        Name::new("gust sphere"),
    ));
    common::spawn_stage(
        &mut commands,
        &mut meshes,
        &mut materials,
        Vec3::new(0.5, 1.2, 0.0),
        9.0,
        0.35,
    );
}

/// Swings the sweeping zone across the field.
fn sweep(time: Res<Time>, mut zones: Query<(&Sweeps, &mut Transform)>) {
    for (sweeps, mut transform) in &mut zones {
        transform.translation.x = sweeps.reach * (sweeps.speed * time.elapsed_secs()).sin();
    }
}
