//! Shape matching (Sladović 2014 §2.3, §3.3): goals against rigid motions known exactly,
//! degenerate shapes, return to rest, the two rotation methods, the force exponent.

use bevy::math::{Affine3A, Quat, Vec3};
use bevy_cloth::params::{
    Environment, GoalUpdate, Model, RotationMethod, ShapeMatchingParams, Wind, WindField,
};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::{ClothSolver, Layout};

const DT: f32 = 0.016;
const POLAR: RotationMethod = RotationMethod::PolarDecomposition;
const QUATERNION: RotationMethod = RotationMethod::QuaternionAverage;

/// A small deterministic generator (no dependency), uniform in [0, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
    fn unit(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(self.next(), self.next(), self.next()) * 2.0 - 1.0;
            if (0.1..1.0).contains(&v.length_squared()) {
                return v.normalize();
            }
        }
    }
}

fn sm(rotation: RotationMethod) -> ShapeMatchingParams {
    ShapeMatchingParams {
        rotation,
        ..ShapeMatchingParams::default()
    }
}

/// A playing card, 6.3 × 8.8 cm, as an 8 × 11 grid, pinned nowhere.
fn card(params: ShapeMatchingParams, pins: ClothPins) -> ClothSolver {
    let cloth = ClothParams {
        model: Model::ShapeMatching(params),
        node_mass: 2e-5,
        drag: 0.0,
        ..ClothParams::seeds()
    };
    ClothShape::Grid {
        width: 8,
        height: 11,
        spacing: 0.009,
    }
    .build_solver(&pins, &cloth, Affine3A::IDENTITY)
    .unwrap()
}

const CARD_SIZE: f32 = 0.113; // the card's diagonal, m

/// Moves every particle by `motion` and returns the largest |goal − moved position|.
fn goal_error_after(cloth: &mut ClothSolver, motion: Affine3A) -> f32 {
    let moved: Vec<Vec3> = cloth
        .positions()
        .iter()
        .map(|x| motion.transform_point3(*x))
        .collect();
    cloth.particles_mut().position.copy_from_slice(&moved);
    cloth.update_goals();
    let goals = cloth.goals().unwrap();
    goals
        .iter()
        .zip(&moved)
        .map(|(g, x)| g.distance(*x))
        .fold(0.0, f32::max)
}

#[test]
fn the_rest_shape_is_a_fixed_point() {
    for rotation in [POLAR, QUATERNION] {
        for clusters in [1, 3] {
            let mut c = card(
                ShapeMatchingParams {
                    clusters,
                    ..sm(rotation)
                },
                ClothPins::None,
            );
            let error = goal_error_after(&mut c, Affine3A::IDENTITY);
            assert!(error < 1e-6, "{rotation:?}, {clusters}×{clusters}: {error}");
        }
    }
}

#[test]
fn rigidly_moved_cards_have_goals_on_their_particles() {
    let mut rng = Lcg(7);
    for trial in 0..200 {
        let axis = rng.unit();
        let angle = (179.0 * rng.next()).to_radians();
        let shift = (Vec3::new(rng.next(), rng.next(), rng.next()) - 0.5) * 4.0;
        let motion = Affine3A::from_rotation_translation(Quat::from_axis_angle(axis, angle), shift);
        for clusters in [1, 2] {
            let mut c = card(
                ShapeMatchingParams {
                    clusters,
                    ..sm(POLAR)
                },
                ClothPins::None,
            );
            let error = goal_error_after(&mut c, motion);
            assert!(
                error < 1e-4 * CARD_SIZE,
                "trial {trial}: {:.1}° about {axis}, {clusters}×{clusters}: error {error}",
                angle.to_degrees()
            );
        }
        // The quaternion average is exact when the card turns about its own normal (every
        // offset turns by the same arc); see `rotation_methods_agree_for_small_rotations`
        // for other axes.
        let about_normal = Affine3A::from_rotation_translation(Quat::from_rotation_z(angle), shift);
        let mut c = card(sm(QUATERNION), ClothPins::None);
        let error = goal_error_after(&mut c, about_normal);
        assert!(
            error < 1e-4 * CARD_SIZE,
            "quaternion average, {:.1}° about the normal: {error}",
            angle.to_degrees()
        );
    }
}

