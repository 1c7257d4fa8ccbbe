//! # bevy_cloth
//!
//! Cloth simulation for Bevy on the CPU: the mass-spring model of the 2014 thesis
//! "Model elastične tkanine" (seed 000) and the BMSTU T-shirt course work (seed 002),
//! with a measured solver that runs the same way in a game, a test and a benchmark.
//!
//! Add [`ClothPlugin`](plugin::ClothPlugin) and spawn a [`Cloth`](components::Cloth):
//!
//! ```no_run
//! use bevy::prelude::*;
//! use bevy_cloth::prelude::*;
//!
//! fn main() {
//!     App::new()
//!         .add_plugins((DefaultPlugins, ClothPlugin::default()))
//!         .add_systems(Startup, setup)
//!         .run();
//! }
//!
//! fn setup(mut commands: Commands, mut materials: ResMut<Assets<StandardMaterial>>) {
//!     commands.spawn((
//!         Cloth::grid(32, 32, 0.05).with_pins(Pins::TopCorners),
//!         MeshMaterial3d(materials.add(StandardMaterial { double_sided: true, cull_mode: None, ..default() })),
//!         Transform::from_xyz(0.0, 2.0, 0.0),
//!     ));
//! }
//! ```
//!
//! Layers, top to bottom: [`scene`] files and Rust builders → [`components::Cloth`]
//! (plain data) → [`solver::ClothSolver`] (pure Rust, no ECS) → [`plugin`] (systems, mesh
//! write-back).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod components;
pub mod controls;
pub mod error;
pub mod garment;
pub mod headless;
pub mod mesh;
pub mod params;
pub mod pattern;
pub mod plugin;
pub mod scene;
pub mod shape;
pub mod solver;
pub mod stats;

/// The types a user needs to add cloth to an app.
pub mod prelude {
    pub use crate::components::{
        Cloth, ClothCollider, ClothEnvironment, ClothInvalid, ClothPause, ClothSimulation,
        ClothStats, ClothTorn, ColliderKind, StatSample,
    };
    pub use crate::controls::{ClothControls, ClothControlsPlugin};
    pub use crate::error::ClothError;
    pub use crate::headless::{SceneRun, headless_app};
    pub use crate::params::{
        ClothParams, Environment, GoalUpdate, Integrator, Model, ModelKind, PatchParams,
        PatchTargets, RotationMethod, ShapeMatchingParams, SpringFamily, SpringParams, Substeps,
        Wind, WindField,
    };
    pub use crate::plugin::{ClothPlugin, ClothSubstep, ClothSubstepSystems, ClothSystems};
    pub use crate::scene::{ClothScene, SceneCloth, SceneCollider, SceneError, SpawnedScene};
    pub use crate::shape::{ClothShape, Pins};
}
