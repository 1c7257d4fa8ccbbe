//! What the example scenes share: command-line options, the stage (camera, light,
//! ground) and screenshot mode. Uses only bevy_cloth's public API.

use std::path::PathBuf;

use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured, save_to_disk};
use bevy_cloth::ColliderKind;
use bevy_cloth::prelude::*;
use bevy_egui::EguiPlugin;
use bevy_panorbit_camera::{PanOrbitCamera, PanOrbitCameraPlugin};
use clap::Parser;

pub mod controls;
pub mod inspector;
pub mod tools;

/// Runs an example scene: the window, the plugins every example shares (cloth, controls,
/// inspector, tools, screenshots, orbit camera), the scene from `default_scene` (or
/// `--scene`) and a camera looking at `focus` from `radius` m.
pub fn run(title: &str, default_scene: &str, focus: Vec3, radius: f32) {
    let args = ExampleArgs::parse(default_scene);
    let scene = args.load_scene();
    let yaw = args.yaw_degrees.to_radians();
    app(title, args)
        .add_plugins(tools::ToolsPlugin)
        // A setting too stiff for real time slows the simulation down instead of freezing
        // the window: at most 100 ms of simulated time per frame.
        .insert_resource(Time::<Virtual>::from_max_delta(
            std::time::Duration::from_millis(100),
        ))
        .add_systems(
            Startup,
            move |mut commands: Commands,
                  mut meshes: ResMut<Assets<Mesh>>,
                  mut materials: ResMut<Assets<StandardMaterial>>| {
                spawn_scene(&scene, &mut commands, &mut meshes, &mut materials);
                spawn_stage(
                    &mut commands,
                    &mut meshes,
                    &mut materials,
                    focus,
                    radius,
                    yaw,
                );
            },
        )
        .run();
}

/// The app every example starts from: the window, the cloth and its keys, the egui
/// inspector, the orbit camera, screenshots (`args`) and the sky. The scene examples add the
/// mouse tools; an example with keys of its own leaves them out.
pub fn app(title: &str, args: ExampleArgs) -> App {
    app_with(
        title,
        args,
        ClothPlugin::default().with_timestep(std::time::Duration::from_millis(16)),
    )
}

/// [`app`] with the cloths stepped as `cloth` says.
pub fn app_with(title: &str, args: ExampleArgs, cloth: ClothPlugin) -> App {
    let mut app = App::new();
    if let Some(seconds) = args.frame_time {
        app.insert_resource(bevy::time::TimeUpdateStrategy::ManualDuration(
            std::time::Duration::from_secs_f32(seconds),
        ));
    }
    app.add_plugins((
        DefaultPlugins.set(window_plugin(title)),
        EguiPlugin::default(),
        PanOrbitCameraPlugin,
        cloth,
        controls::ClothControlsPlugin,
        inspector::InspectorPlugin,
        ScreenshotPlugin,
    ))
    .insert_resource(args)
    .insert_resource(ClearColor(Color::srgb(0.62, 0.70, 0.78)));
    app
}

/// Options every example accepts (`cargo run --example curtain -- --help`): `--scene FILE`,
/// `--set key=value` (repeatable, see `ClothScene::apply_override`), `--screenshot PATH
/// --frames N` (repeatable: one PNG per pair, then exit; also `CLOTH_SCREENSHOT` /
/// `CLOTH_FRAMES` for one) and `--yaw DEGREES`.
#[derive(Resource, Clone, Debug)]
pub struct ExampleArgs {
    /// The scene file to load.
    pub scene: PathBuf,
    /// Overrides applied to the scene after loading.
    pub overrides: Vec<String>,
    /// `(frame, path)`: save a PNG of the window at that frame; exit after the last.
    pub screenshots: Vec<(u32, PathBuf)>,
    /// The camera's starting angle about the vertical, degrees (`--yaw`; 20 by default,
    /// 180 looks at the back).
    pub yaw_degrees: f32,
    /// Seconds the app's clock advances a frame, whatever the frame took (`--frame-time`):
    /// screenshots at set simulated times on a slow or loaded machine. `None`: the wall
    /// clock.
    pub frame_time: Option<f32>,
}

