//! avian3d colliders (the `avian` feature): a particle dropped on an avian ball, capsule,
//! cuboid, cylinder and half-space comes to rest at the collider's thickness from the analytic
//! surface. `cargo test --features avian --test avian`.
#![cfg(feature = "avian")]

mod common;

use avian3d::prelude::{Collider, Friction};
use bevy::math::{Affine3A, Quat, Vec3};
use bevy::prelude::{GlobalTransform, Transform};
use bevy_cloth::avian::{HullCache, THICKNESS, to_solver_collider};
use bevy_cloth::params::Environment;
use bevy_cloth::prelude::*;
use bevy_cloth::solver::{ClothSolver, Layout};

fn rest_on(collider: bevy_cloth::solver::Collider, start: Vec3) -> Vec3 {
    let mut cloth = ClothSolver::new(
        Layout::from_springs(&[start], &[]).unwrap(),
        &[],
        &ClothParams {
            drag: 0.0,
            ..ClothParams::seeds()
        },
        Affine3A::IDENTITY,
    )
    .unwrap();
    cloth.set_colliders([collider]);
    for _ in 0..125 {
        cloth.step(0.016, &Environment::default());
    }
    assert!(cloth.particles().velocity[0].length() < 1e-3, "still moves");
    cloth.positions()[0]
}

/// The headless app with transforms, avian's physics and `plugin`, set up as `App::run`
/// sets it up (avian makes some of its resources there).
fn avian_app(plugin: ClothAvianPlugin) -> bevy::app::App {
    use bevy::prelude::*;
    let mut app = bevy_cloth::headless::headless_app();
    app.add_plugins((
        TransformPlugin,
        avian3d::prelude::PhysicsPlugins::default(),
        plugin,
    ));
    app.finish();
    app.cleanup();
    app
}

