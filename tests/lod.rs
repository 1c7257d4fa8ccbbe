//! Level of detail: a grid cloth's model follows its size on the camera's
//! view, with a band against flicker, and switches without a jump.

use bevy::camera::{Camera, PerspectiveProjection, Projection};
use bevy::prelude::*;
use bevy_cloth::ClothLodPlugin;
use bevy_cloth::params::{Environment, Model, PatchParams};
use bevy_cloth::prelude::*;

fn level(app: &App, e: Entity) -> usize {
    app.world().get::<ClothLod>(e).unwrap().level
}

fn positions(app: &App, e: Entity) -> Vec<Vec3> {
    let sim = app.world().get::<ClothSimulation>(e).unwrap();
    sim.solver.positions().to_vec()
}

fn largest_move(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f32::max)
}

/// A 24×24 curtain (1.15 m, so a bounding sphere of radius ~0.8 m) in wind with level of
/// detail, and a camera `distance` m in front of it; run for a second.
fn scene(distance: f32) -> (App, Entity, Entity) {
    let mut app = bevy_cloth::headless::headless_app();
    app.world_mut()
        .resource_mut::<ClothEnvironment>()
        .wind
        .strength = 2e-4;
    let cloth = app
        .world_mut()
        .spawn((
            Cloth::grid(24, 24, 0.05)
                .with_pins(ClothPins::TopRow)
                // The patch model takes no fabric: the seeds' springs.
                .with_params(ClothParams::seeds()),
            ClothLod::default(),
            ClothSleep::never(),
            Transform::from_xyz(0.0, 2.0, 0.0),
        ))
        .id();
    let camera = app
        .world_mut()
        .spawn((
            Camera::default(),
            Projection::Perspective(PerspectiveProjection::default()),
            Transform::from_xyz(0.0, 1.4, distance).looking_at(Vec3::new(0.0, 1.4, 0.0), Vec3::Y),
        ))
        .id();
    for _ in 0..60 {
        app.update();
    }
    (app, cloth, camera)
}

fn move_camera(app: &mut App, camera: Entity, distance: f32) {
    app.world_mut()
        .get_mut::<Transform>(camera)
        .unwrap()
        .translation
        .z = distance;
}

#[test]
fn the_level_follows_the_distance_and_the_model_with_it() {
    // Radius ≈ 0.8 m, fov 45°: the fraction is 0.8 / (d · 0.414).
    let (mut app, cloth, camera) = scene(1.5);
    assert_eq!(level(&app, cloth), 0, "near: the cloth's own model");
    assert_eq!(
        app.world().get::<Cloth>(cloth).unwrap().params.model,
        Model::MassSpring
    );
    let mut seen = vec![0];
    for distance in [5.0, 10.0, 30.0] {
        move_camera(&mut app, camera, distance);
        for _ in 0..5 {
            app.update();
        }
        seen.push(level(&app, cloth));
    }
    assert_eq!(seen, [0, 1, 2, 3], "levels at 1.5, 5, 10 and 30 m");
    match app.world().get::<Cloth>(cloth).unwrap().params.model {
        Model::Patches(p) => assert_eq!((p.part_width, p.part_height), (8, 8)),
        other => panic!("far: {other:?}"),
    }
    let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
    assert!(
        sim.solver.patches().is_some(),
        "the solver runs the patch model"
    );
    // Back near: the cloth's own model again.
    move_camera(&mut app, camera, 1.5);
    for _ in 0..5 {
        app.update();
    }
    assert_eq!(level(&app, cloth), 0);
    assert_eq!(
        app.world().get::<Cloth>(cloth).unwrap().params.model,
        Model::MassSpring
    );
}

