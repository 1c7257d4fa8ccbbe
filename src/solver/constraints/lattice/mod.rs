//! Grid cloths as stencils: every spring of a grid joins particle `a` to `a + step` for
//! one of a few offsets (structural, shear, bend, diagonal bend), so each offset's
//! springs are read and written as two shifted slices of the particle arrays, with no
//! index lists, no per-spring bounds checks and no scatter through indices.
//!
//! The [`Springs`] stay the truth (tearing, counts, faces, the general path for meshes
//! and garments); a stencil mirrors their rest lengths and weights (stiffness factor ×
//! alive) per offset, synced when they change.
//!
//! The strain limiter on a stencil is a coloured Gauss–Seidel: within one colour (row
//! springs starting on even or on odd particles; from one row to the next the vertical
//! springs, then both diagonals of even cells, then of odd cells) no two springs share a
//! particle, so its corrections do not depend on the order they are made in, nor on the
//! thread. A mirror image of the cloth (even width) maps every colour onto itself, so
//! it is corrected as the mirror image. On one thread (below the pool's threshold) the
//! springs between rows go row after row from the first, so a correction travels down
//! the cloth within a sweep, as in the general path's sweep in spring order; on the
//! pool, bands of two rows in two colours, each band a piece.
//!
//! Both kernels run in fixed pieces over the compute pool (`parallel.rs`).

use std::ops::Range;

use bevy::math::Vec3;

use crate::solver::chains::Row;
use crate::solver::parallel::{self, CHUNK};
use crate::solver::{Particles, SpringKind, Springs};

mod limiter;
mod lines;
mod xpbd;

use limiter::*;

/// One stencil offset: the springs `(a, a + step)` of one family.
#[derive(Clone, Debug)]
struct Offset {
    kind: SpringKind,
    /// Column offset of `b` from `a` (−2…2).
    dx: isize,
    /// Row offset (0, 1 or 2).
    dy: usize,
    /// `b − a` in particle indices.
    step: usize,
    /// Rest length of the spring from `a` (0 where there is none), indexed by `a`; one
    /// per particle (the last `step` are 0), so a row's springs read in whole chunks.
    rest: Vec<f32>,
    /// Stiffness factor × alive of the spring from `a` (0 where there is none or it
    /// tore), indexed by `a`, one per particle as `rest`.
    weight: Vec<f32>,
}

impl Offset {
    /// `(rest, weight)` of the offset's springs from particle `start` on.
    fn springs_from(&self, start: usize) -> (&[f32], &[f32]) {
        (&self.rest[start..], &self.weight[start..])
    }
}

/// A cell's two diagonals: the one from (r, c) to (r + 1, c + 1), and the one from
/// (r, c + 1) to (r + 1, c).
fn right_and_left(diagonals: Option<[&Offset; 2]>) -> (Option<&Offset>, Option<&Offset>) {
    match diagonals {
        Some([d1, d2]) if d1.dx == 1 => (Some(d1), Some(d2)),
        Some([d1, d2]) => (Some(d2), Some(d1)),
        None => (None, None),
    }
}

/// Three lanes of `f32`, one per coordinate (x, y, z): the form the compiler vectorises.
#[derive(Clone, Debug, Default)]
struct Lanes([Vec<f32>; 3]);

impl Lanes {
    fn new(n: usize) -> Self {
        Self([vec![0.0; n], vec![0.0; n], vec![0.0; n]])
    }

    /// Copies `v` into the lanes (in pieces over the compute pool).
    fn load(&mut self, v: &[Vec3]) {
        let [x, y, z] = &mut self.0;
        let pieces = x
            .chunks_mut(CHUNK)
            .zip(y.chunks_mut(CHUNK))
            .zip(z.chunks_mut(CHUNK))
            .zip(v.chunks(CHUNK));
        parallel::for_each(v.len(), pieces, |(((x, y), z), v)| {
            for (((x, y), z), v) in x.iter_mut().zip(y.iter_mut()).zip(z.iter_mut()).zip(v) {
                (*x, *y, *z) = (v.x, v.y, v.z);
            }
        });
    }
}

