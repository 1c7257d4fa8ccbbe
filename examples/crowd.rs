//! A crowd: fifty characters walking their own loops across a square, each in a cape
//! (attached at the shoulders) and a skirt (a mesh held within painted distances of the
//! hips, Jolt's and Magica's skinned constraints, with a back stop), each cloth drawn
//! through a proxy mesh three times finer each way. Every three seconds one character
//! is teleported 12 m across the square and back, its cloth carried with it; a gusty
//! wind zone blows across the square's middle; cloths out of the camera's view stop
//! (`ClothCulling`). `cloth crowd` is its headless twin, which
//! times the parts of a frame.
//!
//! `cargo run --example crowd [-- --screenshot out.png --frames 120]`

// The shared example code; this example builds its own scene, so it uses part of it.
#[allow(dead_code)]
mod common;

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;
use bevy_cloth::prelude::*;

/// Characters, and the square's side in loops.
const CHARACTERS: usize = 50;
const SIDE: usize = 8;
/// Shoulder height, hip height and the body's radius, m.
const SHOULDERS: f32 = 1.45;
const HIPS: f32 = 0.95;
const BODY_RADIUS: f32 = 0.17;
/// The cape: particles across and down, spacing (m); the skirt: around and down.
const CAPE: (u32, u32, f32) = (16, 24, 0.035);
const SKIRT: (u32, u32) = (32, 12);
/// How many times finer each way the drawn meshes are.
const REFINE: u32 = 3;
/// Seconds between teleports, and how far one goes.
const TELEPORT_EVERY: f32 = 3.0;
const TELEPORT: Vec3 = Vec3::new(12.0, 0.0, 0.0);

/// A character's loop.
#[derive(Component)]
struct Walk {
    centre: Vec3,
    radius: f32,
    speed: f32,
    phase: f32,
    away: bool,
}

impl Walk {
    fn transform(&self, t: f32) -> Transform {
        let angle = self.phase + self.speed * t / self.radius;
        let (s, c) = angle.sin_cos();
        let jump = if self.away { TELEPORT } else { Vec3::ZERO };
        let at = self.centre + self.radius * Vec3::new(c, 0.0, s) + jump;
        Transform::from_translation(at + Vec3::Y * 0.02 * (4.0 * angle).sin())
            .with_rotation(Quat::from_rotation_y(-angle))
    }
}

fn main() {
    let args = common::ExampleArgs::parse("");
    common::app("bevy_cloth — crowd", args)
        .add_systems(Startup, setup)
        .add_systems(FixedUpdate, walk.before(ClothSystems::Prepare))
        .run();
}

/// A grid's points in its own frame as the cloth lays it out (x across about its
/// middle, y down from 0), `k` times finer, with normals, UVs and triangles.
fn grid_mesh(w: u32, h: u32, spacing: f32, k: u32) -> Mesh {
    let (fw, fh) = ((w - 1) * k + 1, (h - 1) * k + 1);
    let (step, half) = (spacing / k as f32, (w - 1) as f32 * spacing * 0.5);
    let positions: Vec<[f32; 3]> = (0..fw * fh)
        .map(|v| {
            [
                (v % fw) as f32 * step - half,
                -((v / fw) as f32) * step,
                0.0,
            ]
        })
        .collect();
    let uvs: Vec<[f32; 2]> = (0..fw * fh)
        .map(|v| {
            [
                (v % fw) as f32 / (fw - 1) as f32,
                (v / fw) as f32 / (fh - 1) as f32,
            ]
        })
        .collect();
    let mut indices = Vec::new();
    for j in 0..fh - 1 {
        for i in 0..fw - 1 {
            let v = j * fw + i;
            indices.extend([v, v + fw, v + 1, v + 1, v + fw, v + fw + 1]);
        }
    }
    mesh_of(positions, uvs, indices)
}

/// A skirt's cone from the waist (radius 0.19 m at the hips) flaring to 0.31 m 0.42 m
/// below, `around × down` points `k` times finer, in the hips' frame.
fn cone_mesh(around: u32, down: u32, k: u32) -> Mesh {
    let (fa, fd) = (around * k, (down - 1) * k + 1);
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for j in 0..fd {
        let s = j as f32 / (fd - 1) as f32;
        for i in 0..fa {
            let a = std::f32::consts::TAU * i as f32 / fa as f32;
            let r = 0.19 + 0.12 * s;
            positions.push([r * a.sin(), -0.42 * s, r * a.cos()]);
            uvs.push([i as f32 / fa as f32, s]);
        }
    }
    let mut indices = Vec::new();
    for j in 0..fd - 1 {
        for i in 0..fa {
            let (a, b) = (j * fa + i, j * fa + (i + 1) % fa);
            indices.extend([a, a + fa, b, b, a + fa, b + fa]);
        }
    }
    mesh_of(positions, uvs, indices)
}

