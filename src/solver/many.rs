//! Stepping many cloths at once, one piece of code for the plugin and the headless
//! runner: after [`collide_cloths`](super::collide_cloths), the cloths in contact with
//! one another begin together at one substep count ([`begin_together`]) and take their
//! substeps together, substep by substep, in one task ([`substep_together`]); every
//! other cloth begins alone and takes its substeps in a task of its own, side by side on
//! the compute pool ([`begin_cloths`], [`run_cloths`]). Each cloth's work is the same
//! calls in the same order whatever runs beside it, so the bits do not depend on the
//! pool.

use super::ClothSolver;
use super::parallel::share_items;
use super::self_contact::refresh;
use crate::params::Environment;

/// Begins a step of `dt` for every cloth whose flag is set (a sleeping or paused cloth's
/// is not, and it takes no substeps): those in contact with others together at one
/// substep count, the rest alone. Each cloth's count is then its
/// [`substeps`](ClothSolver::substeps) and its report's.
pub fn begin_cloths(cloths: &mut [(&mut ClothSolver, bool)], dt: f32) {
    let alone = |(cloth, steps): &(&mut ClothSolver, bool)| *steps && !cloth.touches_other_cloths();
    // Each cloth's plan (its drivers, teleports, the wind at its particles, its model's
    // state and substeps) is its own: side by side, as the substeps are. Planned one
    // after another, they were an eighth of a crowd's step on two cores.
    let plans = cloths
        .iter_mut()
        .filter(|c| alone(c))
        .map(|(cloth, _)| (cloth.particle_count() as u64, &mut **cloth));
    share_items(plans, |cloth| {
        cloth.begin_step(dt);
    });
    let mut touching: Vec<&mut ClothSolver> = cloths
        .iter_mut()
        .filter(|(cloth, steps)| *steps && cloth.touches_other_cloths())
        .map(|(cloth, _)| &mut **cloth)
        .collect();
    if !touching.is_empty() {
        begin_together(&mut touching, dt);
    }
}

/// Takes the substeps each cloth has left in its step (begun by [`begin_cloths`]): those
/// in contact with others together ([`substep_together`]), every other cloth alone, the
/// work shared among the threads (`share_items`: the largest first by particles ×
/// substeps, each thread taking the next cloth when done with its last): one task a
/// thread on the compute pool (the calling thread working beside its threads). With 20
/// small cloths one task per cloth left the two cores at 1.15× one; one task a thread,
/// 1.8×.
/// One thread ([`set_parallel`](super::set_parallel)`(false)`) runs them all here, those
/// in contact last.
pub fn run_cloths(cloths: &mut [&mut ClothSolver], env: &Environment) {
    let left = |c: &ClothSolver| c.report.substeps.saturating_sub(c.report.taken);
    if cloths.iter().filter(|c| left(c) > 0).count() <= 1 {
        // One cloth at work: on this thread (its own kernels use the pool).
        for cloth in cloths.iter_mut() {
            for _ in 0..left(cloth) {
                cloth.substep(env);
            }
        }
        return;
    }
    let mut units: Vec<(u64, Unit)> = Vec::new();
    let mut touching: Vec<&mut ClothSolver> = Vec::new();
    for cloth in cloths.iter_mut() {
        let n = left(cloth);
        if n == 0 {
            continue;
        }
        if cloth.touches_other_cloths() {
            touching.push(cloth);
        } else {
            units.push((work(cloth, n), Unit::Alone(cloth, n)));
        }
    }
    if !touching.is_empty() {
        let w = touching.iter().map(|c| work(c, left(c))).sum();
        units.push((w, Unit::Together(touching)));
    }
    share_items(units.into_iter(), |unit| run_unit(unit, env));
}

/// What one cloth (or the cloths in contact, together) has left of its step, as work.
enum Unit<'a> {
    Alone(&'a mut ClothSolver, u32),
    Together(Vec<&'a mut ClothSolver>),
}

/// The work of `n` substeps of `cloth`: its particles times `n`.
fn work(cloth: &ClothSolver, n: u32) -> u64 {
    cloth.particle_count() as u64 * n as u64
}

/// Runs a unit's substeps.
fn run_unit(unit: Unit, env: &Environment) {
    match unit {
        Unit::Alone(cloth, n) => {
            for _ in 0..n {
                cloth.substep(env);
            }
        }
        Unit::Together(mut cloths) => substep_together(&mut cloths, env),
    }
}

/// Begins a step of `dt` for cloths in contact with one another
/// ([`collide_cloths`](super::collide_cloths)): each plans its step, and all take the
/// most substeps any of them needs, so that they meet substep by substep at the same
/// times ([`substep_together`]). Returns that count.
/// Three self-colliding cloths stacked on a cushion, each at its own count (64, 55 and
/// 22), met at times that did not line up and jittered at 0.28 m/s when solved along
/// lines (`assets/scenes/stack.ron`); at one count they come to rest.
pub fn begin_together(cloths: &mut [&mut ClothSolver], dt: f32) -> u32 {
    let n = cloths
        .iter_mut()
        .map(|c| c.plan_step(dt))
        .max()
        .unwrap_or(0);
    for cloth in cloths {
        cloth.start_substeps(dt, n);
    }
    n
}

/// Runs the substeps of cloths in contact with one another, begun together
/// ([`begin_together`]): every substep, all take their forces, prediction and targets,
/// then each one's copy of the others is refreshed, then each projects its constraints:
/// the order the plugin's stage-by-stage path runs (the same bits). With the others one
/// step old, as when each cloth takes its step alone, three cloths stacked on a cushion
/// jittered by up to 1 m/s for as long as they lay there (`assets/scenes/stack.ron`); so,
/// they come to rest. A cloth that was not begun (0 substeps) takes none.
pub fn substep_together(cloths: &mut [&mut ClothSolver], env: &Environment) {
    let due = |c: &ClothSolver| c.report.taken < c.report.substeps;
    while cloths.iter().any(|c| due(c)) {
        for cloth in cloths.iter_mut().filter(|c| due(c)) {
            cloth.accumulate_forces(env);
            cloth.integrate();
            cloth.fit_targets();
        }
        for c in 0..cloths.len() {
            if due(cloths[c]) {
                refresh(cloths, c);
            }
        }
        for cloth in cloths.iter_mut().filter(|c| due(c)) {
            cloth.constrain();
        }
    }
}
