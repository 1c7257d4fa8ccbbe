//! XPBD on a grid's stencil: the constraints of `xpbd.rs` (the same Δλ,
//! [`xpbd::correction`]) projected offset by offset over position lanes, with no index
//! lists, no per-constraint arrays but the rest lengths and alive weights the stencil
//! keeps, and no summed corrections: the lanes are loaded from the predicted positions,
//! projected, and each particle's velocity takes `(x − x_pred)/h` as they are stored back.
//!
//! Each offset `(dx, dy)` is two colours, each a set of springs that share no particle:
//! - across rows (`dy` = 1 or 2): the springs from the rows `r` with `r mod 2dy < dy`,
//!   then from the others. A colour is a run of bands of `2dy` rows whose first `dy`
//!   rows reach the next `dy`; bands share no particle, so they run in pieces over the
//!   compute pool, and within a band a spring joins row `t` to row `t + dy` at a fixed
//!   column shift: two slices side by side, the loop the compiler vectorises;
//! - along rows (`dy` = 0): the springs from the columns `c` with `c mod 2dx < dx`, then
//!   from the others, row by row (rows in pieces over the pool).
//!
//! Families go in `xpbd.rs`'s projection order (structural last).

use bevy::math::Vec3;

use super::{CHUNK, Offset, Stencil, parallel};
use crate::solver::parallel::XPBD_PARALLEL_FROM;

use crate::solver::Particles;
use crate::solver::xpbd::{self, Family};

/// What one colour's kernel reads besides the positions.
#[derive(Clone, Copy)]
struct Shared<'a> {
    offset: &'a Offset,
    family: Family,
    inv_mass: &'a [f32],
    /// Positions at the start of the substep, as lanes (read only when damped).
    previous: &'a [Vec<f32>; 3],
    width: usize,
}

impl Stencil {
    /// Projects every acting family's constraints once (see the module doc) and gives
    /// each particle its corrections as velocity over `h`; `families` by [`SpringKind`].
    /// The same bits on any number of threads: a colour's springs share no particle.
    pub fn project_xpbd(&mut self, p: &mut Particles, families: &[Family; 5], h: f32) {
        self.begin_xpbd(p, families);
        self.sweep_xpbd(&p.inv_mass, families);
        self.end_xpbd(p, h);
    }

    /// Loads the lanes for a substep's projections: the positions, and the substep's
    /// start when a family of `families` is damped.
    pub fn begin_xpbd(&mut self, p: &Particles, families: &[Family; 5]) {
        self.x.load(&p.position);
        self.damped = families.iter().any(|f| f.on && f.damping > 0.0);
        if self.damped {
            self.previous.load(&p.previous);
        }
    }

    /// One sweep of the acting families of `families` on the lanes (see the module doc).
    pub fn sweep_xpbd(&mut self, inv_mass: &[f32], families: &[Family; 5]) {
        let Stencil {
            offsets,
            x,
            previous,
            width,
            ..
        } = self;
        for kind in xpbd::PROJECTION_ORDER {
            let family = families[kind as usize];
            if !family.on {
                continue;
            }
            for offset in offsets.iter().filter(|o| o.kind == kind) {
                let shared = Shared {
                    offset,
                    family,
                    inv_mass,
                    previous: &previous.0,
                    width: *width,
                };
                for class in 0..2 {
                    match (family.damping > 0.0, family.max_stretch.is_finite()) {
                        (false, false) => colour::<false, false>(&mut x.0, shared, class),
                        (false, true) => colour::<false, true>(&mut x.0, shared, class),
                        (true, false) => colour::<true, false>(&mut x.0, shared, class),
                        (true, true) => colour::<true, true>(&mut x.0, shared, class),
                    }
                }
            }
        }
    }

    /// Stores the projected lanes as positions (see [`store`]).
    pub fn end_xpbd(&mut self, p: &mut Particles, h: f32) {
        let (x, r) = (&self.x.0, &mut self.residue.0);
        if std::mem::take(&mut self.lines_moved) {
            store::<true>(x, r, p, h);
        } else {
            store::<false>(x, r, p, h);
        }
    }
}

