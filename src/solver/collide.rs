//! Colliders: spheres, capsules, boxes, cylinders and planes the particles are kept out of,
//! every substep, with a thickness and Coulomb friction (position-based, as in Macklin et
//! al. 2014, "Unified particle physics for real-time applications", §6.1). A moving
//! collider carries its rigid [`Motion`]: within a step it is swept from where it was to
//! where it is, substep by substep, and friction acts on the particles' motion relative to
//! its surface, so a moving body pushes the cloth at its own speed and carries it along.

use std::sync::Arc;

use bevy::math::{Quat, Vec3};

/// The solid a collider fills, in world space.
#[derive(Clone, Debug, PartialEq)]
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
    /// A cylinder: `center` plus up to `half_height` along its unit `axis`, within `radius`
    /// of the axis.
    Cylinder {
        /// Centre, m.
        center: Vec3,
        /// Unit axis.
        axis: Vec3,
        /// Half its length along the axis, m.
        half_height: f32,
        /// Radius, m.
        radius: f32,
    },
    /// A convex polyhedron (a physics engine's convex hull), placed: a point `x` of the
    /// world is `rotation⁻¹ (x − center)` in the hull's own frame.
    Convex {
        /// Where the hull's origin is, m.
        center: Vec3,
        /// Its orientation.
        rotation: Quat,
        /// The hull, in its own frame (shared: placing it copies no geometry).
        hull: Arc<ConvexHull>,
    },
    /// The half-space behind a plane (a ground).
    Plane {
        /// A point on the plane, m.
        point: Vec3,
        /// Unit normal pointing out of the solid.
        normal: Vec3,
    },
}

impl ColliderShape {
    /// A box of `half_extents` along the axes of `rotation`, about `center`.
    pub fn cuboid(center: Vec3, rotation: Quat, half_extents: Vec3) -> Self {
        Self::Cuboid {
            center,
            axes: [rotation * Vec3::X, rotation * Vec3::Y, rotation * Vec3::Z],
            half_extents,
        }
    }
}

/// A collider in world space: particles stay at least `thickness` outside its surface and
/// slide on it with friction coefficient `friction`.
#[derive(Clone, Debug, PartialEq)]
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
    /// How the solid moves over the step it is set for ([`Motion::NONE`] for a still one).
    pub motion: Motion,
}

/// What the cloth gave one collider over the last step: the reaction to every push and
/// friction correction of its particles (each changes a particle's momentum by `m Δx / h`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ColliderImpulse {
    /// Linear impulse on the collider, N·s.
    pub linear: Vec3,
    /// Angular impulse on it about the world origin, N·m·s (about a point `c`, it is
    /// `angular − c × linear`).
    pub angular: Vec3,
}

/// A collider's rigid motion over a step: its velocity when the step ends. The solver
/// sweeps the collider back along it to where it was at each substep, and takes friction
/// against the surface's velocity there, `linear + angular × (x − pivot)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    /// Velocity of `pivot`, m/s.
    pub linear: Vec3,
    /// Angular velocity about `pivot`, rad/s.
    pub angular: Vec3,
    /// The point of the body `linear` is the velocity of, where it is at the step's end, m.
    pub pivot: Vec3,
}

impl Motion {
    /// A still collider.
    pub const NONE: Self = Self {
        linear: Vec3::ZERO,
        angular: Vec3::ZERO,
        pivot: Vec3::ZERO,
    };

    /// The motion that carries a body from pose `before` to pose `after` (rotation,
    /// translation) in `dt` seconds, about `after`'s translation: sweeping back by `dt`
    /// gives `before` exactly. `NONE` for a `dt` that is not positive or poses that are
    /// not finite.
    pub fn between(before: (Quat, Vec3), after: (Quat, Vec3), dt: f32) -> Self {
        let turn = (after.0 * before.0.inverse()).normalize();
        let motion = Self {
            linear: (after.1 - before.1) / dt,
            angular: turn.to_scaled_axis() / dt,
            pivot: after.1,
        };
        let finite = motion.linear.is_finite() && motion.angular.is_finite();
        if dt > 0.0 && finite {
            motion
        } else {
            Self::NONE
        }
    }

    /// Whether the collider does not move.
    pub fn is_still(&self) -> bool {
        self.linear == Vec3::ZERO && self.angular == Vec3::ZERO
    }

