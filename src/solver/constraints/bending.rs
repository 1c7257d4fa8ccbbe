//! Bending in physical units: the quadratic bending model of Bergou, Wardetzky, Harmon,
//! Zorin and Grinspun ("A Quadratic Bending Model for Inextensible Surfaces", SGP 2006),
//! with a fabric's bending rigidity `B` (N·m) as its stiffness.
//!
//! Each edge shared by two triangles is a hinge of four particles: the edge's ends `x0`,
//! `x1` and the far corners `x2`, `x3`. Its cotangent weights at rest,
//! `K = (c03 + c04, c01 + c02, −c01 − c03, −c02 − c04)` (`c0k` the cotangent of the
//! rest angle at `x0` in the triangle with `xk`, `c1k` at `x1`), make `v = Σ K_k x_k` the
//! edge's share of the mean-curvature normal: zero while the two triangles lie in one
//! plane, whatever their motion as a whole. The hinge's energy is
//! `E = ½ B |v|² / (A0 + A1)`, `A0`, `A1` the triangles' rest areas: summed over a
//! regular mesh bent to a cylinder of curvature `κ` it is `½ B κ² A`, the energy of a
//! plate of rigidity `B` (the test `a_cylinder_stores_half_b_kappa_squared`). The energy
//! is exact for bending that does not stretch the cloth, which is what a fabric does.
//!
//! - Mass-spring: the force `−∂E/∂x_k = −B K_k v / (A0 + A1)`, linear in the positions.
//! - XPBD: one constraint `C = |v|` per hinge of compliance `(A0 + A1)/B`, so that
//!   `½ C²/α` is `E`; gradient `K_k v̂`.
//!
//! The rest shape is flat (a fabric lies flat when nothing bends it); a mesh's curved
//! rest shape is bent from flat.

use bevy::math::Vec3;

use crate::solver::Particles;

/// The hinges of a cloth (see the module doc).
#[derive(Clone, Debug, Default)]
pub(in crate::solver) struct Hinges {
    /// `[x0, x1, x2, x3]`: the edge, then the far corners.
    corners: Vec<[u32; 4]>,
    /// The cotangent weights `K`.
    weights: Vec<[f32; 4]>,
    /// `1/(A0 + A1)`, times the hinge's weight (½ where both splits of a rectangle are taken, see [`Hinges::new`]).
    inv_area: Vec<f32>,
}

impl Hinges {
    /// The hinges of `triangles` at the rest positions `rest`: every edge shared by
    /// exactly two non-degenerate triangles. Where triangles pair up into rectangles
    /// (a grid's, a garment's, any lattice cut from one: two triangles sharing their
    /// longest edge, the rectangle's diagonal), the hinges of both diagonal splits are
    /// taken at half the stiffness each ([`flipped`]): one split alone couples bending
    /// along the rows to a twist (its hinges' stencils lean one way), and a strip bent
    /// along its length then twists and bends more (a clamped denim strip sagged
    /// 13.6 mm where the discrete elastica sags 11.9).
    pub fn new(triangles: &[[u32; 3]], rest: &[Vec3]) -> Self {
        let mut hinges = Hinges::default();
        match flipped(triangles, rest) {
            Some(other) => {
                hinges.add_all(triangles, rest, 0.5);
                hinges.add_all(&other, rest, 0.5);
            }
            None => hinges.add_all(triangles, rest, 1.0),
        }
        hinges
    }

    /// Adds the hinges of `triangles` at `weight` times their stiffness.
    fn add_all(&mut self, triangles: &[[u32; 3]], rest: &[Vec3], weight: f32) {
        // Each triangle's three edges as (low end, high end, far corner), sorted so an
        // edge's triangles are side by side.
        let mut edges: Vec<(u32, u32, u32)> = triangles
            .iter()
            .flat_map(|t| {
                (0..3).map(move |k| {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    (a.min(b), a.max(b), t[(k + 2) % 3])
                })
            })
            .collect();
        edges.sort_unstable();
        let mut k = 0;
        while k < edges.len() {
            let mut end = k + 1;
            while end < edges.len() && edges[end].0 == edges[k].0 && edges[end].1 == edges[k].1 {
                end += 1;
            }
            if end - k == 2 {
                let (a, b, c) = edges[k];
                self.add([a, b, c, edges[k + 1].2], rest, weight);
            }
            k = end;
        }
    }

