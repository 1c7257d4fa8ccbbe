//! Plain-data model parameters shared by the solver, the ECS layer and scene files.
//!
//! Everything here is `Reflect` (so the inspector can edit it) and `serde` (so scene
//! files can hold it). Nothing here knows about the ECS.

use crate::limits::{
    MAX_DAMPING, MAX_LIMITER_SWEEPS, MAX_NODE_MASS, MAX_STIFFNESS, MAX_SUBSTEPS, MIN_NODE_MASS,
};
use bevy::math::Vec3;
use bevy::reflect::Reflect;
use serde::{Deserialize, Serialize};

use crate::error::ClothError;
pub use crate::fabric::Fabric;

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

/// One family of springs (Sladović 2014 §2.2, fig. 1): whether it exists and how stiff it is.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SpringFamily {
    /// Switch the whole family off (Sladović 2014 §4, figs. 18–20 show cloth without each family).
    pub enabled: bool,
    /// Hooke constant `k` in N/m (Maslova eq. 1.4).
    pub stiffness: f32,
}

impl Default for SpringFamily {
    fn default() -> Self {
        Self {
            enabled: true,
            stiffness: 100.0,
        }
    }
}

impl SpringFamily {
    /// An enabled family with the given stiffness.
    pub fn new(stiffness: f32) -> Self {
        Self {
            enabled: true,
            stiffness,
        }
    }

    /// A switched-off family (keeps its stiffness so switching it back on restores it).
    pub fn off(stiffness: f32) -> Self {
        Self {
            enabled: false,
            stiffness,
        }
    }

    /// The stiffness that acts: 0 when switched off.
    pub fn effective(&self) -> f32 {
        if self.enabled { self.stiffness } else { 0.0 }
    }
}

/// The four spring families of a grid cloth and the damping along springs.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SpringParams {
    /// Horizontal and vertical neighbours (i±1, j±1), rest length = spacing.
    pub structural: SpringFamily,
    /// Diagonal neighbours, rest length = √2·spacing.
    pub shear: SpringFamily,
    /// Every second particle (i±2, j±2), rest length = 2·spacing.
    pub bend: SpringFamily,
    /// Every second particle diagonally, rest length = 2√2·spacing (Sladović 2014 §2.2, optional).
    pub bend_diagonal: SpringFamily,
    /// Damping along each spring in N·s/m: `F = c ((v_b − v_a)·d̂) d̂`.
    pub damping: f32,
    /// Seam springs joining garment pieces (Maslova §1.4).
    pub seam: SpringFamily,
    /// The length a seam spring is sewn to, m (0: the two edges meet).
    pub seam_rest_length: f32,
    /// Seconds over which seams are sewn: a seam spring's rest length shrinks linearly
    /// from the gap it starts with to `seam_rest_length`, as a tailor pulls the edges
    /// together (0 sews at once). Meanwhile the garment is held: gravity and wind act on
    /// it from the end of sewing.
    pub sew_time: f32,
}

impl Default for SpringParams {
    /// Sladović 2014 §4's structural:shear:bend ratio of 2:1:1, at a stiffness soft enough that
    /// a 0.5 g-per-node cloth drapes and folds under its own weight; the strain limiter
    /// (Provot 1995) keeps the stretch below 10%. Stiffer springs make a board-like sheet
    /// that will not buckle, and cost more substeps.
    fn default() -> Self {
        Self::from_structural(20.0)
    }
}

