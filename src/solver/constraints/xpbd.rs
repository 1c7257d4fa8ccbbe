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
//! (Gauss–Seidel across colours, Jacobi within). Each particle's velocity then takes its
//! change from the predicted position over `h`. A grid cloth is projected by the same
//! formula ([`correction`]) on its stencil instead (`lattice/xpbd.rs`), with no index
//! lists.
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

use crate::solver::chains::Chains;
use crate::solver::parallel::{self, CHUNK};
use crate::solver::tethers::Tethers;
use crate::solver::{Particles, SpringKind, Springs};

/// A colour goes to the compute pool from this many pieces (16,384 constraints) on: a
/// colour's two fork-joins cost about 20 µs, and at 16,384 particles (colours of about
/// 8,000 constraints) the pool made a step slower (40 against 29.5 ms per step at 20
/// substeps, `cloth run` with and without `--one-thread`); at 65,536 it is 1.37× faster.
const PARALLEL_PIECES: usize = 8;

/// The order families are projected in within a substep (see [`Constraints::new`]).
pub(in crate::solver) const PROJECTION_ORDER: [SpringKind; 5] = [
    SpringKind::Seam,
    SpringKind::BendDiagonal,
    SpringKind::Bend,
    SpringKind::Shear,
    SpringKind::Structural,
];

/// The constraints of a cloth's springs, grouped by colour.
#[derive(Clone, Debug, Default)]
pub(in crate::solver) struct Constraints {
    /// Each constraint's spring (index into [`Springs`]), colour after colour.
    spring: Vec<u32>,
    /// Its particles, in the same order (copied so the projection reads one array).
    a: Vec<u32>,
    b: Vec<u32>,
    /// Its rest length, synced once per step.
    rest: Vec<f32>,
    /// 1 while its spring is whole, 0 once torn; synced once per step.
    alive: Vec<f32>,
    /// The colours, in projection order.
    colours: Vec<Colour>,
    /// The positions predicted for this substep, before any projection (for the
    /// velocity).
    predicted: Vec<Vec3>,
    /// Long-range attachments to the pins (`tethers.rs`), projected after the colours.
    pub tethers: Tethers,
    /// The structural constraints as chains, solved exactly along each
    /// (`chains.rs`; [`XpbdSolve::Lines`](crate::params::XpbdSolve::Lines)).
    pub chains: Chains,
    /// A fabric's hinges are projected once every this many substeps of the step, set
    /// when it begins (`steps/xpbd.rs`).
    pub hinge_every: u32,
}

/// What one family's constraints take in a substep.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(in crate::solver) struct Family {
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
    /// A family that is only its strain limit: no stiffness of its own (infinite
    /// compliance), a finite `max_stretch`. Projected, it moves only what is past the
    /// limit.
    pub fn limit_only(&self) -> bool {
        self.on && self.compliance == f32::INFINITY && self.max_stretch.is_finite()
    }

    /// The strain limit `max_stretch` alone ([`Family::limit_only`]).
    pub fn limit(max_stretch: f32) -> Self {
        Self {
            on: true,
            compliance: f32::INFINITY,
            damping: 0.0,
            max_stretch,
        }
    }

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
    /// Call [`Self::sync`] before projecting. Not `general`: no constraint lists (a
    /// grid's are projected on its stencil), only the tethers.
    pub fn new(springs: &Springs, n: usize, general: bool) -> Self {
        if !general {
            return Self::default();
        }
        let (colour, count) = greedy_colours(springs, n);
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
            alive: vec![0.0; m],
            a,
            b,
            spring: order,
            colours,
            predicted: Vec::with_capacity(n),
            tethers: Tethers::default(),
            chains: Chains::default(),
            hinge_every: 1,
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

    /// Takes the springs' rest lengths (seams change theirs while sewn) and alive flags;
    /// called once per step, before its substeps.
    pub fn sync(&mut self, springs: &Springs) {
        let out = self.rest.iter_mut().zip(&mut self.alive);
        for ((rest, alive), &s) in out.zip(&self.spring) {
            *rest = springs.rest_length[s as usize];
            *alive = f32::from(u8::from(springs.alive[s as usize]));
        }
    }

    /// Projects every constraint once, colour by colour, then gives each particle its
    /// change from the predicted position as velocity over `h`. `families` by
    /// [`SpringKind`].
    ///
    /// A colour's pieces (`CHUNK` constraints each, sorted by first particle) reach the
    /// particles between their first particle and their last: where those windows of
    /// pieces two apart do not overlap (grids), the even pieces run side by side on the
    /// compute pool, each on its own slice of the particles, then the odd ones; other
    /// colours run on this thread. The same bits either way: a colour's constraints
    /// share no particle.
    pub fn project(&mut self, p: &mut Particles, families: &[Family; 5], h: f32) {
        let n = p.len();
        self.predicted.clear();
        self.predicted.extend_from_slice(&p.position);
        let (x, inv_mass) = (&mut p.position[..], &p.inv_mass[..]);
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
                    alive: &self.alive[range],
                }
            };
            let damped = family.damping > 0.0;
            let limited = family.max_stretch.is_finite();
            let project = |piece, x: &mut [Vec3], offset| match (damped, limited) {
                (false, false) => {
                    project_piece::<false, false>(piece, (x, offset), previous, inv_mass, family)
                }
                (false, true) => {
                    project_piece::<false, true>(piece, (x, offset), previous, inv_mass, family)
                }
                (true, false) => {
                    project_piece::<true, false>(piece, (x, offset), previous, inv_mass, family)
                }
                (true, true) => {
                    project_piece::<true, true>(piece, (x, offset), previous, inv_mass, family)
                }
            };
            if !colour.windowed || colour.pieces.len() < PARALLEL_PIECES {
                for k in 0..colour.pieces.len() {
                    project(piece(k), &mut *x, 0);
                }
                continue;
            }
            for parity in 0..2 {
                let windows = Windows {
                    x: &mut *x,
                    at: 0,
                    bounds: &colour.windows,
                    next: parity,
                };
                let pieces = windows.map(|(k, x, offset)| (piece(k), x, offset));
                parallel::for_each(n, pieces, |(piece, x, offset)| project(piece, x, offset));
            }
        }
        store_velocity(p, &self.predicted, h);
    }
}

