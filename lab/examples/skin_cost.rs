//! What skinning a cloth on the CPU costs beside its step: a skirt of `ROWS × AROUND`
//! particles (56 × 36 = 2,016 by default) made of a mesh skinned to a hip and a thigh
//! joint that swing, with painted max distances, run in a headless app; and the same
//! mesh without its skin (its distances following its entity instead). Each frame's
//! update time and the cloth's own step time (`ClothSimulation::last_step_ms`), medians
//! over 300 frames after 30, alternating the two apps frame by frame so both see the same
//! machine. The skinning's share is (skinned update − unskinned update) / cloth step.
//!
//! `cargo run -p bevy_cloth_lab --example skin_cost`

use std::time::Instant;

use bevy::asset::RenderAssetUsages;
use bevy::mesh::skinning::{SkinnedMesh, SkinnedMeshInverseBindposes};
use bevy::mesh::{Indices, Mesh, Mesh3d, PrimitiveTopology, VertexAttributeValues};
use bevy::prelude::*;
use bevy_cloth::ATTRIBUTE_MAX_DISTANCE;
use bevy_cloth::prelude::*;

const ROWS: u32 = 56;
const AROUND: u32 = 36;

/// The skirt: rings from the waist (y 0.95) down 0.45 m, skinned to the hip (top) and
/// blending to the thigh (bottom), max distance 0 at the waist to 0.2 m at the hem.
fn skirt(skinned: bool) -> Mesh {
    let (mut positions, mut joints, mut weights, mut distance) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for j in 0..ROWS {
        let down = j as f32 / (ROWS - 1) as f32;
        for i in 0..AROUND {
            let a = std::f32::consts::TAU * i as f32 / AROUND as f32;
            let r = 0.18 + 0.14 * down;
            positions.push([r * a.sin(), 0.95 - 0.45 * down, r * a.cos()]);
            joints.push([0u16, 1, 0, 0]);
            weights.push([1.0 - 0.5 * down, 0.5 * down, 0.0, 0.0]);
            distance.push(0.2 * down * down);
        }
    }
    let mut indices = Vec::new();
    for j in 0..ROWS - 1 {
        for i in 0..AROUND {
            let (a, b) = (j * AROUND + i, j * AROUND + (i + 1) % AROUND);
            indices.extend([a, a + AROUND, b, b, a + AROUND, b + AROUND]);
        }
    }
    let mut mesh = Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(ATTRIBUTE_MAX_DISTANCE, distance)
    .with_inserted_indices(Indices::U32(indices));
    if skinned {
        mesh.insert_attribute(
            Mesh::ATTRIBUTE_JOINT_INDEX,
            VertexAttributeValues::Uint16x4(joints),
        );
        mesh.insert_attribute(Mesh::ATTRIBUTE_JOINT_WEIGHT, weights);
    }
    mesh
}

/// A headless app with the skirt, skinned or not, and its two joints; returns the app,
/// the joints and the cloth.
fn app(skinned: bool) -> (App, [Entity; 2], Entity) {
    let mut app = bevy_cloth::headless::headless_app();
    let hip = app
        .world_mut()
        .spawn(Transform::from_xyz(0.0, 0.95, 0.0))
        .id();
    let thigh = app
        .world_mut()
        .spawn((Transform::from_xyz(0.1, -0.05, 0.0), ChildOf(hip)))
        .id();
    let inverse = vec![
        Mat4::from_translation(Vec3::new(0.0, -0.95, 0.0)),
        Mat4::from_translation(Vec3::new(-0.1, -0.9, 0.0)),
    ];
    let bindposes = app
        .world_mut()
        .resource_mut::<Assets<SkinnedMeshInverseBindposes>>()
        .add(SkinnedMeshInverseBindposes::from(inverse));
    let mesh = app
        .world_mut()
        .resource_mut::<Assets<Mesh>>()
        .add(skirt(skinned));
    let mut cloth = app
        .world_mut()
        .spawn((Mesh3d(mesh), Cloth::from_mesh().with_pins(ClothPins::None)));
    if skinned {
        cloth.insert(SkinnedMesh {
            inverse_bindposes: bindposes,
            joints: vec![hip, thigh],
        });
    }
    let cloth = cloth.id();
    (app, [hip, thigh], cloth)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let mut runs: Vec<_> = [true, false].map(app).into_iter().collect();
    let mut update = [Vec::new(), Vec::new()];
    let mut step = [Vec::new(), Vec::new()];
    for frame in 0..330 {
        let t = frame as f32 / 60.0;
        for (k, (app, [hip, thigh], cloth)) in runs.iter_mut().enumerate() {
            let world = app.world_mut();
            world.get_mut::<Transform>(*hip).unwrap().translation.x = 0.8 * t;
            world.get_mut::<Transform>(*thigh).unwrap().rotation =
                Quat::from_rotation_x(0.5 * (std::f32::consts::TAU * t).sin());
            let start = Instant::now();
            app.update();
            let took = start.elapsed().as_secs_f64() * 1e3;
            let Some(sim) = app.world().get::<ClothSimulation>(*cloth) else {
                assert!(frame < 5, "the cloth is built");
                continue;
            };
            assert!(sim.solver.is_stable());
            if frame >= 30 {
                update[k].push(took);
                step[k].push(f64::from(sim.last_step_ms));
            }
        }
    }
    let particles = runs[0]
        .0
        .world()
        .get::<ClothSimulation>(runs[0].2)
        .unwrap()
        .solver
        .particle_count();
    let [skinned, plain] = update.map(median);
    let cloth_step = median(step[0].clone());
    println!("{particles} particles, medians of 300 frames:");
    println!("  update, skinned:   {skinned:.3} ms (cloth step {cloth_step:.3} ms)");
    println!(
        "  update, unskinned: {plain:.3} ms (cloth step {:.3} ms)",
        median(step[1].clone())
    );
    println!(
        "  skinning on the CPU: {:.3} ms, {:.1}% of the cloth step",
        skinned - plain,
        100.0 * (skinned - plain) / cloth_step
    );
}
