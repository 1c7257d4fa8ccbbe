//! A ball.

use bevy::math::Vec3;

use super::{Placement, Shape, check_point, check_size, round_surface, round_surface_within};
use crate::error::ClothError;

/// A ball: every point within `radius` of `center`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre, m.
    pub center: Vec3,
    /// Radius, m.
    pub radius: f32,
}

impl Shape for Sphere {
    #[inline]
    fn distance(&self, x: Vec3) -> (f32, Vec3) {
        round_surface(x - self.center, self.radius, || Vec3::Y)
    }

    #[inline]
    fn distance_within(&self, x: Vec3, reach: f32) -> Option<(f32, Vec3)> {
        round_surface_within(x - self.center, self.radius, reach, || Vec3::Y)
    }

    fn extent(&self) -> (Vec3, Vec3) {
        let r = Vec3::splat(self.radius);
        (self.center - r, self.center + r)
    }

    fn placed(&self, placement: &Placement) -> Self {
        Self {
            center: placement.point(self.center),
            radius: placement.radius(self.radius, Vec3::ZERO),
        }
    }

    fn validate(&self) -> Result<(), ClothError> {
        check_point("center", self.center)?;
        check_size("radius", self.radius, false, format!("a radius from 0 (excluded) to {max:e} m", max = crate::limits::MAX_POSITION))
    }
}
