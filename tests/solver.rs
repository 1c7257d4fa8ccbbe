//! ClothSolver tests against answers known independently of the code: free fall, a spring's
//! period, energy conservation, rest, tearing, the explicit stability bound.

use bevy::math::{Affine3A, Quat, Vec3};
use bevy_cloth::params::{
    Environment, Integrator, Model, PatchParams, SpringFamily, SpringParams, Substeps, Wind,
    WindField, XpbdParams,
};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::{ClothSolver, Layout, SpringKind};

const DT: f32 = 0.016;

fn no_springs() -> SpringParams {
    SpringParams {
        structural: SpringFamily::off(100.0),
        shear: SpringFamily::off(50.0),
        bend: SpringFamily::off(50.0),
        bend_diagonal: SpringFamily::off(25.0),
        seam: SpringFamily::off(100.0),
        ..SpringParams::default()
    }
}

/// Parameters with every dissipative or corrective term off.
fn conservative(integrator: Integrator) -> ClothParams {
    ClothParams {
        model: Model::MassSpring,
        node_mass: 1e-3,
        springs: SpringParams::from_structural(50.0),
        drag: 0.0,
        integrator,
        substeps: Substeps::Auto { max: 8192 },
        strain_limit: None,
        strain_limit_iterations: 0,
        strain_limit_tolerance: None,
        tear_ratio: None,
        self_collision: Default::default(),
        fabric: None,
    }
}

fn no_wind() -> Environment {
    Environment::default()
}

/// Four unpinned particles with no springs: each falls freely, one substep per step.
fn free_particles(integrator: Integrator) -> ClothSolver {
    free_particles_at(integrator, 1, Affine3A::IDENTITY)
}

/// Four unconnected particles placed by `frame`, stepped in `substeps` substeps.
fn free_particles_at(integrator: Integrator, substeps: u32, frame: Affine3A) -> ClothSolver {
    let params = ClothParams {
        springs: no_springs(),
        substeps: Substeps::Fixed(substeps),
        ..conservative(integrator)
    };
    let shape = ClothShape::Grid {
        width: 2,
        height: 2,
        spacing: 0.1,
    };
    shape
        .build_solver(&ClothPins::None, &params, frame)
        .unwrap()
}

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

