//! Where each method fails: a grid over stiffness, node mass and timestep, and
//! the measured stability threshold of a single spring and of the full lattice against
//! the explicit bound `ω_max·h = 2`.
//!
//! The linear regime ([`Regime::Linear`]): a free cloth (nothing pinned but the single
//! spring's anchor) with no gravity, wind or damping, started from rest with every
//! particle displaced by a small deterministic pseudo-random offset, so every mode, the
//! fastest too, is excited. Springs and goal pulls are undamped (damping only moves the
//! bound, to `h²ω² + 2hγ < 4`); the strain limiter is off, since it would hide the
//! failure it is there to mask. Here the bound is exact, so automatic substeps pass by
//! construction.
//!
//! The nonlinear regimes test what the bound does not cover: a cloth hanging from its
//! top corners under gravity, one stretched by 50%, one crumpled (every particle moved
//! by up to 25% of the spacing per axis), each with the strain limiter on (10%, 4
//! sweeps) and the models' default damping, and the shape-matching and patch pulls at
//! exponents 0.5 and 3 and shape matching's velocity update besides the linear force
//! ([`NONLINEAR_MODELS`]). A failed cell there is run again with four times the
//! substeps: a failure that stays is the model's own (the cloth does what the model
//! says, and that passes 100% strain), one that goes was the automatic bound's.
//!
//! A probe fails on a non-finite position, a structural strain over 100%, or kinetic
//! energy growing tenfold without input: over ten times the larger of the energy it
//! started with and the largest kinetic energy of the first quarter of the run (a hanging
//! cloth's fall is input; so is a stretched cloth's release).

use bevy::math::{Affine3A, Vec3};
use serde::Serialize;

use bevy_cloth::error::ClothError;
use bevy_cloth::layout::shape::{ClothPins, ClothShape};
use bevy_cloth::params::{
    ClothParams, Environment, GoalUpdate, Integrator, Model, ModelKind, PatchParams,
    ShapeMatchingParams, SpringFamily, SpringParams, Substeps, Wind, XpbdParams,
};
use bevy_cloth::solver;

/// Spring (and pull) stiffnesses of the grid, N/m (Maslova §1.4's range).
pub const STIFFNESS: [f32; 6] = [100.0, 300.0, 1_000.0, 3_000.0, 10_000.0, 25_000.0];
/// Node masses of the grid, kg (Maslova: 0.001–1 g).
pub const MASS: [f32; 4] = [1e-6, 1e-5, 1e-4, 1e-3];
/// Timesteps of the grid, s.
pub const TIMESTEP: [f32; 6] = [0.001, 0.002, 0.004, 0.008, 0.016, 0.033];

/// The models of the grid. XPBD moves by constraints, not an explicit step: its
/// integrator setting does nothing (the Verlet and Euler panels are the same run twice),
/// and its automatic substeps follow its accuracy target, not a stability bound.
pub const MODELS: [&str; 4] = [
    ModelKind::MassSpring.name(),
    ModelKind::ShapeMatching.name(),
    ModelKind::Patches.name(),
    ModelKind::Xpbd.name(),
];

/// The models of the nonlinear regimes: the grid's four, and the pulls at exponents 0.5
/// and 3 and shape matching's velocity update (α = 0.5 of the way per substep).
pub const NONLINEAR_MODELS: [&str; 9] = [
    "mass-spring",
    "shape-matching",
    "shape-matching p=0.5",
    "shape-matching p=3",
    "shape-matching velocity",
    "patches",
    "patches p=0.5",
    "patches p=3",
    "xpbd",
];

/// Timesteps of the nonlinear regimes, s.
pub const NONLINEAR_TIMESTEP: [f32; 3] = [0.004, 0.016, 0.033];

/// How far each particle of the crumpled probe is moved, per axis, as a fraction of the
/// spacing: its springs start at up to ~65% strain (40% started some past 100%, a failure
/// before the first step).
pub const CRUMPLE: f32 = 0.25;

/// The state a probe starts from and what acts on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Regime {
    /// Free, 1% perturbation, no gravity, limiter off: the explicit bound's own regime.
    Linear,
    /// Pinned at its top corners under gravity, starting flat at rest; limiter on.
    Hanging,
    /// Free, every particle 50% further from the centre than at rest; limiter on.
    Stretched,
    /// Free, every particle displaced by up to [`CRUMPLE`] of the spacing; limiter on.
    Crumpled,
}

