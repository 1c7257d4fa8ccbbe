//! A textured flag on a moving pole: the flag's edge is attached to the pole
//! entity (`ClothAttachments`), so it follows the pole as it is carried round a circle and
//! turned; the pole is a capsule collider the flag wraps against; the flag's material is
//! your own — here a texture made in code, through the mesh's UVs (u along the width, v
//! down the height). Orbit camera, mouse tools and the inspector as in the other examples.
//!
//! `cargo run --example flag [-- --screenshot out.png --frames 120]`

// The shared example code; this example builds its own scene, so it uses part of it.
#[allow(dead_code)]
mod common;

use bevy::asset::RenderAssetUsages;
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
use bevy_cloth::params::{Wind, WindField};
use bevy_cloth::prelude::*;

/// The flag: particles across and down, and their spacing (m).
const WIDTH: u32 = 36;
const HEIGHT: u32 = 24;
const SPACING: f32 = 0.035;
/// The pole's radius and the height of its top (m).
const POLE_RADIUS: f32 = 0.03;
const POLE_TOP: f32 = 2.2;

/// The pole is carried round a circle of this radius (m) at this angular speed (rad/s).
#[derive(Component)]
struct Carried {
    radius: f32,
    speed: f32,
}

fn main() {
    let args = common::ExampleArgs::parse("");
    common::app("bevy_cloth — flag", args)
        .add_plugins(common::tools::ToolsPlugin)
        .add_systems(Startup, setup)
        .add_systems(FixedUpdate, carry_pole.before(ClothSystems::Prepare))
        .run();
}

/// A flag's texture: three horizontal bands with a white disc, `size` texels square.
fn flag_texture(size: u32) -> Image {
    let mut data = Vec::with_capacity((size * size * 4) as usize);
    for y in 0..size {
        for x in 0..size {
            let (u, v) = (x as f32 / size as f32, y as f32 / size as f32);
            let band = match (v * 3.0) as u32 {
                0 => [20, 60, 160],
                1 => [230, 190, 40],
                _ => [180, 30, 40],
            };
            let disc = (u - 0.3).powi(2) + (v - 0.5).powi(2) < 0.02;
            let [r, g, b] = if disc { [245, 245, 240] } else { band };
            data.extend_from_slice(&[r, g, b, 255]);
        }
    }
    Image::new(
        Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        data,
        TextureFormat::Rgba8UnormSrgb,
        RenderAssetUsages::default(),
    )
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut images: ResMut<Assets<Image>>,
    mut environment: ResMut<ClothEnvironment>,
) {
    environment.wind = Wind {
        direction: Vec3::new(1.0, 0.0, 0.3),
        strength: 0.002,
        field: WindField::Trigonometric,
    };
    // The pole: a capsule collider from the ground to its top, drawn.
    let half_length = POLE_TOP * 0.5 - POLE_RADIUS;
    let pole = commands
        .spawn((
            Transform::from_xyz(1.0, POLE_TOP * 0.5, 0.0),
            ClothCollider::capsule(POLE_RADIUS, 2.0 * half_length).with_thickness(0.01),
            Carried {
                radius: 1.0,
                speed: 0.5,
            },
            Mesh3d(meshes.add(Capsule3d::new(POLE_RADIUS, 2.0 * half_length))),
            MeshMaterial3d(materials.add(Color::srgb(0.55, 0.5, 0.45))),
            Name::new("pole"),
        ))
        .id();
    // The flag's grid hangs from the middle of its top edge; put its first column beside
    // the pole and attach that column to it (each particle at the point it has in the
    // pole's frame now).
    let half = (WIDTH - 1) as f32 * SPACING * 0.5;
    let edge: Vec<u32> = (0..HEIGHT).map(|j| j * WIDTH).collect();
    commands.spawn((
        Cloth::grid(WIDTH, HEIGHT, SPACING).with_params(ClothParams {
            node_mass: 3e-4,
            ..ClothParams::seeds()
        }),
        Transform::from_xyz(1.0 + POLE_RADIUS + 0.015 + half, POLE_TOP - 0.02, 0.0),
        ClothAttachments(vec![ClothAttachment::indices(pole, edge)]),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color_texture: Some(images.add(flag_texture(64))),
            double_sided: true,
            cull_mode: None,
            perceptual_roughness: 0.8,
            ..default()
        })),
        Name::new("flag"),
    ));
    common::spawn_stage(
        &mut commands,
        &mut meshes,
        &mut materials,
        Vec3::new(0.0, 1.4, 0.0),
        4.0,
        0.0,
    );
}

/// Carries the pole round its circle and turns it to face along its path.
fn carry_pole(time: Res<Time>, mut poles: Query<(&Carried, &mut Transform)>) {
    let t = time.elapsed_secs();
    for (carried, mut transform) in &mut poles {
        let angle = carried.speed * t;
        transform.translation.x = carried.radius * angle.cos();
        transform.translation.z = -carried.radius * angle.sin();
        transform.rotation = Quat::from_rotation_y(angle);
    }
}
