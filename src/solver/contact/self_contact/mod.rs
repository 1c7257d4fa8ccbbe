//! Self-collision: the particles of one cloth kept a distance `d` apart, so that folds do
//! not pass through themselves (Müller, "Ten Minute Physics" #15, "Self-collision"; the
//! method of NvCloth's self-collision).
//!
//! Once a step, a uniform grid over the cloth's box (cells the size of the query radius,
//! at most four a particle, filled by counting sort: no allocation once grown) lists the
//! pairs closer than `2.5 d`; the list is kept while no particle has moved `d/4`
//! relative to the cloth's mean since, so every pair off it is at least `2 d` apart and
//! can come within `d` during a step only by closing in faster than `d` a step. Rest
//! neighbours are not listed (NvCloth and Ten Minute Physics #15 leave them out too):
//! particles joined by a structural, shear or seam spring never (they are the cloth's
//! own structure, closer than `d` at rest, and a seam's two ends are meant to meet), and
//! particles two such springs apart only once closer than `1.75 d`, where the cloth
//! folds sharply between them. A flat or gently curved cloth so lists no pair at all.
//! Each substep, after the model's constraints and before contact:
//! 1. every free particle's motion relative to the mean is clamped to `d/2` a substep
//!    (the velocity clamp): two particles then close in by at most `d` in a substep, so
//!    one cannot pass another between two substeps' tests;
//! 2. every listed pair closer than `d` is moved apart to `d` along their line, shared
//!    by inverse mass, a move that adds no velocity; their approach along the line is
//!    stopped and Coulomb friction takes at most μ times that from their relative
//!    sliding (contact at the velocity level, as cloth–cloth contact below; friction
//!    from the overlap held jammed folds), in the list's order (Gauss–Seidel on one thread: the
//!    same bits whatever the pool; the list itself is made on both cores in pieces
//!    joined in order).
//!
//! Cloth–cloth contact is the same test between a cloth's particles and those of the
//! other cloths near it ([`collide_cloths`]): once a step each cloth takes a copy of their
//! particles (position, velocity, inverse mass) and lists the pairs that can meet in
//! the step. Cloths with such a copy step together (`many.rs`): at one substep count,
//! the most any of them needs, and
//! before each substep's constraints the copy is
//! refreshed to where the others are then, so each keeps its `d` from where they were
//! one substep ago. Each cloth moves only its own particle, by its share of the
//! correction (`w_i/(w_i + w_k)`), so the two cloths' substeps together make the whole
//! correction (a Jacobi split across the cloths; Gauss–Seidel within one). The push
//! adds no velocity (the other has moved since: a push against a stale position must not
//! launch), only the approach is stopped. Tried and dropped: predicting the others along
//! their velocity (a cloth stopped by a collider is then predicted through it, and the
//! stack of `assets/scenes/stack.ron` went non-finite); keeping the copy a whole step
//! old (the cloths could then step apart in parallel, but that stack never came to
//! rest: particles jittered by up to 1 m/s, each cloth pushed off where the others had
//! been); under-relaxing the share, or a cloth taking the whole correction (no better).

//! The clamp is relative to the mean motion, so a cloth falling or carried as a whole is
//! not slowed; only its parts' motion relative to one another is bounded, to `d/2` per
//! substep (at 13 substeps of 16 ms and `d` = 3 cm, 12 m/s).

mod cloths;
mod grid;

pub(in crate::solver) use cloths::refresh;
use cloths::{Other, bounds};
pub use cloths::{collide_cloths, exchange_cloths};
use grid::Grid;

use bevy::math::{Vec3, Vec3A};

use crate::params::SelfCollision;
use crate::solver::parallel::{self, CHUNK};
use crate::solver::state::mark;
use crate::solver::{Particles, SpringKind, Springs};

