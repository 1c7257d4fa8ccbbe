//! Finding each render vertex's simulation triangle: the triangles with an area,
//! bucketed in a uniform grid, searched ring by ring outward for the nearest.

use bevy::math::Vec3;

use super::frame;

/// The point of triangle `a b c` nearest `p` (Ericson 2005, "Real-Time Collision
/// Detection", §5.1.5), as its squared distance from `p`.
pub(super) fn nearest_squared(p: Vec3, [a, b, c]: [Vec3; 3]) -> f32 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.length_squared();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.length_squared();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (p - (a + v * ab)).length_squared();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.length_squared();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (p - (a + w * ac)).length_squared();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (p - (b + w * (c - b))).length_squared();
    }
    let denominator = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denominator, vc * denominator);
    (p - (a + ab * v + ac * w)).length_squared()
}

/// Each triangle of `triangles` over `x` that has an area: its corners, centre and reach
/// (the farthest corner from the centre), for a quick rejection.
pub(super) fn usable(x: &[Vec3], triangles: &[[u32; 3]]) -> Vec<([u32; 3], Vec3, f32)> {
    triangles
        .iter()
        .filter(|&&t| frame(x, t).is_some())
        .map(|&t| {
            let p = t.map(|i| x[i as usize]);
            let centre = (p[0] + p[1] + p[2]) / 3.0;
            let reach = p.iter().map(|q| q.distance(centre)).fold(0.0, f32::max);
            (t, centre, reach)
        })
        .collect()
}

/// The usable triangles (corners, centre, reach) bucketed by their centres in a uniform
/// grid, so that a vertex's nearest triangle is searched among its neighbours, ring by
/// ring of cells outward, instead of among all of them.
pub(super) struct Buckets<'a> {
    usable: &'a [([u32; 3], Vec3, f32)],
    low: Vec3,
    cell: f32,
    dims: [i32; 3],
    /// Each cell's first entry in `items` (one more than the cells: the end).
    start: Vec<u32>,
    /// Triangles (indices into `usable`), cell by cell, in index order within each.
    items: Vec<u32>,
    /// The largest reach.
    reach: f32,
}

impl<'a> Buckets<'a> {
    pub(super) fn new(usable: &'a [([u32; 3], Vec3, f32)]) -> Self {
        let (mut low, mut high) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for &(_, centre, _) in usable {
            (low, high) = (low.min(centre), high.max(centre));
        }
        let reach = usable.iter().map(|u| u.2).fold(0.0, f32::max);
        // Cells about two reaches wide (a triangle or two each on a cloth), widened
        // until there are at most four cells a triangle.
        let extent = (high - low).max(Vec3::splat(f32::EPSILON));
        let mut cell = (2.0 * reach).max(extent.max_element() * 1e-3);
        let dims_of = |cell: f32| (extent / cell).floor().as_ivec3() + 1;
        while dims_of(cell).as_i64vec3().element_product() > 4 * usable.len() as i64 + 8 {
            cell *= 1.5;
        }
        let dims = dims_of(cell).to_array();
        let mut buckets = Buckets {
            usable,
            low,
            cell,
            dims,
            start: Vec::new(),
            items: Vec::new(),
            reach,
        };
        let cells = (dims[0] * dims[1] * dims[2]) as usize;
        let of: Vec<usize> = usable
            .iter()
            .map(|u| buckets.index(buckets.cell_of(u.1)))
            .collect();
        let mut count = vec![0u32; cells + 1];
        for &c in &of {
            count[c + 1] += 1;
        }
        for c in 0..cells {
            count[c + 1] += count[c];
        }
        buckets.start = count.clone();
        buckets.items = vec![0; usable.len()];
        for (t, &c) in of.iter().enumerate() {
            buckets.items[count[c] as usize] = t as u32;
            count[c] += 1;
        }
        buckets
    }

    /// The cell `p` is in, or nearest it.
    fn cell_of(&self, p: Vec3) -> [i32; 3] {
        let c = ((p - self.low) / self.cell).floor().as_ivec3();
        [0, 1, 2].map(|k| c[k].clamp(0, self.dims[k] - 1))
    }

    fn index(&self, [x, y, z]: [i32; 3]) -> usize {
        ((z * self.dims[1] + y) * self.dims[0] + x) as usize
    }

    /// The triangle over `x` nearest `p` (of those equally near, the first), as a search
    /// over every one finds it.
    pub(super) fn nearest(&self, x: &[Vec3], p: Vec3) -> [u32; 3] {
        let home = self.cell_of(p);
        let (mut best, mut best_d2) = (u32::MAX, f32::INFINITY);
        let most = self.dims.into_iter().max().unwrap_or(1);
        for ring in 0..=most {
            // Every centre in this ring or beyond is at least `(ring − 1)·cell` from
            // `p` (or from its nearest point in the grid's box, which is nearer), its
            // triangle at least `reach` less.
            let gap = (ring as f32 - 1.0) * self.cell - self.reach;
            if best != u32::MAX && gap > 0.0 && gap * gap > best_d2 {
                break;
            }
            self.visit_ring(home, ring, |t| {
                let (corners, centre, reach) = self.usable[t as usize];
                let far = p.distance(centre) - reach;
                if far > 0.0 && far * far > best_d2 {
                    return;
                }
                let d2 = nearest_squared(p, corners.map(|i| x[i as usize]));
                if d2 < best_d2 || (d2 == best_d2 && t < best) {
                    (best, best_d2) = (t, d2);
                }
            });
        }
        self.usable[best as usize].0
    }

    /// Calls `visit` with each triangle in the cells `ring` cells from `home` (in every
    /// direction, the shell of a cube).
    fn visit_ring(&self, home: [i32; 3], ring: i32, mut visit: impl FnMut(u32)) {
        let range = |k: usize| (home[k] - ring).max(0)..=(home[k] + ring).min(self.dims[k] - 1);
        for z in range(2) {
            for y in range(1) {
                for x in range(0) {
                    let shell = [x - home[0], y - home[1], z - home[2]]
                        .iter()
                        .any(|d| d.abs() == ring);
                    if !shell {
                        continue;
                    }
                    let c = self.index([x, y, z]);
                    for &t in &self.items[self.start[c] as usize..self.start[c + 1] as usize] {
                        visit(t);
                    }
                }
            }
        }
    }
}
