//! Cloth on animated characters: motion constraints (a painted maximum distance from
//! where the body's skinning puts each vertex), a cloth built from a skinned mesh
//! following its bones, mesh vertex indices through the welding, a glTF character, and
//! teleports, inertia and a speed cap. One file per feature, in one test binary (one link
//! of Bevy). `cargo test --test character`.

#[path = "../common/mod.rs"]
mod common;

mod gltf;
mod motion;
mod skinned;
mod teleport;

use bevy::asset::RenderAssetUsages;
use bevy::math::{Affine3A, Quat, Vec3};
use bevy::mesh::skinning::{SkinnedMesh, SkinnedMeshInverseBindposes};
use bevy::mesh::{Indices, Mesh, Mesh3d, PrimitiveTopology, VertexAttributeValues};
use bevy::prelude::*;
use bevy_cloth::ATTRIBUTE_MAX_DISTANCE;
use bevy_cloth::params::{Environment, Model};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::BackStop;

/// Where a 12 × 12 grid's rest particle `local` is at time `t` on a body that walks
/// (1.5 m/s along x), bobs (3 cm at 2 Hz) and sways (±20° about y at 1 Hz).
fn animated(local: Vec3, t: f32) -> Vec3 {
    let sway = Quat::from_rotation_y(0.35 * (std::f32::consts::TAU * t).sin());
    let bob = Vec3::new(
        1.5 * t,
        1.0 + 0.03 * (2.0 * std::f32::consts::TAU * t).sin(),
        0.0,
    );
    sway * local + bob
}

/// An unpinned `width × height` grid 5 cm apart with the default parameters, as built.
fn free_grid(width: u32, height: u32) -> bevy_cloth::solver::ClothSolver {
    let shape = ClothShape::Grid {
        width,
        height,
        spacing: 0.05,
    };
    shape
        .build_solver(&ClothPins::None, &ClothParams::seeds(), Affine3A::IDENTITY)
        .unwrap()
}