#[test]
fn a_particle_rests_on_avian_colliders_at_the_analytic_distance() {
    let at = |x: f32, y: f32, z: f32| GlobalTransform::from(Transform::from_xyz(x, y, z));
    let cases = [
        // A ball of radius 0.3 at y = 1: rests at 1.3 + thickness.
        (
            "ball",
            Collider::sphere(0.3),
            at(0.2, 1.0, 0.0),
            Vec3::new(0.2, 2.0, 0.0),
            Vec3::new(0.2, 1.3 + THICKNESS, 0.0),
        ),
        // A capsule of radius 0.1 and length 1 lying along x (turned 90° about z) at y = 0.5.
        (
            "capsule",
            Collider::capsule(0.1, 1.0),
            GlobalTransform::from(
                Transform::from_xyz(0.0, 0.5, 0.0)
                    .with_rotation(Quat::from_rotation_z(std::f32::consts::FRAC_PI_2)),
            ),
            Vec3::new(0.2, 1.5, 0.0),
            Vec3::new(0.2, 0.6 + THICKNESS, 0.0),
        ),
        // A 0.6 × 0.4 × 0.2 box at y = 0.5: its top face at 0.7.
        (
            "cuboid",
            Collider::cuboid(0.6, 0.4, 0.2),
            at(0.0, 0.5, 0.0),
            Vec3::new(0.1, 1.5, 0.05),
            Vec3::new(0.1, 0.7 + THICKNESS, 0.05),
        ),
        // An upright cylinder of radius 0.2 and height 0.6 at y = 0.5: its top disc at 0.8.
        (
            "cylinder",
            Collider::cylinder(0.2, 0.6),
            at(0.0, 0.5, 0.0),
            Vec3::new(0.1, 1.5, -0.05),
            Vec3::new(0.1, 0.8 + THICKNESS, -0.05),
        ),
        // The same lying along z (turned 90° about x): its round side 0.2 above its axis.
        (
            "lying cylinder",
            Collider::cylinder(0.2, 0.6),
            GlobalTransform::from(
                Transform::from_xyz(0.0, 0.5, 0.0)
                    .with_rotation(Quat::from_rotation_x(std::f32::consts::FRAC_PI_2)),
            ),
            Vec3::new(0.0, 1.5, 0.2),
            Vec3::new(0.0, 0.7 + THICKNESS, 0.2),
        ),
        // The convex hull of a tetrahedron's corners, turned 30° about y, at y = 0.5: its
        // flat base up (corners at y = +0.2 above its apex at −0.3).
        (
            "convex hull",
            Collider::convex_hull(vec![
                Vec3::new(-0.3, 0.2, -0.3),
                Vec3::new(0.4, 0.2, -0.2),
                Vec3::new(0.0, 0.2, 0.4),
                Vec3::new(0.0, -0.3, 0.0),
            ])
            .unwrap(),
            GlobalTransform::from(
                Transform::from_xyz(0.0, 0.5, 0.0).with_rotation(Quat::from_rotation_y(0.5)),
            ),
            Vec3::new(0.02, 1.5, 0.01),
            Vec3::new(0.02, 0.7 + THICKNESS, 0.01),
        ),
        // The ground at y = 0.25.
        (
            "half-space",
            Collider::half_space(Vec3::Y),
            at(0.0, 0.25, 0.0),
            Vec3::new(0.3, 1.0, 0.3),
            Vec3::new(0.3, 0.25 + THICKNESS, 0.3),
        ),
    ];
    let mut hulls = HullCache::default();
    for (name, collider, transform, start, rest) in cases {
        let c = to_solver_collider(&collider, &transform, Some(&Friction::new(0.5)), &mut hulls)
            .unwrap_or_else(|| panic!("{name}"));
        assert_eq!(c.friction, 0.5);
        let x = rest_on(c.clone(), start);
        assert!(
            x.distance(rest) < 1e-4,
            "{name}: rests at {x}, expected {rest}"
        );
        assert!((c.distance(x).0 - THICKNESS).abs() < 1e-4, "{name}");
    }
    // A shape the cloth does not collide with.
    let cone = Collider::cone(0.1, 1.0);
    assert!(to_solver_collider(&cone, &at(0.0, 0.0, 0.0), None, &mut hulls).is_none());
    // A hull is made once per avian shape: the same shared hull however it is placed.
    let points = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    let shape = Collider::convex_hull(points).unwrap();
    let hull_of = |c: bevy_cloth::solver::Collider| match c.shape {
        bevy_cloth::solver::ColliderShape::Convex(bevy_cloth::solver::shapes::Convex {
            hull,
            ..
        }) => hull,
        other => panic!("{other:?}"),
    };
    let first = hull_of(to_solver_collider(&shape, &at(0.0, 0.0, 0.0), None, &mut hulls).unwrap());
    let again = hull_of(to_solver_collider(&shape, &at(1.0, 2.0, 3.0), None, &mut hulls).unwrap());
    assert!(std::sync::Arc::ptr_eq(&first, &again));
}

