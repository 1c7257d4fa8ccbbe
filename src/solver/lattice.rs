//! Grid cloths as stencils: every spring of a grid joins particle `a` to `a + step` for
//! one of a few offsets (structural, shear, bend, diagonal bend), so each offset's
//! springs are read and written as two shifted slices of the particle arrays, with no
//! index lists, no per-spring bounds checks and no scatter through indices.
//!
//! The [`Springs`] stay the truth (tearing, counts, faces, the general path for meshes
//! and garments); a stencil mirrors their rest lengths and weights (stiffness factor ×
//! alive) per offset, synced when they change.
//!
//! The strain limiter on a stencil is a coloured Gauss–Seidel: within one colour (an
//! offset's springs starting on even or on odd columns or rows) no two springs share a
//! particle, so its corrections do not depend on the order they are made in. The two
//! diagonals of one band of rows are corrected together (Jacobi, summed), so a mirror
//! image of the cloth is corrected as the mirror image (for an even width).

use std::iter::Zip;
use std::ops::Range;
use std::slice::{ChunksMut, Iter};

use bevy::math::Vec3;

use super::parallel::{self, PIECE};
use super::{Particles, SpringKind, Springs};

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
    /// Rest length of the spring from `a` (0 where there is none), indexed by `a`.
    rest: Vec<f32>,
    /// Stiffness factor × alive of the spring from `a` (0 where there is none or it
    /// tore), indexed by `a`.
    weight: Vec<f32>,
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
            .chunks_mut(PIECE)
            .zip(y.chunks_mut(PIECE))
            .zip(z.chunks_mut(PIECE))
            .zip(v.chunks(PIECE));
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
    let [x, y, z] = &x.0;
    let [vx, vy, vz] = &v.0;
    let springs = sx
        .iter_mut()
        .zip(sy.iter_mut())
        .zip(sz.iter_mut())
        .zip(o.rest[a.clone()].iter().zip(&o.weight[a.clone()]))
        .zip(pair(x, &a, &b))
        .zip(pair(y, &a, &b))
        .zip(pair(z, &a, &b))
        .zip(pair(vx, &a, &b))
        .zip(pair(vy, &a, &b))
        .zip(pair(vz, &a, &b));
    for (((((((((fx, fy), fz), (&rest, &weight)), x), y), z), vx), vy), vz) in springs {
        let (dx, dy, dz) = (x.1 - x.0, y.1 - y.0, z.1 - z.0);
        let len = (dx * dx + dy * dy + dz * dz).sqrt();
        // 1/|l| for a live spring, 0 for a torn or missing one (no branch).
        let live = f32::from(u8::from(weight != 0.0 && len > f32::EPSILON));
        let inv = live / len.max(f32::EPSILON);
        let along = (vx.1 - vx.0) * dx + (vy.1 - vy.0) * dy + (vz.1 - vz.0) * dz;
        let magnitude = k * weight * (len - rest) + damping * along * inv;
        let scale = magnitude * inv;
        (*fx, *fy, *fz) = (dx * scale, dy * scale, dz * scale);
    }
}

/// The elements `a` and `b` of one lane, side by side.
fn pair<'l>(
    lane: &'l [f32],
    a: &Range<usize>,
    b: &Range<usize>,
) -> Zip<Iter<'l, f32>, Iter<'l, f32>> {
    lane[a.clone()].iter().zip(&lane[b.clone()])
}

/// Adds to `sum` (one lane of the particles from `from` on) the forces `springs` of an
/// offset of `step` (one lane): `+` on each spring's start, `−` on its end.
fn add_ends(sum: &mut [f32], springs: &[f32], from: usize, step: usize, n: usize) {
    let (len, m) = (sum.len(), n - step);
    if from < m {
        let end = (from + len).min(m);
        for (f, s) in sum[..end - from].iter_mut().zip(&springs[from..end]) {
            *f += s;
        }
    }
    let (lo, hi) = (from.max(step), from + len);
    if lo < hi {
        for (f, s) in sum[lo - from..]
            .iter_mut()
            .zip(&springs[lo - step..hi - step])
        {
            *f -= s;
        }
    }
}

