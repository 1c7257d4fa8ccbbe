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

use crate::solver::parallel::{self, CHUNK};
use crate::solver::{Particles, SpringKind, Springs};

mod xpbd;

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
    /// Positions at the start of the substep, for XPBD's damping (`lattice/xpbd.rs`).
    previous: Lanes,
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
        };
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
    }

    /// Spring `s` tore.
    pub fn tear(&mut self, s: usize) {
        let (o, a) = self.slot[s];
        if o != APART {
            self.offsets[o as usize].weight[a as usize] = 0.0;
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

/// A sweep corrected a spring.
const MOVED: u8 = 1;
/// A sweep found a spring longer than `past·l0`: not yet within.
const UNCONVERGED: u8 = 2;

/// Provot's projection of one spring in place.
#[derive(Clone, Copy)]
struct Projection {
    limit: f32,
    past: f32,
}

/// A group of whole rows or bands: positions as lanes, inverse masses from the group's
/// first particle on.
struct Group<'a> {
    x: [&'a mut [f32]; 3],
    /// The corrections made in this call, summed (for the velocity: see
    /// [`Stencil::limit_strain`]).
    dx: [&'a mut [f32]; 3],
    inv_mass: &'a [f32],
}

/// One offset's rest lengths and weights, from a group's first particle on.
type RestAndWeight<'a> = (&'a [f32], &'a [f32]);

/// The springs from a row to the next: the vertical ones, and a cell's two diagonals
/// (right, then left).
struct Down<'a> {
    down: Option<RestAndWeight<'a>>,
    diagonals: Option<(RestAndWeight<'a>, RestAndWeight<'a>)>,
}

impl<'a> Down<'a> {
    /// The offsets' springs from particle `start` on.
    fn from(down: Option<&'a Offset>, diagonals: Option<[&'a Offset; 2]>, start: usize) -> Self {
        let (right, left) = right_and_left(diagonals);
        Down {
            down: down.map(|o| o.springs_from(start)),
            diagonals: right
                .zip(left)
                .map(|(r, l)| (r.springs_from(start), l.springs_from(start))),
        }
    }
}

/// Lanes `range` of positions and of summed corrections, in chunks of `size`.
fn chunks6<'a>(
    x: &'a mut [Vec<f32>; 3],
    dx: &'a mut [Vec<f32>; 3],
    range: Range<usize>,
    size: usize,
) -> impl Iterator<Item = ([&'a mut [f32]; 3], [&'a mut [f32]; 3])> {
    let [x0, x1, x2] = x;
    let [d0, d1, d2] = dx;
    let cut = |lane: &'a mut Vec<f32>| lane[range.clone()].chunks_mut(size);
    cut(x0)
        .zip(cut(x1))
        .zip(cut(x2))
        .zip(cut(d0).zip(cut(d1)).zip(cut(d2)))
        .map(|(((a, b), c), ((d, e), f))| ([a, b, c], [d, e, f]))
}

impl Projection {
    /// Whether a spring of `rest` at squared length `len2` is past its limit
    /// `(1 + limit)·rest`, a NaN length counted past: the one test of [`Self::project`]
    /// and [`Self::any_over`], without a branch so that the second vectorises.
    #[inline(always)]
    fn past_limit(&self, len2: f32, rest: f32) -> bool {
        let max = (1.0 + self.limit) * rest;
        (len2 > max * max) | len2.is_nan()
    }