/// Each particle's velocity takes its change from the predicted position over `h`.
fn store_velocity(p: &mut Particles, predicted: &[Vec3], h: f32) {
    let n = p.len();
    let pieces = p
        .velocity
        .chunks_mut(CHUNK)
        .zip(p.position.chunks(CHUNK))
        .zip(predicted.chunks(CHUNK));
    parallel::for_each(n, pieces, |((velocity, x), predicted)| {
        for ((v, x), predicted) in velocity.iter_mut().zip(x).zip(predicted) {
            *v += (*x - *predicted) / h;
        }
    });
}

/// Each spring's colour, greedily (the first free around it) family by family in
/// [`PROJECTION_ORDER`], so no two springs of a colour share a particle and every colour
/// is of one family; and the number of colours.
fn greedy_colours(springs: &Springs, n: usize) -> (Vec<u32>, usize) {
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
    (colour, count)
}

/// XPBD's step for one distance constraint of family `f` (module doc) whose ends are
/// `len` apart, of rest length `rest`, with inverse masses summing to `w` (0: torn or
/// held at both ends) and, for damping, `approach = d·((x_b − x_b,prev) − (x_a −
/// x_a,prev))` with `d = x_b − x_a`: the factor `s` of `d` with `Δx_a = −s w_a d` and
/// `Δx_b = s w_b d`. `DAMPED`, `LIMITED`: whether the family has damping, a strain limit
/// (chosen once per colour, not per constraint).
#[inline(always)]
pub(in crate::solver) fn correction<const DAMPED: bool, const LIMITED: bool>(
    len: f32,
    rest: f32,
    w: f32,
    approach: f32,
    f: Family,
) -> f32 {
    // No direction to push along (coincident ends): nothing.
    let inv_len = if len > f32::EPSILON * rest.max(1.0) {
        1.0 / len
    } else {
        0.0
    };
    let scale = if w > 0.0 {
        1.0 / ((1.0 + f.damping) * w + f.compliance)
    } else {
        0.0
    };
    let c = len - rest;
    let mut delta_lambda = if DAMPED {
        (-c - f.damping * approach * inv_len) * scale
    } else {
        -c * scale
    };
    if LIMITED {
        // The strain limit: no longer than `max_stretch · l0` after the step.
        let inv_w = if w > 0.0 { 1.0 / w } else { 0.0 };
        delta_lambda = delta_lambda.min((f.max_stretch * rest - len) * inv_w);
    }
    delta_lambda * inv_len
}

/// One colour: its family, its pieces of constraints, and the particles each piece
/// reaches.
#[derive(Clone, Debug)]
struct Colour {
    kind: u8,
    /// Constraint ranges of `CHUNK` (the last shorter).
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
            .step_by(CHUNK)
            .map(|from| from..(from + CHUNK).min(range.end))
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
/// (`x[lo..=hi]`) and `lo`.
struct Windows<'a, 'w> {
    x: &'a mut [Vec3],
    /// The particle index `x[0]` is.
    at: usize,
    bounds: &'w [(usize, usize)],
    next: usize,
}

impl<'a> Iterator for Windows<'a, '_> {
    type Item = (usize, &'a mut [Vec3], usize);

    fn next(&mut self) -> Option<Self::Item> {
        let k = self.next;
        let &(lo, hi) = self.bounds.get(k)?;
        self.next += 2;
        let x = std::mem::take(&mut self.x);
        let (window, x) = x[lo - self.at..].split_at_mut(hi + 1 - lo);
        (self.x, self.at) = (x, hi + 1);
        Some((k, window, lo))
    }
}

/// One piece of a colour's constraints (see [`Constraints`]).
#[derive(Clone, Copy)]
struct Piece<'a> {
    a: &'a [u32],
    b: &'a [u32],
    rest: &'a [f32],
    alive: &'a [f32],
}