/// A grid cloth's springs as stencil offsets.
#[derive(Clone, Debug)]
pub(super) struct Stencil {
    width: usize,
    offsets: Vec<Offset>,
    /// For each spring: its offset and `a`, to follow tearing.
    slot: Vec<(u8, u32)>,
    /// Each offset's stiffness in this substep (0: its family is off).
    stiffness: Vec<f32>,
    /// Each offset's spring forces (as many as it has springs; room for `n`).
    springs: Vec<Lanes>,
    /// Positions, velocities and forces as lanes, for the substep's kernels.
    x: Lanes,
    v: Lanes,
    f: Lanes,
    /// One value per spring of an offset (its force, or a limiter correction), and a
    /// second for the limiter's other diagonal.
    scratch: [Lanes; 2],
}

impl Stencil {
    /// The stencil of `springs` on a `width`-wide grid of `n` particles, or `None` when a
    /// spring is not a grid offset (a seam, a welded mesh) or two share a slot.
    pub fn new(springs: &Springs, width: usize, n: usize) -> Option<Self> {
        let mut offsets: Vec<Offset> = Vec::new();
        let mut slot = Vec::with_capacity(springs.len());
        for s in 0..springs.len() {
            let kind = springs.kind(s);
            if kind == SpringKind::Seam {
                return None;
            }
            let (mut a, mut b) = (springs.a[s] as usize, springs.b[s] as usize);
            if b < a {
                std::mem::swap(&mut a, &mut b);
            }
            let dy = b / width - a / width;
            let dx = (b % width) as isize - (a % width) as isize;
            if dy > 2 || dx.abs() > 2 {
                return None;
            }
            let index = match offsets
                .iter()
                .position(|o| o.kind == kind && o.dx == dx && o.dy == dy)
            {
                Some(index) => index,
                None => {
                    let step = b - a;
                    offsets.push(Offset {
                        kind,
                        dx,
                        dy,
                        step,
                        rest: vec![0.0; n - step],
                        weight: vec![0.0; n - step],
                    });
                    offsets.len() - 1
                }
            };
            let offset = &mut offsets[index];
            if offset.rest[a] != 0.0 {
                return None;
            }
            offset.rest[a] = springs.rest_length[s];
            slot.push((index as u8, a as u32));
        }
        let mut stencil = Self {
            stiffness: vec![0.0; offsets.len()],
            springs: vec![Lanes::new(n); offsets.len()],
            width,
            offsets,
            slot,
            x: Lanes::new(n),
            v: Lanes::new(n),
            f: Lanes::new(n),
            scratch: [Lanes::new(n), Lanes::new(n)],
        };
        stencil.sync(springs);
        Some(stencil)
    }