impl SpringParams {
    /// All families from one structural stiffness with the seed's 2:1:1 ratio.
    pub fn from_structural(stiffness: f32) -> Self {
        Self {
            structural: SpringFamily::new(stiffness),
            shear: SpringFamily::new(stiffness * 0.5),
            bend: SpringFamily::new(stiffness * 0.5),
            bend_diagonal: SpringFamily::off(stiffness * 0.25),
            damping: 0.0,
            seam: SpringFamily::new(stiffness),
            seam_rest_length: 0.0,
            sew_time: 1.0,
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

/// Sladović 2014 §4: exponents of the pull toward a goal stay within [0.5, 3].
fn check_exponent(exponent: f32) -> Result<(), ClothError> {
    check(
        "model.exponent",
        exponent,
        (0.5..=3.0).contains(&exponent),
        "an exponent in [0.5, 3] (Sladović 2014 §4)",
    )
}

/// How shape matching finds the rotation of a cluster.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Reflect, Serialize, Deserialize)]
pub enum RotationMethod {
    /// Sladović 2014 eq. 6–9: the rotation of each particle's rest offset onto its current
    /// offset as a quaternion, averaged component-wise and normalised once (the thesis's
    /// faster variant). Fast; an approximation that is exact for rotations about the
    /// cloth's normal and degrades for large rotations about in-plane axes (see the
    /// tests' report). The pseudocode's other variant, normalising the running sum after
    /// every particle, weighs the last particle ½, the one before ¼, …: its rotation
    /// depends on the particles' order, so it is not offered.
    QuaternionAverage,
    /// Sladović 2014 eq. 14–16: the rotation part of `A_pq = Σ m p qᵀ`, found by the iterative
    /// method of Müller et al. 2016 (robust for the rank-2 `A_pq` of a flat cloth and
    /// rank-1 of a strip; never a reflection; warm-started from the last step).
    #[default]
    PolarDecomposition,
}

/// How a particle is pulled toward its goal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Reflect, Serialize, Deserialize)]
pub enum GoalUpdate {
    /// A force `α (|d|/L)^(p−1) d` toward the goal (`d = g − x`, L = the cloth's
    /// spacing), as Sladović 2014 §4 describes: exponent p in [0.5, 3], stiffness α in N/m,
    /// integrated with the other forces.
    #[default]
    Force,
    /// Müller et al. 2005: after integration `x += α (g − x)`, velocity likewise; α in
    /// [0, 1] is the fraction of the way to the goal per substep. Cannot overshoot.
    Velocity,
}

/// Parameters of the meshless shape-matching model (Sladović 2014 §2.3, §3.3; Müller 2005).
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ShapeMatchingParams {
    /// How the rotation is found.
    pub rotation: RotationMethod,
    /// How particles move toward their goals.
    pub update: GoalUpdate,
    /// Stiffness α: N/m for `Force`, a fraction 0–1 per substep for `Velocity`.
    pub stiffness: f32,
    /// Exponent p of the force law (Sladović 2014 §4: 0.5–3); 1 is a linear spring.
    pub exponent: f32,
    /// Damping of each particle's velocity, N·s/m (Sladović 2014 §4's particle damping).
    pub damping: f32,
    /// Müller's β: goals from `β A + (1 − β) R`, letting the card shear and stretch a
    /// little (an extension beyond the thesis). 0 = rigid goals.
    pub beta: f32,
    /// k: the grid is covered by k×k overlapping clusters (the start of lattice shape
    /// matching). 1 = one cluster for the whole cloth, as in the thesis.
    pub clusters: u32,
}

impl Default for ShapeMatchingParams {
    fn default() -> Self {
        Self {
            rotation: RotationMethod::PolarDecomposition,
            update: GoalUpdate::Force,
            stiffness: 2.0,
            exponent: 1.0,
            damping: 2e-4,
            beta: 0.0,
            clusters: 1,
        }
    }
}

impl ShapeMatchingParams {
    fn validate(&self) -> Result<(), ClothError> {
        check(
            "model.stiffness",
            self.stiffness,
            (0.0..=MAX_STIFFNESS).contains(&self.stiffness),
            "a stiffness from 0 to 1e9 (limits::MAX_STIFFNESS)",
        )?;
        if self.update == GoalUpdate::Velocity {
            check(
                "model.stiffness",
                self.stiffness,
                self.stiffness <= 1.0,
                "a fraction 0–1 for the Velocity update",
            )?;
        }
        check_exponent(self.exponent)?;
        check(
            "model.damping",
            self.damping,
            (0.0..=MAX_DAMPING).contains(&self.damping),
            "a damping from 0 to 1e6 (limits::MAX_DAMPING)",
        )?;
        check(
            "model.beta",
            self.beta,
            (0.0..=1.0).contains(&self.beta),
            "a β in [0, 1]",
        )?;
        if self.clusters == 0 || self.clusters > 64 {
            return Err(ClothError::InvalidParameter {
                field: "model.clusters",
                value: self.clusters as f32,
                expected: "1 to 64 clusters per side",
            });
        }
        Ok(())
    }
}

/// How the patch model places particle targets between part centres.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Reflect, Serialize, Deserialize)]
pub enum PatchTargets {
    /// Sladović 2014 §3.4's pseudocode: an affine map per part from its four neighbours.
    /// Neighbouring parts disagree along their border when the lattice bends (the
    /// thesis's visible borders, fig. 22). (`Seed` in older scene files.)
    #[serde(alias = "Seed")]
    PerPart,
    /// Bilinear interpolation between the four part centres around each particle
    /// (extrapolated past the outer centres, like the seed's ghosts): continuous across
    /// part borders; the same as the seed's for a flat, rigidly moved cloth. Not in the
    /// thesis. A cloth only one part across uses the seed's targets.
    #[default]
    Bilinear,
}

/// Parameters of the hybrid patch model (Sladović 2014 §3.4).
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PatchParams {
    /// Particles across one part (1–16); parts at the right edge may be narrower.
    pub part_width: u32,
    /// Particles down one part (1–16); parts at the bottom may be shorter.
    pub part_height: u32,
    /// Stiffness α of the pull toward the targets, N/m (as shape matching's force).
    pub stiffness: f32,
    /// Exponent p of the pull (Sladović 2014 §4: 0.5–3).
    pub exponent: f32,
    /// Particle damping as a fraction of critical damping `2√(α m)` (Sladović 2014 §4 keeps
    /// particle damping separate from part damping).
    pub particle_damping_ratio: f32,
    /// Extra damping of the part centres, N·s/m per particle (added to the drag).
    pub part_damping: f32,
    /// The thesis's proposed correction: shift each part's targets by the offset from
    /// their centre of mass to the part's centre, less with distance. Acts only with
    /// [`PatchTargets::PerPart`]: the bilinear targets ignore it (a per-part shift would
    /// break their continuity across part borders).
    pub center_correction: bool,
    /// "Tiles" (fig. 12): particles sit exactly on their targets, no oscillation. The
    /// pull is then neither computed nor integrated, and only the part lattice sets the
    /// substeps: the cheap end of the model.
    pub tiles: bool,
    /// The target interpolation.
    pub targets: PatchTargets,
}

impl Default for PatchParams {
    fn default() -> Self {
        Self {
            part_width: 4,
            part_height: 4,
            stiffness: 60.0,
            exponent: 1.0,
            particle_damping_ratio: 1.0,
            part_damping: 0.0,
            center_correction: true,
            tiles: false,
            targets: PatchTargets::Bilinear,
        }
    }
}

impl PatchParams {
    /// What the part lattice is built from (part width, part height, targets): a change
    /// of these rebuilds it, and is a model switch; the other fields are only parameters.
    pub fn lattice_key(&self) -> (u32, u32, PatchTargets) {
        (self.part_width, self.part_height, self.targets)
    }

    fn validate(&self) -> Result<(), ClothError> {
        for (field, size) in [
            ("model.part_width", self.part_width),
            ("model.part_height", self.part_height),
        ] {
            if !(1..=16).contains(&size) {
                return Err(ClothError::InvalidParameter {
                    field,
                    value: size as f32,
                    expected: "a part size of 1 to 16 particles",
                });
            }
        }
        check(
            "model.stiffness",
            self.stiffness,
            self.stiffness > 0.0 && self.stiffness <= MAX_STIFFNESS,
            "a stiffness from 0 (excluded) to 1e9 (limits::MAX_STIFFNESS)",
        )?;
        check_exponent(self.exponent)?;
        check(
            "model.particle_damping_ratio",
            self.particle_damping_ratio,
            (0.0..=MAX_DAMPING).contains(&self.particle_damping_ratio),
            "a ratio from 0 to 1e6 (limits::MAX_DAMPING)",
        )?;
        check(
            "model.part_damping",
            self.part_damping,
            (0.0..=MAX_DAMPING).contains(&self.part_damping),
            "a damping from 0 to 1e6 (limits::MAX_DAMPING)",
        )?;
        Ok(())
    }
}

/// Parameters of the XPBD model (Macklin, Müller, Chentanez, "XPBD", MIG 2016; Macklin
/// et al., "Small Steps in Physics Simulation", SCA 2019). The material is the cloth's
/// own: every spring family is a distance constraint of compliance `1/k` with the
/// family's stiffness (`k = inf` is an inextensible constraint), the strain limit a
/// hard inequality, spring damping the paper's constraint damping.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct XpbdParams {
    /// The accuracy target of `Substeps::Auto`: the stretch (a fraction of the rest
    /// length) that solving each substep's constraints once may leave beyond what the
    /// material itself stretches. One iteration per substep makes an inextensible
    /// constraint act like a spring of stiffness about `m/h²` (Macklin et al. 2019 §4), so
    /// the stretch it leaves scales as `h²`. When the structural springs' length is bounded
    /// (inextensible or strain limited) the automatic substeps follow the largest stretch
    /// past that bound measured after each step, toward this target (a closed loop with
    /// hysteresis, `ClothSolver::xpbd_closed_loop`); otherwise, and for a run's first step,
    /// they are estimated: a cloth `R` springs of length `L` long hanging under gravity `g`
    /// stretches its most loaded constraint by about `2 R g h² / L`
    /// (`ClothSolver::stable_substeps`).
    pub max_stretch_error: f32,
    /// Long-range attachments (Kim, Chentanez, Müller 2012): no particle moves farther from
    /// its nearest pin (or attachment) than the shortest path to it through the cloth's
    /// springs allows, times `1 + strain limit` (× 1 for an inextensible cloth). They act
    /// when the structural family's length is bounded (`stiffness: inf`, or a strain
    /// limit) and the cloth is held; a hung cloth then keeps its length with few substeps.
    pub tethers: bool,
    /// How the stretch (structural) constraints are solved each substep: exactly along
    /// each line of the cloth (the default), or once each in a sweep.
    pub solve: XpbdSolve,
}

impl Default for XpbdParams {
    fn default() -> Self {
        Self {
            max_stretch_error: 0.01,
            tethers: true,
            solve: XpbdSolve::default(),
        }
    }
}

/// How XPBD solves a cloth's stretch (structural) constraints in a substep.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Reflect, Serialize, Deserialize)]
pub enum XpbdSolve {
    /// Exactly along each line of constraints (a grid's rows, then its columns; a mesh's
    /// straightest paths): each line's linearised system is tridiagonal and solved in
    /// one pass (Goldenthal et al. 2007; Deul et al. 2018), then the structural and seam
    /// constraints are swept once more on their own lengths. Tension crosses the cloth in
    /// one substep: holds a moving cloth's length in a few substeps (a swinging 64×64
    /// cloth within 0.06% at 4 substeps, where the sweep needs 80 for 0.2%).
    #[default]
    Lines,
    /// Each constraint once, colour by colour (Gauss–Seidel; Macklin et al. 2019): tension
    /// moves about one constraint a substep, so a long cloth needs many substeps. Cheaper
    /// per substep (about a third of the lines' cost per constraint), and as good where
    /// the load runs across the lines (a cloth hung from two corners, through its shear).
    Sweep,
}

impl XpbdParams {
    fn validate(&self) -> Result<(), ClothError> {
        check(
            "model.max_stretch_error",
            self.max_stretch_error,
            self.max_stretch_error > 0.0,
            "a stretch error > 0 (a fraction of the rest length)",
        )
    }
}

/// Which cloth model moves the particles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Reflect, Serialize, Deserialize)]
pub enum Model {
    /// Springs between particles (Sladović 2014 §2.2, §3.2; Maslova).
    #[default]
    MassSpring,
    /// Each particle pulled toward a goal from the best rigid fit of the rest shape
    /// (Sladović 2014 §2.3, §3.3). No springs act, so nothing tears.
    ShapeMatching(ShapeMatchingParams),
    /// Parts of w×h particles whose centres form a mass-spring lattice; particles follow
    /// targets interpolated between neighbouring centres (Sladović 2014 §3.4). Grids only.
    Patches(PatchParams),
    /// The springs as compliant distance constraints, solved once per small substep
    /// (XPBD): stable at any stiffness and substep count. Not in the seeds.
    Xpbd(XpbdParams),
}

impl Model {
    /// Which model this is, without its parameters.
    pub fn kind(&self) -> ModelKind {
        match self {
            Model::MassSpring => ModelKind::MassSpring,
            Model::ShapeMatching(_) => ModelKind::ShapeMatching,
            Model::Patches(_) => ModelKind::Patches,
            Model::Xpbd(_) => ModelKind::Xpbd,
        }
    }
}

/// Which model, without its parameters: the one identifier every front end uses (the
/// command line's `--model`, the lab's tables and charts, the inspector's list), written
/// `mass-spring`, `shape-matching`, `patches`, `xpbd`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Reflect, Serialize, Deserialize)]
pub enum ModelKind {
    /// [`Model::MassSpring`].
    MassSpring,
    /// [`Model::ShapeMatching`].
    ShapeMatching,
    /// [`Model::Patches`].
    Patches,
    /// [`Model::Xpbd`].
    Xpbd,
}

impl ModelKind {
    /// Every model, in the seeds' order, then XPBD.
    pub const ALL: [ModelKind; 4] = [
        ModelKind::MassSpring,
        ModelKind::ShapeMatching,
        ModelKind::Patches,
        ModelKind::Xpbd,
    ];

    /// The model's name: `mass-spring`, `shape-matching`, `patches` or `xpbd`.
    pub const fn name(self) -> &'static str {
        match self {
            ModelKind::MassSpring => "mass-spring",
            ModelKind::ShapeMatching => "shape-matching",
            ModelKind::Patches => "patches",
            ModelKind::Xpbd => "xpbd",
        }
    }

    /// The model with its default parameters.
    pub fn default_model(self) -> Model {
        match self {
            ModelKind::MassSpring => Model::MassSpring,
            ModelKind::ShapeMatching => Model::ShapeMatching(ShapeMatchingParams::default()),
            ModelKind::Patches => Model::Patches(PatchParams::default()),
            ModelKind::Xpbd => Model::Xpbd(XpbdParams::default()),
        }
    }
}

impl std::fmt::Display for ModelKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for ModelKind {
    type Err = ClothError;

