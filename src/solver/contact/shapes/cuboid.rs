//! A box.

use bevy::math::{Quat, Vec3};

use super::{Placement, Shape, check_point, check_size};
use crate::error::ClothError;

/// A box: `center` plus up to `half_extents` along each of its unit `axes`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cuboid {
    /// Centre, m.
    pub center: Vec3,
    /// Its three axes, unit and orthogonal (the columns of its rotation).
    pub axes: [Vec3; 3],
    /// Half its size along each axis, m.
    pub half_extents: Vec3,
}

impl Cuboid {
    /// A box of `half_extents` along the axes of `rotation`, about `center`.
    pub fn new(center: Vec3, rotation: Quat, half_extents: Vec3) -> Self {
        Self {
            center,
            axes: [rotation * Vec3::X, rotation * Vec3::Y, rotation * Vec3::Z],
            half_extents,
        }
    }
}

impl Shape for Cuboid {
    /// Outside, the distance to the nearest point of the box; inside, minus the distance
    /// to the nearest face, whose normal it takes.
    fn distance(&self, x: Vec3) -> (f32, Vec3) {
        let (axes, half) = (self.axes, self.half_extents);
        let offset = x - self.center;
        let local = Vec3::new(
            offset.dot(axes[0]),
            offset.dot(axes[1]),
            offset.dot(axes[2]),
        );
        let q = local.abs() - half;
        let world = |v: Vec3| axes[0] * v.x + axes[1] * v.y + axes[2] * v.z;
        if q.max_element() > 0.0 {
            let outside = q.max(Vec3::ZERO) * local.signum();
            let length = outside.length();
            (length, world(outside / length))
        } else {
            // The face nearest: the axis with the largest (least negative) q.
            let k = if q.x >= q.y && q.x >= q.z {
                0
            } else if q.y >= q.z {
                1
            } else {
                2
            };
            let mut n = Vec3::ZERO;
            n[k] = if local[k] >= 0.0 { 1.0 } else { -1.0 };
            (q[k], world(n))
        }
    }

    fn extent(&self) -> (Vec3, Vec3) {
        // The box's extent along each world axis: Σ |axis_k| h_k.
        let h = self.half_extents;
        let e = self.axes[0].abs() * h.x + self.axes[1].abs() * h.y + self.axes[2].abs() * h.z;
        (self.center - e, self.center + e)
    }

    fn placed(&self, placement: &Placement) -> Self {
        let h = self.half_extents;
        Self {
            center: placement.point(self.center),
            axes: self.axes.map(|a| placement.direction(a)),
            half_extents: Vec3::new(
                placement.length(h.x, self.axes[0]),
                placement.length(h.y, self.axes[1]),
                placement.length(h.z, self.axes[2]),
            ),
        }
    }

    fn validate(&self) -> Result<(), ClothError> {
        check_point("center", self.center)?;
        let h = self.half_extents;
        let expected = format!("a half-extent from 0 (excluded) to {max:e} m", max = crate::limits::MAX_POSITION);
        check_size("half_extents.x", h.x, false, expected.clone())?;
        check_size("half_extents.y", h.y, false, expected.clone())?;
        check_size("half_extents.z", h.z, false, expected)
    }
}
