//! Colliders: a solid (one of the [shapes](super::shapes)) the particles are kept out of,
//! every substep, with a thickness and Coulomb friction (position-based, as in Macklin et
//! al. 2014, "Unified particle physics for real-time applications", §6.1). A moving
//! collider carries its rigid [`Motion`]: within a step it is swept from where it was to
//! where it is, substep by substep, and friction acts on the particles' motion relative to
//! its surface, so a moving body pushes the cloth at its own speed and carries it along.

use bevy::math::{Quat, Vec3};

use super::shapes::{ColliderShape, Placement, Shape};

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
}

/// An axis-aligned box a collider's reach lies in: a particle outside it is farther than
/// the thickness from the surface (the contact stage's broad phase).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Bounds {
    min: Vec3,
    max: Vec3,
}

impl Bounds {
    /// The box around `points` (an empty box for none). Four boxes side by side, each
    /// over every fourth point, joined at the end: the same box (a minimum and a maximum
    /// do not depend on the order), where one box waited on its last comparison at every
    /// point.
    pub(crate) fn around(points: &[Vec3]) -> Self {
        let empty = Self {
            min: Vec3::INFINITY,
            max: Vec3::NEG_INFINITY,
        };
        let grow = |b: Self, x: Vec3| Self {
            min: b.min.min(x),
            max: b.max.max(x),
        };
        let quads = points.chunks_exact(4);
        let last = quads.remainder().iter().fold(empty, |b, &x| grow(b, x));
        let mut four = [empty; 4];
        for quad in quads {
            for (b, &x) in four.iter_mut().zip(quad) {
                *b = grow(*b, x);
            }
        }
        four.into_iter().fold(last, |b, q| Self {
            min: b.min.min(q.min),
            max: b.max.max(q.max),
        })
    }

    /// The box around the segment `a–b`.
    #[inline]
    pub(crate) fn segment(a: Vec3, b: Vec3) -> Self {
        Self {
            min: a.min(b),
            max: a.max(b),
        }
    }

    /// The box grown by `margin` on every side.
    pub(crate) fn grown(&self, margin: f32) -> Self {
        Self {
            min: self.min - Vec3::splat(margin),
            max: self.max + Vec3::splat(margin),
        }
    }

    /// The centre of the box and its half diagonal: a sphere around it.
    pub(crate) fn sphere(&self) -> (Vec3, f32) {
        (
            (self.min + self.max) * 0.5,
            (self.max - self.min).length() * 0.5,
        )
    }

    /// Its size along each axis.
    pub(crate) fn size(&self) -> Vec3 {
        self.max - self.min
    }

    /// Whether the two boxes share a point.
    pub(crate) fn overlaps(&self, other: &Bounds) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }

    /// Whether `x` lies in the box.
    #[inline]
    pub(crate) fn contains(&self, x: Vec3) -> bool {
        x.cmpge(self.min).all() && x.cmple(self.max).all()
    }
}

impl Collider {
    /// The box around every point within `thickness` of the solid, grown by a relative
    /// 1e-4 and a little more against rounding (a plane's is everything).
    pub(super) fn bounds(&self) -> Bounds {
        let (lo, hi) = self.shape.extent();
        let size = lo.abs().max(hi.abs()).max_element();
        let reach = self.thickness * 1.0001 + 1e-6 + size * 1e-6;
        Bounds {
            min: lo - Vec3::splat(reach),
            max: hi + Vec3::splat(reach),
        }
    }

    /// The collider where it was `tau` seconds before the step's end, swept back along
    /// its motion.
    pub fn swept_back(&self, tau: f32) -> Self {
        let m = self.motion;
        let turn = Quat::from_scaled_axis(-m.angular * tau);
        let to = m.pivot - m.linear * tau;
        Self {
            shape: self.shape.placed(&Placement::about(m.pivot, turn, to)),
            motion: Motion { pivot: to, ..m },
            thickness: self.thickness,
            friction: self.friction,
        }
    }

    /// How far `x` is inside the band of `thickness` around the solid (its depth below
    /// `thickness` outside the surface) and the outward normal, or `None` when it is not
    /// ([`Shape::distance_within`]: the square root and the normal skipped for the most
    /// particles farther away).
    #[inline]
    pub(super) fn penetration(&self, x: Vec3) -> Option<(f32, Vec3)> {
        let (d, n) = self.shape.distance_within(x, self.thickness)?;
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
    #[inline]
    pub fn distance(&self, x: Vec3) -> (f32, Vec3) {
        self.shape.distance(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The box of four boxes side by side is the box of one fold point after point, for
    /// every count of points from none to eleven (whole fours and remainders), with the
    /// extremes anywhere among them.
    #[test]
    fn the_box_around_points_is_the_fold_over_them() {
        let cloud: Vec<Vec3> = (0..11)
            .map(|k| {
                let f = k as f32;
                Vec3::new((1.7 * f).sin(), (0.9 * f).cos() * 3.0, f * (2.3 * f).sin())
            })
            .collect();
        for n in 0..=cloud.len() {
            let points = &cloud[..n];
            let (min, max) = points
                .iter()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), x| {
                    (lo.min(*x), hi.max(*x))
                });
            assert_eq!(Bounds::around(points), Bounds { min, max }, "{n} points");
        }
    }
}
