//! Colliders: spheres, capsules, boxes and planes the particles are kept out of, every substep,
//! with a thickness and Coulomb friction (position-based, as in Macklin et al. 2014,
//! "Unified particle physics for real-time applications", §6.1).

use bevy::math::Vec3;

use super::ClothSolver;

/// The solid a collider fills, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColliderShape {
    /// A ball.
    Sphere {
        /// Centre, m.
        center: Vec3,
        /// Radius, m.
        radius: f32,
    },
    /// All points within `radius` of the segment `a–b`.
    Capsule {
        /// One end of the axis, m.
        a: Vec3,
        /// The other end, m.
        b: Vec3,
        /// Radius, m.
        radius: f32,
    },
    /// A box: `center` plus up to `half_extents` along each of its unit `axes`.
    Cuboid {
        /// Centre, m.
        center: Vec3,
        /// Its three axes, unit and orthogonal (the columns of its rotation).
        axes: [Vec3; 3],
        /// Half its size along each axis, m.
        half_extents: Vec3,
    },
    /// The half-space behind a plane (a ground).
    Plane {
        /// A point on the plane, m.
        point: Vec3,
        /// Unit normal pointing out of the solid.
        normal: Vec3,
    },
}

/// A collider in world space: particles stay at least `thickness` outside its surface and
/// slide on it with friction coefficient `friction`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Collider {
    /// The solid.
    pub shape: ColliderShape,
    /// How far outside the surface particles stay, m (the cloth's half-thickness plus a
    /// margin).
    pub thickness: f32,
    /// Coulomb friction coefficient μ: a particle pressed into the surface by a normal
    /// correction δ loses up to μ·δ of its tangential motion in that substep, so it sticks
    /// on a slope while tan θ ≤ μ.
    pub friction: f32,
}

/// An axis-aligned box a collider's reach lies in: a particle outside it is farther than
/// the thickness from the surface (the broad phase of [`ClothSolver::collide`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Bounds {
    min: Vec3,
    max: Vec3,
}

impl Bounds {
    /// The box around `points` (an empty box for none).
    pub(super) fn around(points: &[Vec3]) -> Self {
        let (min, max) = points
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(*x), hi.max(*x))
            });
        Self { min, max }
    }

    /// The centre of the box and its half diagonal: a sphere around it.
    pub(super) fn sphere(&self) -> (Vec3, f32) {
        (
            (self.min + self.max) * 0.5,
            (self.max - self.min).length() * 0.5,
        )
    }

    /// Its size along each axis.
    pub(super) fn size(&self) -> Vec3 {
        self.max - self.min
    }

    /// Whether the two boxes share a point.
    pub(super) fn overlaps(&self, other: &Bounds) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }

    /// Whether `x` lies in the box.
    #[inline]
    fn contains(&self, x: Vec3) -> bool {
        x.cmpge(self.min).all() && x.cmple(self.max).all()
    }
}

impl Collider {
    /// The box around every point within `thickness` of the solid, grown by a relative
    /// 1e-4 against rounding (a plane's is everything).
    pub(super) fn bounds(&self) -> Bounds {
        let around = |lo: Vec3, hi: Vec3, reach: f32| {
            let reach = reach * 1.0001 + 1e-6;
            Bounds {
                min: lo - Vec3::splat(reach),
                max: hi + Vec3::splat(reach),
            }
        };
        match self.shape {
            ColliderShape::Sphere { center, radius } => {
                around(center, center, radius + self.thickness)
            }
            ColliderShape::Capsule { a, b, radius } => {
                around(a.min(b), a.max(b), radius + self.thickness)
            }
            ColliderShape::Cuboid {
                center,
                axes,
                half_extents,
            } => {
                // The box's extent along each world axis: Σ |axis_k| h_k.
                let extent = axes[0].abs() * half_extents.x
                    + axes[1].abs() * half_extents.y
                    + axes[2].abs() * half_extents.z;
                let reach = self.thickness;
                around(center - extent, center + extent, reach)
            }
            ColliderShape::Plane { .. } => Bounds {
                min: Vec3::NEG_INFINITY,
                max: Vec3::INFINITY,
            },
        }
    }

