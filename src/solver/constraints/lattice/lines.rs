//! XPBD's structural constraints solved along a grid's lines on the stencil's lanes: the
//! chains' exact solve along each line (the Thomas algorithm of `chains/thomas.rs`), with
//! the grid's rows as one set of chains and its columns as the next, read from the
//! lanes and written back to them. No index lists and no gather through them: a tile
//! of columns is eight neighbours of each row, a tile of rows eight rows side by side.
//!
//! A set is solved in two passes, each in fixed pieces over the compute pool (the same
//! bits on any number of threads): every tile from the lanes as they are (a set's
//! chains share no particle, so no tile reads another's moves), then every particle's
//! move added to its lane with the rounding kept apart (compensated summation, as the
//! chains' moves), so a move far below a float step of the position still counts.

use super::{CHUNK, Lanes, Offset, Stencil, parallel};
use crate::solver::SpringKind;
use crate::solver::chains::{LANES, Row, solve_tile};
use crate::solver::integrate::compensated_add;
use crate::solver::parallel::XPBD_PARALLEL_FROM;
use crate::solver::topology::squared_bound;
use crate::solver::xpbd::Family;

/// One set of a grid's lines: its rows or its columns, `LANES` of them to a tile.
#[derive(Clone, Copy)]
struct Set {
    width: usize,
    height: usize,
    /// The rows (`true`) or the columns.
    rows: bool,
}

impl Set {
    /// How many lines.
    fn lines(self) -> usize {
        if self.rows { self.height } else { self.width }
    }

    /// Particles along each line.
    fn len(self) -> usize {
        if self.rows { self.width } else { self.height }
    }
}

impl Stencil {
    /// The grid's rows (`rows`) or columns as a set of lines.
    fn set(&self, rows: bool) -> Set {
        let width = self.width.max(1);
        Set {
            width,
            height: self.x.0[0].len() / width,
            rows,
        }
    }

    /// The rows of the tiles of the grid's rows (`rows`) or columns: a row per particle
    /// along the lines, for each tile of `LANES` lines.
    pub(super) fn tile_rows(&self, rows: bool) -> usize {
        let set = self.set(rows);
        set.lines().div_ceil(LANES) * set.len()
    }

    /// The structural springs `(dx, dy)` of the rows (`rows`) or columns.
    fn lines_offset(&self, rows: bool) -> Option<&Offset> {
        let (dx, dy) = if rows { (1, 0) } else { (0, 1) };
        self.offsets
            .iter()
            .find(|o| o.kind == SpringKind::Structural && o.dx == dx && o.dy == dy)
    }

    /// The structural constraints solved once along the rows, then along the columns,
    /// with the family `f`, each particle's move added to its lane (compensated); the
    /// velocity takes them at [`Stencil::end_xpbd`].
    pub fn solve_lines(&mut self, inv_mass: &[f32], f: Family) {
        if !f.on {
            return;
        }
        if !self.tiles_synced {
            self.sync_tiles();
        }
        for (rows, set_tiles) in [true, false].into_iter().zip(0..2) {
            if self.lines_offset(rows).is_none() {
                continue;
            }
            let set = self.set(rows);
            let previous = (self.damped && !f.limit_only()).then_some(&self.previous);
            let read = Read {
                set,
                x: &self.x,
                previous,
                inv_mass,
            };
            let tiles = &mut self.tiles[set_tiles];
            solve_set(tiles, read, f);
            add_moves(&mut self.x, &mut self.residue, &self.tiles[set_tiles], set);
            self.lines_moved = true;
        }
    }

    /// The tiles' springs (rest lengths, and weights for their `live`: the solve asks
    /// only whether it is above 0) from the offsets; padding without mass or spring.
    fn sync_tiles(&mut self) {
        for (rows, set_tiles) in [true, false].into_iter().zip(0..2) {
            let set = self.set(rows);
            let mut tiles = std::mem::take(&mut self.tiles[set_tiles]);
            tiles.fill(Row::default());
            if let Some(offset) = self.lines_offset(rows) {
                for (t, tile) in tiles.chunks_mut(set.len().max(1)).enumerate() {
                    fill(tile, set, t * LANES, &offset.rest, |row| &mut row.rest);
                    fill(tile, set, t * LANES, &offset.weight, |row| &mut row.live);
                }
            }
            self.tiles[set_tiles] = tiles;
        }
        self.tiles_synced = true;
    }

    /// Whether a live, free spring of `kind` is longer than `max_stretch` times its rest
    /// length in the lanes (the general path's `Springs::any_longer_than`, on lanes).
    pub fn any_longer(&self, kind: SpringKind, inv_mass: &[f32], max_stretch: f32) -> bool {
        let bound = squared_bound(max_stretch);
        let [x, y, z] = &self.x.0;
        let n = x.len();
        let mut past = false;
        for o in self.offsets.iter().filter(|o| o.kind == kind) {
            let m = n - o.step;
            let (rest, weight) = (&o.rest[..m], &o.weight[..m]);
            let (xa, ya, za, wa) = (&x[..m], &y[..m], &z[..m], &inv_mass[..m]);
            let (xb, yb, zb, wb) = (
                &x[o.step..],
                &y[o.step..],
                &z[o.step..],
                &inv_mass[o.step..],
            );
            for i in 0..m {
                let (dx, dy, dz) = (xb[i] - xa[i], yb[i] - ya[i], zb[i] - za[i]);
                let free = wa[i] + wb[i] > 0.0;
                let long = dx * dx + dy * dy + dz * dz > bound * rest[i] * rest[i];
                past |= (weight[i] > 0.0) & free & long;
            }
        }
        past
    }
}