    /// Shortens the spring from `a` to `b` (indices in `g`) to `(1 + limit)·rest` when it
    /// is longer, each end moved by its share of inverse mass (Sladović 2014 eq. 2); nothing
    /// when it is within, torn (`weight` 0) or held at both ends. Most springs are within,
    /// so the test comes first, on squared lengths. [`MOVED`] when it was corrected, and
    /// with `TRACK` [`UNCONVERGED`] when it was longer than `past·rest`.
    #[inline(always)]
    fn project<const TRACK: bool>(
        &self,
        g: &mut Group<'_>,
        a: usize,
        b: usize,
        rest: f32,
        weight: f32,
    ) -> u8 {
        let (wa, wb) = (g.inv_mass[a], g.inv_mass[b]);
        let [x, y, z] = &mut g.x;
        let d = [x[b] - x[a], y[b] - y[a], z[b] - z[a]];
        let len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if weight == 0.0 || wa + wb == 0.0 || !self.past_limit(len2, rest) {
            return 0;
        }
        let max = (1.0 + self.limit) * rest;
        let len = len2.sqrt();
        let factor = (len - max) / (len * (wa + wb));
        let [dx, dy, dz] = &mut g.dx;
        let lanes = [&mut **x, &mut **y, &mut **z].into_iter();
        for ((lane, sum), d) in lanes.zip([&mut **dx, &mut **dy, &mut **dz]).zip(d) {
            let (ca, cb) = (d * factor * wa, d * factor * wb);
            lane[a] += ca;
            lane[b] -= cb;
            sum[a] += ca;
            sum[b] -= cb;
        }
        MOVED
            | if TRACK && len > self.past * rest {
                UNCONVERGED
            } else {
                0
            }
    }

    /// The springs `(a, a + 1)` along the rows: those with `a` even, then those with `a`
    /// odd, each colour a set of disjoint pairs of particles. Rows do not share these
    /// springs, so groups of whole rows run in pieces over the compute pool.
    fn along_rows<const TRACK: bool>(
        &self,
        (x, dx): (&mut [Vec<f32>; 3], &mut [Vec<f32>; 3]),
        inv_mass: &[f32],
        o: &Offset,
        width: usize,
    ) -> u8 {
        let n = x[0].len();
        let group = width * (CHUNK / width).max(1);
        let pieces = chunks6(x, dx, 0..n, group).enumerate();
        parallel::or_bits(n, pieces, |(i, (x, dx))| {
            let from = i * group;
            let len = x[0].len();
            let mut g = Group {
                x,
                dx,
                inv_mass: &inv_mass[from..],
            };
            let (rest, weight) = (
                &o.rest[from.min(o.rest.len())..],
                &o.weight[from.min(o.rest.len())..],
            );
            let springs = rest.len().min(len - 1); // those starting in the group
            let mut bits = 0;
            // Rows share none of these springs: row by row, each row's two colours, and
            // a row none of whose springs is over its limit left as it is.
            for top in (0..springs).step_by(width) {
                let end = (top + width).min(springs);
                if !self.any_over(&g, top..end, 1, (rest, weight)) {
                    continue;
                }
                for parity in 0..2 {
                    for a in (top + (top + parity + from) % 2..end).step_by(2) {
                        bits |= self.project::<TRACK>(&mut g, a, a + 1, rest[a], weight[a]);
                    }
                }
            }
            bits
        })
    }

    /// Whether any spring from `a` to `a + step`, for `a` in `from`, is one that
    /// [`Self::project`] would correct (`rest` and `weight` indexed by `a`): its test
    /// ([`Self::past_limit`]) over lanes, with no branch a spring, so that the
    /// springs of a calm stretch of cloth are told within four to a vector instruction.
    /// Springs of one colour share no particle, so a colour none of whose springs is
    /// over is left exactly as its projections would leave it.
    #[inline(always)]
    fn any_over(
        &self,
        g: &Group<'_>,
        from: Range<usize>,
        step: usize,
        (rest, weight): RestAndWeight<'_>,
    ) -> bool {
        let [x, y, z] = &g.x;
        let (a, b) = (from.clone(), from.start + step..from.end + step);
        let ends = (x[a.clone()].iter().zip(&x[b.clone()]))
            .zip(y[a.clone()].iter().zip(&y[b.clone()]))
            .zip(z[a.clone()].iter().zip(&z[b]));
        let springs = rest[a.clone()].iter().zip(&weight[a]);
        let over =
            ends.zip(springs)
                .fold(0u32, |over, ((((xa, xb), (ya, yb)), (za, zb)), (r, w))| {
                    let d = [xb - xa, yb - ya, zb - za];
                    let len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                    over | ((*w != 0.0) as u32 & self.past_limit(len2, *r) as u32)
                });
        over != 0
    }