    /// Adds the hinge of `corners` at `weight` times its stiffness, if both its
    /// triangles have an area.
    fn add(&mut self, corners: [u32; 4], rest: &[Vec3], weight: f32) {
        let [x0, x1, x2, x3] = corners.map(|i| rest[i as usize]);
        let area = |p: Vec3| 0.5 * (x1 - x0).cross(p - x0).length();
        let (a0, a1) = (area(x2), area(x3));
        let scale = (x1 - x0).length_squared();
        if !(a0 > 1e-6 * scale && a1 > 1e-6 * scale) {
            return;
        }
        let cot = |u: Vec3, v: Vec3| u.dot(v) / u.cross(v).length();
        let (c01, c02) = (cot(x1 - x0, x2 - x0), cot(x1 - x0, x3 - x0));
        let (c03, c04) = (cot(x0 - x1, x2 - x1), cot(x0 - x1, x3 - x1));
        self.corners.push(corners);
        self.weights
            .push([c03 + c04, c01 + c02, -c01 - c03, -c02 - c04]);
        self.inv_area.push(weight / (a0 + a1));
    }

    /// The number of hinges.
    pub fn len(&self) -> usize {
        self.corners.len()
    }

    /// `v = Σ K_k x_k` of hinge `h`.
    fn curvature(&self, h: usize, x: &[Vec3]) -> Vec3 {
        let (c, k) = (self.corners[h], self.weights[h]);
        (0..4).fold(Vec3::ZERO, |v, j| v + k[j] * x[c[j] as usize])
    }

    /// Adds every hinge's force for rigidity `b` (N·m) to `p.force`.
    pub fn add_forces(&self, p: &mut Particles, b: f32) {
        for h in 0..self.len() {
            let v = self.curvature(h, &p.position) * (b * self.inv_area[h]);
            let (c, k) = (self.corners[h], self.weights[h]);
            for j in 0..4 {
                p.force[c[j] as usize] -= k[j] * v;
            }
        }
    }

    /// Projects every hinge's constraint once (XPBD, Gauss–Seidel in hinge order) for
    /// rigidity `b`, on behalf of `substeps` substeps of length `h`; each correction also
    /// goes to the velocity (`/h`).
    ///
    /// Projected once for `g` substeps, a hinge's compliance is `α/(g h²)`: while it is
    /// soft against its particles' masses (`g h² Σ w K² ≪ α`, which `hinge_projections`
    /// keeps), the correction is the impulse `h · g · f` its force `f` would have given
    /// over the `g` substeps, so a cloth's bending costs what its stiffness needs, not what
    /// its stretch does.
    pub fn project(&self, p: &mut Particles, b: f32, h: f32, substeps: u32) {
        if b <= 0.0 {
            return;
        }
        // `Δλ = −C / (Σ w_k K_k² + α̃)` and `Δx_k = w_k K_k v̂ Δλ` with `C = |v|`: the length
        // cancels, `Δx_k = −w_k K_k v / (Σ w K² + α̃)` (no square root, and nothing to
        // skip at `v = 0`). `α̃ = (A0 + A1)/(B g h²)`.
        let (inv_h, per_area) = (1.0 / h, 1.0 / (b * substeps.max(1) as f32 * h * h));
        for e in 0..self.len() {
            let (corners, k) = (self.corners[e], self.weights[e]);
            let i = corners.map(|i| i as usize);
            let w = i.map(|i| p.inv_mass[i]);
            // `curvature`, written out: calling it (or a free function of the corners)
            // made the denim curtain's step 17% slower (2.2 against 1.87 ms).
            let v = k[0] * p.position[i[0]]
                + k[1] * p.position[i[1]]
                + k[2] * p.position[i[2]]
                + k[3] * p.position[i[3]];
            let stiffness =
                w[0] * k[0] * k[0] + w[1] * k[1] * k[1] + w[2] * k[2] * k[2] + w[3] * k[3] * k[3];
            let scale = -1.0 / (stiffness + per_area / self.inv_area[e]);
            for j in 0..4 {
                let dx = v * (w[j] * k[j] * scale);
                p.position[i[j]] += dx;
                p.velocity[i[j]] += dx * inv_h;
            }
        }
    }

