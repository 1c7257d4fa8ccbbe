//! Stepping many cloths at once, one piece of code for the plugin and the headless
//! runner: after [`collide_cloths`](super::collide_cloths), the cloths in contact with
//! one another begin together at one substep count ([`begin_together`]) and take their
//! substeps together, substep by substep, in one task ([`substep_together`]); every
//! other cloth begins alone and takes its substeps in a task of its own, side by side on
//! the compute pool ([`begin_cloths`], [`run_cloths`]). Each cloth's work is the same
//! calls in the same order whatever runs beside it, so the bits do not depend on the
//! pool.

use super::ClothSolver;
use super::self_contact::refresh;
use crate::params::Environment;

/// Begins a step of `dt` for every cloth whose flag is set (a sleeping or paused cloth's
/// is not, and it takes no substeps): those in contact with others together at one
/// substep count, the rest alone. Each cloth's count is then its
/// [`substeps`](ClothSolver::substeps) and its report's.
pub fn begin_cloths(cloths: &mut [(&mut ClothSolver, bool)], dt: f32) {
    let mut touching: Vec<&mut ClothSolver> = Vec::new();
    for (cloth, steps) in cloths.iter_mut() {
        if !*steps {
            continue;
        }
        if cloth.touches_other_cloths() {
            touching.push(cloth);
        } else {
            cloth.begin_step(dt);
        }
    }
    if !touching.is_empty() {
        begin_together(&mut touching, dt);
    }
}

/// Takes the substeps each cloth has left in its step (begun by [`begin_cloths`]): those
/// in contact with others together in one task ([`substep_together`]), every other cloth
/// in a task of its own, on the compute pool (a scope, so the calling thread works
/// beside the pool's).
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
    let mut touching: Vec<&mut ClothSolver> = Vec::new();
    super::task_pool().scope(|scope| {
        for cloth in cloths.iter_mut() {
            let n = left(cloth);
            if n == 0 {
                continue;
            }
            if cloth.touches_other_cloths() {
                touching.push(cloth);
                continue;
            }
            scope.spawn(async move {
                for _ in 0..n {
                    cloth.substep(env);
                }
            });
        }
        if !touching.is_empty() {
            scope.spawn(async move { substep_together(&mut touching, env) });
        }
    });
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
