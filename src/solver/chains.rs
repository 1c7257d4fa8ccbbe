//! Direct solves along chains of distance constraints: XPBD's stretch constraints solved
//! exactly along each line of the cloth instead of once each in a Gauss–Seidel sweep.
//!
//! A chain is a path of particles `p_0 … p_m` joined by structural constraints
//! `C_k = |p_{k+1} − p_k| − l_k`. Linearised about the substep's positions, the XPBD
//! system of a chain, `((1 + γ) J M⁻¹ Jᵀ + α̃) Δλ = −C − γ J (x − x_prev)` (Macklin,
//! Müller, Chentanez 2016, eq. 18 and 26, λ starting from 0 each substep as in their
//! small-steps variant), is tridiagonal: constraint `k` shares a particle only with
//! `k − 1` and `k + 1`, the diagonal is `(1 + γ)(w_k + w_{k+1}) + α̃`, the off-diagonal
//! `−(1 + γ) w_{k+1} n_k·n_{k+1}`. It is solved exactly by the Thomas algorithm in
//! `O(m)` (Goldenthal et al. 2007 solve the same linearised system for inextensible
//! cloth; Han and Harada 2013 along chains; Deul et al. 2018 along rods). Tension then
//! crosses a whole line in one solve, where a sweep moves it one constraint a substep.
//! Finite stiffness keeps its compliance on the diagonal, so a fabric stretches as it
//! does; a pinned particle (`w = 0`) and a torn constraint cut a chain in two.
//!
//! The chains cover every structural constraint: each particle's structural edges are
//! paired greedily by how straight they continue through it (most aligned first, in the
//! rest shape), and the pairs link edges into paths (a grid's rows and columns; a mesh's
//! longest straight runs, an edge alone where nothing continues it). The paths are
//! coloured into sets that share no particle (a grid: rows, then columns), and the sets
//! are solved one after another, each from the positions the last left.
//!
//! Within a set, the chains are laid side by side in tiles of [`LANES`], padded to the
//! tile's longest: the solve's loops run over the lanes, so they vectorise, and tiles
//! go in fixed pieces to the compute pool (the same bits on one thread and two). Each
//! particle's move is added to its position with the rounding kept apart (compensated
//! summation, in [`Particles::residue`]) and to its velocity over `h`, so a move far
//! below a float step of the position still counts: a soft spring at hundreds of
//! substeps settles where it should instead of where rounding stalls it.

use std::ops::Range;

use bevy::math::Vec3;

use super::parallel::{self, PIECE};
use super::xpbd::Family;
use super::{Particles, SpringKind, Springs};

/// Chains side by side in a tile: the width the solve's loops run over.
pub(super) const LANES: usize = 8;
/// No particle, no constraint (a padding slot, or a chain's last particle).
const NONE: u32 = u32::MAX;
/// Two edges continue each other through a particle when the angle between them is
/// within 60° of straight.
const STRAIGHT: f32 = 0.5;

type Lane = [f32; LANES];

/// The chains of a cloth's structural constraints, in sets solved one after another.
#[derive(Clone, Debug, Default)]
pub(super) struct Chains {
    sets: Vec<ChainSet>,
}

/// Chains that share no particle, tiled.
#[derive(Clone, Debug)]
struct ChainSet {
    /// Each tile: its first slot and its particles per chain; slot `start + k·LANES + j`
    /// is the `k`-th particle of the tile's `j`-th chain.
    tiles: Vec<(usize, usize)>,
    /// Each slot's particle (`NONE` for padding).
    particle: Vec<u32>,
    /// Each slot's constraint to the next slot of its chain (`NONE` for none).
    spring: Vec<u32>,
    /// Each particle's slot in this set (`NONE` when no chain of the set reaches it).
    slot_of: Vec<u32>,
    /// Each slot's constraint's rest length and whether it acts (1) or tore (0); synced
    /// once a step.
    rest: Vec<f32>,
    live: Vec<f32>,
    /// The tiles in pieces of about [`PIECE`] slots, for the compute pool.
    pieces: Vec<Range<usize>>,
    /// The solve's scratch, one value per slot.
    scratch: Scratch,
}