/// A cloth held at two corners, released horizontal so it swings.
fn swinging_cloth(params: &ClothParams) -> ClothSolver {
    let frame = Affine3A::from_rotation_translation(
        Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
        Vec3::new(0.0, 1.0, 0.0),
    );
    ClothShape::Grid {
        width: 8,
        height: 8,
        spacing: 0.1,
    }
    .build_solver(&ClothPins::TopCorners, params, frame)
    .unwrap()
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

fn tear_test_cloth(model: Model, tear_ratio: f32, gravity: f32) -> (ClothSolver, Environment) {
    let params = ClothParams {
        model,
        tear_ratio: Some(tear_ratio),
        drag: 1e-3,
        ..conservative(Integrator::Verlet)
    };
    let cloth = ClothShape::Grid {
        width: 6,
        height: 6,
        spacing: 0.1,
    }
    .build_solver(&ClothPins::TopRow, &params, Affine3A::IDENTITY)
    .unwrap();
    let env = Environment {
        gravity: Vec3::new(0.0, -gravity, 0.0),
        ..no_wind()
    };
    (cloth, env)
}

#[test]
fn cloth_tears_past_its_ratio_and_not_below() {
    // Mass-spring, and XPBD's constraints (a torn one stops acting from the next step).
    for model in [Model::MassSpring, Model::Xpbd(XpbdParams::default())] {
        tears_past_its_ratio_and_not_below(model);
    }
}

fn tears_past_its_ratio_and_not_below(model: Model) {
    // Under normal gravity the top springs stretch by m g (rows below) / k ≈ 5%.
    let (mut calm, env) = tear_test_cloth(model, 1.5, 9.81);
    for _ in 0..300 {
        calm.step(DT, &env);
    }
    assert_eq!(calm.torn_count(), 0);
    assert!(calm.triangle_visible().iter().all(|v| *v));

    // Under 200 g the same springs would stretch by ~1000%: they tear, faces hide.
    let (mut pulled, env) = tear_test_cloth(model, 1.5, 200.0 * 9.81);
    let mut torn = Vec::new();
    for _ in 0..300 {
        let n = pulled.begin_step(DT);
        for _ in 0..n {
            pulled.substep(&env);
        }
        pulled.end_step();
        torn.extend_from_slice(pulled.last_torn());
    }
    assert!(!torn.is_empty());
    assert_eq!(torn.len(), pulled.torn_count());
    assert!(torn.iter().all(|&s| !pulled.springs().alive[s as usize]));
    assert!(
        pulled.triangle_visible().iter().any(|v| !*v),
        "no face was hidden"
    );
    assert!(pulled.is_finite(), "{}", model.kind());
    // A torn spring stops pulling: what hung below the tears fell freely (under 200 g for
    // the seconds left, kilometres; held by a spring that still acted, a few metres).
    let lowest = pulled
        .positions()
        .iter()
        .map(|p| p.y)
        .fold(f32::INFINITY, f32::min);
    assert!(
        lowest < -100.0,
        "{}: lowest particle at {lowest} m",
        model.kind()
    );
}

/// Maslova's stiffest, lightest material: k = 25,000 N/m, m = 0.001 g.
fn seed_002_extreme(substeps: Substeps) -> (ClothSolver, Environment) {
    let params = ClothParams {
        node_mass: 1e-6,
        springs: SpringParams::from_structural(25_000.0),
        substeps,
        ..conservative(Integrator::Verlet)
    };
    tilted_in_gusts(4, &params, 1e-6)
}

/// A `size × size` grid (5 cm spacing) pinned by its top corners, tilted 1.2 rad from
/// hanging so it swings, in Maslova's gusty wind of `wind` N a particle.
fn tilted_in_gusts(size: u32, params: &ClothParams, wind: f32) -> (ClothSolver, Environment) {
    let cloth = ClothShape::Grid {
        width: size,
        height: size,
        spacing: 0.05,
    }
    .build_solver(
        &ClothPins::TopCorners,
        params,
        Affine3A::from_rotation_x(-1.2),
    )
    .unwrap();
    let env = Environment {
        wind: Wind {
            direction: Vec3::Z,
            strength: wind,
            field: WindField::Trigonometric,
        },
        ..no_wind()
    };
    (cloth, env)
}

#[test]
fn stable_substeps_tame_the_stiffest_lightest_seed_material() {
    let (mut auto, env) = seed_002_extreme(Substeps::Auto {
        max: bevy_cloth::limits::MAX_SUBSTEPS,
    });
    let n = auto.stable_substeps(DT);
    // (That this substep lies inside the lattice's measured threshold, and not far inside,
    // is measured by the lab: `lab/tests/measure.rs`.)
    for _ in 0..1000 {
        auto.step(DT, &env);
    }
    assert_eq!(auto.substeps(), n);
    assert!(!auto.under_resolved());
    assert!(auto.is_stable(), "max strain {}", auto.strain().max);

    let (mut single, env) = seed_002_extreme(Substeps::Fixed(1));
    let mut failed_at = None;
    for step in 0..1000 {
        single.step(DT, &env);
        if !single.is_stable() {
            failed_at = Some(step);
            break;
        }
    }
    assert!(
        failed_at.is_some(),
        "one substep of 16 ms should not be stable here"
    );
}

#[test]
fn auto_substeps_report_when_capped() {
    let (mut capped, env) = seed_002_extreme(Substeps::Auto { max: 16 });
    capped.step(DT, &env);
    assert_eq!(capped.substeps(), 16);
    assert!(capped.under_resolved());
}

#[test]
fn changing_substeps_keeps_verlet_velocity() {
    let mut cloth = free_particles(Integrator::Verlet);
    let params = *cloth.params();
    let env = Environment {
        gravity_enabled: false,
        ..no_wind()
    };
    cloth.particles_mut().velocity.fill(Vec3::X);
    let p = cloth.particles_mut();
    for i in 0..p.len() {
        p.previous[i] = p.position[i] - Vec3::X * DT;
    }
    cloth.step(DT, &env);
    let x1 = cloth.positions()[0].x;
    cloth
        .set_params(&ClothParams {
            substeps: Substeps::Fixed(7),
            ..params
        })
        .unwrap();
    cloth.step(DT, &env);
    let x2 = cloth.positions()[0].x;
    assert!(
        ((x2 - x1) - DT).abs() < 1e-5,
        "moved {} instead of {DT}",
        x2 - x1
    );
}

#[test]
fn pins_follow_the_frame() {
    let params = conservative(Integrator::Verlet);
    let mut cloth = swinging_cloth(&params);
    let env = no_wind();
    let before: Vec<Vec3> = cloth
        .pins()
        .iter()
        .map(|&i| cloth.positions()[i as usize])
        .collect();
    let shift = Vec3::new(0.3, 0.0, -0.2);
    cloth.set_frame(Affine3A::from_translation(shift) * cloth.frame());
    cloth.step(DT, &env);
    for (k, &i) in cloth.pins().iter().enumerate() {
        assert!((cloth.positions()[i as usize] - (before[k] + shift)).length() < 1e-5);
    }
    // The rest of the cloth is dragged along over the following steps.
    let centre =
        |c: &ClothSolver| c.positions().iter().copied().sum::<Vec3>() / c.particle_count() as f32;
    let c0 = centre(&cloth);
    for _ in 0..200 {
        cloth.step(DT, &env);
    }
    assert!(
        (centre(&cloth).x - c0.x).abs() < 0.5,
        "cloth did not stay with its pins"
    );
}

#[test]
fn grid_topology_matches_the_seed() {
    let cloth = ClothShape::Grid {
        width: 5,
        height: 4,
        spacing: 0.1,
    }
    .build_solver(
        &ClothPins::TopRow,
        &ClothParams {
            springs: SpringParams {
                bend_diagonal: SpringFamily::new(10.0),
                ..SpringParams::default()
            },
            ..ClothParams::default()
        },
        Affine3A::IDENTITY,
    )
    .unwrap();
    let s = cloth.springs();
    let count = |k: SpringKind| s.ranges[k as usize].len();
    let (w, h) = (5, 4);
    assert_eq!(count(SpringKind::Structural), (w - 1) * h + w * (h - 1));
    assert_eq!(count(SpringKind::Shear), 2 * (w - 1) * (h - 1));
    assert_eq!(count(SpringKind::Bend), (w - 2) * h + w * (h - 2));
    assert_eq!(count(SpringKind::BendDiagonal), 2 * (w - 2) * (h - 2));
    let rest = |k: SpringKind| s.rest_length[s.ranges[k as usize].start];
    assert!((rest(SpringKind::Structural) - 0.1).abs() < 1e-6);
    assert!((rest(SpringKind::Shear) - 0.1 * 2f32.sqrt()).abs() < 1e-6);
    assert!((rest(SpringKind::Bend) - 0.2).abs() < 1e-6);
    assert!((rest(SpringKind::BendDiagonal) - 0.2 * 2f32.sqrt()).abs() < 1e-6);
    assert_eq!(cloth.pins(), &[0, 1, 2, 3, 4]);
    assert_eq!(cloth.triangles().len(), 2 * (w - 1) * (h - 1));
    // Switching a family off removes it from the acting springs.
    let mut c = cloth.clone();
    let all = c.spring_count();
    let mut p = *c.params();
    p.springs.shear.enabled = false;
    c.set_params(&p).unwrap();
    assert_eq!(c.spring_count(), all - count(SpringKind::Shear));
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

#[test]
fn bad_parameters_return_their_error() {
    let grid = ClothShape::Grid {
        width: 4,
        height: 4,
        spacing: 0.1,
    };
    let ok = ClothParams::default();
    let build = |shape: &ClothShape, pins: &ClothPins, params: &ClothParams| {
        shape.build_solver(pins, params, Affine3A::IDENTITY).err()
    };
    let field = |e: Option<ClothError>| match e {
        Some(ClothError::InvalidParameter { field, .. }) => field,
        other => panic!("expected an invalid parameter, got {other:?}"),
    };
    assert_eq!(
        field(build(
            &grid,
            &ClothPins::None,
            &ClothParams {
                node_mass: -1.0,
                ..ok
            }
        )),
        "node_mass"
    );
    assert_eq!(
        field(build(
            &grid,
            &ClothPins::None,
            &ClothParams {
                node_mass: f32::NAN,
                ..ok
            }
        )),
        "node_mass"
    );
    assert_eq!(
        field(build(
            &grid,
            &ClothPins::None,
            &ClothParams {
                node_mass: 0.0,
                ..ok
            }
        )),
        "node_mass"
    );
    let mut stiff = ok;
    stiff.springs.shear.stiffness = -5.0;
    assert_eq!(
        field(build(&grid, &ClothPins::None, &stiff)),
        "springs.shear.stiffness"
    );
    stiff.springs.shear.stiffness = f32::INFINITY;
    assert_eq!(
        field(build(&grid, &ClothPins::None, &stiff)),
        "springs.shear.stiffness"
    );
    assert_eq!(
        field(build(
            &grid,
            &ClothPins::None,
            &ClothParams { drag: -0.1, ..ok }
        )),
        "drag"
    );
    assert_eq!(
        field(build(
            &grid,
            &ClothPins::None,
            &ClothParams {
                tear_ratio: Some(0.9),
                ..ok
            }
        )),
        "tear_ratio"
    );
    assert_eq!(
        field(build(
            &grid,
            &ClothPins::None,
            &ClothParams {
                substeps: Substeps::Fixed(0),
                ..ok
            }
        )),
        "substeps"
    );
    for spacing in [0.0, -0.1, f32::NAN] {
        let shape = ClothShape::Grid {
            width: 4,
            height: 4,
            spacing,
        };
        assert_eq!(field(build(&shape, &ClothPins::None, &ok)), "shape.spacing");
    }
    let thin = ClothShape::Grid {
        width: 1,
        height: 5,
        spacing: 0.1,
    };
    assert_eq!(
        build(&thin, &ClothPins::None, &ok),
        Some(ClothError::GridTooSmall {
            width: 1,
            height: 5
        })
    );
    assert_eq!(
        build(&grid, &ClothPins::Indices(vec![3, 16]), &ok),
        Some(ClothError::PinOutOfRange {
            index: 16,
            count: 16
        })
    );
    // A running cloth refuses bad parameters and keeps its old ones.
    let mut cloth = grid
        .build_solver(&ClothPins::None, &ok, Affine3A::IDENTITY)
        .unwrap();
    assert!(
        cloth
            .set_params(&ClothParams {
                node_mass: -1.0,
                ..ok
            })
            .is_err()
    );
    assert_eq!(cloth.params(), &ok);
}

/// A `n × n`-vertex square mesh, 10 cm across, in the xy-plane: its positions and
/// triangles, indexed.
fn square_mesh(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let positions = (0..n * n)
        .map(|k| Vec3::new((k % n) as f32, -((k / n) as f32), 0.0) * (0.1 / (n - 1) as f32))
        .collect();
    let mut triangles = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let (a, b, c, d) = (
                j * n + i,
                j * n + i + 1,
                (j + 1) * n + i,
                (j + 1) * n + i + 1,
            );
            triangles.push([a, c, b]);
            triangles.push([b, c, d]);
        }
    }
    (positions, triangles)
}