    fn from_str(name: &str) -> Result<Self, ClothError> {
        ModelKind::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| ClothError::UnknownModel {
                name: name.to_string(),
                known: "mass-spring, shape-matching, patches, xpbd",
            })
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
}

/// Self-collision: every two particles of a cloth that are not joined by a spring keep
/// a distance `d` apart, with friction (Müller's "Ten Minute Physics" #15, the method of
/// NvCloth's self-collision). `d` is `distance`, at most the cloth's rest spacing (the
/// median structural rest length): a particle cannot slip through a triangle whose
/// corners it must stay `d` from.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SelfCollision {
    /// On or off.
    pub enabled: bool,
    /// The distance kept, m; `None`: the rest spacing.
    pub distance: Option<f32>,
    /// Coulomb friction between touching particles (0: they slide freely).
    pub friction: f32,
}

impl Default for SelfCollision {
    fn default() -> Self {
        Self {
            enabled: false,
            distance: None,
            friction: 0.3,
        }
    }
}

impl SelfCollision {
    /// On, at the rest spacing, with the default friction.
    pub fn on() -> Self {
        Self {
            enabled: true,
            ..Self::default()
        }
    }
}

impl Default for ClothParams {
    fn default() -> Self {
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
        }
    }
}

/// `Ok` when `ok` holds and `value` is finite; otherwise the error naming `field`.
pub(crate) fn check(
    field: &'static str,
    value: f32,
    ok: bool,
    expected: &'static str,
) -> Result<(), ClothError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(ClothError::InvalidParameter {
            field,
            value,
            expected,
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
            "a mass from 1e-9 to 1,000 kg (limits::MIN_NODE_MASS, MAX_NODE_MASS)",
        )?;
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
                "a stiffness from 0 to 1e9 N/m (limits::MAX_STIFFNESS; inf only for XPBD)",
            )?;
        }
        check(
            "springs.damping",
            s.damping,
            (0.0..=MAX_DAMPING).contains(&s.damping),
            "a damping from 0 to 1e6 N·s/m (limits::MAX_DAMPING)",
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
        )?;
        check(
            "drag",
            self.drag,
            (0.0..=MAX_DAMPING).contains(&self.drag),
            "a drag from 0 to 1e6 N·s/m (limits::MAX_DAMPING)",
        )?;
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
                    feature: "fabric in physical units",
                });
            }
        }
        match &self.model {
            Model::ShapeMatching(sm) => sm.validate()?,
            Model::Patches(patches) => patches.validate()?,
            Model::Xpbd(xpbd) => xpbd.validate()?,
            Model::MassSpring => {}
        }
        Ok(())
    }

    /// The substeps and the strain limiter: counts within their limits, a limit and a
    /// tolerance above zero.
    fn validate_stepping(&self) -> Result<(), ClothError> {
        match self.substeps {
            Substeps::Fixed(0) => {
                return Err(ClothError::InvalidParameter {
                    field: "substeps",
                    value: 0.0,
                    expected: "at least 1 substep",
                });
            }
            Substeps::Auto { max: 0 } => {
                return Err(ClothError::InvalidParameter {
                    field: "substeps.max",
                    value: 0.0,
                    expected: "at least 1 substep",
                });
            }
            Substeps::Fixed(n) if n > MAX_SUBSTEPS => {
                return Err(ClothError::InvalidParameter {
                    field: "substeps",
                    value: n as f32,
                    expected: "at most 65,536 substeps (limits::MAX_SUBSTEPS)",
                });
            }
            Substeps::Auto { max } if max > MAX_SUBSTEPS => {
                return Err(ClothError::InvalidParameter {
                    field: "substeps.max",
                    value: max as f32,
                    expected: "at most 65,536 substeps (limits::MAX_SUBSTEPS)",
                });
            }
            _ => {}
        }
        if self.strain_limit_iterations > MAX_LIMITER_SWEEPS {
            return Err(ClothError::InvalidParameter {
                field: "strain_limit_iterations",
                value: self.strain_limit_iterations as f32,
                expected: "at most 1,024 sweeps (limits::MAX_LIMITER_SWEEPS)",
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
                d > 0.0 && d <= crate::limits::MAX_SPACING,
                "a distance > 0 and at most 10 m (limits::MAX_SPACING)",
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
                feature: "self-collision",
            });
        }
        Ok(())
    }
}