    /// The bending energy for rigidity `b`, J.
    pub fn energy(&self, x: &[Vec3], b: f32) -> f32 {
        (0..self.len())
            .map(|h| 0.5 * b * self.inv_area[h] * self.curvature(h, x).length_squared())
            .sum()
    }

    /// The hinges' mean `B Σ w K² / (A0 + A1)` (`w` the inverse masses, pinned corners
    /// 0): how much a substep of one iteration softens them (`fabric_floor`), 0 without
    /// hinges.
    pub fn mean_load(&self, inv_mass: &[f32], b: f32) -> f32 {
        if self.len() == 0 {
            return 0.0;
        }
        let total: f64 = (0..self.len())
            .map(|e| {
                let (c, k) = (self.corners[e], self.weights[e]);
                let sum: f32 = (0..4).map(|j| inv_mass[c[j] as usize] * k[j] * k[j]).sum();
                f64::from(b * self.inv_area[e] * sum)
            })
            .sum();
        (total / self.len() as f64) as f32
    }

    /// Gershgorin's bound on each particle's row of the bending stiffness `B K Kᵀ/(A0+A1)`
    /// for `b = 1`, added into `rows` (for the explicit models' substeps).
    pub fn add_gershgorin_rows(&self, rows: &mut [f32]) {
        for h in 0..self.len() {
            let k = self.weights[h];
            let total: f32 = k.iter().map(|w| w.abs()).sum();
            for j in 0..4 {
                rows[self.corners[h][j] as usize] += self.inv_area[h] * k[j].abs() * total;
            }
        }
    }
}

/// `triangles` with every rectangle they make split along its other diagonal (two
/// triangles sharing their longest edge, whose far corners are as far apart as that
/// edge's ends, within 1%); the others as they are. `None` when there is no rectangle.
fn flipped(triangles: &[[u32; 3]], rest: &[Vec3]) -> Option<Vec<[u32; 3]>> {
    let x = |i: u32| rest[i as usize];
    // Each triangle's longest edge (low end, high end) and far corner.
    let mut longest: Vec<(u32, u32, u32, usize)> = triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| {
            let k = (0..3)
                .max_by(|&i, &j| {
                    let len = |k: usize| x(tri[k]).distance_squared(x(tri[(k + 1) % 3]));
                    len(i).total_cmp(&len(j))
                })
                .unwrap_or(0);
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            (a.min(b), a.max(b), tri[(k + 2) % 3], t)
        })
        .collect();
    longest.sort_unstable();
    let mut out = triangles.to_vec();
    let mut any = false;
    for pair in longest.windows(2) {
        let ((a, b, p, t), (a2, b2, q, u)) = (pair[0], pair[1]);
        if (a, b) != (a2, b2) {
            continue;
        }
        let (diagonal, other) = (x(a).distance(x(b)), x(p).distance(x(q)));
        if (diagonal - other).abs() > 0.01 * diagonal {
            continue;
        }
        out[t] = [p, q, a];
        out[u] = [q, p, b];
        any = true;
    }
    any.then_some(out)
}

