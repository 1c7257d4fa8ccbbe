//! The measuring instruments checked against answers known without them: the explicit
//! stability bound of a single spring, the largest frequency of a lattice, the error
//! metric of a known displacement, and the full app's frame loop.

use bevy::math::Vec3;
use bevy_cloth::params::{Integrator, Model, Substeps};
use bevy_cloth::prelude::*;
use bevy_cloth_lab::accuracy::{Case, SAMPLE_INTERVAL, Trajectory};
use bevy_cloth_lab::stability::Regime;
use bevy_cloth_lab::{fps, stability};

/// A scene file of the workspace (tests run in `lab/`).
fn scene_path(name: &str) -> String {
    format!("{}/../assets/scenes/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn a_single_spring_goes_unstable_at_omega_h_2() {
    // x'' = −ω² x by Verlet or symplectic Euler: |eigenvalues| = 1 while h ω ≤ 2.
    for integrator in Integrator::ALL {
        for (k, m) in [(100.0, 1e-3), (25_000.0, 1e-6)] {
            let t = stability::single_spring(k, m, integrator).unwrap();
            let ratio = t.measured / t.predicted;
            assert!(
                (0.98..=1.005).contains(&ratio),
                "{integrator:?}, k {k}, m {m}: measured {} s against 2/ω = {} s",
                t.measured,
                t.predicted
            );
            // The automatic substeps stay inside the bound.
            assert!(t.auto_bound < t.measured, "{t:?}");
        }
    }
}

#[test]
fn the_lattice_fails_where_its_largest_frequency_says() {
    let t = stability::lattice(1_000.0, 1e-4, Integrator::Verlet).unwrap();
    // Gershgorin's bound (what the automatic substeps use) is below the true ω_max, and
    // the power iteration's ω_max predicts the measured threshold.
    let ratio = t.measured / t.predicted;
    assert!((0.95..=1.05).contains(&ratio), "{t:?}");
    assert!(t.auto_bound < t.measured, "{t:?}");
    // ω_max scales with √(k/m): the factor is the same at another stiffness and mass.
    let other = stability::lattice(10_000.0, 1e-5, Integrator::Verlet).unwrap();
    let factor = |t: &stability::Threshold| t.omega_max / (t.stiffness / t.mass).sqrt();
    assert!((factor(&t) - factor(&other)).abs() < 0.01 * factor(&t));
    assert!((factor(&t) - stability::lattice_factor()).abs() < 0.01 * factor(&t));
    // Maslova's stiffest, lightest material: the automatic substep lies inside the
    // measured threshold, and not wastefully far inside (Gershgorin overestimates ω_max
    // by ~1.8×, the safety factor is 0.8).
    let x = stability::lattice(25_000.0, 1e-6, Integrator::Verlet).unwrap();
    assert!(
        x.auto_bound < x.measured && x.auto_bound > 0.4 * x.measured,
        "{x:?}"
    );
}

#[test]
fn grid_cells_fail_past_the_bound_and_not_with_auto_substeps() {
    // k = 1000 N/m, 0.1 g: ω₀ = 3162 rad/s, ω_max ≈ 3.9·ω₀ by the lattice factor.
    let fixed = |dt| {
        stability::cell(
            Regime::Linear,
            "mass-spring",
            Integrator::Verlet,
            false,
            1_000.0,
            1e-4,
            dt,
        )
    };
    assert_eq!(fixed(0.0001).unwrap().failure, None);
    assert!(fixed(0.004).unwrap().failure.is_some());
    let auto = stability::cell(
        Regime::Linear,
        "mass-spring",
        Integrator::Verlet,
        true,
        1_000.0,
        1e-4,
        0.004,
    )
    .unwrap();
    assert_eq!(auto.failure, None);
    assert!(auto.substeps > 1);
}

fn trajectory(samples: Vec<Vec<Vec3>>, diagonal: f32) -> Trajectory {
    Trajectory {
        samples,
        milliseconds: 0.0,
        max_strain: 0.0,
        energy_start: 0.0,
        energy_end: 0.0,
        failed_at: None,
        mean_substeps: 1.0,
        mass: 1.0,
        diagonal,
    }
}

#[test]
fn the_error_is_the_rms_distance_over_the_diagonal() {
    let reference = trajectory(vec![vec![Vec3::ZERO; 4]; 3], 2.0);
    assert_eq!(reference.error_against(&reference), Some((0.0, 0.0)));
    // Every particle 0.1 m off in the last sample only: RMS over 3 samples is
    // 0.1·√(1/3); the final drape's error is 0.1; both over the 2 m diagonal.
    let mut moved = reference.samples.clone();
    moved[2] = vec![Vec3::new(0.0, 0.1, 0.0); 4];
    let (all, last) = trajectory(moved, 2.0).error_against(&reference).unwrap();
    assert!((all - 0.1 / 3f64.sqrt() / 2.0).abs() < 1e-7, "{all}");
    assert!((last - 0.05).abs() < 1e-7, "{last}");
    // A run that failed early has fewer samples: no error.
    assert_eq!(
        trajectory(vec![vec![Vec3::ZERO; 4]; 2], 2.0).error_against(&reference),
        None
    );
}

#[test]
fn samples_are_every_tenth_of_a_second_on_every_configuration_alike() {
    let scene = ClothScene::load(scene_path("curtain.ron")).unwrap();
    let case = Case::new("curtain", &scene, 0, 3.0).unwrap();
    let steps = case.sample_steps();
    assert_eq!(steps.len(), 30);
    let dt = scene.timestep as f64;
    for (k, s) in steps.iter().enumerate() {
        let t = *s as f64 * dt;
        // The first step at or past each 0.1 s.
        assert!(
            t + 1e-9 >= (k + 1) as f64 * SAMPLE_INTERVAL
                && t < (k + 1) as f64 * SAMPLE_INTERVAL + dt
        );
    }
    // The reference is the cloth's springs as mass-spring, whatever model it runs.
    let card = ClothScene::load(scene_path("card.ron")).unwrap();
    assert!(matches!(
        card.cloths[0].cloth.params.model,
        Model::ShapeMatching(_)
    ));
    let case = Case::new("card", &card, 0, 3.0).unwrap();
    assert_eq!(case.base().model, Model::MassSpring);
    assert_eq!(case.scene.cloths.len(), 1);
    assert!(Case::new("none", &card, 2, 3.0).is_err());
}

#[test]
fn a_coarse_configuration_is_further_from_the_reference_than_a_fine_one() {
    let mut scene = ClothScene::load(scene_path("curtain.ron")).unwrap();
    scene.apply_override("cloth.shape.width=12").unwrap();
    scene.apply_override("cloth.shape.height=10").unwrap();
    let case = Case::new("small curtain", &scene, 0, 1.0).unwrap();
    let (_, reference) = case.reference(16).unwrap();
    let error = |substeps| {
        let params = ClothParams {
            substeps,
            ..case.base()
        };
        let run = case.simulate(&params).unwrap();
        run.error_against(&reference).expect("stable").0
    };
    let auto = error(Substeps::default());
    let finer = error(Substeps::Fixed(
        4 * bevy_cloth_lab::SceneRun::new(&case.scene).unwrap().cloths[0]
            .1
            .stable_substeps(scene.timestep),
    ));
    assert!(
        finer < auto,
        "4× the automatic substeps: {finer}, automatic: {auto}"
    );
}

#[test]
fn the_full_app_steps_and_writes_the_mesh_each_frame() {
    let row = fps::app_frame("1", 100, 3, 5).unwrap();
    assert_eq!(row.particles, 100);
    assert_eq!(row.failed_at_frame, None);
    assert!(row.ms_per_frame.is_some_and(|ms| ms > 0.0) && row.fps.is_some_and(f64::is_finite));
    assert_eq!(row.seed_fps, Some(60.0));
}

#[test]
fn goal_forces_conserve_momentum_on_a_free_cloth() {
    // Until the goal offsets were formed from relative positions with each cluster's
    // mean removed, the f32 rounding of the centre of mass acted as a net force: the
    // first of these cloths drifted at ~1 m/s² and its energy grew 40× in one second.
    // For p ≠ 1 each particle's own scale (|d|/L)^(p−1) undid the zero sum of the
    // offsets, a net force the goal forces now take back out.
    for (k, m) in [(1_000.0, 1e-4), (25_000.0, 1e-6), (100.0, 1e-5)] {
        for (clusters, model) in [
            (1, "shape-matching"),
            (3, "shape-matching"),
            (1, "shape-matching p=0.5"),
            (3, "shape-matching p=3"),
        ] {
            let mut params =
                stability::params(model, k, m, Integrator::Verlet, Substeps::default()).unwrap();
            if let Model::ShapeMatching(sm) = &mut params.model {
                sm.clusters = clusters;
            }
            let mut cloth = stability::probe_cloth(&params).unwrap();
            let env = stability::quiet();
            let e0 = cloth.energy(&env).total() as f64;
            assert_eq!(stability::probe(&mut cloth, 0.001, 1000), None);
            let p = cloth.particles();
            let total: f32 = p.mass.iter().sum();
            let momentum: Vec3 = (0..p.len()).map(|i| p.velocity[i] * p.mass[i]).sum();
            // Against the momentum of the whole cloth moving at the perturbation's speed.
            let v_scale = (2.0 * e0 / total as f64).sqrt() as f32;
            assert!(
                momentum.length() < 1e-3 * total * v_scale,
                "{model}, k {k}, m {m}, {clusters}×{clusters}: momentum {momentum} against {}",
                total * v_scale
            );
            assert!(stability::kinetic(&cloth) <= 2.0 * e0, "k {k}, m {m}");
        }
    }
}

#[test]
fn the_peer_bench_reads_strain_and_sag_from_positions_as_defined() {
    use bevy_cloth_lab::peers::{Hang, accuracy, rest};
    // A 5×5 grid hung at rest: no strain, no sag. Scaled by 1.1 about its top row's
    // first particle: every structural pair 10% long, the bottom row 10% of the height
    // lower.
    let start = rest(5, Hang::TopRow);
    let (strain, sag) = accuracy(&start, &start, 5);
    assert!(strain.abs() < 1e-6 && sag.abs() < 1e-6, "{strain} {sag}");
    let scaled: Vec<Vec3> = start.iter().map(|p| *p * 1.1).collect();
    let (strain, sag) = accuracy(&scaled, &start, 5);
    assert!((strain - 0.1).abs() < 1e-5, "strain {strain}");
    assert!((sag - 0.1).abs() < 1e-5, "sag {sag}");
}

#[test]
fn the_peer_bench_times_every_solver_and_never_a_failed_run() {
    use bevy_cloth_lab::peers::{Hang, Peer, measure};
    // Every solver on a small hanging cloth: timed, its strain within reason.
    for peer in [
        Peer::Ours {
            substeps: 5,
            tethers: true,
            self_collision: false,
            lines: false,
        },
        Peer::Ours {
            substeps: 5,
            tethers: true,
            self_collision: false,
            lines: true,
        },
        Peer::Ours {
            substeps: 5,
            tethers: true,
            self_collision: true,
            lines: true,
        },
        Peer::Rapier {
            steps: 1,
            iterations: 4,
        },
        Peer::Sticks { sweeps: 20 },
    ] {
        let row = measure(8, Hang::TopRow, peer, 12).unwrap();
        assert!(row.failed.is_none(), "{peer:?}: {:?}", row.failed);
        let (ms, strain) = (row.ms.unwrap(), row.strain.unwrap());
        assert!(
            ms > 0.0 && strain < 0.05,
            "{peer:?}: {ms} ms, strain {strain}"
        );
        let (lo, hi) = row.ms_spread.unwrap();
        assert!(
            lo <= ms && ms <= hi,
            "{peer:?}: median {ms} outside [{lo}, {hi}]"
        );
    }
    // Five sweeps of sticks cannot hold a 32×32 cloth from its corners: past 100% strain,
    // the run is failed, with no time and no strain to rank it by.
    let row = measure(32, Hang::Corners, Peer::Sticks { sweeps: 5 }, 60).unwrap();
    assert!(row.failed.is_some(), "{row:?}");
    assert!(row.ms.is_none() && row.strain.is_none() && row.ns_per_projection.is_none());
}
