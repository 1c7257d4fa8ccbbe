//! Speed against accuracy: every model and its main knobs against a converged
//! mass-spring reference of the same scene.
//!
//! The reference is the scene's cloth as a mass-spring cloth at the same resolution, with
//! the substep divided by [`REFERENCE_FACTOR`] (100): 100 times the automatic substeps
//! (the scene's 16 ms step divided by 100 would be unstable for a stiff card). It is the same
//! material as the configurations: the same springs, and the same strain limit, which
//! the reference runs to convergence (a tolerance, not a fixed number of sweeps), so a
//! configuration that limits less is measured as the softer material it is. It is
//! checked by halving the substep once more; a scene whose reference does not converge
//! gets no Pareto flags. It integrates with symplectic Euler (see [`Case::reference`]).
//!
//! Times are the median of several runs with their spread (fastest and slowest); a
//! configuration is on the cost–error frontier only when no other one is at least as
//! good in both beyond the spread of the times and the reference's own uncertainty
//! (see [`pareto`]). A run that failed gets neither a time nor a flag.

use std::time::Instant;

use bevy::math::Vec3;
use serde::Serialize;

use bevy_cloth::error::ClothError;
use bevy_cloth::params::{
    ClothParams, Integrator, Model, ModelKind, PatchParams, ShapeMatchingParams, Substeps,
    XpbdParams,
};
use bevy_cloth::scene::ClothScene;

use super::SceneRun;

/// Seconds between error samples.
pub const SAMPLE_INTERVAL: f64 = 0.1;

/// The reference takes this many times the automatic substeps (and its check twice as
/// many). 100: with ω_max from the power iteration the curtain's automatic count fell
/// from 8 to 5, and 100× keeps its reference near the 512 substeps it had (500).
pub const REFERENCE_FACTOR: u32 = 100;

/// The reference's strain limiter: sweeps until no spring is past the limit by more than
/// this (a fraction of its rest length) …
pub const REFERENCE_LIMITER_TOLERANCE: f32 = 1e-4;

/// … or at most this many sweeps per substep.
pub const REFERENCE_LIMITER_SWEEPS: u32 = 500;

/// A configuration: a model with its knobs set.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Config {
    /// `mass-spring`, `shape-matching`, `patches` or `xpbd`.
    pub model: &'static str,
    /// The knobs, e.g. `Verlet, 4 substeps`.
    pub label: String,
    /// The parameters.
    #[serde(skip)]
    pub params: ClothParams,
}

/// The configurations measured on a cloth whose mass-spring parameters are `base`:
/// mass-spring with either integrator at 1, 2, 4, 8 and automatic substeps (and, when
/// the material has a strain limit, at automatic substeps with the limiter converged as
/// in the reference); shape
/// matching with 1 and 4×4 clusters at stiffness k, 4k, 16k and 64k (k the structural
/// spring stiffness: the pins hold a shape-matched cloth only through the fit, so a
/// hanging cloth needs a stiff pull); patches of 1, 2, 4 and 8 particles square pulled
/// at 3k; XPBD (the same springs as constraints, the same strain limit) at 5, 10, 20,
/// 40 and 80 substeps and automatic (its stretch-error target).
pub fn configs(base: &ClothParams) -> Vec<Config> {
    let mut out = mass_spring_configs(base);
    out.extend(other_model_configs(base));
    out
}

/// [`configs`]' mass-spring ones.
fn mass_spring_configs(base: &ClothParams) -> Vec<Config> {
    let mut out = Vec::new();
    for integrator in Integrator::ALL {
        for substeps in [
            Substeps::Fixed(1),
            Substeps::Fixed(2),
            Substeps::Fixed(4),
            Substeps::Fixed(8),
            Substeps::default(),
        ] {
            let name = match integrator {
                Integrator::Verlet => "Verlet",
                Integrator::SemiImplicitEuler => "Euler",
            };
            let steps = substeps_label(substeps);
            out.push(Config {
                model: ModelKind::MassSpring.name(),
                label: format!("{name}, {steps}"),
                params: ClothParams {
                    model: Model::MassSpring,
                    integrator,
                    substeps,
                    ..*base
                },
            });
        }
    }
    if base.strain_limit.is_some() {
        // The same step with the limiter run to the reference's tolerance: how much of a
        // configuration's error is its limiter's (4 sweeps make a softer material).
        out.push(Config {
            model: ModelKind::MassSpring.name(),
            label: "Verlet, auto substeps, limiter converged".into(),
            params: ClothParams {
                model: Model::MassSpring,
                integrator: Integrator::Verlet,
                substeps: Substeps::default(),
                strain_limit_iterations: REFERENCE_LIMITER_SWEEPS,
                strain_limit_tolerance: Some(REFERENCE_LIMITER_TOLERANCE),
                ..*base
            },
        });
    }
    out
}

