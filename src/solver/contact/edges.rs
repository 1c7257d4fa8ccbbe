//! Thin colliders: the cloth's edges kept out of capsules and cylinders thinner than
//! them, which slip between its particles (a rope, a pole).

use bevy::math::Vec3;

use super::shapes::Shape;
use super::{Bounds, Collider, Contact};
use crate::solver::state::mark;
use crate::solver::{Particles, SpringKind, Springs};

impl Contact {
    /// Keeps the cloth's edges (its structural and shear springs) out of the capsules and
    /// cylinders thinner than them, which slip between particles: each edge that comes
    /// within `radius + thickness` of such a collider's axis is pushed out along the
    /// closest points' line, the correction shared by its two particles by their
    /// barycentric weight and inverse mass (the position-based edge constraint), back to
    /// the side the edge came from, with Coulomb friction and no energy added. A rope or
    /// a pole across the cloth holds it. Runs after [`Contact::resolve`]; the ends of
    /// each edge it moves are marked in `touched`.
    pub fn resolve_edges(
        &mut self,
        p: &mut Particles,
        springs: &Springs,
        h: f32,
        touched: &mut [bool],
    ) {
        if self.thin.is_empty() {
            return;
        }
        let colliders = if self.colliders_move {
            &self.colliders_now
        } else {
            &self.colliders
        };
        let edges = EDGES.map(|kind| springs.ranges[kind as usize].clone());
        for &k in &self.thin {
            let c = &colliders[k];
            let Some((a, b, reach)) = axis(c) else {
                continue;
            };
            let rope = Rope {
                a,
                b,
                reach,
                friction: c.friction,
                bounds: Bounds::segment(a, b).grown(reach),
            };
            for range in edges.iter() {
                for s in range.clone() {
                    if !springs.alive[s] {
                        continue;
                    }
                    let ends = (springs.a[s] as usize, springs.b[s] as usize);
                    if let Some((impulse, at)) = rope.push_edge(p, ends, h) {
                        mark(touched, ends.0);
                        mark(touched, ends.1);
                        self.collider_impulses[k].linear -= impulse;
                        self.collider_impulses[k].angular -= at.cross(impulse);
                    }
                }
            }
        }
    }
}

/// A thin collider as the edge pass meets it: its axis `a–b`, its reach (radius plus
/// thickness), its friction and the box of everything within reach.
struct Rope {
    a: Vec3,
    b: Vec3,
    reach: f32,
    friction: f32,
    bounds: Bounds,
}

impl Rope {
    /// Keeps the edge between particles `i` and `j` out of the rope (see
    /// [`Contact::resolve_edges`]): the reaction the rope takes (`m Δx / h` of both ends)
    /// and the point it acts at, or `None` when the edge does not touch it.
    fn push_edge(&self, p: &mut Particles, (i, j): (usize, usize), h: f32) -> Option<(Vec3, Vec3)> {
        let (wi, wj) = (p.inv_mass[i], p.inv_mass[j]);
        let (xi, xj) = (p.position[i], p.position[j]);
        let (pi, pj) = (p.previous[i], p.previous[j]);
        // The box of the edge over the substep (it may have crossed the rope).
        let swept = Bounds::around(&[xi, xj, pi, pj]);
        if wi + wj == 0.0 || !swept.overlaps(&self.bounds) {
            return None;
        }
        let (t, on_axis) = closest_points(xi, xj, self.a, self.b);
        let on_edge = xi.lerp(xj, t);
        let (t0, on_axis0) = closest_points(pi, pj, self.a, self.b);
        let (n, depth) = self.out_of(on_edge - on_axis, pi.lerp(pj, t0) - on_axis0)?;
        // The point at `t` moves out by the depth: each end by its weight.
        let (bi, bj) = (1.0 - t, t);
        let w = bi * bi * wi + bj * bj * wj;
        if w <= 0.0 {
            return None;
        }
        let lambda = depth / w;
        // Coulomb friction at the edge's point, once, from this push: its motion across
        // the rope over the substep less up to `friction × depth` (as for particles,
        // Müller 2007), shared as the push is.
        let moved = (xi - pi) * bi + (xj - pj) * bj;
        let across = moved - n * moved.dot(n);
        let (slide, grip) = (across.length(), self.friction * depth);
        let held = -across * if slide <= grip { 1.0 } else { grip / slide };
        for (x, weight, inv) in [(i, bi, wi), (j, bj, wj)] {
            p.position[x] += held * (weight * inv / w);
            let push = lambda * weight * inv;
            // Inelastic, and never adding energy: the part of the push beyond the end's
            // own approach over the substep moves its `previous` too (an overlap left
            // from before is undone, not turned into a bounce).
            let approach = (-(p.position[x] - p.previous[x]).dot(n)).max(0.0);
            p.position[x] += n * push;
            p.previous[x] += n * (push - approach).max(0.0);
            p.velocity[x] = (p.position[x] - p.previous[x]) / h;
        }
        Some(((n * lambda + held / w) * ((bi + bj) / h), on_edge))
    }