/// The mesh hung from its top row for 2 s: the lowest point.
fn hang_mesh(positions: &[Vec3], triangles: &[[u32; 3]]) -> (ClothSolver, f32) {
    let params = ClothParams {
        springs: SpringParams::from_structural(50.0),
        ..ClothParams::default()
    };
    let layout = Layout::from_mesh(positions, triangles).unwrap();
    let pins = ClothPins::TopRow.resolve_for(&layout).unwrap();
    let mut c = ClothSolver::new(layout, &pins, &params, Affine3A::IDENTITY).unwrap();
    for _ in 0..125 {
        c.step(DT, &no_wind());
    }
    assert!(c.is_stable());
    let lowest = c.positions().iter().map(|p| p.y).fold(f32::MAX, f32::min);
    (c, lowest)
}

#[test]
fn meshes_weld_coincident_vertices_into_one_cloth() {
    let (positions, triangles) = square_mesh(6);
    let (indexed, lowest) = hang_mesh(&positions, &triangles);
    assert_eq!(indexed.particle_count(), 36);
    // Non-indexed: every triangle has its own three vertices (as many exporters write).
    let loose: Vec<Vec3> = triangles
        .iter()
        .flat_map(|t| t.map(|v| positions[v as usize]))
        .collect();
    let loose_triangles: Vec<[u32; 3]> = (0..triangles.len() as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    let (welded, welded_lowest) = hang_mesh(&loose, &loose_triangles);
    assert_eq!(welded.particle_count(), 36, "one particle per place");
    assert_eq!(welded.spring_count(), indexed.spring_count());
    // It hangs as the indexed mesh does, not as 50 loose triangles falling away.
    assert!(
        (welded_lowest - lowest).abs() < 1e-4,
        "lowest point {welded_lowest} against {lowest}"
    );
    // Split along a UV seam: the middle column's vertices are repeated for the right half.
    let n = 6;
    let seam = 3;
    let mut split = positions.clone();
    let mut copy_of = std::collections::HashMap::new();
    for j in 0..n {
        copy_of.insert(j * n + seam, split.len() as u32);
        split.push(positions[(j * n + seam) as usize]);
    }
    let split_triangles: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| {
            let right = t.iter().any(|&v| v % n > seam);
            t.map(|v| match copy_of.get(&v) {
                Some(&copy) if right => copy,
                _ => v,
            })
        })
        .collect();
    let (seamed, seamed_lowest) = hang_mesh(&split, &split_triangles);
    assert_eq!(seamed.particle_count(), 36);
    assert!((seamed_lowest - lowest).abs() < 1e-4);
}

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
        ..ClothParams::default()
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
        ..ClothParams::default()
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
            ..ClothParams::default()
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
    let (width, height) = (16usize, 12usize);
    // At the origin, where f32 resolves 1 µm (at y = 2 m one rounding is 0.24 µm).
    // A tight limit (1%), so the limiter moves particles in every substep.
    let params = ClothParams {
        strain_limit: Some(0.01),
        ..ClothParams::default()
    };
    let (mut cloth, _) = stencil_and_general_at(&params, Vec3::ZERO);
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
    // The sequential sweeps of the general path leave 13 µm here.
    assert!(worst < 1e-6, "asymmetry {worst} m after 300 steps");
    assert!(x[(height - 1) * width].y < -0.2, "the curtain hangs");
}