/// Distance from `x` to the segment `a–b`.
fn from_segment(x: Vec3, a: Vec3, b: Vec3) -> f32 {
    let t = ((x - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
    x.distance(a + (b - a) * t)
}

/// What a run of [`run_cape`] saw.
struct CapeRun {
    /// The closest any cape particle came to the body's axis, m.
    closest: f32,
    /// The cape's mean from the body and the body's centre, at frames 90 and 215.
    trail: Vec<(Vec3, Vec3)>,
    /// Frames with a cape edge through a cape triangle, and the most such edges in one.
    crossing_frames: usize,
    most_crossing: usize,
}

/// avian's physics running beside the cloth: a capsule body (radius 0.3, 1.6 m tall)
/// on a half-space ground, driven by setting its velocity; a cape attached by its top
/// edge just behind its shoulders, with self-collision on or off. It runs 1.5 s along −z
/// at 3 m/s, stops dead for 1 s (the cape swings forward into its back), then turns to
/// face +x over 0.2 s and runs that way for 0.8 s (the cape swings round its side).
fn run_cape(self_collision: bool) -> CapeRun {
    use avian3d::prelude::{LinearVelocity, LockedAxes, RigidBody, Rotation};
    use bevy::prelude::*;
    let mut app = avian_app(ClothAvianPlugin::default());
    app.world_mut().spawn((
        RigidBody::Static,
        Collider::half_space(Vec3::Y),
        Transform::default(),
    ));
    let (radius, half_length) = (RADIUS, 0.5);
    let body = app
        .world_mut()
        .spawn((
            RigidBody::Dynamic,
            Collider::capsule(radius, 2.0 * half_length),
            LockedAxes::ROTATION_LOCKED,
            Friction::new(0.0),
            Transform::from_xyz(0.0, radius + half_length, 0.0),
        ))
        .id();
    let (width, height) = (12, 14);
    let mut params = ClothParams::seeds();
    params.self_collision.enabled = self_collision;
    let cape = app
        .world_mut()
        .spawn((
            Cloth::grid(width, height, 0.05)
                .with_pins(ClothPins::None)
                .with_params(params),
            // The grid hangs from the middle of its top edge, here 2 cm behind the back.
            Transform::from_xyz(0.0, 1.25, radius + 0.02),
            ClothAttachments(vec![ClothAttachment::indices(body, (0..width).collect())]),
        ))
        .id();
    let mut run = CapeRun {
        closest: f32::MAX,
        trail: Vec::new(),
        crossing_frames: 0,
        most_crossing: 0,
    };
    for frame in 0..220 {
        let velocity = match frame {
            0..94 => Vec3::new(0.0, 0.0, -3.0),
            94..156 => Vec3::ZERO,
            _ => Vec3::new(3.0, 0.0, 0.0),
        };
        if let Some(mut v) = app.world_mut().get_mut::<LinearVelocity>(body) {
            v.0.x = velocity.x;
            v.0.z = velocity.z;
        }
        // Facing −z, then turning a quarter to face +x (locked axes keep the solver from
        // turning it; a game turns its character itself).
        let turn = ((frame as f32 - 156.0) / 12.0).clamp(0.0, 1.0);
        if let Some(mut r) = app.world_mut().get_mut::<Rotation>(body) {
            r.0 = Quat::from_rotation_y(-std::f32::consts::FRAC_PI_2 * turn);
        }
        app.update();
        let Some(sim) = app.world().get::<ClothSimulation>(cape) else {
            continue;
        };
        let centre = app.world().get::<Transform>(body).unwrap().translation;
        let up = app.world().get::<Transform>(body).unwrap().rotation * Vec3::Y;
        let (a, b) = (centre - up * half_length, centre + up * half_length);
        for &x in sim.solver.positions() {
            run.closest = run.closest.min(from_segment(x, a, b));
        }
        assert!(sim.solver.is_stable(), "frame {frame}");
        let crossing = common::edges_through_triangles(&[&sim.solver]);
        run.crossing_frames += (crossing > 0) as usize;
        run.most_crossing = run.most_crossing.max(crossing);
        if frame == 90 || frame == 215 {
            let mean = sim.solver.positions().iter().sum::<Vec3>() / (width * height) as f32;
            run.trail.push((mean - centre, centre));
        }
    }
    run
}

/// The cape's body's radius, m.
const RADIUS: f32 = 0.3;

#[test]
fn a_cape_on_a_running_avian_capsule_trails_behind_and_never_goes_through_it() {
    // Every step every cape particle stays outside the body, and while running the cape
    // trails behind it.
    let run = run_cape(false);
    let (closest, trail) = (run.closest, &run.trail);
    eprintln!("closest particle to the body's axis: {closest} m (radius {RADIUS}); {trail:?}");
    assert!(
        closest > RADIUS,
        "a particle went {} m into the body",
        RADIUS - closest
    );
    // Running along −z, the cape's middle is behind (+z) the body; along +x, behind (−x).
    let ((along_z, at_z), (along_x, at_x)) = (trail[0], trail[1]);
    assert!(
        at_z.z < -3.0 && at_x.x > 1.5,
        "the body ran: {at_z}, {at_x}"
    );
    assert!(
        along_z.z > RADIUS + 0.1,
        "running along −z: the cape at {along_z}"
    );
    assert!(
        along_x.x < -(RADIUS + 0.1),
        "running along +x: the cape at {along_x}"
    );
}

/// The same run with self-collision on (as the cape example has it): no cape edge ever
/// passes through a cape triangle (the exact test of `tests/self_collision.rs`), and the
/// cape still stays out of the body; with it off the cape does pass through itself.
#[test]
fn a_cape_with_self_collision_never_passes_through_itself() {
    let on = run_cape(true);
    let off = run_cape(false);
    eprintln!(
        "crossing frames, most edges: on {} {}, off {} {}; closest on {}",
        on.crossing_frames, on.most_crossing, off.crossing_frames, off.most_crossing, on.closest
    );
    assert!(
        off.crossing_frames > 0,
        "without self-collision it should cross"
    );
    assert_eq!(on.crossing_frames, 0, "an edge through a triangle");
    assert!(on.closest > RADIUS, "a particle went into the body");
}

#[test]
fn a_ball_dropped_on_a_hammock_is_held_by_the_cloths_push_back() {
    hammock_holds_a_ball(false);
}

/// The same ball, its collider a child entity of its body (avian attaches it to the
/// body): the push goes to the body.
#[test]
fn a_child_colliders_push_reaches_its_body() {
    hammock_holds_a_ball(true);
}

fn hammock_holds_a_ball(child_collider: bool) {
    use avian3d::prelude::{Mass, RigidBody};
    use bevy::prelude::*;
    // A 60 g avian ball (radius 0.1) dropped from 0.3 m onto a 0.75 m square cloth
    // pinned by its four corners at y = 1. The cloth gives the ball the reaction to its
    // particles' contacts, so the ball comes to rest in the cloth; in the last half
    // second the cloth's mean impulse on it is its weight's, m g dt per step. (Without
    // the reaction it would push the particles aside and fall through.) The hammock has
    // air drag (0.02 N·s/m a particle): with the default 0.0005 the ball keeps bouncing
    // (y 0.82–1.0 for the 19 s measured; not from the reaction arriving after the step:
    // applied within it, substep by substep, the ball bounced the same).
    let mut app = avian_app(ClothAvianPlugin::default());
    let n = 16;
    let cloth = app
        .world_mut()
        .spawn((
            Cloth::grid(n, n, 0.05)
                .with_pins(ClothPins::Indices(vec![0, n - 1, n * (n - 1), n * n - 1]))
                .with_params(ClothParams {
                    drag: 0.02,
                    ..ClothParams::seeds()
                }),
            Transform::from_xyz(0.0, 1.0, -0.375)
                .with_rotation(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2)),
        ))
        .id();
    let mass = 0.06;
    let ball = if child_collider {
        let ball = app
            .world_mut()
            .spawn((
                RigidBody::Dynamic,
                Mass(mass),
                Transform::from_xyz(0.0, 1.3, 0.0),
            ))
            .id();
        app.world_mut()
            .spawn((Collider::sphere(0.1), Transform::default(), ChildOf(ball)));
        ball
    } else {
        app.world_mut()
            .spawn((
                RigidBody::Dynamic,
                Collider::sphere(0.1),
                Mass(mass),
                Transform::from_xyz(0.0, 1.3, 0.0),
            ))
            .id()
    };
    let dt = 0.016;
    let mut support = Vec::new();
    let frames = 250;
    let mut heights = Vec::new();
    for frame in 0..frames {
        app.update();
        if frame + 31 >= frames {
            let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
            support.push(sim.solver.collider_impulses()[0].linear);
            heights.push(app.world().get::<Transform>(ball).unwrap().translation.y);
        }
    }
    let y = heights[heights.len() - 1];
    let span = heights.iter().fold(0.0f32, |m, h| m.max((h - y).abs()));
    let mean = support.iter().sum::<Vec3>() / support.len() as f32;
    let weight = mass * 9.81 * dt;
    eprintln!(
        "ball at y = {y} (moved {span} m in the last 0.5 s); mean impulse from the cloth {mean} (weight {weight})"
    );
    assert!(y > 0.55 && y < 1.0, "the ball rests in the cloth: y = {y}");
    assert!(span < 2e-3, "at rest: it moved {span} m");
    assert!(
        (mean.y - weight).abs() < 0.1 * weight && mean.x.abs() < 0.1 * weight,
        "the cloth carries its weight: {mean} against {weight}"
    );
}

#[test]
fn a_cloth_on_a_moving_avian_platform_is_carried_by_friction() {
    use avian3d::prelude::{LinearVelocity, RigidBody};
    use bevy::prelude::*;
    // A kinematic avian box (2 × 0.2 × 2 m, μ = 0.8) moving at 0.5 m/s along x with a
    // cloth lying on it: the plugin gives the avian body its motion from its transforms,
    // and friction carries the cloth (less the ~1.6 cm it slips getting up to speed).
    let mut app = avian_app(ClothAvianPlugin::default());
    let platform = app
        .world_mut()
        .spawn((
            RigidBody::Kinematic,
            Collider::cuboid(2.0, 0.2, 2.0),
            Friction::new(0.8),
            LinearVelocity(Vec3::new(0.5, 0.0, 0.0)),
            Transform::default(),
        ))
        .id();
    let cloth = app
        .world_mut()
        .spawn(common::lying_cloth(Vec3::new(0.0, 0.106, 0.0)))
        .id();
    app.update();
    app.update();
    let (start, platform_start) = (
        common::entity_centroid(&app, cloth),
        app.world().get::<Transform>(platform).unwrap().translation,
    );
    for _ in 0..60 {
        app.update();
    }
    let moved = common::entity_centroid(&app, cloth) - start;
    let carried = app.world().get::<Transform>(platform).unwrap().translation - platform_start;
    eprintln!("the cloth moved {moved}, the platform {carried}");
    assert!(carried.x > 0.45, "the platform moved {carried}");
    assert!(
        moved.x > carried.x - 0.03 && moved.x < carried.x + 1e-3,
        "the cloth moved {moved}, the platform {carried}"
    );
    assert!(moved.y.abs() < 3e-3, "stays on top: {moved}");
}

#[test]
fn sensors_disabled_colliders_and_other_layers_do_not_touch_the_cloth() {
    use avian3d::prelude::{ColliderDisabled, CollisionLayers, RigidBody, Sensor};
    use bevy::prelude::*;
    // Five small cloths dropped from 0.3 m, each over its own static box (top at y = 0):
    // an ordinary box holds its cloth, a sensor, a disabled collider and a box on another
    // layer let theirs fall through; a cloth with its own layers is held by a box on them.
    let mut app = avian_app(ClothAvianPlugin::default());
    let other = CollisionLayers::from_bits(0b10, 0b10);
    let cases: [(&str, bool); 5] = [
        ("ordinary", true),
        ("sensor", false),
        ("disabled", false),
        ("another layer", false),
        ("the cloth's own layer", true),
    ];
    let mut cloths = Vec::new();
    for (k, (name, _)) in cases.iter().enumerate() {
        let x = 3.0 * k as f32;
        let mut collider = app.world_mut().spawn((
            RigidBody::Static,
            Collider::cuboid(1.0, 0.2, 1.0),
            Transform::from_xyz(x, -0.1, 0.0),
        ));
        match *name {
            "sensor" => {
                collider.insert(Sensor);
            }
            "disabled" => {
                collider.insert(ColliderDisabled);
            }
            "another layer" | "the cloth's own layer" => {
                collider.insert(other);
            }
            _ => {}
        }
        let mut cloth = app
            .world_mut()
            .spawn(common::lying_cloth(Vec3::new(x, 0.3, 0.0)));
        if *name == "the cloth's own layer" {
            cloth.insert(other);
        }
        cloths.push(cloth.id());
    }
    for _ in 0..60 {
        app.update();
    }
    for ((name, held), cloth) in cases.iter().zip(cloths) {
        let y = common::entity_centroid(&app, cloth).y;
        eprintln!("{name}: the cloth at y = {y}");
        if *held {
            assert!(
                y > 0.0 && y < 0.02,
                "{name}: held on the box's top, y = {y}"
            );
        } else {
            assert!(y < -1.0, "{name}: fell through, y = {y}");
        }
    }
}

#[test]
fn the_cloth_falls_under_avians_gravity_unless_told_not_to() {
    use avian3d::prelude::Gravity;
    use bevy::prelude::*;
    for follow in [true, false] {
        let mut app = avian_app(ClothAvianPlugin {
            follow_gravity: follow,
        });
        app.insert_resource(Gravity(Vec3::new(0.0, -1.62, 0.0)));
        // (The first update's clock has not advanced: no fixed step runs in it.)
        app.update();
        app.update();
        let gravity = app.world().resource::<ClothEnvironment>().gravity;
        let expected = if follow {
            Vec3::new(0.0, -1.62, 0.0)
        } else {
            Environment::default().gravity
        };
        assert_eq!(gravity, expected, "follow_gravity: {follow}");
    }
}

/// A cape's collar drawn with its body: a kinematic body moving at 3.5 m/s with avian's
/// `TransformInterpolation`, a cloth attached to it by its top row, frames of 10 ms
/// against fixed steps of 16 ms (so the time left over changes every frame). The collar's
/// drawn vertices are compared with where the drawn body puts their attachment points:
/// with `ClothInterpolation` the gap is the largest over 60 frames, and without it.
fn collar_gap(interpolate: bool) -> f32 {
    use avian3d::prelude::{LinearVelocity, RigidBody, TransformInterpolation};
    use bevy::mesh::{Mesh3d, VertexAttributeValues};
    use bevy::prelude::*;
    use bevy::time::TimeUpdateStrategy;
    let mut app = avian_app(ClothAvianPlugin::default());
    app.insert_resource(ClothInterpolation(interpolate));
    let body = app
        .world_mut()
        .spawn((
            RigidBody::Kinematic,
            LinearVelocity(Vec3::new(3.5, 0.0, 0.0)),
            TransformInterpolation,
            Transform::from_xyz(0.0, 1.5, 0.0),
        ))
        .id();
    let width = 8;
    let cloth = app
        .world_mut()
        .spawn((
            Cloth::grid(width, 8, 0.05).with_pins(ClothPins::None),
            Transform::from_xyz(0.0, 1.5, 0.1),
            ClothAttachments(vec![ClothAttachment::indices(body, (0..width).collect())]),
        ))
        .id();
    for _ in 0..20 {
        app.update();
    }
    app.insert_resource(TimeUpdateStrategy::ManualDuration(
        std::time::Duration::from_millis(10),
    ));
    let mut gap = 0.0f32;
    for _ in 0..60 {
        app.update();
        let world = app.world();
        let drawn_body = *world.get::<Transform>(body).unwrap();
        let held = world.get::<ClothAttachments>(cloth).unwrap().0[0]
            .held()
            .to_vec();
        let handle = &world.get::<Mesh3d>(cloth).unwrap().0;
        let mesh = world.resource::<Assets<Mesh>>().get(handle).unwrap();
        let Some(VertexAttributeValues::Float32x3(p)) = mesh.attribute(Mesh::ATTRIBUTE_POSITION)
        else {
            panic!("positions");
        };
        let place = world.get::<GlobalTransform>(cloth).unwrap();
        for (i, local) in held {
            let drawn = place.transform_point(Vec3::from(p[i as usize]));
            gap = gap.max(drawn.distance(drawn_body.transform_point(local)));
        }
    }
    gap
}

#[test]
fn an_attached_collar_is_drawn_with_its_interpolated_body() {
    let (on, off) = (collar_gap(true), collar_gap(false));
    eprintln!("collar behind the drawn body: {on} m with ClothInterpolation, {off} m without");
    assert!(
        on < 0.2 * off,
        "interpolation closes the gap: {on} against {off} m"
    );
}
