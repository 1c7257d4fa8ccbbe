//! Collider shapes: each a type in its own file that implements [`Shape`] (its signed
//! distance, its extent, how it moves, what it checks), registered in [`ColliderShape`] by
//! one line of the list at the foot of this file. Nothing else in the crate names a shape:
//! the contact stage, sweeping, placing a collider by an entity's transform and the
//! plugin's checks all go through the trait.

use bevy::math::{Affine3A, Quat, Vec3};

use crate::error::ClothError;

/// What the contact stage asks of a collider's solid.
pub trait Shape {
    /// Signed distance from the surface (negative inside) and the outward normal at the
    /// nearest surface point.
    fn distance(&self, x: Vec3) -> (f32, Vec3);

    /// [`Shape::distance`] where a cheap test can tell that `x` is at least `reach` from
    /// the surface: `None` only then (the contact stage's narrow phase skips the square
    /// root and the normal for the most particles, even inside a collider's bounding box).
    /// A shape without such a test keeps this default.
    #[inline]
    fn distance_within(&self, x: Vec3, reach: f32) -> Option<(f32, Vec3)> {
        let _ = reach;
        Some(self.distance(x))
    }

    /// The corners `(min, max)` of the axis-aligned box the solid lies in (infinite for an
    /// unbounded one).
    fn extent(&self) -> (Vec3, Vec3);

    /// The solid carried by `placement` (an entity's transform, or a collider's motion
    /// swept back).
    fn placed(&self, placement: &Placement) -> Self
    where
        Self: Sized;

    /// For a thin solid round a segment (a rope, a rod), the segment and the radius round
    /// it, which the contact stage's edge pass keeps the cloth's edges off; `None` else.
    fn axis(&self) -> Option<(Vec3, Vec3, f32)> {
        None
    }

    /// Checks its sizes, naming the field and what it should be.
    fn validate(&self) -> Result<(), ClothError> {
        Ok(())
    }
}

/// A rigid placement with a scale: where points go, how directions turn, how lengths
/// stretch. From an entity's transform ([`Placement::affine`]) or a collider's motion
/// ([`Placement::about`]).
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    map: Map,
    /// The rotation it turns directions by.
    pub rotation: Quat,
    /// The absolute scale along each local axis (one for a motion).
    pub scale: Vec3,
}

#[derive(Clone, Copy, Debug)]
enum Map {
    /// A point goes to `matrix · x`.
    Affine(Affine3A),
    /// A point goes to `to + rotation (x − pivot)`.
    About { pivot: Vec3, to: Vec3 },
}

impl Placement {
    /// The placement of an entity's transform, given as its matrix (scale, rotation,
    /// translation).
    pub fn affine(matrix: Affine3A) -> Self {
        let (scale, rotation, _) = matrix.to_scale_rotation_translation();
        Self {
            map: Map::Affine(matrix),
            rotation,
            scale: scale.abs(),
        }
    }

    /// The rigid motion that turns by `rotation` about `pivot` and takes `pivot` to `to`.
    pub fn about(pivot: Vec3, rotation: Quat, to: Vec3) -> Self {
        Self {
            map: Map::About { pivot, to },
            rotation,
            scale: Vec3::ONE,
        }
    }

    /// Where the point `x` goes.
    #[inline]
    pub fn point(&self, x: Vec3) -> Vec3 {
        match self.map {
            Map::Affine(matrix) => matrix.transform_point3(x),
            Map::About { pivot, to } => to + self.rotation * (x - pivot),
        }
    }

    /// Where the direction `v` turns (its length kept).
    #[inline]
    pub fn direction(&self, v: Vec3) -> Vec3 {
        self.rotation * v
    }

    /// A length along the local unit direction `along`, scaled.
    pub fn length(&self, length: f32, along: Vec3) -> f32 {
        if self.scale == Vec3::ONE {
            length
        } else {
            length * (self.scale * along).length()
        }
    }

