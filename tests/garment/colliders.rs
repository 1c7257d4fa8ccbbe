//! Particles on colliders: resting on each shape, friction on a slope, moving and
//! turning bodies carrying them, the reaction on the ground, convex hulls.

use super::*;

/// One free particle (no springs) at `start`, resting on `collider` after `seconds`.
fn drop_particle(start: Vec3, collider: Collider, seconds: f32) -> ClothSolver {
    let params = ClothParams {
        drag: 0.0,
        ..ClothParams::seeds()
    };
    let mut cloth = ClothSolver::new(
        Layout::from_springs(&[start], &[]).unwrap(),
        &[],
        &params,
        Affine3A::IDENTITY,
    )
    .unwrap();
    cloth.set_colliders([collider]);
    let env = Environment::default();
    for _ in 0..(seconds / 0.016) as usize {
        cloth.step(0.016, &env);
    }
    cloth
}

#[test]
fn a_dropped_particle_comes_to_rest_on_a_sphere_a_capsule_a_box_and_a_plane() {
    let thickness = 0.01;
    let collider = |shape| Collider {
        shape,
        thickness,
        friction: 0.5,
        motion: bevy_cloth::solver::Motion::NONE,
    };
    let cases = [
        (
            "sphere",
            collider(ColliderShape::Sphere(bevy_cloth::solver::shapes::Sphere {
                center: Vec3::new(0.2, 1.0, -0.1),
                radius: 0.3,
            })),
            Vec3::new(0.2, 2.0, -0.1),
            Vec3::new(0.2, 1.3 + thickness, -0.1),
        ),
        (
            "capsule",
            collider(ColliderShape::Capsule(
                bevy_cloth::solver::shapes::Capsule {
                    a: Vec3::new(-0.5, 0.5, 0.0),
                    b: Vec3::new(0.5, 0.5, 0.0),
                    radius: 0.1,
                },
            )),
            Vec3::new(0.1, 1.5, 0.0),
            Vec3::new(0.1, 0.6 + thickness, 0.0),
        ),
        (
            "capsule end cap",
            collider(ColliderShape::Capsule(
                bevy_cloth::solver::shapes::Capsule {
                    a: Vec3::new(0.0, 0.0, 0.0),
                    b: Vec3::new(0.0, 0.5, 0.0),
                    radius: 0.1,
                },
            )),
            Vec3::new(0.0, 1.5, 0.0),
            Vec3::new(0.0, 0.6 + thickness, 0.0),
        ),
        (
            // An axis-aligned box: the particle rests on its top face.
            "box, top face",
            collider(ColliderShape::Cuboid(bevy_cloth::solver::shapes::Cuboid {
                center: Vec3::new(0.0, 0.5, 0.0),
                axes: [Vec3::X, Vec3::Y, Vec3::Z],
                half_extents: Vec3::new(0.3, 0.2, 0.1),
            })),
            Vec3::new(0.1, 1.5, 0.05),
            Vec3::new(0.1, 0.7 + thickness, 0.05),
        ),
        (
            "plane",
            collider(ColliderShape::Plane(bevy_cloth::solver::shapes::Plane {
                point: Vec3::new(0.0, 0.25, 0.0),
                normal: Vec3::Y,
            })),
            Vec3::new(0.3, 1.0, 0.3),
            Vec3::new(0.3, 0.25 + thickness, 0.3),
        ),
    ];
    for (name, c, start, rest) in cases {
        let cloth = drop_particle(start, c.clone(), 2.0);
        let x = cloth.positions()[0];
        assert!(
            x.distance(rest) < 1e-4,
            "{name}: rests at {x}, expected {rest}"
        );
        assert!(
            cloth.particles().velocity[0].length() < 1e-3,
            "{name} still moves"
        );
        // The analytic signed distance is the thickness.
        assert!((c.distance(x).0 - thickness).abs() < 1e-4, "{name}");
    }
}

