//! Stability and the step's report: automatic substeps tame Maslova's stiffest lightest
//! material, report when capped, keep Verlet's velocity; a step that goes non-finite is
//! reported and undone; the report's substeps, stage times and strain.

use crate::common::*;
use bevy::math::{Affine3A, Vec3};
use bevy_cloth::params::{
    Environment, Integrator, Model, SpringFamily, SpringParams, Substeps, Wind, WindField,
    XpbdParams,
};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::{ClothSolver, Layout};

/// Maslova's stiffest, lightest material: k = 25,000 N/m, m = 0.001 g.
fn maslova_extreme_params(substeps: Substeps) -> ClothParams {
    ClothParams {
        node_mass: 1e-6,
        springs: SpringParams::from_structural(25_000.0),
        substeps,
        ..conservative(Integrator::Verlet)
    }
}

/// Maslova's stiffest, lightest material on a 4 × 4 grid, tilted in gusts.
fn maslova_extreme(substeps: Substeps) -> (ClothSolver, Environment) {
    tilted_in_gusts(grid(4), &maslova_extreme_params(substeps), 1e-6)
}

/// A `size × size` grid, 5 cm spacing.
fn grid(size: u32) -> Layout {
    ClothShape::Grid {
        width: size,
        height: size,
        spacing: 0.05,
    }
    .layout()
    .unwrap()
}

/// `layout` pinned by its top corners, tilted 1.2 rad from hanging so it swings, in
/// Maslova's gusty wind of `wind` N a particle.
fn tilted_in_gusts(layout: Layout, params: &ClothParams, wind: f32) -> (ClothSolver, Environment) {
    let pins = ClothPins::TopCorners.resolve_for(&layout).unwrap();
    let frame = Affine3A::from_rotation_x(-1.2);
    let cloth = ClothSolver::new(layout, &pins, params, frame).unwrap();
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
    let (mut auto, env) = maslova_extreme(Substeps::Auto {
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

    let (mut single, env) = maslova_extreme(Substeps::Fixed(1));
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
    let (mut capped, env) = maslova_extreme(Substeps::Auto { max: 16 });
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
    let sane = ClothParams::seeds();
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
        ..ClothParams::seeds()
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
    // The stages that work here are timed (no comparison of one time with another: a
    // loaded machine may stretch any of them).
    let zero = std::time::Duration::ZERO;
    assert!(t.forces > zero && t.constraints > zero, "{t:?}");
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
    cloth.set_params(&ClothParams::seeds()).unwrap();
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
        let (mut cloth, env) = tilted_in_gusts(grid(8), &params, 1e-5);
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

#[test]
fn stable_substeps_tame_the_stiffest_lightest_material_on_an_irregular_mesh() {
    // The power estimate on a mesh (no longer Gershgorin's bound): Maslova's stiffest,
    // lightest material on a mesh of irregular triangles, tilted and swinging in gusts
    // at its automatic substeps, stays stable; at one substep it does not.
    let run = |substeps| {
        // Inner vertices moved up to a third of the 5 cm spacing.
        let mesh = irregular_mesh(6, 6, 0.05);
        let (mut cloth, env) = tilted_in_gusts(mesh, &maslova_extreme_params(substeps), 1e-6);
        for step in 0..1000 {
            cloth.step(DT, &env);
            if !cloth.is_stable() {
                return (false, step, cloth.substeps());
            }
        }
        (true, 1000, cloth.substeps())
    };
    let (stable, step, substeps) = run(Substeps::Auto {
        max: bevy_cloth::limits::MAX_SUBSTEPS,
    });
    assert!(stable, "unstable at step {step} with {substeps} substeps");
    let (stable, ..) = run(Substeps::Fixed(1));
    assert!(!stable, "one substep of 16 ms should not be stable here");
}
