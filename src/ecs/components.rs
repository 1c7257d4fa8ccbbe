//! The components and resources a Bevy user touches.

use bevy::ecs::message::Message;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::ClothError;
use crate::layout::garment::{GarmentLayout, asset_path};
use crate::layout::shape::{ClothShape, Pins};
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
/// let cloth = Cloth::grid(24, 16, 0.05).with_pins(Pins::TopRow);
/// assert!(cloth.validate().is_ok());
/// ```
#[derive(Component, Clone, Debug, Default, PartialEq, Reflect, Serialize, Deserialize)]
#[reflect(Component, Default)]
#[require(Transform, Visibility, ClothSleep)]
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
        self.params.validate()?;
        // A grid's work per step is known from its size (the others' when built).
        if let ClothShape::Grid { width, height, .. } = self.shape {
            crate::limits::check_work(width as usize * height as usize, &self.params)?;
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
            pins: Pins::None,
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

/// A solid the cloths are kept out of, placed by its entity's transform: spheres,
/// capsules and planes with a thickness and friction. Every cloth collides with every
/// collider, every substep.
///
/// ```
/// use bevy::prelude::*;
/// use bevy_cloth::prelude::*;
/// # let mut world = World::new();
/// world.spawn((ClothCollider::sphere(0.3), Transform::from_xyz(0.0, 1.0, 0.0)));
/// world.spawn(ClothCollider::plane().with_friction(0.8)); // the ground, y = 0
/// ```
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[reflect(Component, Default)]
#[require(Transform)]
#[serde(default, deny_unknown_fields)]
pub struct ClothCollider {
    /// The solid, in the entity's local frame.
    pub shape: ColliderKind,
    /// How far outside the surface particles stay, m.
    pub thickness: f32,
    /// Coulomb friction coefficient (0 = ice; a particle sticks on a slope while
    /// tan θ ≤ friction).
    pub friction: f32,
}

/// The solid of a [`ClothCollider`], in its entity's local frame (the same conventions as
/// Bevy's `Sphere`, `Capsule3d` and `Plane3d` meshes).
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
pub enum ColliderKind {
    /// A ball about the origin.
    Sphere {
        /// Radius, m.
        radius: f32,
    },
    /// A capsule along local y: all points within `radius` of the segment from
    /// `(0, −half_length, 0)` to `(0, half_length, 0)`.
    Capsule {
        /// Radius, m.
        radius: f32,
        /// Half the length of the axis segment (without the caps), m.
        half_length: f32,
    },
    /// A box about the origin, `half_extents` along local x, y and z (scaled per axis by
    /// the transform).
    Cuboid {
        /// Half its size along local x, y, z, m.
        #[serde(with = "crate::params::vec3_serde")]
        half_extents: Vec3,
    },
    /// A cylinder along local y about the origin, `radius` from its axis and
    /// `half_height` up and down it (Bevy's `Cylinder`).
    Cylinder {
        /// Radius, m.
        radius: f32,
        /// Half its height, m.
        half_height: f32,
    },
    /// The half-space below the local xz plane (normal +y): a ground or a wall.
    Plane,
}

impl Default for ClothCollider {
    fn default() -> Self {
        Self::plane()
    }
}

impl From<Sphere> for ClothCollider {
    fn from(s: Sphere) -> Self {
        Self::sphere(s.radius)
    }
}

impl From<Capsule3d> for ClothCollider {
    fn from(c: Capsule3d) -> Self {
        Self::capsule(c.radius, 2.0 * c.half_length)
    }
}

impl From<Cuboid> for ClothCollider {
    fn from(c: Cuboid) -> Self {
        Self::new(ColliderKind::Cuboid {
            half_extents: c.half_size,
        })
    }
}

impl From<Cylinder> for ClothCollider {
    fn from(c: Cylinder) -> Self {
        Self::new(ColliderKind::Cylinder {
            radius: c.radius,
            half_height: c.half_height,
        })
    }
}

impl ClothCollider {
    /// The thickness a collider has unless set, m (also avian colliders').
    pub const THICKNESS: f32 = 0.005;
    /// The friction coefficient a collider has unless set (also avian colliders' without
    /// a `Friction`).
    pub const FRICTION: f32 = 0.3;

    fn new(shape: ColliderKind) -> Self {
        Self {
            shape,
            thickness: Self::THICKNESS,
            friction: Self::FRICTION,
        }
    }

    /// A sphere of `radius` m.
    pub fn sphere(radius: f32) -> Self {
        Self::new(ColliderKind::Sphere { radius })
    }

    /// A capsule along local y of `radius` m whose axis segment (without the caps) is
    /// `length` m long: the sizes Bevy's `Capsule3d::new(radius, length)` and avian's
    /// `Collider::capsule` take.
    pub fn capsule(radius: f32, length: f32) -> Self {
        Self::new(ColliderKind::Capsule {
            radius,
            half_length: length / 2.0,
        })
    }

    /// A box `x_length × y_length × z_length` m about the origin: the sizes Bevy's
    /// `Cuboid::new` and avian's `Collider::cuboid` take.
    pub fn cuboid(x_length: f32, y_length: f32, z_length: f32) -> Self {
        let half_extents = Vec3::new(x_length, y_length, z_length) / 2.0;
        Self::new(ColliderKind::Cuboid { half_extents })
    }

    /// A cylinder along local y of `radius` m and `height` m: the sizes Bevy's
    /// `Cylinder::new` and avian's `Collider::cylinder` take.
    pub fn cylinder(radius: f32, height: f32) -> Self {
        Self::new(ColliderKind::Cylinder {
            radius,
            half_height: height / 2.0,
        })
    }

    /// A plane through the origin with normal +y.
    pub fn plane() -> Self {
        Self::new(ColliderKind::Plane)
    }

    /// Replaces the thickness (m).
    pub fn with_thickness(mut self, thickness: f32) -> Self {
        self.thickness = thickness;
        self
    }

    /// Replaces the friction coefficient.
    pub fn with_friction(mut self, friction: f32) -> Self {
        self.friction = friction;
        self
    }

    /// Checks sizes: radius > 0, half-length, thickness and friction ≥ 0, each within
    /// [`crate::limits::MAX_POSITION`].
    pub fn validate(&self) -> Result<(), ClothError> {
        use crate::params::check;
        const MAX: f32 = crate::limits::MAX_POSITION;
        let size = |field, value: f32, least_excluded: bool, expected| {
            let low = if least_excluded {
                value > 0.0
            } else {
                value >= 0.0
            };
            check(field, value, low && value <= MAX, expected)
        };
        let radius = |r: f32| size("radius", r, true, "a radius from 0 (excluded) to 1e5 m");
        match self.shape {
            ColliderKind::Sphere { radius: r } => radius(r)?,
            ColliderKind::Capsule {
                radius: r,
                half_length,
            } => {
                radius(r)?;
                size(
                    "half_length",
                    half_length,
                    false,
                    "a half-length from 0 to 1e5 m",
                )?;
            }
            ColliderKind::Cuboid { half_extents: h } => {
                for (field, value) in [
                    ("half_extents.x", h.x),
                    ("half_extents.y", h.y),
                    ("half_extents.z", h.z),
                ] {
                    size(
                        field,
                        value,
                        true,
                        "a half-extent from 0 (excluded) to 1e5 m",
                    )?;
                }
            }
            ColliderKind::Cylinder {
                radius: r,
                half_height,
            } => {
                radius(r)?;
                size(
                    "half_height",
                    half_height,
                    true,
                    "a half-height from 0 (excluded) to 1e5 m",
                )?;
            }
            ColliderKind::Plane => {}
        }
        size(
            "thickness",
            self.thickness,
            false,
            "a thickness from 0 to 1e5 m",
        )?;
        size(
            "friction",
            self.friction,
            false,
            "a friction coefficient from 0 to 1e5",
        )
    }

    /// The collider in world space under `transform` (radii scale with the largest scale
    /// factor). Negative sizes count as 0.
    pub fn to_world(&self, transform: &GlobalTransform) -> solver::Collider {
        use solver::ColliderShape;
        let scale = transform.scale().abs().max_element();
        let shape = match self.shape {
            ColliderKind::Sphere { radius } => ColliderShape::Sphere {
                center: transform.translation(),
                radius: radius.max(0.0) * scale,
            },
            ColliderKind::Capsule {
                radius,
                half_length,
            } => ColliderShape::Capsule {
                a: transform.transform_point(Vec3::new(0.0, -half_length.max(0.0), 0.0)),
                b: transform.transform_point(Vec3::new(0.0, half_length.max(0.0), 0.0)),
                radius: radius.max(0.0) * scale,
            },
            ColliderKind::Cuboid { half_extents } => ColliderShape::cuboid(
                transform.translation(),
                transform.rotation(),
                half_extents.max(Vec3::ZERO) * transform.scale().abs(),
            ),
            ColliderKind::Cylinder {
                radius,
                half_height,
            } => {
                // Its height scales with y, its radius with the larger of x and z.
                let s = transform.scale().abs();
                ColliderShape::Cylinder {
                    center: transform.translation(),
                    axis: transform.rotation() * Vec3::Y,
                    half_height: half_height.max(0.0) * s.y,
                    radius: radius.max(0.0) * s.x.max(s.z),
                }
            }
            ColliderKind::Plane => ColliderShape::Plane {
                point: transform.translation(),
                normal: transform.rotation() * Vec3::Y,
            },
        };
        solver::Collider {
            shape,
            thickness: self.thickness.max(0.0),
            friction: self.friction.max(0.0),
            motion: solver::Motion::NONE,
        }
    }
}

/// The running simulation of a [`Cloth`], added by the plugin. Read it for positions,
/// energies and statistics; mutate it for tools such as grabbing or cutting.
#[derive(Component, Debug)]
pub struct ClothSimulation {
    /// The solver state.
    pub solver: solver::ClothSolver,
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
    pub(crate) fn new(solver: solver::ClothSolver, cloth: &Cloth) -> Self {
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
    /// True when the cloth fell asleep at its last step (see [`ClothSleep`], which says
    /// whether it sleeps now): the other values are those of that step.
    pub asleep: bool,
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
    pub fn record(&mut self, cloth: &solver::ClothSolver, env: &Environment, step_ms: f32) {
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
        self.step_ms_median = crate::stats::median(&mut self.scratch);
    }
}

/// Sleeping (issue 16): a cloth whose every free particle moves slower than `speed` for
/// `after` seconds falls asleep: its step is skipped and its mesh not rewritten. It wakes
/// within one step on anything that can move it: an edit of its parameters, a change of
/// gravity or wind (`ClothEnvironment`), its transform moving (the pins), a collider
/// changing within reach of it, a grab, drag, release, cut or reset (anything that calls
/// the solver's mutating tools), or a [`ClothWake`] message from the game. Required by
/// [`Cloth`]; `enabled: false` keeps a cloth always awake.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component, Default)]
pub struct ClothSleep {
    /// Whether this cloth may fall asleep.
    pub enabled: bool,
    /// The speed below which a particle counts as still, m/s.
    pub speed: f32,
    /// How long every particle must stay still before the cloth sleeps, s.
    pub after: f32,
    /// Whether it sleeps now (set by the plugin).
    pub asleep: bool,
    /// Simulated seconds it has been still (set by the plugin).
    pub still_for: f32,
}

impl Default for ClothSleep {
    /// 1 mm/s for 1 s.
    fn default() -> Self {
        Self {
            enabled: true,
            speed: 1e-3,
            after: 1.0,
            asleep: false,
            still_for: 0.0,
        }
    }
}

impl ClothSleep {
    /// A cloth that never sleeps.
    pub fn never() -> Self {
        Self {
            enabled: false,
            ..Self::default()
        }
    }

    /// Wakes it (and restarts the stillness count).
    pub fn wake(&mut self) {
        self.asleep = false;
        self.still_for = 0.0;
    }

    /// Counts a step of `dt` in which the fastest particle moved at `speed`; falls asleep
    /// once still for long enough. Returns whether it is asleep.
    pub fn observe(&mut self, speed: f32, dt: f32) -> bool {
        // A NaN speed counts as moving.
        let still = speed < self.speed;
        if !self.enabled || !still {
            self.wake();
            return false;
        }
        self.still_for += dt;
        self.asleep = self.still_for >= self.after;
        self.asleep
    }
}

/// Level of detail (issue 16): the cloth's model follows its size on screen. At level 0
/// the cloth runs its own model; below each threshold it switches to the patch model with
/// parts of 2×2, 4×4 and 8×8 particles (seed 000 §3.4: cheaper the larger the parts),
/// which adopts the running state (no jump), and back as the cloth grows on screen. The
/// size is the cloth's bounding sphere projected by the active camera, as a fraction of
/// the view's height. Grid cloths only (the patch model needs a grid): on others it
/// stays at level 0. While not at level 0 the component owns `Cloth::params.model`
/// (the cloth's own model is kept and put back).
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[reflect(Component, Default)]
pub struct ClothLod {
    /// The fractions of the view's height below which the cloth goes to parts of 2×2,
    /// 4×4 and 8×8 (decreasing).
    pub thresholds: [f32; 3],
    /// A band of this fraction around each threshold: the cloth goes coarser below
    /// `t (1 − band)` and finer above `t (1 + band)`, so it does not flicker at one.
    pub band: f32,
    /// The current level, 0–3 (set by the plugin).
    pub level: usize,
    /// The size on screen last measured (set by the plugin).
    pub screen_fraction: f32,
    /// The cloth's own model, kept while the level is not 0.
    pub(crate) full: Option<crate::params::Model>,
}

impl Default for ClothLod {
    fn default() -> Self {
        Self {
            thresholds: [0.5, 0.25, 0.12],
            band: 0.1,
            level: 0,
            screen_fraction: 1.0,
            full: None,
        }
    }
}

impl ClothLod {
    /// The patch size of each level above 0.
    pub const PART_SIZES: [u32; 3] = [2, 4, 8];

    /// What level `level` runs, in words: `its own model` or `patches 2×2` (…).
    pub fn describe(level: usize) -> String {
        match level.checked_sub(1).and_then(|l| Self::PART_SIZES.get(l)) {
            Some(s) => format!("patches {s}×{s}"),
            None => "its own model".into(),
        }
    }

    /// The level a cloth at `fraction` of the view's height goes to from `level`: one
    /// level at a time, coarser below a threshold less the band, finer above one plus it.
    pub fn next_level(&self, level: usize, fraction: f32) -> usize {
        if level < 3 && fraction < self.thresholds[level] * (1.0 - self.band) {
            level + 1
        } else if level > 0 && fraction > self.thresholds[level - 1] * (1.0 + self.band) {
            level - 1
        } else {
            level
        }
    }
}

/// Attaches particles of this cloth to other entities (a cape to a character's
/// shoulders, a flag to a mast): each attached particle follows its entity's global
/// transform every step, interpolated over the substeps as pins are, at the point it had
/// in that entity's frame when first attached (or at a point given, [`ClothAttachment::at`]).
#[derive(Component, Clone, Debug, Default)]
pub struct ClothAttachments(pub Vec<ClothAttachment>);

/// One entity and the particles held to it (see [`ClothAttachments`]).
#[derive(Clone, Debug)]
pub struct ClothAttachment {
    /// The entity followed.
    pub target: Entity,
    /// Which particles.
    pub particles: AttachParticles,
    /// Each particle and its point in the target's frame, chosen when first attached
    /// (`None` until then, and again after the cloth is rebuilt).
    pub(crate) held: Option<Vec<(u32, Vec3)>>,
}

/// Which particles an attachment holds.
#[derive(Clone, Debug, PartialEq)]
pub enum AttachParticles {
    /// By index (`j·width + i` for a grid); indices past the cloth are skipped.
    Indices(Vec<u32>),
    /// The `count` particles nearest `point`, a point in the target's frame (a shoulder).
    Nearest {
        /// The point, in the target entity's frame.
        point: Vec3,
        /// How many particles.
        count: u32,
    },
    /// A garment's named run of nodes (its file's `runs`, e.g. a collar).
    Run(String),
    /// Particles at given points of the target's frame (local offsets): each is pulled
    /// there from wherever it is.
    At(Vec<(u32, Vec3)>),
}

impl ClothAttachment {
    /// The garment run `name` (its file's `runs`) held to `target`; a cloth without such a
    /// run logs an error and attaches nothing.
    pub fn run(target: Entity, name: impl Into<String>) -> Self {
        Self {
            target,
            particles: AttachParticles::Run(name.into()),
            held: None,
        }
    }

    /// Each particle held to `target` at its point in `target`'s frame (a local offset),
    /// wherever the particle starts; indices past the cloth are skipped.
    pub fn at(target: Entity, points: Vec<(u32, Vec3)>) -> Self {
        Self {
            target,
            particles: AttachParticles::At(points),
            held: None,
        }
    }

    /// Particles `indices` held to `target`.
    pub fn indices(target: Entity, indices: Vec<u32>) -> Self {
        Self {
            target,
            particles: AttachParticles::Indices(indices),
            held: None,
        }
    }

    /// The `count` particles nearest `point` (in `target`'s frame) held to `target`.
    pub fn nearest(target: Entity, point: Vec3, count: u32) -> Self {
        Self {
            target,
            particles: AttachParticles::Nearest { point, count },
            held: None,
        }
    }

    /// The particles held and their points in the target's frame (empty until the first
    /// step after the cloth is built).
    pub fn held(&self) -> &[(u32, Vec3)] {
        self.held.as_deref().unwrap_or(&[])
    }
}

/// Wakes a sleeping cloth (see [`ClothSleep`]): the game's own reason to move it.
#[derive(Message, Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClothWake(pub Entity);

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