/// The options every bevy_cloth example takes.
#[derive(Parser)]
struct Cli {
    /// The scene file (RON); each example has its own default.
    #[arg(long, value_name = "FILE")]
    scene: Option<PathBuf>,
    /// Overrides a scene field, e.g. `environment.wind.strength=0` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Saves a PNG of the window at the matching `--frames` (repeatable, in pairs).
    #[arg(long, value_name = "PATH")]
    screenshot: Vec<PathBuf>,
    /// The frame of the matching `--screenshot` (120 when missing).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    frames: Vec<u32>,
    /// The camera's starting angle about the vertical, degrees.
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true, value_parser = finite)]
    yaw: f32,
    /// Advances the clock this many seconds a frame instead of by the wall clock (e.g.
    /// 0.016667: screenshots at set simulated times however slow the frames are).
    #[arg(long, value_name = "SECONDS", value_parser = frame_time)]
    frame_time: Option<f32>,
}

fn frame_time(text: &str) -> Result<f32, String> {
    text.parse::<f32>()
        .ok()
        .filter(|t| (1e-4..=1.0).contains(t))
        .ok_or_else(|| format!("`{text}` is not a frame time from 0.0001 to 1 s"))
}

fn finite(text: &str) -> Result<f32, String> {
    text.parse::<f32>()
        .ok()
        .filter(|y| y.is_finite())
        .ok_or_else(|| format!("`{text}` is not an angle in degrees"))
}

impl ExampleArgs {
    /// Reads the options from the command line and environment; `default_scene` is the
    /// scene file used without `--scene`. Exits with code 2 on a malformed option.
    pub fn parse(default_scene: &str) -> Self {
        let cli = Cli::try_parse().unwrap_or_else(|e| {
            if !e.use_stderr() {
                let _ = e.print();
                std::process::exit(0);
            }
            // clap's first line names the problem (a usage block follows).
            let message = e.render().to_string();
            let first = message.lines().next().unwrap_or_default();
            fail(first.trim_start_matches("error: "))
        });
        let env_frames = std::env::var("CLOTH_FRAMES")
            .ok()
            .and_then(|f| f.parse().ok());
        let default_frames = env_frames.unwrap_or(120);
        let mut screenshots: Vec<(u32, PathBuf)> = cli
            .screenshot
            .into_iter()
            .enumerate()
            .map(|(k, path)| (cli.frames.get(k).copied().unwrap_or(default_frames), path))
            .collect();
        if screenshots.is_empty()
            && let Some(path) = std::env::var_os("CLOTH_SCREENSHOT")
        {
            screenshots.push((default_frames, PathBuf::from(path)));
        }
        screenshots.sort_by_key(|(frame, _)| *frame);
        ExampleArgs {
            scene: cli.scene.unwrap_or_else(|| PathBuf::from(default_scene)),
            overrides: cli.set,
            screenshots,
            yaw_degrees: cli.yaw,
            frame_time: cli.frame_time,
        }
    }