impl Regime {
    /// The regimes beyond the linear one.
    pub const NONLINEAR: [Regime; 3] = [Regime::Hanging, Regime::Stretched, Regime::Crumpled];
}

/// Particles across the probe cloth (a square grid, 2 cm spacing).
pub const PROBE_SIZE: u32 = 12;
const SPACING: f32 = 0.02;

/// The undamped, unlimited parameters of `model` (one of [`NONLINEAR_MODELS`]) at
/// stiffness `k` and node mass `m`: springs with the seed's 2:1:1 ratio from `k`; shape
/// matching's and the patches' pull at `k` (one cluster; parts of 4×4).
pub fn params(
    model: &str,
    k: f32,
    m: f32,
    integrator: Integrator,
    substeps: Substeps,
) -> Option<ClothParams> {
    let (name, variant) = model.split_once(' ').unwrap_or((model, ""));
    let exponent = match variant {
        "" | "velocity" => 1.0,
        "p=0.5" => 0.5,
        "p=3" => 3.0,
        _ => return None,
    };
    let model = match (name.parse::<ModelKind>().ok()?, variant) {
        (ModelKind::MassSpring, "") => Model::MassSpring,
        (ModelKind::Xpbd, "") => Model::Xpbd(XpbdParams::default()),
        (ModelKind::ShapeMatching, "velocity") => Model::ShapeMatching(ShapeMatchingParams {
            update: GoalUpdate::Velocity,
            stiffness: 0.5,
            damping: 0.0,
            ..ShapeMatchingParams::default()
        }),
        (ModelKind::ShapeMatching, _) => Model::ShapeMatching(ShapeMatchingParams {
            stiffness: k,
            exponent,
            damping: 0.0,
            ..ShapeMatchingParams::default()
        }),
        (ModelKind::Patches, v) if v != "velocity" => Model::Patches(PatchParams {
            stiffness: k,
            exponent,
            particle_damping_ratio: 0.0,
            part_damping: 0.0,
            ..PatchParams::default()
        }),
        _ => return None,
    };
    Some(ClothParams {
        model,
        node_mass: m,
        springs: SpringParams::from_structural(k),
        drag: 0.0,
        integrator,
        substeps,
        strain_limit: None,
        strain_limit_iterations: 0,
        strain_limit_tolerance: None,
        tear_ratio: None,
        self_collision: Default::default(),
        fabric: None,
        still_air: false,
        max_depenetration_speed: 1.0,
        teleport: Default::default(),
        inertia: Default::default(),
    })
}

/// No gravity, no wind: nothing puts energy in.
pub fn quiet() -> Environment {
    Environment {
        gravity_enabled: false,
        wind: Wind {
            strength: 0.0,
            ..Wind::default()
        },
        ..Environment::default()
    }
}

/// Displaces every free particle by up to `fraction` of `spacing` in each axis
/// (a fixed hash, the same every run), at rest, and updates the model's goals.
pub fn perturb(cloth: &mut solver::ClothSolver, spacing: f32, fraction: f32) {
    let p = cloth.particles_mut();
    for i in 0..p.len() {
        if p.is_pinned(i) {
            continue;
        }
        let offset = Vec3::new(
            bevy_cloth::lab::unit_hash(i, 0),
            bevy_cloth::lab::unit_hash(i, 1),
            bevy_cloth::lab::unit_hash(i, 2),
        ) * (spacing * fraction);
        p.position[i] += offset;
        p.previous[i] = p.position[i];
        p.velocity[i] = Vec3::ZERO;
    }
    // Goals and targets of the displaced cloth, so its energy counts the displacement.
    cloth.update_goals();
}

/// Kinetic energy of the free particles, J, summed in `f64` (`ClothSolver::energy` sums in
/// `f32`): the growth test compares it with the small energy of a 1% perturbation.
pub fn kinetic(cloth: &solver::ClothSolver) -> f64 {
    let p = cloth.particles();
    (0..p.len())
        .filter(|&i| !p.is_pinned(i))
        .map(|i| 0.5 * p.mass[i] as f64 * p.velocity[i].length_squared() as f64)
        .sum()
}

/// Why a probe failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Failure {
    /// A position or velocity went non-finite.
    NonFinite,
    /// A structural spring passed 100% strain.
    Strain,
    /// Kinetic energy grew tenfold.
    EnergyGrowth,
}