/// The spatial pattern of the wind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Reflect, Serialize, Deserialize)]
pub enum WindField {
    /// The same force on every particle: `F = strength · d̂` (Sladović 2014 §3.2).
    #[default]
    Constant,
    /// Maslova listing 3.3: gusts from trigonometric functions of position and time.
    /// With `d̂ = +z` and strength 0.1 this is the listing's
    /// `(0.1 sin(10t), ·, 0.1 |sin(z + 10t)|)`; the listing's middle (y) line is missing
    /// from the seed text, so the vertical component here is 0.
    Trigonometric,
}

/// Wind as a direction, a strength (N per particle) and a field.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Wind {
    /// Where the wind blows to; normalised when used (a zero vector means no wind).
    #[serde(with = "vec3_serde")]
    pub direction: Vec3,
    /// Force per particle in N.
    pub strength: f32,
    /// Spatial and temporal pattern.
    pub field: WindField,
}

impl Default for Wind {
    fn default() -> Self {
        Self {
            direction: Vec3::Z,
            strength: 0.0,
            field: WindField::Constant,
        }
    }
}

impl Wind {
    /// Wind force on a particle at `position` at simulated time `time`.
    #[inline]
    pub fn force_at(&self, position: Vec3, time: f32) -> Vec3 {
        self.at_time(time).force_at(position)
    }