/// One colour of `shared.offset`: `class` 0 or 1 (see the module doc).
fn colour<const DAMPED: bool, const LIMITED: bool>(
    x: &mut [Vec<f32>; 3],
    shared: Shared<'_>,
    class: usize,
) {
    let (w, n) = (shared.width, x[0].len());
    let rows = n / w;
    let dy = shared.offset.dy;
    if dy == 0 {
        let group = w * (CHUNK / w).max(1);
        let pieces = chunks3(x, 0..n, group).enumerate();
        parallel::for_each_from(XPBD_PARALLEL_FROM, n, pieces, |(k, lanes)| {
            along::<DAMPED, LIMITED>(lanes, k * group / w, shared, class);
        });
        return;
    }
    let (first, band) = (class * dy, 2 * dy);
    if rows <= first + dy {
        return; // no row of this class has a row `dy` below it
    }
    let bands = band * (CHUNK / (band * w)).max(1);
    let pieces = chunks3(x, first * w..n, bands * w).enumerate();
    parallel::for_each_from(XPBD_PARALLEL_FROM, n, pieces, |(k, lanes)| {
        let top = first + k * bands;
        let [x0, x1, x2] = lanes;
        let bands = x0
            .chunks_mut(band * w)
            .zip(x1.chunks_mut(band * w))
            .zip(x2.chunks_mut(band * w));
        for (b, ((x0, x1), x2)) in bands.enumerate() {
            across::<DAMPED, LIMITED>([x0, x1, x2], top + b * band, shared);
        }
    });
}

/// The springs of one band (rows `top..top + 2dy`, fewer at the bottom): from each of its
/// first `dy` rows to the row `dy` below.
fn across<const DAMPED: bool, const LIMITED: bool>(
    band: [&mut [f32]; 3],
    top: usize,
    shared: Shared<'_>,
) {
    let (w, o) = (shared.width, shared.offset);
    let split = (o.dy * w).min(band[0].len());
    let [(a0, b0), (a1, b1), (a2, b2)] = band.map(|lane| lane.split_at_mut(split));
    // The columns a spring starts and ends at, and how many there are per row.
    let shift = o.dx.unsigned_abs();
    let (from_a, from_b) = if o.dx >= 0 { (0, shift) } else { (shift, 0) };
    let m = w - shift;
    for t in 0..b0.len() / w {
        let (ra, rb) = (t * w + from_a, t * w + from_b);
        let a = [
            &mut a0[ra..ra + m],
            &mut a1[ra..ra + m],
            &mut a2[ra..ra + m],
        ];
        let b = [
            &mut b0[rb..rb + m],
            &mut b1[rb..rb + m],
            &mut b2[rb..rb + m],
        ];
        let first = (top + t) * w + from_a;
        rows::<DAMPED, LIMITED>(a, b, first, shared);
    }
}

/// Springs `(first + k, first + k + step)` for `k < m`, their ends' positions in `a` and
/// `b` (each `m` long): the vectorised loop.
#[inline(always)]
fn rows<'a, const DAMPED: bool, const LIMITED: bool>(
    a: [&mut [f32]; 3],
    b: [&mut [f32]; 3],
    first: usize,
    shared: Shared<'a>,
) {
    let (o, f) = (shared.offset, shared.family);
    // Every slice cut to `m`, so the loop has no bounds checks and vectorises.
    let m = a[0].len();
    let [ax, ay, az] = a.map(|lane| &mut lane[..m]);
    let [bx, by, bz] = b.map(|lane| &mut lane[..m]);
    let rest = &o.rest[first..first + m];
    let weight = &o.weight[first..first + m];
    let wa = &shared.inv_mass[first..first + m];
    let wb = &shared.inv_mass[first + o.step..first + o.step + m];
    let [px, py, pz] = shared.previous;
    fn lane<const DAMPED: bool>(l: &[f32], at: usize, m: usize) -> &[f32] {
        if DAMPED { &l[at..at + m] } else { &l[..0] }
    }
    let lane = |l: &'a Vec<f32>, at: usize| lane::<DAMPED>(l, at, m);
    let (pax, pay, paz) = (lane(px, first), lane(py, first), lane(pz, first));
    let at = first + o.step;
    let (pbx, pby, pbz) = (lane(px, at), lane(py, at), lane(pz, at));
    for k in 0..m {
        let approach_from = if DAMPED {
            [[pax[k], pay[k], paz[k]], [pbx[k], pby[k], pbz[k]]]
        } else {
            [[0.0; 3]; 2]
        };
        let (ma, mb) = pair::<DAMPED, LIMITED>(
            ([ax[k], ay[k], az[k]], [bx[k], by[k], bz[k]]),
            approach_from,
            (wa[k], wb[k]),
            (rest[k], weight[k]),
            f,
        );
        (ax[k], ay[k], az[k]) = (ax[k] + ma[0], ay[k] + ma[1], az[k] + ma[2]);
        (bx[k], by[k], bz[k]) = (bx[k] + mb[0], by[k] + mb[1], bz[k] + mb[2]);
    }
}