    /// How far the body's point at `x` moves over the `h` seconds that end now, `turn`
    /// being its rotation over them (`Quat::from_scaled_axis(angular·h)`): the exact rigid
    /// motion, so a point carried round a turntable stays on its circle.
    #[inline]
    pub(super) fn carry(&self, turn: Quat, h: f32, x: Vec3) -> Vec3 {
        let start = self.pivot - self.linear * h;
        self.pivot + turn * (x - start) - x
    }

    /// Where the body's point now at `x` was `tau` seconds before.
    fn back(&self, turn_back: Quat, tau: f32, x: Vec3) -> Vec3 {
        self.pivot - self.linear * tau + turn_back * (x - self.pivot)
    }
}

/// An axis-aligned box a collider's reach lies in: a particle outside it is farther than
/// the thickness from the surface (the broad phase of the contact stage, `contact.rs`).
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

    /// The box around the segment `a–b`.
    #[inline]
    pub(super) fn segment(a: Vec3, b: Vec3) -> Self {
        Self {
            min: a.min(b),
            max: a.max(b),
        }
    }

    /// The box grown by `margin` on every side.
    pub(super) fn grown(&self, margin: f32) -> Self {
        Self {
            min: self.min - Vec3::splat(margin),
            max: self.max + Vec3::splat(margin),
        }
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
    pub(super) fn contains(&self, x: Vec3) -> bool {
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
            ColliderShape::Cylinder {
                center,
                axis,
                half_height,
                radius,
            } => {
                // Along world axis i: h |a_i| from the axis, r √(1 − a_i²) from the discs.
                let extent = axis.abs() * half_height
                    + (Vec3::ONE - axis * axis).max(Vec3::ZERO).sqrt() * radius;
                around(center - extent, center + extent, self.thickness)
            }
            ColliderShape::Convex {
                center, ref hull, ..
            } => around(center, center, hull.radius + self.thickness),
            ColliderShape::Plane { .. } => Bounds {
                min: Vec3::NEG_INFINITY,
                max: Vec3::INFINITY,
            },
        }
    }

    /// The collider where it was `tau` seconds before the step's end, swept back along
    /// its motion.
    pub fn swept_back(&self, tau: f32) -> Self {
        let m = self.motion;
        let turn = Quat::from_scaled_axis(-m.angular * tau);
        let point = |x: Vec3| m.back(turn, tau, x);
        let shape = match &self.shape {
            &ColliderShape::Sphere { center, radius } => ColliderShape::Sphere {
                center: point(center),
                radius,
            },
            &ColliderShape::Capsule { a, b, radius } => ColliderShape::Capsule {
                a: point(a),
                b: point(b),
                radius,
            },
            &ColliderShape::Cuboid {
                center,
                axes,
                half_extents,
            } => ColliderShape::Cuboid {
                center: point(center),
                axes: axes.map(|a| turn * a),
                half_extents,
            },
            &ColliderShape::Cylinder {
                center,
                axis,
                half_height,
                radius,
            } => ColliderShape::Cylinder {
                center: point(center),
                axis: turn * axis,
                half_height,
                radius,
            },
            ColliderShape::Convex {
                center,
                rotation,
                hull,
            } => ColliderShape::Convex {
                center: point(*center),
                rotation: turn * *rotation,
                hull: hull.clone(),
            },
            &ColliderShape::Plane { point: p, normal } => ColliderShape::Plane {
                point: point(p),
                normal: turn * normal,
            },
        };
        let motion = Motion {
            pivot: m.pivot - m.linear * tau,
            ..m
        };
        Self {
            shape,
            motion,
            thickness: self.thickness,
            friction: self.friction,
        }
    }

    /// How far `x` is inside the band of `thickness` around the solid (its depth below
    /// `thickness` outside the surface) and the outward normal, or `None` when it is not:
    /// [`Collider::distance`] with the square root and the normal skipped for the
    /// particles farther away (the most of them, even inside a collider's bounding box).
    #[inline]
    pub(super) fn penetration(&self, x: Vec3) -> Option<(f32, Vec3)> {
        let (d, n) = match &self.shape {
            &ColliderShape::Sphere { center, radius } => self.near_core(x - center, radius)?,
            &ColliderShape::Capsule { a, b, radius } => {
                self.near_core(x - segment_point(a, b, x), radius)?
            }
            ColliderShape::Convex {
                center,
                rotation,
                hull,
            } => {
                // The farthest face plane is never farther than the surface: past the
                // thickness there, no need of the exact distance.
                let local = rotation.inverse() * (x - *center);
                let farthest = hull.farthest_plane(local);
                if farthest.1 >= self.thickness {
                    return None;
                }
                let (d, n) = hull.distance_given(local, farthest);
                (d, *rotation * n)
            }
            _ => self.distance(x),
        };
        let depth = self.thickness - d;
        (depth > 0.0).then_some((depth, n))
    }

    /// Where the segment `start–end` first comes within `thickness` of the surface, for a
    /// `start` outside that band: the fraction of the way and the outward normal there, or
    /// `None` when it never does. Conservative advancement (Müller 2007's continuous
    /// collision for particles by sphere tracing): the signed distance never exceeds the
    /// distance to the surface, so a step of the gap along the segment cannot cross it; a
    /// plate thinner than the step is met at its near face.
    pub(super) fn sweep(&self, start: Vec3, end: Vec3) -> Option<(f32, Vec3)> {
        let path = end - start;
        let length = path.length();
        if length <= 0.0 {
            return None;
        }
        // Met within 1 µm or 1e-4 of the band (relative, for large scenes).
        let close = 1e-6 + 1e-4 * self.thickness;
        let mut t = 0.0;
        for _ in 0..48 {
            let (d, n) = self.distance(start + path * t);
            let gap = d - self.thickness;
            if gap <= close {
                return Some((t, n));
            }
            t += gap / length;
            if t >= 1.0 {
                return None;
            }
        }
        // Grazing the surface all the way: the particle stays outside (the discrete test
        // still sees where it ends).
        None
    }

    /// Signed distance from the surface (negative inside) and the outward normal at the
    /// closest surface point.
    pub fn distance(&self, x: Vec3) -> (f32, Vec3) {
        match &self.shape {
            &ColliderShape::Sphere { center, radius } => self.surface(x - center, radius),
            &ColliderShape::Capsule { a, b, radius } => {
                self.surface(x - segment_point(a, b, x), radius)
            }
            &ColliderShape::Plane { point, normal } => ((x - point).dot(normal), normal),
            &ColliderShape::Cuboid {
                center,
                axes,
                half_extents,
            } => box_distance(x - center, axes, half_extents),
            &ColliderShape::Cylinder {
                center,
                axis,
                half_height,
                radius,
            } => cylinder_distance(x - center, axis, half_height, radius),
            ColliderShape::Convex {
                center,
                rotation,
                hull,
            } => {
                let (d, n) = hull.distance(rotation.inverse() * (x - *center));
                (d, *rotation * n)
            }
        }
    }

    /// [`Self::surface`] for a sphere or capsule, `offset` being the point less the nearest
    /// point of its core, or `None` when that is past the thickness band (skipping the
    /// square root and the normal for the most particles, even inside its bounding box).
    #[inline]
    fn near_core(&self, offset: Vec3, radius: f32) -> Option<(f32, Vec3)> {
        // A relative margin of 1e-4 leaves the particles near the band's edge (those
        // pushed out to it rest there) to the exact test, so the result is the same bits.
        let reach = (radius + self.thickness).powi(2) * 1.0001;
        (offset.length_squared() < reach).then(|| self.surface(offset, radius))
    }

    /// Signed distance and outward normal of a sphere's or capsule's surface from
    /// `offset`, a point less the nearest point of the core (its centre, or the capsule's
    /// [`segment_point`]).
    #[inline]
    fn surface(&self, offset: Vec3, radius: f32) -> (f32, Vec3) {
        let normal = offset.try_normalize().unwrap_or_else(|| match self.shape {
            // (glam's `any_orthonormal_vector` takes a unit vector.)
            ColliderShape::Capsule { a, b, .. } => {
                (b - a).normalize_or(Vec3::Y).any_orthonormal_vector()
            }
            _ => Vec3::Y,
        });
        (offset.length() - radius, normal)
    }
}

