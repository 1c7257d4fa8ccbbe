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
/// are counted culled; turned round, the camera sees them and they step again, each
/// starting at rest where its body is. One beyond `max_distance` in view is culled too.
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
    // Turned round: the cloths behind are seen, and step.
    let before = time(&app, behind[0]);
    app.world_mut()
        .entity_mut(eye)
        .insert(camera(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 1.0)));
    for _ in 0..10 {
        app.update();
    }
    assert!(!culled(&app, behind[0]));
    assert!(time(&app, behind[0]) > before, "it steps again");
    assert!(culled(&app, front[0]));
}
