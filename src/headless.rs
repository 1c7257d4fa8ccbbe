//! Running without a window: a scene's cloths as solvers stepped directly
//! ([`SceneRun`], for the `cloth` command line, tests and measurements), and the
//! plugin in an [`App`] with no window and manual time ([`headless_app`], for App tests
//! and frame timings).

use std::time::Duration;

use bevy::asset::AssetPlugin;
use bevy::mesh::Mesh;
use bevy::platform::time::Instant;
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use serde::Serialize;

use crate::error::ClothError;
use crate::params::{Environment, WindZone};
use crate::scene::ClothScene;
use crate::solver::{self, Collider};
use crate::{ClothBudget, ClothPlugin};

/// What a headless run of a scene did, per cloth.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClothSummary {
    /// The cloth's name in the scene.
    pub name: String,
    /// Particles.
    pub particles: usize,
    /// Acting springs (or part springs for the patch model).
    pub springs: usize,
    /// Substeps of the last step.
    pub substeps: u32,
    /// True when the automatic substeps needed more than their cap (`substeps.max`, or
    /// the work budget `limits::MAX_WORK_PER_STEP`) at the last step: it ran capped.
    pub under_resolved: bool,
    /// Largest structural strain at the end.
    pub max_strain: f32,
    /// Mean |strain| at the end.
    pub mean_strain: f32,
    /// Kinetic energy at the end, J.
    pub kinetic_energy: f32,
    /// Total energy at the start, J.
    pub energy_start: f32,
    /// Total energy at the end, J.
    pub energy_end: f32,
    /// Springs torn.
    pub torn_springs: usize,
    /// Finite everywhere and no spring past 100% strain.
    pub stable: bool,
    /// The most substeps any step took.
    pub most_substeps: u32,
    /// Steps that ran capped (`under_resolved`).
    pub steps_under_resolved: usize,
    /// Steps that gave accuracy to keep to a frame budget (`over_budget`).
    pub steps_over_budget: usize,
    /// The largest structural strain at the end of any step.
    pub largest_strain: f32,
    /// Every step ended finite with no structural spring past [`WHOLE_STRAIN`]: the cloth
    /// held together throughout, as a person looking at it would say.
    pub whole: bool,
}

/// The strain past which a cloth no longer looks like itself, whatever a solver reports:
/// 50%, five times the limit of believable cloth (Provot 1995 takes 10%).
pub const WHOLE_STRAIN: f32 = 0.5;

/// What a run saw of one cloth over all its steps.
#[derive(Clone, Copy, Debug, Default)]
struct Extremes {
    most_substeps: u32,
    steps_under_resolved: usize,
    steps_over_budget: usize,
    largest_strain: f32,
    broken: bool,
}

impl Extremes {
    fn record(&mut self, cloth: &solver::ClothSolver) {
        let report = cloth.last_report();
        self.most_substeps = self.most_substeps.max(report.substeps);
        self.steps_under_resolved += usize::from(report.under_resolved);
        self.steps_over_budget += usize::from(report.over_budget);
        let strain = report.max_strain.unwrap_or_else(|| cloth.strain().max);
        self.largest_strain = self.largest_strain.max(strain);
        // A NaN strain is no number: not whole.
        let within = strain.partial_cmp(&WHOLE_STRAIN).is_some_and(|o| o.is_le());
        self.broken |= !report.finite || !within;
    }
}

/// A headless run: the scene's cloths stepped together.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunSummary {
    /// Steps taken.
    pub steps: usize,
    /// Simulated seconds.
    pub simulated_seconds: f32,
    /// Median wall-clock time of one step of all cloths, ms (of a uniform sample of
    /// `StepTimes::KEPT` steps in longer runs; it varies between identical runs, as do
    /// the two times below, and nothing else).
    pub median_ms_per_step: f64,
    /// The slowest step, ms (it varies between identical runs too).
    pub max_ms_per_step: f64,
    /// The run's time over its particle-substeps (every cloth's particles times its
    /// substeps, summed over the steps), ns: the cost a frame budget plans with
    /// ([`ClothBudget::nanoseconds_per_particle_substep`]).
    pub ns_per_particle_substep: f64,
    /// Per cloth.
    pub cloths: Vec<ClothSummary>,
}