/// The point of the segment `a–b` nearest `x`.
#[inline]
fn segment_point(a: Vec3, b: Vec3, x: Vec3) -> Vec3 {
    let axis = b - a;
    let t = ((x - a).dot(axis) / axis.length_squared().max(f32::MIN_POSITIVE)).clamp(0.0, 1.0);
    a + axis * t
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

/// A convex polyhedron in its own frame: its corners and its faces (each a plane and the
/// loop of corners round it), for exact signed distances: inside, minus the distance to the
/// nearest face plane; outside, the distance to the nearest point of the nearest face
/// polygon (its inside, an edge or a corner).
#[derive(Debug)]
pub struct ConvexHull {
    vertices: Vec<Vec3>,
    faces: Vec<HullFace>,
    /// The farthest corner from the origin (the bounding sphere), m.
    radius: f32,
}

#[derive(Debug, PartialEq)]
struct HullFace {
    /// Outward unit normal.
    normal: Vec3,
    /// `normal · x` on the face's plane.
    offset: f32,
    /// Its corners, in order round `normal` (counter-clockwise seen from outside).
    corners: Vec<u32>,
}

/// The same hull (one shared allocation, as placed colliders are) without comparing
/// its geometry; else the same corners and faces.
impl PartialEq for ConvexHull {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self, other)
            || (self.radius == other.radius
                && self.vertices == other.vertices
                && self.faces == other.faces)
    }
}

