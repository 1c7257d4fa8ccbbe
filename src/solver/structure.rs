//! What a cloth is made of: its rest shape, springs, faces and pieces, and what tearing
//! has done to them. Built once from a [`Layout`]; only tears change it (and sewing, the
//! seams' rest lengths).

use std::ops::Range;

use bevy::math::Vec3;

use super::bending::{Hinges, particle_areas};
use super::lattice::{Rows, Stencil};
use super::layout::Layout;
use super::topology::{self, SpringKind, Springs, VertexFaces};

/// A cloth's make-up (see the module doc).
#[derive(Clone, Debug)]
pub(super) struct Structure {
    pub springs: Springs,
    /// Particle positions in the cloth's own frame before any motion (for reset, pins).
    pub local_rest: Vec<Vec3>,
    pub grid: Option<(u32, u32)>,
    pub triangles: Vec<[u32; 3]>,
    pub triangle_springs: Vec<[u32; 3]>,
    pub spring_triangles: Vec<Vec<u32>>,
    pub triangle_visible: Vec<bool>,
    /// Each particle's triangles in increasing order, for normals gathered per particle.
    pub vertex_faces: VertexFaces,
    pub faces_changed: bool,
    /// Names and particle ranges of garment pieces (one range for other cloths).
    pub pieces: Vec<(String, Range<u32>)>,
    /// Named runs of particles (a garment's `runs`).
    pub runs: Vec<(String, Vec<u32>)>,
    /// The length each seam spring starts at, before sewing.
    pub seam_start: Vec<f32>,
    /// A grid cloth's springs as stencil offsets (`lattice.rs`); `None` for meshes and
    /// garments.
    pub stencil: Option<Stencil>,
    /// A mesh in rows (a skirt: a grid wrapped round), its springs' forces on a stencil
    /// (`lattice.rs`); `None` for grids, garments and other meshes.
    pub rows: Option<Rows>,
    /// The cloth's characteristic length L (mean structural rest length), for the
    /// shape-matching force law.
    pub length_scale: f32,
    /// The longest rest length of a structural or shear spring: an edge of the cloth, what
    /// a collider must be thinner than to need the edge pass (rest lengths of these
    /// springs do not change after the build).
    pub longest_edge: f32,
    pub torn_this_step: Vec<u32>,
    pub torn_count: usize,
    /// The quadratic bending model's hinges (`bending.rs`): built once a fabric is set
    /// ([`Structure::build_hinges`]), empty until then.
    pub hinges: Hinges,
    /// Each particle's share of the triangles' rest area, m² (a fabric's masses).
    pub area: Vec<f32>,
}

impl Structure {
    /// Particle `i`'s normal, unnormalised: the sum of its visible triangles' area
    /// vectors (twice their areas) at positions `x`, in increasing triangle order; zero
    /// for a particle on no visible triangle.
    pub fn normal_sum(&self, x: &[Vec3], i: usize) -> Vec3 {
        let mut sum = Vec3::ZERO;
        for &t in self.vertex_faces.of(i) {
            if self.triangle_visible[t as usize] {
                let [a, b, c] = self.triangles[t as usize].map(|v| v as usize);
                sum += (x[b] - x[a]).cross(x[c] - x[a]);
            }
        }
        sum
    }

    /// Every particle's [`normal_sum`](Self::normal_sum) into `out` (one entry a
    /// particle), each triangle's area vector worked out once and added to its corners
    /// in increasing triangle order: the same bits as gathering them particle by
    /// particle, at a third of the cross products.
    pub fn normal_sums_into(&self, x: &[Vec3], out: &mut [Vec3]) {
        out.fill(Vec3::ZERO);
        for (t, &[a, b, c]) in self.triangles.iter().enumerate() {
            if self.triangle_visible[t] {
                let [a, b, c] = [a, b, c].map(|v| v as usize);
                let area = (x[b] - x[a]).cross(x[c] - x[a]);
                out[a] += area;
                out[b] += area;
                out[c] += area;
            }
        }
    }

