//! Each cloth model's own parameters: shape matching, the patch model and XPBD.

use bevy::reflect::Reflect;
use serde::{Deserialize, Serialize};

use super::check;
use crate::error::ClothError;
use crate::limits::{MAX_DAMPING, MAX_STIFFNESS};

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
    pub(super) fn validate(&self) -> Result<(), ClothError> {
        check(
            "model.stiffness",
            self.stiffness,
            (0.0..=MAX_STIFFNESS).contains(&self.stiffness),
            format!("a stiffness from 0 to {MAX_STIFFNESS:e} (limits::MAX_STIFFNESS)"),
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
            format!("a damping from 0 to {MAX_DAMPING:e} (limits::MAX_DAMPING)"),
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
                expected: "1 to 64 clusters per side".into(),
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

    pub(super) fn validate(&self) -> Result<(), ClothError> {
        for (field, size) in [
            ("model.part_width", self.part_width),
            ("model.part_height", self.part_height),
        ] {
            if !(1..=16).contains(&size) {
                return Err(ClothError::InvalidParameter {
                    field,
                    value: size as f32,
                    expected: "a part size of 1 to 16 particles".into(),
                });
            }
        }
        check(
            "model.stiffness",
            self.stiffness,
            self.stiffness > 0.0 && self.stiffness <= MAX_STIFFNESS,
            format!("a stiffness from 0 (excluded) to {MAX_STIFFNESS:e} (limits::MAX_STIFFNESS)"),
        )?;
        check_exponent(self.exponent)?;
        check(
            "model.particle_damping_ratio",
            self.particle_damping_ratio,
            (0.0..=MAX_DAMPING).contains(&self.particle_damping_ratio),
            format!("a ratio from 0 to {MAX_DAMPING:e} (limits::MAX_DAMPING)"),
        )?;
        check(
            "model.part_damping",
            self.part_damping,
            (0.0..=MAX_DAMPING).contains(&self.part_damping),
            format!("a damping from 0 to {MAX_DAMPING:e} (limits::MAX_DAMPING)"),
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
    pub(super) fn validate(&self) -> Result<(), ClothError> {
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
