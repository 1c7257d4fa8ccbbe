//! A cylinder.

use bevy::math::Vec3;

use super::{Placement, Shape, check_point, check_size};
use crate::error::ClothError;

/// A cylinder: `center` plus up to `half_height` along its unit `axis`, within `radius`
/// of the axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    /// Centre, m.
    pub center: Vec3,
    /// Unit axis.
    pub axis: Vec3,
    /// Half its length along the axis, m.
    pub half_height: f32,
    /// Radius, m.
    pub radius: f32,
}

impl Shape for Cylinder {
    /// The 2D box distance in (distance from the axis, height along it).
    fn distance(&self, x: Vec3) -> (f32, Vec3) {
        let (axis, offset) = (self.axis, x - self.center);
        let along = offset.dot(axis);
        let radial = offset - axis * along;
        let rho = radial.length();
        let out = radial
            .try_normalize()
            .unwrap_or_else(|| axis.any_orthonormal_vector());
        let cap = if along >= 0.0 { axis } else { -axis };
        let (dr, dh) = (rho - self.radius, along.abs() - self.half_height);
        if dr > 0.0 && dh > 0.0 {
            // Beyond the rim: the nearest point is on its circle.
            let v = out * dr + cap * dh;
            let length = v.length();
            (length, v / length)
        } else if dr >= dh {
            (dr, out)
        } else {
            (dh, cap)
        }
    }

    fn extent(&self) -> (Vec3, Vec3) {
        // Along world axis i: h |a_i| from the axis, r √(1 − a_i²) from the discs.
        let a = self.axis;
        let e = a.abs() * self.half_height + (Vec3::ONE - a * a).max(Vec3::ZERO).sqrt() * self.radius;
        (self.center - e, self.center + e)
    }

    fn placed(&self, placement: &Placement) -> Self {
        // Its height scales along the axis, its radius with the largest scale across it.
        Self {
            center: placement.point(self.center),
            axis: placement.direction(self.axis),
            half_height: placement.length(self.half_height, self.axis),
            radius: placement.radius(self.radius, self.axis),
        }
    }

    fn axis(&self) -> Option<(Vec3, Vec3, f32)> {
        let half = self.axis * self.half_height;
        Some((self.center - half, self.center + half, self.radius))
    }

    fn validate(&self) -> Result<(), ClothError> {
        check_point("center", self.center)?;
        check_size("radius", self.radius, false, format!("a radius from 0 (excluded) to {max:e} m", max = crate::limits::MAX_POSITION))?;
        check_size(
            "half_height",
            self.half_height,
            false,
            format!("a half-height from 0 (excluded) to {max:e} m", max = crate::limits::MAX_POSITION),
        )
    }
}