    /// The make-up of a validated layout.
    pub fn new(layout: Layout) -> Self {
        let Layout {
            positions: local,
            springs: pairs,
            triangles,
            grid,
            pieces,
            runs,
        } = layout;
        let n = local.len();
        let springs = Springs::from_pairs(pairs, &local);
        let stencil = grid.and_then(|(w, _)| Stencil::new(&springs, w as usize, n));
        let sewn = !springs.ranges[SpringKind::Seam as usize].is_empty();
        let rows = (grid.is_none() && !sewn)
            .then(|| Rows::find(&springs, n))
            .flatten();
        let (triangle_springs, spring_triangles) =
            topology::triangle_edge_springs(&triangles, &springs);
        let seams = springs.ranges[SpringKind::Seam as usize].clone();
        let seam_start = springs.rest_length[seams].to_vec();
        let structural = springs.ranges[SpringKind::Structural as usize].clone();
        let length_scale = if structural.is_empty() {
            1.0
        } else {
            springs.rest_length[structural.clone()].iter().sum::<f32>() / structural.len() as f32
        };
        let longest_edge = super::contact::EDGES
            .iter()
            .flat_map(|&kind| springs.rest_length[springs.ranges[kind as usize].clone()].iter())
            .fold(0.0f32, |m, &l| m.max(l));
        Structure {
            hinges: Hinges::default(),
            area: particle_areas(&triangles, &local),
            torn_this_step: Vec::with_capacity(springs.len()),
            springs,
            local_rest: local,
            grid,
            triangle_visible: vec![true; triangles.len()],
            vertex_faces: VertexFaces::new(&triangles, n),
            triangles,
            triangle_springs,
            spring_triangles,
            faces_changed: true,
            pieces: if pieces.is_empty() {
                vec![(String::from("cloth"), 0..n as u32)]
            } else {
                pieces
            },
            runs,
            seam_start,
            stencil,
            rows,
            length_scale,
            longest_edge,
            torn_count: 0,
        }
    }

    /// Builds the hinges if they are not yet (a cloth without a fabric never pays for
    /// them: about 6 a particle, sorted twice).
    pub fn build_hinges(&mut self) {
        if self.hinges.len() == 0 && !self.triangles.is_empty() {
            self.hinges = Hinges::new(&self.triangles, &self.local_rest);
        }
    }

    /// Every spring whole and every face shown again.
    pub fn mend(&mut self) {
        self.springs.alive.fill(true);
        self.sync_stencil();
        self.triangle_visible.fill(true);
        self.faces_changed = true;
        self.torn_count = 0;
        self.torn_this_step.clear();
    }

    /// Tears spring `k` (in the stencil too) and hides the faces it borders.
    pub fn tear(&mut self, k: usize) {
        self.springs.alive[k] = false;
        for stencil in stencils(&mut self.stencil, &mut self.rows) {
            stencil.tear(k);
        }
        for &t in &self.spring_triangles[k] {
            self.triangle_visible[t as usize] = false;
        }
        self.faces_changed = true;
    }

    /// Seam-free springs stretched past `ratio` times their rest length at `x` tear (Sladović
    /// 2014 §3.2); they are this step's torn springs. Seams are sewn to a rest length of 0
    /// and do not tear.
    pub fn tear_overstretched(&mut self, x: &[Vec3], ratio: f32) {
        for k in 0..self.springs.ranges[SpringKind::Seam as usize].start {
            let s = &self.springs;
            if s.alive[k]
                && x[s.a[k] as usize].distance_squared(x[s.b[k] as usize])
                    > (ratio * s.rest_length[k]).powi(2)
            {
                self.tear(k);
                self.torn_this_step.push(k as u32);
            }
        }
        self.torn_count += self.torn_this_step.len();
    }

    /// Mirrors the springs' rest lengths, factors and alive flags into the stencil.
    pub fn sync_stencil(&mut self) {
        for stencil in stencils(&mut self.stencil, &mut self.rows) {
            stencil.sync(&self.springs);
        }
    }
}

/// A grid's stencil or a mesh's rows' (at most one is there).
fn stencils<'a>(
    grid: &'a mut Option<Stencil>,
    rows: &'a mut Option<Rows>,
) -> impl Iterator<Item = &'a mut Stencil> {
    grid.iter_mut().chain(rows.as_mut().map(|r| &mut r.stencil))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::shape::ClothShape;

    /// Scattering each triangle onto its corners gives every particle the bits gathering
    /// its own triangles does, on a crumpled grid with torn (hidden) triangles.
    #[test]
    fn scattered_normal_sums_are_the_gathered_ones() {
        let shape = ClothShape::Grid {
            width: 7,
            height: 5,
            spacing: 0.1,
        };
        let mut structure = Structure::new(shape.layout().unwrap());
        for k in [3, 17, 40] {
            structure.tear(k);
        }
        assert!(structure.triangle_visible.iter().any(|v| !v));
        let x: Vec<Vec3> = structure
            .local_rest
            .iter()
            .enumerate()
            .map(|(i, p)| *p + Vec3::new(0.0, 0.0, 0.03 * (1.3 * i as f32).sin()))
            .collect();
        let mut scattered = vec![Vec3::NAN; x.len()];
        structure.normal_sums_into(&x, &mut scattered);
        for (i, s) in scattered.iter().enumerate() {
            assert_eq!(*s, structure.normal_sum(&x, i), "{i}");
        }
    }
}
