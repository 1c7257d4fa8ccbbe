//! The frame budget: the time all cloths may take in one fixed step, shared out among
//! them ([`ClothBudget`], [`ClothPriority`]); a cap on the fixed steps cloths take in one
//! rendered frame, so a slow frame does not start a spiral; what the whole cloth stage
//! cost ([`ClothStageStats`], and Bevy diagnostics under `cloth/`); and an event and a
//! warning when a cloth goes over its share and when it comes back.

use bevy::diagnostic::{Diagnostic, DiagnosticPath, Diagnostics, RegisterDiagnostic};
use bevy::platform::time::Instant;
use bevy::prelude::*;

use crate::ecs::cloth::{ClothInvalid, ClothSimulation, Named};
use crate::ecs::culling::ClothCulling;
use crate::ecs::plugin::{ClothPrepareSystems, ClothSchedule, ClothSystems};
use crate::ecs::sleep::ClothSleep;
use crate::ecs::step::{StepProgress, begin_steps};
use crate::error::ClothError;
use crate::params::check;
use crate::solver::{BudgetClaim, StepReport, gives_way, share_budget};

/// What the cloths may cost, a resource: the plugin shares `milliseconds` of each fixed
/// step among the cloths that step (by [`ClothPriority`] when it is short), no cloth
/// taking more than `per_cloth_milliseconds`, and steps cloths at most
/// `max_steps_per_frame` times in one rendered frame.
///
/// Only XPBD at automatic substeps is capped: it stays finite at any substep count, so
/// what a smaller count gives is accuracy: the cloth stretches past its target
/// ([`StepReport::over_budget`](crate::solver::StepReport), `docs/features.md` has what
/// the flag gives at each wind).
/// The explicit models (mass-spring, shape matching, patches) keep the substeps their
/// stability needs, and a fixed count is the cloth's own; both are counted against the
/// budget first. And the budget gives way before a cloth does: one whose last step ended
/// past [`GIVE_WAY_STRAIN`](crate::solver::GIVE_WAY_STRAIN) (25%) takes what its
/// accuracy asks for in its next step, and counts as over budget until it is back within
/// both.
///
/// Time becomes work through a planned cost a particle-substep
/// (`nanoseconds_per_particle_substep`), so the caps are the same on every machine and
/// thread count and a run is repeatable; [`ClothStageStats`] says what the stage really
/// cost, and `cloth run` prints the cost a particle-substep of a scene.
///
/// The default is one a game can ship: 4 ms a step for all cloths (a quarter of a
/// 60 Hz frame), no cap of any one's own, and every step `Time<Fixed>` runs. A cap on
/// steps a frame (Magica Cloth 2 defaults to three) is there to ask for, not the
/// default: a cloth that skips steps its bodies take is left behind by them (the cape
/// on the avian runner, drawn by software at several fixed steps a frame, was left out
/// of the camera's view at three). A cap of 1 ms for one cloth (7 substeps of the 651-particle
/// flag) let the flag stretch 64% in 5 m/s gusts; at the whole 4 ms (30 substeps), 14%. [`ClothBudget::UNLIMITED`] puts accuracy first, as the `cloth`
/// command line does.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Resource, Debug, Default, PartialEq)]
pub struct ClothBudget {
    /// Milliseconds all cloths may take in one fixed step (`None`: no shared budget).
    pub milliseconds: Option<f32>,
    /// Milliseconds any one cloth may take in one fixed step (`None`: no cap of its own).
    pub per_cloth_milliseconds: Option<f32>,
    /// The planned cost of one particle in one substep, ns (`cloth run` prints a
    /// scene's). On one core of the 2-core machine the docs measure on, XPBD with a
    /// fabric's bending and air on its triangles: the polyester flag
    /// (`assets/scenes/flag.ron`) 185–212 ns, the denim curtain about 110.
    pub nanoseconds_per_particle_substep: f32,
    /// The most fixed steps the cloths take in one rendered frame (`None`: as many as
    /// `Time<Fixed>` runs). Steps past it are skipped: the cloths slow down for that
    /// frame instead of making the next one slower still.
    pub max_steps_per_frame: Option<u32>,
}

impl Default for ClothBudget {
    fn default() -> Self {
        ClothBudget {
            milliseconds: Some(4.0),
            per_cloth_milliseconds: None,
            nanoseconds_per_particle_substep: 200.0,
            max_steps_per_frame: None,
        }
    }
}

impl ClothBudget {
    /// No budget: every cloth takes the substeps its accuracy asks for (up to its own
    /// `substeps.max`), every step `Time<Fixed>` runs.
    pub const UNLIMITED: ClothBudget = ClothBudget {
        milliseconds: None,
        per_cloth_milliseconds: None,
        nanoseconds_per_particle_substep: 200.0,
        max_steps_per_frame: None,
    };

