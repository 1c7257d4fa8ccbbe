//! A capsule: a segment with a radius round it (a limb, a rope).

use bevy::math::Vec3;

use super::{Placement, Shape, check_point, check_size, round_surface, round_surface_within};
use crate::error::ClothError;

/// All points within `radius` of the segment `a–b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capsule {
    /// One end of the axis, m.
    pub a: Vec3,
    /// The other end, m.
    pub b: Vec3,
    /// Radius, m.
    pub radius: f32,
}

impl Capsule {
    /// The normal at a point on the axis itself: any direction across it.
    fn across(&self) -> Vec3 {
        // (glam's `any_orthonormal_vector` takes a unit vector.)
        (self.b - self.a).normalize_or(Vec3::Y).any_orthonormal_vector()
    }
}

impl Shape for Capsule {
    #[inline]
    fn distance(&self, x: Vec3) -> (f32, Vec3) {
        round_surface(x - segment_point(self.a, self.b, x), self.radius, || {
            self.across()
        })
    }

    #[inline]
    fn distance_within(&self, x: Vec3, reach: f32) -> Option<(f32, Vec3)> {
        let offset = x - segment_point(self.a, self.b, x);
        round_surface_within(offset, self.radius, reach, || self.across())
    }

    fn extent(&self) -> (Vec3, Vec3) {
        let r = Vec3::splat(self.radius);
        (self.a.min(self.b) - r, self.a.max(self.b) + r)
    }

    fn placed(&self, placement: &Placement) -> Self {
        // The radius scales with the largest scale factor, as a ball's.
        Self {
            a: placement.point(self.a),
            b: placement.point(self.b),
            radius: placement.radius(self.radius, Vec3::ZERO),
        }
    }

    fn axis(&self) -> Option<(Vec3, Vec3, f32)> {
        Some((self.a, self.b, self.radius))
    }

    fn validate(&self) -> Result<(), ClothError> {
        check_point("a", self.a)?;
        check_point("b", self.b)?;
        check_size("radius", self.radius, false, format!("a radius from 0 (excluded) to {max:e} m", max = crate::limits::MAX_POSITION))
    }
}

/// The point of the segment `a–b` nearest `x`.
#[inline]
pub(crate) fn segment_point(a: Vec3, b: Vec3, x: Vec3) -> Vec3 {
    let axis = b - a;
    let t = ((x - a).dot(axis) / axis.length_squared().max(f32::MIN_POSITIVE)).clamp(0.0, 1.0);
    a + axis * t
}
