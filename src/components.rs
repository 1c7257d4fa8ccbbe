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

/// Pauses every cloth while true (the fixed step still runs; cloths do not move).
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq, Reflect)]
#[reflect(Resource, Default)]
pub struct ClothPaused(pub bool);

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
