//! # bevy_cloth
//!
//! Cloth simulation for Bevy on the CPU: the mass-spring model of the 2014 thesis
//! "Model elastične tkanine" (Sladović 2014) and the BMSTU T-shirt course work (Maslova),
//! with a measured solver that runs the same way in a game, a test and a benchmark.
//!
//! Add [`ClothPlugin`] and spawn a [`Cloth`]:
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
//!         Cloth::grid(32, 32, 0.05).with_pins(ClothPins::TopCorners),
//!         MeshMaterial3d(materials.add(StandardMaterial { double_sided: true, cull_mode: None, ..default() })),
//!         Transform::from_xyz(0.0, 2.0, 0.0),
//!     ));
//! }
//! ```
//!
//! Layers, top to bottom: [`scene`] files and Rust builders → the Bevy layer (the
//! [`Cloth`] component, [`ClothPlugin`]'s systems, one file per feature, mesh
//! write-back; its items are at this crate's root) → [`layout`] (grids, pattern and
//! garment files → a layout) → [`solver`] (pure Rust, no ECS: [`solver::ClothSolver`]
//! steps a [`solver::Layout`]). [`headless`] runs scenes without a window for tests and
//! measurements.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod ecs;
pub mod error;
pub mod fabric;
pub mod headless;
#[doc(hidden)]
pub mod lab;
pub mod layout;
pub mod limits;
pub mod params;
pub mod scene;
pub mod solver;
pub mod stats;

#[cfg(feature = "avian")]
pub use ecs::avian;
pub use ecs::*;
pub use error::ClothError;
pub use layout::shape::{ClothPins, ClothShape};
pub use params::ClothParams;
pub use scene::ClothScene;

/// What a game uses to add cloth: the plugin, the components, the events, the shape,
/// pins and parameters of a cloth, and what the README's features ask for (a fabric,
/// self-collision, air). The model's parameter types (`Model`, `XpbdParams`, `Wind`, …)
/// are in [`params`], so that their names stay out of a game's namespace.
pub mod prelude {
    #[cfg(feature = "avian")]
    pub use crate::ecs::avian::ClothAvianPlugin;
    pub use crate::ecs::{
        AttachParticles, Cloth, ClothAttachment, ClothAttachments, ClothAwoke, ClothBackStop,
        ClothBecameInvalid, ClothBudget, ClothBuilt, ClothCollider, ClothColliderBecameInvalid,
        ClothColliderInvalid, ClothColliderSpan, ClothCulling, ClothEnvironment, ClothFellAsleep,
        ClothInterpolation, ClothInvalid, ClothLod, ClothMaxDistance, ClothOverBudget, ClothPause,
        ClothPlugin, ClothPriority, ClothProxy, ClothProxyEntity, ClothSimulation, ClothSleep,
        ClothStageStats, ClothStats, ClothSubstep, ClothSubstepSystems, ClothSystems,
        ClothTeleport, ClothTeleported, ClothTorn, ClothWake, ClothWindZone, ClothWithinBudget,
    };
    pub use crate::error::ClothError;
    pub use crate::fabric::Fabric;
    pub use crate::layout::shape::{ClothPins, ClothShape};
    pub use crate::params::{
        Air, ClothParams, Environment, Inertia, Model, SelfCollision, Substeps, Teleport,
        TeleportMode, Turbulence, XpbdParams, ZoneShape,
    };
    pub use crate::scene::ClothScene;
}