/// Steps `cloth` `steps` times by `dt` with no input and says whether and how it failed.
pub fn probe(cloth: &mut solver::ClothSolver, dt: f32, steps: usize) -> Option<Failure> {
    probe_in(cloth, &quiet(), dt, steps)
}

/// [`probe`] under `env` (gravity for a hanging cloth).
pub fn probe_in(
    cloth: &mut solver::ClothSolver,
    env: &Environment,
    dt: f32,
    steps: usize,
) -> Option<Failure> {
    run_probe(cloth, env, dt, steps).0
}

/// Steps `cloth` until it fails or `steps` are done: the failure, and whether any step
/// hit the automatic substeps' cap.
fn run_probe(
    cloth: &mut solver::ClothSolver,
    env: &Environment,
    dt: f32,
    steps: usize,
) -> (Option<Failure>, bool) {
    let quarter = (steps / 4).max(1);
    // The energy it starts with above rest (a fall's or a release's share counts through
    // the early kinetic energy).
    let e = cloth.energy(env);
    let mut early = (e.kinetic + e.spring) as f64;
    let mut under_resolved = false;
    for step in 1..=steps {
        cloth.step(dt, env);
        under_resolved |= cloth.under_resolved();
        if let Some(failure) = failure_of(cloth, step, quarter, &mut early) {
            return (Some(failure), under_resolved);
        }
    }
    (None, under_resolved)
}

/// The probe cloth of the grid: [`PROBE_SIZE`]² particles, nothing pinned, perturbed by
/// 1% of the spacing.
pub fn probe_cloth(params: &ClothParams) -> Result<solver::ClothSolver, ClothError> {
    let mut cloth = rest_lattice(params)?;
    perturb(&mut cloth, SPACING, 0.01);
    Ok(cloth)
}

/// The probe cloth at rest, unperturbed.
fn rest_lattice(params: &ClothParams) -> Result<solver::ClothSolver, ClothError> {
    let shape = ClothShape::Grid {
        width: PROBE_SIZE,
        height: PROBE_SIZE,
        spacing: SPACING,
    };
    shape.build_solver(&ClothPins::None, params, Affine3A::IDENTITY)
}

/// Measures the threshold of cloths from `make` and fills in the table row.
fn threshold(
    case: String,
    k: f32,
    m: f32,
    omega: f32,
    make: impl FnMut() -> Result<solver::ClothSolver, ClothError>,
    auto_bound: f32,
) -> Result<Threshold, ClothError> {
    Ok(Threshold {
        case,
        stiffness: k,
        mass: m,
        omega_max: omega,
        predicted: 2.0 / omega,
        auto_bound,
        measured: measured_threshold(make, 2.0 / omega, 400)?,
    })
}

/// One cell of the grid.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Cell {
    /// The regime probed.
    pub regime: Regime,
    /// The model.
    pub model: String,
    /// `Verlet` or `SemiImplicitEuler`.
    pub integrator: Integrator,
    /// Automatic substeps (else one substep per step).
    pub auto: bool,
    /// Stiffness, N/m.
    pub stiffness: f32,
    /// Node mass, kg.
    pub mass: f32,
    /// Timestep, s.
    pub timestep: f32,
    /// `√(k/m)`, rad/s.
    pub omega0: f32,
    /// Substeps of the last step.
    pub substeps: u32,
    /// The automatic substeps hit their limit (8192) in some step: the bound asked for
    /// more, so a stable result there is not the bound's doing.
    pub under_resolved: bool,
    /// What failed, if anything.
    pub failure: Option<Failure>,
    /// For a failed cell with automatic substeps: whether it fails again with four times
    /// the substeps its last step took. `Some(true)`: the failure is the model's own (it
    /// does not go away as the step shrinks); `Some(false)`: the automatic bound was too
    /// loose there. `None`: not rerun.
    pub persists_at_4x: Option<bool>,
}

