//! The Thomas algorithm on tiles of chains side by side (see the chains' module doc for
//! the system it solves): the kernel of the chains' solve and of a grid's lines on its
//! stencil.

use crate::solver::xpbd::Family;

/// Chains side by side in a tile: the width the solve's loops run over.
pub(in crate::solver) const LANES: usize = 32;

type Lane = [f32; LANES];

/// One particle along each of a tile's chains, and the constraint to the next: what the
/// solve reads and writes at one step down the chains, together.
#[derive(Clone, Copy, Debug, Default)]
pub(in crate::solver) struct Row {
    /// Positions in, moves out.
    pub x: [Lane; 3],
    /// Positions at the substep's start (read when damped).
    pub prev: [Lane; 3],
    /// Inverse masses.
    pub w: Lane,
    /// The constraint to the next row: its rest length and 1 while it acts (0 torn or
    /// none), synced once a step; its direction, Thomas's modified upper diagonal and
    /// right-hand side (then `Δλ`), per solve.
    pub rest: Lane,
    pub live: Lane,
    n: [Lane; 3],
    cp: Lane,
    dp: Lane,
}

/// The Thomas algorithm on a tile's chains (see the module doc), leaving each row's
/// move in its `x`. Every loop runs over the lanes of local arrays, without branches,
/// so it vectorises.
#[inline(always)]
pub(in crate::solver) fn solve_tile<const DAMPED: bool>(rows: &mut [Row], f: Family) {
    if rows.len() < 2 {
        rows.iter_mut().for_each(|row| row.x = [ZERO; 3]);
        return;
    }
    if f.limit_only() {
        eliminate::<false, true>(rows, f);
    } else {
        eliminate::<DAMPED, false>(rows, f);
    }
    substitute(rows);
    moves(rows);
}

const ZERO: Lane = [0.0; LANES];

/// Forward elimination, constraint by constraint down the chains: each row's direction,
/// modified upper diagonal (of the row before, once this one's off-diagonal is known)
/// and right-hand side. What a constraint hands the next is carried in locals, lane by
/// lane; rows are read in place (no copies of whole rows).
///
/// `LIMIT`: the family's strain limit alone ([`Family::limit_only`]), solved along the
/// chains: every constraint longer than `max_stretch` times its rest length is taken
/// back to that length and every other one keeps the length it has (to first order),
/// so the move that shortens one link does not stretch its neighbours past the limit
/// (as it would if they were left free). Provot's (1995) limit, which a sweep carries
/// one constraint a substep, then holds along a whole line at once.
#[inline(always)]
fn eliminate<const DAMPED: bool, const LIMIT: bool>(rows: &mut [Row], f: Family) {
    let (g, compliance) = if LIMIT {
        (1.0, 0.0)
    } else {
        (1.0 + f.damping, f.compliance)
    };
    let (mut n_before, mut inv_before, mut d_before) = ([ZERO; 3], ZERO, ZERO);
    for k in 0..rows.len() - 1 {
        let (head, tail) = rows.split_at_mut(k + 1);
        let (a, b) = (&mut head[k], &tail[0]);
        let mut c_before = ZERO;
        for j in 0..LANES {
            let dx = [
                b.x[0][j] - a.x[0][j],
                b.x[1][j] - a.x[1][j],
                b.x[2][j] - a.x[2][j],
            ];
            let len = (dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]).sqrt();
            let wa = a.w[j];
            let rest = if LIMIT {
                a.rest[j] * f.max_stretch
            } else {
                a.rest[j]
            };
            let wsum = wa + b.w[j];
            let on = a.live[j] > 0.0 && wsum > 0.0 && len > f32::EPSILON * rest;
            let inv = if on {
                1.0 / len.max(f32::MIN_POSITIVE)
            } else {
                0.0
            };
            let nj = [dx[0] * inv, dx[1] * inv, dx[2] * inv];
            let mut rhs = match (on, LIMIT) {
                (false, _) => 0.0,
                (true, false) => rest - len,
                (true, true) => (rest - len).min(0.0),
            };
            if DAMPED {
                let rel =
                    [0, 1, 2].map(|c| (b.x[c][j] - b.prev[c][j]) - (a.x[c][j] - a.prev[c][j]));
                rhs -= f.damping * (nj[0] * rel[0] + nj[1] * rel[1] + nj[2] * rel[2]);
            }
            let diag = if on { g * wsum + compliance } else { 1.0 };
            let dot = n_before[0][j] * nj[0] + n_before[1][j] * nj[1] + n_before[2][j] * nj[2];
            let off = -g * wa * dot;
            c_before[j] = off * inv_before[j];
            inv_before[j] = 1.0 / (diag - off * c_before[j]);
            d_before[j] = (rhs - off * d_before[j]) * inv_before[j];
            for c in 0..3 {
                (a.n[c][j], n_before[c][j]) = (nj[c], nj[c]);
            }
            a.dp[j] = d_before[j];
        }
        if k > 0 {
            head[k - 1].cp = c_before;
        }
    }
}

/// Back substitution: each constraint's `Δλ` into its row's `dp`.
#[inline(always)]
fn substitute(rows: &mut [Row]) {
    for k in (0..rows.len().saturating_sub(2)).rev() {
        let (head, tail) = rows.split_at_mut(k + 1);
        let (row, after) = (&mut head[k], &tail[0]);
        for j in 0..LANES {
            row.dp[j] -= row.cp[j] * after.dp[j];
        }
    }
}

/// Each particle's move, `w_k (n_{k−1} Δλ_{k−1} − n_k Δλ_k)`, into its row's `x`.
#[inline(always)]
fn moves(rows: &mut [Row]) {
    let m = rows.len();
    for k in 0..m {
        let (head, tail) = rows.split_at_mut(k);
        let row = &mut tail[0];
        for j in 0..LANES {
            for c in 0..3 {
                let before = head.last().map_or(0.0, |b| b.n[c][j] * b.dp[j]);
                let here = if k + 1 < m {
                    row.n[c][j] * row.dp[j]
                } else {
                    0.0
                };
                row.x[c][j] = row.w[j] * (before - here);
            }
        }
    }
}