/// Projects a piece's constraints ([`correction`]) on positions `x` that start at
/// particle `offset`; `previous`: all positions at the start of the substep, `inv_mass`
/// all inverse masses.
#[inline(always)]
fn project_piece<const DAMPED: bool, const LIMITED: bool>(
    piece: Piece<'_>,
    (x, offset): (&mut [Vec3], usize),
    previous: &[Vec3],
    inv_mass: &[f32],
    family: Family,
) {
    for k in 0..piece.a.len() {
        let (a, b) = (piece.a[k] as usize, piece.b[k] as usize);
        let (la, lb) = (a - offset, b - offset);
        let d = x[lb] - x[la];
        let (wa, wb) = (inv_mass[a] * piece.alive[k], inv_mass[b] * piece.alive[k]);
        let approach = if DAMPED {
            d.dot((x[lb] - previous[b]) - (x[la] - previous[a]))
        } else {
            0.0
        };
        let s = correction::<DAMPED, LIMITED>(d.length(), piece.rest[k], wa + wb, approach, family);
        x[la] -= d * (s * wa);
        x[lb] += d * (s * wb);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// XPBD eq. 18 and 26 for one constraint with λ = 0, in f64: the ends' moves.
    fn reference(
        xa: [f64; 3],
        xb: [f64; 3],
        (wa, wb): (f64, f64),
        rest: f64,
        (compliance, gamma): (f64, f64),
        approach_rate: f64,
    ) -> ([f64; 3], [f64; 3]) {
        let d: Vec<f64> = (0..3).map(|i| xb[i] - xa[i]).collect();
        let len = d.iter().map(|v| v * v).sum::<f64>().sqrt();
        let n: Vec<f64> = d.iter().map(|v| v / len).collect();
        let c = len - rest;
        // ∇C·(x − x_prev) along n, for damping.
        let delta_lambda = (-c - gamma * approach_rate) / ((1.0 + gamma) * (wa + wb) + compliance);
        let move_a = [0, 1, 2].map(|i| -wa * delta_lambda * n[i]);
        let move_b = [0, 1, 2].map(|i| wb * delta_lambda * n[i]);
        (move_a, move_b)
    }

    fn moves(
        xa: Vec3,
        xb: Vec3,
        (wa, wb): (f32, f32),
        rest: f32,
        family: Family,
        relative: Vec3,
    ) -> (Vec3, Vec3) {
        let d = xb - xa;
        let approach = d.dot(relative);
        let s = if family.damping > 0.0 {
            correction::<true, true>(d.length(), rest, wa + wb, approach, family)
        } else {
            correction::<false, true>(d.length(), rest, wa + wb, approach, family)
        };
        (-d * (s * wa), d * (s * wb))
    }

    #[test]
    fn one_constraint_moves_its_ends_as_the_papers_formula() {
        let (xa, xb) = (Vec3::new(0.1, 0.2, -0.3), Vec3::new(0.9, -0.4, 0.5));
        let (wa, wb) = (1.0, 0.5);
        let rest = 0.8;
        for (compliance, gamma) in [(0.0, 0.0), (0.25, 0.0), (0.25, 0.3)] {
            let family = Family {
                on: true,
                compliance,
                damping: gamma,
                max_stretch: f32::INFINITY,
            };
            let relative = Vec3::new(0.01, -0.02, 0.03);
            let (ma, mb) = moves(xa, xb, (wa, wb), rest, family, relative);
            let f = |v: Vec3| [v.x, v.y, v.z].map(f64::from);
            let d = xb - xa;
            let rate = f64::from(d.dot(relative) / d.length());
            let (ra, rb) = reference(
                f(xa),
                f(xb),
                (f64::from(wa), f64::from(wb)),
                f64::from(rest),
                (f64::from(compliance), f64::from(gamma)),
                rate,
            );
            for i in 0..3 {
                assert!((f64::from(ma[i]) - ra[i]).abs() < 1e-6, "{ma} {ra:?}");
                assert!((f64::from(mb[i]) - rb[i]).abs() < 1e-6, "{mb} {rb:?}");
            }
        }
    }

    #[test]
    fn the_strain_limit_caps_the_length_and_a_torn_or_held_constraint_does_not_move() {
        let family = Family {
            on: true,
            compliance: 10.0, // soft: alone it would leave the constraint long
            damping: 0.0,
            max_stretch: 1.1,
        };
        let (xa, xb) = (Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0));
        let (ma, mb) = moves(xa, xb, (1.0, 1.0), 1.0, family, Vec3::ZERO);
        assert!(((xb + mb).distance(xa + ma) - 1.1).abs() < 1e-6);
        let (ma, mb) = moves(xa, xb, (0.0, 0.0), 1.0, family, Vec3::ZERO);
        assert_eq!((ma, mb), (Vec3::ZERO, Vec3::ZERO));
        // Coincident ends: no direction, no move (and nothing non-finite).
        let (ma, mb) = moves(xa, xa, (1.0, 1.0), 1.0, family, Vec3::ZERO);
        assert_eq!((ma, mb), (Vec3::ZERO, Vec3::ZERO));
    }
}