#[derive(Clone, Debug, Default)]
struct Scratch {
    /// Positions in, moves out.
    x: [Vec<f32>; 3],
    /// Positions at the substep's start (read when damped).
    prev: [Vec<f32>; 3],
    /// Inverse masses.
    w: Vec<f32>,
    /// Each constraint's direction.
    n: [Vec<f32>; 3],
    /// Thomas's modified upper diagonal, and its right-hand side (then `Δλ`).
    cp: Vec<f32>,
    dp: Vec<f32>,
}

impl Chains {
    /// Covers the structural springs with chains (see the module doc), their directions
    /// read from `rest`.
    pub fn new(springs: &Springs, rest: &[Vec3]) -> Self {
        let n = rest.len();
        let paths = path_cover(springs, rest);
        // Colour the paths, longest first, into sets that share no particle.
        let mut order: Vec<usize> = (0..paths.len()).collect();
        order.sort_by_key(|&p| (std::cmp::Reverse(paths[p].0.len()), p));
        let mut marks: Vec<Vec<bool>> = Vec::new();
        let mut members: Vec<Vec<usize>> = Vec::new();
        for p in order {
            let particles = &paths[p].0;
            let set = marks
                .iter()
                .position(|m| particles.iter().all(|&i| !m[i as usize]))
                .unwrap_or_else(|| {
                    marks.push(vec![false; n]);
                    members.push(Vec::new());
                    marks.len() - 1
                });
            for &i in particles {
                marks[set][i as usize] = true;
            }
            members[set].push(p);
        }
        let mut sets: Vec<ChainSet> = members
            .iter()
            .map(|m| ChainSet::new(m.iter().map(|&p| &paths[p]), n))
            .collect();
        // Sets in the order of their chains' mean index step (a grid's rows, then its
        // columns), so the order is the same for every build of a layout.
        sets.sort_by(|a, b| a.mean_step().total_cmp(&b.mean_step()));
        let mut chains = Self { sets };
        chains.sync(springs);
        chains
    }

    /// How many sets, and how many chains' constraints in all.
    #[cfg(test)]
    pub fn counts(&self) -> (usize, usize) {
        let constraints = self
            .sets
            .iter()
            .map(|s| s.spring.iter().filter(|&&k| k != NONE).count())
            .sum();
        (self.sets.len(), constraints)
    }

    /// Takes the springs' rest lengths (seams' change) and alive flags.
    pub fn sync(&mut self, springs: &Springs) {
        for set in &mut self.sets {
            for ((rest, live), &k) in set.rest.iter_mut().zip(&mut set.live).zip(&set.spring) {
                (*rest, *live) = match k {
                    NONE => (0.0, 0.0),
                    k => (
                        springs.rest_length[k as usize],
                        f32::from(u8::from(springs.alive[k as usize])),
                    ),
                };
            }
        }
    }

    /// Solves every set's chains once, set after set (see the module doc), with the
    /// structural family `f`; each particle's move goes to its position (compensated)
    /// and to its velocity over `h`.
    pub fn solve(&mut self, p: &mut Particles, f: Family, h: f32) {
        if !f.on {
            return;
        }
        for set in &mut self.sets {
            set.solve(p, f, h);
        }
    }
}

