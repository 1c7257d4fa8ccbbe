//! The cloth itself: the [`Cloth`] description a game spawns, the [`ClothSimulation`] the
//! plugin adds, why a cloth is not simulated ([`ClothInvalid`]), and the resources every
//! cloth shares ([`ClothEnvironment`], [`ClothPause`]).

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::ecs::events::ClothBecameInvalid;
use crate::error::ClothError;
use crate::layout::garment::{GarmentLayout, asset_path};
use crate::layout::shape::{ClothPins, ClothShape};
use crate::params::{ClothParams, Environment};
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
/// let cloth = Cloth::grid(24, 16, 0.05).with_pins(ClothPins::TopRow);
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
    pub pins: ClothPins,
    /// The model's parameters.
    pub params: ClothParams,
}

impl Cloth {
    /// A `width × height` grid with `spacing` m between neighbours, hanging in its local XY
    /// plane from its origin, pinned at its top corners unless it has
    /// [`ClothAttachments`](crate::ClothAttachments) ([`ClothPins::Auto`]).
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
            pins: ClothPins::TopRow,
            ..default()
        }
    }

    /// Replaces the pins.
    pub fn with_pins(mut self, pins: ClothPins) -> Self {
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
        self.params.validate()?;
        // A grid's work per step is known from its size (the others' when built).
        if let ClothShape::Grid { width, height, .. } = self.shape {
            crate::params::check_work(width as usize * height as usize, &self.params)?;
        }
        Ok(())
    }

    /// A garment from a garment file under `assets/` (see [`crate::layout::garment`]), at
    /// resolution 1, pinned nowhere.
    pub fn garment(file: impl Into<String>) -> Self {
        Self {
            shape: ClothShape::Garment {
                file: file.into(),
                resolution: 1,
            },
            pins: ClothPins::None,
            ..default()
        }
    }

    /// Builds the solver for this cloth placed by `frame`: grids directly, garments from
    /// their files read from disk (the plugin loads them as assets instead). Mesh shapes
    /// are built by the plugin from the entity's mesh.
    pub fn build(&self, frame: bevy::math::Affine3A) -> Result<solver::ClothSolver, ClothError> {
        match &self.shape {
            ClothShape::Garment { file, resolution } => {
                self.build_garment(GarmentLayout::load(&asset_path(file), *resolution)?, frame)
            }
            _ => self.shape.build_solver(&self.pins, &self.params, frame),
        }
    }

    /// Builds the solver of a garment cloth from its laid-out garment, logging the
    /// patterns' warnings.
    pub fn build_garment(
        &self,
        layout: GarmentLayout,
        frame: bevy::math::Affine3A,
    ) -> Result<solver::ClothSolver, ClothError> {
        for warning in &layout.warnings {
            warn!("{warning}");
        }
        if layout.positions.is_empty() || layout.triangles.is_empty() {
            return Err(ClothError::EmptyGarment);
        }
        let layout = layout.into_layout();
        let pins = self.pins.resolve_for(&layout)?;
        solver::ClothSolver::new(layout, &pins, &self.params, frame)
    }
}

/// The running simulation of a [`Cloth`], added by the plugin. Read it for positions,
/// energies and statistics; mutate it for tools such as grabbing or cutting.
///
/// (Reflected for inspectors without its solver, which is not reflectable.)
#[derive(Component, Debug, Reflect)]
#[reflect(Component, Debug, from_reflect = false)]
pub struct ClothSimulation {
    /// The solver state.
    #[reflect(ignore)]
    pub solver: solver::ClothSolver,
    /// The shape and pins it was built from (a change of either rebuilds).
    #[reflect(ignore)]
    pub(crate) built_from: (ClothShape, ClothPins),
    /// True when the solver moved since the mesh was last written.
    pub(crate) mesh_dirty: bool,
    /// Scratch buffer for normals, kept to avoid allocating per frame.
    #[reflect(ignore)]
    pub(crate) normals: Vec<Vec3>,
    /// The collision layers it meets (avian's `CollisionLayers` on the cloth entity).
    #[reflect(ignore)]
    pub(crate) layers: Layers,
    /// Which of the step's placed colliders each of the solver's colliders is.
    #[reflect(ignore)]
    pub(crate) colliders_from: Vec<u32>,
    /// Wall-clock time of the last fixed step, in ms.
    pub last_step_ms: f32,
    /// The positions when the last fixed step began, and whether that step moved the
    /// cloth: the mesh is then drawn between them and the positions now
    /// ([`ClothInterpolation`]).
    #[reflect(ignore)]
    pub(crate) previous: Vec<Vec3>,
    pub(crate) blending: bool,
}

