//! The XPBD model: every spring a distance constraint of compliance `α = 1/k`, solved
//! once per small substep (Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation
//! of Compliant Constrained Dynamics", MIG 2016; Macklin et al., "Small Steps in Physics
//! Simulation", SCA 2019: many substeps of one iteration each, the multipliers starting
//! from 0 every substep).
//!
//! A substep predicts every free particle from the external forces (gravity, wind,
//! drag: symplectic Euler), then projects the constraints colour by colour: a greedy
//! colouring of the spring graph puts springs that share no particle in one colour, so a
//! colour's projections do not depend on their order nor on the thread that makes them
//! (Gauss–Seidel across colours, Jacobi within). Each particle's corrections are summed
//! and its velocity takes them over `h` (as the strain limiter's, `lattice.rs`).
//!
//! Per constraint `C = |x_b − x_a| − l0`, with `α̃ = α/h²` and the paper's damping
//! `γ = α̃ β̃ / h = c / (k h)` (β̃ = h² c, c the springs' damping in N·s/m, eq. 26):
//! `Δλ = (−C − γ ∇C·(x − x_prev)) / ((1 + γ)(w_a + w_b) + α̃)` (XPBD eq. 18 and 26 with
//! λ = 0), `Δx_a = −w_a Δλ n`, `Δx_b = w_b Δλ n`. The strain limit (Provot 1995) is a
//! hard inequality on the structural and shear constraints, applied in the same
//! projection: a constraint still longer than `(1 + limit)·l0` after its compliant step
//! is shortened to it.

use std::ops::Range;

use bevy::math::Vec3;

use super::parallel::{self, PIECE};
use super::{Particles, SpringKind, Springs};

/// The order families are projected in within a substep (see [`Constraints::new`]).
const PROJECTION_ORDER: [SpringKind; 5] = [
    SpringKind::Seam,
    SpringKind::BendDiagonal,
    SpringKind::Bend,
    SpringKind::Shear,
    SpringKind::Structural,
];

/// The constraints of a cloth's springs, grouped by colour.
#[derive(Clone, Debug)]
pub(super) struct Constraints {
    /// Each constraint's spring (index into [`Springs`]), colour after colour.
    spring: Vec<u32>,
    /// Its particles, in the same order (copied so the projection reads one array).
    a: Vec<u32>,
    b: Vec<u32>,
    /// The family and the constraints of each colour.
    colours: Vec<(u8, Range<usize>)>,
    /// The springs this was built for (a new cloth or layout rebuilds it).
    pub built_for: usize,
    /// Corrections made in this substep, summed per particle (zero between substeps).
    dx: Vec<Vec3>,
}

/// What one family's constraints take in a substep.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Family {
    /// Whether its constraints act (the family is on with a stiffness > 0).
    pub on: bool,
    /// `α̃ = 1/(k h²)` (0 for `k = inf`).
    pub compliance: f32,
    /// `γ = c/(k h)` (0 without damping or for `k = inf`).
    pub damping: f32,
    /// `1 + limit` for a strain-limited family, `inf` otherwise.
    pub max_stretch: f32,
}

impl Family {
    /// The coefficients of a family of stiffness `k`, spring damping `c`, substep `h`.
    pub fn new(k: f32, c: f32, h: f32, limit: Option<f32>) -> Self {
        let (compliance, damping) = if k == f32::INFINITY {
            (0.0, 0.0)
        } else {
            (1.0 / (k * h * h), c / (k * h))
        };
        Self {
            on: k > 0.0,
            compliance,
            damping,
            max_stretch: limit.map_or(f32::INFINITY, |l| 1.0 + l),
        }
    }
}

