//! Self-collision: the particles of one cloth kept a distance `d` apart, so that folds do
//! not pass through themselves (Müller, "Ten Minute Physics" #15, "Self-collision"; the
//! method of NvCloth's self-collision).
//!
//! Once a step, a spatial hash over the particles (cells the size of the query radius, a
//! dense table of at least twice the particle count filled by counting sort: no allocation once
//! grown) lists the pairs closer than `2.5 d`; the list is kept while no particle has
//! moved `d/4` relative to the cloth's mean since, so every pair off it is at least `2 d`
//! apart and can come within `d` during a step only by closing in faster than `d` a
//! step. Pairs joined by a structural, shear or seam spring are never
//! listed: they are the cloth's own structure (closer than `d` at rest), and a seam's
//! two ends are meant to meet. Each substep, after the model's constraints and before contact:
//! 1. every free particle's motion relative to the mean is clamped to `d/2` a substep
//!    (the velocity clamp): two particles then close in by at most `d` in a substep, so
//!    one cannot pass another between two substeps' tests;
//! 2. every listed pair closer than `d` is pushed apart to `d` along their line, shared
//!    by inverse mass, with Coulomb friction on their relative tangential motion
//!    (position-based friction, Macklin et al. 2014 §6.1), in the list's order
//!    (Gauss–Seidel on one thread: the same bits whatever the pool; the list itself is
//!    made on both cores in pieces joined in order).
//!
//! Cloth–cloth contact is the same test between a cloth's particles and those of the
//! other cloths near it ([`collide_cloths`]): once a step each cloth takes a copy of their
//! particles (position, velocity, inverse mass) and keeps its own `d` from where they
//! were when the step began. Each cloth moves only its own particle, by its share of the
//! correction (`w_i/(w_i + w_k)`), so the two cloths' steps together make the whole
//! correction and neither waits for the other (they step in parallel, each with its own
//! substeps). The push adds no velocity (the other has moved since: a push against a
//! stale position must not launch), only the approach is stopped. Tried and dropped:
//! predicting the others along their velocity (a cloth stopped by a collider is then
//! predicted through it, and the noisy last-substep velocities of a settling cloth made
//! the stack of `assets/scenes/stack.ron` go non-finite); the cost of the stale positions
//! is that two cloths falling together closer than `d` plus a step's fall hold each
//! other back a little.
//!
//! The clamp is relative to the mean motion, so a cloth falling or carried as a whole is
//! not slowed; only its parts' motion relative to one another is bounded, to `d/2` per
//! substep (at 13 substeps of 16 ms and `d` = 3 cm, 12 m/s).

use bevy::math::Vec3;

use super::parallel::{self, PIECE};
use super::{Particles, SpringKind, Springs};
use crate::params::SelfCollision;

/// The self-collision stage's state (see the module doc).
#[derive(Clone, Debug, Default)]
pub(super) struct SelfContact {
    /// The distance kept this step (0: off).
    d: f32,
    /// The most a free particle moves relative to the mean in one substep.
    reach: f32,
    /// Coulomb's coefficient between two particles.
    friction: f32,
    /// Each particle's partners by a structural, shear or seam spring, sorted:
    /// `excluded[excluded_start[i]..excluded_start[i + 1]]`.
    excluded_start: Vec<u32>,
    excluded: Vec<u32>,
    /// The spring count and particle count the exclusions were built for.
    built_for: Option<(usize, usize)>,
    /// The cloth's rest spacing: the median structural rest length.
    spacing: f32,
    /// This step's pairs, `i < j`, in increasing order.
    pairs: Vec<[u32; 2]>,
    /// The hash: each slot's first entry in `entries` (particle indices by slot).
    slot_start: Vec<u32>,
    entries: Vec<u32>,
    /// Each particle's cell when the list was made.
    cells: Vec<[i32; 3]>,
    /// Each piece's pairs while they are listed (kept for their storage).
    found: Vec<Vec<[u32; 2]>>,
    /// Pairs pushed apart since the step began.
    pushed: usize,
    /// The positions when the pairs were listed, and the `d` and the free particles'
    /// mean position then (`None`: no list).
    listed_at: Vec<Vec3>,
    listed: Option<(f32, Vec3)>,
    /// The other cloths' particles near this one, for the step about to begin ([`collide_cloths`]).
    others: Vec<Other>,
    /// This step's pairs of a particle and another cloth's, `[i, k]` (`k` in `others`).
    cross: Vec<[u32; 2]>,
}

