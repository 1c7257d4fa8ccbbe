//! Plain-data model parameters shared by the solver, the ECS layer and scene files.
//!
//! Everything here is `Reflect` (so the inspector can edit it) and `serde` (so scene
//! files can hold it). Nothing here knows about the ECS.

use crate::limits::{
    MAX_DAMPING, MAX_LIMITER_SWEEPS, MAX_NODE_MASS, MAX_STIFFNESS, MAX_SUBSTEPS, MIN_NODE_MASS,
};
use bevy::reflect::Reflect;
use serde::{Deserialize, Serialize};

use crate::error::ClothError;
pub use crate::fabric::Fabric;

mod environment;
mod following;
mod models;
mod self_collision;
mod springs;
mod wind_zone;

pub use environment::{Air, AirUpdate, Environment, Wind, WindAt, WindField};
pub use following::{Inertia, Teleport, TeleportMode};
pub use models::{
    GoalUpdate, Model, ModelKind, PatchParams, PatchTargets, RotationMethod, ShapeMatchingParams,
    XpbdParams, XpbdSolve,
};
pub use self_collision::SelfCollision;
pub use springs::{SpringFamily, SpringParams};
pub use wind_zone::{Turbulence, WindZone, ZoneAt, ZoneShape};

/// Serde for `Vec3` as a `(x, y, z)` tuple, so scene files can hold vectors without
/// turning on serde for the whole of Bevy.
pub mod vec3_serde {
    use bevy::math::Vec3;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes `(x, y, z)`.
    pub fn serialize<S: Serializer>(v: &Vec3, s: S) -> Result<S::Ok, S::Error> {
        (v.x, v.y, v.z).serialize(s)
    }

    /// Reads `(x, y, z)`.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec3, D::Error> {
        let (x, y, z) = <(f32, f32, f32)>::deserialize(d)?;
        Ok(Vec3::new(x, y, z))
    }
}

/// Serde for `Quat` as an `(x, y, z, w)` tuple (normalised when read).
pub mod quat_serde {
    use bevy::math::Quat;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes `(x, y, z, w)`.
    pub fn serialize<S: Serializer>(q: &Quat, s: S) -> Result<S::Ok, S::Error> {
        (q.x, q.y, q.z, q.w).serialize(s)
    }

    /// Reads `(x, y, z, w)`; a quaternion of no length is refused.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Quat, D::Error> {
        let (x, y, z, w) = <(f32, f32, f32, f32)>::deserialize(d)?;
        let q = Quat::from_xyzw(x, y, z, w);
        let length = q.length();
        if length > 0.0 && length.is_finite() {
            Ok(q / length)
        } else {
            Err(serde::de::Error::custom(
                "a rotation (x, y, z, w) of no length",
            ))
        }
    }
}

/// How positions advance in time.
///
/// For a fixed step `h` the two are the same recurrence in exact arithmetic:
/// `x_{n+1} − x_n = x_n − x_{n−1} + a h²` is `v_{n+1} = v_n + a h, x_{n+1} = x_n + v_{n+1} h`
/// with `v_n = (x_n − x_{n−1})/h`. They differ in rounding (Verlet recovers velocity as a
/// difference of positions, which loses digits in `f32` at tiny `h`) and in how a change of
/// `h` is handled (Verlet must rescale its implicit velocity; see `Cloth::begin_step`).
/// Verlet carries what rounding drops from each displacement (compensated summation),
/// so tiny steps still move a cloth; its velocity is still a difference of positions, so
/// at thousands of substeps per step the strain limiter's rounding heats it slightly
/// where Euler's velocity stays exact (`cloth accuracy` uses Euler for its reference).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Reflect, Serialize, Deserialize)]
pub enum Integrator {
    /// Position Verlet, Maslova eq. 1.12: `x' = 2x − x_prev + a h²`.
    #[default]
    Verlet,
    /// Semi-implicit (symplectic) Euler, Sladović 2014 eq. 21–22: `v' = v + a h`, `x' = x + v' h`.
    SemiImplicitEuler,
}