/// Structural edges paired through each particle and linked into paths: each path's
/// particles in order, and its springs between them.
fn path_cover(springs: &Springs, rest: &[Vec3]) -> Vec<(Vec<u32>, Vec<u32>)> {
    let n = rest.len();
    let structural = springs.ranges[SpringKind::Structural as usize].clone();
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); n];
    for s in structural.clone() {
        incident[springs.a[s] as usize].push(s as u32);
        incident[springs.b[s] as usize].push(s as u32);
    }
    let other = |s: u32, v: u32| {
        let s = s as usize;
        if springs.a[s] == v {
            springs.b[s]
        } else {
            springs.a[s]
        }
    };
    // Every pair of edges through a particle that continue each other, straightest
    // first; each edge's end takes the first pair offered.
    let mut pairs: Vec<(f32, u32, u32, u32)> = Vec::new();
    for (v, edges) in incident.iter().enumerate() {
        let v = v as u32;
        for (i, &e1) in edges.iter().enumerate() {
            for &e2 in &edges[i + 1..] {
                let u1 = (rest[other(e1, v) as usize] - rest[v as usize]).normalize_or_zero();
                let u2 = (rest[other(e2, v) as usize] - rest[v as usize]).normalize_or_zero();
                let straight = -u1.dot(u2);
                if straight > STRAIGHT {
                    pairs.push((straight, v, e1, e2));
                }
            }
        }
    }
    pairs.sort_by(|a, b| {
        b.0.total_cmp(&a.0)
            .then((a.1, a.2, a.3).cmp(&(b.1, b.2, b.3)))
    });
    // link[s][end]: the edge continuing `s` through its end `a` (0) or `b` (1).
    let mut link = vec![[NONE; 2]; springs.len()];
    let end = |s: u32, v: u32| usize::from(springs.a[s as usize] != v);
    for &(_, v, e1, e2) in &pairs {
        let (k1, k2) = (end(e1, v), end(e2, v));
        if link[e1 as usize][k1] == NONE && link[e2 as usize][k2] == NONE {
            link[e1 as usize][k1] = e2;
            link[e2 as usize][k2] = e1;
        }
    }
    // Walk the paths from their free ends, then what is left (closed loops), cut once.
    let mut seen = vec![false; springs.len()];
    let mut paths = Vec::new();
    let walk = |start: u32, from: u32, seen: &mut Vec<bool>| {
        let (mut particles, mut edges) = (vec![from], Vec::new());
        let (mut s, mut v) = (start, from);
        while s != NONE && !seen[s as usize] {
            seen[s as usize] = true;
            edges.push(s);
            v = other(s, v);
            particles.push(v);
            s = link[s as usize][end(s, v)];
        }
        (particles, edges)
    };
    for s in structural.clone() {
        let s = s as u32;
        let ends = [springs.a[s as usize], springs.b[s as usize]];
        for (k, from) in ends.into_iter().enumerate() {
            if !seen[s as usize] && link[s as usize][k] == NONE {
                paths.push(walk(s, from, &mut seen));
            }
        }
    }
    for s in structural {
        if !seen[s] {
            paths.push(walk(s as u32, springs.a[s], &mut seen));
        }
    }
    paths
}

