//! The fast paths against the general ones: the grid stencil, the coloured limiter, XPBD
//! on the stencil, symmetry kept, the same bits on one thread and on the pool.

use crate::common::*;
use bevy::math::{Affine3A, Vec3};
use bevy_cloth::params::{Environment, Model, Substeps, Wind, XpbdParams};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::{ClothSolver, Layout};

/// A 16×12 curtain hung from its top corners in the default wind, built on the grid's
/// stencil path and, from the same layout told it is not a grid, on the general path.
fn stencil_and_general(params: &ClothParams) -> (ClothSolver, ClothSolver) {
    stencil_and_general_at(params, Vec3::new(0.0, 2.0, 0.0))
}

fn stencil_and_general_at(params: &ClothParams, at: Vec3) -> (ClothSolver, ClothSolver) {
    let shape = ClothShape::Grid {
        width: 16,
        height: 12,
        spacing: 0.05,
    };
    let layout = shape.layout().unwrap();
    let pins = ClothPins::TopCorners.resolve_for(&layout).unwrap();
    let general = Layout {
        grid: None,
        ..layout.clone()
    };
    let frame = Affine3A::from_translation(at);
    (
        ClothSolver::new(layout, &pins, params, frame).unwrap(),
        ClothSolver::new(general, &pins, params, frame).unwrap(),
    )
}

fn max_distance(a: &ClothSolver, b: &ClothSolver) -> f32 {
    a.positions()
        .iter()
        .zip(b.positions())
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f32::max)
}

/// The stencil path computes the same spring forces as the general one (only the order
/// of the sums differs): without the limiter, the two agree to 1e-5 m after a second.
/// Substeps fixed: the automatic ones differ (ω_max by power iteration on grids only).
#[test]
fn the_grid_stencil_steps_as_the_general_path() {
    let params = ClothParams {
        strain_limit: None,
        substeps: Substeps::Fixed(8),
        ..ClothParams::seeds()
    };
    let (mut stencil, mut general) = stencil_and_general(&params);
    let env = Environment::default();
    for _ in 0..63 {
        stencil.step(0.016, &env);
        general.step(0.016, &env);
    }
    let moved = stencil.positions()[100].distance(general.particles().position[100]);
    let far = max_distance(&stencil, &general);
    assert!(
        far < 1e-5,
        "stencil and general differ by {far} m ({moved})"
    );
    // And they did move: the corners hold, the rest fell.
    assert!(stencil.positions()[8 * 16].y < 1.9);
}

/// With the limiter the stencil's coloured Gauss–Seidel and the general path's
/// sequential sweeps are different orders of the same projections: both hold the strain
/// near the limit, and the cloths stay within a few millimetres of each other.
#[test]
fn the_coloured_limiter_limits_as_the_sequential_one() {
    let params = ClothParams {
        substeps: Substeps::Fixed(8),
        ..ClothParams::seeds()
    };
    let (mut stencil, mut general) = stencil_and_general(&params);
    let env = Environment::default();
    for _ in 0..63 {
        stencil.step(0.016, &env);
        general.step(0.016, &env);
    }
    let (s, g) = (stencil.strain().max, general.strain().max);
    assert!(
        s < 0.2 && g < 0.2,
        "strain {s} (coloured) and {g} (sequential)"
    );
    assert!(
        (s - g).abs() < 0.02,
        "strain {s} (coloured) and {g} (sequential)"
    );
    let far = max_distance(&stencil, &general);
    assert!(far < 0.005, "coloured and sequential differ by {far} m");
}

/// XPBD on a grid's stencil (offsets in colours of rows and columns) and on the general
/// constraint lists (greedy colours) are different orders of the same projections: the
/// same formula, so the two curtains fall the same way within millimetres, with and
/// without damping, strain limit and tethers.
#[test]
fn xpbd_on_the_stencil_projects_as_the_general_path() {
    for (damping, limit, tethers) in [(0.0, None, false), (0.05, Some(0.05), true)] {
        let mut params = ClothParams {
            model: Model::Xpbd(XpbdParams {
                tethers,
                ..XpbdParams::default()
            }),
            substeps: Substeps::Fixed(20),
            strain_limit: limit,
            ..ClothParams::seeds()
        };
        params.springs.damping = damping;
        let (mut stencil, mut general) = stencil_and_general(&params);
        let env = Environment::default();
        for _ in 0..63 {
            stencil.step(0.016, &env);
            general.step(0.016, &env);
        }
        let far = max_distance(&stencil, &general);
        let (s, g) = (stencil.strain().max, general.strain().max);
        println!(
            "damping {damping}, limit {limit:?}, tethers {tethers}: {far:.2e} m apart, strain {s:.4} and {g:.4}"
        );
        assert!(far < 5e-3, "stencil and general XPBD differ by {far} m");
        assert!(
            (s - g).abs() < 0.01,
            "strain {s} (stencil) and {g} (general)"
        );
        // It fell: the bottom row's middle is lower than it started (1.45 m).
        let bottom = stencil.positions()[11 * 16 + 8].y;
        assert!(bottom < 1.44, "the bottom row's middle at {bottom} m");
    }
}