/// What a set's tiles are read from.
#[derive(Clone, Copy)]
struct Read<'a> {
    set: Set,
    x: &'a Lanes,
    /// The substep's start, when damped.
    previous: Option<&'a Lanes>,
    inv_mass: &'a [f32],
}

/// Every tile of `read.set` gathered into `tiles` and solved, leaving each row's move
/// in its `x`; tiles in pieces of about [`CHUNK`] particles over the compute pool.
fn solve_set(tiles: &mut [Row], read: Read<'_>, f: Family) {
    let len = read.set.len();
    let count = read.set.lines().div_ceil(LANES);
    if len == 0 || count == 0 {
        return;
    }
    let per_piece = (CHUNK / (len * LANES)).max(1);
    let pieces = tiles[..count * len].chunks_mut(per_piece * len).enumerate();
    let n = read.set.width * read.set.height;
    parallel::for_each_from(XPBD_PARALLEL_FROM, n, pieces, |(piece, rows)| {
        solve_tiles(rows, len, read, piece * per_piece * LANES, f);
    });
}

/// The tiles of `rows` (`len` rows each) from the lines from `first` on, gathered and
/// solved.
fn solve_tiles(rows: &mut [Row], len: usize, read: Read<'_>, first: usize, f: Family) {
    for (t, tile) in rows.chunks_mut(len).enumerate() {
        gather(tile, read, first + t * LANES);
        if read.previous.is_some() {
            solve_tile::<true>(tile, f);
        } else {
            solve_tile::<false>(tile, f);
        }
    }
}

/// The particles of the tile of lines `first..first + LANES` into `tile` (positions,
/// inverse masses, and the substep's start when damped), one row per particle along
/// them; padding past the last line is left as [`Stencil::sync_tiles`] made it.
#[inline(always)]
fn gather(tile: &mut [Row], read: Read<'_>, first: usize) {
    let Read {
        set,
        x,
        previous,
        inv_mass,
    } = read;
    for c in 0..3 {
        fill(tile, set, first, &x.0[c], |row| &mut row.x[c]);
        if let Some(previous) = previous {
            fill(tile, set, first, &previous.0[c], |row| &mut row.prev[c]);
        }
    }
    fill(tile, set, first, inv_mass, |row| &mut row.w);
}

/// One lane of the tile of lines from `first` (`lane` by particle): for rows, each
/// line's run of particles; for columns, `LANES` neighbours in each grid row.
#[inline(always)]
fn fill(
    tile: &mut [Row],
    set: Set,
    first: usize,
    lane: &[f32],
    get: impl Fn(&mut Row) -> &mut [f32; LANES],
) {
    let lines = (set.lines() - first).min(LANES);
    if set.rows {
        for j in 0..lines {
            let line = &lane[(first + j) * set.width..][..tile.len()];
            for (row, &v) in tile.iter_mut().zip(line) {
                get(row)[j] = v;
            }
        }
    } else {
        for (k, row) in tile.iter_mut().enumerate() {
            let at = k * set.width + first;
            get(row)[..lines].copy_from_slice(&lane[at..at + lines]);
        }
    }
}

/// Each particle's move in `tiles` (solved for `set`) added to its lane, what rounding
/// lost kept in `residue` ([`compensated_add`], as the chains' moves); in
/// pieces of whole grid rows over the compute pool.
fn add_moves(x: &mut Lanes, residue: &mut Lanes, tiles: &[Row], set: Set) {
    let (w, len) = (set.width, set.len());
    let n = w * set.height;
    let group = w * (CHUNK / w).max(1);
    let [x0, x1, x2] = x.0.each_mut().map(|l| l[..n].chunks_mut(group));
    let [r0, r1, r2] = residue.0.each_mut().map(|l| l[..n].chunks_mut(group));
    let pieces = x0.zip(x1).zip(x2).zip(r0.zip(r1).zip(r2)).enumerate();
    parallel::for_each_from(XPBD_PARALLEL_FROM, n, pieces, |(piece, lanes)| {
        let (((x0, x1), x2), ((r0, r1), r2)) = lanes;
        let (x, r) = ([x0, x1, x2], [r0, r1, r2]);
        let top = piece * group / w;
        for row in 0..x[0].len() / w {
            let at = row * w;
            for c in 0..3 {
                let (x, r) = (&mut x[c][at..at + w], &mut r[c][at..at + w]);
                if set.rows {
                    // Row `top + row` is lane `j` of tile `t`, a row of it per column.
                    let (t, j) = ((top + row) / LANES, (top + row) % LANES);
                    let moved = tiles[t * len..][..w].iter().map(|m| m.x[c][j]);
                    for ((x, r), m) in x.iter_mut().zip(r.iter_mut()).zip(moved) {
                        compensated_add(x, r, m);
                    }
                } else {
                    // Column `column` is lane `column % LANES` of tile `column / LANES`.
                    let moved = tiles.iter().skip(top + row).step_by(len);
                    let lanes = x.chunks_mut(LANES).zip(r.chunks_mut(LANES));
                    for ((x, r), m) in lanes.zip(moved) {
                        for ((x, r), &m) in x.iter_mut().zip(r.iter_mut()).zip(&m.x[c]) {
                            compensated_add(x, r, m);
                        }
                    }
                }
            }
        }
    });
}