impl ChainSet {
    /// The tiled set of `paths` (longest first) over `n` particles.
    fn new<'a>(paths: impl Iterator<Item = &'a (Vec<u32>, Vec<u32>)>, n: usize) -> Self {
        let paths: Vec<_> = paths.collect();
        let (mut tiles, mut particle, mut spring) = (Vec::new(), Vec::new(), Vec::new());
        for tile in paths.chunks(LANES) {
            let len = tile.iter().map(|p| p.0.len()).max().unwrap_or(0);
            let start = particle.len();
            tiles.push((start, len));
            particle.resize(start + len * LANES, NONE);
            spring.resize(start + len * LANES, NONE);
            for (j, (particles, springs)) in tile.iter().enumerate() {
                for (k, &i) in particles.iter().enumerate() {
                    particle[start + k * LANES + j] = i;
                }
                for (k, &s) in springs.iter().enumerate() {
                    spring[start + k * LANES + j] = s;
                }
            }
        }
        let mut slot_of = vec![NONE; n];
        for (slot, &i) in particle.iter().enumerate() {
            if i != NONE {
                slot_of[i as usize] = slot as u32;
            }
        }
        // Pieces of whole tiles, about PIECE slots each.
        let mut pieces = Vec::new();
        let mut from = 0;
        for t in 0..tiles.len() {
            let end = tiles.get(t + 1).map_or(particle.len(), |tile| tile.0);
            if end - tiles[from].0 >= PIECE {
                pieces.push(from..t + 1);
                from = t + 1;
            }
        }
        if from < tiles.len() {
            pieces.push(from..tiles.len());
        }
        let slots = particle.len();
        let lanes = || [vec![0.0; slots], vec![0.0; slots], vec![0.0; slots]];
        Self {
            tiles,
            rest: vec![0.0; slots],
            live: vec![0.0; slots],
            particle,
            spring,
            slot_of,
            pieces,
            scratch: Scratch {
                x: lanes(),
                prev: lanes(),
                w: vec![0.0; slots],
                n: lanes(),
                cp: vec![0.0; slots],
                dp: vec![0.0; slots],
            },
        }
    }

    /// The mean `|b − a|` in particle indices of the set's constraints.
    fn mean_step(&self) -> f64 {
        let (mut sum, mut count) = (0.0, 0usize);
        for (slot, &k) in self.spring.iter().enumerate() {
            if k != NONE {
                let (a, b) = (self.particle[slot], self.particle[slot + LANES]);
                sum += f64::from(a.abs_diff(b));
                count += 1;
            }
        }
        sum / count.max(1) as f64
    }

    fn solve(&mut self, p: &mut Particles, f: Family, h: f32) {
        let damped = f.damping > 0.0;
        let Self {
            tiles,
            particle,
            rest,
            live,
            pieces,
            scratch,
            slot_of,
            ..
        } = self;
        let slots = particle.len();
        let positions = (&p.position[..], &p.previous[..], &p.inv_mass[..]);
        let (tiles, particle, rest, live) = (&tiles[..], &particle[..], &rest[..], &live[..]);
        // Each piece's scratch, cut from the set's as the pieces are handed out (no
        // allocation).
        let Scratch {
            x: [x0, x1, x2],
            prev: [p0, p1, p2],
            w,
            n: [n0, n1, n2],
            cp,
            dp,
        } = scratch;
        let whole = (
            [&mut x0[..], &mut x1[..], &mut x2[..]],
            [&mut p0[..], &mut p1[..], &mut p2[..]],
            &mut w[..],
            [&mut n0[..], &mut n1[..], &mut n2[..]],
            &mut cp[..],
            &mut dp[..],
        );
        let work = pieces.iter().scan((whole, 0), |(rest_of, at), piece| {
            let end = tiles.get(piece.end).map_or(slots, |t| t.0);
            let size = end - *at;
            let (x, prev, w, n, cp, dp) = std::mem::take(rest_of);
            let ((x, x_rest), (prev, prev_rest), (n, n_rest)) =
                (cut3(x, size), cut3(prev, size), cut3(n, size));
            let (w, w_rest) = w.split_at_mut(size);
            let (cp, cp_rest) = cp.split_at_mut(size);
            let (dp, dp_rest) = dp.split_at_mut(size);
            let item = (piece.clone(), *at, x, prev, w, n, cp, dp);
            *rest_of = (x_rest, prev_rest, w_rest, n_rest, cp_rest, dp_rest);
            *at = end;
            Some(item)
        });
        parallel::for_each(
            slots,
            work,
            |(piece, at, mut x, mut prev, w, mut n, cp, dp)| {
                // Gather the piece's particles into its slots.
                for (s, &i) in particle[at..at + w.len()].iter().enumerate() {
                    let (position, previous, inv_mass) = positions;
                    let (xi, pi, wi) = match i {
                        NONE => (Vec3::ZERO, Vec3::ZERO, 0.0),
                        i => (
                            position[i as usize],
                            previous[i as usize],
                            inv_mass[i as usize],
                        ),
                    };
                    (x[0][s], x[1][s], x[2][s], w[s]) = (xi.x, xi.y, xi.z, wi);
                    if damped {
                        (prev[0][s], prev[1][s], prev[2][s]) = (pi.x, pi.y, pi.z);
                    }
                }
                for &(start, len) in &tiles[piece] {
                    let local = start - at..start - at + len * LANES;
                    let global = start..start + len * LANES;
                    let tile = Tile {
                        x: x.each_mut().map(|l| lanes_mut(&mut l[local.clone()])),
                        prev: prev.each_mut().map(|l| lanes(&l[local.clone()])),
                        w: lanes(&w[local.clone()]),
                        n: n.each_mut().map(|l| lanes_mut(&mut l[local.clone()])),
                        cp: lanes_mut(&mut cp[local.clone()]),
                        dp: lanes_mut(&mut dp[local.clone()]),
                        rest: lanes(&rest[global.clone()]),
                        live: lanes(&live[global]),
                    };
                    if damped {
                        solve_tile::<true>(tile, f);
                    } else {
                        solve_tile::<false>(tile, f);
                    }
                }
            },
        );
        // Each particle takes its slot's move (`x` now holds the moves).
        let moves = [&x0[..], &x1[..], &x2[..]];
        let n = p.len();
        let pieces = p
            .position
            .chunks_mut(PIECE)
            .zip(p.velocity.chunks_mut(PIECE))
            .zip(p.residue.chunks_mut(PIECE))
            .zip(slot_of.chunks(PIECE));
        parallel::for_each(n, pieces, |(((x, v), r), slot_of)| {
            for (((x, v), r), &s) in x.iter_mut().zip(v).zip(r).zip(slot_of) {
                if s == NONE {
                    continue;
                }
                let s = s as usize;
                let delta = Vec3::new(moves[0][s], moves[1][s], moves[2][s]);
                *v += delta / h;
                compensated_add(x, r, delta);
            }
        });
    }
}