impl ConvexHull {
    /// A hull from its corners and, per face, its outward normal and corners (in any
    /// order). Refused: non-finite or fewer than 4 corners, fewer than 4 faces, a face
    /// with fewer than 3 corners or an index past the corners, a face whose corners are
    /// off its plane, or a corner in front of a face's plane (not convex, or a wrong
    /// normal) — each by more than 1e-4 of the hull's size.
    pub fn new(vertices: Vec<Vec3>, faces: Vec<(Vec3, Vec<u32>)>) -> Result<Self, String> {
        if vertices.len() < 4 || !vertices.iter().all(|v| v.is_finite()) {
            return Err(format!(
                "a hull needs at least 4 finite corners, got {}",
                vertices.len()
            ));
        }
        if faces.len() < 4 {
            return Err(format!(
                "a hull needs at least 4 faces, got {}",
                faces.len()
            ));
        }
        let radius = vertices.iter().map(|v| v.length()).fold(0.0, f32::max);
        let size = vertices
            .iter()
            .flat_map(|a| vertices.iter().map(move |b| a.distance(*b)))
            .fold(0.0, f32::max);
        let faces = faces.into_iter().enumerate();
        let out = faces
            .map(|(k, (normal, corners))| hull_face(&vertices, k, normal, corners, size))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            vertices,
            faces: out,
            radius,
        })
    }

    /// The face whose plane `x` is farthest in front of, and that distance (negative
    /// inside): a lower bound of the distance from the hull, exact inside.
    fn farthest_plane(&self, x: Vec3) -> (usize, f32) {
        self.faces
            .iter()
            .enumerate()
            .map(|(k, f)| (k, f.normal.dot(x) - f.offset))
            .fold((0, f32::MIN), |a, b| if b.1 > a.1 { b } else { a })
    }

    /// Signed distance from the surface and the outward normal at the nearest surface
    /// point, for `x` in the hull's frame.
    fn distance(&self, x: Vec3) -> (f32, Vec3) {
        self.distance_given(x, self.farthest_plane(x))
    }

    /// [`Self::distance`] given `x`'s [`Self::farthest_plane`].
    fn distance_given(&self, x: Vec3, (k, d): (usize, f32)) -> (f32, Vec3) {
        if d <= 0.0 {
            return (d, self.faces[k].normal);
        }
        // Outside: the nearest point of the faces `x` is in front of.
        let mut best = (f32::INFINITY, Vec3::ZERO);
        for face in &self.faces {
            let s = face.normal.dot(x) - face.offset;
            if s <= 0.0 {
                continue;
            }
            let q = x - face.normal * s;
            let corner = |j: usize| self.vertices[face.corners[j % face.corners.len()] as usize];
            let inside = (0..face.corners.len()).all(|j| {
                let (a, b) = (corner(j), corner(j + 1));
                (b - a).cross(q - a).dot(face.normal) >= 0.0
            });
            let nearest = if inside {
                q
            } else {
                (0..face.corners.len())
                    .map(|j| {
                        let (a, b) = (corner(j), corner(j + 1));
                        let t = ((x - a).dot(b - a)
                            / (b - a).length_squared().max(f32::MIN_POSITIVE))
                        .clamp(0.0, 1.0);
                        a + (b - a) * t
                    })
                    .min_by(|p, r| p.distance_squared(x).total_cmp(&r.distance_squared(x)))
                    .unwrap_or(q)
            };
            let length = nearest.distance(x);
            if length < best.0 {
                best = (length, nearest);
            }
        }
        let normal = (x - best.1).try_normalize().unwrap_or(self.faces[k].normal);
        (best.0, normal)
    }
}

