//! The components and resources a Bevy user touches.

use bevy::ecs::message::Message;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::ClothError;
use crate::params::{ClothParams, Environment};
use crate::shape::{ClothShape, Pins};
use crate::solver;

/// A cloth: its shape, its pins and its model parameters. Spawn it on an entity and the
/// plugin builds the simulation and a mesh for it; the entity's transform places the
/// cloth and moves its pins.
///
/// Edit `params` at run time and the next step uses them; edit `shape` or `pins` and the
/// cloth is rebuilt.
///
/// ```
/// use bevy_cloth::prelude::*;
/// let cloth = Cloth::grid(24, 16, 0.05).with_pins(Pins::TopRow);
/// assert!(cloth.validate().is_ok());
/// ```
#[derive(Component, Clone, Debug, Default, PartialEq, Reflect, Serialize, Deserialize)]
#[reflect(Component, Default)]
#[require(Transform, Visibility)]
#[serde(default, deny_unknown_fields)]
pub struct Cloth {
    /// The initial layout.
    pub shape: ClothShape,
    /// Which particles are held.
    pub pins: Pins,
    /// The model's parameters.
    pub params: ClothParams,
}

impl Cloth {
    /// A `width × height` grid with `spacing` m between neighbours, pinned at its top corners.
    pub fn grid(width: u32, height: u32, spacing: f32) -> Self {
        Self {
            shape: ClothShape::Grid {
                width,
                height,
                spacing,
            },
            ..default()
        }
    }

    /// A cloth made of the entity's own `Mesh3d` (what bevy_silk users know): vertices
    /// become particles, edges springs. Pinned at its highest vertices by default.
    pub fn from_mesh() -> Self {
        Self {
            shape: ClothShape::Mesh,
            pins: Pins::TopRow,
            ..default()
        }
    }

    /// Replaces the pins.
    pub fn with_pins(mut self, pins: Pins) -> Self {
        self.pins = pins;
        self
    }

    /// Replaces the model parameters.
    pub fn with_params(mut self, params: ClothParams) -> Self {
        self.params = params;
        self
    }

    /// Checks shape and parameters (pins are checked when the cloth is built, against its
    /// particle count).
    pub fn validate(&self) -> Result<(), ClothError> {
        self.shape.validate()?;
        self.params.validate()
    }

    /// Builds the solver for this cloth placed by `frame` (grid shapes only; mesh shapes
    /// are built by the plugin from the entity's mesh).
    pub fn build(&self, frame: bevy::math::Affine3A) -> Result<solver::Cloth, ClothError> {
        solver::Cloth::new(&self.shape, &self.pins, &self.params, frame)
    }
}

/// The running simulation of a [`Cloth`], added by the plugin. Read it for positions,
/// energies and statistics; mutate it for tools such as grabbing or cutting.
#[derive(Component, Debug)]
pub struct ClothSimulation {
    /// The solver state.
    pub solver: solver::Cloth,
    /// The shape and pins it was built from (a change of either rebuilds).
    pub(crate) built_from: (ClothShape, Pins),
    /// True when the solver moved since the mesh was last written.
    pub(crate) mesh_dirty: bool,
    /// Scratch buffer for normals, kept to avoid allocating per frame.
    pub(crate) normals: Vec<Vec3>,
    /// Wall-clock time of the last fixed step, in ms.
    pub last_step_ms: f32,
}

impl ClothSimulation {
    pub(crate) fn new(solver: solver::Cloth, cloth: &Cloth) -> Self {
        let n = solver.particle_count();
        Self {
            solver,
            built_from: (cloth.shape.clone(), cloth.pins.clone()),
            mesh_dirty: true,
            normals: vec![Vec3::ZERO; n],
            last_step_ms: 0.0,
        }
    }

    /// Puts the cloth back at rest in its initial layout, with every spring whole.
    pub fn reset(&mut self) {
        self.solver.reset();
        self.mesh_dirty = true;
    }
}

