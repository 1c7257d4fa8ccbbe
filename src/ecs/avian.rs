//! Colliders from avian3d (the `avian` feature): the cloth is kept out of avian bodies'
//! colliders — balls, capsules, cuboids, cylinders and half-spaces — placed by their
//! entities' global transforms, with avian's `Friction` (its dynamic coefficient) when the
//! entity has one; a moving body sweeps through the step and carries the cloth by friction
//! (the plugin gives every collider its motion). An entity with a `ClothCollider` of its own
//! uses that instead. Other shapes (convex hulls, meshes, compounds) are not collided with.

use avian3d::prelude::{Collider, Friction};
use bevy::prelude::*;

use crate::solver::{self, ColliderShape};

/// How far outside an avian collider's surface the particles stay, m (a `ClothCollider`'s
/// default).
pub const THICKNESS: f32 = 0.005;

/// The solver collider of an avian `collider` placed by `transform` (its scale is the
/// collider's own, `shape_scaled`), or `None` for a shape the cloth does not collide with.
pub fn to_solver_collider(
    collider: &Collider,
    transform: &GlobalTransform,
    friction: Option<&Friction>,
) -> Option<solver::Collider> {
    let shape = collider.shape_scaled();
    let (rotation, translation) = {
        let (_, r, t) = transform.to_scale_rotation_translation();
        (r, t)
    };
    let place = |p: Vec3| translation + rotation * p;
    let shape = if let Some(ball) = shape.as_ball() {
        ColliderShape::Sphere {
            center: translation,
            radius: ball.radius,
        }
    } else if let Some(capsule) = shape.as_capsule() {
        ColliderShape::Capsule {
            a: place(capsule.segment.a),
            b: place(capsule.segment.b),
            radius: capsule.radius,
        }
    } else if let Some(cuboid) = shape.as_cuboid() {
        ColliderShape::Cuboid {
            center: translation,
            axes: [rotation * Vec3::X, rotation * Vec3::Y, rotation * Vec3::Z],
            half_extents: cuboid.half_extents,
        }
    } else if let Some(cylinder) = shape.as_cylinder() {
        ColliderShape::Cylinder {
            center: translation,
            axis: rotation * Vec3::Y,
            half_height: cylinder.half_height,
            radius: cylinder.radius,
        }
    } else if let Some(half_space) = shape.as_halfspace() {
        ColliderShape::Plane {
            point: translation,
            normal: rotation * half_space.normal,
        }
    } else {
        return None;
    };
    Some(solver::Collider {
        shape,
        thickness: THICKNESS,
        friction: friction.map_or(0.3, |f| f.dynamic_coefficient.max(0.0)),
        motion: solver::Motion::NONE,
    })
}