/// The forces of one piece of an offset's springs (those from `from` on, as many as
/// `out` holds) into `out`, branch-free so the loop vectorises.
fn spring_piece(
    o: &Offset,
    k: f32,
    damping: f32,
    from: usize,
    x: &Lanes,
    v: &Lanes,
    out: [&mut [f32]; 3],
) {
    let [sx, sy, sz] = out;
    let len = sx.len();
    let (a, b) = (from..from + len, from + o.step..from + o.step + len);
    let (sy, sz) = (&mut sy[..len], &mut sz[..len]);
    let (rest, weight) = (&o.rest[a.clone()], &o.weight[a.clone()]);
    // Each lane at the springs' starts (`_a`) and ends (`_b`).
    let [x, y, z] = &x.0;
    let (xa, ya, za) = (&x[a.clone()], &y[a.clone()], &z[a.clone()]);
    let (xb, yb, zb) = (&x[b.clone()], &y[b.clone()], &z[b.clone()]);
    let [vx, vy, vz] = &v.0;
    let (vxa, vya, vza) = (&vx[a.clone()], &vy[a.clone()], &vz[a]);
    let (vxb, vyb, vzb) = (&vx[b.clone()], &vy[b.clone()], &vz[b]);
    for i in 0..len {
        let (dx, dy, dz) = (xb[i] - xa[i], yb[i] - ya[i], zb[i] - za[i]);
        let l = (dx * dx + dy * dy + dz * dz).sqrt();
        // 1/|l| for a live spring, 0 for a torn or missing one (no branch).
        let live = f32::from(u8::from(weight[i] != 0.0 && l > f32::EPSILON));
        let inv = live / l.max(f32::EPSILON);
        let along = (vxb[i] - vxa[i]) * dx + (vyb[i] - vya[i]) * dy + (vzb[i] - vza[i]) * dz;
        let magnitude = k * weight[i] * (l - rest[i]) + damping * along * inv;
        let scale = magnitude * inv;
        (sx[i], sy[i], sz[i]) = (dx * scale, dy * scale, dz * scale);
    }
}

/// Adds to `sum` (one lane of the particles from `from` on) the forces `springs` of an
/// offset of `step` (one lane, the springs from `lo` on, of `m` in all): `+` on each
/// spring's start, `−` on its end, in that order for every particle.
fn add_ends(sum: &mut [f32], springs: &[f32], from: usize, lo: usize, step: usize, m: usize) {
    let len = sum.len();
    if from < m {
        let end = (from + len).min(m);
        for (f, s) in sum[..end - from]
            .iter_mut()
            .zip(&springs[from - lo..end - lo])
        {
            *f += s;
        }
    }
    let (first, last) = (from.max(step), from + len);
    if first < last {
        for (f, s) in sum[first - from..]
            .iter_mut()
            .zip(&springs[first - step - lo..last - step - lo])
        {
            *f -= s;
        }
    }
}

/// What every piece of [`Stencil::spring_forces`] reads.
struct SpringPass<'a> {
    offsets: &'a [Offset],
    /// Each offset's stiffness (0: its family is off).
    stiffness: &'a [f32],
    damping: f32,
    x: &'a Lanes,
    v: &'a Lanes,
    /// Particles in all.
    n: usize,
}