/// The self-collision stage's state (see the module doc).
#[derive(Clone, Debug, Default)]
pub(in crate::solver) struct SelfContact {
    /// The distance kept this step between the cloth's own particles (0: off).
    d: f32,
    /// The distance kept from the other cloths' particles this step.
    d_cross: f32,
    /// The most a free particle moves relative to the mean in one substep.
    reach: f32,
    /// Coulomb's coefficient between two particles.
    friction: f32,
    /// Each particle's rest neighbours (within two structural, shear or seam springs),
    /// sorted: `excluded[excluded_start[i]..excluded_start[i + 1]]`.
    excluded_start: Vec<u32>,
    excluded: Vec<u32>,
    /// The spring count and particle count the exclusions were built for.
    built_for: Option<(usize, usize)>,
    /// The cloth's rest spacing: the median structural rest length.
    spacing: f32,
    /// This step's pairs, `i < j`, in the grid's cell order.
    pairs: Vec<[u32; 2]>,
    /// The grid: its box's low corner, its cell size and cells a side, each cell's first
    /// entry in `entries` (particle indices by cell, each cell's in increasing order),
    /// and each entry's position.
    grid: Grid,
    cell_start: Vec<u32>,
    entries: Vec<u32>,
    entry_x: Vec<Vec3A>,
    /// Each particle's cell (scratch of the counting sort).
    cells: Vec<u32>,
    /// Each piece's first cell while the pairs are listed, and the grid's cell count.
    piece_cells: Vec<usize>,
    /// Each piece's pairs while they are listed (kept for their storage).
    found: Vec<Vec<[u32; 2]>>,
    /// Pairs pushed apart since the step began.
    pushed: usize,
    /// The positions when the pairs were listed, and the `d` and the free particles'
    /// mean position then (`None`: no list).
    listed_at: Vec<Vec3>,
    listed: Option<(f32, Vec3)>,
    /// How many lists have been made.
    listings: u64,
    /// The other cloths' particles near this one, for the step about to begin ([`collide_cloths`]).
    others: Vec<Other>,
    /// This step's pairs of a particle and another cloth's, `[i, k]` (`k` in `others`).
    cross: Vec<[u32; 2]>,
    /// This cloth's place among those the last [`collide_cloths`] was given.
    tag: Option<u32>,
    /// The clamp's sums of motion and free particles, piece by piece.
    sums: Vec<(Vec3, usize)>,
}

impl SelfContact {
    /// The distance kept this step (0 when self-collision is off).
    pub fn distance(&self) -> f32 {
        self.d
    }

    /// The pairs listed this step.
    pub fn pair_count(&self) -> usize {
        self.pairs.len()
    }

    /// Whether the last [`collide_cloths`] gave this cloth other cloths' particles.
    pub fn touches_others(&self) -> bool {
        !self.others.is_empty()
    }

    /// How many times the pairs have been listed (once a step at most, when the list
    /// made before no longer holds).
    pub fn listings(&self) -> u64 {
        self.listings
    }

    /// Pairs pushed apart since the step began (a pair counts once per substep).
    pub fn pushed(&self) -> usize {
        self.pushed
    }

    /// Lists this step's pairs (switched off when `params` is off or the model has no
    /// self-collision: `on` false). `dt` is the step.
    pub fn prepare(
        &mut self,
        p: &Particles,
        springs: &Springs,
        params: &SelfCollision,
        on: bool,
        dt: f32,
    ) {
        self.cross.clear();
        self.pushed = 0;
        self.d = 0.0;
        if !(on && params.enabled) || p.is_empty() {
            self.others.clear();
            self.pairs.clear();
            self.listed = None;
            return;
        }
        if self.built_for != Some((springs.len(), p.len())) {
            self.exclude_springs(springs, p.len());
        }
        let d = params
            .distance
            .map_or(DEFAULT_DISTANCE * self.spacing, |d| d.min(self.spacing));
        self.d_cross = params
            .distance
            .map_or(self.spacing, |d| d.min(self.spacing));
        if d.is_nan() || d <= 0.0 {
            return;
        }
        let (centre, free) = mean_of_free(p, |i| p.position[i]);
        if free == 0 {
            return;
        }
        // The clamp: at most `d/2` a substep relative to the mean, so two listed
        // particles close in by at most `d` a substep and one cannot pass the other.
        self.reach = 0.5 * d;
        self.d = d;
        self.friction = params.friction;
        let radius = LIST_RADIUS * d;
        if self.list_holds(p, d, centre) && self.others.is_empty() {
            return;
        }
        self.pairs.clear();
        self.fill_grid(&p.position, radius);
        self.find_pairs(p, radius);
        if !self.others.is_empty() {
            let (mean, _) = mean_of_free(p, |i| p.velocity[i]);
            self.find_cross_pairs(&p.position, LIST_RADIUS * self.d_cross, mean, dt);
        }
        self.listed_at.clone_from(&p.position);
        self.listed = Some((d, centre));
        self.listings += 1;
    }

