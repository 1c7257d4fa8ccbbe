//! Contact that holds: a fast cloth stops at a thin plate at any substep count, a particle
//! that starts inside a collider is not launched, a particle in a crease of two colliders
//! ends outside both whatever their order, and a ball fired through a curtain leaves no
//! particle inside it. `cargo test --test contact`.

use bevy::math::{Affine3A, Quat, Vec2, Vec3};
use bevy_cloth::params::{Environment, Model, Substeps, XpbdParams};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::{ClothSolver, Collider, ColliderShape, Layout, Motion};

const DT: f32 = 0.016;

fn collider(shape: ColliderShape) -> Collider {
    Collider {
        shape,
        thickness: 0.005,
        friction: 0.3,
        motion: Motion::NONE,
    }
}

/// A 1 cm plate, 4 × 4 m, its top face at y = 0.
fn plate() -> Collider {
    collider(ColliderShape::from(
        bevy_cloth::solver::shapes::Cuboid::new(
            Vec3::new(0.0, -0.005, 0.0),
            Quat::IDENTITY,
            Vec3::new(2.0, 0.005, 2.0),
        ),
    ))
}

/// A free 16 × 16 cloth (5 cm spacing) lying level at height `y`.
fn lying_cloth(model: Model, substeps: u32, y: f32) -> ClothSolver {
    let params = ClothParams {
        model,
        substeps: Substeps::Fixed(substeps),
        drag: 0.0,
        ..ClothParams::seeds()
    };
    let frame = Affine3A::from_rotation_translation(
        Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
        Vec3::new(0.0, y, 0.4),
    );
    Cloth::grid(16, 16, 0.05)
        .shape
        .build_solver(&ClothPins::None, &params, frame)
        .unwrap()
}

#[test]
fn a_cloth_falling_at_10_m_s_stops_on_a_1_cm_plate_at_any_substep_count() {
    // Dropped from 5.1 m it meets the plate at 10 m/s: 16 cm a step at one substep, eight
    // times the plate's thickness. Every particle must end on top.
    for (name, model) in [
        ("xpbd", Model::Xpbd(XpbdParams::default())),
        ("mass-spring", Model::MassSpring),
    ] {
        for substeps in [1, 2, 5] {
            let mut cloth = lying_cloth(model, substeps, 5.1);
            cloth.set_colliders([plate()]);
            let mut fastest = 0.0f32;
            for _ in 0..(1.5 / DT) as usize {
                fastest = fastest.max(cloth.max_speed());
                cloth.step(DT, &Environment::default());
            }
            let lowest = cloth
                .positions()
                .iter()
                .map(|x| x.y)
                .fold(f32::INFINITY, f32::min);
            eprintln!(
                "{name}, {substeps} substeps: met the plate at {fastest} m/s; lowest particle y = {lowest}"
            );
            assert!(fastest > 9.5, "{name}: it fell at {fastest} m/s");
            assert!(
                lowest > 0.0,
                "{name}, {substeps} substeps: a particle ended at y = {lowest}, under the plate"
            );
        }
    }
}

/// One free particle at `x`, no springs, no drag, gravity off.
fn particle(at: Vec3, substeps: u32) -> ClothSolver {
    let params = ClothParams {
        substeps: Substeps::Fixed(substeps),
        drag: 0.0,
        ..ClothParams::seeds()
    };
    ClothSolver::new(
        Layout::from_springs(&[at], &[]).unwrap(),
        &[],
        &params,
        Affine3A::IDENTITY,
    )
    .unwrap()
}

fn weightless() -> Environment {
    Environment {
        gravity_enabled: false,
        ..Environment::default()
    }
}

