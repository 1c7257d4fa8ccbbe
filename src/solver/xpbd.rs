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

/// A colour goes to the compute pool from this many pieces (16,384 constraints) on: a
/// colour's two fork-joins cost about 20 µs, and at 16,384 particles (colours of about
/// 8,000 constraints) the pool made a step slower (40 against 29.5 ms per step at 20
/// substeps, `cloth run` with and without `--one-thread`); at 65,536 it is 1.37× faster.
const PARALLEL_PIECES: usize = 8;

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
    /// Its rest length, synced once per step.
    rest: Vec<f32>,
    /// The inverse masses of its ends (0 for a torn spring), and `1/(w_a + w_b)` (0
    /// when both are 0), synced once per step.
    wa: Vec<f32>,
    wb: Vec<f32>,
    inv_w: Vec<f32>,
    /// `1/((1 + γ) w + α̃)` of its family in the substep (0 when `w` is 0), computed
    /// when the families' coefficients change ([`Self::project`]).
    scale: Vec<f32>,
    /// The coefficients `scale` was computed for.
    scaled_for: Option<[Family; 5]>,
    /// The colours, in projection order.
    colours: Vec<Colour>,
    /// Corrections made in this substep, summed per particle (zero between substeps).
    dx: Vec<Vec3>,
}

/// What one family's constraints take in a substep.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
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
    /// Call [`Self::sync`] before projecting.
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
        let a: Vec<u32> = order.iter().map(|&s| springs.a[s as usize]).collect();
        let b: Vec<u32> = order.iter().map(|&s| springs.b[s as usize]).collect();
        let colours = colours
            .into_iter()
            .map(|(kind, range)| Colour::new(kind, range, &a, &b))
            .collect();
        let m = order.len();
        let constraints = Self {
            rest: vec![0.0; m],
            wa: vec![0.0; m],
            wb: vec![0.0; m],
            inv_w: vec![0.0; m],
            scale: vec![0.0; m],
            scaled_for: None,
            a,
            b,
            spring: order,
            colours,
            dx: vec![Vec3::ZERO; n],
        };
        debug_assert!(constraints.colours_are_disjoint(n));
        constraints
    }

    /// Whether no two constraints of a colour share a particle (what makes a colour's
    /// result independent of the order and the thread its constraints are projected on).
    pub fn colours_are_disjoint(&self, n: usize) -> bool {
        let mut seen = vec![usize::MAX; n];
        for (c, colour) in self.colours.iter().enumerate() {
            for k in colour.pieces.iter().flat_map(Clone::clone) {
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

    /// Takes the springs' rest lengths (seams change theirs while sewn), alive flags and
    /// the particles' inverse masses (pins, mass edits); called once per step, before
    /// its substeps.
    pub fn sync(&mut self, springs: &Springs, inv_mass: &[f32]) {
        let ends = self.spring.iter().zip(self.a.iter().zip(&self.b));
        let out = self
            .rest
            .iter_mut()
            .zip(self.wa.iter_mut().zip(&mut self.wb))
            .zip(&mut self.inv_w);
        for (((rest, (wa, wb)), inv_w), (&s, (&a, &b))) in out.zip(ends) {
            let alive = f32::from(u8::from(springs.alive[s as usize]));
            *rest = springs.rest_length[s as usize];
            (*wa, *wb) = (inv_mass[a as usize] * alive, inv_mass[b as usize] * alive);
            let w = *wa + *wb;
            *inv_w = if w > 0.0 { 1.0 / w } else { 0.0 };
        }
        self.scaled_for = None;
    }

    /// Each constraint's `1/((1 + γ) w + α̃)` for `families`, unless already computed.
    fn rescale(&mut self, families: &[Family; 5]) {
        if self.scaled_for.as_ref() == Some(families) {
            return;
        }
        for colour in &self.colours {
            let f = families[colour.kind as usize];
            for k in colour.pieces.iter().flat_map(Clone::clone) {
                let w = self.wa[k] + self.wb[k];
                let denominator = (1.0 + f.damping) * w + f.compliance;
                self.scale[k] = if w > 0.0 { 1.0 / denominator } else { 0.0 };
            }
        }
        self.scaled_for = Some(*families);
    }

    /// Projects every constraint once, colour by colour, then gives each particle's
    /// velocity its summed correction over `h`. `families` by [`SpringKind`].
    ///
    /// A colour's pieces (`PIECE` constraints each, sorted by first particle) reach the
    /// particles between their first particle and their last: where those windows of
    /// pieces two apart do not overlap (grids), the even pieces run side by side on the
    /// compute pool, each on its own slice of the particles, then the odd ones; other
    /// colours run on this thread. The same bits either way: a colour's constraints
    /// share no particle.
    pub fn project(&mut self, p: &mut Particles, families: &[Family; 5], h: f32) {
        self.rescale(families);
        let n = p.len();
        let (x, dx) = (&mut p.position[..], &mut self.dx[..]);
        let previous = &p.previous[..];
        for colour in &self.colours {
            let family = families[colour.kind as usize];
            if !family.on {
                continue;
            }
            let piece = |k: usize| {
                let range = colour.pieces[k].clone();
                Piece {
                    a: &self.a[range.clone()],
                    b: &self.b[range.clone()],
                    rest: &self.rest[range.clone()],
                    wa: &self.wa[range.clone()],
                    wb: &self.wb[range.clone()],
                    inv_w: &self.inv_w[range.clone()],
                    scale: &self.scale[range],
                }
            };
            if !colour.windowed || colour.pieces.len() < PARALLEL_PIECES {
                for k in 0..colour.pieces.len() {
                    project_piece(piece(k), (&mut *x, &mut *dx, 0), previous, family);
                }
                continue;
            }
            for parity in 0..2 {
                let windows = Windows {
                    x: &mut *x,
                    dx: &mut *dx,
                    at: 0,
                    bounds: &colour.windows,
                    next: parity,
                };
                let pieces = windows.map(|(k, x, dx, offset)| (piece(k), x, dx, offset));
                parallel::for_each(n, pieces, |(piece, x, dx, offset)| {
                    project_piece(piece, (x, dx, offset), previous, family);
                });
            }
        }
        let pieces = p.velocity.chunks_mut(PIECE).zip(self.dx.chunks_mut(PIECE));
        parallel::for_each(n, pieces, |(velocity, dx)| {
            for (v, d) in velocity.iter_mut().zip(dx) {
                *v += *d / h;
                *d = Vec3::ZERO;
            }
        });
    }
}

/// One colour: its family, its pieces of constraints, and the particles each piece
/// reaches.
#[derive(Clone, Debug)]
struct Colour {
    kind: u8,
    /// Constraint ranges of `PIECE` (the last shorter).
    pieces: Vec<Range<usize>>,
    /// For each piece, the first and last particle it reaches.
    windows: Vec<(usize, usize)>,
    /// Whether the windows of pieces two apart never overlap (each parity's pieces can
    /// then have disjoint slices of the particles).
    windowed: bool,
}

impl Colour {
    fn new(kind: u8, range: Range<usize>, a: &[u32], b: &[u32]) -> Self {
        let pieces: Vec<Range<usize>> = range
            .clone()
            .step_by(PIECE)
            .map(|from| from..(from + PIECE).min(range.end))
            .collect();
        let windows: Vec<(usize, usize)> = pieces
            .iter()
            .map(|r| {
                let ends = a[r.clone()]
                    .iter()
                    .chain(&b[r.clone()])
                    .map(|&i| i as usize);
                let lo = ends.clone().min().unwrap_or(0);
                (lo, ends.max().unwrap_or(0))
            })
            .collect();
        let windowed = windows
            .windows(3)
            .all(|w| w[0].1 < w[2].0 && w[0].0 <= w[2].0);
        Self {
            kind,
            pieces,
            windows,
            windowed,
        }
    }
}

/// The pieces of one parity in order, each with its own slice of the particles
/// (`x[lo..=hi]`, `dx[lo..=hi]`) and `lo`.
struct Windows<'a, 'w> {
    x: &'a mut [Vec3],
    dx: &'a mut [Vec3],
    /// The particle index `x[0]` is.
    at: usize,
    bounds: &'w [(usize, usize)],
    next: usize,
}

impl<'a> Iterator for Windows<'a, '_> {
    type Item = (usize, &'a mut [Vec3], &'a mut [Vec3], usize);

    fn next(&mut self) -> Option<Self::Item> {
        let k = self.next;
        let &(lo, hi) = self.bounds.get(k)?;
        self.next += 2;
        let x = std::mem::take(&mut self.x);
        let dx = std::mem::take(&mut self.dx);
        let (x, dx) = (&mut x[lo - self.at..], &mut dx[lo - self.at..]);
        let (window, x) = x.split_at_mut(hi + 1 - lo);
        let (window_dx, dx) = dx.split_at_mut(hi + 1 - lo);
        (self.x, self.dx, self.at) = (x, dx, hi + 1);
        Some((k, window, window_dx, lo))
    }
}

/// One piece of a colour's constraints (see [`Constraints`]).
#[derive(Clone, Copy)]
struct Piece<'a> {
    a: &'a [u32],
    b: &'a [u32],
    rest: &'a [f32],
    wa: &'a [f32],
    wb: &'a [f32],
    inv_w: &'a [f32],
    scale: &'a [f32],
}