    /// Whether the last list still holds for `d`: no free particle has moved more than
    /// `d/4` relative to the free particles' mean since it was made, so a pair not on it
    /// is still at least `2 d` apart (a resting or slowly draping cloth keeps its list;
    /// the check is one pass over the particles).
    /// `centre` is the free particles' mean position now.
    fn list_holds(&self, p: &Particles, d: f32, centre: Vec3) -> bool {
        let Some((listed_d, listed_mean)) = self.listed else {
            return false;
        };
        if listed_d != d || self.listed_at.len() != p.len() {
            return false;
        }
        let shift = centre - listed_mean;
        let most = RELIST_AFTER * d;
        (0..p.len()).all(|i| {
            p.inv_mass[i] == 0.0
                || (p.position[i] - self.listed_at[i] - shift).length_squared() <= most * most
        })
    }

    /// Every particle's rest neighbours, and the rest spacing: the particles one
    /// structural, shear or seam spring from it (torn ones too: a tear's two sides start
    /// where they were), then those two such springs from it, tagged [`TWO_SPRINGS`] (listed
    /// only once closer than [`FOLDED`]` d`). On a grid that is the 5 × 5 block around a
    /// particle, every particle within `LIST_RADIUS · d` of it while the cloth lies flat,
    /// so a flat or gently curved cloth lists no pair and pays nothing a substep.
    fn exclude_springs(&mut self, springs: &Springs, n: usize) {
        let joined: Vec<usize> = [SpringKind::Structural, SpringKind::Shear, SpringKind::Seam]
            .into_iter()
            .flat_map(|kind| springs.ranges[kind as usize].clone())
            .collect();
        // The partners by one spring, as rows `near[start[i]..start[i + 1]]`.
        let mut start = vec![0u32; n + 1];
        for &s in &joined {
            start[springs.a[s] as usize + 1] += 1;
            start[springs.b[s] as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut near = vec![0u32; start[n] as usize];
        let mut fill: Vec<u32> = start[..n].to_vec();
        for &s in &joined {
            let (a, b) = (springs.a[s], springs.b[s]);
            near[fill[a as usize] as usize] = b;
            fill[a as usize] += 1;
            near[fill[b as usize] as usize] = a;
            fill[b as usize] += 1;
        }
        let row = |i: usize| &near[start[i] as usize..start[i + 1] as usize];
        // Their partners too (tagged `TWO_SPRINGS`), sorted and each once.
        self.excluded_start.clear();
        self.excluded_start.push(0);
        self.excluded.clear();
        let mut two: Vec<u32> = Vec::new();
        for i in 0..n {
            let one = row(i);
            two.clear();
            for &k in one {
                two.extend(
                    row(k as usize)
                        .iter()
                        .filter(|&&j: &&u32| j as usize != i && !one.contains(&j)),
                );
            }
            two.sort_unstable();
            two.dedup();
            self.excluded.extend_from_slice(one);
            self.excluded.extend(two.iter().map(|&j| j | TWO_SPRINGS));
            self.excluded_start.push(self.excluded.len() as u32);
        }
        let structural = springs.ranges[SpringKind::Structural as usize].clone();
        let mut lengths = springs.rest_length[structural].to_vec();
        if lengths.is_empty() {
            lengths = springs.rest_length.clone();
        }
        lengths.sort_unstable_by(f32::total_cmp);
        self.spacing = lengths.get(lengths.len() / 2).copied().unwrap_or(0.0);
        self.built_for = Some((springs.len(), n));
    }

    /// Sorts the particles into the cells of a grid over their box, cells of size
    /// `cell` or larger (at most [`CELLS_PER_PARTICLE`] cells a particle: a cloth spread
    /// through a large box gets larger cells, more candidates and no more memory), with
    /// each entry's position copied in entry order (the listing reads them in runs).
    fn fill_grid(&mut self, x: &[Vec3], cell: f32) {
        let (lo, hi) = bounds(x);
        let most = CELLS_PER_PARTICLE * x.len().max(64);
        self.grid = Grid::new(lo, hi, cell, most);
        self.cell_start.clear();
        self.cell_start.reserve(most + 1); // once: the grid never has more
        let grid = &self.grid;
        self.cells.clear();
        self.cells
            .extend(x.iter().map(|&xi| grid.index(grid.cell(xi))));
        self.cell_start.resize(grid.len() + 1, 0);
        for &c in &self.cells {
            self.cell_start[c as usize] += 1;
        }
        let mut total = 0;
        for start in self.cell_start.iter_mut() {
            total += *start;
            *start = total;
        }
        // Filled from the back, so each cell's entries end up in increasing order and
        // `cell_start[k]` at the cell's first.
        self.entries.clear();
        self.entries.resize(x.len(), 0);
        for (i, &c) in self.cells.iter().enumerate().rev() {
            self.cell_start[c as usize] -= 1;
            self.entries[self.cell_start[c as usize] as usize] = i as u32;
        }
        self.entry_x.clear();
        self.entry_x
            .extend(self.entries.iter().map(|&i| Vec3A::from(x[i as usize])));
    }

    /// The entries of the cells from `(x0, y, z)` to `(x1, y, z)`: one run, as a row's
    /// cells follow one another.
    fn row(&self, x0: i32, x1: i32, y: i32, z: i32) -> std::ops::Range<usize> {
        let g = &self.grid;
        let (x0, x1) = (x0.max(0), x1.min(g.size[0] - 1));
        if y < 0 || y >= g.size[1] || z < 0 || z >= g.size[2] || x0 > x1 {
            return 0..0;
        }
        let first = g.index([x0, y, z]) as usize;
        let last = g.index([x1, y, z]) as usize;
        self.cell_start[first] as usize..self.cell_start[last + 1] as usize
    }

    /// The pairs closer than `radius`, not rest neighbours and not both pinned, in pieces
    /// of cells over the pool (each piece's pairs in its own list, the lists joined in
    /// piece order: the same list on any number of threads; one fork-join a step, so
    /// from two pieces on). Each entry looks at the later entries of its own cell and
    /// the 13 cells after it, in five runs of consecutive cells (its cell and the next
    /// along x; the row above; the three rows of the next layer), so each pair is met
    /// once, with no hashing, no cell check and no sort.
    fn find_pairs(&mut self, p: &Particles, radius: f32) {
        self.pairs.clear();
        if !self.grid.cell.is_finite() {
            return; // a particle at infinity: nothing to list by (the step is undone)
        }
        // Pieces of about `LIST_CHUNK` particles, cut at cell boundaries (a piece of
        // cells would hold most of the cloth where it lies in a band of the grid).
        let (cells, n) = (self.grid.len(), p.len());
        let mut bounds = std::mem::take(&mut self.piece_cells);
        bounds.clear();
        bounds.extend((0..n.div_ceil(LIST_CHUNK)).map(|k| {
            self.cell_start
                .partition_point(|&s| (s as usize) <= k * LIST_CHUNK)
                .saturating_sub(1)
        }));
        bounds.push(cells);
        let pieces = bounds.len() - 1;
        let mut found = std::mem::take(&mut self.found);
        found.resize_with(pieces, Vec::new);
        let this = &*self;
        let r2 = radius * radius;
        let r2_folded = (radius * FOLDED / LIST_RADIUS).powi(2);
        let work = found.iter_mut().zip(bounds.windows(2));
        parallel::for_each_from(2 * LIST_CHUNK, n, work, |(pairs, cells)| {
            pairs.clear();
            MARK.with_borrow_mut(|mark| {
                if mark.len() < p.len() {
                    mark.resize(p.len(), 0);
                }
                this.pairs_in(cells[0]..cells[1], p, (r2, r2_folded), mark, pairs);
            });
        });
        self.piece_cells = bounds;
        self.pairs.clear();
        for pairs in &found {
            self.pairs.extend_from_slice(pairs);
        }
        self.found = found;
    }

    /// The pairs of the entries of `cells` (see [`Self::find_pairs`]) into `pairs`.
    /// `mark` is all false, and is left so: a particle's rest neighbours are marked
    /// while its candidates are looked at.
    fn pairs_in(
        &self,
        cells: std::ops::Range<usize>,
        p: &Particles,
        (r2, r2_folded): (f32, f32),
        mark: &mut [u8],
        pairs: &mut Vec<[u32; 2]>,
    ) {
        for k in cells {
            let (start, end) = (self.cell_start[k] as usize, self.cell_start[k + 1] as usize);
            if start == end {
                continue;
            }
            let [x, y, z] = self.grid.coords(k);
            let own = self.row(x, x + 1, y, z);
            let runs = [
                self.row(x - 1, x + 1, y + 1, z),
                self.row(x - 1, x + 1, y - 1, z + 1),
                self.row(x - 1, x + 1, y, z + 1),
                self.row(x - 1, x + 1, y + 1, z + 1),
            ];
            for a in start..end {
                let (i, xi) = (self.entries[a] as usize, self.entry_x[a]);
                let near = self.excluded_start[i] as usize..self.excluded_start[i + 1] as usize;
                for &j in &self.excluded[near.clone()] {
                    mark[(j & !TWO_SPRINGS) as usize] = if j & TWO_SPRINGS == 0 { 1 } else { 2 };
                }
                let pinned = p.inv_mass[i] == 0.0;
                for run in std::iter::once(a + 1..own.end).chain(runs.iter().cloned()) {
                    for b in run {
                        let l2 = self.entry_x[b].distance_squared(xi);
                        if l2 >= r2 {
                            continue;
                        }
                        let j = self.entries[b] as usize;
                        let neighbour = match mark[j] {
                            0 => false,
                            1 => true,
                            _ => l2 >= r2_folded,
                        };
                        let both_pinned = pinned && p.inv_mass[j] == 0.0;
                        if !(neighbour || both_pinned) {
                            pairs.push([i.min(j) as u32, i.max(j) as u32]);
                        }
                    }
                }
                for &j in &self.excluded[near] {
                    mark[(j & !TWO_SPRINGS) as usize] = 0;
                }
            }
        }
    }

    /// The pairs of a particle of this cloth and one of `others` that can meet in the
    /// step: closer than `radius` plus 1.5× the other's travel relative to this cloth's
    /// mean velocity `mean` (at most three times `radius`).
    fn find_cross_pairs(&mut self, x: &[Vec3], radius: f32, mean: Vec3, dt: f32) {
        let g = self.grid;
        if !g.cell.is_finite() {
            return;
        }
        for (k, o) in self.others.iter().enumerate() {
            let reach = (radius + 1.5 * (o.v - mean).length() * dt).min(3.0 * radius);
            // The cells the reach overlaps (every particle of this cloth is in the grid's
            // box, so the rest hold none).
            let (lo, hi) = (g.cell(o.x - reach), g.cell(o.x + reach));
            let outside = (0..3).any(|a| {
                let (l, h) = (o.x[a] - reach, o.x[a] + reach);
                h < g.lo[a] || l > g.lo[a] + g.size[a] as f32 * g.cell
            });
            if outside {
                continue;
            }
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for b in self.row(lo[0], hi[0], y, z) {
                        let i = self.entries[b];
                        if x[i as usize].distance_squared(o.x) < reach * reach {
                            self.cross.push([i, k as u32]);
                        }
                    }
                }
            }
        }
        // In this cloth's particle order.
        self.cross.sort_unstable();
    }

