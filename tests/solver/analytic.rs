//! ClothSolver against answers known independently of the code: free fall, a spring's
//! period, energy bounded, a damped cloth at rest, a pinned cloth at rest, the lattice's
//! largest eigenvalue.

use crate::common::*;
use bevy::math::{Affine3A, Vec3};
use bevy_cloth::params::{Environment, Integrator, SpringParams, Substeps};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::{ClothSolver, Layout, SpringKind};

#[test]
fn free_fall_follows_half_g_t_squared() {
    for integrator in Integrator::ALL {
        let mut cloth = free_particles(integrator);
        let y0 = cloth.positions()[0].y;
        let env = no_wind();
        let g = 9.81f32;
        let steps = 62; // ≈ 1 s
        for _ in 0..steps {
            cloth.step(DT, &env);
        }
        let t = steps as f32 * DT;
        let drop = y0 - cloth.positions()[0].y;
        let exact = 0.5 * g * t * t;
        // Both integrators take the first step as x1 = x0 + g h², so they fall
        // g h² n(n+1)/2: ahead of g t²/2 by g h t/2, their known first-order error.
        let discrete = 0.5 * g * DT * DT * (steps * (steps + 1)) as f32;
        assert!(
            (drop - discrete).abs() < 1e-4 * exact,
            "{integrator:?}: {drop} vs {discrete}"
        );
        assert!(
            (drop - exact).abs() <= 0.5 * g * DT * t * 1.01,
            "{integrator:?}"
        );
        assert!(
            (drop - exact).abs() / exact < 0.02,
            "{integrator:?}: {drop} vs {exact}"
        );
    }
}

#[test]
fn free_fall_is_not_lost_to_rounding_at_many_substeps() {
    // At 2048 substeps of 16 ms, g h² = 6e-10 m is far below the spacing of floats near
    // y = 2 m (2.4e-7 m): plain position Verlet never moved. Both integrators must fall
    // g h² n(n+1)/2 with n = all substeps taken.
    for integrator in Integrator::ALL {
        let frame = Affine3A::from_translation(Vec3::new(0.0, 2.0, 0.0));
        let mut cloth = free_particles_at(integrator, 2048, frame);
        let y0 = cloth.positions()[0].y;
        let steps = 10;
        for _ in 0..steps {
            cloth.step(DT, &no_wind());
        }
        let (n, h) = ((steps * 2048) as f64, DT as f64 / 2048.0);
        let discrete = 0.5 * 9.81 * h * h * n * (n + 1.0);
        let drop = (y0 - cloth.positions()[0].y) as f64;
        assert!(
            (drop - discrete).abs() < 1e-3 * discrete,
            "{integrator:?}: fell {drop} m, expected {discrete} m"
        );
    }
}

/// A particle of mass m on one spring k to a pin, displaced along the spring, oscillates
/// with period 2π√(m/k).
#[test]
fn spring_period_matches_two_pi_sqrt_m_over_k() {
    for integrator in Integrator::ALL {
        let (m, k) = (0.01f32, 100.0f32);
        let params = ClothParams {
            node_mass: m,
            springs: SpringParams::from_structural(k),
            substeps: Substeps::Fixed(1),
            ..conservative(integrator)
        };
        let positions = [Vec3::ZERO, Vec3::new(0.0, -1.0, 0.0)];
        let mut cloth = ClothSolver::new(
            Layout::from_springs(&positions, &[[0, 1]]).unwrap(),
            &[0],
            &params,
            Affine3A::IDENTITY,
        )
        .unwrap();
        let start = Vec3::new(0.0, -1.05, 0.0);
        let p = cloth.particles_mut();
        p.position[1] = start;
        p.previous[1] = start;
        let env = Environment {
            gravity_enabled: false,
            ..no_wind()
        };
        let dt = 0.0005;
        let mut crossings = Vec::new();
        let mut last = start.y + 1.0;
        for n in 1..=4000 {
            cloth.step(dt, &env);
            let y = cloth.positions()[1].y + 1.0;
            if last < 0.0 && y >= 0.0 {
                // Linear interpolation of the upward zero crossing.
                crossings.push((n as f32 - 1.0 + last / (last - y)) * dt);
            }
            last = y;
        }
        assert!(
            crossings.len() >= 5,
            "{integrator:?}: only {} crossings",
            crossings.len()
        );
        let period = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f32;
        let expected = 2.0 * std::f32::consts::PI * (m / k).sqrt();
        // Verlet's period at ω h = 0.05 is 2π/ω · (1 + (ωh)²/24 + …): 1.0e-4 long.
        let error = (period - expected).abs() / expected;
        assert!(
            error < 3e-4,
            "{integrator:?}: period {period} vs {expected} ({:.3}%)",
            error * 100.0
        );
    }
}

