//! Headless App tests of `ClothPlugin`: MinimalPlugins, manual time, no window.

mod common;

use bevy::ecs::message::Messages;
use bevy::mesh::{Mesh, Mesh3d, VertexAttributeValues};
use bevy::prelude::*;
use bevy_cloth::ColliderKind;
use bevy_cloth::params::{Model, SpringParams, Substeps};
use bevy_cloth::prelude::*;

fn app() -> App {
    bevy_cloth::headless::headless_app()
}

/// Default parameters: automatic substeps keep them stable.
fn quiet_params() -> ClothParams {
    ClothParams::default()
}

fn sim_time(app: &App, e: Entity) -> f32 {
    app.world().get::<ClothSimulation>(e).unwrap().solver.time()
}

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

/// A 5×4 cloth 2 m up, after two updates: its entity and the mesh the plugin made.
fn spawn_small_cloth(app: &mut App) -> (Entity, Handle<Mesh>) {
    let e = app
        .world_mut()
        .spawn((
            Cloth::grid(5, 4, 0.1).with_params(quiet_params()),
            Transform::from_xyz(0.0, 2.0, 0.0),
        ))
        .id();
    app.update();
    app.update();
    let handle = app
        .world()
        .get::<Mesh3d>(e)
        .expect("the plugin adds a mesh")
        .0
        .clone();
    (e, handle)
}

/// The positions in a mesh.
fn mesh_positions(app: &App, handle: &Handle<Mesh>) -> Vec<[f32; 3]> {
    let mesh = app.world().resource::<Assets<Mesh>>().get(handle).unwrap();
    match mesh.attribute(Mesh::ATTRIBUTE_POSITION) {
        Some(VertexAttributeValues::Float32x3(p)) => p.clone(),
        _ => panic!("no positions"),
    }
}

#[test]
fn mesh_is_created_and_rewritten_in_place() {
    let mut app = app();
    // Drawn where the last step ended (see a_hidden_cloth_steps_but_writes_its_mesh_only_when_shown).
    app.insert_resource(ClothInterpolation(false));
    let (e, handle) = spawn_small_cloth(&mut app);
    let read = |app: &App| mesh_positions(app, &handle);
    let before = read(&app);
    assert_eq!(before.len(), 20);
    for _ in 0..10 {
        app.update();
    }
    let after = read(&app);
    assert_eq!(
        app.world().get::<Mesh3d>(e).unwrap().0,
        handle,
        "a new mesh was made"
    );
    assert_ne!(before, after, "the mesh did not follow the cloth");
    // Positions are local to the entity: solver world position = transform · mesh position.
    let sim = app.world().get::<ClothSimulation>(e).unwrap();
    let world = sim.solver.positions()[19];
    let local = Vec3::from(after[19]);
    assert!(
        (local + Vec3::new(0.0, 2.0, 0.0) - world).length() < 1e-4,
        "local {local} world {world}"
    );
    // Pinned corners sit where the grid puts them in the entity's frame.
    assert!((Vec3::from(after[0]) - Vec3::new(-0.2, 0.0, 0.0)).length() < 1e-5);
}