    /// Takes the springs' rest lengths, stiffness factors and alive flags.
    pub fn sync(&mut self, springs: &Springs) {
        for (s, &(o, a)) in self.slot.iter().enumerate() {
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
        self.offsets[o as usize].weight[a as usize] = 0.0;
    }

    /// Adds every spring's Hooke force `k (|l| − l0) l/|l|` plus damping along it
    /// (the general path's law, `forces.rs`) to `p.force`; `k` per family. Two passes,
    /// each split over the compute pool: every spring's force, then every particle's sum
    /// of its springs (offset by offset, `+` from the springs it starts, `−` from those
    /// it ends).
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
        let (x, v) = (&self.x, &self.v);
        let pieces = self
            .offsets
            .iter()
            .zip(&mut self.springs)
            .zip(&self.stiffness)
            .filter(|(_, k)| **k != 0.0)
            .flat_map(|((o, springs), &k)| {
                let m = n - o.step;
                let [sx, sy, sz] = &mut springs.0;
                let chunks = sx[..m].chunks_mut(PIECE).zip(sy[..m].chunks_mut(PIECE));
                chunks
                    .zip(sz[..m].chunks_mut(PIECE))
                    .enumerate()
                    .map(move |(i, ((sx, sy), sz))| (o, k, i * PIECE, [sx, sy, sz]))
            });
        parallel::for_each(n, pieces, |(o, k, from, out)| {
            spring_piece(o, k, damping, from, x, v, out);
        });
        let (springs, offsets, stiffness) = (&self.springs, &self.offsets, &self.stiffness);
        let [fx, fy, fz] = &mut self.f.0;
        let pieces = fx
            .chunks_mut(PIECE)
            .zip(fy.chunks_mut(PIECE))
            .zip(fz.chunks_mut(PIECE))
            .zip(p.force.chunks_mut(PIECE))
            .enumerate();
        parallel::for_each(n, pieces, |(i, (((fx, fy), fz), force))| {
            let from = i * PIECE;
            for (lane, sum) in [&mut *fx, &mut *fy, &mut *fz].into_iter().enumerate() {
                sum.fill(0.0);
                for ((o, springs), k) in offsets.iter().zip(springs).zip(stiffness) {
                    if *k != 0.0 {
                        add_ends(sum, &springs.0[lane], from, o.step, n);
                    }
                }
            }
            for (((force, x), y), z) in force.iter_mut().zip(&*fx).zip(&*fy).zip(&*fz) {
                *force += Vec3::new(*x, *y, *z);
            }
        });
    }

    /// Provot's strain limit (the general path's law, `integrate.rs`) over the enabled
    /// structural and shear springs: `sweeps` coloured sweeps (see the module doc), or
    /// fewer once one finds every spring within `past·l0` (with `past` given). Works on
    /// lanes; each particle's velocity takes its whole correction over `h`.
    #[allow(clippy::too_many_arguments)]
    pub fn limit_strain(
        &mut self,
        p: &mut Particles,
        enabled: impl Fn(SpringKind) -> bool,
        limit: f32,
        sweeps: u32,
        past: Option<f32>,
        h: f32,
    ) {
        self.x.load(&p.position);
        for _ in 0..sweeps {
            let unconverged = match past {
                None => self.sweep::<false>(&p.inv_mass, &enabled, limit, f32::INFINITY),
                Some(past) => self.sweep::<true>(&p.inv_mass, &enabled, limit, past),
            };
            if past.is_some() && !unconverged {
                break;
            }
        }
        let [x, y, z] = &self.x.0;
        let pieces = p
            .position
            .chunks_mut(PIECE)
            .zip(p.velocity.chunks_mut(PIECE))
            .zip(x.chunks(PIECE).zip(y.chunks(PIECE)).zip(z.chunks(PIECE)));
        parallel::for_each(x.len(), pieces, |((position, velocity), ((x, y), z))| {
            let lanes = x.iter().zip(y).zip(z);
            for ((position, velocity), ((x, y), z)) in position.iter_mut().zip(velocity).zip(lanes)
            {
                let corrected = Vec3::new(*x, *y, *z);
                *velocity += (corrected - *position) / h;
                *position = corrected;
            }
        });
    }

    /// One coloured sweep; with `TRACK`, whether a spring was longer than `past·l0`.
    fn sweep<const TRACK: bool>(
        &mut self,
        inv_mass: &[f32],
        enabled: &impl Fn(SpringKind) -> bool,
        limit: f32,
        past: f32,
    ) -> bool {
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
        let x = &mut self.x.0;
        let mut unconverged = false;
        let [along, _] = along;
        if let Some(o) = along {
            unconverged |= projection.along_rows::<TRACK>(x, inv_mass, o, w, &mut self.scratch[0]);
        }
        let [down, _] = down;
        let diagonals = match diagonals {
            [Some(d1), Some(d2)] => Some([d1, d2]),
            _ => None,
        };
        for parity in 0..2 {
            let scratch = &mut self.scratch;
            unconverged |=
                projection.across_rows::<TRACK>(x, inv_mass, down, diagonals, w, parity, scratch);
        }
        unconverged
    }
}