#[test]
fn a_particle_spawned_inside_a_sphere_is_moved_out_without_being_launched() {
    // 5 cm inside a ball of radius 0.2 (5.5 cm under the band it is kept at). Pushed out
    // by the whole depth in one substep, its velocity used to be depth / h: 3.4 m/s here.
    // Now it comes out at the cap (1 m/s: 1.6 cm a step) with no velocity left behind.
    for substeps in [1, 4] {
        let mut p = particle(Vec3::new(0.0, 0.15, 0.0), substeps);
        p.set_colliders([collider(ColliderShape::Sphere(
            bevy_cloth::solver::shapes::Sphere {
                center: Vec3::ZERO,
                radius: 0.2,
            },
        ))]);
        let mut out_at = None;
        for step in 1..=10 {
            let before = p.positions()[0];
            p.step(DT, &weightless());
            let x = p.positions()[0];
            let speed = p.particles().velocity[0].length();
            let moved = x.distance(before) / DT;
            eprintln!(
                "{substeps} substeps, step {step}: at {x}, {speed} m/s, moved at {moved} m/s"
            );
            assert!(speed <= 1e-3, "left with a velocity of {speed} m/s");
            assert!(moved <= 1.0 + 1e-3, "moved out at {moved} m/s");
            if out_at.is_none() && x.length() >= 0.205 - 1e-5 {
                out_at = Some(step);
            }
        }
        assert_eq!(out_at, Some(4), "out after ⌈5.5 cm / 1.6 cm⌉ steps");
    }
}

#[test]
fn a_particle_in_a_crease_of_two_capsules_ends_outside_both_in_either_order() {
    // Two capsules (radius 0.1) crossing in a V; a particle dropped into the crease where
    // they meet, from each of a few starting points.
    let a = collider(ColliderShape::Capsule(
        bevy_cloth::solver::shapes::Capsule {
            a: Vec3::new(-0.5, 0.3, 0.0),
            b: Vec3::new(0.05, 0.0, 0.0),
            radius: 0.1,
        },
    ));
    let b = collider(ColliderShape::Capsule(
        bevy_cloth::solver::shapes::Capsule {
            a: Vec3::new(0.5, 0.3, 0.0),
            b: Vec3::new(-0.05, 0.0, 0.0),
            radius: 0.1,
        },
    ));
    for start in [
        Vec3::new(0.0, 0.5, 0.0),
        Vec3::new(0.02, 0.4, 0.01),
        Vec3::new(-0.03, 0.6, -0.02),
    ] {
        let run = |colliders: [Collider; 2]| {
            let mut p = particle(start, 8);
            p.set_colliders(colliders);
            for _ in 0..60 {
                p.step(DT, &Environment::default());
            }
            p.positions()[0]
        };
        let forward = run([a.clone(), b.clone()]);
        let reverse = run([b.clone(), a.clone()]);
        for (name, c) in [("a", &a), ("b", &b)] {
            for x in [forward, reverse] {
                let (d, _) = c.distance(x);
                assert!(
                    d > 0.005 - 1e-4,
                    "{start}: inside {name} by {} at {x}",
                    0.005 - d
                );
            }
        }
        assert!(
            forward.distance(reverse) <= 1e-6,
            "{start}: {forward} one way, {reverse} the other"
        );
        eprintln!("from {start}: rests at {forward}");
    }
}