#[test]
fn degenerate_shapes_give_finite_goals() {
    for rotation in [POLAR, QUATERNION] {
        for beta in [0.0, 0.5] {
            let params = ShapeMatchingParams {
                beta,
                ..sm(rotation)
            };
            // A flat card (rank-2 A_pq), turned 180° about an in-plane axis.
            let mut flat = card(params, ClothPins::None);
            goal_error_after(&mut flat, Affine3A::from_rotation_x(std::f32::consts::PI));
            assert!(flat.goals().unwrap().iter().all(|g| g.is_finite()));
            // A straight strip of particles (rank-1 A_pq).
            let strip_params = ClothParams {
                model: Model::ShapeMatching(params),
                ..ClothParams::seeds()
            };
            let positions: Vec<Vec3> = (0..6)
                .map(|i| Vec3::new(i as f32 * 0.01, 0.0, 0.0))
                .collect();
            let springs: Vec<[u32; 2]> = (0..5).map(|i| [i, i + 1]).collect();
            let mut strip = ClothSolver::new(
                Layout::from_springs(&positions, &springs).unwrap(),
                &[],
                &strip_params,
                Affine3A::IDENTITY,
            )
            .unwrap();
            goal_error_after(&mut strip, Affine3A::from_rotation_z(2.0));
            assert!(
                strip.goals().unwrap().iter().all(|g| g.is_finite()),
                "{rotation:?}"
            );
            // A card folded onto itself: the bottom half mirrored onto the top half.
            let mut folded = card(params, ClothPins::None);
            let p = folded.particles_mut();
            for x in p.position.iter_mut() {
                if x.y < -0.045 {
                    x.y = -0.09 - x.y;
                    x.z = 1e-4;
                }
            }
            folded.update_goals();
            assert!(
                folded.goals().unwrap().iter().all(|g| g.is_finite()),
                "{rotation:?}, β {beta}"
            );
            // Every particle at one point.
            let mut collapsed = card(params, ClothPins::None);
            collapsed.particles_mut().position.fill(Vec3::ONE);
            collapsed.update_goals();
            assert!(collapsed.goals().unwrap().iter().all(|g| g.is_finite()));
        }
    }
}

/// RMS distance from the goals (the best rigid fit of the rest shape), over the card size.
fn shape_error(c: &mut ClothSolver) -> f32 {
    c.update_goals();
    let goals = c.goals().unwrap().to_vec();
    let sum: f32 = goals
        .iter()
        .zip(c.positions())
        .map(|(g, x)| g.distance_squared(*x))
        .sum();
    (sum / goals.len() as f32).sqrt() / CARD_SIZE
}

#[test]
fn a_strongly_deformed_card_returns_to_its_rest_shape() {
    let env = Environment {
        gravity_enabled: false,
        ..Environment::default()
    };
    for (rotation, update) in [
        (POLAR, GoalUpdate::Force),
        (QUATERNION, GoalUpdate::Force),
        (POLAR, GoalUpdate::Velocity),
    ] {
        let stiffness = if update == GoalUpdate::Force {
            2.0
        } else {
            0.05
        };
        let mut c = card(
            ShapeMatchingParams {
                update,
                stiffness,
                ..sm(rotation)
            },
            ClothPins::None,
        );
        // Crumple it: random offsets of up to a quarter of the card.
        let mut rng = Lcg(3);
        for x in c.particles_mut().position.iter_mut() {
            *x += (Vec3::new(rng.next(), rng.next(), rng.next()) - 0.5) * 0.05;
        }
        let p = c.particles_mut();
        p.previous.copy_from_slice(&p.position);
        let start = shape_error(&mut c);
        assert!(start > 0.05, "not deformed: {start}");
        for _ in 0..300 {
            c.step(DT, &env);
        }
        let end = shape_error(&mut c);
        assert!(
            end < 0.01,
            "{rotation:?} {update:?}: shape error {start} → {end}"
        );
        assert!(c.is_finite());
    }
}

/// Largest distance between the two methods' goals for a card turned `degrees` about a
/// tilted axis, over the card size.
fn method_gap(axis: Vec3, degrees: f32) -> f32 {
    let motion = Affine3A::from_quat(Quat::from_axis_angle(
        axis.normalize(),
        degrees.to_radians(),
    ));
    let mut polar = card(sm(POLAR), ClothPins::None);
    let mut quaternion = card(sm(QUATERNION), ClothPins::None);
    goal_error_after(&mut polar, motion);
    goal_error_after(&mut quaternion, motion);
    let (a, b) = (polar.goals().unwrap(), quaternion.goals().unwrap());
    a.iter()
        .zip(b)
        .map(|(x, y)| x.distance(*y))
        .fold(0.0, f32::max)
        / CARD_SIZE
}

