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

use super::integrate::compensated_add;
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

/// Chains that share no particle, tiled: a tile is [`LANES`] chains side by side, one
/// [`Row`] per particle along them (padded to the tile's longest chain), so slot
/// `row · LANES + j` is that row's particle on chain `j`.
#[derive(Clone, Debug)]
struct ChainSet {
    /// Each tile: its first row and its rows (particles per chain).
    tiles: Vec<(usize, usize)>,
    rows: Vec<Row>,
    /// Each slot's particle (`NONE` for padding).
    particle: Vec<u32>,
    /// Each slot's constraint to the next slot of its chain (`NONE` for none).
    spring: Vec<u32>,
    /// Each particle's slot in this set (`NONE` when no chain of the set reaches it).
    slot_of: Vec<u32>,
    /// The tiles in pieces of about [`PIECE`] slots, for the compute pool.
    pieces: Vec<Range<usize>>,
}

/// One particle along each of a tile's chains, and the constraint to the next: what the
/// solve reads and writes at one step down the chains, together.
#[derive(Clone, Copy, Debug, Default)]
struct Row {
    /// Positions in, moves out.
    x: [Lane; 3],
    /// Positions at the substep's start (read when damped).
    prev: [Lane; 3],
    /// Inverse masses.
    w: Lane,
    /// The constraint to the next row: its rest length and 1 while it acts (0 torn or
    /// none), synced once a step; its direction, Thomas's modified upper diagonal and
    /// right-hand side (then `Δλ`), per solve.
    rest: Lane,
    live: Lane,
    n: [Lane; 3],
    cp: Lane,
    dp: Lane,
}

impl Chains {
    /// Covers the structural springs with chains (see the module doc), their directions
    /// read from `rest`.
    pub fn new(springs: &Springs, rest: &[Vec3]) -> Self {
        let n = rest.len();
        let paths = walk_paths(springs, &straight_links(springs, rest));
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
            for (slot, &k) in set.spring.iter().enumerate() {
                let row = &mut set.rows[slot / LANES];
                (row.rest[slot % LANES], row.live[slot % LANES]) = match k {
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
            set.solve_tiles(p, f);
            set.add_moves(p, h);
        }
    }
}

/// For each structural spring, the spring continuing it straight through its end `a`
/// (index 0) and `b` (1), or `NONE`: every pair of edges through a particle within
/// [`STRAIGHT`] of straight, straightest first, each edge's end taking the first pair
/// offered (in the rest shape).
fn straight_links(springs: &Springs, rest: &[Vec3]) -> Vec<[u32; 2]> {
    let structural = springs.ranges[SpringKind::Structural as usize].clone();
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); rest.len()];
    for s in structural {
        incident[springs.a[s] as usize].push(s as u32);
        incident[springs.b[s] as usize].push(s as u32);
    }
    let mut pairs: Vec<(f32, u32, u32, u32)> = Vec::new();
    for (v, edges) in incident.iter().enumerate() {
        let away =
            |e: u32| (rest[other_end(springs, e, v as u32) as usize] - rest[v]).normalize_or_zero();
        for (i, &e1) in edges.iter().enumerate() {
            for &e2 in &edges[i + 1..] {
                let straight = -away(e1).dot(away(e2));
                if straight > STRAIGHT {
                    pairs.push((straight, v as u32, e1, e2));
                }
            }
        }
    }
    pairs.sort_by(|a, b| {
        b.0.total_cmp(&a.0)
            .then((a.1, a.2, a.3).cmp(&(b.1, b.2, b.3)))
    });
    let mut link = vec![[NONE; 2]; springs.len()];
    for &(_, v, e1, e2) in &pairs {
        let (k1, k2) = (end_at(springs, e1, v), end_at(springs, e2, v));
        if link[e1 as usize][k1] == NONE && link[e2 as usize][k2] == NONE {
            link[e1 as usize][k1] = e2;
            link[e2 as usize][k2] = e1;
        }
    }
    link
}

/// The particle of spring `s` that is not `v`.
fn other_end(springs: &Springs, s: u32, v: u32) -> u32 {
    let s = s as usize;
    if springs.a[s] == v {
        springs.b[s]
    } else {
        springs.a[s]
    }
}

/// Which end of spring `s` particle `v` is: 0 for `a`, 1 for `b`.
fn end_at(springs: &Springs, s: u32, v: u32) -> usize {
    usize::from(springs.a[s as usize] != v)
}