#[test]
fn a_ball_fired_through_a_curtain_at_20_m_s_leaves_no_particle_inside_it() {
    // A curtain (24 × 24, 5 cm spacing) hung by its top row in the z = 0 plane; a ball of
    // radius 0.2 fired along z at 20 m/s through its middle: 32 cm a step, at one substep.
    let params = ClothParams {
        model: Model::Xpbd(XpbdParams::default()),
        substeps: Substeps::Fixed(1),
        ..ClothParams::seeds()
    };
    let mut cloth = Cloth::grid(24, 24, 0.05)
        .shape
        .build_solver(
            &ClothPins::TopRow,
            &params,
            Affine3A::from_translation(Vec3::new(0.0, 1.2, 0.0)),
        )
        .unwrap();
    let radius = 0.2;
    let speed = 20.0;
    let mut centre = Vec3::new(0.0, 0.6, -1.0);
    let start = cloth.positions().to_vec();
    let lo = start.iter().fold(Vec3::INFINITY, |a, b| a.min(*b));
    let hi = start.iter().fold(Vec3::NEG_INFINITY, |a, b| a.max(*b));
    eprintln!("curtain from {lo} to {hi}");
    // The farthest any particle went along the ball's path.
    let mut pushed = 0.0f32;
    for _ in 0..20 {
        let next = centre + Vec3::Z * speed * DT;
        let mut ball = collider(ColliderShape::Sphere(bevy_cloth::solver::shapes::Sphere {
            center: next,
            radius,
        }));
        ball.motion = Motion::between((Quat::IDENTITY, centre), (Quat::IDENTITY, next), DT);
        cloth.set_colliders([ball]);
        cloth.step(DT, &Environment::default());
        centre = next;
        let furthest = cloth.positions().iter().zip(&start).map(|(x, s)| x.z - s.z);
        pushed = furthest.fold(pushed, f32::max);
        for (i, x) in cloth.positions().iter().enumerate() {
            let inside = radius - x.distance(centre);
            assert!(inside < 1e-3, "particle {i} is {inside} m inside the ball");
        }
    }
    eprintln!("the ball pushed the curtain {pushed} m along its path");
    // (Tunnelling, it passed through and left the curtain 0.15 m behind it.)
    assert!(
        pushed > 0.5,
        "the ball went through without carrying the curtain: {pushed} m"
    );
    assert!(cloth.is_stable());
}

#[test]
fn a_cloth_dropped_across_a_rope_hangs_over_it() {
    // A 2 mm rope (a capsule along z) under the middle of a 16 × 16 cloth (5 cm
    // spacing), between two columns of particles: only the cloth's edges can meet it.
    let (radius, thickness) = (0.002, 0.005);
    let rope = Collider {
        thickness,
        ..collider(ColliderShape::Capsule(
            bevy_cloth::solver::shapes::Capsule {
                a: Vec3::new(0.0, 0.0, -1.0),
                b: Vec3::new(0.0, 0.0, 1.0),
                radius,
            },
        ))
    };
    for (name, model) in [
        ("mass-spring", Model::MassSpring),
        ("xpbd", Model::Xpbd(XpbdParams::default())),
    ] {
        let params = ClothParams {
            model,
            ..ClothParams::seeds()
        };
        let frame = Affine3A::from_rotation_translation(
            Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            Vec3::new(0.0, 0.3, 0.0),
        );
        let mut cloth = Cloth::grid(16, 16, 0.05)
            .shape
            .build_solver(&ClothPins::None, &params, frame)
            .unwrap();
        let columns: Vec<f32> = cloth.positions().iter().map(|x| x.x.abs()).collect();
        let nearest = columns.iter().fold(f32::INFINITY, |m, &x| m.min(x));
        assert!(
            nearest > 0.02,
            "a particle column is over the rope: {nearest}"
        );
        cloth.set_colliders([rope.clone()]);
        for _ in 0..125 {
            cloth.step(DT, &Environment::default());
        }
        let x = cloth.positions();
        let top = x.iter().map(|x| x.y).fold(f32::NEG_INFINITY, f32::max);
        let centroid = x.iter().sum::<Vec3>() / x.len() as f32;
        eprintln!("{name}: after 2 s the top at y = {top}, the centroid at {centroid}");
        assert!(
            top > 0.0 && top < 0.02,
            "{name}: the cloth fell off the rope (top at y = {top})"
        );
        assert!(
            centroid.x.abs() < 0.05,
            "{name}: slid off sideways: {centroid}"
        );
        assert!(cloth.is_stable(), "{name}");
    }
}