    /// One substep's self-collision (see the module doc): the clamp on each particle's
    /// motion relative to the mean, then every listed pair kept `d` apart with friction.
    /// `x_prev` is kept at `x − v h`, so Verlet's velocity is the one set here too.
    /// Each particle it moves apart from another is marked in `touched`.
    pub fn resolve(&mut self, p: &mut Particles, h: f32, touched: &mut [bool]) {
        if self.d == 0.0 {
            return;
        }
        self.clamp(p, h);
        let (d, mu) = (self.d, self.friction);
        for &[i, j] in &self.pairs {
            let (i, j) = (i as usize, j as usize);
            let r = p.position[j] - p.position[i];
            let l2 = r.length_squared();
            if l2 >= d * d {
                continue;
            }
            let (wi, wj) = (p.inv_mass[i], p.inv_mass[j]);
            let w = wi + wj;
            if w == 0.0 {
                continue; // both pinned since the list was made
            }
            // Two particles at one point part the way they came from.
            let l = l2.sqrt();
            let n = if l > 1e-6 * d {
                r / l
            } else {
                (p.previous[j] - p.previous[i]).normalize_or(Vec3::Y)
            };
            // The overlap is undone as a move that adds no velocity, and the approach
            // along `n` is stopped, with Coulomb friction taking at most μ times that
            // from the sliding (velocity-level contact, as for the other cloths below).
            // Friction bounded by μ times the overlap instead held folds where the
            // constraints and self-collision disagree (their overlap is the
            // constraints' pull, not an approach), and they jammed: a flag at the full
            // spacing in 10 m/s air at 128 substeps stretched 42% in 120 steps; now 12%.
            let push = n * ((d - r.dot(n)) / w);
            let (vi, vj) = (
                (p.position[i] - p.previous[i]) / h,
                (p.position[j] - p.previous[j]) / h,
            );
            let relative = vj - vi;
            let approach = relative.dot(n).min(0.0);
            let slide = relative - n * relative.dot(n);
            let length = slide.length();
            let friction = if length > 0.0 {
                slide * ((mu * -approach).min(length) / length)
            } else {
                Vec3::ZERO
            };
            let dv = n * approach + friction;
            p.position[i] -= push * wi;
            p.position[j] += push * wj;
            p.velocity[i] = vi + dv * (wi / w);
            p.velocity[j] = vj - dv * (wj / w);
            p.previous[i] = p.position[i] - p.velocity[i] * h;
            p.previous[j] = p.position[j] - p.velocity[j] * h;
            mark(touched, i);
            mark(touched, j);
            self.pushed += 1;
        }
        self.resolve_cross(p, h, touched);
    }