    /// The wind at simulated time `time`, with what does not depend on position worked
    /// out once (the direction, the side, the gust's phase): the force loops call
    /// [`WindAt::force_at`] per particle.
    #[inline]
    pub fn at_time(&self, time: f32) -> WindAt {
        let d = self.direction.normalize_or_zero();
        let side = Vec3::Y.cross(d).normalize_or(Vec3::X);
        let phase = 10.0 * time;
        WindAt {
            field: self.field,
            strength: self.strength,
            direction: d,
            side,
            phase,
            across: phase.sin(),
        }
    }
}

/// [`Wind`] at one moment (see [`Wind::at_time`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindAt {
    field: WindField,
    strength: f32,
    /// The normalised direction.
    direction: Vec3,
    /// The horizontal direction across it.
    side: Vec3,
    /// `10 t`.
    phase: f32,
    /// `sin(10 t)`.
    across: f32,
}

impl WindAt {
    /// Wind force on a particle at `position`.
    #[inline]
    pub fn force_at(&self, position: Vec3) -> Vec3 {
        let d = self.direction;
        match self.field {
            WindField::Constant => d * self.strength,
            // Maslova listing 3.3, rotated so that the listing's +z is `d`.
            WindField::Trigonometric => {
                let along = (position.dot(d) + self.phase).sin().abs();
                self.strength * (along * d + self.across * self.side)
            }
        }
    }
}