#[test]
fn a_particle_rests_on_a_turned_box_at_the_thickness_from_its_top_face() {
    // A box turned 20° about z (tan 20° = 0.36 < μ = 0.5: the particle sticks where it
    // lands). The box's own signed distance is the analytic answer: the thickness, on the
    // face whose normal is the box's turned +y.
    let turn = bevy::math::Quat::from_rotation_z(20f32.to_radians());
    let axes = [turn * Vec3::X, turn * Vec3::Y, turn * Vec3::Z];
    let c = Collider {
        shape: ColliderShape::Cuboid(bevy_cloth::solver::shapes::Cuboid {
            center: Vec3::new(0.0, 0.5, 0.0),
            axes,
            half_extents: Vec3::new(0.4, 0.1, 0.2),
        }),
        thickness: 0.01,
        friction: 0.5,
        motion: bevy_cloth::solver::Motion::NONE,
    };
    let cloth = drop_particle(Vec3::new(0.05, 1.2, 0.0), c.clone(), 2.0);
    let x = cloth.positions()[0];
    let (d, n) = c.distance(x);
    assert!((d - 0.01).abs() < 1e-4, "rests {d} m from the surface");
    assert!(n.distance(axes[1]) < 1e-5, "on the top face: normal {n}");
    assert!(cloth.particles().velocity[0].length() < 1e-3, "still moves");
    // Inside, the nearest face: 0.02 m under the top face, 0.08 m above the bottom one.
    let inside = Vec3::new(0.0, 0.5, 0.0) + axes[1] * 0.08;
    let (d, n) = c.distance(inside);
    assert!(
        (d + 0.02).abs() < 1e-6 && n.distance(axes[1]) < 1e-6,
        "{d} {n}"
    );
    // Off a corner: the distance to the corner point.
    let corner = Vec3::new(0.0, 0.5, 0.0) + axes[0] * 0.4 + axes[1] * 0.1 + axes[2] * 0.2;
    let out = corner + (axes[0] + axes[1] + axes[2]).normalize() * 0.3;
    assert!((c.distance(out).0 - 0.3).abs() < 1e-5);
}

#[test]
fn friction_holds_on_a_slope_below_its_angle_and_lets_go_above() {
    // Coulomb: a particle sticks while tan θ ≤ μ. Slope 20° (tan = 0.364).
    let theta = 20f32.to_radians();
    let normal = Vec3::new(-theta.sin(), theta.cos(), 0.0);
    let plane = |friction| Collider {
        shape: ColliderShape::Plane(bevy_cloth::solver::shapes::Plane {
            point: Vec3::ZERO,
            normal,
        }),
        thickness: 0.0,
        friction,
        motion: bevy_cloth::solver::Motion::NONE,
    };
    // Start on the surface at rest.
    let start = Vec3::ZERO;
    let stuck = drop_particle(start, plane(0.4), 1.0);
    assert!(
        stuck.positions()[0].length() < 1e-4,
        "μ = 0.4 slid to {}",
        stuck.positions()[0]
    );
    let sliding = drop_particle(start, plane(0.3), 1.0);
    // Kinetic friction: acceleration g (sin θ − μ cos θ) down the slope.
    let a = 9.81 * (theta.sin() - 0.3 * theta.cos());
    let expected = 0.5 * a * 1.0f32.powi(2);
    let travelled = sliding.positions()[0].length();
    assert!(
        (travelled - expected).abs() < 0.05 * expected,
        "slid {travelled} m, expected {expected} m"
    );
    let ice = drop_particle(start, plane(0.0), 1.0);
    let expected = 0.5 * 9.81 * theta.sin();
    assert!((ice.positions()[0].length() - expected).abs() < 0.05 * expected);
}

/// [`common::lying_cloth`] as a solver.
fn flat_cloth(centre: Vec3) -> ClothSolver {
    let (cloth, place) = common::lying_cloth(centre);
    let cloth = cloth.build(place.compute_affine()).expect("builds");
    let mean = common::centroid(&cloth);
    let y = cloth.positions().iter().map(|x| (x.y - mean.y).abs());
    assert!(y.fold(0.0, f32::max) < 1e-5, "lies flat");
    cloth
}