    /// The pairs with the other cloths' particles, kept `d` from where those were when
    /// the step began; this cloth's particle takes its share of the correction, as a
    /// position change that adds no velocity, and its share of stopping its approach,
    /// with friction.
    fn resolve_cross(&mut self, p: &mut Particles, h: f32, touched: &mut [bool]) {
        let (d, mu) = (self.d_cross, self.friction);
        for &[i, k] in &self.cross {
            let (i, o) = (i as usize, self.others[k as usize]);
            let wi = p.inv_mass[i];
            if wi == 0.0 {
                continue;
            }
            let xo = o.x;
            let r = p.position[i] - xo;
            let l2 = r.length_squared();
            if l2 >= d * d {
                continue;
            }
            let share = wi / (wi + o.w);
            let l = l2.sqrt();
            let n = if l > 1e-6 * d {
                r / l
            } else {
                (p.previous[i] - xo).normalize_or(Vec3::Y)
            };
            // The overlap is undone without adding velocity (`previous` moves with the
            // particle: the other particle has moved since, and a push against where it
            // was must not launch this one); the approach along `n` is stopped, by this
            // cloth's share, and Coulomb friction takes at most μ times that from the
            // sliding.
            let push = n * ((d - r.dot(n)) * share);
            let v = (p.position[i] - p.previous[i]) / h;
            let approach = v.dot(n).min(0.0) * share;
            let slide = v - n * v.dot(n);
            let length = slide.length();
            let friction = if length > 0.0 {
                slide * ((mu * -approach).min(length) / length)
            } else {
                Vec3::ZERO
            };
            let dv = -n * approach - friction;
            p.position[i] += push;
            p.velocity[i] = (p.position[i] - p.previous[i]) / h + dv - push / h;
            p.previous[i] = p.position[i] - p.velocity[i] * h;
            mark(touched, i);
            self.pushed += 1;
        }
    }