    /// Checks every value: times and the planned cost above 0 and finite, at least one
    /// step a frame.
    pub fn validate(&self) -> Result<(), ClothError> {
        for (field, ms) in [
            ("budget.milliseconds", self.milliseconds),
            ("budget.per_cloth_milliseconds", self.per_cloth_milliseconds),
        ] {
            if let Some(ms) = ms {
                check(field, ms, ms > 0.0, "a time above 0 ms")?;
            }
        }
        let ns = self.nanoseconds_per_particle_substep;
        check(
            "budget.nanoseconds_per_particle_substep",
            ns,
            ns > 0.0,
            "a cost above 0 ns",
        )?;
        if self.max_steps_per_frame == Some(0) {
            return Err(ClothError::InvalidParameter {
                field: "budget.max_steps_per_frame",
                value: 0.0,
                expected: "at least 1 step".into(),
            });
        }
        Ok(())
    }

    /// Particle-substeps that `ms` buys at the planned cost.
    fn work(&self, ms: f32) -> f64 {
        f64::from(ms) * 1e6 / f64::from(self.nanoseconds_per_particle_substep)
    }

    /// Each claim's cap on its substeps (`None`: not capped), in order: its share of
    /// `milliseconds` ([`share_budget`]), at most `per_cloth_milliseconds`' worth. The
    /// plugin and the headless runner share out the same way.
    pub fn share(&self, claims: &[BudgetClaim], caps: &mut Vec<Option<u32>>) {
        match self.milliseconds {
            Some(ms) => share_budget(claims, self.work(ms), caps),
            None => {
                caps.clear();
                caps.resize(claims.len(), None);
            }
        }
        let Some(own) = self.per_cloth_milliseconds.map(|ms| self.work(ms)) else {
            return;
        };
        for (claim, cap) in claims.iter().zip(caps.iter_mut()) {
            if claim.cappable {
                let most = (own / claim.particles.max(1) as f64).floor();
                let most = most.clamp(1.0, u32::MAX as f64) as u32;
                *cap = Some(cap.map_or(most, |c| c.min(most)));
            }
        }
    }

    /// The planned cost of `claims` at `caps`, ms: each cloth's particles times the
    /// smaller of its cap and its need.
    pub fn planned_ms(&self, claims: &[BudgetClaim], caps: &[Option<u32>]) -> f32 {
        let work: f64 = claims
            .iter()
            .zip(caps)
            .map(|(c, cap)| {
                let needed = c.needed.max(1);
                c.particles as f64 * f64::from(cap.map_or(needed, |cap| cap.min(needed)))
            })
            .sum();
        (work * f64::from(self.nanoseconds_per_particle_substep) * 1e-6) as f32
    }
}

/// A cloth's weight when the budget is short: 2 takes twice the share of 1 (the
/// default, for a cloth without one). Give the hero's cape a higher one than the crowd's.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component, Debug, Default, PartialEq)]
pub struct ClothPriority(pub f32);

impl Default for ClothPriority {
    fn default() -> Self {
        ClothPriority(1.0)
    }
}

/// A cloth needed more substeps than its share of the budget allowed, triggered on its
/// entity at the first such step (and logged as a warning); it gives accuracy until
/// [`ClothWithinBudget`].
#[derive(EntityEvent, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Debug, PartialEq)]
pub struct ClothOverBudget {
    /// The cloth entity.
    pub entity: Entity,
    /// The substeps its accuracy target asked for.
    pub needed: u32,
    /// The substeps it took.
    pub allowed: u32,
    /// The largest stretch its constraints left (0.02: 2%).
    pub strain: f32,
}

/// A cloth over its budget ([`ClothOverBudget`]) took what its accuracy asked for again.
#[derive(EntityEvent, Clone, Copy, Debug, PartialEq, Eq, Reflect)]
#[reflect(Debug, PartialEq)]
pub struct ClothWithinBudget {
    /// The cloth entity.
    pub entity: Entity,
}

/// What the whole cloth stage cost in the last fixed step, a resource: the work cloths
/// in contact share and the plugin's own systems included, which the cloths'
/// [`ClothStats`](crate::ClothStats) do not count.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Resource, Debug, Default, PartialEq)]
pub struct ClothStageStats {
    /// Wall time of the cloth stage (from the first system of
    /// [`ClothSystems::Prepare`] to the last of [`ClothSystems::Finish`]), ms.
    pub step_ms: f32,
    /// What the budget planned the cloths' substeps to cost, ms.
    pub planned_ms: f32,
    /// The most substeps a cloth took.
    pub most_substeps: u32,
    /// Cloths that stepped.
    pub cloths: usize,
    /// Cloths that gave accuracy to keep to their budget.
    pub over_budget: usize,
    /// Fixed steps the cloths skipped since the app started, past
    /// [`ClothBudget::max_steps_per_frame`].
    pub skipped_steps: u64,
    /// Fixed steps the cloths took in the current frame.
    pub steps_this_frame: u32,
}