/// The springs along the rows of a group of whole rows from row `row` on: in each row,
/// those from the columns of `class` (see the module doc), in whole chunks of `2 dx`
/// columns (the springs from the first `dx` of a chunk to the last `dx`), then any
/// spring in the row's last few columns one by one.
fn along<const DAMPED: bool, const LIMITED: bool>(
    lanes: [&mut [f32]; 3],
    row: usize,
    shared: Shared<'_>,
    class: usize,
) {
    let (w, dx) = (shared.width, shared.offset.step);
    let [x0, x1, x2] = lanes;
    let rows = x0.chunks_mut(w).zip(x1.chunks_mut(w)).zip(x2.chunks_mut(w));
    for (r, ((x0, x1), x2)) in rows.enumerate() {
        let from = class * dx;
        if from >= w {
            continue;
        }
        let first = (row + r) * w + from;
        let lanes = [&mut x0[from..], &mut x1[from..], &mut x2[from..]];
        let done = match dx {
            1 => chunked::<2, DAMPED, LIMITED>(lanes, first, shared),
            2 => chunked::<4, DAMPED, LIMITED>(lanes, first, shared),
            _ => 0,
        };
        // The columns left after the whole chunks: springs one by one.
        for a in (from + done..w.saturating_sub(dx)).filter(|c| (c / dx) % 2 == class) {
            let (b, ga) = (a + dx, (row + r) * w + a);
            let gb = ga + dx;
            let [p0, p1, p2] = shared.previous;
            let approach_from = if DAMPED {
                [[p0[ga], p1[ga], p2[ga]], [p0[gb], p1[gb], p2[gb]]]
            } else {
                [[0.0; 3]; 2]
            };
            let (ma, mb) = pair::<DAMPED, LIMITED>(
                ([x0[a], x1[a], x2[a]], [x0[b], x1[b], x2[b]]),
                approach_from,
                (shared.inv_mass[ga], shared.inv_mass[gb]),
                (shared.offset.rest[ga], shared.offset.weight[ga]),
                shared.family,
            );
            for (lane, i) in [&mut *x0, &mut *x1, &mut *x2].into_iter().zip(0..3) {
                lane[a] += ma[i];
                lane[b] += mb[i];
            }
        }
    }
}

/// The springs `(k N + j, k N + j + N/2)` for `j < N/2` over the whole chunks of `N` of
/// `lanes` (particles from `first` on); returns how many elements the chunks covered.
#[inline(always)]
fn chunked<const N: usize, const DAMPED: bool, const LIMITED: bool>(
    lanes: [&mut [f32]; 3],
    first: usize,
    shared: Shared<'_>,
) -> usize {
    let (o, f, dx) = (shared.offset, shared.family, N / 2);
    let count = lanes.iter().map(|lane| lane.len() / N).min().unwrap_or(0);
    // Every slice cut to `count` chunks, so the loop has no bounds checks.
    let [x0, x1, x2] = lanes.map(|lane| &mut lane.as_chunks_mut::<N>().0[..count]);
    let span = first..first + count * N;
    let (rest, _) = o.rest[span.clone()].as_chunks::<N>();
    let (weight, _) = o.weight[span.clone()].as_chunks::<N>();
    let (inv_mass, _) = shared.inv_mass[span.clone()].as_chunks::<N>();
    let (rest, weight, inv_mass) = (&rest[..count], &weight[..count], &inv_mass[..count]);
    let [p0, p1, p2] = shared.previous.each_ref().map(|lane| {
        if DAMPED {
            lane[span.clone()].as_chunks::<N>().0
        } else {
            &[]
        }
    });
    for k in 0..count {
        for j in 0..dx {
            let (a, b) = (j, j + dx);
            let xa = [x0[k][a], x1[k][a], x2[k][a]];
            let xb = [x0[k][b], x1[k][b], x2[k][b]];
            let approach_from = if DAMPED {
                [
                    [p0[k][a], p1[k][a], p2[k][a]],
                    [p0[k][b], p1[k][b], p2[k][b]],
                ]
            } else {
                [[0.0; 3]; 2]
            };
            let (wa, wb) = (inv_mass[k][a], inv_mass[k][b]);
            let (ma, mb) = pair::<DAMPED, LIMITED>(
                (xa, xb),
                approach_from,
                (wa, wb),
                (rest[k][a], weight[k][a]),
                f,
            );
            (x0[k][a], x1[k][a], x2[k][a]) = (xa[0] + ma[0], xa[1] + ma[1], xa[2] + ma[2]);
            (x0[k][b], x1[k][b], x2[k][b]) = (xb[0] + mb[0], xb[1] + mb[1], xb[2] + mb[2]);
        }
    }
    count * N
}