    /// Clamps each free particle's motion over the substep, relative to the free
    /// particles' mean, to `reach`; in pieces on both cores from 16,384 particles (the
    /// mean summed piece by piece, the pieces' sums in order: the same bits on any pool).
    fn clamp(&mut self, p: &mut Particles, h: f32) {
        let n = p.len();
        self.sums.clear();
        self.sums.resize(n.div_ceil(CHUNK), (Vec3::ZERO, 0));
        let (x, previous, w) = (&p.position, &p.previous, &p.inv_mass);
        parallel::for_each(n, self.sums.iter_mut().enumerate(), |(k, (sum, free))| {
            for i in k * CHUNK..((k + 1) * CHUNK).min(n) {
                if w[i] != 0.0 {
                    *sum += x[i] - previous[i];
                    *free += 1;
                }
            }
        });
        let (sum, free) = self
            .sums
            .iter()
            .fold((Vec3::ZERO, 0), |(s, f), &(ps, pf)| (s + ps, f + pf));
        let mean = sum / free.max(1) as f32;
        let reach = self.reach;
        parallel::for_each(n, p.chunks(), |piece| {
            for k in 0..piece.position.len() {
                if piece.inv_mass[k] == 0.0 {
                    continue;
                }
                let relative = piece.position[k] - piece.previous[k] - mean;
                let l2 = relative.length_squared();
                if l2 > reach * reach {
                    let relative = relative * (reach / l2.sqrt());
                    piece.position[k] = piece.previous[k] + mean + relative;
                    piece.velocity[k] = (mean + relative) / h;
                }
            }
        });
    }
}

