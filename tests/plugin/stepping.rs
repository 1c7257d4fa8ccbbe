//! Headless App tests of stepping: the fixed clock, several cloths, pause, game systems
//! between the stages, the timestep left alone, cloths in contact, a step that goes non-
//! finite, edits that change the next step.

use bevy::prelude::*;
use bevy_cloth::params::{Model, SpringParams, Substeps};
use bevy_cloth::prelude::*;

use crate::common::*;

#[test]
fn one_update_of_16_ms_runs_one_fixed_step_and_five_run_five() {
    let mut app = app();
    let e = app
        .world_mut()
        .spawn(Cloth::grid(4, 4, 0.1).with_params(quiet_params()))
        .id();
    // Run until the cloth is built and has stepped once, so time is flowing.
    for _ in 0..3 {
        app.update();
    }
    let t0 = sim_time(&app, e);
    app.update();
    let t1 = sim_time(&app, e);
    assert!(
        (t1 - t0 - 0.016).abs() < 1e-5,
        "one update stepped {} s",
        t1 - t0
    );
    for _ in 0..5 {
        app.update();
    }
    let t6 = sim_time(&app, e);
    assert!(
        (t6 - t1 - 0.080).abs() < 1e-5,
        "five updates stepped {} s",
        t6 - t1
    );
}

#[test]
fn gravity_toggle_changes_the_next_step() {
    let mut app = app();
    let e = app
        .world_mut()
        .spawn(Cloth::grid(4, 4, 0.1).with_pins(ClothPins::None))
        .id();
    app.world_mut()
        .resource_mut::<ClothEnvironment>()
        .gravity_enabled = false;
    for _ in 0..5 {
        app.update();
    }
    let y = |app: &App| {
        app.world()
            .get::<ClothSimulation>(e)
            .unwrap()
            .solver
            .positions()[0]
            .y
    };
    let still = y(&app);
    app.update();
    assert_eq!(y(&app), still, "no gravity, no motion");
    app.world_mut()
        .resource_mut::<ClothEnvironment>()
        .gravity_enabled = true;
    app.update();
    assert!(y(&app) < still, "gravity on: it falls");
}

#[test]
fn several_cloths_step_together() {
    let mut app = app();
    let light = app
        .world_mut()
        .spawn(Cloth::grid(4, 4, 0.1).with_params(ClothParams {
            substeps: Substeps::Fixed(40),
            ..ClothParams::seeds()
        }))
        .id();
    let heavy = app
        .world_mut()
        .spawn((
            Cloth::grid(8, 8, 0.05).with_params(ClothParams {
                substeps: Substeps::Fixed(60),
                ..ClothParams::seeds()
            }),
            Transform::from_xyz(2.0, 0.0, 0.0),
        ))
        .id();
    for _ in 0..10 {
        app.update();
    }
    let time = |e| sim_time(&app, e);
    assert!((time(light) - time(heavy)).abs() < 1e-5);
    assert!(time(light) > 0.1);
    let sim = app.world().get::<ClothSimulation>(heavy).unwrap();
    assert_eq!(sim.solver.substeps(), 60);
    assert!(sim.solver.is_stable());
}

#[test]
fn pause_stops_every_cloth() {
    let mut app = app();
    let e = app.world_mut().spawn(Cloth::grid(4, 4, 0.1)).id();
    for _ in 0..3 {
        app.update();
    }
    app.world_mut().resource_mut::<ClothPause>().paused = true;
    let t = sim_time(&app, e);
    for _ in 0..3 {
        app.update();
    }
    assert_eq!(sim_time(&app, e), t);
}

#[test]
fn stiffness_edits_change_the_next_step() {
    // Two identical cloths on the seeds' springs (a fabric's stiffness replaces them);
    // one gets stiffer springs: the next step differs.
    let mut app = app();
    let spawn = |app: &mut App| {
        let cloth = Cloth::grid(5, 5, 0.1)
            .with_pins(ClothPins::TopRow)
            .with_params(ClothParams::seeds());
        app.world_mut().spawn(cloth).id()
    };
    let (a, b) = (spawn(&mut app), spawn(&mut app));
    for _ in 0..5 {
        app.update();
    }
    let pos = |app: &App, e| {
        app.world()
            .get::<ClothSimulation>(e)
            .unwrap()
            .solver
            .positions()
            .to_vec()
    };
    assert_eq!(pos(&app, a), pos(&app, b));
    app.world_mut()
        .get_mut::<Cloth>(b)
        .unwrap()
        .params
        .springs
        .structural
        .stiffness = 200.0;
    app.update();
    assert_ne!(pos(&app, a), pos(&app, b));
}