/// A shape registered by one file (the torus): a level cloth dropped through a ring
/// drapes over it, every particle outside the tube, and the middle sags through the hole
/// below the ring's top.
#[test]
fn a_cloth_dropped_onto_a_ring_drapes_over_it_with_no_particle_inside() {
    let mut cloth = lying_cloth(Model::Xpbd(XpbdParams::default()), 8, 0.2);
    let start = cloth.positions().to_vec();
    let centre = start.iter().sum::<Vec3>() / start.len() as f32;
    let middle = (0..start.len())
        .min_by(|&i, &j| {
            start[i]
                .distance(centre)
                .total_cmp(&start[j].distance(centre))
        })
        .unwrap();
    let ring = bevy_cloth::solver::shapes::Torus {
        center: Vec3::new(centre.x, 0.0, centre.z),
        axis: Vec3::Y,
        major_radius: 0.25,
        minor_radius: 0.03,
    };
    cloth.set_colliders([collider(ring.into())]);
    for _ in 0..90 {
        cloth.step(DT, &Environment::default());
    }
    let tube = |x: Vec3| {
        let d = x - ring.center;
        let radial = Vec3::new(d.x, 0.0, d.z).length();
        (radial - ring.major_radius).hypot(d.y) - ring.minor_radius
    };
    let deepest = cloth
        .positions()
        .iter()
        .map(|&x| tube(x))
        .fold(f32::MAX, f32::min);
    let lowest = cloth
        .positions()
        .iter()
        .map(|x| x.y)
        .fold(f32::MAX, f32::min);
    let middle = cloth.positions()[middle];
    eprintln!("nearest the tube {deepest} m, lowest {lowest} m, middle {middle}");
    assert!(deepest > 0.0, "a particle {deepest} m inside the tube");
    // Held by the ring (not fallen through), the middle hanging inside the hole.
    assert!(lowest > -0.6, "fell through: lowest at {lowest} m");
    assert!(middle.y < 0.0, "the middle did not sag: {middle}");
}

/// A 2 mm rope along z at `x`, with the contact tests' thickness.
fn rope_at(x: f32) -> Collider {
    collider(ColliderShape::Capsule(
        bevy_cloth::solver::shapes::Capsule {
            a: Vec3::new(x, 0.0, -1.0),
            b: Vec3::new(x, 0.0, 1.0),
            radius: 0.002,
        },
    ))
}

/// The highest the top of a 16 × 16 cloth (5 cm) dropped edge-first from a top at 1 m
/// onto `below` rises after its bottom first comes within 1 cm of y = 0, above where the
/// top was then; and the top after 2 s.
fn edge_first_drop(model: Model, substeps: Substeps, below: Collider) -> (f32, f32) {
    let params = ClothParams {
        model,
        substeps,
        ..ClothParams::seeds()
    };
    // Tilted 2° out of its plane, as any real drop is: a sheet exactly upright balanced
    // on its edge has no way to fall but in its own plane, pivoting about the rope.
    let frame = Affine3A::from_rotation_translation(
        Quat::from_rotation_x(2f32.to_radians()),
        Vec3::new(0.0, 1.0, 0.0),
    );
    let mut cloth = Cloth::grid(16, 16, 0.05)
        .shape
        .build_solver(&ClothPins::None, &params, frame)
        .unwrap();
    cloth.set_colliders([below]);
    let top = |c: &ClothSolver| c.positions().iter().map(|x| x.y).fold(f32::MIN, f32::max);
    let bottom = |c: &ClothSolver| c.positions().iter().map(|x| x.y).fold(f32::MAX, f32::min);
    let (mut met, mut highest) = (None, f32::MIN);
    for _ in 0..125 {
        cloth.step(DT, &Environment::default());
        if met.is_none() && bottom(&cloth) < 0.01 {
            met = Some(top(&cloth));
        }
        if met.is_some() {
            highest = highest.max(top(&cloth));
        }
    }
    assert!(cloth.is_stable());
    (highest - met.expect("the cloth reached y = 0"), top(&cloth))
}