#[test]
fn friction_against_a_moving_box_carries_the_cloth_along() {
    // A 2 × 0.2 × 2 m box (top at y = 0.1) slides along x at 0.5 m/s under a cloth
    // lying on it, μ = 0.8. With the box's motion the cloth is carried: after 1 s it has
    // moved with the box, less the few cm it slipped while friction (μg = 7.8 m/s²) took
    // it to the box's speed (v²/2μg = 1.6 cm). Without it, friction holds the cloth to
    // the world and the box slides away under it.
    let (dt, steps, speed) = (0.016, 62, 0.5);
    let box_at = |t: f32, motion| Collider {
        shape: ColliderShape::Cuboid(bevy_cloth::solver::shapes::Cuboid {
            center: Vec3::new(speed * t, 0.0, 0.0),
            axes: [Vec3::X, Vec3::Y, Vec3::Z],
            half_extents: Vec3::new(1.0, 0.1, 1.0),
        }),
        thickness: 0.005,
        friction: 0.8,
        motion,
    };
    let env = Environment::default();
    let run = |moving: bool| {
        let mut cloth = flat_cloth(Vec3::new(0.0, 0.106, 0.0));
        let start = common::centroid(&cloth);
        for k in 1..=steps {
            let t = k as f32 * dt;
            let motion = if moving {
                bevy_cloth::solver::Motion {
                    linear: Vec3::X * speed,
                    angular: Vec3::ZERO,
                    pivot: Vec3::new(speed * t, 0.0, 0.0),
                }
            } else {
                bevy_cloth::solver::Motion::NONE
            };
            cloth.set_colliders([box_at(t, motion)]);
            cloth.step(dt, &env);
        }
        let v = cloth.particles().velocity.iter().sum::<Vec3>() / 36.0;
        (common::centroid(&cloth) - start, v)
    };
    let travelled = speed * steps as f32 * dt;
    let (carried, velocity) = run(true);
    eprintln!("carried {carried} at {velocity} (the box {travelled} m)");
    assert!(
        (carried.x - travelled).abs() < 0.03 && carried.x < travelled,
        "carried {carried}, the box moved {travelled}"
    );
    assert!((velocity.x - speed).abs() < 0.01, "moves at {velocity}");
    assert!(carried.y.abs() < 2e-3, "stays on the top: {carried}");
    let (held, _) = run(false);
    eprintln!("without the box's motion: {held}");
    assert!(held.x.abs() < 0.01, "without the motion it stays: {held}");
}

#[test]
fn a_moving_ball_pushes_a_particle_at_its_own_speed() {
    // No gravity: a ball of radius 0.2 at 2 m/s along x meets a particle at rest 0.5 m
    // ahead. Swept through each step, it pushes the particle to its front and on at its
    // own speed; placed only where each step ends, it would throw it ahead at the 16 ms
    // step's jump over one of the 8 substeps (12.5 m/s, measured).
    let speed = 2.0;
    let mut cloth = drop_particle(Vec3::new(0.5, 0.0, 0.0), plane_far(), 0.0);
    cloth
        .set_params(&ClothParams {
            substeps: bevy_cloth::params::Substeps::Fixed(8),
            ..*cloth.params()
        })
        .unwrap();

    let env = Environment {
        gravity_enabled: false,
        ..Environment::default()
    };
    let (dt, steps) = (0.016, 40);
    for k in 1..=steps {
        let centre = Vec3::X * speed * k as f32 * dt;
        cloth.set_colliders([Collider {
            shape: ColliderShape::Sphere(bevy_cloth::solver::shapes::Sphere {
                center: centre,
                radius: 0.2,
            }),
            thickness: 0.005,
            friction: 0.3,
            motion: bevy_cloth::solver::Motion {
                linear: Vec3::X * speed,
                angular: Vec3::ZERO,
                pivot: centre,
            },
        }]);
        cloth.step(dt, &env);
    }
    let ball = speed * steps as f32 * dt;
    let (x, v) = (cloth.positions()[0], cloth.particles().velocity[0]);
    eprintln!("particle at {x}, {v}; the ball's front at {}", ball + 0.205);
    assert!((x.x - (ball + 0.205)).abs() < 2e-3, "at {x}");
    assert!((v.x - speed).abs() < 0.02 * speed, "moves at {v}");
}

/// A plane far below, for a particle that should meet nothing else.
fn plane_far() -> Collider {
    Collider {
        shape: ColliderShape::Plane(bevy_cloth::solver::shapes::Plane {
            point: Vec3::new(0.0, -100.0, 0.0),
            normal: Vec3::Y,
        }),
        thickness: 0.0,
        friction: 0.0,
        motion: bevy_cloth::solver::Motion::NONE,
    }
}

