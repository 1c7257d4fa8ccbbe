//! The physics core: pure Rust, no ECS. The plugin, the tests, the command line and the
//! benches all call the same [`ClothSolver::step`], so what is measured is what runs in a game.
//!
//! A step is a pipeline of stages (`steps/mod.rs` describes it; one file per model under
//! `steps/`). The code is kept in rooms by concern: `constraints/` (stretch, bending,
//! tethers), `contact/` (colliders, one file per [shape](shapes), self-collision and
//! cloth–cloth contact), `drivers/` (pins, attachments, motion constraints, the grab),
//! `models/` (each model's own state), `diagnostics/` (energy, strain); beside them a
//! cloth's particles ([`Particles`]), what it is made of (`structure.rs`), its clock
//! (`clock.rs`) and the shared stages (`forces.rs`, `integrate.rs`).

mod budget;
mod build;
mod clock;
mod constraints;
mod contact;
mod diagnostics;
mod drivers;
mod forces;
mod integrate;
mod layout;
mod many;
mod models;
mod parallel;
mod proxy;
mod queries;
mod state;
mod steps;
mod structure;
mod substeps;
pub mod topology;
pub(crate) mod unit;
mod xpbd_substeps;

// The rooms' modules the other stages name.
use constraints::{bending, chains, lattice, tethers, xpbd};
use contact::self_contact;
use models::switch;

pub use budget::{BudgetClaim, GIVE_WAY_STRAIN, gives_way, share_budget};
pub use contact::shapes::{self, ColliderShape, ConvexHull, Placement, Shape};
pub use contact::{Collider, ColliderImpulse, Motion};
pub use diagnostics::{Energy, Strain};
pub use drivers::BackStop;
pub use drivers::interact::Grab;
pub use drivers::teleport::{RigidMove, Teleported};
pub use layout::{Layout, MAX_PARTICLES};
pub use many::{begin_cloths, run_cloths};
pub use many::{begin_together, substep_together};
pub use models::{patches, shape_matching};
pub(crate) use parallel::for_each_indexed;
pub use parallel::{on_one_thread, set_parallel, threads};
pub use proxy::ProxyBinding;
// Used by the lab through `crate::lab`: hidden from the docs.
#[doc(hidden)]
pub use parallel::{pool as task_pool, share_items};
pub use self_contact::{collide_cloths, exchange_cloths};
pub use state::Particles;
pub use steps::{StageTimes, StepReport};
#[doc(hidden)]
pub use substeps::unit_hash;
pub use topology::{SpringKind, Springs};

use bevy::math::Affine3A;

use crate::error::ClothError;
use crate::params::{ClothParams, Model};
use patches::Patches;
use shape_matching::ShapeMatching;

/// A simulated cloth: particles, springs, triangles and the step.
#[derive(Clone, Debug)]
pub struct ClothSolver {
    /// Every particle's state.
    particles: Particles,
    /// Rest shape, springs, faces, pieces, tears.
    structure: structure::Structure,
    /// ClothPins, attachments, the frame, a grab.
    drivers: drivers::Drivers,
    /// Colliders and the contact stage's scratch.
    contact: contact::Contact,
    /// Self-collision's pairs and scratch.
    self_contact: self_contact::SelfContact,
    /// Time and substeps.
    clock: clock::Clock,
    params: ClothParams,
    /// The active model's own state (built lazily by the step).
    model: ModelState,
    /// The model of the step in progress, chosen when it began.
    stepping: Model,
    /// A model switch in progress (`switch.rs`).
    switch: Option<switch::Switch>,
    /// Set by everything from outside that can move a resting cloth (see
    /// [`ClothSolver::take_disturbed`]); what a sleeping cloth is woken by.
    disturbed: bool,
    /// What the step in progress (or the last) has done.
    report: StepReport,
    /// The state the step in progress started from.
    checkpoint: steps::Checkpoint,
    /// A teleport asked for the next step ([`ClothSolver::teleport_next_step`]).
    teleport_request: Option<crate::params::TeleportMode>,
    /// The drivers' rigid motion over the last step, while teleports are watched for.
    drivers_motion: Option<RigidMove>,
    /// The part of it the cloth felt and where it started, while its
    /// [`Inertia`](crate::params::Inertia) is scaled.
    felt: drivers::inertia::Felt,
    /// Each particle's share of the air's force, as worked out on the triangles
    /// (`forces.rs`).
    air: forces::AirLoad,
    /// The wind zones that reach it.
    wind: forces::Blowing,
    /// The particles self-collision or contact moved in the step in progress: the
    /// stretch at their springs is not the solver's error (`steps/mod.rs`).
    touched: Vec<bool>,
}

/// The active model's own state: none for mass-spring (or before the first step
/// builds it), the clusters and goals of shape matching, the part lattice and
/// targets of the patch model, or XPBD's coloured constraints. One at a time, by
/// construction.
#[derive(Clone, Debug)]
enum ModelState {
    None,
    ShapeMatching(ShapeMatching),
    Patches(Box<Patches>),
    Xpbd(Box<xpbd::Constraints>),
}

impl ModelState {
    fn shape_matching(&self) -> Option<&ShapeMatching> {
        match self {
            ModelState::ShapeMatching(s) => Some(s),
            _ => None,
        }
    }

    fn shape_matching_mut(&mut self) -> Option<&mut ShapeMatching> {
        match self {
            ModelState::ShapeMatching(s) => Some(s),
            _ => None,
        }
    }