/// [`configs`]' shape-matching, patch and XPBD ones.
fn other_model_configs(base: &ClothParams) -> Vec<Config> {
    let mut out = Vec::new();
    let k = base.springs.structural.stiffness;
    for clusters in [1, 4] {
        for factor in [1.0, 4.0, 16.0, 64.0] {
            let stiffness = k * factor;
            out.push(Config {
                model: ModelKind::ShapeMatching.name(),
                label: format!("{clusters}×{clusters} clusters, α = {stiffness} N/m"),
                params: ClothParams {
                    model: Model::ShapeMatching(ShapeMatchingParams {
                        stiffness,
                        clusters,
                        // The reference's spring damping, as particle damping.
                        damping: base.springs.damping,
                        ..ShapeMatchingParams::default()
                    }),
                    substeps: Substeps::default(),
                    ..*base
                },
            });
        }
    }
    for size in [1, 2, 4, 8] {
        out.push(Config {
            model: ModelKind::Patches.name(),
            label: format!("{size}×{size} parts"),
            params: ClothParams {
                model: Model::Patches(PatchParams {
                    part_width: size,
                    part_height: size,
                    stiffness: 3.0 * k,
                    ..PatchParams::default()
                }),
                substeps: Substeps::default(),
                ..*base
            },
        });
    }
    for substeps in [5, 10, 20, 40, 80]
        .map(Substeps::Fixed)
        .into_iter()
        .chain([Substeps::default()])
    {
        out.push(Config {
            model: ModelKind::Xpbd.name(),
            label: substeps_label(substeps),
            params: ClothParams {
                model: Model::Xpbd(XpbdParams::default()),
                substeps,
                ..*base
            },
        });
    }
    out
}

/// `1 substep`, `8 substeps`, `auto substeps`: a configuration's substeps in a label.
fn substeps_label(substeps: Substeps) -> String {
    match substeps {
        Substeps::Fixed(1) => "1 substep".into(),
        Substeps::Fixed(n) => format!("{n} substeps"),
        Substeps::Auto { .. } => "auto substeps".into(),
    }
}

/// One scene of the accuracy study: `scene` reduced to the cloth measured.
#[derive(Clone, Debug)]
pub struct Case {
    /// A name for tables and charts.
    pub name: String,
    /// The scene with one cloth; its parameters are the reference's: the cloth's own
    /// with its springs as mass-spring, whatever model the scene gives it.
    pub scene: ClothScene,
    /// Simulated seconds.
    pub seconds: f32,
}

impl Case {
    /// Cloth `index` of `scene` alone (colliders kept), its springs as mass-spring.
    pub fn new(
        name: &str,
        scene: &ClothScene,
        index: usize,
        seconds: f32,
    ) -> Result<Self, ClothError> {
        let cloth = scene
            .cloths
            .get(index)
            .ok_or_else(|| ClothError::NotMeasurable {
                reason: format!("the scene has no cloth {index}"),
            })?;
        let mut scene = scene.clone();
        scene.cloths = vec![cloth.clone()];
        scene.cloths[0].cloth.params.model = Model::MassSpring;
        Ok(Self {
            name: name.to_string(),
            scene,
            seconds,
        })
    }

    /// Steps of the scene's timestep that cover `seconds`.
    pub fn steps(&self) -> usize {
        (self.seconds as f64 / self.scene.timestep as f64 - 1e-6).ceil() as usize
    }

    /// The reference's parameters.
    pub fn base(&self) -> ClothParams {
        self.scene.cloths[0].cloth.params
    }

    /// Steps after which a sample is taken: the first step at or past each multiple of
    /// [`SAMPLE_INTERVAL`], the same steps for every configuration.
    pub fn sample_steps(&self) -> Vec<usize> {
        let dt = self.scene.timestep as f64;
        (1..=self.steps())
            .filter(|&s| {
                let k = |s: usize| ((s as f64 * dt + 1e-9) / SAMPLE_INTERVAL).floor();
                k(s) > k(s - 1)
            })
            .collect()
    }