impl SpringPass<'_> {
    /// The spring forces on the particles of the piece from `from` on: for each offset,
    /// the forces of the springs that start or end in the piece into `halo` (those
    /// crossing into the previous piece computed by both, the same way), then each
    /// particle's sum into `sums` (`+` from the springs it starts, `−` from those it
    /// ends, offset by offset), added to `force` at the end.
    fn piece(
        &self,
        from: usize,
        mut sums: [&mut [f32]; 3],
        halo: [&mut [f32]; 3],
        force: &mut [Vec3],
    ) {
        let n = self.n;
        sums.iter_mut().for_each(|sum| sum.fill(0.0));
        let [hx, hy, hz] = halo;
        for (o, &k) in self.offsets.iter().zip(self.stiffness) {
            if k == 0.0 {
                continue;
            }
            // The springs that start or end in this piece: from `lo` to `hi`.
            let m = n - o.step;
            let lo = from.saturating_sub(o.step).min(m);
            let hi = (from + CHUNK).min(m).max(lo);
            let springs = [&mut hx[..hi - lo], &mut hy[..hi - lo], &mut hz[..hi - lo]];
            spring_piece(o, k, self.damping, lo, self.x, self.v, springs);
            let springs = [&hx[..hi - lo], &hy[..hi - lo], &hz[..hi - lo]];
            for (sum, springs) in sums.iter_mut().zip(springs) {
                add_ends(sum, springs, from, lo, o.step, m);
            }
        }
        let [fx, fy, fz] = sums;
        for (((force, x), y), z) in force.iter_mut().zip(&*fx).zip(&*fy).zip(&*fz) {
            *force += Vec3::new(*x, *y, *z);
        }
    }
}

/// The index in `offsets` of the offset of `kind` by `(dx, dy)` (`step` in particle
/// indices), added (empty, for `n` particles) if it is not there yet.
fn offset_of(
    offsets: &mut Vec<Offset>,
    (kind, dx, dy): (SpringKind, isize, usize),
    step: usize,
    n: usize,
) -> usize {
    if let Some(index) = offsets
        .iter()
        .position(|o| o.kind == kind && o.dx == dx && o.dy == dy)
    {
        return index;
    }
    offsets.push(Offset {
        kind,
        dx,
        dy,
        step,
        rest: vec![0.0; n],
        weight: vec![0.0; n],
    });
    offsets.len() - 1
}

/// The slot of a spring that is not in the stencil ([`Rows`]).
const APART: u8 = u8::MAX;

/// A mesh whose particles lie in rows (a skirt, a sleeve: a grid wrapped round into a
/// cone or a tube): its springs' forces on a stencil over the rows, and the few that are
/// no grid offset (those across the seam where the rows close) kept apart, for the
/// general path. Only its forces take the stencil: its strain limiter and XPBD stay on
/// the general path, whose sweep needs no colours of offsets.
#[derive(Clone, Debug)]
pub(in crate::solver) struct Rows {
    pub stencil: Stencil,
    /// The springs kept apart, by index in increasing order (so each family's are
    /// together).
    pub apart: Vec<u32>,
}

impl Rows {
    /// Rows in a mesh's `springs` over `n` particles, when at most one spring in
    /// [`APART_SHARE`] is no offset of them and the offsets are at least half full. The
    /// row's length is among the commonest distances in index between a structural
    /// spring's ends (beyond the two a stencil reaches along a row); the likeliest few
    /// are tried, and the one that keeps fewest springs apart is taken.
    pub fn find(springs: &Springs, n: usize) -> Option<Self> {
        let structural = springs.ranges[SpringKind::Structural as usize].clone();
        let mut count = std::collections::HashMap::<usize, usize>::new();
        for s in structural.clone() {
            let d = springs.a[s].abs_diff(springs.b[s]) as usize;
            if d > 2 && d <= n / 2 {
                *count.entry(d).or_default() += 1;
            }
        }
        let mut widths: Vec<(usize, usize)> = count
            .into_iter()
            .filter(|&(_, c)| c * 8 >= structural.len())
            .collect();
        widths.sort_by_key(|&(w, c)| (std::cmp::Reverse(c), w));
        widths
            .into_iter()
            .take(3)
            .filter_map(|(width, _)| {
                let mut apart = Vec::new();
                let stencil = Stencil::build(springs, width, n, Some(&mut apart))?;
                Some(Rows { stencil, apart })
            })
            .min_by_key(|rows| rows.apart.len())
            .filter(|rows| rows.apart.len() * APART_SHARE <= springs.len())
            // Each offset is a pass over every particle: at least half of them must
            // start one of its springs, or the general path does less.
            .filter(|rows| rows.stencil.offsets.len() * n <= 2 * springs.len())
    }
}

