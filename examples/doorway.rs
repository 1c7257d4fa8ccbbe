//! A doorway hung with six strips of denim that a body walks through, back and forth, with
//! air blowing through the door: `cargo run --example doorway`, or
//! `cargo run --example doorway -- --wind 10 --self-collision`. Everything is the
//! plugin's defaults but the fabric: its frame budget, the strips' model, the distance
//! self-collision keeps. `cargo run -p bevy_cloth_lab --example doorway_cost` runs it
//! headless and measures it. Public API only.

use bevy::prelude::*;
use bevy_cloth::params::{Environment, WindField};
use bevy_cloth::prelude::*;

fn main() {
    let mut doorway = Doorway::default();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--wind" => match args.next().and_then(|v| v.parse::<f32>().ok()) {
                Some(speed) if speed.is_finite() && speed >= 0.0 => doorway.wind = speed,
                _ => exit("--wind takes an air speed in m/s, 0 or more"),
            },
            "--self-collision" => doorway.self_collision = true,
            _ => exit(&format!(
                "unknown argument `{arg}` (--wind M/S, --self-collision)"
            )),
        }
    }
    App::new()
        .add_plugins(DefaultPlugins)
        .insert_resource(doorway)
        .add_plugins(scene)
        .run();
}

fn exit(message: &str) -> ! {
    eprintln!("error: {message}");
    std::process::exit(2)
}

/// How the doorway is set up.
#[derive(Resource, Clone, Copy, Debug)]
pub struct Doorway {
    /// Air through the door, m/s, in gusts.
    pub wind: f32,
    /// Whether each strip keeps apart from itself and the others.
    pub self_collision: bool,
    /// The gap between strips, m.
    pub gap: f32,
}

impl Default for Doorway {
    fn default() -> Self {
        Doorway {
            wind: 0.0,
            self_collision: false,
            gap: 0.02,
        }
    }
}

/// Six strips 5 × 45 particles, 4 cm apart (16 × 176 cm), [`Doorway::gap`] between
/// strips, their top rows pinned under a lintel 2 m up.
pub const STRIPS: usize = 6;
const STRIP: (u32, u32) = (5, 45);
const SPACING: f32 = 0.04;
const LINTEL: f32 = 2.0;

/// The body: a capsule 1.64 m tall that waits `WAIT` s three metres before the door,
/// then walks through it to three metres behind and back, at 1.2 m/s.
#[derive(Component)]
struct Walker;
/// Seconds the body waits before its first walk.
pub const WAIT: f32 = 3.0;
const SPEED: f32 = 1.2;
const REACH: f32 = 3.0;

/// The doorway headless, with no window or renderer, for its measurements and tests:
/// `setup` in a headless app with `budget`, updated until its six strips are built.
#[allow(dead_code)] // the example opens a window; its headless twin and a test use this
pub fn headless(setup: Doorway, budget: ClothBudget) -> App {
    let root = bevy_cloth::layout::garment::asset_root();
    let mut app = bevy_cloth::headless::headless_base_in(root.to_string_lossy());
    app.add_plugins(TransformPlugin)
        .init_asset::<StandardMaterial>()
        .insert_resource(setup);
    scene(&mut app);
    app.insert_resource(budget);
    let mut sims = app.world_mut().query::<&ClothSimulation>();
    for _ in 0..10 {
        app.update();
        if sims.iter(app.world()).count() == STRIPS {
            break;
        }
    }
    app
}

/// The doorway as a plugin: the cloth plugin, the air, the scene and the walk. Reads the
/// [`Doorway`] resource (its default when absent).
pub fn scene(app: &mut App) {
    let doorway = *app
        .world_mut()
        .get_resource_or_insert_with(Doorway::default);
    app.add_plugins(ClothPlugin::default())
        .insert_resource(ClothEnvironment(Environment {
            air: Some(Air {
                velocity: Vec3::new(0.0, 0.0, doorway.wind),
                field: WindField::Trigonometric,
                ..default()
            }),
            ..default()
        }))
        .add_systems(Startup, setup)
        .add_systems(FixedUpdate, walk);
}

fn setup(
    mut commands: Commands,
    doorway: Res<Doorway>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let (w, h) = STRIP;
    let width = (w - 1) as f32 * SPACING;
    let params = ClothParams {
        fabric: Some(Fabric::DENIM),
        self_collision: if doorway.self_collision {
            SelfCollision::on()
        } else {
            SelfCollision::default()
        },
        ..default()
    };
    let denim = materials.add(StandardMaterial {
        base_color: Color::srgb(0.16, 0.25, 0.45),
        double_sided: true,
        cull_mode: None,
        perceptual_roughness: 0.9,
        ..default()
    });
    for k in 0..STRIPS {
        // Each grid hangs in its XY plane from the middle of its top row.
        let x = (k as f32 - (STRIPS - 1) as f32 * 0.5) * (width + doorway.gap);
        commands.spawn((
            Cloth::grid(w, h, SPACING)
                .with_pins(ClothPins::TopRow)
                .with_params(params),
            Transform::from_xyz(x, LINTEL, 0.0),
            MeshMaterial3d(denim.clone()),
            Name::new(format!("strip {k}")),
        ));
    }
    let wood = materials.add(Color::srgb(0.45, 0.3, 0.18));
    let opening = STRIPS as f32 * (width + doorway.gap);
    for (size, at) in [
        (
            Vec3::new(opening + 0.3, 0.12, 0.2),
            Vec3::new(0.0, LINTEL + 0.07, 0.0),
        ),
        (
            Vec3::new(0.12, LINTEL, 0.2),
            Vec3::new(-0.5 * opening - 0.1, 0.5 * LINTEL, 0.0),
        ),
        (
            Vec3::new(0.12, LINTEL, 0.2),
            Vec3::new(0.5 * opening + 0.1, 0.5 * LINTEL, 0.0),
        ),
    ] {
        commands.spawn((
            Mesh3d(meshes.add(Cuboid::from_size(size))),
            MeshMaterial3d(wood.clone()),
            Transform::from_translation(at),
        ));
    }
    commands.spawn((
        Walker,
        ClothCollider::capsule(0.22, 1.2),
        Mesh3d(meshes.add(Capsule3d::new(0.22, 1.2))),
        MeshMaterial3d(materials.add(Color::srgb(0.75, 0.55, 0.4))),
        Transform::from_translation(pose(0.0)),
    ));
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(10.0, 10.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.55, 0.6, 0.5))),
    ));
    commands.spawn((
        DirectionalLight::default(),
        Transform::from_xyz(3.0, 6.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((
        Camera3d::default(),
        Transform::from_xyz(3.4, 1.7, 2.8).looking_at(Vec3::new(0.0, 1.0, 0.0), Vec3::Y),
    ));
}

/// Where the body is `t` s in: waiting `REACH` before the door, then walking to as far
/// behind it and back.
fn pose(t: f32) -> Vec3 {
    let walked = (t - WAIT).max(0.0) * SPEED;
    let lap = 4.0 * REACH;
    let along = walked % lap;
    let along = if along < 2.0 * REACH {
        along
    } else {
        lap - along
    };
    Vec3::new(0.0, 0.82, along - REACH)
}

fn walk(time: Res<Time>, mut walker: Query<&mut Transform, With<Walker>>) {
    for mut body in &mut walker {
        body.translation = pose(time.elapsed_secs());
    }
}