    /// How far `x` is inside the band of `thickness` around the solid (its depth below
    /// `thickness` outside the surface) and the outward normal, or `None` when it is not:
    /// [`Collider::distance`] with the square root and the normal skipped for the
    /// particles farther away (the most of them, even inside a collider's bounding box).
    #[inline]
    pub(super) fn penetration(&self, x: Vec3) -> Option<(f32, Vec3)> {
        let (d, n) = match self.shape {
            ColliderShape::Plane { .. } | ColliderShape::Cuboid { .. } => self.distance(x),
            _ => {
                let (offset, radius) = self.off_core(x);
                // A relative margin of 1e-4 leaves the particles near the band's edge
                // (those pushed out to it rest there) to the exact test, so the result is
                // the same bits.
                let reach = (radius + self.thickness).powi(2) * 1.0001;
                if offset.length_squared() >= reach {
                    return None;
                }
                self.surface(offset, radius)
            }
        };
        let depth = self.thickness - d;
        (depth > 0.0).then_some((depth, n))
    }

    /// Signed distance from the surface (negative inside) and the outward normal at the
    /// closest surface point.
    pub fn distance(&self, x: Vec3) -> (f32, Vec3) {
        match self.shape {
            ColliderShape::Plane { point, normal } => ((x - point).dot(normal), normal),
            ColliderShape::Cuboid {
                center,
                axes,
                half_extents,
            } => box_distance(x - center, axes, half_extents),
            _ => {
                let (offset, radius) = self.off_core(x);
                self.surface(offset, radius)
            }
        }
    }

    /// `x` less the nearest point of the solid's core (a sphere's centre, a capsule's
    /// axis segment) and the radius around it. (A plane has no core: its point, 0.)
    #[inline]
    fn off_core(&self, x: Vec3) -> (Vec3, f32) {
        match self.shape {
            ColliderShape::Sphere { center, radius } => (x - center, radius),
            ColliderShape::Capsule { a, b, radius } => {
                let axis = b - a;
                let t = ((x - a).dot(axis) / axis.length_squared().max(f32::MIN_POSITIVE))
                    .clamp(0.0, 1.0);
                (x - (a + axis * t), radius)
            }
            ColliderShape::Plane { point, .. } => (x - point, 0.0),
            ColliderShape::Cuboid { center, .. } => (x - center, 0.0),
        }
    }

    /// Signed distance and outward normal of a sphere's or capsule's surface from
    /// `offset`, a point less the nearest point of the core (see [`Self::off_core`]).
    #[inline]
    fn surface(&self, offset: Vec3, radius: f32) -> (f32, Vec3) {
        let normal = offset.try_normalize().unwrap_or_else(|| match self.shape {
            ColliderShape::Capsule { a, b, .. } => (b - a).any_orthonormal_vector(),
            _ => Vec3::Y,
        });
        (offset.length() - radius, normal)
    }
}

/// Signed distance from a box's surface and the outward normal at the nearest surface
/// point, for `offset` from its centre: outside, the distance to the nearest point of the
/// box; inside, minus the distance to the nearest face, whose normal it takes.
fn box_distance(offset: Vec3, axes: [Vec3; 3], half: Vec3) -> (f32, Vec3) {
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

impl ClothSolver {
    /// Pushes every free particle out of every collider to `thickness` outside its surface,
    /// then removes tangential motion of this substep up to `friction × push` (Coulomb).
    /// Velocities follow the corrected positions: `v = (x − x_prev)/h`.
    pub(super) fn collide(&mut self) {
        if self.colliders.is_empty() {
            return;
        }
        let h = self.h;
        let p = &mut self.particles;
        for i in 0..p.position.len() {
            if p.inv_mass[i] == 0.0 {
                continue;
            }
            let mut x = p.position[i];
            let mut touched = false;
            for (c, bounds) in self.colliders.iter().zip(&self.collider_bounds) {
                if !bounds.contains(x) {
                    continue; // farther than the thickness: the distance would say so
                }
                let Some((depth, n)) = c.penetration(x) else {
                    continue;
                };
                x += n * depth;
                let moved = x - p.previous[i];
                let tangential = moved - n * moved.dot(n);
                let slide = tangential.length();
                let grip = c.friction * depth;
                x -= if slide <= grip {
                    tangential
                } else {
                    tangential * (grip / slide)
                };
                touched = true;
            }
            if touched {
                p.position[i] = x;
                p.velocity[i] = (x - p.previous[i]) / h;
            }
        }
    }
}