/// Largest |E − E0| over steps `[from, to)` of a swinging cloth with `substeps` fixed.
fn energy_drift(substeps: u32, steps: usize, from: usize) -> (f32, ClothSolver) {
    let params = ClothParams {
        substeps: Substeps::Fixed(substeps),
        ..conservative(Integrator::Verlet)
    };
    let mut cloth = swinging_cloth(&params);
    let env = no_wind();
    let pins: Vec<Vec3> = cloth
        .pins()
        .iter()
        .map(|&i| cloth.positions()[i as usize])
        .collect();
    let e0 = cloth.energy(&env).total();
    let mut worst = 0.0f32;
    for n in 0..steps {
        cloth.step(DT, &env);
        if n >= from {
            worst = worst.max((cloth.energy(&env).total() - e0).abs());
        }
        for (k, &i) in cloth.pins().iter().enumerate() {
            assert_eq!(
                cloth.positions()[i as usize],
                pins[k],
                "pin {i} moved at step {n}"
            );
        }
    }
    (worst, cloth)
}

#[test]
fn undamped_verlet_keeps_energy_bounded_and_pins_still() {
    // Verlet is symplectic and first order in its velocity estimate: the energy error
    // oscillates with an amplitude proportional to h and does not grow.
    let params = conservative(Integrator::Verlet);
    let scale = 64.0 * params.node_mass * 9.81 * 0.7; // the cloth dropping its own length
    let n = swinging_cloth(&params).stable_substeps(DT);
    // Windows of 3,000 steps each: the swinging cloth is chaotic, and the largest error
    // in a short window depends on which swings it catches (a change of rounding order
    // alone moved the first 1,000 steps' from 0.017 to 0.012).
    let (early, _) = energy_drift(n, 3000, 0);
    let (late, cloth) = energy_drift(n, 10_000, 7000);
    assert!(cloth.is_stable());
    // The error's amplitude grows with h: with ω_max from the power iteration the
    // automatic substeps take h nearer the bound than Gershgorin's did (0.047 of 0.44
    // here), still a bounded oscillation.
    assert!(late < 0.15 * scale, "late drift {late} of scale {scale}");
    assert!(
        late < 2.0 * early,
        "energy grows: {early} in the first 1000 steps, {late} in the last"
    );
    // Halving h roughly halves the error (first order): it is truncation, not blow-up.
    let (fine, _) = energy_drift(2 * n, 3000, 0);
    assert!(fine < 0.75 * early, "halving h: {early} → {fine}");
}

#[test]
fn damped_cloth_comes_to_rest() {
    let params = ClothParams {
        drag: 2e-3,
        springs: SpringParams {
            damping: 0.01,
            ..SpringParams::from_structural(50.0)
        },
        ..conservative(Integrator::SemiImplicitEuler)
    };
    let mut cloth = swinging_cloth(&params);
    let env = no_wind();
    let mut peak = 0.0f32;
    for _ in 0..(20.0 / DT) as usize {
        cloth.step(DT, &env);
        peak = peak.max(cloth.energy(&env).kinetic);
    }
    let kinetic = cloth.energy(&env).kinetic;
    assert!(peak > 1e-3, "the cloth never moved: {peak}");
    assert!(
        kinetic < 1e-6 * peak,
        "still moving: {kinetic} of peak {peak}"
    );
    // At rest it hangs below its pins.
    let lowest = cloth
        .positions()
        .iter()
        .map(|p| p.y)
        .fold(f32::INFINITY, f32::min);
    assert!(lowest < 1.0 - 0.5, "lowest point {lowest}");
}

