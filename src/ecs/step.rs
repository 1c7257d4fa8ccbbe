//! Stepping: each fixed step begins every awake cloth's step (its substep count), runs the
//! substeps (the [`ClothSubstep`] schedule, or one task per cloth when no game system
//! sits between its stages), then ends each cloth's step and reports what happened.

use bevy::ecs::schedule::{ScheduleLabel, SingleThreadedExecutor};
use bevy::platform::time::Instant;
use bevy::prelude::*;

use crate::ecs::cloth::{
    ClothEnvironment, ClothInterpolation, ClothInvalid, ClothPause, ClothSimulation, pause_invalid,
};
use crate::ecs::culling::ClothCulling;
use crate::ecs::events::{ClothTeleport, ClothTeleported, ClothTorn};
use crate::ecs::sleep::ClothSleep;
use crate::ecs::stats::ClothStats;
use crate::error::ClothError;
use crate::solver;

/// The ordered system sets of one substep, in the [`ClothSubstep`] schedule only (a
/// system put in them in another schedule would never run with the cloth's substeps,
/// so they are a type of their own).
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ClothSubstepSystems {
    /// [`ClothSolver::accumulate_forces`](crate::solver::ClothSolver::accumulate_forces):
    /// every force from the old state (gravity, wind, drag; springs for mass-spring;
    /// the goal pull for shape matching; for the patch model, the part lattice's forces
    /// and the particles' pull toward their targets). Add forces after this set.
    AccumulateForces,
    /// [`ClothSolver::integrate`](crate::solver::ClothSolver::integrate): the prediction
    /// (Verlet or semi-implicit Euler; XPBD always the latter; the patch model's part
    /// lattice takes its whole substep here first).
    Integrate,
    /// [`ClothSolver::fit_targets`](crate::solver::ClothSolver::fit_targets): shape
    /// matching's velocity update, the patch model's targets (nothing for mass-spring
    /// and XPBD).
    FitTargets,
    /// [`ClothSolver::constrain`](crate::solver::ClothSolver::constrain): pins and grab
    /// driven, the model's constraints (Provot's limit; XPBD's projection and tethers),
    /// contact with the colliders; it ends the substep (the cloth's clock advances).
    Constrain,
}

/// The schedule run once per substep inside
/// [`ClothSystems::Substeps`](crate::ClothSystems::Substeps).
#[derive(ScheduleLabel, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ClothSubstep;

/// How many substeps this fixed step runs (the most any cloth needs) and which one is
/// running; each cloth takes part in the first `n` of them, `n` being its own count.
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct ClothSubstepPlan {
    /// Substeps to run in this step.
    pub count: u32,
    /// The substep running now.
    pub index: u32,
}

/// The [`ClothSubstep`] schedule: the four stages in their sets, in order, on one thread
/// (each stage runs its cloths in parallel itself).
pub(crate) fn substep_schedule() -> Schedule {
    let mut substep = Schedule::new(ClothSubstep);
    substep.set_executor(SingleThreadedExecutor::new());
    substep.configure_sets(
        (
            ClothSubstepSystems::AccumulateForces,
            ClothSubstepSystems::Integrate,
            ClothSubstepSystems::FitTargets,
            ClothSubstepSystems::Constrain,
        )
            .chain(),
    );
    substep.add_systems((
        accumulate_forces.in_set(ClothSubstepSystems::AccumulateForces),
        integrate.in_set(ClothSubstepSystems::Integrate),
        fit_targets.in_set(ClothSubstepSystems::FitTargets),
        constrain.in_set(ClothSubstepSystems::Constrain),
    ));
    substep
}

/// Per-cloth bookkeeping of the step in progress.
#[derive(Component, Clone, Copy, Debug, Default)]
pub(crate) struct StepProgress {
    /// Substeps this cloth takes in this step (0: it does not step).
    pub(crate) substeps: u32,
}

/// A cloth paused because a step went non-finite runs again once it has been reset
/// (its last report is no longer a failure); a valid change of its parameters lifts
/// the pause too (`apply_params`).
pub(crate) fn recover_cloths(
    mut commands: Commands,
    cloths: Query<(Entity, &ClothSimulation, &ClothInvalid)>,
) {
    for (entity, sim, invalid) in &cloths {
        if matches!(invalid.0, ClothError::NonFinite { .. }) && sim.solver.last_report().finite {
            commands.entity(entity).remove::<ClothInvalid>();
        }
    }
}

/// Hands each [`ClothTeleport`] to its cloth's solver (before the sleeping cloths are
/// woken: the request wakes its cloth).
pub(crate) fn request_teleports(
    mut messages: MessageReader<ClothTeleport>,
    mut cloths: Query<&mut ClothSimulation>,
) {
    for message in messages.read() {
        match cloths.get_mut(message.cloth) {
            Ok(mut sim) => sim.solver.teleport_next_step(message.mode),
            Err(_) => warn!(
                "ClothTeleport for {}, which is not a built cloth: ignored",
                message.cloth
            ),
        }
    }
}

