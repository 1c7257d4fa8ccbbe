//! The examples' keyboard controls (`examples/common/controls.rs`), driven through
//! `ButtonInput`.

#[path = "../../examples/common/controls.rs"]
mod controls;

use controls::ClothControlsPlugin;

use bevy::prelude::*;
use bevy_cloth::prelude::*;

use crate::common::*;

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