#[test]
fn a_cloth_falling_edge_first_onto_a_thin_rope_hangs_on_it_and_the_rope_adds_no_bounce() {
    // Onto a 2 mm rope that pierces its plane between two columns (x = 0.0125): only
    // its row edges can meet it, edge-first, at 2.2 m/s. It must stay on the rope, and
    // rise after meeting it no more than the same sheet does landing on a plate: the
    // rope's contact adds no energy. (Dropped exactly upright, a sheet rebounds 11–16 cm
    // off a plate too, its rows in compression; tilted 2°, it tips over and rises not at
    // all, on the plate or on the rope.)
    edge_first_onto_a_rope(&[(
        "xpbd",
        Model::Xpbd(XpbdParams::default()),
        Substeps::default(),
    )]);
}

#[test]
#[ignore = "target not met yet: at 1 XPBD substep each row edge across the rope pivots about \
            it and slips off its far end; the column nearest the rope piles onto it while the \
            sheet slides past (top at -8.4 m after 2 s, friction 0.3 to 3 alike); mass-spring \
            drapes, then slips off (-2.1 m)"]
fn a_cloth_falling_edge_first_onto_a_thin_rope_hangs_on_it_at_1_substep_and_on_mass_spring() {
    edge_first_onto_a_rope(&[
        (
            "xpbd, 1 substep",
            Model::Xpbd(XpbdParams::default()),
            Substeps::Fixed(1),
        ),
        ("mass-spring", Model::MassSpring, Substeps::default()),
    ]);
}

fn edge_first_onto_a_rope(cases: &[(&str, Model, Substeps)]) {
    for &(name, model, substeps) in cases {
        let (rise, end) = edge_first_drop(model, substeps, rope_at(0.0125));
        let (plate_rise, _) = edge_first_drop(model, substeps, plate());
        eprintln!(
            "{name}: rose {rise:.3} m after meeting the rope ({plate_rise:.3} on a plate), top at {end:.3} after 2 s"
        );
        // Folded over the rope its top is at the rope (measured 4.3 cm above it, XPBD);
        // one that slipped off falls metres in the 2 s.
        assert!(end > -0.05, "{name}: fell off the rope (top at {end})");
        assert!(
            rise <= plate_rise.max(0.0) + 0.01,
            "{name}: the rope made it bounce: rose {rise}, on a plate {plate_rise}"
        );
    }
}

#[test]
fn a_level_cloth_dropped_onto_a_rope_at_5_m_s_hangs_over_it() {
    // Level, centred on the rope, 1.28 m above it: it meets it at 5 m/s, 8 cm a step,
    // its row edges across the rope between two columns.
    for (name, model) in [
        ("xpbd", Model::Xpbd(XpbdParams::default())),
        ("mass-spring", Model::MassSpring),
    ] {
        let params = ClothParams {
            model,
            drag: 0.0,
            ..ClothParams::seeds()
        };
        let frame = Affine3A::from_rotation_translation(
            Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            Vec3::new(0.0, 1.28, -0.375),
        );
        let mut cloth = Cloth::grid(16, 16, 0.05)
            .shape
            .build_solver(&ClothPins::None, &params, frame)
            .unwrap();
        cloth.set_colliders([rope_at(0.0)]);
        for _ in 0..125 {
            cloth.step(DT, &Environment::default());
        }
        let top = cloth
            .positions()
            .iter()
            .map(|x| x.y)
            .fold(f32::MIN, f32::max);
        eprintln!("{name}: top at {top:.3} after 2 s");
        assert!(top > -0.05, "{name}: fell through the rope (top at {top})");
        assert!(cloth.is_stable(), "{name}");
    }
}

/// The fastest particle's speed.
fn fastest(cloth: &ClothSolver) -> f32 {
    cloth
        .particles()
        .velocity
        .iter()
        .map(|v| v.length())
        .fold(0.0, f32::max)
}