impl Constraints {
    /// Colours the springs greedily (first fit, by first particle) one family at a time,
    /// so no two springs of a colour share a particle and every colour is of one family.
    /// The families are projected in the order [`PROJECTION_ORDER`]: what is projected
    /// last is met best after the one iteration, so the structural springs (and their
    /// strain limit) come last, after the seams that pull against them.
    pub fn new(springs: &Springs, n: usize) -> Self {
        // Each particle's springs (CSR), to find the colours already taken around a spring.
        let mut start = vec![0u32; n + 1];
        for s in 0..springs.len() {
            start[springs.a[s] as usize + 1] += 1;
            start[springs.b[s] as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut incident = vec![0u32; start[n] as usize];
        for s in 0..springs.len() {
            for p in [springs.a[s], springs.b[s]] {
                incident[fill[p as usize] as usize] = s as u32;
                fill[p as usize] += 1;
            }
        }
        let mut colour = vec![u32::MAX; springs.len()];
        let mut taken: Vec<bool> = Vec::new();
        let mut first = 0usize; // the family's first colour
        let mut count = 0usize;
        for kind in PROJECTION_ORDER {
            for s in springs.ranges[kind as usize].clone() {
                taken.iter_mut().for_each(|t| *t = false);
                for p in [springs.a[s], springs.b[s]] {
                    let p = p as usize;
                    for &t in &incident[start[p] as usize..start[p + 1] as usize] {
                        let c = colour[t as usize] as usize;
                        if let Some(slot) = c.checked_sub(first).and_then(|c| taken.get_mut(c)) {
                            *slot = true;
                        }
                    }
                }
                let c = taken.iter().position(|&t| !t).unwrap_or(taken.len());
                if c == taken.len() {
                    taken.push(false);
                    count += 1;
                }
                colour[s] = (first + c) as u32;
            }
            first = count;
            taken.clear();
        }
        // Constraints colour by colour, each colour in storage order.
        let mut order: Vec<u32> = (0..springs.len() as u32).collect();
        order.sort_by_key(|&s| (colour[s as usize], s));
        let mut colours = Vec::with_capacity(count);
        let mut from = 0;
        for c in 0..count as u32 {
            let to = from + order[from..].partition_point(|&s| colour[s as usize] == c);
            colours.push((springs.kind(order[from] as usize) as u8, from..to));
            from = to;
        }
        let constraints = Self {
            a: order.iter().map(|&s| springs.a[s as usize]).collect(),
            b: order.iter().map(|&s| springs.b[s as usize]).collect(),
            spring: order,
            colours,
            built_for: springs.len(),
            dx: vec![Vec3::ZERO; n],
        };
        debug_assert!(constraints.colours_are_disjoint(n));
        constraints
    }

    /// Whether no two constraints of a colour share a particle (what lets a colour's
    /// pieces write particles from several threads).
    pub fn colours_are_disjoint(&self, n: usize) -> bool {
        let mut seen = vec![usize::MAX; n];
        for (c, (_, range)) in self.colours.iter().enumerate() {
            for k in range.clone() {
                for p in [self.a[k], self.b[k]] {
                    if seen[p as usize] == c {
                        return false;
                    }
                    seen[p as usize] = c;
                }
            }
        }
        true
    }

    /// Projects every constraint once, colour by colour, then gives each particle's
    /// velocity its summed correction over `h`. `families` by [`SpringKind`]; the
    /// springs' rest lengths and alive flags are read as they are now (seams sewing).
    ///
    /// One thread: the crate forbids `unsafe`, and a colour's constraints reach particles
    /// all over the arrays, so its pieces cannot be handed out as disjoint slices. The
    /// colours still make the result independent of the order within each.
    pub fn project(
        &mut self,
        p: &mut Particles,
        springs: &Springs,
        families: &[Family; 5],
        h: f32,
    ) {
        let damped = families.iter().any(|f| f.on && f.damping > 0.0);
        let (x, dx) = (&mut p.position, &mut self.dx);
        let (previous, inv_mass) = (&p.previous, &p.inv_mass);
        for (kind, range) in &self.colours {
            let family = &families[*kind as usize];
            if !family.on {
                continue;
            }
            let constraints = self.spring[range.clone()]
                .iter()
                .zip(self.a[range.clone()].iter().zip(&self.b[range.clone()]));
            for (&s, (&a, &b)) in constraints {
                let (s, a, b) = (s as usize, a as usize, b as usize);
                if !springs.alive[s] {
                    continue;
                }
                let (wa, wb) = (inv_mass[a], inv_mass[b]);
                let relative = || (x[b] - previous[b]) - (x[a] - previous[a]);
                let d = x[b] - x[a];
                let rest = springs.rest_length[s];
                let Some(lambda) = family.multiplier(d, rest, wa + wb, damped.then(relative))
                else {
                    continue;
                };
                let normal = d.normalize();
                let (ca, cb) = (normal * (wa * lambda), normal * (wb * lambda));
                x[a] -= ca;
                x[b] += cb;
                dx[a] -= ca;
                dx[b] += cb;
            }
        }
        let pieces = p.velocity.chunks_mut(PIECE).zip(dx.chunks_mut(PIECE));
        parallel::for_each(p.position.len(), pieces, |(velocity, dx)| {
            for (v, d) in velocity.iter_mut().zip(dx) {
                *v += *d / h;
                *d = Vec3::ZERO;
            }
        });
    }
}

impl Family {
    /// The multiplier change `Δλ` of a constraint along `d = x_b − x_a` of rest length
    /// `rest`, summed inverse mass `w`, and (when damped) relative motion this substep
    /// (module doc); `None` when it cannot act (both ends held, or no direction).
    #[inline(always)]
    fn multiplier(&self, d: Vec3, rest: f32, w: f32, relative: Option<Vec3>) -> Option<f32> {
        let len = d.length();
        if w == 0.0 || len <= f32::EPSILON * rest.max(1.0) {
            return None;
        }
        let c = len - rest;
        let mut lambda = match relative {
            Some(relative) if self.damping > 0.0 => {
                let gamma = self.damping;
                let along = d.dot(relative) / len;
                (-c - gamma * along) / ((1.0 + gamma) * w + self.compliance)
            }
            _ => -c / (w + self.compliance),
        };
        // The strain limit: what the compliant step leaves past `(1 + limit)·l0`.
        let max = self.max_stretch * rest;
        let after = len + w * lambda;
        if after > max {
            lambda += (max - after) / w;
        }
        Some(lambda)
    }
}
