//! A cape on a running character, with avian3d's physics: the character is an
//! avian capsule body that runs on a ground among obstacles (avian keeps it out of them);
//! the cape is attached by its top edge round the character's shoulders
//! (`ClothAttachment::at`, points of the body's frame) and collides with the character's
//! own capsule, the ground and the obstacles through their avian colliders (the `avian`
//! feature), friction included. The orbit camera follows the character.
//!
//! WASD or the arrow keys run (relative to the camera); without input for two seconds the
//! character runs its own loop round the middle. Mouse: orbit (left), zoom (wheel).
//!
//! `cargo run --example cape --features avian [-- --screenshot out.png --frames 240]`

// The shared example code; this example builds its own scene, so it uses part of it.
#[allow(dead_code)]
mod common;

use avian3d::prelude::{
    Collider, Friction, LinearVelocity, LockedAxes, PhysicsPlugins, RigidBody, Rotation,
};
use bevy::prelude::*;
use bevy_cloth::params::{Model, Wind, WindField, XpbdParams};
use bevy_cloth::prelude::*;
use bevy_panorbit_camera::PanOrbitCamera;

/// The character's capsule: radius and half the length of its axis (m); 1.6 m tall.
const RADIUS: f32 = 0.3;
const HALF_LENGTH: f32 = 0.5;
/// Running speed (m/s) and the fastest it turns (rad/s).
const SPEED: f32 = 3.5;
const TURN_RATE: f32 = 6.0;
/// The scripted loop: a circle of this radius (m) round the origin.
const LOOP_RADIUS: f32 = 3.2;
/// Half the arena's side (m): the walls round it.
const ARENA: f32 = 10.0;
/// Seconds without input before the character runs its loop again.
const SCRIPT_AFTER: f32 = 2.0;
/// The camera looks from this angle (radians) round from straight behind the character,
/// and this far (radians) down on it: high enough to look over the boxes (a camera 7°
/// above the character lost it behind a pillar between them).
const CAMERA_YAW: f32 = 0.6;
const CAMERA_PITCH: f32 = 0.35;
/// The cape: particles across and down, and their spacing (m).
const CAPE_WIDTH: u32 = 14;
const CAPE_HEIGHT: u32 = 17;
const CAPE_SPACING: f32 = 0.045;

/// The running character: where it faces (radians about y; 0 faces −z) and how long
/// since a key moved it (s; it starts on its loop).
#[derive(Component)]
struct Runner {
    heading: f32,
    idle: f32,
}