/// Provot's projection of one spring: how far to move its ends.
#[derive(Clone, Copy)]
struct Projection {
    limit: f32,
    past: f32,
}

impl Projection {
    /// The correction `c` of the spring from `a` to `b` (`a += c·w_a`, `b −= c·w_b`) that
    /// brings it back to `(1 + limit)·rest`, zero when it is within it, torn or held at
    /// both ends; and whether it was longer than `past·rest`.
    #[inline(always)]
    fn correction(
        &self,
        a: [f32; 3],
        b: [f32; 3],
        wa: f32,
        wb: f32,
        rest: f32,
        weight: f32,
    ) -> ([f32; 3], bool) {
        let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let live = weight != 0.0 && wa + wb != 0.0;
        let excess = (len - (1.0 + self.limit) * rest).max(0.0);
        let factor = f32::from(u8::from(live)) * excess / (len * (wa + wb)).max(f32::MIN_POSITIVE);
        (
            [d[0] * factor, d[1] * factor, d[2] * factor],
            live && len > self.past * rest,
        )
    }

    /// The springs `(a, a + 1)` along the rows: those with `a` even, then those with `a`
    /// odd, each colour a set of disjoint pairs of particles. Rows do not share these
    /// springs, so groups of whole rows run in pieces over the compute pool (one task
    /// each for both colours).
    fn along_rows<const TRACK: bool>(
        &self,
        x: &mut [Vec<f32>; 3],
        inv_mass: &[f32],
        o: &Offset,
        width: usize,
        scratch: &mut Lanes,
    ) -> bool {
        let n = x[0].len();
        let group = width * (PIECE / width).max(1);
        let [x, y, z] = x;
        let [cx, cy, cz] = &mut scratch.0;
        let pieces = x
            .chunks_mut(group)
            .zip(y.chunks_mut(group))
            .zip(z.chunks_mut(group))
            .zip(
                cx.chunks_mut(group)
                    .zip(cy.chunks_mut(group))
                    .zip(cz.chunks_mut(group)),
            )
            .enumerate();
        parallel::any(n, pieces, |(i, (((x, y), z), ((cx, cy), cz)))| {
            let from = i * group;
            let mut x = [x, y, z];
            let mut c = [cx, cy, cz];
            let w = &inv_mass[from..from + x[0].len()];
            let springs = (
                &o.rest[from.min(o.rest.len())..],
                &o.weight[from.min(o.rest.len())..],
            );
            let mut unconverged = false;
            for parity in 0..2 {
                unconverged |= self.row_colour::<TRACK>(&mut x, w, springs, from, parity, &mut c);
            }
            unconverged
        })
    }

    /// One colour of [`Self::along_rows`] on a group of rows starting at particle `from`,
    /// in two vectorised passes over shifted slices: every spring's correction into `c`
    /// (zero for the springs of the other colour), then every particle's (`+` as a start,
    /// `−` as an end; one of the two is zero).
    fn row_colour<const TRACK: bool>(
        &self,
        x: &mut [&mut [f32]; 3],
        inv_mass: &[f32],
        (rest, weight): (&[f32], &[f32]),
        from: usize,
        parity: usize,
        c: &mut [&mut [f32]; 3],
    ) -> bool {
        let m = (x[0].len() - 1).min(rest.len()); // springs starting in the group
        let (a, b) = (0..m, 1..m + 1);
        let mut unconverged = false;
        {
            let [cx, cy, cz] = c;
            let springs = cx[..m]
                .iter_mut()
                .zip(cy[..m].iter_mut())
                .zip(cz[..m].iter_mut())
                .zip(rest.iter().zip(weight))
                .zip(
                    pair(x[0], &a, &b)
                        .zip(pair(x[1], &a, &b))
                        .zip(pair(x[2], &a, &b)),
                )
                .zip(pair(inv_mass, &a, &b))
                .enumerate();
            for (i, (((((cx, cy), cz), (&rest, &weight)), ((x, y), z)), (&wa, &wb))) in springs {
                let mine = f32::from(u8::from((from + i) % 2 == parity));
                let (c, long) = self.correction(
                    [*x.0, *y.0, *z.0],
                    [*x.1, *y.1, *z.1],
                    wa,
                    wb,
                    rest,
                    weight * mine,
                );
                unconverged |= TRACK && long;
                (*cx, *cy, *cz) = (c[0], c[1], c[2]);
            }
        }
        for (lane, c) in x.iter_mut().zip(c.iter()) {
            // As a start: x_a += c_a w_a; as an end: x_b −= c_{b−1} w_b.
            for ((x, w), c) in lane[..m].iter_mut().zip(inv_mass).zip(&c[..m]) {
                *x += c * w;
            }
            for ((x, w), c) in lane[1..m + 1].iter_mut().zip(&inv_mass[1..]).zip(&c[..m]) {
                *x -= c * w;
            }
        }
        unconverged
    }