/// The distance a cloth's own particles keep when none is given, as a fraction of the
/// rest spacing `s`: the least that keeps a particle from slipping between the corners
/// of a grid's triangle (its widest gap is the hypotenuse's middle, `s/√2` from each
/// corner) with a margin. At the spacing itself, a cloth behaves as a sheet `s` thick: a
/// polyester flag (4 cm spacing) in 10 m/s gusts folded its corners into jams where
/// self-collision and the stretch constraints disagreed, stretched 59% and took 314
/// substeps against 191 without self-collision; at `0.75 s`, at most 16% at 188–221.
/// Another cloth's particles are kept the full spacing away: their grid does not line
/// up with this one's, and sheared, its triangles open wider than `s/√2` (three
/// cloths stacked at `0.75 s` passed edges through each other in 31 of 39 frames).
pub(crate) const DEFAULT_DISTANCE: f32 = 0.75;

/// The mean of `v(i)` over the free particles, and their count.
fn mean_of_free(p: &Particles, v: impl Fn(usize) -> Vec3) -> (Vec3, usize) {
    let mut sum = Vec3::ZERO;
    let mut free = 0;
    for i in 0..p.len() {
        if p.inv_mass[i] != 0.0 {
            sum += v(i);
            free += 1;
        }
    }
    (sum / free.max(1) as f32, free)
}

/// The pairs listed are those closer than this many times `d`; with the list kept until
/// a particle has moved [`RELIST_AFTER`]` d`, a pair off it is at least `2 d` apart at a
/// step's start, and one closing in faster than `d` a step (2 m/s at `d` = 3 cm and
/// 16 ms) can pass within `d` unseen. A longer list (the relative speed's reach, up to two
/// spacings) cost 6.5× the XPBD step of a swinging 64² cloth at 5 substeps (`cloth peers
/// --sides 64 --hang swing --solvers tethers,self`), against ≤ 0.5× asked.
const LIST_RADIUS: f32 = 2.5;

/// Rest neighbours two springs apart are listed once closer than this many times `d`:
/// a crease folding on one particle (the two across it closing in to `d`), where the
/// particles three springs apart are not yet close. On a grid they are `2 d` and
/// `√5 d` apart while the cloth lies flat, so a flat cloth lists none of them.
/// Without them (every pair within two springs left out) a mass-spring cloth of the stack
/// of `assets/scenes/stack.ron` passed edges through its own triangles.
const FOLDED: f32 = 1.75;

/// The tag of a rest neighbour two springs apart in `excluded`.
const TWO_SPRINGS: u32 = 1 << 31;

/// Particles a piece of the listing (it is one fork-join a step: smaller pieces than
/// the substeps' kernels share two threads more evenly).
const LIST_CHUNK: usize = 512;

thread_local! {
    /// Each thread's marks of one particle's rest neighbours while its candidates are
    /// looked at (all false between particles; grown once to the largest cloth).
    static MARK: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// The list is made again once a particle has moved this many times `d` relative to the
/// cloth's mean since it was made: until then every pair off it is at least
/// `(LIST_RADIUS − 2·RELIST_AFTER)·d = 2 d` apart.
const RELIST_AFTER: f32 = 0.25;

/// The most cells the grid has a particle. A cloth lying in a plane fills about one
/// cell in six of its box at cells of `2.5 d`; a crumpled or swinging one spreads through
/// more, and its cells grow to stay within this (the scratch stays a few bytes a particle).
const CELLS_PER_PARTICLE: usize = 4;

#[cfg(test)]
mod tests {
    use super::*;

    /// A cell far smaller than the box (1e-30 m over 2 m) grows until the grid has at
    /// most the cells asked for, instead of overflowing the count per axis.
    #[test]
    fn a_tiny_cell_over_a_large_box_grows_to_the_cells_allowed() {
        let grid = Grid::new(Vec3::ZERO, Vec3::new(2.0, 1.0, 0.5), 1e-30, 4096);
        let count: i64 = grid.size.iter().map(|&n| i64::from(n)).product();
        assert!((1..=4096).contains(&count), "{:?} cells", grid.size);
        assert_eq!(
            grid.cell(Vec3::new(2.0, 1.0, 0.5)),
            grid.size.map(|n| n - 1)
        );
    }
}
