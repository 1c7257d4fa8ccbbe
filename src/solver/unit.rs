//! Vectors made unit a batch at a time, to the bit as glam's `normalize_or` makes them
//! one by one. One by one, each vector's square root and division are scalar
//! instructions, and placing a proxy's vertices that way spent two fifths of its time on
//! them; a batch's squared lengths side by side become vector square roots and
//! divisions, and a batch whose vectors all have a length (nearly every batch of drawn
//! normals) is scaled without a test a vector.

use std::ops::Mul;

use bevy::math::{Vec3, Vec3A, Vec4};

/// Vectors made unit together.
pub(crate) const BATCH: usize = 8;
const _: () = assert!(BATCH == 8, "all_scale tests two vectors of four");

/// The squared length of each of `v`, as glam's `length_squared` works it out ((x² +
/// y²) + z², the same bits), four at a time: the squares' x, y and z of four vectors as
/// three four-lane vectors, where one vector at a time added each one's lanes in turn.
#[inline(always)]
pub(crate) fn squared_lengths(v: &[Vec3A; BATCH]) -> [f32; BATCH] {
    let four = |v: &[Vec3A]| {
        let s = [v[0] * v[0], v[1] * v[1], v[2] * v[2], v[3] * v[3]];
        let lane = |k: usize| Vec4::new(s[0][k], s[1][k], s[2][k], s[3][k]);
        (lane(0) + lane(1) + lane(2)).to_array()
    };
    joined(four(&v[..4]), four(&v[4..]))
}

/// `1 / √s` of each squared length `s`, as glam's `length_recip` works it out from
/// `length_squared` (the same bits: a square root and a division are rounded alike one
/// at a time and four at a time), four at a time in glam's vectors. Written lane by lane,
/// the compiler made half of them scalar square roots and divisions, each waited on in
/// turn.
#[inline(always)]
pub(crate) fn length_recips(squared: [f32; BATCH]) -> [f32; BATCH] {
    let recips = |s: &[f32]| (Vec4::ONE / Vec4::from_slice(s).sqrt()).to_array();
    let (low, high) = squared.split_at(4);
    joined(recips(low), recips(high))
}

/// Two fours as one batch.
#[inline(always)]
fn joined(low: [f32; 4], high: [f32; 4]) -> [f32; BATCH] {
    [
        low[0], low[1], low[2], low[3], high[0], high[1], high[2], high[3],
    ]
}

/// Whether every one of `rcp` scales its vector to a unit one, finite and above zero,
/// where glam's `normalize_or` would not take its fallback (a zero vector's is infinite,
/// an infinite or not-a-number one's zero or not a number). Tested all at once, without
/// a branch a vector.
#[inline(always)]
pub(crate) fn all_scale(rcp: &[f32; BATCH]) -> bool {
    // Four at a time in glam's vectors: written lane by lane, the compiler tested each
    // float's bits in integer registers and branched on each.
    let scales = |r: Vec4| (r.cmpgt(Vec4::ZERO) & r.cmplt(Vec4::INFINITY)).all();
    let (low, high) = rcp.split_at(4);
    scales(Vec4::from_slice(low)) & scales(Vec4::from_slice(high))
}

/// `v` scaled by its `rcp` (`1 / |v|`), or `fallback` when it has no length: glam's
/// `normalize_or`, with the reciprocal worked out beforehand.
#[inline(always)]
pub(crate) fn scaled_or<V: Mul<f32, Output = V>>(v: V, rcp: f32, fallback: V) -> V {
    if rcp.is_finite() && rcp > 0.0 {
        v * rcp
    } else {
        fallback
    }
}

/// Each of `v` made unit, or `fallback` where it has no length: `normalize_or` on each,
/// to the bit, a batch at a time.
pub(crate) fn normalize_each_or(v: &mut [Vec3], fallback: Vec3) {
    // Whole batches of eight (their loops unrolled; a last, shorter batch through the
    // same path measured 3% slower in `place_cost`), then the rest one by one.
    let mut batches = v.chunks_exact_mut(BATCH);
    for batch in &mut batches {
        // One at a time here: four at a time (`squared_lengths`) measured 1% slower on
        // three-float vectors, each loaded into four lanes first.
        let mut squared = [0.0; BATCH];
        for (s, v) in squared.iter_mut().zip(batch.iter()) {
            *s = v.length_squared();
        }
        let rcp = length_recips(squared);
        if all_scale(&rcp) {
            for (v, r) in batch.iter_mut().zip(rcp) {
                *v *= r;
            }
        } else {
            for (v, r) in batch.iter_mut().zip(rcp) {
                *v = scaled_or(*v, r, fallback);
            }
        }
    }
    for v in batches.into_remainder() {
        *v = v.normalize_or(fallback);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A batch at a time is glam's `normalize_or` one by one, to the bit: for vectors of
    /// every size, of no length, infinite and not a number, in whole batches and a
    /// remainder, in batches all of length and batches with one of none.
    #[test]
    fn normalized_in_batches_as_one_by_one() {
        let fallback = Vec3::new(0.0, 0.0, 1.0);
        let mut v: Vec<Vec3> = (0..53)
            .map(|k| {
                let f = k as f32;
                let scale = 10f32.powi(k % 13 - 6);
                scale * Vec3::new((0.7 * f).sin(), (1.3 * f).cos(), 0.1 * f - 2.0)
            })
            .collect();
        v[9] = Vec3::ZERO;
        v[20] = Vec3::new(f32::INFINITY, 1.0, 0.0);
        v[31] = Vec3::new(f32::NAN, 0.0, 0.0);
        v[50] = Vec3::ZERO;
        let want: Vec<Vec3> = v.iter().map(|v| v.normalize_or(fallback)).collect();
        normalize_each_or(&mut v, fallback);
        for (k, (got, want)) in v.iter().zip(&want).enumerate() {
            assert_eq!(
                got.to_array().map(f32::to_bits),
                want.to_array().map(f32::to_bits),
                "{k}"
            );
        }
        assert_eq!(v[9], fallback);
        assert_eq!(v[31], fallback);
    }

    /// Four at a time, the squared lengths and their reciprocal roots are glam's one by
    /// one, to the bit: for vectors of every size from 1e-20 to 1e15, and with one of no
    /// length, infinite or not a number among them.
    #[test]
    fn squared_lengths_and_recips_as_one_by_one() {
        let mut v: [Vec3A; BATCH] = std::array::from_fn(|k| {
            let f = k as f32;
            let scale = 10f32.powi(5 * k as i32 - 20);
            scale * Vec3A::new((0.7 * f).sin(), (1.3 * f).cos() + 0.1, 0.3 * f - 1.0)
        });
        let bits = |a: [f32; BATCH]| a.map(f32::to_bits);
        for special in [
            v[3],
            Vec3A::ZERO,
            Vec3A::new(f32::INFINITY, 1.0, 0.0),
            Vec3A::new(0.0, f32::NAN, 2.0),
        ] {
            v[3] = special;
            let squared = squared_lengths(&v);
            assert_eq!(bits(squared), bits(v.map(|v| v.length_squared())));
            assert_eq!(
                bits(length_recips(squared)),
                bits(v.map(|v| v.length_recip()))
            );
        }
    }
}