/// A `width × height` grid 2 cm apart, hung from its top corners, default parameters.
fn corner_hung_grid(width: u32, height: u32) -> ClothSolver {
    corner_hung_grid_with(width, height, &ClothParams::default())
}

fn corner_hung_grid_with(width: u32, height: u32, params: &ClothParams) -> ClothSolver {
    ClothShape::Grid {
        width,
        height,
        spacing: 0.02,
    }
    .build_solver(&ClothPins::TopCorners, params, Affine3A::IDENTITY)
    .unwrap()
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
        ..ClothParams::default()
    };
    for params in [ClothParams::default(), xpbd] {
        same_bits_on_one_thread_and_on_the_pool(&params);
    }
}

fn same_bits_on_one_thread_and_on_the_pool(params: &ClothParams) {
    let run = |parallel: bool| {
        bevy_cloth::solver::set_parallel(parallel);
        let mut cloth = corner_hung_grid_with(256, 256, params);
        let start = cloth.positions().to_vec();
        for _ in 0..20 {
            cloth.step(0.016, &Environment::default());
        }
        bevy_cloth::solver::set_parallel(true);
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

#[test]
fn the_power_iteration_finds_the_lattice_eigenvalue() {
    // The automatic substeps' 30 iterations against a converged 2,000, on a flat and on a
    // crumpled grid: below the true value (a Rayleigh quotient), and close enough that
    // the margin of 1.25 covers it.
    for crumple in [0.0f32, 0.25] {
        let mut cloth = corner_hung_grid(48, 32);
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
        // Gershgorin's bound lies above it.
        let m = cloth.particles().mass[100];
        let k_sum = 2.0
            * (2.0 * k(SpringKind::Structural)
                + 2.0 * k(SpringKind::Shear)
                + 2.0 * k(SpringKind::Bend));
        assert!(converged < 2.0 * k_sum / m);
        println!(
            "crumple {crumple}: 30 iterations {fast}, converged {converged}, ratio {}",
            converged / fast
        );
    }
}

#[test]
fn an_attached_particle_reaches_its_target_every_step_and_falls_when_let_go() {
    // Every model: the attached corner is at its target at the end of each step, the
    // cloth hangs from it, and once detached it falls freely.
    for model in [
        Model::MassSpring,
        Model::Xpbd(XpbdParams::default()),
        Model::Patches(PatchParams {
            part_width: 2,
            part_height: 2,
            ..PatchParams::default()
        }),
    ] {
        let params = ClothParams {
            model,
            ..ClothParams::default()
        };
        let mut cloth = ClothShape::Grid {
            width: 6,
            height: 6,
            spacing: 0.05,
        }
        .build_solver(&ClothPins::None, &params, Affine3A::IDENTITY)
        .unwrap();
        let env = Environment::default();
        for step in 0..60 {
            let target = Vec3::new(0.01 * step as f32, 0.0, 0.0);
            cloth.attach(0, target).unwrap();
            cloth.step(DT, &env);
            assert!(
                cloth.positions()[0].distance(target) < 1e-5,
                "{model:?} step {step}"
            );
        }
        assert_eq!(cloth.attached(), [0]);
        let hanging = cloth.positions()[35].y;
        assert!(hanging < -0.2, "{model:?}: hangs to {hanging}");
        assert!(cloth.detach(0));
        let y0 = cloth.positions()[0].y;
        for _ in 0..10 {
            cloth.step(DT, &env);
        }
        assert!(
            cloth.positions()[0].y < y0 - 0.05,
            "{model:?}: let go, falls"
        );
        assert!(cloth.attach(99, Vec3::ZERO).is_err());
        assert!(cloth.attach(1, Vec3::splat(f32::NAN)).is_err());
    }
}

/// Parameters an explicit step cannot hold: springs of 1e5 N/m on 1 g particles at one
/// substep of 16 ms (ω h ≈ 160, a hundred times past the bound of 2).
fn absurd(params: &ClothParams) -> ClothParams {
    ClothParams {
        model: Model::MassSpring,
        springs: SpringParams::from_structural(1e5),
        node_mass: 1e-3,
        substeps: Substeps::Fixed(1),
        strain_limit: None,
        tear_ratio: None,
        ..*params
    }
}

/// A step that would leave the state non-finite says so in its report and keeps the
/// positions of the last good step, at rest; the cloth steps normally again after a
/// reset. Driven there twice: by an edit of its parameters that no explicit step can
/// hold, and by a non-finite force added between the stages.
#[test]
fn a_step_that_goes_non_finite_reports_it_keeps_the_last_good_state_and_recovers_on_reset() {
    let sane = ClothParams::default();
    let mut cloth = ClothShape::Grid {
        width: 8,
        height: 8,
        spacing: 0.05,
    }
    .build_solver(&ClothPins::TopRow, &sane, Affine3A::IDENTITY)
    .unwrap();
    let env = Environment::default();
    for _ in 0..10 {
        assert!(cloth.step(DT, &env).finite);
    }
    cloth.set_params(&absurd(&sane)).unwrap();
    let mut failed = None;
    for step in 0..200 {
        let before = (
            cloth.positions().to_vec(),
            cloth.particles().velocity.clone(),
        );
        let time = cloth.time();
        let report = cloth.step(DT, &env);
        if !report.finite {
            assert_eq!(cloth.positions(), &before.0[..], "positions kept");
            assert!(cloth.particles().velocity.iter().all(|v| *v == Vec3::ZERO));
            assert!(before.1.iter().all(|v| v.is_finite()));
            assert_eq!(cloth.time(), time, "the clock kept");
            failed = Some(step);
            break;
        }
    }
    let step = failed.expect("the absurd parameters never went non-finite");
    assert!(step > 0, "it blew up from a finite state");
    assert!(cloth.is_finite());
    // Every later step fails the same way and keeps the same state.
    let kept = cloth.positions().to_vec();
    assert!(!cloth.step(DT, &env).finite);
    assert_eq!(cloth.positions(), &kept[..]);

    cloth.reset();
    assert!(cloth.last_report().finite);
    cloth.set_params(&sane).unwrap();
    for _ in 0..10 {
        assert!(cloth.step(DT, &env).finite);
    }
    let rest = cloth.positions().to_vec();

    // A non-finite force added by hand between the stages.
    let n = cloth.begin_step(DT);
    for k in 0..n {
        cloth.accumulate_forces(&env);
        if k == 0 {
            cloth.add_force(20, Vec3::NAN);
        }
        cloth.integrate();
        cloth.fit_targets();
        cloth.constrain();
    }
    let report = cloth.end_step();
    assert!(!report.finite && report.taken == n);
    assert_eq!(cloth.positions(), &rest[..]);
    cloth.reset();
    assert!(cloth.step(DT, &env).finite && cloth.is_finite());
}

/// The report says what the step did: its substeps, every stage timed, and (XPBD at
/// automatic substeps) the largest structural strain, which is the solver's own measure
/// of the free springs.
#[test]
fn the_step_report_counts_substeps_times_stages_and_measures_xpbd_strain() {
    let params = ClothParams {
        model: Model::Xpbd(XpbdParams::default()),
        springs: SpringParams {
            structural: SpringFamily::new(f32::INFINITY),
            ..SpringParams::default()
        },
        substeps: Substeps::Auto { max: 64 },
        ..ClothParams::default()
    };
    let mut cloth = ClothShape::Grid {
        width: 12,
        height: 12,
        spacing: 0.05,
    }
    .build_solver(&ClothPins::TopCorners, &params, Affine3A::IDENTITY)
    .unwrap();
    let env = Environment::default();
    let mut report = cloth.step(DT, &env);
    for _ in 0..30 {
        report = cloth.step(DT, &env);
    }
    assert_eq!(report.substeps, cloth.substeps());
    assert_eq!(report.taken, report.substeps);
    assert!(report.finite && !report.under_resolved);
    let t = report.time;
    assert!(t.forces > t.fit_targets && t.constraints > std::time::Duration::ZERO);
    assert_eq!(
        t.total(),
        t.begin
            + t.forces
            + t.integrate
            + t.fit_targets
            + t.constraints
            + t.self_contact
            + t.contact
            + t.end
    );
    let strain = report
        .max_strain
        .expect("XPBD's closed loop measures the strain");
    assert!(
        strain > 0.0 && strain <= cloth.strain().max + 1e-6,
        "{strain}"
    );
    assert!(
        strain < 0.02,
        "inextensible at its automatic substeps: {strain}"
    );
    // Mass-spring at fixed substeps does not measure it.
    cloth.set_params(&ClothParams::default()).unwrap();
    assert_eq!(cloth.step(DT, &env).max_strain, None);
    // A step of no time does nothing and reports nothing wrong.
    let none = cloth.step(0.0, &env);
    assert_eq!((none.substeps, none.taken, none.finite), (0, 0, true));
}

#[test]
fn the_lightest_seed_material_with_drag_is_stable_at_one_substep() {
    // Maslova's lightest node, 0.001 g, with 0.005 N·s/m of drag: h c/m = 80 at one
    // 16 ms substep, where explicit drag (`v += h (a − c v/m)`) multiplies the velocity
    // by −79 a step. Implicit drag is stable at any h c/m and only takes energy away.
    // Mass-spring without springs (its springs at this mass need thousands of substeps
    // on their own: the drag is what is tested), and XPBD with its springs as constraints,
    // released swinging from tilted, in gusty wind.
    let models = [
        ("mass-spring", Model::MassSpring, no_springs()),
        (
            "xpbd",
            Model::Xpbd(XpbdParams::default()),
            SpringParams::from_structural(100.0),
        ),
    ];
    for (name, model, springs) in models {
        let params = ClothParams {
            model,
            node_mass: 1e-6,
            springs,
            drag: 0.005,
            substeps: Substeps::Fixed(1),
            ..conservative(Integrator::Verlet)
        };
        let (mut cloth, env) = tilted_in_gusts(8, &params, 1e-5);
        let mut most = 0.0f32;
        for step in 0..500 {
            cloth.step(DT, &env);
            assert!(cloth.is_stable(), "{name}: unstable at step {step}");
            // Drag bounds the speed: the kinetic energy never exceeds what terminal
            // velocity under gravity and wind allows (`m (g m/c)²/2` a particle, times 4).
            let kinetic = cloth.energy(&env).kinetic;
            most = most.max(kinetic);
        }
        let n = 64.0;
        let terminal = 9.81 * 1e-6 / 0.005;
        let bound = 4.0 * n * 0.5 * 1e-6 * terminal * terminal;
        eprintln!("{name}: most kinetic energy {most} J (bound {bound} J)");
        assert!(
            most <= bound,
            "{name}: kinetic energy {most} J over {bound} J"
        );
    }
}
