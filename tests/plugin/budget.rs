//! The frame budget in an app: each cloth's share, the events when a cloth goes over it
//! and comes back, the stage's cost as a resource and as diagnostics, a refused budget,
//! and the cap on steps a frame.

use std::time::Duration;

use bevy::diagnostic::DiagnosticsStore;
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use bevy_cloth::params::{Air, Model, WindField, XpbdParams};
use bevy_cloth::prelude::*;

use crate::common::*;

/// A polyester flag of 651 particles in 10 m/s air, pinned along one side: its accuracy
/// asks for about 150–200 substeps.
fn flag() -> (Cloth, Transform) {
    let pins = (0..21).map(|j| j * 31).collect();
    let cloth = Cloth::grid(31, 21, 0.04)
        .with_pins(ClothPins::Indices(pins))
        .with_params(ClothParams {
            model: Model::Xpbd(XpbdParams::default()),
            fabric: Some(Fabric::POLYESTER),
            ..ClothParams::seeds()
        });
    (cloth, Transform::from_xyz(0.0, 2.0, 0.0))
}

fn windy_app() -> App {
    let mut app = app();
    app.insert_resource(ClothEnvironment(bevy_cloth::params::Environment {
        air: Some(Air {
            velocity: Vec3::new(10.0, 0.0, 0.5),
            field: WindField::Trigonometric,
            ..default()
        }),
        ..default()
    }));
    app
}

/// The cloth's last step report.
fn last_report(app: &App, e: Entity) -> bevy_cloth::solver::StepReport {
    app.world()
        .get::<ClothSimulation>(e)
        .expect("the cloth is built")
        .solver
        .last_report()
}

#[derive(Resource, Default)]
struct Seen {
    over: Vec<ClothOverBudget>,
    within: usize,
}

#[test]
fn a_cloth_over_its_share_says_so_and_says_when_it_is_back() {
    let mut app = windy_app();
    // A budget of 2 ms: 15 substeps of the flag, half what its gusts ask for.
    app.insert_resource(ClothBudget {
        milliseconds: Some(2.0),
        ..default()
    });
    app.init_resource::<Seen>()
        .add_observer(|over: On<ClothOverBudget>, mut seen: ResMut<Seen>| {
            seen.over.push(*over.event());
        })
        .add_observer(|_: On<ClothWithinBudget>, mut seen: ResMut<Seen>| {
            seen.within += 1;
        });
    let e = app.world_mut().spawn(flag()).id();
    for _ in 0..60 {
        app.update();
    }
    // 2 ms at the default 200 ns a particle-substep is 10,000 particle-substeps, 15
    // substeps of 651 particles.
    let stats = app.world().get::<ClothStats>(e).cloned();
    let report = last_report(&app, e);
    // Its share, or the floor its springs' speed sets (`StepReport::budget_floor`).
    assert_eq!(report.substeps, 15.max(report.budget_floor));
    assert!(report.over_budget && report.needed > 15, "{report:?}");
    if let Some(stats) = stats {
        assert!(stats.over_budget && stats.needed_substeps == report.needed);
    }
    // One event each way over and back: now over, one more over than back.
    let seen = app.world().resource::<Seen>();
    let within = seen.within;
    assert_eq!(seen.over.len(), within + 1, "events each way");
    let last = seen.over.last().unwrap();
    assert_eq!((last.entity, last.allowed), (e, 15));
    assert!(last.needed > 15 && last.strain > 0.0);
    // The whole stage, as a resource and as diagnostics.
    let stage = *app.world().resource::<ClothStageStats>();
    assert!(stage.step_ms > 0.0 && stage.most_substeps == report.substeps);
    assert_eq!(stage.over_budget, 1);
    assert!(
        stage.planned_ms > 1.9 && stage.planned_ms <= 2.0,
        "{stage:?}"
    );
    let store = app.world().resource::<DiagnosticsStore>();
    let step = store
        .get(&ClothStageStats::STEP_MS)
        .and_then(|d| d.value())
        .expect("the stage's time is measured");
    assert!(step > 0.0);
    // Accuracy first: the cloth takes what it needs, and says it is back.
    *app.world_mut().resource_mut::<ClothBudget>() = ClothBudget::UNLIMITED;
    for _ in 0..3 {
        app.update();
    }
    let report = last_report(&app, e);
    assert!(
        !report.over_budget && report.substeps == report.needed,
        "{report:?}"
    );
    assert_eq!(app.world().resource::<Seen>().within, within + 1);
}

/// Two flags share a world budget of 2 ms by priority: twice the priority, twice the
/// substeps.
#[test]
fn a_short_budget_is_shared_by_priority() {
    let mut app = windy_app();
    app.insert_resource(ClothBudget {
        milliseconds: Some(2.0),
        per_cloth_milliseconds: None,
        ..default()
    });
    let low = app.world_mut().spawn(flag()).id();
    let (cloth, at) = flag();
    let high = app
        .world_mut()
        .spawn((
            cloth,
            at.with_translation(Vec3::new(0.0, 2.0, 3.0)),
            ClothPriority(2.0),
        ))
        .id();
    for _ in 0..30 {
        app.update();
    }
    // 10,000 particle-substeps: 3,333 and 6,667, 5 and 10 substeps (or the floor each
    // flag's springs' speed sets, `StepReport::budget_floor`).
    let substeps = |e, share: u32| {
        let report = last_report(&app, e);
        (report.substeps, share.max(report.budget_floor))
    };
    let (low, high) = (substeps(low, 5), substeps(high, 10));
    assert_eq!(low.0, low.1);
    assert_eq!(high.0, high.1);
}

/// A budget of 0 ms is refused (logged) and caps nothing, not even by its valid half
/// (0.5 ms for one cloth would be 3 substeps).
#[test]
fn a_refused_budget_caps_nothing() {
    let mut app = windy_app();
    app.insert_resource(ClothBudget {
        milliseconds: Some(0.0),
        per_cloth_milliseconds: Some(0.5),
        ..default()
    });
    let e = app.world_mut().spawn(flag()).id();
    for _ in 0..20 {
        app.update();
    }
    let report = last_report(&app, e);
    assert!(report.substeps > 3 && !report.over_budget, "{report:?}");
}

/// A frame of 80 ms holds five fixed steps of 16 ms; at a cap of three a frame the cloths
/// take three of them and count those they skip.
#[test]
fn the_cloths_step_at_most_three_times_a_frame() {
    let mut app = app();
    app.insert_resource(ClothBudget {
        max_steps_per_frame: Some(3),
        ..default()
    });
    let e = app
        .world_mut()
        .spawn(Cloth::grid(4, 4, 0.1).with_params(quiet_params()))
        .id();
    for _ in 0..3 {
        app.update();
    }
    let t0 = sim_time(&app, e);
    let skipped = app.world().resource::<ClothStageStats>().skipped_steps;
    app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_millis(
        80,
    )));
    app.update();
    let t1 = sim_time(&app, e);
    assert!((t1 - t0 - 0.048).abs() < 1e-5, "stepped {} s", t1 - t0);
    let stage = *app.world().resource::<ClothStageStats>();
    assert_eq!(stage.steps_this_frame, 3);
    assert!(stage.skipped_steps - skipped >= 2, "{stage:?}");
    // Without the cap, all five.
    app.world_mut()
        .resource_mut::<ClothBudget>()
        .max_steps_per_frame = None;
    app.update();
    let t2 = sim_time(&app, e);
    assert!((t2 - t1 - 0.080).abs() < 1e-5, "stepped {} s", t2 - t1);
}