    /// A radius across the local unit direction `axis` (a cylinder's or a capsule's), or
    /// of a ball with `Vec3::ZERO`: scaled by the largest scale across the axis.
    pub fn radius(&self, radius: f32, axis: Vec3) -> f32 {
        if self.scale == Vec3::ONE {
            return radius;
        }
        let across = (Vec3::ONE - axis * axis).max(Vec3::ZERO).sqrt();
        radius * (self.scale * across).max_element()
    }
}

/// The signed distance and outward normal of a round surface (a ball's, a capsule's) of
/// `radius` about a core point, for `offset` = the point less that core point; `fallback`
/// is the normal at the core itself.
#[inline]
fn round_surface(offset: Vec3, radius: f32, fallback: impl Fn() -> Vec3) -> (f32, Vec3) {
    let normal = offset.try_normalize().unwrap_or_else(fallback);
    (offset.length() - radius, normal)
}

/// [`round_surface`] unless `offset` is at least `reach` past it: then `None`, with the
/// square root skipped. A relative margin of 1e-4 leaves the points near the band's edge
/// (those pushed out to it rest there) to the exact test, so the result is the same bits.
#[inline]
fn round_surface_within(
    offset: Vec3,
    radius: f32,
    reach: f32,
    fallback: impl Fn() -> Vec3,
) -> Option<(f32, Vec3)> {
    let within = (radius + reach).powi(2) * 1.0001;
    (offset.length_squared() < within).then(|| round_surface(offset, radius, fallback))
}

/// Checks one size: finite, above 0 (or from 0 with `zero_allowed`), at most
/// [`MAX_POSITION`](crate::limits::MAX_POSITION); `expected` says so in words.
pub(crate) fn check_size(
    field: &'static str,
    value: f32,
    zero_allowed: bool,
    expected: impl Into<std::borrow::Cow<'static, str>>,
) -> Result<(), ClothError> {
    let low = if zero_allowed {
        value >= 0.0
    } else {
        value > 0.0
    };
    let ok = low && value <= crate::limits::MAX_POSITION;
    crate::params::check(field, value, ok, expected)
}

/// Checks that a point lies within [`MAX_POSITION`](crate::limits::MAX_POSITION) of the
/// origin.
pub(crate) fn check_point(field: &'static str, x: Vec3) -> Result<(), ClothError> {
    let far = x.abs().max_element();
    let ok = far <= crate::limits::MAX_POSITION;
    crate::params::check(
        field,
        far,
        ok,
        format!(
            "a point within {max:e} m of the origin",
            max = crate::limits::MAX_POSITION
        ),
    )
}