/// The diagnostics the budget plugin measures each fixed step (print them with Bevy's
/// `LogDiagnosticsPlugin`).
impl ClothStageStats {
    /// The whole cloth stage's wall time, ms.
    pub const STEP_MS: DiagnosticPath = DiagnosticPath::const_new("cloth/step_ms");
    /// The most substeps any cloth took.
    pub const SUBSTEPS: DiagnosticPath = DiagnosticPath::const_new("cloth/substeps");
    /// Cloths over their budget.
    pub const OVER_BUDGET: DiagnosticPath = DiagnosticPath::const_new("cloth/over_budget");
    /// Fixed steps skipped since the start, past the cap a frame.
    pub const SKIPPED_STEPS: DiagnosticPath = DiagnosticPath::const_new("cloth/skipped_steps");
}

/// Whether a cloth is over its budget now (the plugin's, for the events on change).
#[derive(Component, Clone, Copy, Debug, Default)]
pub(crate) struct OverBudget(bool);

/// When the stage began, and the budget last refused (said once).
#[derive(Resource, Default)]
struct StageClock {
    began: Option<Instant>,
    refused: Option<ClothBudget>,
}

/// The frame budget ([`ClothBudget`]), the stage's cost ([`ClothStageStats`] and the
/// `cloth/` diagnostics) and the over-budget events. In [`ClothPlugin`](crate::ClothPlugin);
/// left out, nothing is capped.
pub struct ClothBudgetPlugin;

impl Plugin for ClothBudgetPlugin {
    fn build(&self, app: &mut App) {
        let schedule = ClothSchedule::of(app);
        app.init_resource::<ClothBudget>()
            .init_resource::<ClothStageStats>()
            .init_resource::<StageClock>()
            .register_type::<ClothBudget>()
            .register_type::<ClothPriority>()
            .register_type::<ClothStageStats>()
            .register_type::<ClothOverBudget>()
            .register_type::<ClothWithinBudget>()
            .register_diagnostic(Diagnostic::new(ClothStageStats::STEP_MS).with_suffix(" ms"))
            .register_diagnostic(Diagnostic::new(ClothStageStats::SUBSTEPS))
            .register_diagnostic(Diagnostic::new(ClothStageStats::OVER_BUDGET))
            .register_diagnostic(Diagnostic::new(ClothStageStats::SKIPPED_STEPS))
            .add_systems(First, new_frame)
            .configure_sets(
                schedule,
                (
                    ClothSystems::Prepare,
                    ClothSystems::Substeps,
                    ClothSystems::Finish,
                )
                    .run_if(frame_allows_step),
            )
            .add_systems(
                schedule,
                (
                    start_stage
                        .in_set(ClothSystems::Prepare)
                        .before(ClothPrepareSystems::Levels),
                    share_out
                        .in_set(ClothPrepareSystems::Begin)
                        .before(begin_steps),
                    end_stage
                        .after(ClothSystems::Finish)
                        .run_if(frame_allows_step),
                    count_skipped
                        .after(ClothSystems::Finish)
                        .run_if(not(frame_allows_step)),
                ),
            );
    }
}

/// The budget when it is valid; a refused one is said once and caps nothing.
fn valid_budget(budget: &ClothBudget, clock: &mut StageClock) -> Option<ClothBudget> {
    match budget.validate() {
        Ok(()) => {
            clock.refused = None;
            Some(*budget)
        }
        Err(e) => {
            if clock.refused != Some(*budget) {
                error!("ClothBudget refused, nothing is capped until it is mended: {e}");
                clock.refused = Some(*budget);
            }
            None
        }
    }
}

fn new_frame(mut stats: ResMut<ClothStageStats>) {
    stats.steps_this_frame = 0;
}

/// Whether the cloths step in this fixed step: fewer than the cap a frame so far.
fn frame_allows_step(budget: Res<ClothBudget>, stats: Res<ClothStageStats>) -> bool {
    match budget.max_steps_per_frame {
        Some(most) if most > 0 => stats.steps_this_frame < most,
        _ => true,
    }
}

fn start_stage(mut clock: ResMut<StageClock>) {
    clock.began = Some(Instant::now());
}

fn count_skipped(mut stats: ResMut<ClothStageStats>) {
    stats.skipped_steps += 1;
}