/// A mesh is taken as [`Rows`] when at most one spring in this many is kept apart.
const APART_SHARE: usize = 8;

/// A grid cloth's springs as stencil offsets.
#[derive(Clone, Debug)]
pub(in crate::solver) struct Stencil {
    width: usize,
    offsets: Vec<Offset>,
    /// For each spring: its offset and `a`, to follow tearing.
    slot: Vec<(u8, u32)>,
    /// Each offset's stiffness in this substep (0: its family is off).
    stiffness: Vec<f32>,
    /// Each piece's spring forces of one offset at a time: the springs that start or
    /// end in the piece (`CHUNK + max_step` per piece), so a piece's forces stay in its
    /// core's cache and no piece writes another's.
    halo: Lanes,
    /// The largest offset `b − a`.
    max_step: usize,
    /// Positions, velocities and forces as lanes, for the substep's kernels.
    x: Lanes,
    v: Lanes,
    f: Lanes,
    /// The limiter's corrections in one call, summed per particle (zero between calls).
    dx: Lanes,
    /// Positions at the start of the substep, for XPBD's damping (`lattice/xpbd.rs`),
    /// loaded when a family is `damped`.
    previous: Lanes,
    damped: bool,
    /// What rounding lost of the lines' moves in this substep (`lattice/lines.rs`), and
    /// whether they moved anything since the lanes were loaded.
    residue: Lanes,
    lines_moved: bool,
    /// The lines' tiles, the rows' and the columns': a set's chains side by side, one
    /// row per particle along them; their springs' rest lengths and weights are taken
    /// again when `tiles_synced` is false.
    tiles: [Vec<Row>; 2],
    tiles_synced: bool,
}

impl Stencil {
    /// The stencil of `springs` on a `width`-wide grid of `n` particles, or `None` when a
    /// spring is not a grid offset (a seam, a welded mesh) or two share a slot.
    pub fn new(springs: &Springs, width: usize, n: usize) -> Option<Self> {
        Self::build(springs, width, n, None)
    }

    /// [`Stencil::new`], or with `apart` the stencil of the springs that are grid
    /// offsets, the others (by index, in increasing order) put in `apart`.
    fn build(
        springs: &Springs,
        width: usize,
        n: usize,
        mut apart: Option<&mut Vec<u32>>,
    ) -> Option<Self> {
        let mut offsets: Vec<Offset> = Vec::new();
        let mut slot = Vec::with_capacity(springs.len());
        for s in 0..springs.len() {
            let kind = springs.kind(s);
            let (mut a, mut b) = (springs.a[s] as usize, springs.b[s] as usize);
            if b < a {
                std::mem::swap(&mut a, &mut b);
            }
            let dy = b / width - a / width;
            let dx = (b % width) as isize - (a % width) as isize;
            // Its offset, unless it is none (a seam, too far) or its slot is taken.
            let index = (kind != SpringKind::Seam && dy <= 2 && dx.abs() <= 2)
                .then(|| offset_of(&mut offsets, (kind, dx, dy), b - a, n))
                .filter(|&o| offsets[o].rest[a] == 0.0);
            let Some(index) = index else {
                apart.as_mut()?.push(s as u32);
                slot.push((APART, 0));
                continue;
            };
            offsets[index].rest[a] = springs.rest_length[s];
            slot.push((index as u8, a as u32));
        }
        let max_step = offsets.iter().map(|o| o.step).max().unwrap_or(0);
        let mut stencil = Self {
            stiffness: vec![0.0; offsets.len()],
            halo: Lanes::new(n.div_ceil(CHUNK) * (CHUNK + max_step)),
            max_step,
            width,
            offsets,
            slot,
            x: Lanes::new(n),
            v: Lanes::new(n),
            f: Lanes::new(n),
            dx: Lanes::new(n),
            previous: Lanes::new(n),
            damped: false,
            residue: Lanes::new(n),
            lines_moved: false,
            tiles: [Vec::new(), Vec::new()],
            tiles_synced: false,
        };
        stencil.tiles = [true, false].map(|rows| vec![Row::default(); stencil.tile_rows(rows)]);
        stencil.sync(springs);
        Some(stencil)
    }