/// A scene's cloths built as solvers, with their colliders, ready to step.
pub struct SceneRun {
    /// `(name, solver)` per cloth.
    pub cloths: Vec<(String, solver::ClothSolver)>,
    /// Gravity and wind.
    pub environment: Environment,
    /// The step, s.
    pub timestep: f32,
    /// The wind zones, on the run's clock.
    pub wind_zones: Vec<WindZone>,
    /// A frame budget shared among the cloths each step as the plugin shares it
    /// ([`ClothBudget::share`], every cloth at priority 1; `max_steps_per_frame` has no
    /// frames here). `None` (the default): accuracy first.
    pub budget: Option<ClothBudget>,
    /// The budget's claims and caps, kept for their storage.
    shares: (Vec<solver::BudgetClaim>, Vec<Option<u32>>),
}

impl SceneRun {
    /// Builds every cloth of `scene` where its frame puts it, with the scene's colliders.
    pub fn new(scene: &ClothScene) -> Result<Self, ClothError> {
        let colliders: Vec<Collider> = scene
            .colliders
            .iter()
            .map(|c| c.collider.to_world(&GlobalTransform::from(c.transform())))
            .collect();
        for zone in &scene.wind_zones {
            zone.validate()?;
        }
        let mut cloths = Vec::with_capacity(scene.cloths.len());
        for entry in &scene.cloths {
            let mut cloth = entry.cloth.build(entry.transform().compute_affine())?;
            cloth.set_colliders(colliders.iter().cloned());
            cloths.push((entry.name.clone(), cloth));
        }
        Ok(Self {
            cloths,
            environment: scene.environment,
            timestep: scene.timestep,
            wind_zones: scene.wind_zones.clone(),
            budget: None,
            shares: Default::default(),
        })
    }

    /// One step of every cloth: the wind zones handed over, cloths in contact met, then
    /// all stepped as the plugin steps them.
    fn step(&mut self) {
        if !self.wind_zones.is_empty() {
            for (_, cloth) in &mut self.cloths {
                let time = cloth.time();
                // Checked in `new`; a zone spoilt since is refused, and said.
                if let Err(e) = cloth.set_wind_zones(&self.wind_zones, time) {
                    warn!("wind zones not taken: {e}");
                }
            }
        }
        if self.cloths.len() > 1 {
            let mut all: Vec<_> = self.cloths.iter_mut().map(|(_, c)| (c, true)).collect();
            solver::collide_cloths(&mut all);
        }
        if let Some(budget) = &self.budget {
            let (claims, caps) = &mut self.shares;
            claims.clear();
            claims.extend(
                self.cloths
                    .iter()
                    .map(|(_, c)| solver::BudgetClaim::of(c, 1.0)),
            );
            budget.share(claims, caps);
            for ((_, cloth), &cap) in self.cloths.iter_mut().zip(caps.iter()) {
                cloth.set_substep_budget(cap);
            }
        }
        // As the plugin steps them: cloths in contact together, the rest side by side.
        let mut all: Vec<_> = self.cloths.iter_mut().map(|(_, c)| (c, true)).collect();
        solver::begin_cloths(&mut all, self.timestep);
        let mut all: Vec<_> = self.cloths.iter_mut().map(|(_, c)| c).collect();
        solver::run_cloths(&mut all, &self.environment);
        for (_, cloth) in &mut self.cloths {
            cloth.end_step();
        }
    }