impl Integrator {
    /// Every integrator.
    pub const ALL: [Integrator; 2] = [Integrator::Verlet, Integrator::SemiImplicitEuler];
}

/// How many substeps one fixed step is split into.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Reflect, Serialize, Deserialize)]
pub enum Substeps {
    /// Exactly this many substeps (at least 1).
    Fixed(u32),
    /// As many as the explicit stability bound asks for (see `Cloth::stable_substeps`),
    /// at least 1 and at most `max`.
    Auto {
        /// Upper limit; a cloth that would need more is reported as under-resolved.
        max: u32,
    },
}

impl Default for Substeps {
    fn default() -> Self {
        Substeps::Auto { max: 8192 }
    }
}

/// Parameters of the model of one cloth. Edits take effect on the next step.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ClothParams {
    /// The cloth model; spring parameters are used by the mass-spring and XPBD models.
    pub model: Model,
    /// Mass of one particle in kg (Maslova §1.4: 0.001–1 g, i.e. 1e-6–1e-3 kg).
    pub node_mass: f32,
    /// Spring families and spring damping.
    pub springs: SpringParams,
    /// Linear air drag per particle in N·s/m: `F = −c v` (Sladović 2014 eq. 31, Maslova eq. 1.5).
    pub drag: f32,
    /// The time integrator.
    pub integrator: Integrator,
    /// Substeps per fixed step.
    pub substeps: Substeps,
    /// Provot (1995) strain limit: springs longer than `(1 + limit)·rest` are shortened
    /// after each substep. `None` switches it off.
    pub strain_limit: Option<f32>,
    /// Gauss–Seidel sweeps of the strain limiter per substep (with a tolerance: at most
    /// this many).
    pub strain_limit_iterations: u32,
    /// Run the limiter to convergence instead of a fixed number of sweeps: sweeps stop
    /// once a sweep finds no spring longer than `(1 + limit + tolerance)·l0`. `None`:
    /// exactly `strain_limit_iterations` sweeps (a game's fixed cost).
    pub strain_limit_tolerance: Option<f32>,
    /// A spring longer than `tear_ratio · rest_length` breaks (Sladović 2014 §3.2). `None`: never.
    pub tear_ratio: Option<f32>,
    /// Particles of the cloth kept apart from one another, so folds do not pass through
    /// themselves (XPBD and mass-spring). Off by default.
    pub self_collision: SelfCollision,
    /// A fabric in physical units (XPBD and mass-spring, cloths with triangles): when set,
    /// it replaces `node_mass` (each particle weighs the fabric's areal density times its
    /// share of the triangles' area), the structural and shear stiffnesses (from its
    /// tensile and shear stiffness, [`Fabric::grid_springs`]) and the bend springs (the
    /// quadratic bending model takes its rigidity instead). `None`: the seeds' per-spring
    /// parameters. In scene files a preset by name: `fabric: Some("denim")`.
    pub fabric: Option<Fabric>,
    /// A cloth with a `fabric` meets still air ([`Air::default`](crate::params::Air):
    /// each triangle dragged by its area) when the environment has no air of its own
    /// (`Environment::air` is `None`). `false` leaves it in a vacuum, with only `drag`.
    /// A real fabric in a vacuum swings and streams like a sheet of metal: a running cape
    /// trails 9 cm behind the shoulders in a vacuum and 0.76 m in still air.
    pub still_air: bool,
    /// The fastest a collider pushes out a particle that is inside it at the start of a
    /// substep, m/s (a cloth spawned, teleported or reset into a body, or a collider
    /// that appeared under it): it is moved out over as many steps as that takes, with no
    /// velocity left behind. Contact met from outside is not limited. PhysX's and
    /// avian's `max_depenetration_velocity` sense; `f32::INFINITY` moves it out at once.
    pub max_depenetration_speed: f32,
    /// What the cloth does when the bodies holding it jump or turn farther in a step than
    /// any run does ([`Teleport`]): by default its shape and motion are carried with
    /// them.
    pub teleport: Teleport,
    /// How much of its drivers' motion the cloth feels ([`Inertia`]): by default all of
    /// it, as in world space.
    pub inertia: Inertia,
}