/// Face `k` of a hull of `vertices` (of diameter `size`): its unit normal, its plane's
/// offset and its corners ordered round the normal; refused when it has no normal,
/// fewer than 3 corners (or one past the corners), is not flat, or has a corner in
/// front of it (see [`ConvexHull::new`]).
fn hull_face(
    vertices: &[Vec3],
    k: usize,
    normal: Vec3,
    mut corners: Vec<u32>,
    size: f32,
) -> Result<HullFace, String> {
    let Some(normal) = normal.try_normalize() else {
        return Err(format!("face {k} has no normal"));
    };
    if corners.len() < 3 || corners.iter().any(|&i| i as usize >= vertices.len()) {
        return Err(format!(
            "face {k} needs 3 or more of the {} corners",
            vertices.len()
        ));
    }
    // Order the corners round the normal, by angle about their centroid.
    let mid = corners.iter().map(|&i| vertices[i as usize]).sum::<Vec3>() / corners.len() as f32;
    let u = normal.any_orthonormal_vector();
    let w = normal.cross(u);
    let angle = |i: u32| {
        let d = vertices[i as usize] - mid;
        d.dot(w).atan2(d.dot(u))
    };
    corners.sort_by(|&a, &b| angle(a).total_cmp(&angle(b)));
    let offset = corners
        .iter()
        .map(|&i| normal.dot(vertices[i as usize]))
        .fold(f32::MIN, f32::max);
    if corners
        .iter()
        .any(|&i| offset - normal.dot(vertices[i as usize]) > 1e-4 * size)
    {
        return Err(format!("face {k} is not flat"));
    }
    if let Some(v) = vertices
        .iter()
        .find(|v| normal.dot(**v) - offset > 1e-4 * size)
    {
        return Err(format!("corner {v} is in front of face {k}: not convex"));
    }
    Ok(HullFace {
        normal,
        offset,
        corners,
    })
}

/// Signed distance from a cylinder's surface and the outward normal at the nearest surface
/// point, for `offset` from its centre: the 2D box distance in (distance from the axis,
/// height along it).
fn cylinder_distance(offset: Vec3, axis: Vec3, half_height: f32, radius: f32) -> (f32, Vec3) {
    let along = offset.dot(axis);
    let radial = offset - axis * along;
    let rho = radial.length();
    let out = radial
        .try_normalize()
        .unwrap_or_else(|| axis.any_orthonormal_vector());
    let cap = if along >= 0.0 { axis } else { -axis };
    let (dr, dh) = (rho - radius, along.abs() - half_height);
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
        (
            ColliderShape::cuboid(c, turn, half),
            points,
            Box::new(inside),
        )
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
        let shape = ColliderShape::Cylinder {
            center,
            axis,
            half_height,
            radius,
        };
        (shape, points, Box::new(inside))
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
        (
            ColliderShape::Capsule { a, b, radius },
            points,
            Box::new(inside),
        )
    }

    /// Each shape's signed distance against brute force: the distance to the nearest of
    /// dense samples of its surface (never less than the true distance, at most the
    /// sampling's spacing more), signed by the membership test. 300 points in and around
    /// each shape.
    #[test]
    fn distances_match_brute_force_sampling_of_the_surface() {
        let turn = Quat::from_euler(bevy::math::EulerRot::XYZ, 0.3, -0.5, 0.8);
        let c = Vec3::new(0.2, 1.0, -0.3);
        let cases = [
            box_case(c, turn, Vec3::new(0.4, 0.25, 0.3)),
            cylinder_case(c, turn * Vec3::Y, 0.3, 0.25),
            capsule_case(Vec3::new(-0.3, 0.9, 0.1), Vec3::new(0.4, 1.2, -0.2), 0.2),
        ];
        for (shape, surface, inside) in cases {
            let collider = Collider {
                shape,
                thickness: 0.0,
                friction: 0.0,
                motion: Motion::NONE,
            };
            for i in 0..300 {
                let q = Vec3::new(unit_hash(i, 0), unit_hash(i, 1), unit_hash(i, 2));
                let x = c + q * 0.7;
                let (d, _) = collider.distance(x);
                let brute = surface
                    .iter()
                    .map(|s| s.distance(x))
                    .fold(f32::MAX, f32::min);
                let sign = if inside(x) { -1.0 } else { 1.0 };
                assert!(
                    brute >= d.abs() - 1e-5 && brute - d.abs() < 0.012 && d * sign >= -1e-5,
                    "{:?} at {x}: {d} against {} by sampling",
                    collider.shape,
                    sign * brute
                );
            }
        }
    }
}
