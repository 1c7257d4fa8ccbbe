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

use crate::solver::integrate::compensated_add;
use crate::solver::parallel::{self, CHUNK};
use crate::solver::xpbd::Family;
use crate::solver::{Particles, SpringKind, Springs};

mod thomas;

pub(in crate::solver) use thomas::{LANES, Row, solve_tile};

/// No particle, no constraint (a padding slot, or a chain's last particle).
const NONE: u32 = u32::MAX;
/// Two edges continue each other through a particle when the angle between them is
/// within 60° of straight.
const STRAIGHT: f32 = 0.5;

/// The chains of a cloth's structural constraints, in sets solved one after another.
#[derive(Clone, Debug, Default)]
pub(in crate::solver) struct Chains {
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
    /// The tiles in pieces of about [`CHUNK`] slots, for the compute pool.
    pieces: Vec<Range<usize>>,
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
        // Pieces of whole tiles, about CHUNK slots each.
        let rows = particle.len() / LANES;
        let mut pieces = Vec::new();
        let mut from = 0;
        for t in 0..tiles.len() {
            let end = tiles.get(t + 1).map_or(rows, |tile| tile.0);
            if (end - tiles[from].0) * LANES >= CHUNK {
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
            .chunks_mut(CHUNK)
            .zip(p.velocity.chunks_mut(CHUNK))
            .zip(p.residue.chunks_mut(CHUNK))
            .zip(self.slot_of.chunks(CHUNK));
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

#[cfg(test)]
mod tests;