/// Registers the shapes: one line each, `Variant(module)`, its doc comment above it. The
/// module is a file of this folder that defines the type `Variant` and implements
/// [`Shape`] for it; the list makes it a [`ColliderShape`] and dispatches to it.
macro_rules! shapes {
    ($($(#[$doc:meta])* $name:ident($file:ident),)*) => {
        $(mod $file; pub use $file::$name;)*

        /// The solid a collider fills, in world space: one of the registered [`Shape`]s.
        /// (Reflected as one opaque value: an inspector shows it, without its fields.)
        #[derive(Clone, Debug, PartialEq, bevy::reflect::Reflect)]
        #[reflect(opaque, Debug, PartialEq, Clone)]
        pub enum ColliderShape {
            $($(#[$doc])* $name($name),)*
        }

        $(impl From<$name> for ColliderShape {
            fn from(shape: $name) -> Self {
                Self::$name(shape)
            }
        })*

        impl Shape for ColliderShape {
            #[inline]
            fn distance(&self, x: Vec3) -> (f32, Vec3) {
                match self { $(Self::$name(s) => s.distance(x),)* }
            }
            #[inline]
            fn distance_within(&self, x: Vec3, reach: f32) -> Option<(f32, Vec3)> {
                match self { $(Self::$name(s) => s.distance_within(x, reach),)* }
            }
            fn extent(&self) -> (Vec3, Vec3) {
                match self { $(Self::$name(s) => s.extent(),)* }
            }
            fn placed(&self, placement: &Placement) -> Self {
                match self { $(Self::$name(s) => Self::$name(s.placed(placement)),)* }
            }
            fn axis(&self) -> Option<(Vec3, Vec3, f32)> {
                match self { $(Self::$name(s) => s.axis(),)* }
            }
            fn validate(&self) -> Result<(), ClothError> {
                match self { $(Self::$name(s) => s.validate(),)* }
            }
        }
    };
}

shapes! {
    /// A ball.
    Sphere(sphere),
    /// All points within a radius of a segment.
    Capsule(capsule),
    /// A box.
    Cuboid(cuboid),
    /// A cylinder.
    Cylinder(cylinder),
    /// A convex polyhedron (a physics engine's convex hull).
    Convex(convex),
    /// The half-space behind a plane (a ground, a wall).
    Plane(plane),
    /// A ring: all points within a radius of a circle.
    Torus(torus),
}

pub use convex::ConvexHull;

#[cfg(test)]
mod tests {
    use std::f32::consts::TAU;

    use super::*;
    use crate::solver::unit_hash;

    /// `n × n` points of the parallelogram `corner + s·u + t·v`, `s, t ∈ [0, 1]`.
    fn patch(corner: Vec3, u: Vec3, v: Vec3, n: usize, out: &mut Vec<Vec3>) {
        for i in 0..=n {
            for j in 0..=n {
                out.push(corner + u * (i as f32 / n as f32) + v * (j as f32 / n as f32));
            }
        }
    }

    /// Points on the circle of `radius` about `center` across unit `axis`.
    fn ring(center: Vec3, axis: Vec3, radius: f32, n: usize, out: &mut Vec<Vec3>) {
        let (u, v) = axis.any_orthonormal_pair();
        for k in 0..n {
            let a = TAU * k as f32 / n as f32;
            out.push(center + (u * a.cos() + v * a.sin()) * radius);
        }
    }

    /// A shape, dense samples of its surface, and a membership test written apart from
    /// the distance code.
    type Case = (ColliderShape, Vec<Vec3>, Box<dyn Fn(Vec3) -> bool>);

    const N: usize = 80;

    fn box_case(c: Vec3, turn: Quat, half: Vec3) -> Case {
        let mut points = Vec::new();
        let e = [
            turn * Vec3::X * half.x,
            turn * Vec3::Y * half.y,
            turn * Vec3::Z * half.z,
        ];
        for k in 0..3 {
            let (u, v) = (e[(k + 1) % 3], e[(k + 2) % 3]);
            for side in [-1.0, 1.0] {
                patch(c + e[k] * side - u - v, u * 2.0, v * 2.0, N, &mut points);
            }
        }
        let inside = move |x: Vec3| (turn.inverse() * (x - c)).abs().cmple(half).all();
        (Cuboid::new(c, turn, half).into(), points, Box::new(inside))
    }

    fn cylinder_case(center: Vec3, axis: Vec3, half_height: f32, radius: f32) -> Case {
        let mut points = Vec::new();
        for k in 0..=N {
            let t = -half_height + 2.0 * half_height * k as f32 / N as f32;
            ring(center + axis * t, axis, radius, 4 * N, &mut points);
            let r = radius * k as f32 / N as f32;
            ring(center + axis * half_height, axis, r, 4 * N, &mut points);
            ring(center - axis * half_height, axis, r, 4 * N, &mut points);
        }
        let inside = move |x: Vec3| {
            let along = (x - center).dot(axis);
            along.abs() <= half_height && (x - center - axis * along).length() <= radius
        };
        let shape = Cylinder {
            center,
            axis,
            half_height,
            radius,
        };
        (shape.into(), points, Box::new(inside))
    }

    fn capsule_case(a: Vec3, b: Vec3, radius: f32) -> Case {
        let mut points = Vec::new();
        let along = (b - a).normalize();
        for k in 0..=N {
            ring(
                a.lerp(b, k as f32 / N as f32),
                along,
                radius,
                4 * N,
                &mut points,
            );
            // The hemispheres facing away from the axis.
            let polar = std::f32::consts::FRAC_PI_2 * k as f32 / N as f32;
            for (end, out) in [(a, -along), (b, along)] {
                let centre = end + out * radius * polar.cos();
                ring(centre, along, radius * polar.sin(), 4 * N, &mut points);
            }
        }
        let inside = move |x: Vec3| {
            let t = ((x - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            x.distance(a.lerp(b, t)) <= radius
        };
        (Capsule { a, b, radius }.into(), points, Box::new(inside))
    }

    fn torus_case(center: Vec3, axis: Vec3, major: f32, minor: f32) -> Case {
        let mut points = Vec::new();
        let (u, v) = axis.any_orthonormal_pair();
        for k in 0..4 * N {
            let a = TAU * k as f32 / (4 * N) as f32;
            let out = u * a.cos() + v * a.sin();
            // The tube's circle round the point of the ring in direction `out`.
            ring(center + out * major, out.cross(axis), minor, N, &mut points);
        }
        let inside = move |x: Vec3| {
            let d = x - center;
            let along = d.dot(axis);
            let radial = (d - axis * along).length();
            (radial - major).hypot(along) <= minor
        };
        let shape = Torus {
            center,
            axis,
            major_radius: major,
            minor_radius: minor,
        };
        (shape.into(), points, Box::new(inside))
    }

    /// The shapes tested, about the point returned: a turned box, cylinder and torus, and
    /// a tilted capsule.
    fn cases() -> (Vec3, [Case; 4]) {
        let turn = Quat::from_euler(bevy::math::EulerRot::XYZ, 0.3, -0.5, 0.8);
        let c = Vec3::new(0.2, 1.0, -0.3);
        let cases = [
            box_case(c, turn, Vec3::new(0.4, 0.25, 0.3)),
            cylinder_case(c, turn * Vec3::Y, 0.3, 0.25),
            capsule_case(Vec3::new(-0.3, 0.9, 0.1), Vec3::new(0.4, 1.2, -0.2), 0.2),
            torus_case(c, turn * Vec3::Z, 0.4, 0.1),
        ];
        (c, cases)
    }

    /// Each shape's signed distance against brute force: the distance to the nearest of
    /// dense samples of its surface (never less than the true distance, at most the
    /// sampling's spacing more), signed by the membership test. 300 points in and around
    /// each shape.
    #[test]
    fn distances_match_brute_force_sampling_of_the_surface() {
        let (c, cases) = cases();
        for (shape, surface, inside) in cases {
            for i in 0..300 {
                let q = Vec3::new(unit_hash(i, 0), unit_hash(i, 1), unit_hash(i, 2));
                let x = c + q * 0.7;
                let (d, _) = shape.distance(x);
                let brute = surface
                    .iter()
                    .map(|s| s.distance(x))
                    .fold(f32::MAX, f32::min);
                let sign = if inside(x) { -1.0 } else { 1.0 };
                assert!(
                    brute >= d.abs() - 1e-5 && brute - d.abs() < 0.012 && d * sign >= -1e-5,
                    "{shape:?} at {x}: {d} against {} by sampling",
                    sign * brute
                );
            }
        }
    }

    /// Every shape's extent holds every sampled point of its surface, and a shape placed
    /// by a motion and back is where it was.
    #[test]
    fn extents_hold_the_surface_and_placements_invert() {
        let (c, cases) = cases();
        let turn = Quat::from_euler(bevy::math::EulerRot::ZYX, -0.7, 0.4, 1.1);
        let pivot = Vec3::new(0.5, 0.0, 0.2);
        let there = Placement::about(pivot, turn, Vec3::new(1.0, 2.0, 3.0));
        let back = Placement::about(Vec3::new(1.0, 2.0, 3.0), turn.inverse(), pivot);
        for (shape, surface, _) in cases {
            let (lo, hi) = shape.extent();
            for s in &surface {
                assert!(
                    s.cmpge(lo - 1e-5).all() && s.cmple(hi + 1e-5).all(),
                    "{shape:?}: {s}"
                );
            }
            let again = shape.placed(&there).placed(&back);
            for i in 0..50 {
                let x = c + Vec3::new(unit_hash(i, 3), unit_hash(i, 4), unit_hash(i, 5)) * 0.7;
                let (d, e) = (shape.distance(x).0, again.distance(x).0);
                assert!((d - e).abs() < 1e-5, "{shape:?} at {x}: {d} then {e}");
            }
        }
    }
}