/// Why a cloth is not simulated: the plugin puts this on a cloth whose description is
/// invalid (and logs it), and removes it once the description is fixed.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct ClothInvalid(pub ClothError);

/// Gravity and wind for every cloth.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Reflect, Deref, DerefMut)]
#[reflect(Resource, Default)]
pub struct ClothEnvironment(pub Environment);

/// Pauses every cloth; while paused, `step_once` lets exactly one fixed step through.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq, Reflect)]
#[reflect(Resource, Default)]
pub struct ClothPause {
    /// No cloth moves while true (the fixed schedule still runs).
    pub paused: bool,
    /// Fixed steps still to run while paused.
    pub pending_steps: u32,
}

impl ClothPause {
    /// Pauses, or resumes.
    pub fn toggle(&mut self) {
        self.paused = !self.paused;
        self.pending_steps = 0;
    }

    /// While paused, runs one more fixed step.
    pub fn step_once(&mut self) {
        if self.paused {
            self.pending_steps += 1;
        }
    }
}

/// One sample of a cloth's statistics history.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StatSample {
    /// Simulated time, s.
    pub time: f32,
    /// Wall-clock time of that step, ms.
    pub step_ms: f32,
    /// Total energy after it, J.
    pub energy: f32,
}

/// Live statistics of a cloth, kept by the plugin when this component is present (it costs
/// one pass over the springs per step). For inspectors and measurement.
#[derive(Component, Clone, Debug, Default)]
pub struct ClothStats {
    /// Particles.
    pub particles: usize,
    /// Acting springs.
    pub springs: usize,
    /// Springs torn since the last reset.
    pub torn: usize,
    /// Substeps in the last step.
    pub substeps: u32,
    /// True when automatic substeps hit their cap: the step may be unstable.
    pub under_resolved: bool,
    /// Median step time over the last second of wall-clock steps, ms.
    pub step_ms_median: f32,
    /// Largest structural strain.
    pub max_strain: f32,
    /// Energies after the last step.
    pub energy: crate::solver::Energy,
    /// The last `HISTORY_SECONDS` of samples, oldest first.
    pub history: std::collections::VecDeque<StatSample>,
    scratch: Vec<f32>,
}

impl ClothStats {
    /// Seconds of history kept.
    pub const HISTORY_SECONDS: f32 = 10.0;

    /// Records a finished step.
    pub fn record(&mut self, cloth: &solver::Cloth, env: &Environment, step_ms: f32) {
        self.particles = cloth.particle_count();
        self.springs = cloth.spring_count();
        self.torn = cloth.torn_count();
        self.substeps = cloth.substeps();
        self.under_resolved = cloth.under_resolved();
        self.max_strain = cloth.strain().max;
        self.energy = cloth.energy(env);
        let time = cloth.time();
        if self.history.back().is_some_and(|s| s.time > time) {
            self.history.clear(); // the cloth was reset
        }
        self.history.push_back(StatSample {
            time,
            step_ms,
            energy: self.energy.total(),
        });
        while self
            .history
            .front()
            .is_some_and(|s| s.time < time - Self::HISTORY_SECONDS)
        {
            self.history.pop_front();
        }
        self.scratch.clear();
        self.scratch.extend(
            self.history
                .iter()
                .rev()
                .take_while(|s| s.time >= time - 1.0)
                .map(|s| s.step_ms),
        );
        let mid = self.scratch.len() / 2;
        self.step_ms_median = if self.scratch.is_empty() {
            0.0
        } else {
            *self.scratch.select_nth_unstable_by(mid, f32::total_cmp).1
        };
    }
}

/// Sent when a spring tears, once per spring.
#[derive(Message, Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClothTorn {
    /// The cloth entity.
    pub cloth: Entity,
    /// The torn spring's index in `solver.springs()`.
    pub spring: u32,
    /// The two particles it joined.
    pub particles: [u32; 2],
}