#[test]
fn a_camera_inside_the_band_does_not_make_the_level_flicker() {
    // The first threshold, 0.5, is crossed at d ≈ 3.9 m; the band keeps a cloth at level 1
    // between 0.45 and 0.55 of the view.
    let (mut app, cloth, camera) = scene(5.0);
    assert_eq!(level(&app, cloth), 1);
    let radius = app
        .world()
        .get::<ClothSimulation>(cloth)
        .unwrap()
        .solver
        .bounding_sphere()
        .1;
    let tan = (PerspectiveProjection::default().fov * 0.5).tan();
    // Just finer than the threshold, inside the band: stays coarse.
    move_camera(&mut app, camera, radius / (0.52 * tan));
    for _ in 0..30 {
        app.update();
        assert_eq!(level(&app, cloth), 1, "flickered inside the band");
    }
}

/// The scene of [`scene`] with its camera taken through `distances`, each held for 41
/// frames (past the switch's fade, `EASE_TIME`).
fn after(distances: &[f32]) -> (App, Entity, Entity) {
    let (mut app, cloth, camera) = scene(3.0);
    for &distance in distances {
        move_camera(&mut app, camera, distance);
        for _ in 0..41 {
            app.update();
        }
    }
    (app, cloth, camera)
}

/// For each switch along `distances`: the level it goes to, the largest move of the
/// switch step, and that of the same step of a twin with the same history whose camera
/// stays (what one normal step moves the cloth).
fn switch_moves(distances: &[f32]) -> Vec<(usize, f32, f32)> {
    (0..distances.len())
        .map(|k| {
            let (mut app, cloth, camera) = after(&distances[..k]);
            let (mut twin, twin_cloth, _) = after(&distances[..k]);
            let (a, b) = (positions(&app, cloth), positions(&twin, twin_cloth));
            let before = level(&app, cloth);
            move_camera(&mut app, camera, distances[k]);
            app.update();
            twin.update();
            let now = level(&app, cloth);
            assert_ne!(now, before, "no switch at {} m", distances[k]);
            assert_eq!(level(&twin, twin_cloth), before);
            let switch = largest_move(&a, &positions(&app, cloth));
            let normal = largest_move(&b, &positions(&twin, twin_cloth));
            (now, switch, normal)
        })
        .collect()
}

#[test]
fn switching_level_makes_no_jump() {
    // Both ways through every level, in wind (the cloth moving 2–6 mm a step). A switch
    // matches the old model's acceleration and fades the difference out over 0.5 s
    // (`solver/switch.rs`); before that the switch step moved this curtain 2.0× a normal
    // step (11.0 mm against 5.5) and a settled one 10–100×.
    let moves = switch_moves(&[5.0, 10.0, 30.0, 10.0, 5.0, 1.5]);
    for &(level, switch, normal) in &moves {
        println!(
            "to level {level}: {:.2} mm in the switch step, {:.2} mm in the twin's ({:.2}×)",
            switch * 1e3,
            normal * 1e3,
            switch / normal
        );
    }
    let levels: Vec<usize> = moves.iter().map(|m| m.0).collect();
    assert_eq!(levels, [1, 2, 3, 2, 1, 0]);
    for (level, switch, normal) in moves {
        assert!(
            switch <= normal * 1.05,
            "a jump switching to level {level}: {switch} m against {normal} m"
        );
    }
}

