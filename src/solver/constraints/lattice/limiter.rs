//! The strain limiter's projection on a stencil (Provot 1995): each spring past its
//! limit pulled back to it, colour by colour along the rows and across them (see the
//! lattice module's doc).

use super::*;

/// A sweep corrected a spring.
pub(super) const MOVED: u8 = 1;
/// A sweep found a spring longer than `past·l0`: not yet within.
pub(super) const UNCONVERGED: u8 = 2;

/// Provot's projection of one spring in place.
#[derive(Clone, Copy)]
pub(super) struct Projection {
    pub(super) limit: f32,
    pub(super) past: f32,
}

/// A group of whole rows or bands: positions as lanes, inverse masses from the group's
/// first particle on.
pub(super) struct Group<'a> {
    pub(super) x: [&'a mut [f32]; 3],
    /// The corrections made in this call, summed (for the velocity: see
    /// [`Stencil::limit_strain`]).
    pub(super) dx: [&'a mut [f32]; 3],
    pub(super) inv_mass: &'a [f32],
}

/// One offset's rest lengths and weights, from a group's first particle on.
pub(super) type RestAndWeight<'a> = (&'a [f32], &'a [f32]);

/// The springs from a row to the next: the vertical ones, and a cell's two diagonals
/// (right, then left).
pub(super) struct Down<'a> {
    pub(super) down: Option<RestAndWeight<'a>>,
    pub(super) diagonals: Option<(RestAndWeight<'a>, RestAndWeight<'a>)>,
}

impl<'a> Down<'a> {
    /// The offsets' springs from particle `start` on.
    pub(super) fn from(
        down: Option<&'a Offset>,
        diagonals: Option<[&'a Offset; 2]>,
        start: usize,
    ) -> Self {
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
pub(super) fn chunks6<'a>(
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
    pub(super) fn past_limit(&self, len2: f32, rest: f32) -> bool {
        let max = (1.0 + self.limit) * rest;
        (len2 > max * max) | len2.is_nan()
    }

    /// Shortens the spring from `a` to `b` (indices in `g`) to `(1 + limit)·rest` when it
    /// is longer, each end moved by its share of inverse mass (Sladović 2014 eq. 2); nothing
    /// when it is within, torn (`weight` 0) or held at both ends. Most springs are within,
    /// so the test comes first, on squared lengths. [`MOVED`] when it was corrected, and
    /// with `TRACK` [`UNCONVERGED`] when it was longer than `past·rest`.
    #[inline(always)]
    pub(super) fn project<const TRACK: bool>(
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
    pub(super) fn along_rows<const TRACK: bool>(
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
    pub(super) fn any_over(
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
    pub(super) fn down_rows<const TRACK: bool>(
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
    pub(super) fn row_to_next<const TRACK: bool>(
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
    pub(super) fn across_rows<const TRACK: bool>(
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