#[test]
fn a_turntable_carries_a_particle_round_and_a_cylinder_is_exact() {
    // A flat cylinder (radius 0.5, 0.1 high, top at y = 0.05) turning about y at 1 rad/s,
    // μ = 1: a particle put on it 0.3 m from the axis goes round with it, at that radius.
    let omega = 1.0;
    // (A cylinder about its own axis is the same at every angle: only its motion turns.)
    let table = || Collider {
        shape: ColliderShape::Cylinder(bevy_cloth::solver::shapes::Cylinder {
            center: Vec3::ZERO,
            axis: Vec3::Y,
            half_height: 0.05,
            radius: 0.5,
        }),
        thickness: 0.005,
        friction: 1.0,
        motion: bevy_cloth::solver::Motion {
            linear: Vec3::ZERO,
            angular: Vec3::Y * omega,
            pivot: Vec3::ZERO,
        },
    };
    let mut cloth = drop_particle(Vec3::new(0.3, 0.055, 0.0), table(), 0.0);
    let (dt, steps) = (0.016, 100);
    for _ in 0..steps {
        cloth.set_colliders([table()]);
        cloth.step(dt, &Environment::default());
    }
    let x = cloth.positions()[0];
    let turned = steps as f32 * dt * omega;
    let angle = (-x.z).atan2(x.x);
    let radius = Vec3::new(x.x, 0.0, x.z).length();
    eprintln!(
        "turned {angle} rad (the table {turned}), radius {radius}, height {}",
        x.y
    );
    assert!(
        (angle - turned).abs() < 0.02,
        "turned {angle}, the table {turned}"
    );
    assert!((radius - 0.3).abs() < 5e-3, "radius {radius}");
    assert!((x.y - 0.055).abs() < 1e-4, "height {}", x.y);

    // Distances: inside nearest the side and the top, beyond the side, the top and the rim.
    let c = table();
    let d = |x: Vec3| c.distance(x);
    let close =
        |a: (f32, Vec3), b: (f32, Vec3)| (a.0 - b.0).abs() < 1e-6 && a.1.distance(b.1) < 1e-6;
    assert!(close(d(Vec3::new(0.47, 0.0, 0.0)), (-0.03, Vec3::X)));
    assert!(close(d(Vec3::new(0.1, 0.04, 0.0)), (-0.01, Vec3::Y)));
    assert!(close(d(Vec3::new(0.0, 0.0, -0.8)), (0.3, Vec3::NEG_Z)));
    assert!(close(d(Vec3::new(0.2, -0.25, 0.0)), (0.2, Vec3::NEG_Y)));
    let rim = d(Vec3::new(0.8, 0.45, 0.0));
    assert!(close(rim, (0.5, Vec3::new(0.6, 0.8, 0.0))), "{rim:?}");
}

#[test]
fn a_resting_particle_gives_the_ground_its_weight_as_impulse() {
    // A particle resting on a plane at x = (1, y, 0.5): over each step the plane takes its
    // weight's impulse, m g dt downwards, and its moment about the origin, x × (−m g dt ŷ).
    let start = Vec3::new(1.0, 0.02, 0.5);
    let ground = Collider {
        shape: ColliderShape::Plane(bevy_cloth::solver::shapes::Plane {
            point: Vec3::ZERO,
            normal: Vec3::Y,
        }),
        thickness: 0.005,
        friction: 0.5,
        motion: bevy_cloth::solver::Motion::NONE,
    };
    let mut cloth = drop_particle(start, ground, 2.0);
    let m = cloth.params().node_mass;
    cloth.step(0.016, &Environment::default());
    let got = cloth.collider_impulses()[0];
    let weight = Vec3::new(0.0, -m * 9.81 * 0.016, 0.0);
    let x = cloth.positions()[0];
    eprintln!("impulse {got:?}, weight {weight}");
    assert!(
        got.linear.distance(weight) < 1e-3 * weight.length(),
        "{got:?}"
    );
    assert!(
        got.angular.distance(x.cross(weight)) < 1e-3 * weight.length(),
        "{got:?}"
    );
}