    /// Runs the cloth with `params`.
    pub fn simulate(&self, params: &ClothParams) -> Result<Trajectory, ClothError> {
        let mut scene = self.scene.clone();
        scene.cloths[0].cloth.params = *params;
        let mut run = SceneRun::new(&scene)?;
        let env = run.environment;
        let dt = run.timestep;
        let samples_at = self.sample_steps();
        let (_, cloth) = &mut run.cloths[0];
        let start = cloth.energy(&env).total();
        let mut t = Trajectory {
            samples: Vec::with_capacity(samples_at.len()),
            milliseconds: 0.0,
            max_strain: 0.0,
            energy_start: start,
            energy_end: start,
            failed_at: None,
            mean_substeps: 0.0,
            mass: cloth.particles().mass.iter().sum(),
            diagonal: diagonal(cloth.positions()),
        };
        let (mut substeps, mut steps_run) = (0u64, 0usize);
        for step in 1..=self.steps() {
            steps_run = step;
            let clock = Instant::now();
            cloth.step(dt, &env);
            t.milliseconds += clock.elapsed().as_secs_f64() * 1e3;
            substeps += cloth.substeps() as u64;
            let strain = cloth.strain().max;
            t.max_strain = t.max_strain.max(strain);
            if !cloth.is_stable() {
                t.failed_at = Some(step as f32 * dt);
                break;
            }
            if samples_at.binary_search(&step).is_ok() {
                t.samples.push(cloth.positions().to_vec());
            }
        }
        t.energy_end = cloth.energy(&env).total();
        t.mean_substeps = substeps as f64 / steps_run.max(1) as f64;
        Ok(t)
    }

    /// The reference: the base parameters with `factor` times the automatic substeps,
    /// integrated by symplectic Euler.
    pub fn reference(&self, factor: u32) -> Result<(u32, Trajectory), ClothError> {
        let scene = &self.scene;
        let solver = SceneRun::new(scene)?;
        let auto = solver.cloths[0].1.stable_substeps(scene.timestep);
        let substeps = auto * factor;
        // Symplectic Euler, not Verlet: at hundreds of substeps per step a displacement
        // is a few float spacings of the position, and Verlet's velocity, a difference of
        // positions, picks up the rounding of every strain-limiter correction; Euler
        // carries its velocity exactly. The strain limiter (when the material has one)
        // runs until every spring is within 0.01% of the limit.
        let base = self.base();
        let params = ClothParams {
            substeps: Substeps::Fixed(substeps),
            integrator: Integrator::SemiImplicitEuler,
            strain_limit_iterations: REFERENCE_LIMITER_SWEEPS,
            strain_limit_tolerance: base.strain_limit.map(|_| REFERENCE_LIMITER_TOLERANCE),
            ..base
        };
        Ok((substeps, self.simulate(&params)?))
    }
}

/// The bounding-box diagonal of `positions`.
fn diagonal(positions: &[Vec3]) -> f32 {
    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    (hi - lo).length()
}

/// A run sampled every [`SAMPLE_INTERVAL`].
#[derive(Clone, Debug)]
pub struct Trajectory {
    /// Positions at each sample step (fewer when the run failed).
    pub samples: Vec<Vec<Vec3>>,
    /// Wall-clock time of all steps, ms.
    pub milliseconds: f64,
    /// Largest structural strain over the run.
    pub max_strain: f32,
    /// Total energy at the start and the end, J.
    pub energy_start: f32,
    /// Total energy at the end, J.
    pub energy_end: f32,
    /// When the run went non-finite or past 100% strain, s.
    pub failed_at: Option<f32>,
    /// Substeps per step, on average.
    pub mean_substeps: f64,
    /// Mass of the cloth, kg.
    pub mass: f32,
    /// Diagonal of the cloth at the start, m.
    pub diagonal: f32,
}

