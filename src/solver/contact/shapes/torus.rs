//! A torus: a ring, a hoop, a handle.

use bevy::math::Vec3;

use super::{Placement, Shape, check_point, check_size};
use crate::error::ClothError;

/// A ring: every point within `minor_radius` of the circle of `major_radius` about
/// `center`, across its unit `axis`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Torus {
    /// Centre of the ring, m.
    pub center: Vec3,
    /// Unit axis the ring turns about.
    pub axis: Vec3,
    /// Radius of the ring's centre circle, m.
    pub major_radius: f32,
    /// Radius of the tube, m.
    pub minor_radius: f32,
}

impl Shape for Torus {
    /// The distance from the nearest point of the centre circle, less the tube's radius.
    fn distance(&self, x: Vec3) -> (f32, Vec3) {
        let offset = x - self.center;
        let along = offset.dot(self.axis);
        let radial = offset - self.axis * along;
        // On the axis every point of the circle is nearest: take any.
        let out = radial
            .try_normalize()
            .unwrap_or_else(|| self.axis.any_orthonormal_vector());
        let from_circle = offset - out * self.major_radius;
        let normal = from_circle.try_normalize().unwrap_or(self.axis);
        (from_circle.length() - self.minor_radius, normal)
    }

    fn extent(&self) -> (Vec3, Vec3) {
        // The circle reaches R √(1 − a_i²) along world axis i; the tube r more.
        let a = self.axis;
        let e = (Vec3::ONE - a * a).max(Vec3::ZERO).sqrt() * self.major_radius
            + Vec3::splat(self.minor_radius);
        (self.center - e, self.center + e)
    }

    fn placed(&self, placement: &Placement) -> Self {
        Self {
            center: placement.point(self.center),
            axis: placement.direction(self.axis),
            major_radius: placement.radius(self.major_radius, self.axis),
            minor_radius: placement.radius(self.minor_radius, Vec3::ZERO),
        }
    }

    fn validate(&self) -> Result<(), ClothError> {
        check_point("center", self.center)?;
        let expected = format!("a radius from 0 (excluded) to {max:e} m", max = crate::limits::MAX_POSITION);
        check_size("major_radius", self.major_radius, false, expected.clone())?;
        check_size("minor_radius", self.minor_radius, false, expected)
    }
}
