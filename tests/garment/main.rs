//! Pattern files, seams, colliders and the T-shirt on its mannequin (Maslova §1.4). One
//! file per feature, in one test binary (one link of Bevy). `cargo test --test garment`.

#[path = "../common/mod.rs"]
mod common;

mod assets;
mod colliders;
mod patterns;
mod tshirt;

use std::path::Path;

use bevy::math::{Affine3A, Vec3};
use bevy::prelude::App;
use bevy_cloth::headless::SceneRun;
use bevy_cloth::layout::garment::{GarmentLayout, asset_path};
use bevy_cloth::layout::pattern::{MAX_PATTERN_NODES, Pattern, PatternErrorKind};
use bevy_cloth::params::{Environment, Model, SpringParams, Substeps, XpbdParams};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::{ClothSolver, Collider, ColliderShape, Layout, SpringKind};