/// The thesis's quaternion average takes, per particle, the arc from the rest offset to
/// the current one; offsets along the rotation axis contribute no rotation, so the average
/// under-rotates for any in-plane component of the axis (an error of first order in the
/// angle). About the card's normal every arc is the rotation itself and it is exact.
#[test]
fn rotation_methods_agree_for_small_rotations() {
    for degrees in [5.0, 15.0, 30.0] {
        let about_normal = method_gap(Vec3::Z, degrees);
        assert!(
            about_normal < 1e-4,
            "{degrees}° about the normal: {about_normal}"
        );
        let near_normal = method_gap(Vec3::new(0.0, 0.36, 1.0), degrees); // axis 20° off the normal
        assert!(
            near_normal < 0.04,
            "{degrees}° about an axis 20° off the normal: {:.1}%",
            near_normal * 100.0
        );
        // About an in-plane axis the offsets along the axis contribute no rotation, so the
        // average under-rotates by a fixed fraction: a gap proportional to the angle,
        // 16.6% of the card per radian from 5° to 30°.
        let in_plane = method_gap(Vec3::X, degrees);
        let radians = degrees.to_radians();
        assert!(
            in_plane > near_normal && (0.15..0.18).contains(&(in_plane / radians)),
            "{degrees}° about an in-plane axis: {:.1}% of the card",
            in_plane * 100.0
        );
    }
    for (name, axis) in [
        ("20° off the normal", Vec3::new(0.0, 0.36, 1.0)),
        ("70° off the normal", Vec3::new(1.0, 0.6, 0.3)),
        ("in the card's plane", Vec3::X),
    ] {
        for degrees in [30.0, 90.0, 170.0] {
            eprintln!(
                "quaternion average vs polar decomposition, {degrees}° about an axis {name}: goals differ by {:.1}% of the card",
                method_gap(axis, degrees) * 100.0
            );
        }
    }
}

/// Seconds until a particle displaced by `offset` m from its goal first halves the
/// distance, with the rest of the card pinned (so the goal stays put).
fn halving_time(exponent: f32, offset: f32) -> f32 {
    let params = ShapeMatchingParams {
        exponent,
        stiffness: 2.0,
        damping: 0.0,
        ..sm(POLAR)
    };
    let free = 5 * 8 + 4;
    let pins = ClothPins::Indices((0..88).filter(|&i| i != free).collect());
    let mut c = card(params, pins);
    let env = Environment {
        gravity_enabled: false,
        ..Environment::default()
    };
    let rest = c.positions()[free as usize];
    let p = c.particles_mut();
    p.position[free as usize] += Vec3::Z * offset;
    p.previous[free as usize] = p.position[free as usize];
    let dt = 1e-4;
    for n in 1..200_000 {
        c.step(dt, &env);
        if c.positions()[free as usize].distance(rest) < 0.5 * offset {
            return n as f32 * dt;
        }
    }
    f32::INFINITY
}

#[test]
fn larger_exponents_return_faster_from_far_and_slower_from_near() {
    // L = spacing = 9 mm: "far" is 3 L, "near" is L/5 (Sladović 2014 §4).
    let (far, near) = (0.027, 0.0018);
    let (p1_far, p2_far) = (halving_time(1.0, far), halving_time(2.0, far));
    let (p1_near, p2_near) = (halving_time(1.0, near), halving_time(2.0, near));
    assert!(p2_far < p1_far, "far: p=2 {p2_far} s, p=1 {p1_far} s");
    assert!(p2_near > p1_near, "near: p=2 {p2_near} s, p=1 {p1_near} s");
    // For p = 1 it is a harmonic oscillator: a quarter period to reach the goal, so the
    // halving time is T/6 = (2π/6)·√(m/α) whatever the offset.
    let expected = std::f32::consts::TAU / 6.0 * (2e-5f32 / 2.0).sqrt();
    assert!(
        (p1_far - expected).abs() < 0.05 * expected,
        "{p1_far} vs {expected}"
    );
    assert!(
        (p1_near - expected).abs() < 0.05 * expected,
        "{p1_near} vs {expected}"
    );
}

#[test]
fn bad_shape_matching_parameters_name_their_field() {
    let field = |params: ShapeMatchingParams| match (ClothParams {
        model: Model::ShapeMatching(params),
        ..ClothParams::seeds()
    })
    .validate()
    {
        Err(ClothError::InvalidParameter { field, .. }) => field,
        other => panic!("{other:?}"),
    };
    assert_eq!(
        field(ShapeMatchingParams {
            exponent: 4.0,
            ..sm(POLAR)
        }),
        "model.exponent"
    );
    assert_eq!(
        field(ShapeMatchingParams {
            exponent: 0.2,
            ..sm(POLAR)
        }),
        "model.exponent"
    );
    assert_eq!(
        field(ShapeMatchingParams {
            stiffness: -1.0,
            ..sm(POLAR)
        }),
        "model.stiffness"
    );
    assert_eq!(
        field(ShapeMatchingParams {
            update: GoalUpdate::Velocity,
            stiffness: 1.5,
            ..sm(POLAR)
        }),
        "model.stiffness"
    );
    assert_eq!(
        field(ShapeMatchingParams {
            beta: 1.5,
            ..sm(POLAR)
        }),
        "model.beta"
    );
    assert_eq!(
        field(ShapeMatchingParams {
            clusters: 0,
            ..sm(POLAR)
        }),
        "model.clusters"
    );
}