/// Air in physical units: a velocity (m/s) and the aerodynamic force it puts on each
/// triangle from its area, normal and the air's velocity relative to it, shared to its
/// corners, so the same air moves the same fabric the same way at any resolution and
/// mass. With `w` the air's velocity relative to the triangle (its corners' mean), `n`
/// its unit normal and `A` its area:
/// - drag, along the normal: `½ ρ C_d A (w·n) |w·n| n`;
/// - lift, across the relative flow in the plane of `w` and `n`:
///   `½ ρ C_l A (w·n) |w × n| ℓ`, `ℓ` the unit vector of `(n − (n·ŵ) ŵ)` (the flat-plate
///   force of Keckeisen et al. 2004, "Interactive cloth simulation in virtual
///   environments", §4, which separates the normal and tangential parts likewise).
///
/// Each particle takes a third of its triangles' force, scaled by `1 / (1 + h r)` with
/// `r` its drag rate `Σ ½ ρ C_d A |w·n| / 3m`: the backward-Euler step of the drag
/// linearised about the relative velocity, so a light fabric in a strong wind is carried
/// with the air without overshooting it, at any step (explicit drag diverges once
/// `h r > 2`). The per-particle [`Wind`] stays for the seeds' scenes.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Air {
    /// The air's velocity far from the cloth, m/s (its pattern in space and time: `field`).
    #[serde(with = "vec3_serde")]
    pub velocity: Vec3,
    /// Its spatial and temporal pattern ([`WindField`]: constant, or Maslova's gusts).
    pub field: WindField,
    /// Its density, kg/m³ (1.2 at sea level and 20 °C).
    pub density: f32,
    /// The drag coefficient of a triangle facing the flow (a flat plate: about 1.2).
    pub drag: f32,
    /// The lift coefficient.
    pub lift: f32,
}