/// Runs one cell of `regime` for one simulated second (at least 30 steps).
pub fn cell(
    regime: Regime,
    model: &str,
    integrator: Integrator,
    auto: bool,
    k: f32,
    m: f32,
    dt: f32,
) -> Result<Cell, ClothError> {
    let substeps = if auto {
        Substeps::default()
    } else {
        Substeps::Fixed(1)
    };
    let params =
        params(model, k, m, integrator, substeps).ok_or_else(|| ClothError::UnknownModel {
            name: model.to_string(),
            known: "the stability map's models (stability::MODELS, NONLINEAR_MODELS)",
        })?;
    let (mut cloth, env) = regime_cloth(regime, &params)?;
    let steps = ((1.0 / dt).ceil() as usize).max(30);
    let (failure, under_resolved) = run_probe(&mut cloth, &env, dt, steps);
    let persists_at_4x = match (failure, auto) {
        (Some(_), true) => {
            let finer = ClothParams {
                substeps: Substeps::Fixed(cloth.substeps().max(1).saturating_mul(4)),
                ..params
            };
            let (mut again, env) = regime_cloth(regime, &finer)?;
            Some(run_probe(&mut again, &env, dt, steps).0.is_some())
        }
        _ => None,
    };
    Ok(Cell {
        regime,
        model: model.to_string(),
        integrator,
        auto,
        stiffness: k,
        mass: m,
        timestep: dt,
        omega0: (k / m).sqrt(),
        substeps: cloth.substeps(),
        under_resolved,
        failure,
        persists_at_4x,
    })
}

/// The failure test after `step` (1-based): non-finite, past 100% strain, or kinetic
/// energy over ten times `early` (the start's energy, raised to the largest kinetic
/// energy of the first `quarter` steps).
fn failure_of(
    cloth: &solver::ClothSolver,
    step: usize,
    quarter: usize,
    early: &mut f64,
) -> Option<Failure> {
    if !cloth.is_finite() {
        return Some(Failure::NonFinite);
    }
    if cloth.strain().max > 1.0 {
        return Some(Failure::Strain);
    }
    let ke = kinetic(cloth);
    if step <= quarter {
        *early = early.max(ke);
        None
    } else if ke > 10.0 * *early {
        Some(Failure::EnergyGrowth)
    } else {
        None
    }
}

/// The probe cloth of `regime` (with `params`, the limiter switched on for the nonlinear
/// regimes) and the environment it runs in.
pub fn regime_cloth(
    regime: Regime,
    params: &ClothParams,
) -> Result<(solver::ClothSolver, Environment), ClothError> {
    // The nonlinear regimes run each model as a game would: its default damping (the
    // bound accounts for it) and the strain limiter on.
    let model = match params.model {
        Model::ShapeMatching(sm) => Model::ShapeMatching(ShapeMatchingParams {
            damping: ShapeMatchingParams::default().damping,
            ..sm
        }),
        Model::Patches(patch) => Model::Patches(PatchParams {
            particle_damping_ratio: PatchParams::default().particle_damping_ratio,
            ..patch
        }),
        other @ (Model::MassSpring | Model::Xpbd(_)) => other,
    };
    let limited = ClothParams {
        model,
        strain_limit: Some(0.1),
        strain_limit_iterations: 4,
        ..*params
    };
    let shape = ClothShape::Grid {
        width: PROBE_SIZE,
        height: PROBE_SIZE,
        spacing: SPACING,
    };
    let free = |p: &ClothParams| shape.build_solver(&ClothPins::None, p, Affine3A::IDENTITY);
    Ok(match regime {
        Regime::Linear => (probe_cloth(params)?, quiet()),
        Regime::Hanging => {
            let cloth = shape.build_solver(&ClothPins::TopCorners, &limited, Affine3A::IDENTITY)?;
            let env = Environment {
                wind: Wind {
                    strength: 0.0,
                    ..Wind::default()
                },
                ..Environment::default()
            };
            (cloth, env)
        }
        Regime::Stretched => {
            let mut cloth = free(&limited)?;
            let p = cloth.particles_mut();
            let centre = p.position.iter().copied().sum::<Vec3>() / p.len() as f32;
            for i in 0..p.len() {
                p.position[i] = centre + (p.position[i] - centre) * 1.5;
                p.previous[i] = p.position[i];
            }
            cloth.update_goals();
            (cloth, quiet())
        }
        Regime::Crumpled => {
            let mut cloth = free(&limited)?;
            perturb(&mut cloth, SPACING, CRUMPLE);
            (cloth, quiet())
        }
    })
}

/// ω_max of the mass-spring lattice linearised at its current (rest) state: the square
/// root of the largest eigenvalue of `M⁻¹K`, by the solver's own power iteration
/// ([`solver::ClothSolver::lattice_eigenvalue`]) run to convergence (2,000 iterations,
/// where the automatic substeps take 30).
pub fn lattice_omega_max(cloth: &solver::ClothSolver) -> f32 {
    cloth
        .lattice_eigenvalue(|kind| cloth.stiffness(kind), true, 2_000)
        .sqrt()
}