/// A left–right symmetric curtain (even width, top corners pinned, no wind, limiter on)
/// stays mirror symmetric: the coloured limiter does not favour a side.
#[test]
fn a_symmetric_curtain_stays_symmetric() {
    // A tight limit (1%), so the limiter moves particles in every substep.
    let params = ClothParams {
        strain_limit: Some(0.01),
        ..ClothParams::seeds()
    };
    let worst = asymmetry_after_300_steps(&params);
    // The sequential sweeps of the general path leave 13 µm here.
    assert!(worst < 1e-6, "asymmetry {worst} m after 300 steps");
}

/// The same curtain as the default cloth (XPBD in twill, its stretch along lines): the
/// rows are solved from left to right, but the solve along a line is exact, so only
/// rounding tells the sides apart. Within 0.05 mm after 300 steps.
#[test]
fn a_symmetric_curtain_stays_symmetric_along_lines() {
    let worst = asymmetry_after_300_steps(&ClothParams::default());
    println!("asymmetry along lines: {worst} m after 300 steps");
    assert!(worst < 5e-5, "asymmetry {worst} m after 300 steps");
}

/// The 16 × 12 curtain of `stencil_and_general_at` at the origin (where f32 resolves
/// 1 µm; at y = 2 m one rounding is 0.24 µm), in still air: its largest distance from
/// its mirror image after 300 steps, m.
fn asymmetry_after_300_steps(params: &ClothParams) -> f32 {
    let (width, height) = (16usize, 12usize);
    let (mut cloth, _) = stencil_and_general_at(params, Vec3::ZERO);
    let env = Environment {
        wind: Wind {
            strength: 0.0,
            ..Wind::default()
        },
        ..Environment::default()
    };
    for _ in 0..300 {
        cloth.step(0.016, &env);
    }
    let x = cloth.positions();
    let mut worst = 0.0f32;
    for j in 0..height {
        for i in 0..width {
            let (p, q) = (x[j * width + i], x[j * width + width - 1 - i]);
            let mirrored = Vec3::new(-q.x, q.y, q.z);
            worst = worst.max(p.distance(mirrored));
        }
    }
    assert!(x[(height - 1) * width].y < -0.2, "the curtain hangs");
    worst
}

#[test]
fn a_large_cloth_steps_to_the_same_bits_on_one_thread_and_on_the_pool() {
    // 256 × 256 = 65,536 particles: every kernel runs in pieces on the compute pool
    // (from 16,384; XPBD's grid kernels from 65,536), several pieces per thread. Wind,
    // limiter on, top corners pinned. Mass-spring, and XPBD (its stencil colours' bands of
    // rows side by side, its tethers to the two corners in pieces).
    let xpbd = ClothParams {
        model: Model::Xpbd(XpbdParams::default()),
        substeps: Substeps::Fixed(10),
        ..ClothParams::seeds()
    };
    for params in [ClothParams::seeds(), xpbd] {
        same_bits_on_one_thread_and_on_the_pool(&params);
    }
}

fn same_bits_on_one_thread_and_on_the_pool(params: &ClothParams) {
    let run = |parallel: bool| {
        let steps = || {
            let mut cloth = corner_hung_grid_with(256, 256, params);
            let start = cloth.positions().to_vec();
            for _ in 0..20 {
                cloth.step(0.016, &Environment::default());
            }
            (start, cloth)
        };
        let (start, cloth) = if parallel {
            steps()
        } else {
            bevy_cloth::solver::on_one_thread(steps)
        };
        let moved = start
            .iter()
            .zip(cloth.positions())
            .map(|(a, b)| a.distance(*b))
            .fold(0.0, f32::max);
        assert!(moved > 0.1, "the cloth moves ({moved} m)");
        cloth.positions().to_vec()
    };
    let (one, pool) = (run(false), run(true));
    let differ = one.iter().zip(&pool).filter(|(a, b)| a != b).count();
    let model = params.model.kind();
    assert_eq!(
        differ,
        0,
        "{model}: {differ} of {} particles differ",
        one.len()
    );
}

/// One thread for one run: inside `on_one_thread` the kernels this thread starts stay on
/// it (one thread), while another thread's still use the pool, and the pool is back after.
/// So "one thread against the pool" compares what it says even with tests side by side.
#[test]
fn one_thread_for_one_run_leaves_other_threads_on_the_pool() {
    use bevy_cloth::solver::{on_one_thread, threads};
    let pool = threads();
    let inside = on_one_thread(|| (threads(), std::thread::spawn(threads).join().unwrap()));
    assert_eq!(
        inside,
        (1, pool),
        "inside, and another thread at the same time"
    );
    assert_eq!(threads(), pool, "after");
}