impl Trajectory {
    /// RMS distance between corresponding particles over all samples, and at the last
    /// sample, both divided by the cloth's diagonal; `None` when either run has fewer
    /// samples (it failed).
    pub fn error_against(&self, reference: &Trajectory) -> Option<(f64, f64)> {
        if self.samples.len() != reference.samples.len() || self.samples.is_empty() {
            return None;
        }
        let rms = |pairs: &mut dyn Iterator<Item = (&Vec<Vec3>, &Vec<Vec3>)>| {
            let (mut sum, mut count) = (0.0f64, 0usize);
            for (a, b) in pairs {
                for (p, q) in a.iter().zip(b) {
                    sum += p.distance_squared(*q) as f64;
                    count += 1;
                }
            }
            (sum / count.max(1) as f64).sqrt() / reference.diagonal as f64
        };
        let all = rms(&mut self.samples.iter().zip(&reference.samples));
        let last = rms(&mut std::iter::once((
            self.samples.last()?,
            reference.samples.last()?,
        )));
        Some((all, last))
    }
}

/// One row of the accuracy table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Row {
    /// The case.
    pub scene: String,
    /// The model.
    pub model: &'static str,
    /// Its knobs.
    pub label: String,
    /// Wall-clock ms per simulated second, the median of the timed runs (`None`: failed).
    pub ms_per_second: Option<f64>,
    /// The fastest and slowest timed run, ms per simulated second.
    pub ms_range: Option<(f64, f64)>,
    /// Substeps per 16 ms step, on average.
    pub substeps: f64,
    /// RMS particle distance to the reference over the run / diagonal (`None`: failed).
    pub error: Option<f64>,
    /// The same at the last sample only: the final drape.
    pub final_error: Option<f64>,
    /// Largest structural strain over the run.
    pub max_strain: f32,
    /// Final total energy minus the reference's, over `M g D` (mass, gravity, diagonal);
    /// the same quantity for every model: the particles' kinetic, gravitational and
    /// spring energy at the scene's spring parameters
    /// ([`bevy_cloth::solver::ClothSolver::energy`]).
    pub energy_drift: Option<f64>,
    /// When the run failed, s.
    pub failed_at: Option<f32>,
    /// On the cost–error Pareto frontier of its scene.
    pub pareto: bool,
}

/// The reference of a case and its convergence check.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Reference {
    /// The case.
    pub scene: String,
    /// Substeps per step of the reference.
    pub substeps: u32,
    /// Error of the reference against one with half its substep (its own error).
    pub halving_change: f64,
    /// The smallest error reported for a configuration of the case.
    pub smallest_error: f64,
    /// `halving_change < 0.05 · smallest_error`.
    pub converged: bool,
    /// Wall-clock time of the reference run, ms.
    pub milliseconds: f64,
}

/// Measures every configuration of `case` against its reference, timing each stable one
/// `repeats` times (at least 1); `progress` hears of each row as it is done.
pub fn measure(
    case: &Case,
    configs: &[Config],
    repeats: usize,
    mut progress: impl FnMut(&Row),
) -> Result<(Reference, Vec<Row>), ClothError> {
    let (substeps, reference) = case.reference(REFERENCE_FACTOR)?;
    let (_, finer) = case.reference(2 * REFERENCE_FACTOR)?;
    let halving_change = reference
        .error_against(&finer)
        .map_or(f64::INFINITY, |e| e.0);
    let g = case
        .scene
        .environment
        .effective_gravity()
        .length()
        .max(1e-6) as f64;
    let scale = reference.mass as f64 * g * reference.diagonal as f64;
    let mut rows = Vec::new();
    for config in configs {
        let row = measure_one(case, config, repeats, &reference, scale)?;
        progress(&row);
        rows.push(row);
    }
    let smallest_error = rows
        .iter()
        .filter_map(|r| r.error)
        .filter(|e| *e > 0.0)
        .fold(f64::INFINITY, f64::min);
    let converged = halving_change < 0.05 * smallest_error;
    if converged {
        let points: Vec<Option<Point>> = rows
            .iter()
            .map(|r| {
                Some(Point {
                    cost: r.ms_range?,
                    error: r.error?,
                })
            })
            .collect();
        for i in pareto(&points, halving_change) {
            rows[i].pareto = true;
        }
    }
    Ok((
        Reference {
            scene: case.name.clone(),
            substeps,
            halving_change,
            smallest_error,
            converged,
            milliseconds: reference.milliseconds,
        },
        rows,
    ))
}

