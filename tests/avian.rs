//! avian3d colliders (the `avian` feature): a particle dropped on an avian ball, capsule,
//! cuboid and half-space comes to rest at the collider's thickness from the analytic
//! surface. `cargo test --features avian --test avian`.
#![cfg(feature = "avian")]

use avian3d::prelude::{Collider, Friction};
use bevy::math::{Affine3A, Quat, Vec3};
use bevy::prelude::{GlobalTransform, Transform};
use bevy_cloth::ecs::avian::{THICKNESS, to_solver_collider};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::{ClothSolver, Layout};

fn rest_on(collider: bevy_cloth::solver::Collider, start: Vec3) -> Vec3 {
    let mut cloth = ClothSolver::new(
        Layout::from_springs(&[start], &[]).unwrap(),
        &[],
        &ClothParams {
            drag: 0.0,
            ..ClothParams::default()
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
        // The ground at y = 0.25.
        (
            "half-space",
            Collider::half_space(Vec3::Y),
            at(0.0, 0.25, 0.0),
            Vec3::new(0.3, 1.0, 0.3),
            Vec3::new(0.3, 0.25 + THICKNESS, 0.3),
        ),
    ];
    for (name, collider, transform, start, rest) in cases {
        let c = to_solver_collider(&collider, &transform, Some(&Friction::new(0.5)))
            .unwrap_or_else(|| panic!("{name}"));
        assert_eq!(c.friction, 0.5);
        let x = rest_on(c, start);
        assert!(
            x.distance(rest) < 1e-4,
            "{name}: rests at {x}, expected {rest}"
        );
        assert!((c.distance(x).0 - THICKNESS).abs() < 1e-4, "{name}");
    }
    // A shape the cloth does not collide with yet.
    assert!(to_solver_collider(&Collider::cylinder(0.1, 1.0), &at(0.0, 0.0, 0.0), None).is_none());
}