/// Each particle's share of the triangles' rest area: a third of each triangle it is a
/// corner of, m².
pub(in crate::solver) fn particle_areas(triangles: &[[u32; 3]], rest: &[Vec3]) -> Vec<f32> {
    let mut area = vec![0.0f32; rest.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| rest[i as usize]);
        let third = (b - a).cross(c - a).length() / 6.0;
        for &i in t {
            area[i as usize] += third;
        }
    }
    area
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::topology::grid_triangles;

    /// A `w × h` grid of spacing `s` in the xy plane.
    fn grid(w: u32, h: u32, s: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let x = (0..h)
            .flat_map(|j| (0..w).map(move |i| Vec3::new(i as f32 * s, j as f32 * s, 0.0)))
            .collect();
        (x, grid_triangles(w, h))
    }

    /// The grid wrapped round a cylinder of curvature `kappa` about an axis along y
    /// (arc length along x kept: an isometric bend).
    fn wrapped(x: &[Vec3], kappa: f32) -> Vec<Vec3> {
        x.iter()
            .map(|p| {
                let a = p.x * kappa;
                Vec3::new(a.sin() / kappa, p.y, (1.0 - a.cos()) / kappa)
            })
            .collect()
    }

    /// The hinges of `t` as they are (one diagonal split), at full stiffness.
    fn one_split(t: &[[u32; 3]], x: &[Vec3]) -> Hinges {
        let mut hinges = Hinges::default();
        hinges.add_all(t, x, 1.0);
        hinges
    }

    #[test]
    fn a_flat_cloth_stores_nothing_however_it_moves() {
        let (x, t) = grid(9, 7, 0.1);
        let one = one_split(&t, &x);
        assert_eq!(one.len(), 3 * 8 * 6 - 8 - 6, "every inner edge is a hinge");
        let both = Hinges::new(&t, &x);
        assert_eq!(both.len(), 2 * one.len(), "both splits' inner edges");
        let moved: Vec<Vec3> = x
            .iter()
            .map(|&p| bevy::math::Quat::from_rotation_x(0.7) * (p * 1.3) + Vec3::ONE)
            .collect();
        for hinges in [one, both] {
            let e = hinges.energy(&moved, 1.0);
            assert!(
                e.abs() < 1e-9,
                "a flat cloth rotated and scaled stores {e} J"
            );
        }
    }

    #[test]
    fn a_cylinder_stores_half_b_kappa_squared() {
        // A 1 m × 0.5 m strip wrapped to curvature 2/m: the energy over ½ B κ² A is 1 less
        // the end columns' missing hinges (1/(w − 1) of the strip).
        let (w, s) = (81, 1.0 / 80.0);
        let (x, t) = grid(w, 41, s);
        let (b, kappa, area) = (2e-5, 2.0, 1.0 * 0.5);
        for grid in [false, true] {
            let hinges = if grid {
                Hinges::new(&t, &x)
            } else {
                one_split(&t, &x)
            };
            let e = hinges.energy(&wrapped(&x, kappa), b);
            let ratio = e / (0.5 * b * kappa * kappa * area);
            assert!(
                (ratio - (1.0 - 1.0 / (w - 1) as f32)).abs() < 0.01,
                "energy {ratio:.4} × ½Bκ²A ({grid:?})"
            );
        }
    }

    #[test]
    fn the_force_is_minus_the_energy_gradient() {
        let (x, t) = grid(5, 5, 0.1);
        let hinges = Hinges::new(&t, &x);
        let bent = wrapped(&x, 3.0);
        let mut p = Particles::with_len(x.len());
        p.position.clone_from(&bent);
        hinges.add_forces(&mut p, 1e-3);
        let (i, eps) = (12, 1e-3);
        for axis in 0..3 {
            let mut plus = bent.clone();
            let mut minus = bent.clone();
            plus[i][axis] += eps;
            minus[i][axis] -= eps;
            let slope = (hinges.energy(&plus, 1e-3) - hinges.energy(&minus, 1e-3)) / (2.0 * eps);
            let f = p.force[i][axis];
            assert!(
                (f + slope).abs() < 1e-3 * slope.abs().max(1e-4),
                "axis {axis}: force {f}, −dE/dx {}",
                -slope
            );
        }
    }

    #[test]
    fn areas_sum_to_the_cloth() {
        let (x, t) = grid(11, 6, 0.1);
        let total: f32 = particle_areas(&t, &x).iter().sum();
        assert!((total - 1.0 * 0.5).abs() < 1e-5, "{total}");
    }
}