    /// The springs from each row to the next, row after row from the first (see
    /// [`Self::row_to_next`]), on the calling thread: a correction travels down the cloth
    /// within one sweep, as in the general path's sweep in spring order, where the bands
    /// of [`Self::across_rows`] carry it two rows a sweep. The crowd's capes, pinned at
    /// the shoulders, stretched less (`cloth crowd`: largest strain in a frame 11.8%
    /// median and 14.7% at most, against 12.9% and 17.2%).
    fn down_rows<const TRACK: bool>(
        &self,
        (x, dx): (&mut [Vec<f32>; 3], &mut [Vec<f32>; 3]),
        inv_mass: &[f32],
        down: Option<&Offset>,
        diagonals: Option<[&Offset; 2]>,
        width: usize,
    ) -> u8 {
        let ([x0, x1, x2], [d0, d1, d2]) = (x, dx);
        let rows = x0.len() / width;
        let mut g = Group {
            x: [x0, x1, x2].map(|lane| lane.as_mut_slice()),
            dx: [d0, d1, d2].map(|lane| lane.as_mut_slice()),
            inv_mass,
        };
        let springs = Down::from(down, diagonals, 0);
        let mut bits = 0;
        for row in 0..rows.saturating_sub(1) {
            bits |= self.row_to_next::<TRACK>(&mut g, row * width, width, &springs);
        }
        bits
    }

    /// The springs from the row starting at `top` (an index in `g`) to the next: the
    /// vertical ones, then the diagonal pairs of even cells, then of odd cells (a cell's
    /// two diagonals share no particle, nor do cells two apart). Each colour is a set of
    /// disjoint springs, and a mirror image of the cloth (even width) maps each colour
    /// onto itself.
    #[inline(always)]
    fn row_to_next<const TRACK: bool>(
        &self,
        g: &mut Group<'_>,
        top: usize,
        width: usize,
        springs: &Down<'_>,
    ) -> u8 {
        let mut bits = 0;
        if let Some((rest, weight)) = springs.down
            && self.any_over(g, top..top + width, width, (rest, weight))
        {
            for a in top..top + width {
                bits |= self.project::<TRACK>(g, a, a + width, rest[a], weight[a]);
            }
        }
        let Some(((r_rest, r_weight), (l_rest, l_weight))) = springs.diagonals else {
            return bits;
        };
        // Both colours of diagonals tested at once: none over, neither moves.
        let cells = top..top + width - 1;
        let right = self.any_over(g, cells.clone(), width + 1, (r_rest, r_weight));
        if !right
            && !self.any_over(
                g,
                cells.start + 1..cells.end + 1,
                width - 1,
                (l_rest, l_weight),
            )
        {
            return bits;
        }
        for cells in 0..2 {
            for c in (top + cells..top + width - 1).step_by(2) {
                let (a, b) = (c, c + width + 1);
                bits |= self.project::<TRACK>(g, a, b, r_rest[a], r_weight[a]);
                let (a, b) = (c + 1, c + width);
                bits |= self.project::<TRACK>(g, a, b, l_rest[a], l_weight[a]);
            }
        }
        bits
    }

    /// The springs from the rows of one parity to the next row, band by band (two rows):
    /// the vertical ones, then the diagonal pairs of even cells, then of odd cells (a
    /// cell's two diagonals share no particle, nor do cells two apart). Every colour is a
    /// set of disjoint springs, and a mirror image of the cloth (even width) maps each
    /// colour onto itself, so the result depends neither on order nor on side. Bands do
    /// not share particles, so groups of bands run in pieces over the compute pool.
    #[allow(clippy::too_many_arguments)]
    fn across_rows<const TRACK: bool>(
        &self,
        (x, dx): (&mut [Vec<f32>; 3], &mut [Vec<f32>; 3]),
        inv_mass: &[f32],
        down: Option<&Offset>,
        diagonals: Option<[&Offset; 2]>,
        width: usize,
        parity: usize,
    ) -> u8 {
        let from = parity * width;
        let band = 2 * width;
        let n = x[0].len();
        if n < from + band {
            return 0; // too few rows for a band from this parity
        }
        let end = from + (n - from) / band * band; // whole bands only
        let group = band * (CHUNK / band).max(1);
        let pieces = chunks6(x, dx, from..end, group).enumerate();
        parallel::or_bits(n, pieces, |(i, (x, dx))| {
            let start = from + i * group;
            let bands = x[0].len() / band;
            let mut g = Group {
                x,
                dx,
                inv_mass: &inv_mass[start..],
            };
            let springs = Down::from(down, diagonals, start);
            let mut bits = 0;
            for k in 0..bands {
                bits |= self.row_to_next::<TRACK>(&mut g, k * band, width, &springs);
            }
            bits
        })
    }
}