/// Each cloth about to step gets its cap: its share of the budget, from the substeps its
/// last step needed (`solver::share_budget`).
#[allow(clippy::type_complexity)]
fn share_out(
    budget: Res<ClothBudget>,
    mut clock: ResMut<StageClock>,
    mut stats: ResMut<ClothStageStats>,
    mut cloths: Query<
        (
            &mut ClothSimulation,
            Option<&ClothPriority>,
            (Option<&ClothSleep>, Option<&ClothCulling>),
        ),
        Without<ClothInvalid>,
    >,
    mut claims: Local<Vec<BudgetClaim>>,
    mut caps: Local<Vec<Option<u32>>>,
) {
    let budget = valid_budget(&budget, &mut clock);
    let stepping = |(sleep, culling): (Option<&ClothSleep>, Option<&ClothCulling>)| {
        sleep.is_none_or(|s| !s.asleep) && culling.is_none_or(|c| !c.culled)
    };
    claims.clear();
    for (sim, priority, rest) in &cloths {
        if stepping(rest) {
            claims.push(BudgetClaim::of(&sim.solver, priority.map_or(1.0, |p| p.0)));
        }
    }
    match budget {
        Some(b) => {
            b.share(&claims, &mut caps);
            stats.planned_ms = b.planned_ms(&claims, &caps);
        }
        None => {
            caps.clear();
            caps.resize(claims.len(), None);
            stats.planned_ms = 0.0;
        }
    }
    let mut caps = caps.iter();
    for (mut sim, _, rest) in &mut cloths {
        if stepping(rest) {
            sim.solver
                .set_substep_budget(caps.next().copied().flatten());
        }
    }
}

/// A cloth's crossing of its budget, either way: the event on its entity and a log line
/// (`was`: it was over before this step).
fn announce(commands: &mut Commands, who: Named, report: &StepReport, (was, now): (bool, bool)) {
    let entity = who.0;
    if now && !was {
        let strain = report.solver_strain.or(report.max_strain).unwrap_or(0.0);
        warn!(
            "{who} is over its cloth budget: its accuracy asks for {} substeps, it takes {} \
             (its stretch {:.1}%); raise ClothBudget or its ClothPriority to give it more",
            report.needed,
            report.substeps,
            strain * 100.0
        );
        commands.trigger(ClothOverBudget {
            entity,
            needed: report.needed,
            allowed: report.substeps,
            strain,
        });
    } else if !now && was {
        info!("{who} is within its cloth budget again");
        commands.trigger(ClothWithinBudget { entity });
    }
}

/// The stage's cost and counts, the diagnostics, and the events of the cloths that went
/// over their budget or came back.
#[allow(clippy::type_complexity)]
fn end_stage(
    mut commands: Commands,
    mut clock: ResMut<StageClock>,
    mut stats: ResMut<ClothStageStats>,
    mut diagnostics: Diagnostics,
    mut cloths: Query<(
        Entity,
        &ClothSimulation,
        &StepProgress,
        Option<&mut OverBudget>,
        Option<&Name>,
    )>,
) {
    let (mut most, mut count, mut over) = (0u32, 0usize, 0usize);
    for (entity, sim, progress, state, name) in &mut cloths {
        if progress.substeps == 0 {
            continue;
        }
        let report = sim.solver.last_report();
        most = most.max(report.substeps);
        count += 1;
        over += usize::from(report.over_budget);
        let was = state.as_ref().is_some_and(|s| s.0);
        // A cloth over budget that the budget gave way to (its strain past
        // `GIVE_WAY_STRAIN`, uncapped for a step) is still in trouble: not within again.
        let now = report.over_budget || (was && gives_way(&sim.solver));
        announce(&mut commands, Named(entity, name), &report, (was, now));
        match state {
            Some(mut s) => s.0 = now,
            None => {
                commands.entity(entity).insert(OverBudget(now));
            }
        }
    }
    let step_ms = clock
        .began
        .take()
        .map_or(0.0, |t| t.elapsed().as_secs_f32() * 1e3);
    stats.step_ms = step_ms;
    stats.most_substeps = most;
    stats.cloths = count;
    stats.over_budget = over;
    stats.steps_this_frame += 1;
    diagnostics.add_measurement(&ClothStageStats::STEP_MS, || f64::from(step_ms));
    diagnostics.add_measurement(&ClothStageStats::SUBSTEPS, || f64::from(most));
    diagnostics.add_measurement(&ClothStageStats::OVER_BUDGET, || over as f64);
    diagnostics.add_measurement(&ClothStageStats::SKIPPED_STEPS, || {
        stats.skipped_steps as f64
    });
}