fn mesh_of(positions: Vec<[f32; 3]>, uvs: Vec<[f32; 2]>, indices: Vec<u32>) -> Mesh {
    let n = positions.len();
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, vec![[0.0f32, 0.0, 1.0]; n])
    .with_inserted_attribute(Mesh::ATTRIBUTE_UV_0, uvs)
    .with_inserted_indices(Indices::U32(indices))
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let (cw, ch, spacing) = CAPE;
    let (around, down) = SKIRT;
    let body_mesh = meshes.add(Capsule3d::new(BODY_RADIUS, SHOULDERS - HIPS + 0.25));
    let head_mesh = meshes.add(Sphere::new(0.11));
    let skin = materials.add(Color::srgb(0.85, 0.7, 0.6));
    let cape_fine = meshes.add(grid_mesh(cw, ch, spacing, REFINE));
    let skirt_fine = meshes.add(cone_mesh(around, down, REFINE));
    // The skirt's painted distances: 0 at the waist, growing to 0.2 m at the hem.
    let distances: Vec<f32> = (0..around * down)
        .map(|k| 0.2 * ((k / around) as f32 / (down - 1) as f32).powi(2))
        .collect();
    let top_row: Vec<u32> = (0..cw).collect();
    let colours = [
        Color::srgb(0.7, 0.12, 0.12),
        Color::srgb(0.12, 0.3, 0.7),
        Color::srgb(0.85, 0.65, 0.12),
        Color::srgb(0.15, 0.55, 0.3),
        Color::srgb(0.5, 0.2, 0.6),
    ];
    for c in 0..CHARACTERS {
        let (row, column) = (c / SIDE, c % SIDE);
        let walk = Walk {
            centre: Vec3::new(column as f32 * 3.0 - 10.5, 0.0, row as f32 * 3.0 - 10.5),
            radius: 0.8 + 0.15 * (c % 4) as f32,
            speed: 1.0 + 0.1 * (c % 5) as f32,
            phase: c as f32 * 0.7,
            away: false,
        };
        let at = walk.transform(0.0);
        let body = commands
            .spawn((
                at,
                Visibility::default(),
                walk,
                Name::new(format!("character {c}")),
            ))
            .id();
        // The body: a capsule between hips and shoulders, drawn and collided with.
        let middle = 0.5 * (HIPS + SHOULDERS) - 0.1;
        commands.entity(body).with_children(|parent| {
            parent.spawn((
                Mesh3d(body_mesh.clone()),
                MeshMaterial3d(skin.clone()),
                Transform::from_xyz(0.0, middle, 0.0),
                ClothCollider::capsule(BODY_RADIUS, SHOULDERS - HIPS + 0.25),
            ));
            parent.spawn((
                Mesh3d(head_mesh.clone()),
                MeshMaterial3d(skin.clone()),
                Transform::from_xyz(0.0, SHOULDERS + 0.2, 0.0),
            ));
        });
        let material = materials.add(StandardMaterial {
            base_color: colours[c % colours.len()],
            double_sided: true,
            cull_mode: None,
            perceptual_roughness: 0.85,
            ..default()
        });
        // The cape: its top row attached to the shoulders, where it is at spawn.
        let behind = at.transform_point(Vec3::new(0.0, SHOULDERS, -BODY_RADIUS - 0.03));
        commands.spawn((
            Cloth::grid(cw, ch, spacing)
                .with_pins(ClothPins::None)
                .with_params(params()),
            Transform::from_translation(behind).with_rotation(at.rotation),
            ClothAttachments(vec![ClothAttachment::indices(body, top_row.clone())]),
            ClothProxy {
                mesh: cape_fine.clone(),
            },
            ClothCulling::default(),
            MeshMaterial3d(material.clone()),
            Name::new(format!("cape {c}")),
        ));
        // The skirt: a mesh at the hips, following them within its painted distances.
        let skirt = commands
            .spawn((
                Cloth::from_mesh()
                    .with_pins(ClothPins::None)
                    .with_params(params()),
                Mesh3d(meshes.add(cone_mesh(around, down, 1))),
                ClothMaxDistance::PerVertex(distances.clone()),
                ClothBackStop::Uniform {
                    distance: 0.01,
                    radius: 0.3,
                },
                ClothProxy {
                    mesh: skirt_fine.clone(),
                },
                ClothCulling::default(),
                Transform::from_xyz(0.0, HIPS, 0.0),
                MeshMaterial3d(material),
                Name::new(format!("skirt {c}")),
            ))
            .id();
        commands.entity(body).add_child(skirt);
    }
    // A gusty wind across the square's middle.
    commands.spawn((
        ClothWindZone::cuboid(Vec3::new(16.0, 2.0, 3.0), Vec3::new(5.0, 0.0, 1.5)).with_turbulence(
            Turbulence {
                gust: 0.4,
                gust_period: 1.2,
                noise: 0.3,
                scale: 0.8,
                seed: 11,
            },
        ),
        Transform::from_xyz(0.0, 1.0, 0.0),
        Name::new("wind"),
    ));
    common::spawn_stage(
        &mut commands,
        &mut meshes,
        &mut materials,
        Vec3::new(0.0, 1.0, 0.0),
        16.0,
        0.5,
    );
}

/// Walks every character along its loop; every few seconds the next one in turn is
/// teleported across the square (or back).
fn walk(time: Res<Time>, mut characters: Query<(&mut Walk, &mut Transform)>) {
    let (t, dt) = (time.elapsed_secs(), time.delta_secs());
    let turn = (t / TELEPORT_EVERY) as usize;
    let due = ((t - dt) / TELEPORT_EVERY) as usize != turn;
    for (k, (mut walk, mut transform)) in characters.iter_mut().enumerate() {
        if due && turn % CHARACTERS == k {
            walk.away = !walk.away;
        }
        *transform = walk.transform(t);
    }
}

/// The crowd's cloths: the seeds' mass-spring (`ClothParams::seeds`), its strain limiter sweeping until every
/// spring is within 1% of its limit, at most eight times, rather than always taking four.
/// Most of the crowd is calm and stops after one sweep; the capes in the gusts take more.
/// Against four sweeps always, `cloth crowd` measured 0.8 of the cost at the same strain;
/// against at most four, eight cost 2% more and leave the gusted capes less stretched.
fn params() -> ClothParams {
    ClothParams {
        strain_limit_tolerance: Some(0.01),
        strain_limit_iterations: 8,
        ..ClothParams::seeds()
    }
}