    /// Takes the springs' rest lengths, stiffness factors and alive flags.
    pub fn sync(&mut self, springs: &Springs) {
        for (s, &(o, a)) in self.slot.iter().enumerate() {
            if o == APART {
                continue;
            }
            let offset = &mut self.offsets[o as usize];
            offset.rest[a as usize] = springs.rest_length[s];
            offset.weight[a as usize] = if springs.alive[s] {
                springs.scale(s)
            } else {
                0.0
            };
        }
        self.tiles_synced = false;
    }

    /// Spring `s` tore.
    pub fn tear(&mut self, s: usize) {
        let (o, a) = self.slot[s];
        if o != APART {
            self.offsets[o as usize].weight[a as usize] = 0.0;
            self.tiles_synced = false;
        }
    }

    /// Adds every spring's Hooke force `k (|l| − l0) l/|l|` plus damping along it
    /// (the general path's law, `forces.rs`) to `p.force`; `k` per family. In pieces of
    /// particles over the compute pool: for each offset, the forces of the springs that
    /// start or end in the piece (those crossing into the previous piece computed by
    /// both, the same way), then each particle's sum (`+` from the springs it starts, `−`
    /// from those it ends, offset by offset).
    pub fn spring_forces(
        &mut self,
        p: &mut Particles,
        k: impl Fn(SpringKind) -> f32,
        damping: f32,
    ) {
        let n = p.len();
        self.x.load(&p.position);
        self.v.load(&p.velocity);
        for (stiffness, offset) in self.stiffness.iter_mut().zip(&self.offsets) {
            *stiffness = k(offset.kind);
        }
        let pass = SpringPass {
            offsets: &self.offsets,
            stiffness: &self.stiffness,
            damping,
            x: &self.x,
            v: &self.v,
            n,
        };
        let halo = CHUNK + self.max_step;
        let [fx, fy, fz] = &mut self.f.0;
        let [hx, hy, hz] = &mut self.halo.0;
        let pieces = fx
            .chunks_mut(CHUNK)
            .zip(fy.chunks_mut(CHUNK))
            .zip(fz.chunks_mut(CHUNK))
            .zip(p.force.chunks_mut(CHUNK))
            .zip(
                hx.chunks_mut(halo)
                    .zip(hy.chunks_mut(halo))
                    .zip(hz.chunks_mut(halo)),
            )
            .enumerate();
        parallel::for_each(
            n,
            pieces,
            |(i, ((((fx, fy), fz), force), ((hx, hy), hz)))| {
                pass.piece(i * CHUNK, [fx, fy, fz], [hx, hy, hz], force);
            },
        );
    }

    /// Provot's strain limit (the general path's law, `integrate.rs`) over the enabled
    /// structural and shear springs: `sweeps` coloured sweeps (see the module doc), or
    /// fewer once one finds every spring within `past·l0` (with `past` given). Works on
    /// lanes; each particle's velocity takes its whole correction over `h`. Returns the
    /// sweeps run, and whether the last found every spring within `past·l0` (true
    /// without `past`).
    #[allow(clippy::too_many_arguments)]
    pub fn limit_strain(
        &mut self,
        p: &mut Particles,
        enabled: impl Fn(SpringKind) -> bool,
        limit: f32,
        sweeps: u32,
        past: Option<f32>,
        h: f32,
    ) -> (u32, bool) {
        self.x.load(&p.position);
        let (mut run, mut within, mut moved) = (0, past.is_none(), false);
        while run < sweeps {
            run += 1;
            let bits = match past {
                None => self.sweep::<false>(&p.inv_mass, &enabled, limit, f32::INFINITY),
                Some(past) => self.sweep::<true>(&p.inv_mass, &enabled, limit, past),
            };
            moved |= bits & MOVED != 0;
            if past.is_some() && bits & UNCONVERGED == 0 {
                within = true;
                break;
            }
        }
        // Nothing corrected (a calm cloth within its limit): the particles are as they were.
        if !moved {
            return (run, within);
        }
        self.store(p, h);
        (run, within)
    }