#[test]
fn shape_matching_works_with_pins_gravity_and_wind_and_never_tears() {
    let params = ShapeMatchingParams {
        stiffness: 2.0,
        ..sm(POLAR)
    };
    let cloth = ClothParams {
        model: Model::ShapeMatching(params),
        node_mass: 2e-5,
        tear_ratio: Some(1.01),
        ..ClothParams::seeds()
    };
    let mut c = ClothShape::Grid {
        width: 8,
        height: 11,
        spacing: 0.009,
    }
    .build_solver(&ClothPins::Indices(vec![0]), &cloth, Affine3A::IDENTITY)
    .unwrap();
    let env = Environment {
        wind: Wind {
            direction: Vec3::Z,
            strength: 1e-4,
            field: WindField::Trigonometric,
        },
        ..Environment::default()
    };
    let pin = c.positions()[0];
    let centre_of =
        |c: &ClothSolver| c.positions().iter().copied().sum::<Vec3>() / c.particle_count() as f32;
    let arm = centre_of(&c).distance(pin);
    for _ in 0..500 {
        c.step(DT, &env);
    }
    assert_eq!(c.positions()[0], pin);
    assert_eq!(c.torn_count(), 0);
    assert_eq!(c.spring_count(), 0, "no spring acts in shape matching");
    assert!(shape_error(&mut c) < 0.01, "still card-shaped");
    // Then the wind drops and the damped card settles as a rigid body hung from a point
    // does: its centre of mass straight below the pin (at the start it is 57% of its
    // distance to the side). The pin holds the card only through its own goal offset,
    // which carries the whole weight (the offsets sum to zero): the goal frame, and the
    // card with it, hangs M g/α further down than its rest arm.
    let calm = Environment::default();
    for _ in 0..500 {
        c.step(DT, &calm);
    }
    let hang = centre_of(&c) - pin;
    let aside = Vec3::new(hang.x, 0.0, hang.z).length();
    assert!(
        aside < 0.02 * arm,
        "the centre is {aside} m to the side of the pin"
    );
    let weight = 88.0 * 2e-5 * 9.81;
    let expected = arm + weight / params.stiffness;
    assert!(
        (hang.length() - expected).abs() < 0.02 * expected,
        "the centre is {} m below the pin, expected {expected} m (arm {arm} + M g/α)",
        hang.length()
    );
}

#[test]
fn the_quaternion_average_does_not_depend_on_the_particle_order() {
    // The pseudocode's "normalise after each particle" weighed the last particle ½, the
    // one before ¼, …: the same cloth listed in another order got another rotation.
    use bevy_cloth::solver::shape_matching::ShapeMatching;
    let mut rng = Lcg(11);
    let rest: Vec<Vec3> = (0..40)
        .map(|i| Vec3::new((i % 8) as f32 * 0.01, (i / 8) as f32 * 0.01, 0.0))
        .collect();
    let motion = Affine3A::from_rotation_translation(
        Quat::from_axis_angle(Vec3::new(0.3, 0.2, 1.0).normalize(), 0.8),
        Vec3::new(0.1, -0.2, 0.05),
    );
    let moved: Vec<Vec3> = rest
        .iter()
        .map(|x| {
            motion.transform_point3(*x)
                + (Vec3::new(rng.next(), rng.next(), rng.next()) - 0.5) * 0.004
        })
        .collect();
    let mass = vec![1e-4; rest.len()];
    let params = sm(QUATERNION);
    let goals = |order: &[usize]| {
        let r: Vec<Vec3> = order.iter().map(|&i| rest[i]).collect();
        let x: Vec<Vec3> = order.iter().map(|&i| moved[i]).collect();
        let mut state = ShapeMatching::new(&r, &mass, None, 1);
        state.compute_goals(&x, &mass, &params);
        let mut by_particle = vec![Vec3::ZERO; rest.len()];
        for (k, &i) in order.iter().enumerate() {
            by_particle[i] = state.goals[k];
        }
        by_particle
    };
    let forward: Vec<usize> = (0..rest.len()).collect();
    let reversed: Vec<usize> = forward.iter().rev().copied().collect();
    let mut shuffled = forward.clone();
    for i in (1..shuffled.len()).rev() {
        let j = (rng.next() * (i + 1) as f32) as usize;
        shuffled.swap(i, j.min(i));
    }
    let a = goals(&forward);
    for order in [reversed, shuffled] {
        let b = goals(&order);
        let gap = a
            .iter()
            .zip(&b)
            .map(|(p, q)| p.distance(*q))
            .fold(0.0, f32::max);
        assert!(
            gap < 1e-6,
            "goals move by {gap} m when the particles are listed in another order"
        );
    }
}