#[cfg(test)]
mod tests {
    use bevy::math::Vec3;

    use super::*;
    use crate::solver::forces::spring_forces;
    use crate::solver::unit_hash;

    /// Particles at `rest`, each moved up to 2 cm along each axis and given a velocity
    /// (both of a hash of its index).
    fn jittered(rest: &[Vec3]) -> Particles {
        let mut p = Particles::with_len(rest.len());
        for (i, &x) in rest.iter().enumerate() {
            let jitter = |axis| unit_hash(i, axis) * 0.02;
            p.position[i] = x + Vec3::new(jitter(0), jitter(1), jitter(2));
            p.velocity[i] = Vec3::new(unit_hash(i, 3), unit_hash(i, 4), unit_hash(i, 5));
        }
        p
    }

    /// `p`'s forces are `general`'s, particle by particle, to rounding (summed in another
    /// order), and some are more than 1 N.
    fn assert_same_forces(p: &Particles, general: &Particles) {
        for (i, (f, g)) in p.force.iter().zip(&general.force).enumerate() {
            assert!(
                f.distance(*g) < 1e-4 * (1.0 + g.length()),
                "particle {i}: {f} against {g}"
            );
        }
        assert!(general.force.iter().any(|f| f.length() > 1.0));
    }

    /// The stencil's spring forces on a crumpled, moving 7×5 grid against the general
    /// path's, spring by spring (`forces.rs`): the same law, summed in another order.
    #[test]
    fn the_stencils_spring_forces_are_the_general_paths() {
        let layout = crate::layout::shape::ClothShape::Grid {
            width: 7,
            height: 5,
            spacing: 0.1,
        }
        .layout()
        .unwrap();
        let springs = Springs::from_pairs(layout.springs.clone(), &layout.positions);
        let n = layout.positions.len();
        let mut stencil = Stencil::new(&springs, 7, n).unwrap();
        stencil.sync(&springs);
        let mut p = jittered(&layout.positions);
        let mut general = p.clone();
        let k = [200.0, 50.0, 5.0, 2.0, 0.0];
        stencil.spring_forces(&mut p, |kind| k[kind as usize], 0.3);
        for kind in SpringKind::ALL {
            let range = springs.ranges[kind as usize].clone();
            spring_forces(&springs, &mut general, range, k[kind as usize], 0.3, |_| {
                1.0
            });
        }
        assert_same_forces(&p, &general);
    }

    /// A strip hanging from its top row, every row below pulled 0.2 m down at once (only
    /// the top row's springs stretched, to three times their length): on one thread the
    /// limiter goes down the rows in order, so within one sweep the correction travels
    /// row after row, past the two rows the bands of [`Projection::across_rows`] reach.
    #[test]
    fn one_sweep_down_the_rows_carries_a_correction_down_the_strip() {
        let (width, height) = (4, 12);
        let layout = crate::layout::shape::ClothShape::Grid {
            width,
            height,
            spacing: 0.1,
        }
        .layout()
        .unwrap();
        let springs = Springs::from_pairs(layout.springs.clone(), &layout.positions);
        let n = layout.positions.len();
        let mut stencil = Stencil::new(&springs, width as usize, n).unwrap();
        let mut p = Particles::with_len(n);
        let width = width as usize;
        for (i, &x) in layout.positions.iter().enumerate() {
            let top = i < width;
            p.position[i] = if top { x } else { x - Vec3::Y * 0.2 };
            p.inv_mass[i] = if top { 0.0 } else { 1.0 };
        }
        let before = p.position.clone();
        stencil.limit_strain(&mut p, |_| true, 0.1, 1, None, 0.01);
        let rise = |row: usize| p.position[row * width].y - before[row * width].y;
        // Each row after the first takes a share of the correction on its way down.
        for row in 1..=4 {
            assert!(rise(row) > 1e-3, "row {row} rose {} m", rise(row));
        }
    }