impl ClothSimulation {
    pub(crate) fn new(solver: solver::ClothSolver, cloth: &Cloth) -> Self {
        let n = solver.particle_count();
        Self {
            solver,
            built_from: (cloth.shape.clone(), cloth.pins.clone()),
            mesh_dirty: true,
            normals: vec![Vec3::ZERO; n],
            layers: Layers::DEFAULT,
            colliders_from: Vec::new(),
            last_step_ms: 0.0,
            previous: Vec::new(),
            blending: false,
        }
    }

    /// Puts the cloth back at rest in its initial layout, with every spring whole.
    pub fn reset(&mut self) {
        self.solver.reset();
        self.mesh_dirty = true;
        self.blending = false;
    }

    /// Notes where the cloth is as a fixed step begins, for drawing between that step's
    /// start and end (`blend`: it steps, and meshes are drawn between steps).
    pub(crate) fn note_step(&mut self, blend: bool) {
        // A cloth that stops blending is drawn once more, where it is.
        self.mesh_dirty |= self.blending && !blend;
        self.blending = blend;
        if blend {
            self.previous.clear();
            self.previous.extend_from_slice(self.solver.positions());
        }
    }
}

/// Whether cloth meshes are drawn between the last two fixed steps (as avian's
/// `TransformInterpolation` draws bodies): each frame the mesh shows the positions a
/// fraction `Time<Fixed>::overstep_fraction()` of the way from where the last step began
/// to where it ended, so a cloth and the bodies it hangs from are drawn at the same
/// instant. On by default when the cloths step in a fixed schedule (the default,
/// `FixedPostUpdate`); off when they step in another schedule, where `Time<Fixed>` says
/// nothing of their steps. Off, the mesh shows where the last step left the cloth.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq, Reflect)]
#[reflect(Resource, Debug, PartialEq)]
pub struct ClothInterpolation(pub bool);

impl Default for ClothInterpolation {
    fn default() -> Self {
        Self(true)
    }
}

/// Why a cloth is not simulated: the plugin puts this on a cloth whose description (or
/// an attachment) is invalid, or whose step went non-finite, logs it, and removes it
/// once the cause is fixed. (A refused collider gets
/// [`ClothColliderInvalid`](crate::ClothColliderInvalid) instead.)
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[reflect(Component, Debug, PartialEq)]
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

/// Stops simulating a cloth and says why: logs `error`, marks the entity
/// [`ClothInvalid`] and triggers [`ClothBecameInvalid`] on it.
pub(crate) fn pause_invalid(commands: &mut Commands, entity: Entity, error: ClothError) {
    commands.entity(entity).insert(ClothInvalid(error.clone()));
    commands.trigger(ClothBecameInvalid { entity, error });
}

/// Logs why a cloth is not simulated, naming it by its `Name` when it has one (an entity
/// id alone, `47v0`, says little to a person reading the log).
pub(crate) fn log_invalid(invalid: On<ClothBecameInvalid>, names: Query<&Name>) {
    let who = Named(invalid.entity, names.get(invalid.entity).ok());
    error!("cloth {who} is not simulated: {}", invalid.error);
}

/// An entity as a log line names it: its `Name` and id (`` `cape` (47v0) ``), or its id.
#[derive(Clone, Copy)]
pub(crate) struct Named<'a>(pub(crate) Entity, pub(crate) Option<&'a Name>);

impl std::fmt::Display for Named<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.1 {
            Some(name) => write!(f, "`{name}` ({})", self.0),
            None => write!(f, "{}", self.0),
        }
    }
}

/// Collision layers as bit masks (avian's `CollisionLayers`, which the `avian` feature
/// reads): a cloth meets a collider when each one's memberships meet the other's filters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Layers {
    pub(crate) memberships: u32,
    pub(crate) filters: u32,
}

impl Layers {
    /// Avian's default: the first layer, meeting every layer.
    pub(crate) const DEFAULT: Self = Self {
        memberships: 1,
        filters: u32::MAX,
    };

    pub(crate) fn meet(self, other: Self) -> bool {
        self.memberships & other.filters != 0 && other.memberships & self.filters != 0
    }
}