impl Default for Air {
    fn default() -> Self {
        Self {
            velocity: Vec3::ZERO,
            field: WindField::Constant,
            density: 1.2,
            drag: 1.2,
            lift: 0.3,
        }
    }
}

impl Air {
    /// The air's velocity at `position` at simulated time `time`: `velocity`, or with
    /// Maslova's gusts their pattern at the speed of `velocity`.
    pub fn velocity_at(&self, position: Vec3, time: f32) -> Vec3 {
        self.at_time(time).force_at(position)
    }

    /// The air at simulated time `time`, what does not depend on position worked out
    /// once: its velocity at a position is the returned pattern's
    /// [`WindAt::force_at`] (a per-triangle loop calls it).
    pub fn at_time(&self, time: f32) -> WindAt {
        Wind {
            direction: self.velocity,
            strength: self.velocity.length(),
            field: self.field,
        }
        .at_time(time)
    }

    /// Checks the velocity, density and coefficients.
    pub fn validate(&self) -> Result<(), ClothError> {
        check(
            "air.velocity",
            self.velocity.length(),
            self.velocity.is_finite() && self.velocity.length() <= 1e3,
            "a finite velocity of at most 1,000 m/s",
        )?;
        for (field, value, most) in [
            ("air.density", self.density, 1e3),
            ("air.drag", self.drag, 100.0),
            ("air.lift", self.lift, 100.0),
        ] {
            check(
                field,
                value,
                (0.0..=most).contains(&value),
                "a value from 0 to its most (density 1,000 kg/m³, coefficients 100)",
            )?;
        }
        Ok(())
    }
}

