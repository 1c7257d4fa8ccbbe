//! Culling: cloths out of every camera's view, or too far, take no steps, and are put
//! back on their bodies at rest when seen again.

use crate::common::*;
use bevy::camera::primitives::Frustum;
use bevy::camera::{Camera, CameraProjection, PerspectiveProjection, Projection};
use bevy::prelude::*;
use bevy_cloth::prelude::*;

/// A camera at `eye` looking at `target`, with the view frustum a render would compute
/// (a headless app has no render to compute it).
fn camera(eye: Vec3, target: Vec3) -> impl Bundle {
    let transform = Transform::from_translation(eye).looking_at(target, Vec3::Y);
    let projection = PerspectiveProjection::default();
    let clip_from_world = projection.get_clip_from_view() * transform.to_matrix().inverse();
    (
        Camera::default(),
        Projection::Perspective(projection),
        transform,
        Frustum(bevy::math::primitives::ViewFrustum::from_clip_from_world(
            &clip_from_world,
        )),
    )
}

/// Ten cloths in front of a camera and ten behind it: those behind take no substeps and
/// are counted culled; one carried 1 m while unseen, seen again when the camera turns
/// round, starts at rest on its body, its shape carried with it (the golden dump
/// `culled_and_seen`). One beyond `max_distance` in view is culled too.
#[test]
fn cloths_no_camera_sees_take_no_steps() {
    let mut app = app();
    let spawn = |app: &mut App, z: f32, culling: ClothCulling| {
        app.world_mut()
            .spawn((
                Cloth::grid(6, 6, 0.1),
                Transform::from_xyz(0.0, 1.0, z),
                culling,
            ))
            .id()
    };
    let front: Vec<Entity> = (0..10)
        .map(|k| spawn(&mut app, -3.0 - k as f32, ClothCulling::default()))
        .collect();
    let behind: Vec<Entity> = (0..10)
        .map(|k| spawn(&mut app, 3.0 + k as f32, ClothCulling::default()))
        .collect();
    let far = spawn(
        &mut app,
        -40.0,
        ClothCulling {
            max_distance: 20.0,
            ..default()
        },
    );
    let eye = app
        .world_mut()
        .spawn(camera(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 1.0, -1.0)))
        .id();
    for _ in 0..30 {
        app.update();
    }
    let time = |app: &App, e| sim_time(app, e);
    let culled = |app: &App, e| app.world().get::<ClothCulling>(e).unwrap().culled;
    let work = |app: &App, cloths: &[Entity]| -> f32 { cloths.iter().map(|&e| time(app, e)).sum() };
    let (seen, unseen) = (work(&app, &front), work(&app, &behind));
    eprintln!(
        "simulated seconds: in view {seen:.3}, behind {unseen:.3}, far {:.3}",
        time(&app, far)
    );
    assert!(
        front
            .iter()
            .all(|&e| !culled(&app, e) && time(&app, e) > 0.3)
    );
    assert!(behind.iter().all(|&e| culled(&app, e)));
    assert!(
        unseen <= 0.1 * seen,
        "behind the camera: {unseen} s against {seen} s"
    );
    assert!(culled(&app, far), "beyond its distance");
    let stats = app.world().get::<ClothStats>(behind[0]);
    assert!(stats.is_none_or(|s| s.culled));
    // While unseen, the first cloth behind is carried 1 m to the side; turned round, the
    // camera sees it again and it is put back on its body at rest: its whole shape moved
    // with its body (within what one step from rest moves it) and nothing swinging.
    let carried = behind[0];
    let shape = positions_of(&app, carried);
    let offset = Vec3::new(1.0, 0.0, 0.0);
    app.world_mut()
        .get_mut::<Transform>(carried)
        .unwrap()
        .translation += offset;
    app.update();
    assert!(culled(&app, carried), "still unseen while carried");
    let before = time(&app, carried);
    app.world_mut()
        .entity_mut(eye)
        .insert(camera(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 1.0)));
    app.update();
    assert!(!culled(&app, carried));
    assert!(time(&app, carried) > before, "it steps again");
    let sim = &app.world().get::<ClothSimulation>(carried).unwrap().solver;
    let off_body = (sim.positions().iter().zip(&shape))
        .map(|(x, x0)| x.distance(*x0 + offset))
        .fold(0.0, f32::max);
    let fastest = sim
        .particles()
        .velocity
        .iter()
        .map(|v| v.length())
        .fold(0.0, f32::max);
    eprintln!("seen again: {off_body:e} m off its carried shape, fastest {fastest:e} m/s");
    // One 16 ms step from rest: gravity alone moves a particle g·dt² = 2.5 mm, at
    // g·dt = 0.16 m/s (measured 0.34 mm, 0.028 m/s).
    assert!(
        off_body < 0.0025,
        "{off_body} m off its shape carried with its body"
    );
    assert!(fastest < 0.16, "{fastest} m/s: swung across the gap");
    golden::assert_golden("culled_and_seen", sim.positions());
    for _ in 0..10 {
        app.update();
    }
    assert!(culled(&app, front[0]));
}

/// A cloth entity's particle positions now.
fn positions_of(app: &App, e: Entity) -> Vec<Vec3> {
    let sim = app.world().get::<ClothSimulation>(e).unwrap();
    sim.solver.positions().to_vec()
}