impl Default for ClothParams {
    /// What a game's cloth should start from: XPBD with its stretch solved along the
    /// grid's lines ([`XpbdParams::default`]), in twill (65% cotton, 35% polyester,
    /// [`Fabric::TWILL`]) meeting still air. On the 64 × 64 cloth swinging down from level
    /// (`cargo run -p bevy_cloth_lab --example default_cost`) it stretches 0.8% at about
    /// five times the cost of [`ClothParams::seeds`]' mass-spring, which stretches 13%.
    /// A fabric needs triangles: a rope or chain built from springs alone takes
    /// `fabric: None`.
    fn default() -> Self {
        Self {
            model: Model::Xpbd(XpbdParams::default()),
            fabric: Some(Fabric::TWILL),
            ..Self::seeds()
        }
    }
}

impl ClothParams {
    /// The source works' model: mass-spring on the seeds' per-spring stiffnesses
    /// (Maslova's structural, shear and bend springs, 0.5 g particles), Verlet, Provot's
    /// 10% strain limit, no fabric. The seed scenes name it, so their tables stay
    /// reproducible; a game's cloth reads as rubber on it (13% on the swinging cloth).
    pub fn seeds() -> Self {
        Self {
            model: Model::MassSpring,
            node_mass: 0.5e-3,
            springs: SpringParams::default(),
            drag: 0.5e-3,
            integrator: Integrator::Verlet,
            substeps: Substeps::default(),
            strain_limit: Some(0.1),
            strain_limit_iterations: 4,
            strain_limit_tolerance: None,
            tear_ratio: None,
            self_collision: SelfCollision::default(),
            fabric: None,
            still_air: true,
            max_depenetration_speed: 1.0,
            teleport: Teleport::default(),
            inertia: Inertia::default(),
        }
    }
}

/// `Ok` when `ok` holds and `value` is finite; otherwise the error naming `field`.
pub(crate) fn check(
    field: &'static str,
    value: f32,
    ok: bool,
    expected: impl Into<std::borrow::Cow<'static, str>>,
) -> Result<(), ClothError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(ClothError::InvalidParameter {
            field,
            value,
            expected: expected.into(),
        })
    }
}

impl ClothParams {
    /// The spring families that act: [`ClothParams::springs`], or with a fabric its
    /// structural and shear stiffnesses and no bend springs (its bending is the quadratic
    /// bending model's).
    pub fn springs_in_use(&self) -> SpringParams {
        let Some(fabric) = &self.fabric else {
            return self.springs;
        };
        let (structural, shear) = fabric.grid_springs();
        SpringParams {
            structural: SpringFamily::new(structural),
            shear: SpringFamily::new(shear),
            bend: SpringFamily::off(self.springs.bend.stiffness),
            bend_diagonal: SpringFamily::off(self.springs.bend_diagonal.stiffness),
            ..self.springs
        }
    }