/// Three lanes split at `size`.
#[allow(clippy::type_complexity)]
fn cut3(l: [&mut [f32]; 3], size: usize) -> ([&mut [f32]; 3], [&mut [f32]; 3]) {
    let [a, b, c] = l;
    let ((a, a2), (b, b2), (c, c2)) = (
        a.split_at_mut(size),
        b.split_at_mut(size),
        c.split_at_mut(size),
    );
    ([a, b, c], [a2, b2, c2])
}

/// `x + r += delta`, keeping in `r` what rounding `x` lost (Kahan's compensated sum;
/// Fast2Sum, exact while `|x| ≥ |delta + r|`).
#[inline(always)]
pub(super) fn compensated_add(x: &mut Vec3, r: &mut Vec3, delta: Vec3) {
    let t = delta + *r;
    let s = *x + t;
    *r = t - (s - *x);
    *x = s;
}

fn lanes(l: &[f32]) -> &[Lane] {
    l.as_chunks::<LANES>().0
}

fn lanes_mut(l: &mut [f32]) -> &mut [Lane] {
    l.as_chunks_mut::<LANES>().0
}

/// One tile's slots as lanes (`len` rows of [`LANES`]).
struct Tile<'a> {
    x: [&'a mut [Lane]; 3],
    prev: [&'a [Lane]; 3],
    w: &'a [Lane],
    n: [&'a mut [Lane]; 3],
    cp: &'a mut [Lane],
    dp: &'a mut [Lane],
    rest: &'a [Lane],
    live: &'a [Lane],
}

/// The Thomas algorithm on a tile's chains (see the module doc); leaves each slot's move
/// in `x`. Every loop runs over the lanes of local arrays, without branches, so it
/// vectorises; what one constraint hands the next (its direction, `1/m`, its right-hand
/// side) is carried in locals.
#[inline(always)]
fn solve_tile<const DAMPED: bool>(t: Tile<'_>, f: Family) {
    let m = t.w.len();
    let [x0, x1, x2] = t.x;
    if m < 2 {
        for lane in [x0, x1, x2] {
            lane.iter_mut().for_each(|l| *l = [0.0; LANES]);
        }
        return;
    }
    let [n0, n1, n2] = t.n;
    let (cp, dp) = (t.cp, t.dp);
    let (w, rest, live) = (&t.w[..m], &t.rest[..m], &t.live[..m]);
    let prev = t.prev;
    let g = 1.0 + f.damping;
    let zero = [0.0f32; LANES];
    // Forward elimination, constraint by constraint down the chains.
    let mut xa = [x0[0], x1[0], x2[0]];
    let mut pa = if DAMPED {
        [prev[0][0], prev[1][0], prev[2][0]]
    } else {
        [zero; 3]
    };
    let (mut n_before, mut inv_before, mut d_before) = ([zero; 3], zero, zero);
    for k in 0..m - 1 {
        let xb = [x0[k + 1], x1[k + 1], x2[k + 1]];
        let pb = if DAMPED {
            [prev[0][k + 1], prev[1][k + 1], prev[2][k + 1]]
        } else {
            [zero; 3]
        };
        let (wa, wb, r, alive) = (w[k], w[k + 1], rest[k], live[k]);
        let (mut nk, mut inv_m, mut dk, mut c_before) = ([zero; 3], zero, zero, zero);
        for j in 0..LANES {
            let d = [
                xb[0][j] - xa[0][j],
                xb[1][j] - xa[1][j],
                xb[2][j] - xa[2][j],
            ];
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let wsum = wa[j] + wb[j];
            let on = alive[j] > 0.0 && wsum > 0.0 && len > f32::EPSILON * r[j];
            let inv = if on {
                1.0 / len.max(f32::MIN_POSITIVE)
            } else {
                0.0
            };
            let n = [d[0] * inv, d[1] * inv, d[2] * inv];
            let mut rhs = if on { r[j] - len } else { 0.0 };
            if DAMPED {
                let rel = [0, 1, 2].map(|c| (xb[c][j] - pb[c][j]) - (xa[c][j] - pa[c][j]));
                rhs -= f.damping * (n[0] * rel[0] + n[1] * rel[1] + n[2] * rel[2]);
            }
            let diag = if on { g * wsum + f.compliance } else { 1.0 };
            let dot = n_before[0][j] * n[0] + n_before[1][j] * n[1] + n_before[2][j] * n[2];
            let off = -g * wa[j] * dot;
            // The previous constraint's upper diagonal is this off-diagonal.
            c_before[j] = off * inv_before[j];
            inv_m[j] = 1.0 / (diag - off * c_before[j]);
            dk[j] = (rhs - off * d_before[j]) * inv_m[j];
            (nk[0][j], nk[1][j], nk[2][j]) = (n[0], n[1], n[2]);
        }
        if k > 0 {
            cp[k - 1] = c_before;
        }
        (n0[k], n1[k], n2[k], dp[k]) = (nk[0], nk[1], nk[2], dk);
        (n_before, inv_before, d_before, xa, pa) = (nk, inv_m, dk, xb, pb);
    }
    // Back substitution: Δλ into dp.
    let mut after = dp[m - 2];
    for k in (0..m - 2).rev() {
        let (c, mut d) = (cp[k], dp[k]);
        for j in 0..LANES {
            d[j] -= c[j] * after[j];
        }
        dp[k] = d;
        after = d;
    }
    // Each particle's move: w_k (n_{k−1} Δλ_{k−1} − n_k Δλ_k).
    let mut before = [zero; 3];
    for k in 0..m {
        let here = if k + 1 < m {
            let (l, n) = (dp[k], [n0[k], n1[k], n2[k]]);
            n.map(|n| std::array::from_fn(|j| n[j] * l[j]))
        } else {
            [zero; 3]
        };
        let wk = w[k];
        for (c, x) in [&mut *x0, &mut *x1, &mut *x2].into_iter().enumerate() {
            let mut out = zero;
            for j in 0..LANES {
                out[j] = wk[j] * (before[c][j] - here[c][j]);
            }
            x[k] = out;
        }
        before = here;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The linearised XPBD system of a chain, `(J W Jᵀ + α̃) Δλ = −C`, assembled densely
    /// and solved by Gaussian elimination in `f64`: each particle's move `W Jᵀ Δλ`.
    fn dense_moves(x: &[Vec3], w: &[f32], rest: &[f32], compliance: f64) -> Vec<[f64; 3]> {
        let m = rest.len();
        let f = |v: Vec3| [v.x, v.y, v.z].map(f64::from);
        let n: Vec<[f64; 3]> = (0..m)
            .map(|k| {
                let d = f(x[k + 1] - x[k]);
                let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                d.map(|c| c / len)
            })
            .collect();
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let mut a = vec![vec![0.0f64; m + 1]; m];
        for k in 0..m {
            let (wa, wb) = (f64::from(w[k]), f64::from(w[k + 1]));
            a[k][k] = wa + wb + compliance;
            if k + 1 < m {
                let off = -f64::from(w[k + 1]) * dot(n[k], n[k + 1]);
                (a[k][k + 1], a[k + 1][k]) = (off, off);
            }
            let len = dot(f(x[k + 1] - x[k]), n[k]);
            a[k][m] = -(len - f64::from(rest[k]));
        }
        for c in 0..m {
            let pivot = (c..m).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()));
            a.swap(c, pivot.unwrap());
            let pivot_row = a[c].clone();
            for (r, row) in a.iter_mut().enumerate() {
                if r != c {
                    let factor = row[c] / pivot_row[c];
                    for (x, p) in row[c..].iter_mut().zip(&pivot_row[c..]) {
                        *x -= factor * p;
                    }
                }
            }
        }
        let lambda: Vec<f64> = (0..m).map(|k| a[k][m] / a[k][k]).collect();
        (0..=m)
            .map(|i| {
                let mut d = [0.0; 3];
                for c in 0..3 {
                    if i > 0 {
                        d[c] += n[i - 1][c] * lambda[i - 1];
                    }
                    if i < m {
                        d[c] -= n[i][c] * lambda[i];
                    }
                    d[c] *= f64::from(w[i]);
                }
                d
            })
            .collect()
    }

    /// A bent, stretched chain of `count` particles.
    fn bent_chain(count: usize) -> Vec<Vec3> {
        (0..count)
            .map(|i| {
                let t = i as f32;
                Vec3::new(0.11 * t, -0.02 * t * t, 0.013 * (t * 1.7).sin())
            })
            .collect()
    }

    fn tile_solve(x: &[Vec3], w: &[f32], rest: &[f32], family: Family) -> Vec<Vec3> {
        // One chain in lane 3 of a tile, the other lanes padding.
        let m = x.len();
        let j = 3;
        let lane = |f: &dyn Fn(usize) -> f32| {
            let mut l = vec![0.0f32; m * LANES];
            for k in 0..m {
                l[k * LANES + j] = f(k);
            }
            l
        };
        let mut xs = [lane(&|k| x[k].x), lane(&|k| x[k].y), lane(&|k| x[k].z)];
        let prev = [lane(&|_| 0.0), lane(&|_| 0.0), lane(&|_| 0.0)];
        let ws = lane(&|k| w[k]);
        let rs = lane(&|k| rest.get(k).copied().unwrap_or(0.0));
        let live = lane(&|k| f32::from(u8::from(k + 1 < m)));
        let mut n = [
            vec![0.0; m * LANES],
            vec![0.0; m * LANES],
            vec![0.0; m * LANES],
        ];
        let (mut cp, mut dp) = (vec![0.0; m * LANES], vec![0.0; m * LANES]);
        let [n0, n1, n2] = &mut n;
        let [x0, x1, x2] = &mut xs;
        solve_tile::<false>(
            Tile {
                x: [lanes_mut(x0), lanes_mut(x1), lanes_mut(x2)],
                prev: prev.each_ref().map(|l| lanes(l)),
                w: lanes(&ws),
                n: [lanes_mut(n0), lanes_mut(n1), lanes_mut(n2)],
                cp: lanes_mut(&mut cp),
                dp: lanes_mut(&mut dp),
                rest: lanes(&rs),
                live: lanes(&live),
            },
            family,
        );
        // The padding lanes do not move.
        for (k, v) in xs[0].iter().enumerate() {
            assert!(k % LANES == j || *v == 0.0, "padding moved");
        }
        (0..m)
            .map(|k| {
                Vec3::new(
                    xs[0][k * LANES + j],
                    xs[1][k * LANES + j],
                    xs[2][k * LANES + j],
                )
            })
            .collect()
    }

    #[test]
    fn a_chain_is_solved_as_its_dense_linear_system() {
        let x = bent_chain(9);
        // Rest lengths 3% to 10% below the current ones, the first particle pinned and
        // the masses uneven.
        let rest: Vec<f32> = (0..8)
            .map(|k| x[k].distance(x[k + 1]) * (0.9 + 0.01 * k as f32))
            .collect();
        let w: Vec<f32> = (0..9)
            .map(|i| if i == 0 { 0.0 } else { 1.0 + 0.3 * i as f32 })
            .collect();
        for compliance in [0.0, 0.5, 40.0] {
            let family = Family {
                on: true,
                compliance,
                damping: 0.0,
                max_stretch: f32::INFINITY,
            };
            let moves = tile_solve(&x, &w, &rest, family);
            let expected = dense_moves(&x, &w, &rest, f64::from(compliance));
            for (i, (got, want)) in moves.iter().zip(&expected).enumerate() {
                for c in 0..3 {
                    let error = (f64::from(got[c]) - want[c]).abs();
                    assert!(
                        error < 2e-6,
                        "α̃ {compliance}, particle {i}: {got} against {want:?}"
                    );
                }
            }
            assert_eq!(moves[0], Vec3::ZERO, "the pinned particle moved");
        }
    }

    #[test]
    fn repeated_solves_converge_on_an_inextensible_chain_as_newton_does() {
        // Each solve is a Newton step on the chain's lengths (Goldenthal et al. 2007's
        // fast projection): the error left falls quadratically, solve after solve.
        let mut y = bent_chain(17);
        let rest: Vec<f32> = (0..16).map(|k| y[k].distance(y[k + 1]) * 0.98).collect();
        let w = vec![1.0; 17];
        let family = Family {
            on: true,
            ..Family::default()
        };
        let error = |y: &[Vec3]| {
            (0..16)
                .map(|k| (y[k].distance(y[k + 1]) - rest[k]).abs() / rest[k])
                .fold(0.0f32, f32::max)
        };
        let mut errors = vec![error(&y)];
        for _ in 0..3 {
            let moves = tile_solve(&y, &w, &rest, family);
            y.iter_mut().zip(&moves).for_each(|(a, b)| *a += *b);
            errors.push(error(&y));
        }
        println!("largest length error, solve after solve: {errors:?}");
        // From 2% off (1.4% after the first solve, which turns the links a long way),
        // then quadratically: 1.8e-4, 5.8e-7.
        assert!(errors[1] < errors[0], "{errors:?}");
        assert!(errors[2] < errors[1] * 0.05, "{errors:?}");
        assert!(
            errors[3] < errors[2] * 0.05 && errors[3] < 1e-6,
            "{errors:?}"
        );
    }

    #[test]
    fn a_grid_is_covered_by_its_rows_then_its_columns() {
        let (width, height) = (7usize, 5usize);
        let positions: Vec<Vec3> = (0..width * height)
            .map(|i| Vec3::new((i % width) as f32 * 0.1, -((i / width) as f32) * 0.1, 0.0))
            .collect();
        let mut pairs = Vec::new();
        for r in 0..height {
            for c in 0..width {
                let i = (r * width + c) as u32;
                if c + 1 < width {
                    pairs.push((SpringKind::Structural, i, i + 1));
                }
                if r + 1 < height {
                    pairs.push((SpringKind::Structural, i, i + width as u32));
                }
                if c + 1 < width && r + 1 < height {
                    pairs.push((SpringKind::Shear, i, i + width as u32 + 1));
                }
            }
        }
        let springs = Springs::from_pairs(pairs, &positions);
        let chains = Chains::new(&springs, &positions);
        assert_eq!(chains.sets.len(), 2, "rows and columns");
        let structural = springs.ranges[SpringKind::Structural as usize].len();
        assert_eq!(
            chains.counts(),
            (2, structural),
            "every structural spring once"
        );
        // Rows first: the first set's constraints join neighbours in a row.
        let (rows, columns) = (&chains.sets[0], &chains.sets[1]);
        assert_eq!(rows.mean_step(), 1.0);
        assert_eq!(columns.mean_step(), width as f64);
        // Whole lines: a row's particles in one chain of `width`, a column's of `height`.
        assert_eq!(rows.tiles[0].1, width);
        assert_eq!(columns.tiles[0].1, height);
    }
}
