//! The source works' keyboard controls for the simulation (Sladović 2014 §3.1 and its
//! appendix; Maslova §2.1), as the examples' plugin: a game has its own keys (this is
//! example code, through the crate's public API; copy what you like).
//!
//! | key | action |
//! | --- | --- |
//! | O / P | lower / raise the wind strength |
//! | keypad 4 / 6 | turn the wind left / right (about the vertical) |
//! | keypad 8 / 2 | tilt the wind up / down |
//! | G | gravity on / off (Sladović 2014's `toggleGravity`) |
//! | Space | pause / resume |
//! | N | one step while paused |
//! | R | reset every cloth (undoes grabs and cuts) |
//! | Escape | quit |
//!
//! Camera keys (W/A/S/D/Q/E, keypad +/−) belong to the camera, so the examples add them.

use bevy::math::{Quat, Vec3};
use bevy::prelude::*;

use bevy_cloth::prelude::*;

/// Adds the keyboard controls. Needs a `ButtonInput<KeyCode>` resource (from
/// `InputPlugin`, part of `DefaultPlugins`).
#[derive(Default)]
pub struct ClothControlsPlugin;

/// How far one key press moves a value.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Resource)]
pub struct ClothControls {
    /// Wind strength change per press of O / P, N per particle.
    pub wind_step: f32,
    /// Upper limit of the wind strength reachable with P.
    pub max_wind: f32,
    /// Wind direction change per press of a keypad arrow, degrees.
    pub angle_step_degrees: f32,
}

impl Default for ClothControls {
    fn default() -> Self {
        Self {
            wind_step: 2.5e-4,
            max_wind: 0.02,
            angle_step_degrees: 15.0,
        }
    }
}

impl Plugin for ClothControlsPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<ClothControls>()
            .register_type::<ClothControls>()
            .add_systems(
                Update,
                keyboard_controls.run_if(resource_exists::<ButtonInput<KeyCode>>),
            );
    }
}

fn keyboard_controls(
    keys: Res<ButtonInput<KeyCode>>,
    controls: Res<ClothControls>,
    mut env: ResMut<ClothEnvironment>,
    mut pause: ResMut<ClothPause>,
    mut cloths: Query<&mut ClothSimulation>,
    mut exit: MessageWriter<AppExit>,
) {
    let wind = &mut env.wind;
    if keys.just_pressed(KeyCode::KeyO) {
        wind.strength = (wind.strength - controls.wind_step).max(0.0);
    }
    if keys.just_pressed(KeyCode::KeyP) {
        wind.strength = (wind.strength + controls.wind_step).min(controls.max_wind);
    }
    let step = controls.angle_step_degrees.to_radians();
    let turn = |key, rotation: Quat| keys.just_pressed(key).then_some(rotation);
    let horizontal = Vec3::Y.cross(wind.direction).normalize_or(Vec3::X);
    let rotations = [
        turn(KeyCode::Numpad4, Quat::from_rotation_y(step)),
        turn(KeyCode::Numpad6, Quat::from_rotation_y(-step)),
        turn(KeyCode::Numpad8, Quat::from_axis_angle(horizontal, -step)),
        turn(KeyCode::Numpad2, Quat::from_axis_angle(horizontal, step)),
    ];
    for rotation in rotations.into_iter().flatten() {
        let turned = rotation * wind.direction.normalize_or(Vec3::Z);
        // Keep the wind off the poles so left/right stays defined.
        if turned.y.abs() < 0.99 {
            wind.direction = turned;
        }
    }
    if keys.just_pressed(KeyCode::KeyG) {
        env.gravity_enabled = !env.gravity_enabled;
    }
    if keys.just_pressed(KeyCode::Space) {
        pause.toggle();
    }
    if keys.just_pressed(KeyCode::KeyN) {
        pause.step_once();
    }
    if keys.just_pressed(KeyCode::KeyR) {
        for mut sim in &mut cloths {
            sim.reset();
        }
    }
    if keys.just_pressed(KeyCode::Escape) {
        exit.write(AppExit::Success);
    }
}