#[allow(clippy::type_complexity)]
pub(crate) fn begin_steps(
    mut commands: Commands,
    time: Res<Time>,
    mut pause: ResMut<ClothPause>,
    mut plan: ResMut<ClothSubstepPlan>,
    interpolation: Option<Res<ClothInterpolation>>,
    mut cloths: Query<
        (
            Entity,
            &mut ClothSimulation,
            Option<&mut StepProgress>,
            (Option<&ClothSleep>, Option<&ClothCulling>),
        ),
        Without<ClothInvalid>,
    >,
) {
    let dt = time.delta_secs();
    let interpolate = interpolation.is_some_and(|i| i.0);
    let run = !pause.paused || pause.pending_steps > 0;
    if pause.paused && run {
        pause.pending_steps -= 1;
    }
    plan.count = 0;
    plan.index = 0;
    // Which cloths step (not paused, not asleep).
    let mut all = Vec::new();
    for (entity, mut sim, progress, (sleep, culling)) in &mut cloths {
        let steps = run && sleep.is_none_or(|s| !s.asleep) && culling.is_none_or(|c| !c.culled);
        // Where the step begins, kept only when the mesh is drawn between steps.
        sim.note_step(steps && interpolate);
        all.push((entity, sim, progress, steps));
    }
    let mut solvers: Vec<_> = all
        .iter_mut()
        .map(|(_, sim, _, steps)| (&mut sim.solver, *steps))
        .collect();
    // Cloth–cloth contact: the cloths with self-collision on take each other's
    // particles near them (a sleeping cloth's stay where they are). With one such cloth
    // left it still runs, so a copy of a cloth since despawned or switched off is dropped.
    if solvers
        .iter()
        .any(|(s, _)| s.params().self_collision.enabled)
    {
        solver::collide_cloths(&mut solvers);
    }
    // Cloths in contact with others begin together at one substep count, the rest alone
    // (`solver::begin_cloths`, as the headless runner does); a sleeping cloth not at all.
    solver::begin_cloths(&mut solvers, dt);
    for (entity, sim, progress, steps) in all {
        let substeps = if steps { sim.solver.substeps() } else { 0 };
        let now = StepProgress { substeps };
        match progress {
            Some(mut p) => *p = now,
            None => {
                commands.entity(entity).insert(now);
            }
        }
        plan.count = plan.count.max(substeps);
    }
}

/// Whether every system of the [`ClothSubstep`] schedule is one of the plugin's own four
/// (`substep_schedule`'s, one per stage), told by their types: then the stages can run
/// in one pass over the cloths. `false` before the schedule has first run (it is not
/// initialised until then), which runs the schedule: always right, only slower.
fn only_own_substep_systems(schedule: &Schedule) -> bool {
    static OWN: std::sync::OnceLock<[std::any::TypeId; 4]> = std::sync::OnceLock::new();
    let own = OWN.get_or_init(|| {
        let id = |system: &dyn System<In = (), Out = ()>| system.system_type();
        [
            id(&IntoSystem::into_system(accumulate_forces)),
            id(&IntoSystem::into_system(integrate)),
            id(&IntoSystem::into_system(fit_targets)),
            id(&IntoSystem::into_system(constrain)),
        ]
    });
    schedule
        .systems()
        .is_ok_and(|mut systems| systems.all(|(_, system)| own.contains(&system.system_type())))
}

/// Runs the step's substeps. When a game has put systems between the stages
/// ([`ClothSubstepSystems`]), every substep runs the [`ClothSubstep`] schedule, each
/// stage over all cloths in parallel. Otherwise each cloth takes all its substeps in one
/// task on the compute pool: the same calls in the same order per cloth (the same bits),
/// one fork-join per step instead of four per substep, which is what many small cloths
/// cost most.
pub(crate) fn run_substeps(
    world: &mut World,
    mut cloths: Local<Option<QueryState<ActiveCloth, Without<ClothInvalid>>>>,
) {
    let count = world.resource::<ClothSubstepPlan>().count;
    if count == 0 {
        return;
    }
    let schedules = world.resource::<Schedules>();
    let others = !schedules
        .get(ClothSubstep)
        .is_some_and(only_own_substep_systems);
    if others {
        for index in 0..count {
            world.resource_mut::<ClothSubstepPlan>().index = index;
            world.run_schedule(ClothSubstep);
        }
        return;
    }
    let env = **world.resource::<ClothEnvironment>();
    let cloths = cloths.get_or_insert_with(|| world.query_filtered());
    // The solver's pool (`solver::run_cloths`), not `Query::par_iter_mut`: on two cores
    // Bevy gives its compute pool one thread, and `par_iter_mut` then runs on the calling
    // thread alone; a scope has the calling thread work beside the pool's.
    let mut active: Vec<_> = cloths.iter_mut(world).collect();
    let mut solvers: Vec<_> = active.iter_mut().map(|(sim, _)| &mut sim.solver).collect();
    solver::run_cloths(&mut solvers, &env);
}