    /// Checks every value; the error names the field.
    pub fn validate(&self) -> Result<(), ClothError> {
        check(
            "node_mass",
            self.node_mass,
            (MIN_NODE_MASS..=MAX_NODE_MASS).contains(&self.node_mass),
            format!(
                "a mass from {MIN_NODE_MASS:e} to {MAX_NODE_MASS} kg (limits::MIN_NODE_MASS, MAX_NODE_MASS)"
            ),
        )?;
        self.validate_springs()?;
        check(
            "drag",
            self.drag,
            (0.0..=MAX_DAMPING).contains(&self.drag),
            format!("a drag from 0 to {MAX_DAMPING:e} N·s/m (limits::MAX_DAMPING)"),
        )?;
        let cap = self.max_depenetration_speed;
        check(
            "max_depenetration_speed",
            cap.min(crate::limits::MAX_POSITION),
            cap > 0.0,
            "a speed > 0 m/s (`inf`: no cap)",
        )?;
        self.teleport.validate()?;
        self.inertia.validate()?;
        self.validate_stepping()?;
        if let Some(ratio) = self.tear_ratio {
            check("tear_ratio", ratio, ratio > 1.0, "a tear ratio > 1")?;
        }
        self.validate_self_collision()?;
        if let Some(fabric) = &self.fabric {
            fabric.validate()?;
            if !matches!(self.model, Model::MassSpring | Model::Xpbd(_)) {
                return Err(ClothError::ModelLacks {
                    model: self.model.kind().name(),
                    feature: "fabric in physical units (`fabric`)",
                });
            }
        }
        if !self.inertia.is_world() && matches!(self.model, Model::Patches(_)) {
            // Its part lattice is a cloth of its own, which the blend does not reach.
            return Err(ClothError::ModelLacks {
                model: self.model.kind().name(),
                feature: "inertia other than world space (`inertia`)",
            });
        }
        match &self.model {
            Model::ShapeMatching(sm) => sm.validate()?,
            Model::Patches(patches) => patches.validate()?,
            Model::Xpbd(xpbd) => xpbd.validate()?,
            Model::MassSpring => {}
        }
        Ok(())
    }

    /// The spring families' stiffnesses, the damping, the seams' rest length and sewing
    /// time.
    fn validate_springs(&self) -> Result<(), ClothError> {
        let s = &self.springs;
        // XPBD takes an infinite stiffness as an inextensible constraint (compliance 0);
        // the explicit models need a finite one.
        let rigid_ok = matches!(self.model, Model::Xpbd(_));
        for (field, family) in [
            ("springs.structural.stiffness", s.structural),
            ("springs.shear.stiffness", s.shear),
            ("springs.bend.stiffness", s.bend),
            ("springs.bend_diagonal.stiffness", s.bend_diagonal),
            ("springs.seam.stiffness", s.seam),
        ] {
            if rigid_ok && family.stiffness == f32::INFINITY {
                continue;
            }
            check(
                field,
                family.stiffness,
                (0.0..=MAX_STIFFNESS).contains(&family.stiffness),
                format!(
                    "a stiffness from 0 to {MAX_STIFFNESS:e} N/m (limits::MAX_STIFFNESS; inf only for XPBD)"
                ),
            )?;
        }
        check(
            "springs.damping",
            s.damping,
            (0.0..=MAX_DAMPING).contains(&s.damping),
            format!("a damping from 0 to {MAX_DAMPING:e} N·s/m (limits::MAX_DAMPING)"),
        )?;
        check(
            "springs.seam_rest_length",
            s.seam_rest_length,
            s.seam_rest_length >= 0.0,
            "a length ≥ 0 m",
        )?;
        check(
            "springs.sew_time",
            s.sew_time,
            s.sew_time >= 0.0,
            "a time ≥ 0 s",
        )
    }