    /// A cone of `around × down` particles (a skirt: a grid wrapped round, its rows
    /// closed where the last column meets the first) as a mesh, its vertices numbered
    /// `order(i)` for particle `i` of the rows.
    fn cone(around: u32, down: u32, order: impl Fn(u32) -> u32) -> crate::solver::Layout {
        let n = around * down;
        let mut points = vec![Vec3::ZERO; n as usize];
        for v in 0..n {
            let (i, j) = (v % around, v / around);
            let a = std::f32::consts::TAU * i as f32 / around as f32;
            let r = 0.2 + 0.03 * j as f32;
            points[order(v) as usize] = Vec3::new(r * a.sin(), -0.05 * j as f32, r * a.cos());
        }
        let mut triangles = Vec::new();
        for j in 0..down - 1 {
            for i in 0..around {
                let (a, b) = (j * around + i, j * around + (i + 1) % around);
                triangles.push([a, a + around, b].map(&order));
                triangles.push([b, a + around, b + around].map(&order));
            }
        }
        crate::solver::Layout::from_mesh(&points, &triangles).unwrap()
    }

    /// A cone's springs take a stencil over its rows, all but those across its seam
    /// (whose ends are more than two columns apart), which are kept apart; the stencil's
    /// forces and the general path's over those kept apart are the general path's over
    /// every spring, a torn one too. The same cone with its vertices shuffled has no
    /// rows: it stays on the general path.
    #[test]
    fn a_mesh_in_rows_takes_a_stencil_and_keeps_its_seam_apart() {
        let (around, down) = (12u32, 5u32);
        let layout = cone(around, down, |v| v);
        let springs = Springs::from_pairs(layout.springs.clone(), &layout.positions);
        let n = layout.positions.len();
        // A cloth built of it takes the rows.
        assert!(
            crate::solver::structure::Structure::new(layout.clone())
                .rows
                .is_some()
        );
        let mut rows = Rows::find(&springs, n).expect("rows");
        assert_eq!(rows.stencil.width, around as usize);
        let across = |s: usize| {
            let column = |v: u32| v % around;
            column(springs.a[s]).abs_diff(column(springs.b[s])) > 2
        };
        let apart: Vec<usize> = (0..springs.len()).filter(|&s| across(s)).collect();
        assert_eq!(
            rows.apart.iter().map(|&s| s as usize).collect::<Vec<_>>(),
            apart
        );
        assert!(!apart.is_empty() && apart.len() * APART_SHARE <= springs.len());

        let mut springs = springs;
        let torn = 7;
        springs.alive[torn] = false;
        rows.stencil.tear(torn);
        let mut p = jittered(&layout.positions);
        let mut general = p.clone();
        let k = [200.0, 50.0, 5.0, 2.0, 0.0];
        rows.stencil
            .spring_forces(&mut p, |kind| k[kind as usize], 0.3);
        for kind in SpringKind::ALL {
            let k = k[kind as usize];
            let range = springs.ranges[kind as usize].clone();
            let kept = rows.apart.iter().map(|&s| s as usize);
            let kept = kept.filter(|s| range.contains(s));
            spring_forces(&springs, &mut p, kept, k, 0.3, |_| 1.0);
            spring_forces(&springs, &mut general, range, k, 0.3, |_| 1.0);
        }
        assert_same_forces(&p, &general);

        let mut order: Vec<u32> = (0..around * down).collect();
        order.sort_by(|&u, &v| unit_hash(u as usize, 9).total_cmp(&unit_hash(v as usize, 9)));
        let shuffled = cone(around, down, |v| order[v as usize]);
        let springs = Springs::from_pairs(shuffled.springs, &shuffled.positions);
        assert!(Rows::find(&springs, n).is_none());
    }
}
