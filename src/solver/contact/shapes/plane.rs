//! A plane: the half-space behind it.

use bevy::math::Vec3;

use super::{Placement, Shape, check_point};
use crate::error::ClothError;

/// The half-space behind a plane (a ground, a wall).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// A point on the plane, m.
    pub point: Vec3,
    /// Unit normal pointing out of the solid.
    pub normal: Vec3,
}

impl Shape for Plane {
    #[inline]
    fn distance(&self, x: Vec3) -> (f32, Vec3) {
        ((x - self.point).dot(self.normal), self.normal)
    }

    fn extent(&self) -> (Vec3, Vec3) {
        (Vec3::NEG_INFINITY, Vec3::INFINITY)
    }

    /// The plane turns with the placement; scale moves its point, not its normal.
    fn placed(&self, placement: &Placement) -> Self {
        Self {
            point: placement.point(self.point),
            normal: placement.direction(self.normal),
        }
    }

    fn validate(&self) -> Result<(), ClothError> {
        check_point("point", self.point)?;
        let length = self.normal.length();
        let ok = (length - 1.0).abs() < 1e-3;
        crate::params::check("normal", length, ok, "a unit normal")
    }
}