/// One configuration's row: its error against `reference` and, when it ran, the median
/// and range of `repeats` timed runs; its energy drift in units of `scale`.
fn measure_one(
    case: &Case,
    config: &Config,
    repeats: usize,
    reference: &Trajectory,
    scale: f64,
) -> Result<Row, ClothError> {
    let run = case.simulate(&config.params)?;
    let errors = run.error_against(reference);
    let (ms_per_second, ms_range) = match errors {
        Some(_) => {
            let mut times = vec![run.milliseconds / case.seconds as f64];
            for _ in 1..repeats.max(1) {
                times.push(case.simulate(&config.params)?.milliseconds / case.seconds as f64);
            }
            let range = times.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &t| {
                (lo.min(t), hi.max(t))
            });
            (Some(super::median(&mut times)), Some(range))
        }
        None => (None, None),
    };
    Ok(Row {
        scene: case.name.clone(),
        model: config.model,
        label: config.label.clone(),
        ms_per_second,
        ms_range,
        substeps: run.mean_substeps,
        error: errors.map(|e| e.0),
        final_error: errors.map(|e| e.1),
        max_strain: run.max_strain,
        energy_drift: errors.map(|_| (run.energy_end as f64 - reference.energy_end as f64) / scale),
        failed_at: run.failed_at,
        pareto: false,
    })
}

/// A measured configuration: its cost as the range of its timed runs, and its error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Fastest and slowest run.
    pub cost: (f64, f64),
    /// Error against the reference.
    pub error: f64,
}

impl Point {
    /// True when `self` is at least as good as `other` in cost and error, and better in
    /// one of them beyond the uncertainty: cost ranges that overlap are equal, and errors
    /// within `uncertainty` (the reference's own) are equal.
    fn dominates(&self, other: &Point, uncertainty: f64) -> bool {
        let cost_no_worse = self.cost.0 <= other.cost.1;
        let cost_better = self.cost.1 < other.cost.0;
        let error_no_worse = self.error <= other.error + uncertainty;
        let error_better = self.error + uncertainty < other.error;
        cost_no_worse && error_no_worse && (cost_better || error_better)
    }
}

/// Indices of the points no other point dominates ([`Point::dominates`]: at least as
/// good in both, better in one beyond the spread of the times and `uncertainty` in the
/// error), cheapest first; `None` points (failed runs) are left out. Two configurations
/// that cannot be told apart are flagged alike.
pub fn pareto(points: &[Option<Point>], uncertainty: f64) -> Vec<usize> {
    let mut out: Vec<usize> = (0..points.len())
        .filter(|&i| {
            let Some(p) = points[i] else { return false };
            !points
                .iter()
                .flatten()
                .any(|q| q.dominates(&p, uncertainty))
        })
        .collect();
    out.sort_by(|&a, &b| {
        let (pa, pb) = (points[a].expect("some"), points[b].expect("some"));
        pa.cost.0.total_cmp(&pb.cost.0)
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(lo: f64, hi: f64, error: f64) -> Option<Point> {
        Some(Point {
            cost: (lo, hi),
            error,
        })
    }

    #[test]
    fn pareto_keeps_points_nothing_beats_in_cost_and_error() {
        let points = [
            point(1.0, 1.1, 0.5),
            point(2.0, 2.1, 0.6), // beaten by the first in both
            point(3.0, 3.1, 0.1),
            None,
            point(0.5, 0.6, 0.9),
            point(3.0, 3.1, 0.2), // same cost as the third, worse error
        ];
        assert_eq!(pareto(&points, 0.0), vec![4, 0, 2]);
    }

    #[test]
    fn pareto_needs_a_difference_beyond_the_spread() {
        // The same simulation timed twice (equal errors, overlapping times): flagged alike,
        // whichever single timing happened to be lower.
        let twins = [point(40.0, 46.0, 0.0165), point(41.0, 45.0, 0.0165)];
        assert_eq!(pareto(&twins, 0.0), vec![0, 1]);
        // A slower run whose times overlap a more accurate one is not beaten on cost.
        let overlap = [point(10.0, 14.0, 0.010), point(12.0, 16.0, 0.020)];
        assert_eq!(pareto(&overlap, 0.0), vec![0]);
        let apart = [point(10.0, 11.0, 0.010), point(5.0, 6.0, 0.020)];
        assert_eq!(pareto(&apart, 0.0), vec![1, 0]);
        // An error gap inside the reference's uncertainty is no gap: the cheaper one wins.
        assert_eq!(pareto(&apart, 0.05), vec![1]);
    }
}