/// How a cloth started through a ball came out ([`started_through_a_ball`]).
struct OutOfBall {
    /// The step at which no particle was inside any more (if within 1 s).
    out_at: Option<usize>,
    /// The fastest particle seen until then, m/s.
    fastest: f32,
    /// How the particles that started inside had moved by then: the mean of their moves
    /// along the cloth's normal (z), against the mean of their moves in its plane.
    along_normal: f32,
    in_plane: f32,
}

const BALL_CENTER: Vec3 = Vec3::new(0.0, 0.35, 0.0);
const BALL_RADIUS: f32 = 0.2;

/// A 16 × 16 cloth (5 cm) hung by its top row at y = 1 with a frictionless ball of radius
/// 0.2 centred on its plane 0.65 m below the top: its lower rows start inside. The seeds'
/// parameters, the depenetration cap at 1 m/s.
fn hung_through_a_ball(model: Model) -> ClothSolver {
    let params = ClothParams {
        model,
        ..ClothParams::seeds()
    };
    assert_eq!(params.max_depenetration_speed, 1.0);
    let frame = Affine3A::from_translation(Vec3::new(0.0, 1.0, 0.0));
    let mut cloth = Cloth::grid(16, 16, 0.05)
        .shape
        .build_solver(&ClothPins::TopRow, &params, frame)
        .unwrap();
    let mut ball = collider(ColliderShape::Sphere(bevy_cloth::solver::shapes::Sphere {
        center: BALL_CENTER,
        radius: BALL_RADIUS,
    }));
    ball.friction = 0.0;
    cloth.set_colliders([ball]);
    cloth
}

/// [`hung_through_a_ball`], stepped until no particle is inside (or 1 s).
fn started_through_a_ball(model: Model) -> OutOfBall {
    let (center, radius) = (BALL_CENTER, BALL_RADIUS);
    let mut cloth = hung_through_a_ball(model);
    let inside = |c: &ClothSolver| {
        c.positions()
            .iter()
            .filter(|x| x.distance(center) < radius)
            .count()
    };
    let start = cloth.positions().to_vec();
    let started_inside: Vec<usize> = (0..start.len())
        .filter(|&i| start[i].distance(center) < radius)
        .collect();
    assert!(started_inside.len() > 10);
    let mut out = OutOfBall {
        out_at: None,
        fastest: 0.0,
        along_normal: 0.0,
        in_plane: 0.0,
    };
    for step in 1..=63 {
        cloth.step(DT, &Environment::default());
        assert!(cloth.is_stable());
        out.fastest = out.fastest.max(fastest(&cloth));
        if inside(&cloth) == 0 {
            out.out_at = Some(step);
            break;
        }
    }
    let n = started_inside.len() as f32;
    for &i in &started_inside {
        let moved = cloth.positions()[i] - start[i];
        out.along_normal += moved.z.abs() / n;
        out.in_plane += moved.truncate().length() / n;
    }
    out
}