/// A particle of another cloth, as it was when the step began.
#[derive(Clone, Copy, Debug, Default)]
struct Other {
    x: Vec3,
    v: Vec3,
    w: f32,
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
        self.fill_hash(&p.position, radius);
        self.find_pairs(p, radius);
        if !self.others.is_empty() {
            let (mean, _) = mean_of_free(p, |i| p.velocity[i]);
            self.find_cross_pairs(&p.position, radius, mean, dt);
        }
        self.listed_at.clone_from(&p.position);
        self.listed = Some((d, centre));
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

    /// Every particle's partners by a structural, shear or seam spring (torn ones too: a
    /// tear's two sides start where they were), and the rest spacing. Bend springs join
    /// particles two spacings apart, farther than `d`: those pairs are kept apart like
    /// any other, so a crease cannot fold flat within two rows (where an edge would pass
    /// through the next cell's triangles without any pair coming closer than `d`).
    fn exclude_springs(&mut self, springs: &Springs, n: usize) {
        let joined: Vec<usize> = [SpringKind::Structural, SpringKind::Shear, SpringKind::Seam]
            .into_iter()
            .flat_map(|kind| springs.ranges[kind as usize].clone())
            .collect();
        let mut count = vec![0u32; n + 1];
        for &s in &joined {
            count[springs.a[s] as usize] += 1;
            count[springs.b[s] as usize] += 1;
        }
        self.excluded_start.clear();
        self.excluded_start.push(0);
        let mut total = 0;
        for c in &count[..n] {
            total += c;
            self.excluded_start.push(total);
        }
        self.excluded.clear();
        self.excluded.resize(total as usize, 0);
        let mut fill: Vec<u32> = self.excluded_start[..n].to_vec();
        for &s in &joined {
            let (a, b) = (springs.a[s], springs.b[s]);
            self.excluded[fill[a as usize] as usize] = b;
            fill[a as usize] += 1;
            self.excluded[fill[b as usize] as usize] = a;
            fill[b as usize] += 1;
        }
        for i in 0..n {
            let (start, end) = (self.excluded_start[i], self.excluded_start[i + 1]);
            self.excluded[start as usize..end as usize].sort_unstable();
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

    /// Whether `i` and `j` are joined by a spring.
    fn excluded(&self, i: u32, j: u32) -> bool {
        let (start, end) = (
            self.excluded_start[i as usize],
            self.excluded_start[i as usize + 1],
        );
        self.excluded[start as usize..end as usize]
            .binary_search(&j)
            .is_ok()
    }

    /// Sorts the particles into the hash's slots by their cell of size `cell`.
    fn fill_hash(&mut self, x: &[Vec3], cell: f32) {
        let slots = table_size(x.len());
        self.cells.clear();
        self.cells.extend(x.iter().map(|&xi| cell_of(xi, cell)));
        self.slot_start.clear();
        self.slot_start.resize(slots + 1, 0);
        for &c in &self.cells {
            self.slot_start[slot(c, slots)] += 1;
        }
        let mut total = 0;
        for start in self.slot_start.iter_mut() {
            total += *start;
            *start = total;
        }
        // Filled from the back, so each slot's entries end up in increasing order and
        // `slot_start[k]` at the slot's first.
        self.entries.clear();
        self.entries.resize(x.len(), 0);
        for (i, &c) in self.cells.iter().enumerate().rev() {
            let k = slot(c, slots);
            self.slot_start[k] -= 1;
            self.entries[self.slot_start[k] as usize] = i as u32;
        }
    }

    /// The pairs closer than `radius`, not joined by a spring and not both pinned, on
    /// both cores from 16,384 particles (`parallel::PARALLEL_FROM`). Each particle looks in its own cell (at higher indices) and in the 13 cells after it
    /// (all of theirs), so each pair is met once; an entry of a slot is taken only if
    /// its cell is the one looked for (cells sharing a slot are told apart), so nothing
    /// is met twice and no sort is needed. Deterministic: particle order, then cells.
    fn find_pairs(&mut self, p: &Particles, radius: f32) {
        let n = p.len();
        let pieces = n.div_ceil(PIECE);
        let mut found = std::mem::take(&mut self.found);
        found.resize_with(pieces, Vec::new);
        let this = &*self;
        // In pieces of particles over the pool (each piece's pairs in its own list, the
        // lists joined in piece order: the same list on any number of threads).
        parallel::for_each(n, found.iter_mut().enumerate(), |(piece, pairs)| {
            pairs.clear();
            let start = piece * PIECE;
            for i in start..(start + PIECE).min(n) {
                this.pairs_of(i, p, radius * radius, pairs);
            }
        });
        self.pairs.clear();
        for pairs in &found {
            self.pairs.extend_from_slice(pairs);
        }
        self.found = found;
    }

    /// Particle `i`'s pairs closer than `√r2` (see [`Self::find_pairs`]) into `pairs`.
    fn pairs_of(&self, i: usize, p: &Particles, r2: f32, pairs: &mut Vec<[u32; 2]>) {
        let (x, slots) = (&p.position, table_size(p.len()));
        let c = self.cells[i];
        for (n, o) in FORWARD.iter().enumerate() {
            let cell = [c[0] + o[0], c[1] + o[1], c[2] + o[2]];
            let k = slot(cell, slots);
            let (start, end) = (self.slot_start[k], self.slot_start[k + 1]);
            for &j in &self.entries[start as usize..end as usize] {
                let ju = j as usize;
                // The own cell (the first offset): each pair from its lower index.
                if (n == 0 && ju <= i) || self.cells[ju] != cell {
                    continue;
                }
                if x[ju].distance_squared(x[i]) >= r2 {
                    continue;
                }
                let (a, b) = (i.min(ju) as u32, i.max(ju) as u32);
                let pinned = p.inv_mass[i] == 0.0 && p.inv_mass[ju] == 0.0;
                if !pinned && !self.excluded(a, b) {
                    pairs.push([a, b]);
                }
            }
        }
    }

    /// The pairs of a particle of this cloth and one of `others` that can meet in the
    /// step: closer than `radius` plus 1.5× the other's travel relative to this cloth's
    /// mean velocity `mean` (at most three cells away).
    fn find_cross_pairs(&mut self, x: &[Vec3], radius: f32, mean: Vec3, dt: f32) {
        let slots = table_size(x.len());
        for (k, o) in self.others.iter().enumerate() {
            let reach = (radius + 1.5 * (o.v - mean).length() * dt).min(3.0 * radius);
            let c = cell_of(o.x, radius);
            let m = (reach / radius).ceil() as i32;
            for dz in -m..=m {
                for dy in -m..=m {
                    for dx in -m..=m {
                        let k2 = slot([c[0] + dx, c[1] + dy, c[2] + dz], slots);
                        let (start, end) = (self.slot_start[k2], self.slot_start[k2 + 1]);
                        for &i in &self.entries[start as usize..end as usize] {
                            if x[i as usize].distance_squared(o.x) < reach * reach {
                                self.cross.push([i, k as u32]);
                            }
                        }
                    }
                }
            }
        }
        // Two cells may share a slot: each pair once.
        self.cross.sort_unstable();
        self.cross.dedup();
    }

    /// One substep's self-collision (see the module doc): the clamp on each particle's
    /// motion relative to the mean, then every listed pair kept `d` apart with friction.
    /// Velocities follow the corrected positions, `v = (x − x_prev)/h`.
    pub fn resolve(&mut self, p: &mut Particles, h: f32) {
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
            let c = d - r.dot(n);
            let push = n * (c / w);
            p.position[i] -= push * wi;
            p.position[j] += push * wj;
            // Coulomb: their relative tangential motion over the substep, cut by at most
            // μ times the normal correction.
            let moved = (p.position[j] - p.previous[j]) - (p.position[i] - p.previous[i]);
            let slide = moved - n * moved.dot(n);
            let length = slide.length();
            if length > 0.0 {
                let cut = slide * ((mu * c).min(length) / (length * w));
                p.position[i] += cut * wi;
                p.position[j] -= cut * wj;
            }
            p.velocity[i] = (p.position[i] - p.previous[i]) / h;
            p.velocity[j] = (p.position[j] - p.previous[j]) / h;
            self.pushed += 1;
        }
        self.resolve_cross(p, h);
    }

    /// The pairs with the other cloths' particles, kept `d` from where those were when
    /// the step began; this cloth's particle takes its share of the correction, as a
    /// position change that adds no velocity, and its share of stopping its approach,
    /// with friction.
    fn resolve_cross(&mut self, p: &mut Particles, h: f32) {
        let (d, mu) = (self.d, self.friction);
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
            self.pushed += 1;
        }
    }