/// Projects a piece's constraints (module doc) on positions and summed corrections
/// `x`, `dx` that start at particle `offset`; `previous`: all positions at the start of
/// the substep.
#[inline(always)]
fn project_piece(
    piece: Piece<'_>,
    (x, dx, offset): (&mut [Vec3], &mut [Vec3], usize),
    previous: &[Vec3],
    family: Family,
) {
    let (gamma, max_stretch) = (family.damping, family.max_stretch);
    let damped = gamma > 0.0;
    let constraints = piece
        .a
        .iter()
        .zip(piece.b)
        .zip(piece.rest.iter().zip(piece.scale))
        .zip(piece.wa.iter().zip(piece.wb).zip(piece.inv_w));
    for (((&a, &b), (&rest, &scale)), ((&wa, &wb), &inv_w)) in constraints {
        let (a, b) = (a as usize, b as usize);
        let (la, lb) = (a - offset, b - offset);
        let d = x[lb] - x[la];
        let len = d.length();
        // No direction to push along (coincident ends): nothing.
        let inv_len = if len > f32::EPSILON * rest.max(1.0) {
            1.0 / len
        } else {
            0.0
        };
        let c = len - rest;
        let lambda = if damped {
            let relative = (x[lb] - previous[b]) - (x[la] - previous[a]);
            (-c - gamma * d.dot(relative) * inv_len) * scale
        } else {
            -c * scale
        };
        // The strain limit: no longer than `max_stretch · l0` after the step (`inf` for a
        // family without one: nothing). A held or torn constraint has `w = 0`: no move.
        let lambda = lambda.min((max_stretch * rest - len) * inv_w);
        let correction = d * (lambda * inv_len);
        let (ca, cb) = (correction * wa, correction * wb);
        x[la] -= ca;
        x[lb] += cb;
        dx[la] -= ca;
        dx[lb] += cb;
    }
}
