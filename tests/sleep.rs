//! Sleeping: a still cloth falls asleep, costs no step, and wakes within one
//! step on each thing that can move it, without a jump. Headless App, manual 16 ms time.

use bevy::prelude::*;
use bevy_cloth::prelude::*;

fn sim_time(app: &App, e: Entity) -> f32 {
    app.world().get::<ClothSimulation>(e).unwrap().solver.time()
}

fn asleep(app: &App, e: Entity) -> bool {
    app.world().get::<ClothSleep>(e).unwrap().asleep
}

fn positions(app: &App, e: Entity) -> Vec<Vec3> {
    let sim = app.world().get::<ClothSimulation>(e).unwrap();
    sim.solver.positions().to_vec()
}

/// A small curtain hanging from its top row, well damped, run until it sleeps (at most
/// 30 s); a ball collider far to the side.
fn sleeping_curtain() -> (App, Entity, Entity) {
    let mut app = bevy_cloth::headless::headless_app();
    let params = ClothParams {
        drag: 2e-2,
        ..ClothParams::seeds()
    };
    let cloth = app
        .world_mut()
        .spawn((
            Cloth::grid(6, 5, 0.1)
                .with_pins(ClothPins::TopRow)
                .with_params(params),
            ClothStats::default(),
            Transform::from_xyz(0.0, 2.0, 0.0),
        ))
        .id();
    let ball = app
        .world_mut()
        .spawn((
            ClothCollider::sphere(0.1),
            Transform::from_xyz(5.0, 2.0, 0.0),
        ))
        .id();
    for _ in 0..(30.0 / 0.016) as usize {
        app.update();
        if asleep(&app, cloth) {
            break;
        }
    }
    assert!(asleep(&app, cloth), "the damped curtain never fell asleep");
    assert!(app.world().get::<ClothStats>(cloth).unwrap().asleep);
    (app, cloth, ball)
}

/// Asleep, the cloth does not step: its clock stands still over a second.
fn assert_sleeps_on(app: &mut App, e: Entity) {
    let t = sim_time(app, e);
    for _ in 0..60 {
        app.update();
    }
    assert_eq!(sim_time(app, e), t, "a sleeping cloth stepped");
    assert!(asleep(app, e));
}

/// What one 16 ms step can move a particle at rest that gravity is taken from or given
/// to: `g dt² / 2`, with 10% to spare.
const ONE_STEP: f32 = 0.5 * 9.81 * 0.016 * 0.016 * 1.1;

/// After `disturb`, the next update steps the cloth again, and no particle moves more
/// than one normal step moves it plus `moved`, what the disturbance itself moves (no
/// jump: it was at rest).
fn assert_wakes_on(name: &str, moved: f32, disturb: impl FnOnce(&mut App, Entity, Entity)) {
    let (mut app, cloth, ball) = sleeping_curtain();
    assert_sleeps_on(&mut app, cloth);
    let before = positions(&app, cloth);
    let t = sim_time(&app, cloth);
    disturb(&mut app, cloth, ball);
    app.update();
    assert!(!asleep(&app, cloth), "{name}: still asleep");
    assert!(sim_time(&app, cloth) > t, "{name}: did not step");
    let jump = before
        .iter()
        .zip(positions(&app, cloth))
        .map(|(a, b)| a.distance(b))
        .fold(0.0, f32::max);
    assert!(
        jump <= ONE_STEP + moved,
        "{name}: a particle jumped {jump} m on waking"
    );
}

#[test]
fn a_still_cloth_falls_asleep_and_stops_stepping() {
    let (mut app, cloth, _) = sleeping_curtain();
    assert_sleeps_on(&mut app, cloth);
    // Nothing that cannot reach it wakes it: the far ball moving, identical parameters.
    let ball = app.world_mut().spawn_empty().id();
    app.world_mut().entity_mut(ball).insert((
        ClothCollider::sphere(0.1),
        Transform::from_xyz(-6.0, 0.0, 0.0),
    ));
    let params = app.world().get::<Cloth>(cloth).unwrap().params;
    app.world_mut().get_mut::<Cloth>(cloth).unwrap().params = params;
    assert_sleeps_on(&mut app, cloth);
}

#[test]
fn it_wakes_on_a_parameter_edit() {
    assert_wakes_on("parameters", 0.0, |app, cloth, _| {
        app.world_mut()
            .get_mut::<Cloth>(cloth)
            .unwrap()
            .params
            .node_mass *= 1.5;
    });
}

#[test]
fn it_wakes_on_wind_and_on_gravity() {
    assert_wakes_on("wind", 0.0, |app, _, _| {
        app.world_mut()
            .resource_mut::<ClothEnvironment>()
            .wind
            .strength = 1e-3;
    });
    assert_wakes_on("gravity", 0.0, |app, _, _| {
        app.world_mut()
            .resource_mut::<ClothEnvironment>()
            .gravity_enabled = false;
    });
}

#[test]
fn it_wakes_when_its_transform_moves_the_pins() {
    // The pins move with the transform, 1 cm in this step.
    assert_wakes_on("transform", 0.01, |app, cloth, _| {
        app.world_mut()
            .get_mut::<Transform>(cloth)
            .unwrap()
            .translation
            .x += 0.01;
    });
}

#[test]
fn it_wakes_when_a_collider_moves_near_it() {
    // From 5 m to the side to just touch the cloth's face (which hangs in z = 0): the
    // ball pushes the particles it reaches out over the step.
    assert_wakes_on("collider", 0.1, |app, _, ball| {
        app.world_mut()
            .get_mut::<Transform>(ball)
            .unwrap()
            .translation = Vec3::new(0.0, 1.8, 0.05);
    });
}

#[test]
fn it_wakes_on_a_grab_and_on_a_cut() {
    assert_wakes_on("grab", 0.0, |app, cloth, _| {
        let mut sim = app.world_mut().get_mut::<ClothSimulation>(cloth).unwrap();
        assert!(sim.solver.grab(29));
    });
    assert_wakes_on("cut", 0.0, |app, cloth, _| {
        let mut sim = app.world_mut().get_mut::<ClothSimulation>(cloth).unwrap();
        assert!(sim.solver.tear(0));
    });
}

#[test]
fn it_wakes_on_a_message_from_the_game() {
    assert_wakes_on("message", 0.0, |app, cloth, _| {
        app.world_mut().write_message(ClothWake(cloth));
    });
}

#[test]
fn sleeping_can_be_switched_off() {
    let (mut app, cloth, _) = sleeping_curtain();
    *app.world_mut().get_mut::<ClothSleep>(cloth).unwrap() = ClothSleep::never();
    let t = sim_time(&app, cloth);
    for _ in 0..120 {
        app.update();
    }
    assert!(
        sim_time(&app, cloth) > t + 1.5,
        "a cloth that may not sleep stepped"
    );
    assert!(!asleep(&app, cloth));
}