    fn patches(&self) -> Option<&Patches> {
        match self {
            ModelState::Patches(p) => Some(p),
            _ => None,
        }
    }

    fn patches_mut(&mut self) -> Option<&mut Patches> {
        match self {
            ModelState::Patches(p) => Some(p),
            _ => None,
        }
    }
}

impl ClothSolver {
    /// The parameters in use.
    pub fn params(&self) -> &ClothParams {
        &self.params
    }

    /// Replaces the parameters; they act from the next substep. Invalid values are
    /// refused with an error and the old parameters stay.
    pub fn set_params(&mut self, params: &ClothParams) -> Result<(), ClothError> {
        params.validate()?;
        check_model_fits(
            params,
            self.structure.grid,
            !self.structure.triangles.is_empty(),
        )?;
        crate::params::check_work(self.particles.len(), params)?;
        check_fabric_masses(params, &self.structure.area)?;
        self.apply_params(params);
        Ok(())
    }

    /// [`ClothSolver::set_params`] for parameters known to be valid for this cloth (the
    /// patch lattice's, derived from the cloth's validated ones).
    pub(crate) fn apply_params(&mut self, params: &ClothParams) {
        self.disturbed |= *params != self.params;
        self.begin_switch(params);
        let reweigh =
            params.node_mass != self.params.node_mass || params.fabric != self.params.fabric;
        self.params = *params;
        if params.fabric.is_some() {
            self.structure.build_hinges();
        }
        if reweigh {
            for i in 0..self.particles.len() {
                self.particles.mass[i] = self.particle_mass(i);
                if self.particles.inv_mass[i] != 0.0 {
                    self.particles.inv_mass[i] = 1.0 / self.particles.mass[i];
                }
            }
        }
    }

    /// The frame (local → world) the pins follow.
    pub fn frame(&self) -> Affine3A {
        self.drivers.frame
    }

    /// Moves the pins' frame; pinned particles move there over the next step, smoothly
    /// across its substeps, and drag the cloth along.
    pub fn set_frame(&mut self, frame: Affine3A) {
        self.disturbed |= frame != self.drivers.frame;
        self.drivers.frame = frame;
    }

    /// True once after anything from outside could have moved the cloth since the last
    /// call: new parameters, a moved frame (the pins), a collider that changed within
    /// reach of the cloth, a grab, a drag or a release, a tear or a cut, a reset, or
    /// mutable access to the particles. A sleeping cloth (the plugin's `ClothSleep`)
    /// wakes on it; the step itself never sets it.
    pub fn take_disturbed(&mut self) -> bool {
        std::mem::take(&mut self.disturbed)
    }
}

/// The acting stiffness of family `kind` in `springs` (0 when switched off).
fn family_stiffness(springs: &crate::params::SpringParams, kind: SpringKind) -> f32 {
    match kind {
        SpringKind::Structural => springs.structural.effective(),
        SpringKind::Shear => springs.shear.effective(),
        SpringKind::Bend => springs.bend.effective(),
        SpringKind::BendDiagonal => springs.bend_diagonal.effective(),
        SpringKind::Seam => springs.seam.effective(),
    }
}

/// The patch model needs a grid cloth (its parts are blocks of rows and columns); a
/// fabric needs triangles (its masses and hinges come from their areas).
fn check_model_fits(
    params: &ClothParams,
    grid: Option<(u32, u32)>,
    triangles: bool,
) -> Result<(), ClothError> {
    if matches!(params.model, Model::Patches(_)) && grid.is_none() {
        return Err(ClothError::ModelNeedsGrid { model: "patch" });
    }
    if params.fabric.is_some() && !triangles {
        return Err(ClothError::FabricNeedsSurface);
    }
    Ok(())
}

/// The scale `(d/L)^(p−1)` of the pull `α (d/L)^(p−1) d` toward a goal or target used by
/// shape matching and the patch model (Sladović 2014 §4's exponent p), with `d/L` kept ≥ 0.05
/// so that `p < 1` stays finite at the goal.
#[inline]
pub(crate) fn pull_scale(d: f32, length_scale: f32, exponent: f32) -> f32 {
    if exponent == 1.0 {
        1.0
    } else {
        (d / length_scale).max(0.05).powf(exponent - 1.0)
    }
}

/// A fabric's particles weigh its areal density times their share of the cloth's area:
/// the lightest must weigh at least [`MIN_NODE_MASS`](crate::limits::MIN_NODE_MASS), or
/// forces leave `f32`'s range (a density only checked `> 0` gave particles of 0 kg at a
/// fine spacing, or on a vertex no triangle uses).
pub(crate) fn check_fabric_masses(params: &ClothParams, area: &[f32]) -> Result<(), ClothError> {
    let Some(fabric) = &params.fabric else {
        return Ok(());
    };
    let lightest = area.iter().fold(f32::INFINITY, |m, &a| m.min(a)) * fabric.areal_density;
    if area.is_empty() || lightest >= crate::limits::MIN_NODE_MASS {
        return Ok(());
    }
    Err(ClothError::InvalidParameter {
        field: "fabric.areal_density",
        value: fabric.areal_density,
        expected: "a density whose lightest particle weighs at least 1e-9 kg \
                   (limits::MIN_NODE_MASS) at this cloth's spacing"
            .into(),
    })
}