/// A cloth whose step goes non-finite (parameters no explicit step can hold) is paused
/// with `ClothInvalid` saying so, keeps finite positions in its mesh, and runs again
/// after a reset; with valid parameters again and a reset it stays running.
#[test]
fn a_cloth_that_goes_non_finite_is_paused_with_the_reason_and_recovers() {
    let mut app = app();
    let (e, handle) = spawn_small_cloth(&mut app);
    let absurd = ClothParams {
        model: Model::MassSpring,
        springs: SpringParams::from_structural(1e5),
        node_mass: 1e-3,
        substeps: Substeps::Fixed(1),
        strain_limit: None,
        ..quiet_params()
    };
    app.world_mut().get_mut::<Cloth>(e).unwrap().params = absurd;
    let mut invalid = None;
    for _ in 0..300 {
        app.update();
        if let Some(reason) = app.world().get::<ClothInvalid>(e) {
            invalid = Some(reason.0.clone());
            break;
        }
    }
    let reason = invalid.expect("the absurd parameters never went non-finite");
    assert!(matches!(reason, ClothError::NonFinite { .. }), "{reason}");
    let t = sim_time(&app, e);
    app.update();
    assert_eq!(sim_time(&app, e), t, "a paused cloth does not step");
    let sim = app.world().get::<ClothSimulation>(e).unwrap();
    assert!(sim.solver.is_finite());
    assert!(
        mesh_positions(&app, &handle)
            .iter()
            .flatten()
            .all(|v| v.is_finite())
    );

    // A reset lifts the pause (the parameters are still absurd: it runs, then fails again).
    app.world_mut()
        .get_mut::<ClothSimulation>(e)
        .unwrap()
        .reset();
    app.update();
    assert!(sim_time(&app, e) > 0.0, "stepping again after the reset");
    for _ in 0..300 {
        app.update();
        if app.world().get::<ClothInvalid>(e).is_some() {
            break;
        }
    }
    assert!(app.world().get::<ClothInvalid>(e).is_some(), "fails again");
    app.world_mut().get_mut::<Cloth>(e).unwrap().params = quiet_params();
    app.world_mut()
        .get_mut::<ClothSimulation>(e)
        .unwrap()
        .reset();
    for _ in 0..20 {
        app.update();
    }
    assert!(app.world().get::<ClothInvalid>(e).is_none());
    assert!(
        app.world()
            .get::<ClothSimulation>(e)
            .unwrap()
            .solver
            .is_finite()
    );
}

/// How many times the game's substep system ran.
#[derive(Resource, Default)]
struct SubstepCalls(u32);

/// A game system between two stages: adds no force, only counts.
fn count_substeps(mut calls: ResMut<SubstepCalls>, mut cloths: Query<&mut ClothSimulation>) {
    calls.0 += 1;
    for mut sim in &mut cloths {
        sim.solver.add_force(0, Vec3::ZERO);
    }
}

/// The headless app counting the calls of a game system put between the stages, when
/// `with_system` (else the count stays 0 and no game system is there).
fn app_counting_substeps(with_system: bool) -> App {
    let mut app = app();
    app.init_resource::<SubstepCalls>();
    if with_system {
        app.add_systems(
            ClothSubstep,
            count_substeps
                .after(ClothSubstepSystems::AccumulateForces)
                .before(ClothSubstepSystems::Integrate),
        );
    }
    app
}