#[test]
fn a_pinned_cloth_at_rest_stays_at_rest_without_gravity() {
    let mut cloth = ClothShape::Grid {
        width: 6,
        height: 6,
        spacing: 0.1,
    }
    .build_solver(
        &ClothPins::TopCorners,
        &conservative(Integrator::Verlet),
        Affine3A::IDENTITY,
    )
    .unwrap();
    let start = cloth.positions().to_vec();
    let env = Environment {
        gravity_enabled: false,
        ..no_wind()
    };
    for _ in 0..500 {
        cloth.step(DT, &env);
    }
    for (a, b) in start.iter().zip(cloth.positions()) {
        assert!(a.distance(*b) < 1e-6);
    }
    assert!(cloth.energy(&env).total().abs() < 1e-9);
}

/// A `width × height` grid 2 cm apart, hung from its top corners, default parameters.
fn corner_hung_grid(width: u32, height: u32) -> ClothSolver {
    corner_hung_grid_with(width, height, &ClothParams::seeds())
}

#[test]
fn the_power_iteration_finds_the_lattice_eigenvalue() {
    // The automatic substeps' 30 iterations against a converged 2,000, on a flat and on a
    // crumpled grid: below the true value (a Rayleigh quotient), and close enough that
    // the margin of 1.25 covers it.
    for crumple in [0.0f32, 0.25] {
        let (cloth, converged) = crumpled_within_margin(corner_hung_grid(48, 32), crumple);
        // Gershgorin's bound lies above it.
        let k = |kind| cloth.stiffness(kind);
        let m = cloth.particles().mass[100];
        let k_sum = 2.0
            * (2.0 * k(SpringKind::Structural)
                + 2.0 * k(SpringKind::Shear)
                + 2.0 * k(SpringKind::Bend));
        assert!(converged < 2.0 * k_sum / m);
    }
}

/// `cloth` crumpled by `crumple` × 2 cm: its lattice eigenvalue by the automatic
/// substeps' 30 power iterations is below the converged 2,000's and within the margin of
/// 1.25 of it. The cloth and the converged value.
fn crumpled_within_margin(mut cloth: ClothSolver, crumple: f32) -> (ClothSolver, f32) {
    let p = cloth.particles_mut();
    for i in 0..p.len() {
        let t = i as f32;
        p.position[i] +=
            Vec3::new((t * 0.7).sin(), (t * 1.3).cos(), (t * 2.9).sin()) * (0.02 * crumple);
    }
    let k = |kind| cloth.stiffness(kind);
    let (fast, converged) = (
        cloth.lattice_eigenvalue(k, true, 30),
        cloth.lattice_eigenvalue(k, true, 2_000),
    );
    assert!(
        fast <= converged * 1.0001,
        "crumple {crumple}: {fast} > {converged}"
    );
    assert!(
        fast * 1.25 > converged,
        "crumple {crumple}: {fast} vs {converged}"
    );
    println!(
        "crumple {crumple}: 30 iterations {fast}, converged {converged}, ratio {}",
        converged / fast
    );
    (cloth, converged)
}

#[test]
fn the_power_iteration_finds_a_meshs_eigenvalue() {
    // A mesh without seams takes its substeps from the same estimate as a grid: on an
    // irregular mesh, flat and crumpled, the 30 iterations stay below the converged value
    // and within the margin of 1.25.
    for crumple in [0.0f32, 0.25] {
        let params = ClothParams::seeds();
        let layout = irregular_mesh(40, 28, 0.02);
        let pins = ClothPins::TopCorners.resolve_for(&layout).unwrap();
        let cloth = ClothSolver::new(layout, &pins, &params, Affine3A::IDENTITY).unwrap();
        crumpled_within_margin(cloth, crumple);
    }
}