/// Gravity and wind: the world a cloth lives in.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Environment {
    /// Acceleration of gravity in m/s² (Maslova eq. 1.6).
    #[serde(with = "vec3_serde")]
    pub gravity: Vec3,
    /// Switch gravity off without forgetting its value (Sladović's (2014) G key).
    pub gravity_enabled: bool,
    /// The wind as a force per particle (the seeds' scenes).
    pub wind: Wind,
    /// Air in physical units (`None`: no aerodynamic force; still air is `Some` with a
    /// zero velocity, and drags a falling cloth to its terminal velocity).
    pub air: Option<Air>,
}

impl Default for Environment {
    fn default() -> Self {
        Self {
            gravity: Vec3::new(0.0, -9.81, 0.0),
            gravity_enabled: true,
            wind: Wind::default(),
            air: None,
        }
    }
}

impl Environment {
    /// The gravity that acts: zero when switched off.
    pub fn effective_gravity(&self) -> Vec3 {
        if self.gravity_enabled {
            self.gravity
        } else {
            Vec3::ZERO
        }
    }

    /// Checks gravity and wind for non-finite values.
    pub fn validate(&self) -> Result<(), ClothError> {
        let g = self.gravity;
        check(
            "gravity",
            g.length(),
            g.is_finite() && g.length() <= crate::limits::MAX_GRAVITY,
            "a finite vector of at most 1,000 m/s² (limits::MAX_GRAVITY)",
        )?;
        let w = &self.wind;
        check(
            "wind.direction",
            w.direction.length(),
            w.direction.is_finite(),
            "a finite vector",
        )?;
        check(
            "wind.strength",
            w.strength,
            (0.0..=crate::limits::MAX_WIND).contains(&w.strength),
            "a strength from 0 to 1,000 N (limits::MAX_WIND)",
        )?;
        self.air.as_ref().map_or(Ok(()), Air::validate)
    }
}

/// Refuses `params` on a cloth of `particles` when a step's fixed work is over
/// [`MAX_WORK_PER_STEP`](crate::limits::MAX_WORK_PER_STEP) (particles × fixed substeps) or
/// [`MAX_SWEEP_WORK_PER_STEP`](crate::limits::MAX_SWEEP_WORK_PER_STEP) (× fixed limiter
/// sweeps). Automatic substeps are capped at the budget instead (see
/// [`auto_substeps_cap`](crate::limits::auto_substeps_cap)).
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