    /// Clamps each free particle's motion over the substep, relative to the free
    /// particles' mean, to `reach`.
    fn clamp(&self, p: &mut Particles, h: f32) {
        let (mean, _) = mean_of_free(p, |i| p.position[i] - p.previous[i]);
        let reach = self.reach;
        for i in 0..p.len() {
            if p.inv_mass[i] == 0.0 {
                continue;
            }
            let relative = p.position[i] - p.previous[i] - mean;
            let l2 = relative.length_squared();
            if l2 > reach * reach {
                let relative = relative * (reach / l2.sqrt());
                p.position[i] = p.previous[i] + mean + relative;
                p.velocity[i] = (mean + relative) / h;
            }
        }
    }
}

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

/// A cell and the 13 after it (of the 26 around it, those with the first non-zero
/// offset positive): every two neighbouring cells are met once, from the first.
const FORWARD: [[i32; 3]; 14] = [
    [0, 0, 0],
    [1, 0, 0],
    [-1, 1, 0],
    [0, 1, 0],
    [1, 1, 0],
    [-1, -1, 1],
    [0, -1, 1],
    [1, -1, 1],
    [-1, 0, 1],
    [0, 0, 1],
    [1, 0, 1],
    [-1, 1, 1],
    [0, 1, 1],
    [1, 1, 1],
];