fn models() -> [(&'static str, Model); 2] {
    [
        ("xpbd", Model::Xpbd(XpbdParams::default())),
        ("mass-spring", Model::MassSpring),
    ]
}

#[test]
fn a_cloth_started_through_a_ball_leaves_it_along_its_normal_within_half_a_second() {
    // Its plane through the ball's centre, the nearest-surface push opened a hole the
    // ball's size against the cloth's constraints: 591 m/s (XPBD, its automatic substeps
    // at the cap) and 16 m/s (mass-spring). Leaving along its own normal, each particle
    // inside at the cap speed, it only bends. Its neighbours, dragged out elastically,
    // overshoot that speed (about 2.5× it, measured at caps of 0.5, 1 and 2 m/s).
    for (name, model) in models() {
        let out = started_through_a_ball(model);
        let (out_at, fastest_seen) = (out.out_at, out.fastest);
        eprintln!(
            "{name}: out of the ball after {out_at:?} steps, fastest particle \
             {fastest_seen:.2} m/s; those inside moved {:.3} m along the normal, {:.3} m in \
             the plane",
            out.along_normal, out.in_plane
        );
        let out_at = out_at.expect("still inside after 1 s");
        assert!(
            out_at as f32 * DT <= 0.5,
            "{name}: still inside after {out_at} steps"
        );
        assert!(
            fastest_seen <= 3.0,
            "{name}: launched at {fastest_seen} m/s"
        );
        // Along its normal: the particles that started inside moved out of the cloth's
        // plane (measured 0.17 m) more than twice as far as within it (0.045–0.048 m); a
        // push to the ball's nearest surface moves them within the plane, opening a hole.
        assert!(
            out.along_normal > 2.0 * out.in_plane,
            "{name}: moved {} m along the normal, {} m in the plane",
            out.along_normal,
            out.in_plane
        );
    }
}

#[test]
fn a_cloth_started_through_a_ball_is_moved_out_no_faster_than_the_cap() {
    // The particles pushed out move at the cap; the cloth around them is carried along
    // without taking speed from the push (measured 0.73 m/s XPBD, 0.82 mass-spring).
    // Without the carry the neighbours overshot (2.3 m/s XPBD, 2.7 mass-spring), pulled
    // in and out every substep by springs tied to particles still inside. Hung without
    // the ball, the cloth moves at most 0.39 m/s in these steps.
    for (name, model) in models() {
        let mut cloth = hung_through_a_ball(model);
        let mut fastest_seen = 0.0f32;
        for _ in 0..30 {
            cloth.step(DT, &Environment::default());
            fastest_seen = fastest_seen.max(fastest(&cloth));
        }
        eprintln!("{name}: fastest particle over the first 30 steps {fastest_seen:.3} m/s");
        assert!(
            fastest_seen <= 1.0 + 1e-4,
            "{name}: launched at {fastest_seen} m/s"
        );
    }
}

#[test]
fn a_cape_spawned_5_cm_into_its_capsule_is_out_within_10_steps() {
    // A cape's cloth spawned in a plane 5 cm inside a body's capsule (radius 0.3), free
    // and weightless (what moves it is the contact alone): moved out at no more than the
    // cap, out within 10 steps.
    let params = ClothParams {
        model: Model::Xpbd(XpbdParams::default()),
        ..ClothParams::seeds()
    };
    let (width, spacing) = (14, 0.045);
    // The grid hangs in a plane 0.25 m behind the axis: 5 cm inside the back.
    let frame = Affine3A::from_translation(Vec3::new(0.0, 1.4, 0.25));
    let mut cloth = Cloth::grid(width, 17, spacing)
        .shape
        .build_solver(&ClothPins::None, &params, frame)
        .unwrap();
    let body = collider(ColliderShape::Capsule(
        bevy_cloth::solver::shapes::Capsule {
            a: Vec3::new(0.0, 0.3, 0.0),
            b: Vec3::new(0.0, 1.7, 0.0),
            radius: 0.3,
        },
    ));
    cloth.set_colliders([body]);
    let inside = |c: &ClothSolver| {
        c.positions()
            .iter()
            .filter(|x| Vec2::new(x.x, x.z).length() < 0.3 && (0.3..=1.7).contains(&x.y))
            .count()
    };
    assert!(inside(&cloth) > 100);
    let mut fastest_seen = 0.0f32;
    for step in 1..=10 {
        cloth.step(DT, &weightless());
        fastest_seen = fastest_seen.max(fastest(&cloth));
        eprintln!(
            "step {step}: {} inside, fastest {:.2} m/s",
            inside(&cloth),
            fastest(&cloth)
        );
    }
    assert_eq!(inside(&cloth), 0, "still inside after 10 steps");
    // The bound is the cap (1 m/s), what the depenetration promises; measured 0.32 m/s,
    // out after 4 steps.
    assert!(fastest_seen <= 1.0, "launched at {fastest_seen} m/s");
}
