//! Colliders from avian3d (the `avian` feature): the cloth is kept out of avian bodies'
//! colliders — balls, capsules, cuboids, cylinders, convex hulls and half-spaces — placed by their
//! entities' global transforms, with avian's `Friction` (its dynamic coefficient) when the
//! entity has one; a moving body sweeps through the step and carries the cloth by friction
//! (the plugin gives every collider its motion). An entity with a `ClothCollider` of its own
//! uses that instead. Other shapes (trimeshes, compounds, cones, …) are not collided with.

use std::sync::Arc;

use avian3d::prelude::{Collider, Friction};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;

use crate::ecs::components::ClothCollider;
use crate::solver::{self, ColliderShape, ConvexHull};

/// Hulls made from avian convex shapes, kept by the shape they came from so each is made
/// once (not every step); ones not used in a step are dropped at [`HullCache::end_step`].
#[derive(Default)]
pub struct HullCache {
    hulls: HashMap<usize, (Arc<ConvexHull>, bool)>,
}

impl HullCache {
    /// The hull made from `polyhedron`, the shape named `key`: the kept one, or made now
    /// and kept; `None` (with a warning, once) for a hull the cloth cannot use.
    fn get_or_make(
        &mut self,
        key: usize,
        polyhedron: &avian3d::parry::shape::ConvexPolyhedron,
    ) -> Option<Arc<ConvexHull>> {
        if let Some((hull, used)) = self.hulls.get_mut(&key) {
            *used = true;
            return Some(hull.clone());
        }
        let corners = polyhedron.vertices_adj_to_face();
        let faces = polyhedron
            .faces()
            .iter()
            .map(|f| {
                let first = f.first_vertex_or_edge as usize;
                let n = f.num_vertices_or_edges as usize;
                (f.normal, corners[first..first + n].to_vec())
            })
            .collect();
        let hull = match ConvexHull::new(polyhedron.points().to_vec(), faces) {
            Ok(hull) => Arc::new(hull),
            Err(e) => {
                warn_once!("an avian convex hull the cloth cannot use: {e}");
                return None;
            }
        };
        self.hulls.insert(key, (hull.clone(), true));
        Some(hull)
    }

    /// Drops the hulls no collider used since the last call.
    pub fn end_step(&mut self) {
        self.hulls.retain(|_, (_, used)| std::mem::take(used));
    }
}

/// How far outside an avian collider's surface the particles stay, m (a `ClothCollider`'s
/// default).
pub const THICKNESS: f32 = ClothCollider::THICKNESS;

/// The solver collider of an avian `collider` placed by `transform` (its scale is the
/// collider's own, `shape_scaled`), or `None` for a shape the cloth does not collide with.
pub fn to_solver_collider(
    collider: &Collider,
    transform: &GlobalTransform,
    friction: Option<&Friction>,
    hulls: &mut HullCache,
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
        ColliderShape::cuboid(translation, rotation, cuboid.half_extents)
    } else if let Some(cylinder) = shape.as_cylinder() {
        ColliderShape::Cylinder {
            center: translation,
            axis: rotation * Vec3::Y,
            half_height: cylinder.half_height,
            radius: cylinder.radius,
        }
    } else if let Some(polyhedron) = shape.as_convex_polyhedron() {
        // The shape's own allocation names it (avian keeps a scaled shape until the scale
        // changes).
        let key = Arc::as_ptr(&shape.0) as *const () as usize;
        let hull = hulls.get_or_make(key, polyhedron)?;
        ColliderShape::Convex {
            center: translation,
            rotation,
            hull,
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
        friction: friction.map_or(ClothCollider::FRICTION, |f| f.dynamic_coefficient.max(0.0)),
        motion: solver::Motion::NONE,
    })
}