/// A cloth that takes part in the step, and how many substeps it takes (each stage times
/// itself into the cloth's report).
type ActiveCloth = (&'static mut ClothSimulation, &'static StepProgress);

/// Runs one solver phase on every cloth that takes part in the current substep, in
/// parallel.
fn for_each_active(
    plan: &ClothSubstepPlan,
    cloths: &mut Query<(&mut ClothSimulation, &StepProgress), Without<ClothInvalid>>,
    phase: impl Fn(&mut solver::ClothSolver) + Sync + Send,
) {
    cloths.par_iter_mut().for_each(|(mut sim, progress)| {
        if plan.index < progress.substeps {
            phase(&mut sim.solver);
        }
    });
}

type ActiveCloths<'w, 's> = Query<'w, 's, ActiveCloth, Without<ClothInvalid>>;

fn accumulate_forces(
    plan: Res<ClothSubstepPlan>,
    env: Res<ClothEnvironment>,
    mut cloths: ActiveCloths,
) {
    for_each_active(&plan, &mut cloths, |c| c.accumulate_forces(&env));
}

fn integrate(plan: Res<ClothSubstepPlan>, mut cloths: ActiveCloths) {
    for_each_active(&plan, &mut cloths, solver::ClothSolver::integrate);
}

fn fit_targets(plan: Res<ClothSubstepPlan>, mut cloths: ActiveCloths) {
    for_each_active(&plan, &mut cloths, solver::ClothSolver::fit_targets);
}

fn constrain(plan: Res<ClothSubstepPlan>, mut cloths: ActiveCloths) {
    // Cloth–cloth contact keeps apart from where the other cloths are now.
    if cloths
        .iter()
        .any(|(sim, _)| sim.solver.touches_other_cloths())
    {
        let mut all: Vec<_> = cloths.iter_mut().map(|(sim, _)| sim).collect();
        let mut solvers: Vec<_> = all.iter_mut().map(|sim| &mut sim.solver).collect();
        solver::exchange_cloths(&mut solvers);
    }
    for_each_active(&plan, &mut cloths, solver::ClothSolver::constrain);
}

#[allow(clippy::type_complexity)]
pub(crate) fn finish_steps(
    mut commands: Commands,
    mut torn: MessageWriter<ClothTorn>,
    env: Res<ClothEnvironment>,
    mut cloths: Query<
        (
            Entity,
            &mut ClothSimulation,
            &StepProgress,
            Option<&mut ClothStats>,
        ),
        Without<ClothInvalid>,
    >,
) {
    // Each cloth's end of step (its finiteness check, checkpoint and tears) is its own:
    // side by side over the pool, as its substeps were; then what it tells the app, one
    // cloth after another (commands and messages are one resource).
    let mut ended: Vec<_> = cloths
        .iter_mut()
        .filter(|(_, _, progress, _)| progress.substeps > 0)
        .map(|(entity, sim, _, stats)| (entity, sim, stats, solver::StepReport::default()))
        .collect();
    let each = ended
        .iter_mut()
        .map(|e| (e.1.solver.particle_count() as u64, e));
    solver::share_items(each, |(_, sim, _, report)| *report = sim.solver.end_step());
    for (entity, mut sim, stats, report) in ended {
        let sim = &mut *sim;
        let start = Instant::now();
        if !report.finite {
            let error = ClothError::NonFinite {
                time: sim.solver.time(),
                substeps: report.substeps,
            };
            pause_invalid(&mut commands, entity, error);
            sim.mesh_dirty = true;
            continue;
        }
        if let Some(jump) = report.teleported {
            announce_teleport(&mut commands, entity, sim, jump);
        }
        for &spring in sim.solver.last_torn() {
            let s = spring as usize;
            let particles = [sim.solver.springs().a[s], sim.solver.springs().b[s]];
            let event = ClothTorn {
                cloth: entity,
                spring,
                particles,
            };
            torn.write(event);
            commands.trigger(event);
        }
        // The solver's own time for the step (each stage times itself) and this system's.
        sim.last_step_ms = (report.time.total() + start.elapsed()).as_secs_f32() * 1e3;
        sim.mesh_dirty = true;
        if let Some(mut stats) = stats {
            stats.record(&sim.solver, &env, sim.last_step_ms);
        }
    }
}

/// A teleport the step began with: the mesh drawn between steps from the carried start
/// (no streak across the jump), a debug line and [`ClothTeleported`] on the cloth.
fn announce_teleport(
    commands: &mut Commands,
    entity: Entity,
    sim: &mut ClothSimulation,
    jump: solver::Teleported,
) {
    for x in &mut sim.previous {
        *x = jump.by.apply(*x);
    }
    debug!(
        "{entity} teleported ({:?}): {:.2} m, {:.0}°",
        jump.mode,
        jump.distance,
        jump.angle.to_degrees()
    );
    commands.trigger(ClothTeleported {
        entity,
        mode: jump.mode,
        distance: jump.distance,
        angle: jump.angle,
    });
}