/// One spring's projection: its ends `x_a`, `x_b` and where they were at the start of
/// the substep (read only when `DAMPED`), their inverse masses, its rest length and
/// weight (0: torn or none): the moves of its ends.
#[inline(always)]
fn pair<const DAMPED: bool, const LIMITED: bool>(
    (xa, xb): ([f32; 3], [f32; 3]),
    [pa, pb]: [[f32; 3]; 2],
    (wa, wb): (f32, f32),
    (rest, weight): (f32, f32),
    f: Family,
) -> ([f32; 3], [f32; 3]) {
    let d = [xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]];
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let w = if weight > 0.0 { wa + wb } else { 0.0 };
    let approach = if DAMPED {
        let relative = [0, 1, 2].map(|i| (xb[i] - pb[i]) - (xa[i] - pa[i]));
        d[0] * relative[0] + d[1] * relative[1] + d[2] * relative[2]
    } else {
        0.0
    };
    let s = xpbd::correction::<DAMPED, LIMITED>(len, rest, w, approach, f);
    let (sa, sb) = (s * wa, s * wb);
    (d.map(|d| -d * sa), d.map(|d| d * sb))
}

/// Three lanes' elements `range` in chunks of `size`, side by side.
fn chunks3(
    x: &mut [Vec<f32>; 3],
    range: std::ops::Range<usize>,
    size: usize,
) -> impl Iterator<Item = [&mut [f32]; 3]> {
    let [x0, x1, x2] = x;
    x0[range.clone()]
        .chunks_mut(size)
        .zip(x1[range.clone()].chunks_mut(size))
        .zip(x2[range].chunks_mut(size))
        .map(|((a, b), c)| [a, b, c])
}

/// Stores the projected lanes as positions; each free particle's velocity takes the
/// change from the predicted position over `h` (a held one's was set by its driver).
/// With `KEPT` (after the lines), the rounding their compensated moves kept apart in
/// the residue lanes `r` goes to the velocity too and joins the particle's residue, and
/// those lanes are zeroed for the next substep.
fn store<const KEPT: bool>(x: &[Vec<f32>; 3], r: &mut [Vec<f32>; 3], p: &mut Particles, h: f32) {
    let n = p.len();
    let [x0, x1, x2] = x.each_ref().map(|l| l.chunks(CHUNK));
    let [r0, r1, r2] = r.each_mut().map(|l| l.chunks_mut(CHUNK));
    let pieces = p
        .position
        .chunks_mut(CHUNK)
        .zip(p.velocity.chunks_mut(CHUNK))
        .zip(p.residue.chunks_mut(CHUNK))
        .zip(x0.zip(x1).zip(x2).zip(r0.zip(r1).zip(r2)));
    parallel::for_each_from(
        XPBD_PARALLEL_FROM,
        n,
        pieces,
        |(((position, velocity), residue), (((x0, x1), x2), ((r0, r1), r2)))| {
            let particles = position.iter_mut().zip(velocity).zip(residue);
            for (k, ((x, v), residue)) in particles.enumerate() {
                let projected = Vec3::new(x0[k], x1[k], x2[k]);
                if KEPT {
                    let kept = Vec3::new(r0[k], r1[k], r2[k]);
                    *v += ((projected - *x) + kept) / h;
                    *residue += kept;
                    (r0[k], r1[k], r2[k]) = (0.0, 0.0, 0.0);
                } else {
                    *v += (projected - *x) / h;
                }
                *x = projected;
            }
        },
    );
}