    /// The springs from the rows of one parity to the next row: the vertical ones, then
    /// both diagonals together. Each band of two rows is disjoint from the others, so
    /// groups of bands run in pieces over the compute pool (one task each for both).
    #[allow(clippy::too_many_arguments)]
    fn across_rows<const TRACK: bool>(
        &self,
        x: &mut [Vec<f32>; 3],
        inv_mass: &[f32],
        down: Option<&Offset>,
        diagonals: Option<[&Offset; 2]>,
        width: usize,
        parity: usize,
        scratch: &mut [Lanes; 2],
    ) -> bool {
        let from = parity * width;
        let band = 2 * width;
        // Too few rows for a band from this parity: no springs to take.
        let fits = |o: &&Offset| o.rest.len() > from;
        let down = down.filter(fits);
        let diagonals = diagonals.filter(|d| d.iter().all(fits));
        let n = x[0].len();
        if (down.is_none() && diagonals.is_none()) || n < from + band {
            return false;
        }
        let end = from + (n - from) / band * band; // whole bands only
        let group = band * (PIECE / band).max(1);
        let [x, y, z] = x;
        let [s0, s1] = scratch;
        let [c0x, c0y, c0z] = &mut s0.0;
        let [c1x, c1y, c1z] = &mut s1.0;
        fn cut(lane: &mut [f32], range: Range<usize>, group: usize) -> ChunksMut<'_, f32> {
            lane[range].chunks_mut(group)
        }
        let chunks = |lane| cut(lane, from..end, group);
        let pieces = chunks(x)
            .zip(chunks(y))
            .zip(chunks(z))
            .zip(chunks(c0x).zip(chunks(c0y)).zip(chunks(c0z)))
            .zip(chunks(c1x).zip(chunks(c1y)).zip(chunks(c1z)))
            .enumerate();
        parallel::any(
            n,
            pieces,
            |(i, ((((x, y), z), ((c0x, c0y), c0z)), ((c1x, c1y), c1z)))| {
                let start = from + i * group;
                let mut rows = Bands {
                    x: [x, y, z],
                    inv_mass: &inv_mass[start..],
                    width,
                };
                let mut scratch = [[c0x, c0y, c0z], [c1x, c1y, c1z]];
                let mut unconverged = false;
                if let Some(o) = down {
                    unconverged |= self.bands::<TRACK>(&mut rows, &[o], start, &mut scratch);
                }
                if let Some(d) = diagonals {
                    unconverged |= self.bands::<TRACK>(&mut rows, &d, start, &mut scratch);
                }
                unconverged
            },
        )
    }

    /// [`Self::across_rows`] on one group of bands starting at particle `start`: every
    /// correction comes from the positions before any (the two diagonals share
    /// particles), then all are applied.
    fn bands<const TRACK: bool>(
        &self,
        rows: &mut Bands<'_>,
        offsets: &[&Offset],
        start: usize,
        scratch: &mut [[&mut [f32]; 3]; 2],
    ) -> bool {
        let Bands { x, inv_mass, width } = rows;
        let (inv_mass, width) = (*inv_mass, *width);
        let band = 2 * width;
        let mut unconverged = false;
        for (o, corrections) in offsets.iter().zip(scratch.iter_mut()) {
            let (top, bottom) = band_columns(o, width);
            let [cx, cy, cz] = corrections;
            let rest = &o.rest[start.min(o.rest.len())..];
            let weight = &o.weight[start.min(o.rest.len())..];
            let bands = x[0]
                .chunks_exact(band)
                .zip(x[1].chunks_exact(band))
                .zip(x[2].chunks_exact(band))
                .zip(inv_mass.chunks_exact(band))
                .zip(rest.chunks(band).zip(weight.chunks(band)))
                .zip(
                    cx.chunks_mut(band)
                        .zip(cy.chunks_mut(band))
                        .zip(cz.chunks_mut(band)),
                );
            for (((((xs, ys), zs), w), (rest, weight)), ((cx, cy), cz)) in bands {
                let (t, b) = (top.clone(), bottom.start + width..bottom.end + width);
                let springs = xs[t.clone()]
                    .iter()
                    .zip(&xs[b.clone()])
                    .zip(ys[t.clone()].iter().zip(&ys[b.clone()]))
                    .zip(zs[t.clone()].iter().zip(&zs[b.clone()]))
                    .zip(w[t.clone()].iter().zip(&w[b]))
                    .zip(rest[t.clone()].iter().zip(&weight[t.clone()]))
                    .zip(
                        cx[t.clone()]
                            .iter_mut()
                            .zip(&mut cy[t.clone()])
                            .zip(&mut cz[t]),
                    );
                for (((((x, y), z), (&wa, &wb)), (&rest, &weight)), ((cx, cy), cz)) in springs {
                    let (c, long) = self.correction(
                        [*x.0, *y.0, *z.0],
                        [*x.1, *y.1, *z.1],
                        wa,
                        wb,
                        rest,
                        weight,
                    );
                    unconverged |= TRACK && long;
                    (*cx, *cy, *cz) = (c[0], c[1], c[2]);
                }
            }
        }
        apply_bands(x, inv_mass, width, offsets, scratch);
        unconverged
    }
}

