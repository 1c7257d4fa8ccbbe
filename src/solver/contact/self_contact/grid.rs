//! The uniform grid self-collision lists its pairs by.

use bevy::math::Vec3;

/// A uniform grid over a box: cells `size` a side, of side `cell`, from `lo`, indexed
/// x fastest (so a row of cells along x is one run of entries).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Grid {
    pub(super) lo: Vec3,
    pub(super) cell: f32,
    pub(super) size: [i32; 3],
}

impl Grid {
    /// The grid over `lo..=hi` with cells of `cell` or, if that takes more than
    /// `most` cells, the smallest larger cells that take at most that many.
    pub(super) fn new(lo: Vec3, hi: Vec3, cell: f32, most: usize) -> Self {
        let extent = hi - lo;
        if !(extent.is_finite() && cell.is_finite() && cell > 0.0) {
            // Nothing to list by: one cell (a non-finite step is undone after).
            return Self {
                lo,
                cell: f32::INFINITY,
                size: [1, 1, 1],
            };
        }
        let mut cell = cell;
        loop {
            // Counted in floats: a tiny cell over a large box has more cells along an
            // axis than an `i32` holds (converted only once the count is small).
            let size = (extent / cell).floor() + Vec3::ONE;
            let count = f64::from(size.x) * f64::from(size.y) * f64::from(size.z);
            if count <= most as f64 {
                return Self {
                    lo,
                    cell,
                    size: size.as_ivec3().to_array(),
                };
            }
            cell *= (count / most as f64).cbrt().max(1.01) as f32;
        }
    }

    /// The cell holding `x`, clamped to the grid (every particle listed is inside it).
    pub(super) fn cell(&self, x: Vec3) -> [i32; 3] {
        let c = ((x - self.lo) / self.cell).floor();
        let clamp = |v: f32, n: i32| (v.max(0.0) as i32).min(n - 1);
        [
            clamp(c.x, self.size[0]),
            clamp(c.y, self.size[1]),
            clamp(c.z, self.size[2]),
        ]
    }

    pub(super) fn index(&self, [x, y, z]: [i32; 3]) -> u32 {
        ((z * self.size[1] + y) * self.size[0] + x) as u32
    }

    pub(super) fn coords(&self, k: usize) -> [i32; 3] {
        let k = k as i32;
        let (nx, ny) = (self.size[0], self.size[1]);
        [k % nx, (k / nx) % ny, k / (nx * ny)]
    }

    pub(super) fn len(&self) -> usize {
        self.size.iter().map(|&n| n as usize).product()
    }
}