/// The largest step the solver's own automatic substeps take as one substep (its
/// Gershgorin bound with the 0.8 safety factor), by bisection on
/// [`solver::ClothSolver::stable_substeps`].
pub fn auto_bound(cloth: &solver::ClothSolver) -> f32 {
    let (mut lo, mut hi) = (1e-7f32, 1.0f32);
    for _ in 0..60 {
        let mid = (lo * hi).sqrt();
        if cloth.stable_substeps(mid) <= 1 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The largest stable step found by bisection: `make` builds the perturbed cloth
/// afresh for each try, and a try runs `steps` single-substep steps.
pub fn measured_threshold(
    mut make: impl FnMut() -> Result<solver::ClothSolver, ClothError>,
    guess: f32,
    steps: usize,
) -> Result<f32, ClothError> {
    let fails = |dt: f32, cloth: &mut solver::ClothSolver| probe(cloth, dt, steps).is_some();
    let (mut lo, mut hi) = (guess * 0.25, guess * 4.0);
    if fails(lo, &mut make()?) || !fails(hi, &mut make()?) {
        return Err(ClothError::NotMeasurable {
            reason: format!("no threshold between {lo} and {hi} s"),
        });
    }
    for _ in 0..30 {
        let mid = (lo * hi).sqrt();
        if fails(mid, &mut make()?) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(lo)
}

/// A row of the threshold table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Threshold {
    /// What was measured.
    pub case: String,
    /// Stiffness, N/m.
    pub stiffness: f32,
    /// Node mass, kg.
    pub mass: f32,
    /// ω_max used for the prediction, rad/s.
    pub omega_max: f32,
    /// `2 / ω_max`, s.
    pub predicted: f32,
    /// The largest step the automatic substeps allow as one substep, s.
    pub auto_bound: f32,
    /// The largest stable step found, s.
    pub measured: f32,
}

/// A single spring from a pinned particle to a free one of mass `m`: `ω = √(k/m)`.
pub fn single_spring(k: f32, m: f32, integrator: Integrator) -> Result<Threshold, ClothError> {
    let springs = SpringParams {
        structural: SpringFamily::new(k),
        shear: SpringFamily::off(k),
        bend: SpringFamily::off(k),
        bend_diagonal: SpringFamily::off(k),
        ..SpringParams::from_structural(k)
    };
    let params = ClothParams {
        springs,
        ..params("mass-spring", k, m, integrator, Substeps::Fixed(1)).expect("model")
    };
    let make = || {
        let layout = solver::Layout::from_springs(&[Vec3::ZERO, Vec3::X * SPACING], &[[0, 1]])?;
        let mut cloth = solver::ClothSolver::new(layout, &[0], &params, Affine3A::IDENTITY)?;
        // Stretched along the spring by 1%.
        let p = cloth.particles_mut();
        p.position[1].x += SPACING * 0.01;
        p.previous[1] = p.position[1];
        Ok(cloth)
    };
    let auto = auto_bound(&make()?);
    let case = format!("single spring, {integrator:?}");
    threshold(case, k, m, (k / m).sqrt(), make, auto)
}

/// The full [`PROBE_SIZE`]² lattice (structural, shear, bend at 2:1:1): `ω_max` from
/// [`lattice_omega_max`].
pub fn lattice(k: f32, m: f32, integrator: Integrator) -> Result<Threshold, ClothError> {
    let params = params("mass-spring", k, m, integrator, Substeps::Fixed(1)).expect("model");
    let rest = rest_lattice(&params)?;
    let case = format!("{PROBE_SIZE}×{PROBE_SIZE} lattice, {integrator:?}");
    let make = || probe_cloth(&params);
    threshold(
        case,
        k,
        m,
        lattice_omega_max(&rest),
        make,
        auto_bound(&rest),
    )
}

/// `ω_max / √(k/m)` of the mass-spring lattice: the same for every `k` and `m`, since
/// all families scale with `k`.
pub fn lattice_factor() -> f32 {
    let (k, m) = (1000.0, 1e-4);
    let params =
        params("mass-spring", k, m, Integrator::Verlet, Substeps::Fixed(1)).expect("model");
    rest_lattice(&params).map_or(f32::NAN, |c| lattice_omega_max(&c) / (k / m).sqrt())
}