#[test]
fn edits_take_effect_and_grid_changes_rebuild() {
    let mut app = app();
    let e = app
        .world_mut()
        .spawn(Cloth::grid(4, 4, 0.1).with_params(quiet_params()))
        .id();
    app.update();
    app.update();
    app.world_mut()
        .get_mut::<Cloth>(e)
        .unwrap()
        .params
        .springs
        .structural
        .stiffness = 321.0;
    app.update();
    let sim = app.world().get::<ClothSimulation>(e).unwrap();
    assert_eq!(sim.solver.params().springs.structural.stiffness, 321.0);
    assert_eq!(sim.solver.particle_count(), 16);
    app.world_mut().get_mut::<Cloth>(e).unwrap().shape = ClothShape::Grid {
        width: 6,
        height: 3,
        spacing: 0.1,
    };
    app.update();
    app.update();
    assert_eq!(
        app.world()
            .get::<ClothSimulation>(e)
            .unwrap()
            .solver
            .particle_count(),
        18
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
fn pinned_cloth_follows_its_transform() {
    let mut app = app();
    let e = app
        .world_mut()
        .spawn((Cloth::grid(4, 4, 0.1), Transform::from_xyz(0.0, 1.0, 0.0)))
        .id();
    for _ in 0..3 {
        app.update();
    }
    app.world_mut().get_mut::<Transform>(e).unwrap().translation = Vec3::new(1.0, 1.5, 0.0);
    for _ in 0..3 {
        app.update();
    }
    let sim = app.world().get::<ClothSimulation>(e).unwrap();
    let corner = sim.solver.positions()[0];
    assert!(
        (corner - Vec3::new(1.0 - 0.15, 1.5, 0.0)).length() < 1e-4,
        "corner at {corner}"
    );
}

/// A small cloth hung by its top row that tears under [`TEARING_GRAVITY`].
fn tearing_cloth() -> Cloth {
    let params = ClothParams {
        tear_ratio: Some(1.3),
        strain_limit: None,
        ..ClothParams::default()
    };
    Cloth::grid(5, 5, 0.1)
        .with_pins(ClothPins::TopRow)
        .with_params(params)
}

/// Gravity far past what [`tearing_cloth`]'s springs hold.
const TEARING_GRAVITY: Vec3 = Vec3::new(0.0, -30_000.0, 0.0);

#[test]
fn torn_springs_send_messages() {
    let mut app = app();
    let e = app.world_mut().spawn(tearing_cloth()).id();
    app.world_mut().resource_mut::<ClothEnvironment>().gravity = TEARING_GRAVITY;
    let mut cursor = app.world().resource::<Messages<ClothTorn>>().get_cursor();
    let mut seen = Vec::new();
    for _ in 0..30 {
        app.update();
        let messages = app.world().resource::<Messages<ClothTorn>>();
        seen.extend(cursor.read(messages).copied());
    }
    let sim = app.world().get::<ClothSimulation>(e).unwrap();
    assert!(
        !seen.is_empty(),
        "strain {:?} torn {}",
        sim.solver.strain(),
        sim.solver.torn_count()
    );
    assert_eq!(seen.len(), sim.solver.torn_count());
    assert!(
        seen.iter()
            .all(|m| m.cloth == e && !sim.solver.springs().alive[m.spring as usize])
    );
}

#[test]
fn invalid_cloths_are_logged_and_skipped_not_panicked() {
    let mut app = app();
    let bad_mass = app
        .world_mut()
        .spawn(Cloth::grid(4, 4, 0.1).with_params(ClothParams {
            node_mass: -1.0,
            ..default()
        }))
        .id();
    let bad_pin = app
        .world_mut()
        .spawn(Cloth::grid(4, 4, 0.1).with_pins(ClothPins::Indices(vec![99])))
        .id();
    let tiny = app.world_mut().spawn(Cloth::grid(1, 4, 0.1)).id();
    let good = app.world_mut().spawn(Cloth::grid(4, 4, 0.1)).id();
    for _ in 0..3 {
        app.update();
    }
    for e in [bad_mass, bad_pin, tiny] {
        assert!(app.world().get::<ClothInvalid>(e).is_some());
        assert!(app.world().get::<ClothSimulation>(e).is_none());
    }
    assert!(app.world().get::<ClothSimulation>(good).is_some());
    // Fixing the description builds it.
    app.world_mut()
        .get_mut::<Cloth>(bad_mass)
        .unwrap()
        .params
        .node_mass = 1e-3;
    app.update();
    app.update();
    assert!(app.world().get::<ClothInvalid>(bad_mass).is_none());
    assert!(app.world().get::<ClothSimulation>(bad_mass).is_some());
    // A running cloth given a bad value pauses with the error, and resumes when fixed.
    app.world_mut().get_mut::<Cloth>(good).unwrap().params.drag = f32::NAN;
    app.update();
    let t = sim_time(&app, good);
    app.update();
    assert!(app.world().get::<ClothInvalid>(good).is_some());
    assert_eq!(sim_time(&app, good), t);
    app.world_mut().get_mut::<Cloth>(good).unwrap().params.drag = 0.0;
    app.update();
    app.update();
    assert!(app.world().get::<ClothInvalid>(good).is_none());
    assert!(sim_time(&app, good) > t);
}

#[test]
fn a_mesh_becomes_a_cloth() {
    let mut app = app();
    let plane = Plane3d::new(Vec3::Z, Vec2::splat(0.5))
        .mesh()
        .subdivisions(3)
        .build();
    let vertices = plane.count_vertices();
    let handle = app.world_mut().resource_mut::<Assets<Mesh>>().add(plane);
    let e = app
        .world_mut()
        .spawn((Cloth::from_mesh(), Mesh3d(handle.clone())))
        .id();
    for _ in 0..3 {
        app.update();
    }
    let sim = app
        .world()
        .get::<ClothSimulation>(e)
        .expect("built from the mesh");
    assert_eq!(sim.solver.particle_count(), vertices);
    assert_eq!(
        sim.solver.pins().len(),
        5,
        "the top row of a 5×5 vertex plane"
    );
    assert!(sim.solver.spring_count() > vertices);
    assert_ne!(
        app.world().get::<Mesh3d>(e).unwrap().0,
        handle,
        "the source mesh is left alone"
    );
}

#[test]
fn several_cloths_step_together() {
    let mut app = app();
    let light = app
        .world_mut()
        .spawn(Cloth::grid(4, 4, 0.1).with_params(ClothParams {
            substeps: Substeps::Fixed(40),
            ..default()
        }))
        .id();
    let heavy = app
        .world_mut()
        .spawn((
            Cloth::grid(8, 8, 0.05).with_params(ClothParams {
                substeps: Substeps::Fixed(60),
                ..default()
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

/// An app whose keyboard is driven by hand (no InputPlugin to clear it).
fn keyboard_app() -> App {
    let mut app = app();
    app.add_plugins(ClothControlsPlugin)
        .init_resource::<ButtonInput<KeyCode>>();
    app
}

fn tap(app: &mut App, key: KeyCode) {
    app.world_mut()
        .resource_mut::<ButtonInput<KeyCode>>()
        .press(key);
    app.update();
    let mut keys = app.world_mut().resource_mut::<ButtonInput<KeyCode>>();
    keys.release(key);
    keys.clear();
}

#[test]
fn keys_drive_gravity_wind_pause_step_and_reset() {
    let mut app = keyboard_app();
    let e = app
        .world_mut()
        .spawn((Cloth::grid(6, 6, 0.1), ClothStats::default()))
        .id();
    for _ in 0..10 {
        app.update();
    }
    let env = |app: &App| app.world().resource::<ClothEnvironment>().0;
    tap(&mut app, KeyCode::KeyG);
    assert!(!env(&app).gravity_enabled);
    tap(&mut app, KeyCode::KeyG);
    assert!(env(&app).gravity_enabled);

    let wind0 = env(&app).wind;
    tap(&mut app, KeyCode::KeyP);
    tap(&mut app, KeyCode::KeyP);
    assert!((env(&app).wind.strength - wind0.strength - 5e-4).abs() < 1e-7);
    tap(&mut app, KeyCode::KeyO);
    assert!((env(&app).wind.strength - wind0.strength - 2.5e-4).abs() < 1e-7);
    tap(&mut app, KeyCode::Numpad6);
    let d = env(&app).wind.direction;
    let angle = d.angle_between(wind0.direction).to_degrees();
    assert!(
        (angle - 15.0).abs() < 1e-3 && d.y.abs() < 1e-6,
        "turned by {angle}°"
    );
    tap(&mut app, KeyCode::Numpad8);
    assert!(env(&app).wind.direction.y > 0.2);

    // Space pauses; N steps exactly once; Space resumes.
    tap(&mut app, KeyCode::Space);
    let t = sim_time(&app, e);
    app.update();
    assert_eq!(sim_time(&app, e), t);
    // Keys are read in Update, after this frame's fixed step: the step runs next frame.
    tap(&mut app, KeyCode::KeyN);
    app.update();
    assert!((sim_time(&app, e) - t - 0.016).abs() < 1e-5);
    app.update();
    app.update();
    assert!(
        (sim_time(&app, e) - t - 0.016).abs() < 1e-5,
        "only one step"
    );
    tap(&mut app, KeyCode::Space);
    app.update();
    assert!(sim_time(&app, e) > t + 0.02);

    // R resets: the clock restarts and cut springs come back.
    app.world_mut()
        .get_mut::<ClothSimulation>(e)
        .unwrap()
        .solver
        .tear(3);
    tap(&mut app, KeyCode::KeyR);
    let sim = app.world().get::<ClothSimulation>(e).unwrap();
    assert_eq!(sim.solver.torn_count(), 0);
    assert!(sim.solver.time() < 0.05);
    app.update();
    let stats = app.world().get::<ClothStats>(e).unwrap();
    assert_eq!(stats.particles, 36);
    assert!(stats.step_ms_median > 0.0);
    assert!(stats.history.len() < 5, "history restarts after a reset");
}

#[test]
fn stiffness_edits_change_the_next_step() {
    // Two identical cloths; one gets stiffer springs: the next step differs.
    let mut app = app();
    let a = app
        .world_mut()
        .spawn(Cloth::grid(5, 5, 0.1).with_pins(ClothPins::TopRow))
        .id();
    let b = app
        .world_mut()
        .spawn(Cloth::grid(5, 5, 0.1).with_pins(ClothPins::TopRow))
        .id();
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

#[test]
fn collider_entities_keep_cloth_out_and_follow_their_transform() {
    let mut app = app();
    let cloth = app
        .world_mut()
        .spawn((
            Cloth::grid(8, 8, 0.05).with_pins(ClothPins::None),
            Transform::from_xyz(0.0, 1.0, 0.0)
                .with_rotation(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2)),
        ))
        .id();
    let ball = app
        .world_mut()
        .spawn((
            ClothCollider::sphere(0.15).with_thickness(0.01),
            Transform::from_xyz(0.0, 0.6, 0.175),
        ))
        .id();
    app.world_mut().spawn(ClothCollider::plane());
    // The cloth falls onto the ball and drapes over it: never inside it (by more than its
    // thickness), never below the ground, and touching it.
    let centre = Vec3::new(0.0, 0.6, 0.175);
    let mut touched = false;
    for _ in 0..150 {
        app.update();
        let Some(sim) = app.world().get::<ClothSimulation>(cloth) else {
            continue;
        };
        let x = sim.solver.positions();
        let closest = x
            .iter()
            .map(|p| p.distance(centre))
            .fold(f32::MAX, f32::min);
        assert!(
            closest > 0.15 - 1e-4,
            "a particle is {closest} m from the centre"
        );
        touched |= closest < 0.15 + 0.01 + 1e-3;
        assert!(
            x.iter().all(|p| p.y >= -1e-4),
            "a particle went through the ground"
        );
    }
    assert!(touched, "the cloth never reached the ball");
    let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
    let colliders = sim.solver.colliders();
    assert_eq!(colliders.len(), 2);
    assert!(colliders.iter().any(|c| matches!(
        c.shape,
        bevy_cloth::solver::ColliderShape::Sphere(bevy_cloth::solver::shapes::Sphere { center, radius })
            if center.distance(centre) < 1e-6 && radius == 0.15
    )));
    // Moving the entity moves the collider.
    app.world_mut()
        .get_mut::<Transform>(ball)
        .unwrap()
        .translation = Vec3::new(1.0, 0.5, 0.0);
    app.update();
    app.update();
    let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
    assert!(sim.solver.colliders().iter().any(|c| matches!(
        c.shape,
        bevy_cloth::solver::ColliderShape::Sphere(bevy_cloth::solver::shapes::Sphere { center, .. })
            if center.distance(Vec3::new(1.0, 0.5, 0.0)) < 1e-6
    )));
}

#[test]
fn a_scene_spawns_its_cloths_colliders_and_world() {
    let mut scene = ClothScene::load("assets/scenes/tshirt.ron").unwrap();
    // Made for another timestep than the app's 16 ms.
    scene.timestep = 0.01;
    let mut app = app();
    let spawned = scene.spawn(&mut app.world_mut().commands());
    app.world_mut().flush();
    assert_eq!(spawned.cloths.len(), scene.cloths.len());
    assert_eq!(spawned.colliders.len(), scene.colliders.len());
    // The garment loads through the asset server, in the background.
    let start = std::time::Instant::now();
    while start.elapsed().as_secs() < 10
        && !spawned
            .cloths
            .iter()
            .all(|&e| app.world().get::<ClothSimulation>(e).is_some())
    {
        app.update();
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    for (entry, &entity) in scene.cloths.iter().zip(&spawned.cloths) {
        let sim = app.world().get::<ClothSimulation>(entity).expect("built");
        assert!(sim.solver.particle_count() > 0);
        assert_eq!(
            app.world().get::<Name>(entity).map(|n| n.as_str()),
            Some(entry.name.as_str())
        );
    }
    for (entry, &entity) in scene.colliders.iter().zip(&spawned.colliders) {
        assert_eq!(
            app.world().get::<ClothCollider>(entity),
            Some(&entry.collider)
        );
    }
    assert_eq!(
        app.world().resource::<ClothEnvironment>().0,
        scene.environment
    );
    // Spawning a scene leaves the game's clock alone (a scene made for another timestep
    // once overwrote it).
    let fixed = app.world().resource::<Time<Fixed>>().timestep();
    assert_eq!(fixed, std::time::Duration::from_millis(16));
}

#[test]
fn a_hidden_cloth_steps_but_writes_its_mesh_only_when_shown() {
    let mut app = app();
    // Drawn where the last step ended (with interpolation, at 16 ms updates and no time
    // over, a mesh shows where the step began: the_mesh_is_drawn_between_the_last_two_steps).
    app.insert_resource(ClothInterpolation(false));
    let (e, handle) = spawn_small_cloth(&mut app);
    let read = |app: &App| mesh_positions(app, &handle);
    app.world_mut().entity_mut(e).insert(Visibility::Hidden);
    app.update();
    let hidden = read(&app);
    let solver_at = |app: &App| {
        app.world()
            .get::<ClothSimulation>(e)
            .unwrap()
            .solver
            .positions()[19]
    };
    let before = solver_at(&app);
    for _ in 0..10 {
        app.update();
    }
    assert_ne!(solver_at(&app), before, "a hidden cloth still steps");
    assert_eq!(read(&app), hidden, "a hidden cloth's mesh is not rewritten");
    app.world_mut().entity_mut(e).insert(Visibility::Inherited);
    app.update();
    let shown = Vec3::from(read(&app)[19]);
    let world = solver_at(&app);
    assert!(
        (shown + Vec3::new(0.0, 2.0, 0.0) - world).length() < 1e-4,
        "written when shown"
    );
}

#[test]
fn an_attached_cloth_follows_its_moving_entity_with_no_lag_beyond_a_step() {
    // A cape-like cloth hanging from a "shoulder" entity that walks along x and turns:
    // its two top corners, attached, are where the entity puts them at the end of every
    // step (the solver reaches the target over the step's substeps, as pins do).
    let mut app = app();
    let shoulder = app
        .world_mut()
        .spawn(Transform::from_xyz(0.0, 2.0, 0.0))
        .id();
    let cloth = app
        .world_mut()
        .spawn((
            Cloth::grid(8, 6, 0.05).with_pins(ClothPins::None),
            Transform::from_xyz(0.0, 2.0, 0.0),
            ClothAttachments(vec![
                ClothAttachment::indices(shoulder, vec![0]),
                ClothAttachment::nearest(shoulder, Vec3::new(0.175, 0.0, 0.0), 1),
            ]),
        ))
        .id();
    // Built in the first frame (by command), attached from the second.
    app.update();
    app.update();
    let held: Vec<(u32, Vec3)> = app
        .world()
        .get::<ClothAttachments>(cloth)
        .unwrap()
        .0
        .iter()
        .flat_map(|a| a.held().to_vec())
        .collect();
    assert_eq!(held.iter().map(|h| h.0).collect::<Vec<_>>(), [0, 7]);
    for frame in 1..=60 {
        {
            let mut t = app.world_mut().get_mut::<Transform>(shoulder).unwrap();
            t.translation.x += 0.02;
            t.rotate_y(0.01);
        }
        app.update();
        let t = *app.world().get::<Transform>(shoulder).unwrap();
        let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
        for &(i, local) in &held {
            let want = t.transform_point(local);
            let got = sim.solver.positions()[i as usize];
            assert!(
                got.distance(want) < 1e-5,
                "frame {frame}: particle {i} at {got}, the shoulder puts it at {want}"
            );
        }
        // The rest of the cloth hangs below and follows (a sheet 0.25 m long).
        let lowest = sim
            .solver
            .positions()
            .iter()
            .map(|p| p.y)
            .fold(f32::MAX, f32::min);
        assert!(
            lowest < 2.0 && lowest > 1.6,
            "frame {frame}: lowest {lowest}"
        );
        assert!(sim.solver.is_stable());
    }
    // The entity gone: the cloth is let go and falls.
    app.world_mut().despawn(shoulder);
    for _ in 0..30 {
        app.update();
    }
    let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
    assert!(sim.solver.attached().is_empty());
    assert!(sim.solver.positions()[0].y < 1.0);
}

#[test]
fn a_cloth_lying_on_a_moving_collider_entity_is_carried_along() {
    // A box entity moved by its Transform 8 mm each 16 ms frame (0.5 m/s along x), a
    // cloth lying on it (μ = 0.8): the plugin gives the box its motion from the change of
    // its transform, and friction carries the cloth with it (less the ~1.6 cm it slips
    // while getting up to speed, v²/2μg).
    let mut app = app();
    let platform = app
        .world_mut()
        .spawn((
            ClothCollider::cuboid(2.0, 0.2, 2.0).with_friction(0.8),
            Transform::default(),
        ))
        .id();
    let cloth = app
        .world_mut()
        .spawn(common::lying_cloth(Vec3::new(0.0, 0.106, 0.0)))
        .id();
    app.update();
    app.update();
    let start = common::entity_centroid(&app, cloth);
    for _ in 0..60 {
        app.world_mut()
            .get_mut::<Transform>(platform)
            .unwrap()
            .translation
            .x += 0.008;
        app.update();
    }
    let moved = common::entity_centroid(&app, cloth) - start;
    let platform_x = app
        .world()
        .get::<Transform>(platform)
        .unwrap()
        .translation
        .x;
    eprintln!("the cloth moved {moved}, the box {platform_x}");
    assert!(
        moved.x > platform_x - 0.03 && moved.x < platform_x,
        "the cloth moved {moved}, the box {platform_x}"
    );
    assert!(moved.y.abs() < 3e-3, "stays on top: {moved}");
}

#[test]
fn a_garment_hangs_from_its_named_runs_on_a_moving_hanger() {
    // The T-shirt held by its file's two shoulder runs to a "hanger" entity that moves
    // and turns: every run particle is where the hanger puts it each frame, and the shirt
    // hangs below; a run that does not exist attaches nothing (and the cloth runs on).
    let mut app = app();
    let hanger = app
        .world_mut()
        .spawn(Transform::from_xyz(0.0, 1.5, 0.0))
        .id();
    let shirt = app
        .world_mut()
        .spawn((
            Cloth::garment("patterns/tshirt.ron"),
            Transform::from_xyz(0.0, 1.5, 0.0),
            ClothAttachments(vec![
                ClothAttachment::run(hanger, "right shoulder"),
                ClothAttachment::run(hanger, "left shoulder"),
                ClothAttachment::run(hanger, "collar"),
            ]),
        ))
        .id();
    // The garment loads through the asset server: a few frames until it is built and held.
    let mut held = Vec::new();
    for _ in 0..200 {
        app.update();
        held = app
            .world()
            .get::<ClothAttachments>(shirt)
            .map_or(Vec::new(), |a| {
                a.0.iter().flat_map(|a| a.held().to_vec()).collect()
            });
        if !held.is_empty() {
            break;
        }
    }
    assert_eq!(held.len(), 12, "two runs of 6 nodes, none for `collar`");
    for frame in 1..=90 {
        {
            let mut t = app.world_mut().get_mut::<Transform>(hanger).unwrap();
            t.translation.x += 0.01;
            t.rotate_y(0.01);
        }
        app.update();
        let t = *app.world().get::<Transform>(hanger).unwrap();
        let sim = app.world().get::<ClothSimulation>(shirt).unwrap();
        for &(i, local) in &held {
            let got = sim.solver.positions()[i as usize];
            let want = t.transform_point(local);
            assert!(
                got.distance(want) < 1e-5,
                "frame {frame}: particle {i} at {got}, the hanger puts it at {want}"
            );
        }
        assert!(sim.solver.is_stable());
    }
    // After the sewing (1 s, no gravity) the shirt drops and hangs from the shoulders.
    let sim = app.world().get::<ClothSimulation>(shirt).unwrap();
    let lowest = sim
        .solver
        .positions()
        .iter()
        .map(|x| x.y)
        .fold(f32::MAX, f32::min);
    assert!(
        lowest < 1.5 - 0.6,
        "hangs below the hanger: lowest {lowest}"
    );
}

#[test]
fn particles_attached_at_local_offsets_go_there_and_follow() {
    // Two corners of a cloth held at points given in a bar entity's frame (not where they
    // start): they are pulled there in the first step and then follow the bar.
    let mut app = app();
    let bar = app
        .world_mut()
        .spawn(Transform::from_xyz(0.5, 2.0, 0.0))
        .id();
    let offsets = vec![
        (0, Vec3::new(-0.3, 0.0, 0.1)),
        (7, Vec3::new(0.3, 0.0, 0.1)),
    ];
    let cloth = app
        .world_mut()
        .spawn((
            Cloth::grid(8, 6, 0.05).with_pins(ClothPins::None),
            Transform::from_xyz(0.0, 1.8, 0.0),
            ClothAttachments(vec![ClothAttachment::at(bar, offsets.clone())]),
        ))
        .id();
    app.update();
    for frame in 0..40 {
        {
            let mut t = app.world_mut().get_mut::<Transform>(bar).unwrap();
            t.translation.z -= 0.01;
            t.rotate_y(0.02);
        }
        app.update();
        if frame == 0 {
            continue; // the first step after the cloth is built attaches them
        }
        let t = *app.world().get::<Transform>(bar).unwrap();
        let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
        for &(i, local) in &offsets {
            let (got, want) = (sim.solver.positions()[i as usize], t.transform_point(local));
            assert!(
                got.distance(want) < 1e-5,
                "frame {frame}: particle {i} at {got}, wanted {want}"
            );
        }
    }
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

/// Collider constructors take the sizes Bevy's primitives take, and the primitives
/// convert into the same colliders.
#[test]
fn colliders_take_the_sizes_of_bevys_primitives() {
    let cuboid = ClothCollider::cuboid(2.0, 0.2, 1.0);
    assert_eq!(
        cuboid.shape,
        ColliderKind::Cuboid {
            half_extents: Vec3::new(1.0, 0.1, 0.5)
        }
    );
    assert_eq!(ClothCollider::from(Cuboid::new(2.0, 0.2, 1.0)), cuboid);
    let capsule = ClothCollider::capsule(0.1, 0.6);
    assert_eq!(
        capsule.shape,
        ColliderKind::Capsule {
            radius: 0.1,
            half_length: 0.3
        }
    );
    assert_eq!(ClothCollider::from(Capsule3d::new(0.1, 0.6)), capsule);
    let cylinder = ClothCollider::cylinder(0.2, 1.0);
    assert_eq!(
        cylinder.shape,
        ColliderKind::Cylinder {
            radius: 0.2,
            half_height: 0.5
        }
    );
    assert_eq!(ClothCollider::from(Cylinder::new(0.2, 1.0)), cylinder);
    assert_eq!(
        ClothCollider::from(Sphere::new(0.3)),
        ClothCollider::sphere(0.3)
    );
}

#[test]
fn planes_and_half_spaces_convert_with_their_normals_and_offsets() {
    let identity = GlobalTransform::IDENTITY;
    let plane = |c: ClothCollider| match c.to_world(&identity).shape {
        bevy_cloth::solver::ColliderShape::Plane(bevy_cloth::solver::shapes::Plane {
            point,
            normal,
        }) => (point, normal),
        other => panic!("not a plane: {other:?}"),
    };
    // Bevy's infinite plane: the solid behind it, like avian's `Collider::half_space`.
    let tilted = Vec3::new(1.0, 1.0, 0.0).normalize();
    let (point, normal) = plane(InfinitePlane3d::new(tilted).into());
    assert!(point.length() < 1e-6 && (normal - tilted).length() < 1e-6);
    assert_eq!(
        plane(InfinitePlane3d::new(Vec3::Y).into()),
        plane(ClothCollider::plane())
    );
    // Bevy's half-space is the solid, its normal pointing in: y > 0.5 here, a ceiling.
    let ceiling = bevy::math::primitives::HalfSpace::new(Vec4::new(0.0, 1.0, 0.0, -0.5));
    let (point, normal) = plane(ceiling.into());
    assert!(
        (point - Vec3::new(0.0, 0.5, 0.0)).length() < 1e-6,
        "{point}"
    );
    assert!((normal - Vec3::NEG_Y).length() < 1e-6, "{normal}");
    // A zero normal is refused; thickness and friction take their defaults in a file.
    assert!(
        ClothCollider::half_space(Vec3::ZERO, 0.0)
            .validate()
            .is_err()
    );
    let from_file: ClothCollider = ron::from_str("(shape: Sphere(radius: 0.2))").unwrap();
    assert_eq!(from_file, ClothCollider::sphere(0.2));
    assert!(
        ron::from_str::<ClothCollider>("(thickness: 0.01)").is_err(),
        "no shape"
    );
}

/// A solver shape of its own file (the torus) is a component like the built-in kinds:
/// placed by its entity's transform, checked by its own sizes.
#[test]
fn a_torus_collider_is_placed_by_its_transform_and_checked() {
    use bevy_cloth::solver::shapes::Torus;
    let ring = Torus {
        center: Vec3::ZERO,
        axis: Vec3::Y,
        major_radius: 0.3,
        minor_radius: 0.02,
    };
    let transform = Transform::from_xyz(0.0, 1.0, 2.0)
        .with_rotation(Quat::from_rotation_x(std::f32::consts::FRAC_PI_2))
        .with_scale(Vec3::splat(2.0));
    let world = ClothCollider::from_shape(ring).to_world(&GlobalTransform::from(transform));
    let bevy_cloth::solver::ColliderShape::Torus(placed) = world.shape else {
        panic!("{:?}", world.shape)
    };
    assert!((placed.center - Vec3::new(0.0, 1.0, 2.0)).length() < 1e-6);
    assert!((placed.axis - Vec3::Z).length() < 1e-6, "{}", placed.axis);
    assert!((placed.major_radius - 0.6).abs() < 1e-6 && (placed.minor_radius - 0.04).abs() < 1e-6);
    let thin = Torus {
        minor_radius: -0.01,
        ..ring
    };
    let refused = ClothCollider::from_shape(thin).validate().unwrap_err();
    assert!(refused.to_string().contains("minor_radius"), "{refused}");
}

/// `value` is registered (with `ReflectComponent` when `component`) and comes back equal
/// from its reflected copy.
fn round_trips<T>(app: &App, value: T, component: bool)
where
    T: Reflect + FromReflect + TypePath + PartialEq + std::fmt::Debug,
{
    let registry = app.world().resource::<AppTypeRegistry>().read();
    let name = T::type_path();
    let registration = registry
        .get(std::any::TypeId::of::<T>())
        .unwrap_or_else(|| panic!("{name} is not registered"));
    if component {
        assert!(
            registration.data::<ReflectComponent>().is_some(),
            "{name} has no ReflectComponent"
        );
    }
    let copy = T::from_reflect(value.to_dynamic().as_partial_reflect())
        .unwrap_or_else(|| panic!("{name} does not come back from reflection"));
    assert_eq!(copy, value, "{name}");
}

#[test]
fn every_public_component_resource_message_and_event_is_reflected_and_registered() {
    let mut app = app();
    app.add_plugins(ClothControlsPlugin);
    let e = Entity::from_raw_u32(7).unwrap();
    round_trips(&app, Cloth::grid(4, 3, 0.1), true);
    round_trips(
        &app,
        ClothCollider::capsule(0.1, 0.5).with_friction(0.7),
        true,
    );
    round_trips(&app, ClothSleep::never(), true);
    round_trips(&app, ClothLod::default(), true);
    round_trips(
        &app,
        ClothAttachments(vec![
            ClothAttachment::nearest(e, Vec3::Y, 3),
            ClothAttachment::run(e, "collar"),
        ]),
        true,
    );
    round_trips(
        &app,
        ClothInvalid(bevy_cloth::ClothError::EmptyGarment),
        true,
    );
    round_trips(&app, ClothEnvironment::default(), false);
    round_trips(&app, ClothPause::default(), false);
    round_trips(&app, ClothInterpolation(false), false);
    round_trips(
        &app,
        ClothMaxDistance::VertexColor {
            channel: 0,
            scale: 0.2,
        },
        true,
    );
    round_trips(&app, bevy_cloth::ClothControls::default(), false);
    round_trips(&app, bevy_cloth::StatSample::default(), false);
    round_trips(&app, ClothWake(e), false);
    round_trips(
        &app,
        ClothTorn {
            cloth: e,
            spring: 3,
            particles: [1, 2],
        },
        false,
    );
    round_trips(&app, ClothAwoke { entity: e }, false);
    round_trips(&app, ClothFellAsleep { entity: e }, false);
    round_trips(&app, ClothBuilt { entity: e }, false);
    round_trips(
        &app,
        ClothBecameInvalid {
            entity: e,
            error: bevy_cloth::ClothError::EmptyGarment,
        },
        false,
    );
    // Reflected without their solver state (not reflectable), for inspectors.
    let registry = app.world().resource::<AppTypeRegistry>().read();
    for (name, id) in [
        ("ClothSimulation", std::any::TypeId::of::<ClothSimulation>()),
        ("ClothStats", std::any::TypeId::of::<ClothStats>()),
    ] {
        let registration = registry.get(id).unwrap_or_else(|| panic!("{name}"));
        assert!(registration.data::<ReflectComponent>().is_some(), "{name}");
    }
}

/// What the observers on one cloth saw.
#[derive(Resource, Default, Debug)]
struct Seen {
    built: usize,
    torn: Vec<u32>,
    asleep: usize,
    awoke: usize,
    invalid: Vec<bevy_cloth::ClothError>,
}

#[test]
fn observers_on_a_cloth_see_it_built_torn_asleep_woken_and_invalid() {
    let mut app = app();
    app.init_resource::<Seen>();
    let e = app
        .world_mut()
        .spawn(tearing_cloth())
        .observe(|_: On<ClothBuilt>, mut seen: ResMut<Seen>| seen.built += 1)
        .observe(|torn: On<ClothTorn>, mut seen: ResMut<Seen>| seen.torn.push(torn.spring))
        .observe(|_: On<ClothFellAsleep>, mut seen: ResMut<Seen>| seen.asleep += 1)
        .observe(|_: On<ClothAwoke>, mut seen: ResMut<Seen>| seen.awoke += 1)
        .observe(|bad: On<ClothBecameInvalid>, mut seen: ResMut<Seen>| {
            seen.invalid.push(bad.error.clone())
        })
        .id();
    app.world_mut().resource_mut::<ClothEnvironment>().gravity = TEARING_GRAVITY;
    for _ in 0..30 {
        app.update();
    }
    let torn = app
        .world()
        .get::<ClothSimulation>(e)
        .unwrap()
        .solver
        .torn_count();
    let seen = app.world().resource::<Seen>();
    assert_eq!(seen.built, 1, "{seen:?}");
    assert!(
        !seen.torn.is_empty() && seen.torn.len() == torn,
        "{seen:?}, {torn} torn"
    );
    // Asleep: no gravity, the pieces come to rest within a few seconds and sleep.
    app.world_mut()
        .resource_mut::<ClothEnvironment>()
        .gravity_enabled = false;
    app.world_mut()
        .get_mut::<ClothSimulation>(e)
        .unwrap()
        .reset();
    for _ in 0..400 {
        app.update();
        if app.world().resource::<Seen>().asleep > 0 {
            break;
        }
    }
    assert_eq!(app.world().resource::<Seen>().asleep, 1);
    // Woken by the game's message.
    app.world_mut().write_message(ClothWake(e));
    app.update();
    assert_eq!(app.world().resource::<Seen>().awoke, 1);
    // Invalid: a negative mass.
    app.world_mut()
        .get_mut::<Cloth>(e)
        .unwrap()
        .params
        .node_mass = -1.0;
    app.update();
    let seen = app.world().resource::<Seen>();
    assert_eq!(seen.invalid.len(), 1, "{seen:?}");
    assert!(app.world().get::<ClothInvalid>(e).is_some());
}

/// The mesh is drawn between the last two fixed steps: after an update that leaves half
/// a timestep over (8 of 16 ms), each vertex is midway between where the last step
/// began and where it ended; with interpolation off it is where the step ended.
#[test]
fn the_mesh_is_drawn_between_the_last_two_steps() {
    use bevy::time::TimeUpdateStrategy;
    use std::time::Duration;
    for on in [true, false] {
        let mut app = app();
        app.insert_resource(ClothInterpolation(on));
        let (e, handle) = spawn_small_cloth(&mut app);
        for _ in 0..5 {
            app.update();
        }
        let positions = |app: &App| {
            let sim = app.world().get::<ClothSimulation>(e).unwrap();
            sim.solver.positions().to_vec()
        };
        let before = positions(&app);
        app.update(); // one 16 ms step, nothing over
        let after = positions(&app);
        app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_millis(8)));
        app.update(); // no step: half a timestep over
        assert_eq!(positions(&app), after, "an 8 ms update stepped");
        let drawn = mesh_positions(&app, &handle);
        let mut moved = 0.0f32;
        for i in 0..after.len() {
            // The cloth's frame is a translation by 2 m up.
            let want = if on {
                before[i].lerp(after[i], 0.5)
            } else {
                after[i]
            };
            let got = Vec3::from(drawn[i]) + Vec3::new(0.0, 2.0, 0.0);
            assert!(
                got.distance(want) < 1e-5,
                "interpolation {on}: vertex {i} drawn at {got}, not {want}"
            );
            moved = moved.max(before[i].distance(after[i]));
        }
        assert!(moved > 1e-3, "the cloth moved in that step: {moved} m");
    }
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
                let (mut cloth, place) = common::lying_cloth(Vec3::new(0.0, y, 0.0));
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

/// A collider with a negative radius is not clamped to 0 in silence: it gets
/// `ClothInvalid` naming the radius (and is logged) and is left out of the cloths' steps;
/// fixed, it is a collider again.
#[test]
fn a_collider_of_negative_size_is_refused_until_fixed() {
    let mut app = app();
    let collider = app
        .world_mut()
        .spawn((ClothCollider::sphere(-1.0), Transform::default()))
        .id();
    for _ in 0..3 {
        app.update();
    }
    let invalid = app.world().get::<ClothInvalid>(collider).expect("refused");
    assert!(
        matches!(
            invalid.0,
            ClothError::InvalidParameter {
                field: "radius",
                ..
            }
        ),
        "{:?}",
        invalid.0
    );
    *app.world_mut().get_mut::<ClothCollider>(collider).unwrap() = ClothCollider::sphere(0.2);
    for _ in 0..3 {
        app.update();
    }
    assert!(app.world().get::<ClothInvalid>(collider).is_none());
}