    /// The lanes back into the particles after [`Self::limit_strain`]'s sweeps: each
    /// position, and each velocity its summed correction over `h`.
    fn store(&mut self, p: &mut Particles, h: f32) {
        // The velocity takes the summed corrections, not the difference of the positions
        // before and after: at hundreds of substeps a correction is a few float spacings
        // of a position 2 m from the origin, and that difference was noise (the accuracy
        // study's reference stopped converging in h).
        // The sums are zeroed as they are read, ready for the next call.
        let ([x, y, z], [dx, dy, dz]) = (&self.x.0, &mut self.dx.0);
        let lanes = x.chunks(CHUNK).zip(y.chunks(CHUNK)).zip(z.chunks(CHUNK));
        let sums = dx
            .chunks_mut(CHUNK)
            .zip(dy.chunks_mut(CHUNK))
            .zip(dz.chunks_mut(CHUNK));
        let pieces = p
            .position
            .chunks_mut(CHUNK)
            .zip(p.velocity.chunks_mut(CHUNK))
            .zip(lanes.zip(sums));
        parallel::for_each(
            x.len(),
            pieces,
            |((position, velocity), (((x, y), z), ((dx, dy), dz)))| {
                let lanes = x
                    .iter()
                    .zip(y)
                    .zip(z)
                    .zip(dx.iter_mut().zip(dy.iter_mut()).zip(dz.iter_mut()));
                for ((position, velocity), (((x, y), z), ((dx, dy), dz))) in
                    position.iter_mut().zip(velocity).zip(lanes)
                {
                    *velocity += Vec3::new(*dx, *dy, *dz) / h;
                    *position = Vec3::new(*x, *y, *z);
                    (*dx, *dy, *dz) = (0.0, 0.0, 0.0);
                }
            },
        );
    }

    /// One coloured sweep: [`MOVED`] when it corrected a spring, and with `TRACK`
    /// [`UNCONVERGED`] when a spring was longer than `past·l0`.
    fn sweep<const TRACK: bool>(
        &mut self,
        inv_mass: &[f32],
        enabled: &impl Fn(SpringKind) -> bool,
        limit: f32,
        past: f32,
    ) -> u8 {
        let limited = |o: &&Offset| {
            matches!(o.kind, SpringKind::Structural | SpringKind::Shear) && enabled(o.kind)
        };
        let pick = |keep: &dyn Fn(&Offset) -> bool| {
            let mut found = self.offsets.iter().filter(limited).filter(|o| keep(o));
            [found.next(), found.next()]
        };
        let along = pick(&|o| o.dy == 0);
        let down = pick(&|o| o.dy == 1 && o.dx == 0);
        let diagonals = pick(&|o| o.dy == 1 && o.dx != 0);
        let projection = Projection { limit, past };
        let w = self.width;
        let (x, dx) = (&mut self.x.0, &mut self.dx.0);
        let mut bits = 0;
        let [along, _] = along;
        if let Some(o) = along {
            bits |= projection.along_rows::<TRACK>((&mut *x, &mut *dx), inv_mass, o, w);
        }
        let [down, _] = down;
        let diagonals = match diagonals {
            [Some(d1), Some(d2)] => Some([d1, d2]),
            _ => None,
        };
        if x[0].len() < parallel::PARALLEL_FROM {
            // On one thread anyway: row after row.
            bits |= projection.down_rows::<TRACK>((x, dx), inv_mass, down, diagonals, w);
        } else {
            for parity in 0..2 {
                bits |= projection.across_rows::<TRACK>(
                    (&mut *x, &mut *dx),
                    inv_mass,
                    down,
                    diagonals,
                    w,
                    parity,
                );
            }
        }
        bits
    }
}

#[cfg(test)]
mod tests;