/// A box's hull: its 8 corners and 6 faces (corners given in no particular order).
fn box_hull(h: Vec3) -> bevy_cloth::solver::ConvexHull {
    let corners: Vec<Vec3> = (0..8)
        .map(|k| {
            Vec3::new(
                if k & 1 == 0 { -h.x } else { h.x },
                if k & 2 == 0 { -h.y } else { h.y },
                if k & 4 == 0 { -h.z } else { h.z },
            )
        })
        .collect();
    let faces = [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
    ]
    .into_iter()
    .map(|n| {
        let on: Vec<u32> = (0..8u32)
            .filter(|&k| corners[k as usize].dot(n) > 0.0)
            .collect();
        (n, on)
    })
    .collect();
    bevy_cloth::solver::ConvexHull::new(corners, faces).unwrap()
}

#[test]
fn a_convex_hull_is_exact_the_box_hull_matches_the_box_everywhere() {
    // The hull of a box, turned and placed, against the box collider: the same signed
    // distance and normal at 2,000 points inside, beside faces, edges and corners.
    let h = Vec3::new(0.3, 0.2, 0.5);
    let rotation = bevy::math::Quat::from_euler(bevy::math::EulerRot::YXZ, 0.4, -0.3, 0.2);
    let center = Vec3::new(0.5, 1.0, -0.2);
    let hull = Collider {
        shape: ColliderShape::Convex(bevy_cloth::solver::shapes::Convex {
            center,
            rotation,
            hull: std::sync::Arc::new(box_hull(h)),
        }),
        thickness: 0.005,
        friction: 0.5,
        motion: bevy_cloth::solver::Motion::NONE,
    };
    let cuboid = Collider {
        shape: ColliderShape::Cuboid(bevy_cloth::solver::shapes::Cuboid {
            center,
            axes: [rotation * Vec3::X, rotation * Vec3::Y, rotation * Vec3::Z],
            half_extents: h,
        }),
        ..hull.clone()
    };
    let mut seed = 7u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    };
    let mut worst = 0.0f32;
    for _ in 0..2000 {
        let x = center + Vec3::new(next(), next(), next()) * 0.9;
        let (a, b) = (hull.distance(x), cuboid.distance(x));
        worst = worst.max((a.0 - b.0).abs());
        assert!(
            (a.0 - b.0).abs() < 1e-5 && (a.0.abs() < 1e-4 || a.1.distance(b.1) < 1e-4),
            "at {x}: hull {a:?}, box {b:?}"
        );
    }
    eprintln!("largest difference hull − box over 2000 points: {worst:e} m");
    // A particle dropped on it rests as on the box.
    let start = center + Vec3::Y * 0.8;
    let on_hull = drop_particle(start, hull, 2.0).positions()[0];
    let on_box = drop_particle(start, cuboid, 2.0).positions()[0];
    assert!(
        on_hull.distance(on_box) < 1e-4,
        "{on_hull} against {on_box}"
    );
    // A corner pulled off its faces' planes, a face turned inside out, too few faces:
    // refused; the unit cube itself is a hull.
    let mut corners: Vec<Vec3> = (0..8)
        .map(|k| Vec3::new((k & 1) as f32, ((k >> 1) & 1) as f32, (k >> 2) as f32))
        .collect();
    corners[7] *= 1.5;
    let faces = vec![
        (Vec3::X, vec![1, 3, 5, 7]),
        (Vec3::NEG_X, vec![0, 2, 4, 6]),
        (Vec3::Y, vec![2, 3, 6, 7]),
        (Vec3::NEG_Y, vec![0, 1, 4, 5]),
        (Vec3::Z, vec![4, 5, 6, 7]),
        (Vec3::NEG_Z, vec![0, 1, 2, 3]),
    ];
    let e = bevy_cloth::solver::ConvexHull::new(corners.clone(), faces.clone()).unwrap_err();
    assert!(e.contains("face 0 is not flat"), "{e}");
    corners[7] /= 1.5;
    let mut flipped = faces.clone();
    flipped[2].0 = Vec3::NEG_Y;
    let e = bevy_cloth::solver::ConvexHull::new(corners.clone(), flipped).unwrap_err();
    assert!(e.contains("in front of face 2: not convex"), "{e}");
    assert!(bevy_cloth::solver::ConvexHull::new(corners.clone(), faces.clone()).is_ok());
    let e = bevy_cloth::solver::ConvexHull::new(corners, faces[..3].to_vec()).unwrap_err();
    assert!(e.contains("at least 4 faces"), "{e}");
}