/// The hash table's slots for `n` particles: a power of two, at least `2n`.
fn table_size(n: usize) -> usize {
    (2 * n).next_power_of_two()
}

/// The list is made again once a particle has moved this many times `d` relative to the
/// cloth's mean since it was made: until then every pair off it is at least
/// `(LIST_RADIUS − 2·RELIST_AFTER)·d = 2 d` apart.
const RELIST_AFTER: f32 = 0.25;

/// The cell of size `cell` that `x` is in (float-to-int casts saturate: a far point
/// lands in an edge cell, which only costs a candidate).
fn cell_of(x: Vec3, cell: f32) -> [i32; 3] {
    let c = (x / cell).floor();
    [c.x as i32, c.y as i32, c.z as i32]
}

/// The hash slot of cell `c` among `slots`, a power of two (Teschner et al. 2003's
/// primes; a mask, not a division: this runs 27 times a particle a step).
fn slot(c: [i32; 3], slots: usize) -> usize {
    let h = (c[0].wrapping_mul(92_837_111))
        ^ (c[1].wrapping_mul(689_287_499))
        ^ (c[2].wrapping_mul(283_923_481));
    (h as u32 as usize) & (slots - 1)
}

/// Cloth–cloth contact for the step about to begin (see the module doc): each cloth of
/// `cloths` with self-collision on takes the particles of the others with it on that
/// lie within its box grown by a margin (their positions and velocities now, and their
/// inverse masses: 0 for a cloth that will not step, `moving` false, such as a sleeping
/// one, so the cloth that steps takes the whole correction). Call it before the cloths'
/// `begin_step`; a cloth keeps its copy until the next call.
pub fn collide_cloths(cloths: &mut [(&mut super::ClothSolver, bool)]) {
    let on: Vec<bool> = cloths
        .iter()
        .map(|(c, _)| c.params.self_collision.enabled)
        .collect();
    let boxes: Vec<(Vec3, Vec3)> = cloths
        .iter()
        .map(|(c, _)| {
            let x = &c.particles.position;
            x.iter()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
                    (lo.min(p), hi.max(p))
                })
        })
        .collect();
    for a in 0..cloths.len() {
        let mut others = std::mem::take(&mut cloths[a].0.self_contact.others);
        others.clear();
        if on[a] {
            // What can come within reach of the cloth in a step: four spacings, and where
            // a particle's speed takes it in 50 ms (three 16 ms steps).
            let (lo, hi) = boxes[a];
            let margin = 4.0 * cloths[a].0.self_contact.spacing.max(0.01);
            for b in (0..cloths.len()).filter(|&b| b != a && on[b]) {
                let (other, moving) = (&*cloths[b].0, cloths[b].1);
                let p = &other.particles;
                for i in 0..p.len() {
                    let reach = margin + p.velocity[i].length() * 0.05;
                    let x = p.position[i];
                    if x.cmpge(lo - reach).all() && x.cmple(hi + reach).all() {
                        others.push(Other {
                            x,
                            v: p.velocity[i],
                            w: if moving { p.inv_mass[i] } else { 0.0 },
                        });
                    }
                }
            }
        }
        cloths[a].0.self_contact.others = others;
    }
}