    /// The substeps and the strain limiter: counts within their limits, a limit and a
    /// tolerance above zero.
    fn validate_stepping(&self) -> Result<(), ClothError> {
        match self.substeps {
            Substeps::Fixed(0) => {
                return Err(ClothError::InvalidParameter {
                    field: "substeps",
                    value: 0.0,
                    expected: "at least 1 substep".into(),
                });
            }
            Substeps::Auto { max: 0 } => {
                return Err(ClothError::InvalidParameter {
                    field: "substeps.max",
                    value: 0.0,
                    expected: "at least 1 substep".into(),
                });
            }
            Substeps::Fixed(n) if n > MAX_SUBSTEPS => {
                return Err(ClothError::InvalidParameter {
                    field: "substeps",
                    value: n as f32,
                    expected: "at most 65,536 substeps (limits::MAX_SUBSTEPS)".into(),
                });
            }
            Substeps::Auto { max } if max > MAX_SUBSTEPS => {
                return Err(ClothError::InvalidParameter {
                    field: "substeps.max",
                    value: max as f32,
                    expected: "at most 65,536 substeps (limits::MAX_SUBSTEPS)".into(),
                });
            }
            _ => {}
        }
        if self.strain_limit_iterations > MAX_LIMITER_SWEEPS {
            return Err(ClothError::InvalidParameter {
                field: "strain_limit_iterations",
                value: self.strain_limit_iterations as f32,
                expected: "at most 1,024 sweeps (limits::MAX_LIMITER_SWEEPS)".into(),
            });
        }
        if let Some(limit) = self.strain_limit {
            check("strain_limit", limit, limit > 0.0, "a strain limit > 0")?;
        }
        if let Some(tolerance) = self.strain_limit_tolerance {
            check(
                "strain_limit_tolerance",
                tolerance,
                tolerance > 0.0,
                "a tolerance > 0",
            )?;
        }
        Ok(())
    }

    /// Self-collision's distance and friction, and a model that has it: the patch model
    /// moves its particles with their parts, and shape matching toward goals that would
    /// pull folds back through each other.
    fn validate_self_collision(&self) -> Result<(), ClothError> {
        let sc = &self.self_collision;
        if let Some(d) = sc.distance {
            check(
                "self_collision.distance",
                d,
                (crate::limits::MIN_SELF_COLLISION_DISTANCE..=crate::limits::MAX_SPACING)
                    .contains(&d),
                "a distance from 0.1 mm to 10 m (limits::MIN_SELF_COLLISION_DISTANCE, \
                 limits::MAX_SPACING)",
            )?;
        }
        check(
            "self_collision.friction",
            sc.friction,
            (0.0..=10.0).contains(&sc.friction),
            "a friction coefficient from 0 to 10",
        )?;
        let model = self.model.kind();
        if sc.enabled && matches!(model, ModelKind::Patches | ModelKind::ShapeMatching) {
            return Err(ClothError::ModelLacks {
                model: model.name(),
                feature: "self-collision (`self_collision`)",
            });
        }
        Ok(())
    }
}

/// Refuses `params` on a cloth of `particles` when a step's fixed work is over
/// [`MAX_WORK_PER_STEP`](crate::limits::MAX_WORK_PER_STEP) (particles × fixed substeps) or
/// [`MAX_SWEEP_WORK_PER_STEP`](crate::limits::MAX_SWEEP_WORK_PER_STEP) (× fixed limiter
/// sweeps). Automatic substeps are capped at the budget instead (the step reports
/// `under_resolved`).
pub fn check_work(particles: usize, params: &ClothParams) -> Result<(), ClothError> {
    let n = particles as u64;
    let Substeps::Fixed(substeps) = params.substeps else {
        return Ok(());
    };
    let work = n.saturating_mul(substeps as u64);
    if work > crate::limits::MAX_WORK_PER_STEP {
        return Err(ClothError::TooMuchWork {
            field: "substeps",
            particles,
            per_particle: substeps as u64,
            limit: crate::limits::MAX_WORK_PER_STEP,
        });
    }
    let fixed_sweeps = params.strain_limit.is_some()
        && params.strain_limit_tolerance.is_none()
        && !matches!(params.model, Model::Xpbd(_));
    if fixed_sweeps {
        let per_particle = (substeps as u64).saturating_mul(params.strain_limit_iterations as u64);
        if n.saturating_mul(per_particle) > crate::limits::MAX_SWEEP_WORK_PER_STEP {
            return Err(ClothError::TooMuchWork {
                field: "strain_limit_iterations",
                particles,
                per_particle,
                limit: crate::limits::MAX_SWEEP_WORK_PER_STEP,
            });
        }
    }
    Ok(())
}