/// The paths `link` makes of the structural springs: each path's particles in order and
/// its springs between them. Walked from their free ends, then what is left (closed
/// loops), cut once.
fn walk_paths(springs: &Springs, link: &[[u32; 2]]) -> Vec<(Vec<u32>, Vec<u32>)> {
    let structural = springs.ranges[SpringKind::Structural as usize].clone();
    let mut seen = vec![false; springs.len()];
    let mut walk = |start: u32, from: u32| {
        let (mut particles, mut edges) = (vec![from], Vec::new());
        let (mut s, mut v) = (start, from);
        while s != NONE && !seen[s as usize] {
            seen[s as usize] = true;
            edges.push(s);
            v = other_end(springs, s, v);
            particles.push(v);
            s = link[s as usize][end_at(springs, s, v)];
        }
        (particles, edges)
    };
    let mut paths = Vec::new();
    for s in structural.clone() {
        for (k, from) in [springs.a[s], springs.b[s]].into_iter().enumerate() {
            if link[s][k] == NONE {
                let path = walk(s as u32, from);
                if !path.1.is_empty() {
                    paths.push(path);
                }
            }
        }
    }
    for s in structural {
        let path = walk(s as u32, springs.a[s]);
        if !path.1.is_empty() {
            paths.push(path);
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
            tiles.push((start / LANES, len));
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
        let rows = particle.len() / LANES;
        let mut pieces = Vec::new();
        let mut from = 0;
        for t in 0..tiles.len() {
            let end = tiles.get(t + 1).map_or(rows, |tile| tile.0);
            if (end - tiles[from].0) * LANES >= PIECE {
                pieces.push(from..t + 1);
                from = t + 1;
            }
        }
        if from < tiles.len() {
            pieces.push(from..tiles.len());
        }
        Self {
            tiles,
            rows: vec![Row::default(); rows],
            particle,
            spring,
            slot_of,
            pieces,
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

    /// Each piece's tiles, on the compute pool: their particles gathered into the rows,
    /// then solved ([`solve_tile`]), leaving each slot's move in its row's `x`.
    fn solve_tiles(&mut self, p: &Particles, f: Family) {
        let damped = f.damping > 0.0;
        let Self {
            tiles,
            rows,
            particle,
            pieces,
            ..
        } = self;
        let (tiles, particle, slots) = (&tiles[..], &particle[..], particle.len());
        // Each piece's rows cut from the set's as the pieces are handed out.
        let mut left = &mut rows[..];
        let work = pieces.iter().map(|piece| {
            let first = tiles[piece.start].0;
            let end = tiles.get(piece.end).map_or(slots / LANES, |t| t.0);
            let (mine, others) = std::mem::take(&mut left).split_at_mut(end - first);
            left = others;
            (piece.clone(), first, mine)
        });
        parallel::for_each(slots, work, |(piece, first, rows)| {
            gather(rows, &particle[first * LANES..], p, damped);
            for &(start, len) in &tiles[piece] {
                let tile = &mut rows[start - first..start - first + len];
                if damped {
                    solve_tile::<true>(tile, f);
                } else {
                    solve_tile::<false>(tile, f);
                }
            }
        });
    }

    /// Each particle takes its slot's move: to its velocity over `h`, and to its
    /// position with the rounding kept in its residue.
    fn add_moves(&self, p: &mut Particles, h: f32) {
        let rows = &self.rows;
        let pieces = p
            .position
            .chunks_mut(PIECE)
            .zip(p.velocity.chunks_mut(PIECE))
            .zip(p.residue.chunks_mut(PIECE))
            .zip(self.slot_of.chunks(PIECE));
        parallel::for_each(self.slot_of.len(), pieces, |(((x, v), r), slot_of)| {
            for (((x, v), r), &s) in x.iter_mut().zip(v).zip(r).zip(slot_of) {
                if s == NONE {
                    continue;
                }
                let (row, j) = (&rows[s as usize / LANES].x, s as usize % LANES);
                let delta = Vec3::new(row[0][j], row[1][j], row[2][j]);
                *v += delta / h;
                compensated_add(x, r, delta);
            }
        });
    }
}

/// The particles of `particle` (slot by slot from the first of `rows`) into `rows`:
/// positions, inverse masses, and the substep's start when `damped`; padding at rest
/// with no mass to move.
fn gather(rows: &mut [Row], particle: &[u32], p: &Particles, damped: bool) {
    for (row, particle) in rows.iter_mut().zip(particle.chunks(LANES)) {
        for (j, &i) in particle.iter().enumerate() {
            let (x, prev, w) = match i {
                NONE => (Vec3::ZERO, Vec3::ZERO, 0.0),
                i => {
                    let i = i as usize;
                    (p.position[i], p.previous[i], p.inv_mass[i])
                }
            };
            (row.x[0][j], row.x[1][j], row.x[2][j], row.w[j]) = (x.x, x.y, x.z, w);
            if damped {
                (row.prev[0][j], row.prev[1][j], row.prev[2][j]) = (prev.x, prev.y, prev.z);
            }
        }
    }
}

/// The Thomas algorithm on a tile's chains (see the module doc), leaving each row's
/// move in its `x`. Every loop runs over the lanes of local arrays, without branches,
/// so it vectorises.
#[inline(always)]
fn solve_tile<const DAMPED: bool>(rows: &mut [Row], f: Family) {
    if rows.len() < 2 {
        rows.iter_mut().for_each(|row| row.x = [ZERO; 3]);
        return;
    }
    eliminate::<DAMPED>(rows, f);
    substitute(rows);
    moves(rows);
}

const ZERO: Lane = [0.0; LANES];

/// Forward elimination, constraint by constraint down the chains: each row's direction,
/// modified upper diagonal (of the row before, once this one's off-diagonal is known)
/// and right-hand side. What a constraint hands the next is carried in locals.
#[inline(always)]
fn eliminate<const DAMPED: bool>(rows: &mut [Row], f: Family) {
    let g = 1.0 + f.damping;
    let (mut n_before, mut inv_before, mut d_before) = ([ZERO; 3], ZERO, ZERO);
    let mut xa = rows[0].x;
    let mut pa = if DAMPED { rows[0].prev } else { [ZERO; 3] };
    for k in 0..rows.len() - 1 {
        let (wa, rest, live) = (rows[k].w, rows[k].rest, rows[k].live);
        let (xb, wb) = (rows[k + 1].x, rows[k + 1].w);
        let pb = if DAMPED { rows[k + 1].prev } else { [ZERO; 3] };
        let (mut n, mut inv_m, mut d, mut c_before) = ([ZERO; 3], ZERO, ZERO, ZERO);
        for j in 0..LANES {
            let dx = [
                xb[0][j] - xa[0][j],
                xb[1][j] - xa[1][j],
                xb[2][j] - xa[2][j],
            ];
            let len = (dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]).sqrt();
            let wsum = wa[j] + wb[j];
            let on = live[j] > 0.0 && wsum > 0.0 && len > f32::EPSILON * rest[j];
            let inv = if on {
                1.0 / len.max(f32::MIN_POSITIVE)
            } else {
                0.0
            };
            let nj = [dx[0] * inv, dx[1] * inv, dx[2] * inv];
            let mut rhs = if on { rest[j] - len } else { 0.0 };
            if DAMPED {
                let rel = [
                    (xb[0][j] - pb[0][j]) - (xa[0][j] - pa[0][j]),
                    (xb[1][j] - pb[1][j]) - (xa[1][j] - pa[1][j]),
                    (xb[2][j] - pb[2][j]) - (xa[2][j] - pa[2][j]),
                ];
                rhs -= f.damping * (nj[0] * rel[0] + nj[1] * rel[1] + nj[2] * rel[2]);
            }
            let diag = if on { g * wsum + f.compliance } else { 1.0 };
            let dot = n_before[0][j] * nj[0] + n_before[1][j] * nj[1] + n_before[2][j] * nj[2];
            let off = -g * wa[j] * dot;
            c_before[j] = off * inv_before[j];
            inv_m[j] = 1.0 / (diag - off * c_before[j]);
            d[j] = (rhs - off * d_before[j]) * inv_m[j];
            (n[0][j], n[1][j], n[2][j]) = (nj[0], nj[1], nj[2]);
        }
        if k > 0 {
            rows[k - 1].cp = c_before;
        }
        (rows[k].n, rows[k].dp) = (n, d);
        (n_before, inv_before, d_before, xa, pa) = (n, inv_m, d, xb, pb);
    }
}

/// Back substitution: each constraint's `Δλ` into its row's `dp`.
#[inline(always)]
fn substitute(rows: &mut [Row]) {
    let m = rows.len();
    let mut after = rows[m - 2].dp;
    for row in rows[..m - 2].iter_mut().rev() {
        for ((d, c), a) in row.dp.iter_mut().zip(&row.cp).zip(&after) {
            *d -= c * a;
        }
        after = row.dp;
    }
}

/// Each particle's move, `w_k (n_{k−1} Δλ_{k−1} − n_k Δλ_k)`, into its row's `x`.
#[inline(always)]
fn moves(rows: &mut [Row]) {
    let m = rows.len();
    let mut before = [ZERO; 3];
    for (k, row) in rows.iter_mut().enumerate() {
        let mut here = [ZERO; 3];
        if k + 1 < m {
            for (h, n) in here.iter_mut().zip(&row.n) {
                for ((h, n), l) in h.iter_mut().zip(n).zip(&row.dp) {
                    *h = n * l;
                }
            }
        }
        for ((x, b), h) in row.x.iter_mut().zip(&before).zip(&here) {
            for (((x, w), b), h) in x.iter_mut().zip(&row.w).zip(b).zip(h) {
                *x = w * (b - h);
            }
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
        let (m, j) = (x.len(), 3);
        let mut rows = vec![Row::default(); m];
        for (k, row) in rows.iter_mut().enumerate() {
            (row.x[0][j], row.x[1][j], row.x[2][j]) = (x[k].x, x[k].y, x[k].z);
            row.w[j] = w[k];
            row.rest[j] = rest.get(k).copied().unwrap_or(0.0);
            row.live[j] = f32::from(u8::from(k + 1 < m));
        }
        solve_tile::<false>(&mut rows, family);
        for row in &rows {
            for (lane, c) in row.x.iter().flatten().enumerate() {
                assert!(lane % LANES == j || *c == 0.0, "padding moved");
            }
        }
        rows.iter()
            .map(|row| Vec3::new(row.x[0][j], row.x[1][j], row.x[2][j]))
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