    /// Loads the scene and applies the overrides, or exits with code 2 and the error
    /// (file, line, field).
    pub fn load_scene(&self) -> ClothScene {
        let mut scene = ClothScene::load(&self.scene).unwrap_or_else(|e| fail(&e.to_string()));
        for spec in &self.overrides {
            scene
                .apply_override(spec)
                .unwrap_or_else(|e| fail(&e.to_string()));
        }
        scene
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

/// Spawns every cloth of the scene with a double-sided material of its colour (one per
/// garment piece), its colliders (drawn when they have a colour), and sets gravity, wind
/// and the timestep from it.
pub fn spawn_scene(
    scene: &ClothScene,
    commands: &mut Commands,
    meshes: &mut Assets<Mesh>,
    materials: &mut Assets<StandardMaterial>,
) {
    let spawned = scene.spawn(commands);
    // The example runs at the scene's timestep (spawning a scene leaves the clock alone).
    commands.insert_resource(Time::<Fixed>::from_seconds(f64::from(scene.timestep)));
    for (entry, entity) in scene.colliders.iter().zip(spawned.colliders) {
        if let Some([r, g, b]) = entry.color {
            let mesh = match entry.collider.shape.clone() {
                ColliderKind::Sphere { radius } => Sphere::new(radius).mesh().build(),
                ColliderKind::Capsule {
                    radius,
                    half_length,
                } => Capsule3d::new(radius, 2.0 * half_length).mesh().build(),
                ColliderKind::Cuboid { half_extents: h } => {
                    Cuboid::new(2.0 * h.x, 2.0 * h.y, 2.0 * h.z).mesh().build()
                }
                ColliderKind::Cylinder {
                    radius,
                    half_height,
                } => Cylinder::new(radius, 2.0 * half_height).mesh().build(),
                ColliderKind::Plane => Plane3d::default().mesh().size(4.0, 4.0).build(),
                ColliderKind::HalfSpace { normal, distance } => {
                    let normal = Dir3::new(normal).unwrap_or(Dir3::Y);
                    Plane3d::new(*normal, Vec2::splat(2.0))
                        .mesh()
                        .build()
                        .translated_by(*normal * distance)
                }
                // A scene file names only the kinds above.
                ColliderKind::Shape(_) => continue,
            };
            commands.entity(entity).insert((
                Mesh3d(meshes.add(mesh)),
                MeshMaterial3d(materials.add(StandardMaterial {
                    base_color: Color::linear_rgb(r, g, b),
                    perceptual_roughness: 0.6,
                    ..default()
                })),
            ));
        }
    }
    for (entry, entity) in scene.cloths.iter().zip(spawned.cloths) {
        let look = inspector::ClothLook {
            piece_colors: entry.piece_colors.clone(),
            ..inspector::ClothLook::from_color(entry.color)
        };
        commands
            .entity(entity)
            .insert((MeshMaterial3d(materials.add(look.material())), look));
    }
}

/// Ground, light and an orbit camera looking at `focus` from `radius` m, turned `yaw`
/// radians about the vertical.
pub fn spawn_stage(
    commands: &mut Commands,
    meshes: &mut Assets<Mesh>,
    materials: &mut Assets<StandardMaterial>,
    focus: Vec3,
    radius: f32,
    yaw: f32,
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
            yaw: Some(yaw),
            pitch: Some(0.12),
            // Right-drag cuts the cloth (see tools.rs), so panning takes the middle button.
            button_pan: MouseButton::Middle,
            ..default()
        },
        Transform::from_translation(focus + Vec3::new(0.0, 0.0, radius)),
        Name::new("camera"),
    ));
}

/// Screenshot mode: at each requested frame, save the window to a PNG; exit after the last.
pub struct ScreenshotPlugin;

#[derive(Resource, Default)]
struct ScreenshotState {
    frame: u32,
    saved: usize,
}

#[derive(Component)]
struct PendingScreenshot;

impl Plugin for ScreenshotPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<ScreenshotState>()
            .add_systems(Last, take_screenshots);
    }
}

fn take_screenshots(
    mut commands: Commands,
    time: Res<Time>,
    args: Res<ExampleArgs>,
    mut state: ResMut<ScreenshotState>,
    mut exit: MessageWriter<AppExit>,
) {
    if args.screenshots.is_empty() {
        return;
    }
    state.frame += 1;
    if state.saved == args.screenshots.len() {
        exit.write(AppExit::Success);
        return;
    }
    for (frame, path) in &args.screenshots {
        if *frame == state.frame {
            // The app's time too: under a software renderer a frame can be far longer
            // than a 60th of a second.
            info!(
                "screenshot {} at frame {frame}, {:.2} s in",
                path.display(),
                time.elapsed_secs()
            );
            commands
                .spawn((Screenshot::primary_window(), PendingScreenshot))
                .observe(save_to_disk(path.clone()))
                .observe(
                    |_: On<ScreenshotCaptured>, mut state: ResMut<ScreenshotState>| {
                        state.saved += 1;
                    },
                );
        }
    }
    let last = args.screenshots.last().map_or(0, |(f, _)| *f);
    if state.frame > last + 600 {
        error!("screenshots not captured 600 frames after they were asked for");
        exit.write(AppExit::error());
    }
}