fn main() {
    let args = common::ExampleArgs::parse("");
    common::app("bevy_cloth — cape", args)
        .add_plugins((PhysicsPlugins::default(), ClothAvianPlugin::default()))
        .insert_resource(common::inspector::Help(
            "W/A/S/D or arrows run (the loop after 2 s without) · left-drag orbit · wheel zoom · \
O/P wind · G gravity · Space pause · N step · R reset · Esc quit",
        ))
        .add_systems(Startup, setup)
        // The character's velocity is set before avian's step (in `FixedPostUpdate`); the
        // cloth steps after it (`ClothAvianPlugin` orders it so).
        .add_systems(FixedUpdate, run)
        .add_systems(Update, follow)
        .run();
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut environment: ResMut<ClothEnvironment>,
) {
    // Still air with Maslova's gusts in it (1.5 m/s): the cape flies behind the runner
    // from its drag and lift on every triangle, and ripples (without air it hangs stiff
    // behind the back). The particle wind is off: the air carries the gusts.
    environment.wind = Wind {
        strength: 0.0,
        ..Wind::default()
    };
    environment.air = Some(Air {
        velocity: Vec3::new(0.6, 0.0, 1.4),
        field: WindField::Trigonometric,
        ..Air::default()
    });
    // The character starts on the loop, facing along it (+x).
    let start = Vec3::new(0.0, RADIUS + HALF_LENGTH, LOOP_RADIUS);
    let heading = -std::f32::consts::FRAC_PI_2;
    // The stage's ground, light and camera; the ground is an avian half-space.
    common::spawn_stage(
        &mut commands,
        &mut meshes,
        &mut materials,
        start + Vec3::Y * 0.3,
        5.0,
        heading + CAMERA_YAW,
    );
    // The arena: the ground drawn wider than the stage's, and low walls round it that
    // avian keeps the character inside.
    commands.spawn((
        RigidBody::Static,
        Collider::half_space(Vec3::Y),
        Transform::from_xyz(0.0, -0.001, 0.0),
        Mesh3d(meshes.add(Plane3d::default().mesh().size(2.0 * ARENA, 2.0 * ARENA))),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.42, 0.45, 0.40),
            perceptual_roughness: 0.95,
            ..default()
        })),
        Name::new("arena ground"),
    ));
    // Obstacles: boxes and pillars inside and outside the loop (run into them with the
    // keys: avian stops the character, the cape drapes over them).
    let stone = materials.add(StandardMaterial {
        base_color: Color::srgb(0.55, 0.53, 0.50),
        perceptual_roughness: 0.9,
        ..default()
    });
    let boxes = [
        (Vec3::new(0.0, 0.4, 0.0), Vec3::new(1.2, 0.8, 1.2), 0.3),
        (Vec3::new(-5.0, 0.5, -1.0), Vec3::new(0.8, 1.0, 2.0), 0.0),
        (Vec3::new(4.6, 0.25, 3.0), Vec3::new(1.5, 0.5, 0.6), 0.7),
    ];
    for (at, size, turn) in boxes {
        commands.spawn((
            RigidBody::Static,
            Collider::cuboid(size.x, size.y, size.z),
            Transform::from_translation(at).with_rotation(Quat::from_rotation_y(turn)),
            Mesh3d(meshes.add(Cuboid::from_size(size))),
            MeshMaterial3d(stone.clone()),
            Name::new("box"),
        ));
    }
    for (at, size) in [
        (
            Vec3::new(0.0, 0.3, -ARENA),
            Vec3::new(2.0 * ARENA, 0.6, 0.3),
        ),
        (Vec3::new(0.0, 0.3, ARENA), Vec3::new(2.0 * ARENA, 0.6, 0.3)),
        (
            Vec3::new(-ARENA, 0.3, 0.0),
            Vec3::new(0.3, 0.6, 2.0 * ARENA),
        ),
        (Vec3::new(ARENA, 0.3, 0.0), Vec3::new(0.3, 0.6, 2.0 * ARENA)),
    ] {
        commands.spawn((
            RigidBody::Static,
            Collider::cuboid(size.x, size.y, size.z),
            Transform::from_translation(at),
            Mesh3d(meshes.add(Cuboid::from_size(size))),
            MeshMaterial3d(stone.clone()),
            Name::new("wall"),
        ));
    }
    // One pillar inside the loop, one outside beyond where the following camera goes.
    for at in [Vec3::new(1.6, 0.9, -1.4), Vec3::new(-2.0, 0.9, 8.5)] {
        commands.spawn((
            RigidBody::Static,
            Collider::cylinder(0.25, 1.8),
            Transform::from_translation(at),
            Mesh3d(meshes.add(Cylinder::new(0.25, 1.8))),
            MeshMaterial3d(stone.clone()),
            Name::new("pillar"),
        ));
    }
    // The character: an avian capsule body that does not tip over (it turns itself), drawn
    // as a capsule with a head.
    let skin = materials.add(StandardMaterial {
        base_color: Color::srgb(0.80, 0.78, 0.74),
        perceptual_roughness: 0.7,
        ..default()
    });
    let body = commands
        .spawn((
            RigidBody::Dynamic,
            Collider::capsule(RADIUS, 2.0 * HALF_LENGTH),
            LockedAxes::ROTATION_LOCKED,
            Friction::new(0.0),
            Transform::from_translation(start).with_rotation(Quat::from_rotation_y(heading)),
            Runner {
                heading,
                idle: SCRIPT_AFTER,
            },
            Mesh3d(meshes.add(Capsule3d::new(RADIUS, 2.0 * HALF_LENGTH))),
            MeshMaterial3d(skin.clone()),
            Name::new("character"),
        ))
        .with_children(|body| {
            body.spawn((
                Mesh3d(meshes.add(Sphere::new(0.16))),
                MeshMaterial3d(skin),
                Transform::from_xyz(0.0, HALF_LENGTH + RADIUS + 0.12, 0.0),
            ));
        })
        .id();
    // The cape: its grid hangs from the middle of its top edge, put 3 cm behind the back
    // at shoulder height (+z is behind a character facing −z). Its top edge is attached
    // at points of the body's frame (`ClothAttachment::at`): round the back on an arc 3 cm
    // out from the body, a particle spacing apart, so it wraps the shoulders.
    let arc_radius = RADIUS + 0.03;
    let shoulders = Vec3::new(0.0, 0.42, arc_radius);
    let collar: Vec<(u32, Vec3)> = (0..CAPE_WIDTH)
        .map(|i| {
            let angle = (i as f32 - (CAPE_WIDTH - 1) as f32 * 0.5) * CAPE_SPACING / arc_radius;
            let at = Vec3::new(
                arc_radius * angle.sin(),
                shoulders.y,
                arc_radius * angle.cos(),
            );
            (i, at)
        })
        .collect();
    let place = Transform::from_translation(start).with_rotation(Quat::from_rotation_y(heading));
    commands.spawn((
        Cloth::grid(CAPE_WIDTH, CAPE_HEIGHT, CAPE_SPACING)
            // Denim in physical units (its mass, stretch, shear and bending from Wang et
            // al. 2011's measurements), on XPBD, which solves its stretch along the cape's
            // rows and columns: about 1.2 ms a step for a cape this size on one core
            // (`cargo run -p bevy_cloth_lab --example cape_cost`). Self-collision keeps
            // the cape out of itself when it wraps round the runner.
            .with_params(ClothParams {
                model: Model::Xpbd(XpbdParams::default()),
                fabric: Some(Fabric::DENIM),
                self_collision: SelfCollision::on(),
                ..default()
            }),
        place.with_translation(place.transform_point(shoulders)),
        ClothAttachments(vec![ClothAttachment::at(body, collar)]),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.62, 0.06, 0.10),
            double_sided: true,
            cull_mode: None,
            perceptual_roughness: 0.75,
            ..default()
        })),
        Name::new("cape"),
    ));
}

