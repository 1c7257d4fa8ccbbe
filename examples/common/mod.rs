//! What the example scenes share: command-line options, the stage (camera, light,
//! ground) and screenshot mode. Uses only bevy_cloth's public API.

use std::path::PathBuf;

use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured, save_to_disk};
use bevy_cloth::prelude::*;
use bevy_panorbit_camera::PanOrbitCamera;

/// Options every example accepts:
/// `--scene FILE`, `--screenshot PATH --frames N` (also `CLOTH_SCREENSHOT`, `CLOTH_FRAMES`).
#[derive(Resource, Clone, Debug)]
pub struct ExampleArgs {
    /// The scene file to load.
    pub scene: PathBuf,
    /// Save a PNG of the window here after `frames` frames, then exit.
    pub screenshot: Option<PathBuf>,
    /// Frames to run before the screenshot.
    pub frames: u32,
}

impl ExampleArgs {
    /// Reads the options from the command line and environment; `default_scene` is the
    /// scene file used without `--scene`. Exits with code 2 on a malformed option.
    pub fn parse(default_scene: &str) -> Self {
        let mut args = ExampleArgs {
            scene: PathBuf::from(default_scene),
            screenshot: std::env::var_os("CLOTH_SCREENSHOT").map(PathBuf::from),
            frames: std::env::var("CLOTH_FRAMES")
                .ok()
                .and_then(|f| f.parse().ok())
                .unwrap_or(120),
        };
        let mut it = std::env::args().skip(1);
        while let Some(flag) = it.next() {
            let mut value = || {
                it.next()
                    .unwrap_or_else(|| fail(&format!("{flag} needs a value")))
            };
            match flag.as_str() {
                "--scene" => args.scene = PathBuf::from(value()),
                "--screenshot" => args.screenshot = Some(PathBuf::from(value())),
                "--frames" => {
                    let v = value();
                    args.frames = v.parse().unwrap_or_else(|_| {
                        fail(&format!("--frames: `{v}` is not a whole number"))
                    });
                }
                other => fail(&format!(
                    "unknown option `{other}` (try --scene, --screenshot, --frames)"
                )),
            }
        }
        args
    }

    /// Loads the scene, or exits with code 2 and the error (file, line, field).
    pub fn load_scene(&self) -> ClothScene {
        ClothScene::load(&self.scene).unwrap_or_else(|e| fail(&e.to_string()))
    }
}

fn fail(message: &str) -> ! {
    eprintln!("error: {message}");
    std::process::exit(2)
}

/// A window title and size that suit the scenes; fixed size so screenshots compare.
pub fn window_plugin(title: &str) -> WindowPlugin {
    WindowPlugin {
        primary_window: Some(Window {
            title: title.into(),
            resolution: (1280, 720).into(),
            ..default()
        }),
        ..default()
    }
}

/// Spawns every cloth of the scene with a double-sided material of its colour, and sets
/// gravity, wind and the timestep from it.
pub fn spawn_scene(
    scene: &ClothScene,
    commands: &mut Commands,
    materials: &mut Assets<StandardMaterial>,
) {
    commands.insert_resource(ClothEnvironment(scene.environment));
    commands.insert_resource(Time::<Fixed>::from_seconds(scene.timestep as f64));
    for entry in &scene.cloths {
        let [r, g, b] = entry.color;
        commands.spawn((
            entry.cloth.clone(),
            Name::new(entry.name.clone()),
            Transform::from_translation(entry.translation)
                .with_rotation(Quat::from_rotation_y(entry.yaw_degrees.to_radians())),
            MeshMaterial3d(materials.add(StandardMaterial {
                base_color: Color::linear_rgb(r, g, b),
                perceptual_roughness: 0.75,
                reflectance: 0.3,
                // Back faces get flipped normals: lit as back faces, not as the front.
                double_sided: true,
                cull_mode: None,
                ..default()
            })),
        ));
    }
}

/// Ground, light and an orbit camera looking at `focus` from `radius` m.
pub fn spawn_stage(
    commands: &mut Commands,
    meshes: &mut Assets<Mesh>,
    materials: &mut Assets<StandardMaterial>,
    focus: Vec3,
    radius: f32,
) {
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(12.0, 12.0))),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.42, 0.45, 0.40),
            perceptual_roughness: 0.95,
            ..default()
        })),
        Name::new("ground"),
    ));
    commands.insert_resource(GlobalAmbientLight {
        brightness: 250.0,
        ..default()
    });
    commands.spawn((
        DirectionalLight {
            illuminance: 9_000.0,
            shadow_maps_enabled: true,
            ..default()
        },
        Transform::from_xyz(3.0, 6.0, 5.0).looking_at(Vec3::ZERO, Vec3::Y),
        Name::new("sun"),
    ));
    commands.spawn((
        PanOrbitCamera {
            focus,
            radius: Some(radius),
            yaw: Some(0.35),
            pitch: Some(0.12),
            ..default()
        },
        Transform::from_translation(focus + Vec3::new(0.0, 0.0, radius)),
        Name::new("camera"),
    ));
}

/// Screenshot mode: after `frames` frames, save the window to a PNG and exit.
pub struct ScreenshotPlugin;

#[derive(Resource, Default)]
struct ScreenshotState {
    frame: u32,
    saved: bool,
}

impl Plugin for ScreenshotPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<ScreenshotState>()
            .add_systems(Last, take_screenshot);
    }
}

fn take_screenshot(
    mut commands: Commands,
    args: Res<ExampleArgs>,
    mut state: ResMut<ScreenshotState>,
    mut exit: MessageWriter<AppExit>,
) {
    let Some(path) = &args.screenshot else {
        return;
    };
    state.frame += 1;
    if state.saved {
        exit.write(AppExit::Success);
    } else if state.frame == args.frames {
        commands
            .spawn(Screenshot::primary_window())
            .observe(save_to_disk(path.clone()))
            .observe(
                |_: On<ScreenshotCaptured>, mut state: ResMut<ScreenshotState>| {
                    state.saved = true;
                },
            );
    } else if state.frame > args.frames + 600 {
        error!("no screenshot after 600 frames");
        exit.write(AppExit::error());
    }
}