#[test]
fn a_settled_cloth_switches_without_a_jump() {
    // Solver level, 10 s of light wind: the cloth moves ~0.1 mm a step, and the models'
    // equilibria differ by up to 8 mm (8×8 parts against the particles), so an instant
    // switch moved it 1.6–11 mm in the switch step.
    let model = |p: u32| match p {
        0 => Model::MassSpring,
        p => Model::Patches(PatchParams {
            part_width: p,
            part_height: p,
            ..PatchParams::default()
        }),
    };
    let shape = ClothShape::Grid {
        width: 24,
        height: 24,
        spacing: 0.05,
    };
    let mut env = Environment::default();
    env.wind.strength = 2e-4;
    let frame = bevy::math::Affine3A::from_translation(Vec3::new(0.0, 2.0, 0.0));
    for (from, to) in [(0, 2), (2, 4), (4, 8), (8, 4), (4, 2), (2, 0)] {
        let params = ClothParams {
            model: model(from),
            ..ClothParams::seeds()
        };
        let build = || {
            shape
                .build_solver(&ClothPins::TopRow, &params, frame)
                .unwrap()
        };
        let (mut cloth, mut twin) = (build(), build());
        for _ in 0..600 {
            cloth.step(0.016, &env);
            twin.step(0.016, &env);
        }
        let (a, b) = (cloth.positions().to_vec(), twin.positions().to_vec());
        cloth
            .set_params(&ClothParams {
                model: model(to),
                ..params
            })
            .unwrap();
        cloth.step(0.016, &env);
        twin.step(0.016, &env);
        let switch = largest_move(&a, cloth.positions());
        let normal = largest_move(&b, twin.positions());
        println!(
            "{from}→{to}: {:.3} mm in the switch step, {:.3} mm in the twin's",
            switch * 1e3,
            normal * 1e3
        );
        assert!(
            switch <= normal * 1.05,
            "{from}→{to}: {switch} m against {normal} m"
        );
    }
}

/// Level of detail is a plugin of the group a game can leave out: with `ClothLodPlugin`
/// disabled, a cloth with `ClothLod` 30 m from the camera (the patch model's 8×8 parts
/// with it on) keeps its own model and level 0, and steps.
#[test]
fn an_app_without_level_of_detail_keeps_the_cloths_model() {
    use bevy::time::TimeUpdateStrategy;
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        AssetPlugin::default(),
        ClothPlugin::default().build().disable::<ClothLodPlugin>(),
    ))
    .init_asset::<Mesh>()
    .init_asset::<bevy::mesh::skinning::SkinnedMeshInverseBindposes>()
    .insert_resource(TimeUpdateStrategy::ManualDuration(
        std::time::Duration::from_millis(16),
    ));
    let cloth = app
        .world_mut()
        .spawn((
            Cloth::grid(24, 24, 0.05)
                .with_pins(ClothPins::TopRow)
                // The patch model takes no fabric: the seeds' springs.
                .with_params(ClothParams::seeds()),
            ClothLod::default(),
            Transform::from_xyz(0.0, 2.0, 0.0),
        ))
        .id();
    app.world_mut().spawn((
        Camera::default(),
        Projection::Perspective(PerspectiveProjection::default()),
        Transform::from_xyz(0.0, 1.4, 30.0).looking_at(Vec3::new(0.0, 1.4, 0.0), Vec3::Y),
    ));
    for _ in 0..60 {
        app.update();
    }
    assert_eq!(level(&app, cloth), 0);
    let sim = app.world().get::<ClothSimulation>(cloth).expect("built");
    assert_eq!(sim.solver.params().model, Model::MassSpring);
    assert!(
        sim.solver.time() > 0.5,
        "it stepped: {} s",
        sim.solver.time()
    );
}

/// A cloth the patch model refuses — self-collision on, or a fabric in physical units —
/// keeps its own model however far the camera is, and is never refused for it.
#[test]
fn a_cloth_the_patch_model_refuses_keeps_its_model_far_away() {
    let self_colliding = ClothParams {
        self_collision: SelfCollision::on(),
        ..ClothParams::seeds()
    };
    let denim = ClothParams {
        fabric: Some(Fabric::DENIM),
        ..ClothParams::seeds()
    };
    for params in [self_colliding, denim] {
        let (mut app, cloth, camera) = scene(1.5);
        app.world_mut().get_mut::<Cloth>(cloth).unwrap().params = params;
        move_camera(&mut app, camera, 30.0);
        for _ in 0..30 {
            app.update();
        }
        assert_eq!(level(&app, cloth), 0);
        assert!(app.world().get::<ClothInvalid>(cloth).is_none(), "refused");
        let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
        assert_eq!(sim.solver.params().model, Model::MassSpring);
        assert!(sim.solver.patches().is_none());
    }
}