/// Runs the character: towards the keys' direction (relative to the camera), or round the
/// loop after two seconds without input; it turns to face where it runs.
fn run(
    time: Res<Time>,
    keys: Option<Res<ButtonInput<KeyCode>>>,
    camera: Query<&Transform, (With<PanOrbitCamera>, Without<Runner>)>,
    mut runners: Query<(&Transform, &mut Runner, &mut LinearVelocity, &mut Rotation)>,
) {
    let dt = time.delta_secs();
    let held = |a: KeyCode, b: KeyCode| {
        keys.as_ref().is_some_and(|k| k.pressed(a) || k.pressed(b)) as i32 as f32
    };
    let input = Vec2::new(
        held(KeyCode::KeyD, KeyCode::ArrowRight) - held(KeyCode::KeyA, KeyCode::ArrowLeft),
        held(KeyCode::KeyW, KeyCode::ArrowUp) - held(KeyCode::KeyS, KeyCode::ArrowDown),
    );
    for (transform, mut runner, mut velocity, mut rotation) in &mut runners {
        runner.idle = if input == Vec2::ZERO {
            runner.idle + dt
        } else {
            0.0
        };
        let at = transform.translation;
        let wanted = if input != Vec2::ZERO {
            // Forward is where the camera looks, flattened.
            let (forward, right) = camera.single().map_or((Vec3::NEG_Z, Vec3::X), |c| {
                let f = (c.forward().as_vec3() * Vec3::new(1.0, 0.0, 1.0)).normalize_or_zero();
                (f, f.cross(Vec3::Y))
            });
            (forward * input.y + right * input.x).normalize_or_zero()
        } else if runner.idle >= SCRIPT_AFTER {
            // The loop: along its tangent, steered back onto it.
            let out = Vec3::new(at.x, 0.0, at.z);
            let radial = out.normalize_or(Vec3::Z);
            let tangent = Vec3::new(radial.z, 0.0, -radial.x);
            (tangent + radial * 0.8 * (LOOP_RADIUS - out.length())).normalize()
        } else {
            Vec3::ZERO
        };
        // The heading turns towards the running direction at most TURN_RATE.
        if wanted != Vec3::ZERO {
            let target = (-wanted.x).atan2(-wanted.z);
            let mut diff = target - runner.heading;
            diff = (diff + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU)
                - std::f32::consts::PI;
            runner.heading += diff.clamp(-TURN_RATE * dt, TURN_RATE * dt);
        }
        rotation.0 = Quat::from_rotation_y(runner.heading);
        velocity.0.x = wanted.x * SPEED;
        velocity.0.z = wanted.z * SPEED;
    }
}

/// Keeps the orbit camera on the character; while it runs its loop, the camera also
/// swings round to look at it from behind, to one side and from above.
fn follow(runners: Query<(&Transform, &Runner)>, mut cameras: Query<&mut PanOrbitCamera>) {
    let Ok((transform, runner)) = runners.single() else {
        return;
    };
    for mut camera in &mut cameras {
        camera.target_focus = transform.translation + Vec3::Y * 0.3;
        if runner.idle >= SCRIPT_AFTER {
            camera.target_yaw = runner.heading + CAMERA_YAW;
            camera.target_pitch = CAMERA_PITCH;
        }
    }
}
