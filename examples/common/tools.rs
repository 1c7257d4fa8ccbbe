//! The camera keys of Sladović 2014 §3.1 (W/A/S/D/Q/E rotate, keypad +/− zoom) on the orbit
//! camera, and the mouse tools: left-drag grabs the particle under the cursor and pulls
//! it, right-drag cuts the springs the stroke crosses. The orbit camera keeps left-drag
//! (away from the cloth) for orbiting; panning moves to the middle button.

use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_cloth::prelude::*;
use bevy_egui::EguiContexts;
use bevy_panorbit_camera::PanOrbitCamera;

/// Camera keys and mouse tools.
pub struct ToolsPlugin;

impl Plugin for ToolsPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<MouseTool>()
            .add_systems(Update, (camera_keys, mouse_tools));
    }
}

/// What the mouse is doing to a cloth.
#[derive(Resource, Default, Debug)]
enum MouseTool {
    #[default]
    Idle,
    /// Holding a particle of `cloth` at `depth` m along the cursor ray.
    Grabbing { cloth: Entity, depth: f32 },
    /// Cutting; the previous cursor ray's far point.
    Cutting { last_far: Vec3 },
}

const PICK_RADIUS: f32 = 0.06;
const CUT_REACH: f32 = 100.0;

fn camera_keys(
    keys: Res<ButtonInput<KeyCode>>,
    time: Res<Time>,
    mut cameras: Query<&mut PanOrbitCamera>,
) {
    let rate = 1.5 * time.delta_secs(); // radians per second held
    for mut camera in &mut cameras {
        let held = |k| if keys.pressed(k) { 1.0 } else { 0.0 };
        camera.target_pitch += rate * (held(KeyCode::KeyW) - held(KeyCode::KeyS));
        camera.target_yaw += rate * (held(KeyCode::KeyA) - held(KeyCode::KeyD));
        let roll = rate * (held(KeyCode::KeyE) - held(KeyCode::KeyQ));
        if roll != 0.0 {
            // Sladović 2014 rotates about the view's z axis too: roll the camera's frame.
            let r = Quat::from_rotation_z(roll);
            camera.axis = camera.axis.map(|a| r * a);
            camera.force_update = true;
        }
        let zoom = held(KeyCode::NumpadSubtract) - held(KeyCode::NumpadAdd);
        if zoom != 0.0 {
            camera.target_radius =
                (camera.target_radius * (1.0 + zoom * time.delta_secs())).clamp(0.3, 50.0);
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn mouse_tools(
    buttons: Res<ButtonInput<MouseButton>>,
    window: Single<&Window, With<PrimaryWindow>>,
    mut camera: Single<(&Camera, &GlobalTransform, &mut PanOrbitCamera)>,
    mut cloths: Query<(Entity, &mut ClothSimulation)>,
    mut tool: ResMut<MouseTool>,
    mut contexts: EguiContexts,
) {
    let over_ui = contexts
        .ctx_mut()
        .is_ok_and(|ctx| ctx.egui_wants_pointer_input() || ctx.is_pointer_over_egui());
    let (cam, cam_transform, orbit) = &mut *camera;
    let ray = window
        .cursor_position()
        .and_then(|cursor| cam.viewport_to_world(cam_transform, cursor).ok());
    match *tool {
        MouseTool::Idle => {
            let Some(ray) = ray else { return };
            if over_ui {
                return;
            }
            if buttons.just_pressed(MouseButton::Left) {
                // The nearest particle under the cursor, over every cloth.
                let hit = cloths
                    .iter()
                    .filter_map(|(e, sim)| {
                        sim.solver
                            .nearest_particle_to_ray(ray.origin, *ray.direction, PICK_RADIUS)
                            .map(|(i, depth)| (e, i, depth))
                    })
                    .min_by(|a, b| a.2.total_cmp(&b.2));
                if let Some((entity, particle, depth)) = hit
                    && let Ok((_, mut sim)) = cloths.get_mut(entity)
                {
                    sim.solver.grab(particle);
                    orbit.enabled = false;
                    *tool = MouseTool::Grabbing {
                        cloth: entity,
                        depth,
                    };
                }
            } else if buttons.just_pressed(MouseButton::Right) {
                *tool = MouseTool::Cutting {
                    last_far: ray.origin + *ray.direction * CUT_REACH,
                };
            }
        }
        MouseTool::Grabbing { cloth, depth } => {
            let Ok((_, mut sim)) = cloths.get_mut(cloth) else {
                *tool = MouseTool::Idle;
                orbit.enabled = true;
                return;
            };
            if !buttons.pressed(MouseButton::Left) || sim.solver.grabbed().is_none() {
                sim.solver.release_grab();
                orbit.enabled = true;
                *tool = MouseTool::Idle;
            } else if let Some(ray) = ray {
                sim.solver.drag_grab(ray.origin + *ray.direction * depth);
            }
        }
        MouseTool::Cutting { last_far } => {
            if !buttons.pressed(MouseButton::Right) {
                *tool = MouseTool::Idle;
                return;
            }
            let Some(ray) = ray else { return };
            let far = ray.origin + *ray.direction * CUT_REACH;
            if far.distance(last_far) > 1e-6 {
                for (_, mut sim) in &mut cloths {
                    sim.solver.cut(ray.origin, last_far, far);
                }
                *tool = MouseTool::Cutting { last_far: far };
            }
        }
    }
}