    /// The way out and the depth of an edge point at `offset` from the axis that was at
    /// `before` at the start of the substep, or `None` when it is clear. An edge that
    /// crossed the axis in one substep (fast, edge-first, or pulled through by its
    /// springs) is sent back to the side it came from (clear of the rope, or resting on
    /// it), not on through, where the closest points' line alone would send it.
    fn out_of(&self, offset: Vec3, before: Vec3) -> Option<(Vec3, f32)> {
        let d = offset.length();
        let came_from = before.try_normalize();
        match came_from {
            Some(n) if offset.dot(n) < 0.0 => Some((n, self.reach - offset.dot(n))),
            _ if d >= self.reach => None,
            _ => {
                let n = offset.try_normalize().or(came_from).unwrap_or_else(|| {
                    (self.b - self.a)
                        .normalize_or(Vec3::X)
                        .any_orthonormal_vector()
                });
                Some((n, self.reach - d))
            }
        }
    }
}

/// The springs the edge pass keeps out of thin colliders.
pub(in crate::solver) const EDGES: [SpringKind; 2] = [SpringKind::Structural, SpringKind::Shear];

/// A thin solid's axis (a capsule's, a cylinder's: [`Shape::axis`]) and its reach
/// (radius plus thickness), or `None` for another shape.
pub(super) fn axis(c: &Collider) -> Option<(Vec3, Vec3, f32)> {
    let (a, b, radius) = c.shape.axis()?;
    Some((a, b, radius + c.thickness))
}

/// The closest points of the segments `p–q` and `a–b`: the fraction along `p–q` and the
/// point of `a–b` (Ericson, *Real-Time Collision Detection*, §5.1.9).
fn closest_points(p: Vec3, q: Vec3, a: Vec3, b: Vec3) -> (f32, Vec3) {
    let (d1, d2, r) = (q - p, b - a, p - a);
    let (l1, l2, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    let tiny = f32::MIN_POSITIVE;
    if l1 <= tiny {
        let u = (f / l2.max(tiny)).clamp(0.0, 1.0);
        return (0.0, a + d2 * u);
    }
    let c = d1.dot(r);
    let (s, u) = if l2 <= tiny {
        ((-c / l1).clamp(0.0, 1.0), 0.0)
    } else {
        let e = d1.dot(d2);
        let denom = l1 * l2 - e * e;
        let mut s = if denom > tiny {
            ((e * f - c * l2) / denom).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let mut u = (e * s + f) / l2;
        if u < 0.0 {
            u = 0.0;
            s = (-c / l1).clamp(0.0, 1.0);
        } else if u > 1.0 {
            u = 1.0;
            s = ((e - c) / l1).clamp(0.0, 1.0);
        }
        (s, u)
    };
    (s, a + d2 * u)
}