/// A group of whole bands of two rows: positions as lanes, inverse masses from the
/// group's first particle on.
struct Bands<'a> {
    x: [&'a mut [f32]; 3],
    inv_mass: &'a [f32],
    width: usize,
}

/// The columns of a band's springs of an offset: (top row, bottom row) for a column
/// offset of −1, 0 or 1.
fn band_columns(o: &Offset, width: usize) -> (Range<usize>, Range<usize>) {
    match o.dx {
        1 => (0..width - 1, 1..width),
        -1 => (1..width, 0..width - 1),
        _ => (0..width, 0..width),
    }
}

/// Applies the corrections of [`Projection::bands`] to each band's two rows.
fn apply_bands(
    x: &mut [&mut [f32]; 3],
    inv_mass: &[f32],
    width: usize,
    offsets: &[&Offset],
    scratch: &[[&mut [f32]; 3]; 2],
) {
    let band = 2 * width;
    for (o, corrections) in offsets.iter().zip(scratch.iter()) {
        let (top, bottom) = band_columns(o, width);
        for (lane, c) in x.iter_mut().zip(corrections) {
            let bands = lane
                .chunks_exact_mut(band)
                .zip(inv_mass.chunks_exact(band))
                .zip(c.chunks(band));
            for ((lane, w), c) in bands {
                let (t, b) = lane.split_at_mut(width);
                let (wt, wb) = w.split_at(width);
                let pairs = t[top.clone()]
                    .iter_mut()
                    .zip(&mut b[bottom.clone()])
                    .zip(wt[top.clone()].iter().zip(&wb[bottom.clone()]))
                    .zip(&c[top.clone()]);
                for (((a, b), (wa, wb)), c) in pairs {
                    *a += c * wa;
                    *b -= c * wb;
                }
            }
        }
    }
}