/// A game's system put between the stages (`ClothSubstepSystems`) runs once per substep;
/// without one, the plugin steps each cloth's substeps in one task. Both ways the cloths
/// end on the same bits.
#[test]
fn a_system_between_the_stages_runs_every_substep_and_the_bits_do_not_depend_on_it() {
    let run = |with_system: bool| {
        let mut app = app_counting_substeps(with_system);
        let params = ClothParams {
            substeps: Substeps::Fixed(5),
            ..quiet_params()
        };
        let cloths: Vec<Entity> = (0..3)
            .map(|k| {
                let cloth = Cloth::grid(6, 5, 0.1).with_params(params);
                let at = Transform::from_xyz(k as f32, 2.0, 0.0);
                app.world_mut().spawn((cloth, at, ClothSleep::never())).id()
            })
            .collect();
        for _ in 0..30 {
            app.update();
        }
        let steps = (sim_time(&app, cloths[0]) / 0.016).round() as u32;
        let positions: Vec<Vec<Vec3>> = cloths
            .iter()
            .map(|&e| {
                let sim = app.world().get::<ClothSimulation>(e).unwrap();
                sim.solver.positions().to_vec()
            })
            .collect();
        (positions, steps, app.world().resource::<SubstepCalls>().0)
    };
    let (alone, steps, none) = run(false);
    let (with_system, _, calls) = run(true);
    assert_eq!(none, 0);
    assert!(steps > 20, "{steps} steps");
    assert_eq!(calls, 5 * steps, "once per substep");
    assert_eq!(alone, with_system);
}

/// `ClothPlugin::default()` leaves the game's fixed rate alone; `with_timestep` sets it.
#[test]
fn the_plugin_changes_the_fixed_timestep_only_when_asked() {
    let build = |plugin: ClothPlugin| {
        let mut app = App::new();
        app.add_plugins((MinimalPlugins, AssetPlugin::default(), plugin));
        app.world().resource::<Time<Fixed>>().timestep()
    };
    let bevy_default = Time::<Fixed>::default().timestep();
    assert_eq!(build(ClothPlugin::default()), bevy_default);
    let asked = std::time::Duration::from_millis(16);
    assert_ne!(asked, bevy_default);
    assert_eq!(build(ClothPlugin::default().with_timestep(asked)), asked);
}

/// Two cloths in contact (self-collision on, one laid 2 cm over the other on the ground)
/// step together: on the plugin's task path (`solver::substep_together`) and on its
/// stage-by-stage path (a game system between the stages, `solver::exchange_cloths`
/// before the constraints) they end on the same bits, and they did touch. The lower one
/// asks for 3 substeps, the upper for 5: in contact both take 5.
#[test]
fn cloths_in_contact_step_together_the_same_on_both_paths() {
    let run = |with_system: bool| {
        let mut app = app_counting_substeps(with_system);
        app.world_mut().spawn(ClothCollider::plane());
        let cloths: Vec<Entity> = [(0.1, 3), (0.12, 5)]
            .into_iter()
            .map(|(y, substeps)| {
                let (mut cloth, place) = lying_cloth(Vec3::new(0.0, y, 0.0));
                cloth.params.self_collision.enabled = true;
                cloth.params.substeps = Substeps::Fixed(substeps);
                app.world_mut()
                    .spawn((cloth, place, ClothSleep::never()))
                    .id()
            })
            .collect();
        let mut touched = false;
        for _ in 0..40 {
            app.update();
            let solvers: Vec<_> = cloths
                .iter()
                .filter_map(|&e| app.world().get::<ClothSimulation>(e))
                .map(|s| &s.solver)
                .collect();
            if solvers.iter().any(|s| s.touches_other_cloths()) {
                touched = true;
                let counts: Vec<u32> = solvers.iter().map(|s| s.last_report().substeps).collect();
                assert_eq!(counts, [5, 5], "cloths in contact take one count");
            }
        }
        let positions: Vec<Vec<Vec3>> = cloths
            .iter()
            .map(|&e| {
                app.world()
                    .get::<ClothSimulation>(e)
                    .unwrap()
                    .solver
                    .positions()
                    .to_vec()
            })
            .collect();
        (positions, touched, app.world().resource::<SubstepCalls>().0)
    };
    let (alone, touched, none) = run(false);
    let (with_system, _, calls) = run(true);
    assert!(touched, "the cloths are in contact");
    assert_eq!(none, 0);
    assert!(calls > 0);
    let top = alone[1].iter().map(|p| p.y).sum::<f32>() / 36.0;
    let bottom = alone[0].iter().map(|p| p.y).sum::<f32>() / 36.0;
    assert!(top > bottom + 0.02, "in layers: {top} over {bottom}");
    assert!(alone == with_system, "the two paths differ");
}
