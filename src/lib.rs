//! # bevy_cloth
//!
//! Cloth simulation for Bevy on the CPU: the mass-spring model of the 2014 thesis
//! "Model elastične tkanine" (seed 000) and the BMSTU T-shirt course work (seed 002),
//! with a measured solver that runs the same way in a game, a test and a benchmark.
//!
//! Add [`ClothPlugin`](ecs::plugin::ClothPlugin) and spawn a [`Cloth`](ecs::components::Cloth):
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
//! Layers, top to bottom: [`scene`] files and Rust builders → [`ecs`] (the
//! [`Cloth`](ecs::components::Cloth) component, the plugin's systems, mesh write-back) →
//! [`layout`] (grids, pattern and garment files → a layout) → [`solver`] (pure Rust, no
//! ECS: [`solver::ClothSolver`] steps a [`solver::Layout`]).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod ecs;
pub mod error;
pub mod headless;
pub mod layout;
pub mod limits;
pub mod params;
pub mod scene;
pub mod solver;
pub mod stats;

/// The types a user needs to add cloth to an app.
pub mod prelude {
    pub use crate::ecs::components::{
        AttachParticles, Cloth, ClothAttachment, ClothAttachments, ClothCollider, ClothEnvironment,
        ClothInvalid, ClothLod, ClothPause, ClothSimulation, ClothSleep, ClothStats, ClothTorn,
        ClothWake, ColliderKind, StatSample,
    };
    pub use crate::ecs::controls::{ClothControls, ClothControlsPlugin};
    pub use crate::ecs::plugin::{ClothPlugin, ClothSubstep, ClothSubstepSystems, ClothSystems};
    pub use crate::error::ClothError;
    pub use crate::headless::{SceneRun, headless_app};
    pub use crate::layout::shape::{ClothShape, Pins};
    pub use crate::params::{
        ClothParams, Environment, GoalUpdate, Integrator, Model, ModelKind, PatchParams,
        PatchTargets, RotationMethod, ShapeMatchingParams, SpringFamily, SpringParams, Substeps,
        Wind, WindField, XpbdParams,
    };
    pub use crate::scene::{ClothScene, SceneCloth, SceneCollider, SceneError, SpawnedScene};
}