    /// Runs `steps` steps, calling `each` after every step with the step number (1-based),
    /// and returns the summary.
    pub fn run(
        &mut self,
        steps: usize,
        mut each: impl FnMut(usize, &[(String, solver::ClothSolver)]),
    ) -> RunSummary {
        let env = self.environment;
        let energy_start: Vec<f32> = self
            .cloths
            .iter()
            .map(|(_, c)| c.energy(&env).total())
            .collect();
        // Any number of steps in bounded memory (`--steps` is streamed).
        let mut times = crate::stats::StepTimes::default();
        let (mut slowest, mut total_ms, mut work) = (0.0f64, 0.0f64, 0.0f64);
        let mut extremes = vec![Extremes::default(); self.cloths.len()];
        for step in 1..=steps {
            let start = Instant::now();
            self.step();
            let ms = start.elapsed().as_secs_f64() * 1e3;
            times.push(ms);
            slowest = slowest.max(ms);
            total_ms += ms;
            for ((_, cloth), seen) in self.cloths.iter().zip(&mut extremes) {
                seen.record(cloth);
                work += cloth.particle_count() as f64 * f64::from(cloth.last_report().taken);
            }
            each(step, &self.cloths);
        }
        RunSummary {
            steps,
            simulated_seconds: steps as f32 * self.timestep,
            median_ms_per_step: times.median(),
            max_ms_per_step: slowest,
            ns_per_particle_substep: if work > 0.0 {
                total_ms * 1e6 / work
            } else {
                0.0
            },
            cloths: self
                .cloths
                .iter()
                .zip(energy_start)
                .zip(extremes)
                .map(|(((name, c), energy_start), seen)| {
                    summarise(name, c, &env, energy_start, seen, steps)
                })
                .collect(),
        }
    }
}

/// The app without a window: `MinimalPlugins`, assets (from
/// [`crate::layout::garment::asset_root`]), meshes and `ClothPlugin`, with time advanced by
/// exactly one 16 ms fixed step per `update`. It has no `LogPlugin`: the crate's warnings
/// and refusals (an invalid cloth, a collider left out) print nothing until you add one
/// (`app.add_plugins(bevy::log::LogPlugin::default())`); `ClothInvalid` and the
/// `ClothBecameInvalid` event say the same to code.
pub fn headless_app() -> App {
    headless_app_in(crate::layout::garment::asset_root().to_string_lossy())
}

/// [`headless_app`] with its assets in the folder `assets` (absolute, or relative to
/// where Bevy looks: see [`AssetPlugin::file_path`]). Bevy's `file_watcher` feature
/// makes it hot-reload them.
pub fn headless_app_in(assets: impl Into<String>) -> App {
    let mut app = headless_base_in(assets);
    app.add_plugins(ClothPlugin::default());
    app
}

/// [`headless_app_in`] without `ClothPlugin`: for an app that adds the plugin itself, as
/// a game or a recipe does (its fixed clock already at 16 ms).
pub fn headless_base_in(assets: impl Into<String>) -> App {
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        AssetPlugin {
            file_path: assets.into(),
            ..default()
        },
    ))
    .init_asset::<Mesh>()
    .init_asset::<bevy::mesh::skinning::SkinnedMeshInverseBindposes>()
    .insert_resource(Time::<Fixed>::from_duration(HEADLESS_STEP))
    .insert_resource(TimeUpdateStrategy::ManualDuration(HEADLESS_STEP));
    app
}

/// The headless apps' frame and fixed step.
const HEADLESS_STEP: Duration = Duration::from_millis(16);

/// A cloth's line of the summary: its state now and what the run `seen` of it.
fn summarise(
    name: &str,
    c: &solver::ClothSolver,
    env: &Environment,
    energy_start: f32,
    seen: Extremes,
    steps: usize,
) -> ClothSummary {
    let strain = c.strain();
    let energy = c.energy(env);
    ClothSummary {
        name: name.to_string(),
        particles: c.particle_count(),
        springs: c.spring_count(),
        substeps: c.substeps(),
        under_resolved: c.under_resolved(),
        max_strain: strain.max,
        mean_strain: strain.mean,
        kinetic_energy: energy.kinetic,
        energy_start,
        energy_end: energy.total(),
        torn_springs: c.torn_count(),
        stable: c.is_stable(),
        most_substeps: seen.most_substeps,
        steps_under_resolved: seen.steps_under_resolved,
        steps_over_budget: seen.steps_over_budget,
        largest_strain: seen.largest_strain,
        whole: !seen.broken && steps > 0,
    }
}
