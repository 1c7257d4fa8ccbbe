//! Springs and triangles: who is connected to whom, built once per cloth.

use std::collections::HashMap;
use std::ops::Range;

use bevy::math::Vec3;

/// The kind of a spring, which decides its stiffness (Sladović 2014 §2.2, fig. 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SpringKind {
    /// Horizontal and vertical neighbours: resist stretch and compression.
    Structural = 0,
    /// Diagonal neighbours: resist shear.
    Shear = 1,
    /// Every second particle along rows and columns: resist bending.
    Bend = 2,
    /// Every second particle along diagonals: optional extra bending resistance.
    BendDiagonal = 3,
    /// Joins two garment pieces along a seam (Maslova §1.4); rest length from the
    /// parameters, reached by sewing.
    Seam = 4,
}

impl SpringKind {
    /// All kinds, in storage order.
    pub const ALL: [SpringKind; 5] = [
        SpringKind::Structural,
        SpringKind::Shear,
        SpringKind::Bend,
        SpringKind::BendDiagonal,
        SpringKind::Seam,
    ];
}

/// Springs as structure-of-arrays, sorted by kind so each kind is one contiguous range.
#[derive(Clone, Debug, Default)]
pub struct Springs {
    /// First particle of each spring.
    pub a: Vec<u32>,
    /// Second particle of each spring.
    pub b: Vec<u32>,
    /// Rest length `l0` of each spring, from the initial layout.
    pub rest_length: Vec<f32>,
    /// False once a spring has torn.
    pub alive: Vec<bool>,
    /// Factor on the family's stiffness for each spring; `None`: 1 for every spring (a
    /// particle cloth). The patch model's part lattice scales its springs by the parts'
    /// aspect ratio.
    pub stiffness_scale: Option<Vec<f32>>,
    /// The index range of each kind, in `SpringKind` order.
    pub ranges: [Range<usize>; 5],
}

impl Springs {
    /// Number of springs, torn ones included.
    pub fn len(&self) -> usize {
        self.a.len()
    }

    /// True when there are no springs.
    pub fn is_empty(&self) -> bool {
        self.a.is_empty()
    }

    /// Whether a whole spring of `kind` with a free end (by `inv_mass`) may be longer than
    /// `max_stretch` times its rest length at `x`: what a strain limit's projection would
    /// move. Squared lengths against a bound a few float steps below the square of the
    /// projection's own (`len > max_stretch · l0`), so every spring the projection would
    /// move is seen; a spring within those steps of its limit is only a sweep that moves
    /// nothing. One pass without branches, so the loop stays cheap (a sixteenth of a step).
    pub(in crate::solver) fn any_longer_than(
        &self,
        kind: SpringKind,
        x: &[Vec3],
        inv_mass: &[f32],
        max_stretch: f32,
    ) -> bool {
        let range = self.ranges[kind as usize].clone();
        let (a, b) = (&self.a[range.clone()], &self.b[range.clone()]);
        let (rest, alive) = (&self.rest_length[range.clone()], &self.alive[range]);
        let bound = squared_bound(max_stretch);
        let mut past = false;
        for (((&a, &b), &rest), &alive) in a.iter().zip(b).zip(rest).zip(alive) {
            let (a, b) = (a as usize, b as usize);
            let free = inv_mass[a] + inv_mass[b] > 0.0;
            past |= alive & free & (x[a].distance_squared(x[b]) > bound * rest * rest);
        }
        past
    }

    /// The factor on spring `s`'s family stiffness (see `stiffness_scale`).
    #[inline]
    pub fn scale(&self, s: usize) -> f32 {
        self.stiffness_scale.as_ref().map_or(1.0, |f| f[s])
    }

    /// The kind of spring `s`.
    pub fn kind(&self, s: usize) -> SpringKind {
        SpringKind::ALL
            .into_iter()
            .find(|k| self.ranges[*k as usize].contains(&s))
            .unwrap_or(SpringKind::Structural)
    }

    /// Builds from unsorted `(kind, a, b)` triples with rest lengths from `positions`.
    /// Duplicate pairs (in either order) of the same kind are kept once.
    pub fn from_pairs(mut pairs: Vec<(SpringKind, u32, u32)>, positions: &[Vec3]) -> Self {
        for p in &mut pairs {
            if p.1 > p.2 {
                std::mem::swap(&mut p.1, &mut p.2);
            }
        }
        pairs.sort_by_key(|&(k, a, b)| (k as u8, a, b));
        pairs.dedup();
        let mut springs = Springs::default();
        for kind in SpringKind::ALL {
            let start = springs.a.len();
            for &(_, a, b) in pairs.iter().filter(|p| p.0 == kind) {
                springs.a.push(a);
                springs.b.push(b);
                springs
                    .rest_length
                    .push(positions[a as usize].distance(positions[b as usize]));
                springs.alive.push(true);
            }
            springs.ranges[kind as usize] = start..springs.a.len();
        }
        springs
    }
}

/// Spring pairs of a `width × height` grid, as in Sladović 2014 §3.2's pseudocode, plus the
/// optional diagonal bend springs. Particle `(i, j)` has index `j·width + i`.
pub fn grid_spring_pairs(width: u32, height: u32) -> Vec<(SpringKind, u32, u32)> {
    let idx = |i: u32, j: u32| j * width + i;
    let mut pairs = Vec::new();
    for j in 0..height {
        for i in 0..width {
            let p = idx(i, j);
            // Neighbours one apart: structural along the rows and columns, shear across;
            // two apart: bend, and the optional diagonal bend.
            for (along, across, d) in [
                (SpringKind::Structural, SpringKind::Shear, 1),
                (SpringKind::Bend, SpringKind::BendDiagonal, 2),
            ] {
                if i + d < width {
                    pairs.push((along, p, idx(i + d, j)));
                }
                if j + d < height {
                    pairs.push((along, p, idx(i, j + d)));
                }
                if i + d < width && j + d < height {
                    pairs.push((across, p, idx(i + d, j + d)));
                    pairs.push((across, idx(i + d, j), idx(i, j + d)));
                }
            }
        }
    }
    pairs
}

/// Two triangles per grid quad, counter-clockwise seen from +z (the cloth's front), split
/// along the quad's anti-diagonal.
pub fn grid_triangles(width: u32, height: u32) -> Vec<[u32; 3]> {
    let idx = |i: u32, j: u32| j * width + i;
    let mut triangles = Vec::with_capacity(2 * (width as usize - 1) * (height as usize - 1));
    for j in 0..height - 1 {
        for i in 0..width - 1 {
            let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i, j + 1), idx(i + 1, j + 1));
            triangles.push([a, c, b]);
            triangles.push([b, c, d]);
        }
    }
    triangles
}

/// Spring pairs of a triangle mesh: every edge is a structural spring; for every edge
/// shared by two triangles, their two far corners are joined by a bend spring.
pub fn mesh_spring_pairs(triangles: &[[u32; 3]]) -> Vec<(SpringKind, u32, u32)> {
    let mut opposite: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for t in triangles {
        for e in 0..3 {
            let (a, b, c) = (t[e], t[(e + 1) % 3], t[(e + 2) % 3]);
            opposite.entry((a.min(b), a.max(b))).or_default().push(c);
        }
    }
    let mut pairs = Vec::with_capacity(opposite.len() * 2);
    for (&(a, b), far) in &opposite {
        pairs.push((SpringKind::Structural, a, b));
        if let [c, d] = far[..]
            && c != d
        {
            pairs.push((SpringKind::Bend, c, d));
        }
    }
    pairs
}

/// For each triangle, the springs along its three edges (`u32::MAX` where an edge has no
/// spring), and for each spring the triangles that use it as an edge. A torn spring hides
/// the triangles it borders, so the cloth visibly splits.
pub fn triangle_edge_springs(
    triangles: &[[u32; 3]],
    springs: &Springs,
) -> (Vec<[u32; 3]>, Vec<Vec<u32>>) {
    let mut by_pair: HashMap<(u32, u32), u32> = HashMap::with_capacity(springs.len());
    // Prefer the structural or shear spring of an edge (they come first in storage).
    for s in (0..springs.len()).rev() {
        by_pair.insert((springs.a[s], springs.b[s]), s as u32);
    }
    let mut spring_triangles = vec![Vec::new(); springs.len()];
    let edges = triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| {
            let mut e = [u32::MAX; 3];
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if let Some(&s) = by_pair.get(&(a.min(b), a.max(b))) {
                    e[k] = s;
                    spring_triangles[s as usize].push(t as u32);
                }
            }
            e
        })
        .collect();
    (edges, spring_triangles)
}

/// Vertices welded into particles: vertices closer than a millionth of the mesh's size
/// become one (a non-indexed mesh repeats each shared corner; a mesh split along UV seams
/// repeats the seam's vertices). The first vertex of each group is kept, in order.
#[derive(Clone, Debug, PartialEq)]
pub struct Welded {
    /// One position per particle.
    pub positions: Vec<Vec3>,
    /// For each input vertex, its particle.
    pub particle_of: Vec<u32>,
}

/// Welds coincident vertices (see [`Welded`]); positions must be finite.
pub fn weld(positions: &[Vec3]) -> Welded {
    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let tolerance = ((hi - lo).length() * 1e-6).max(f32::MIN_POSITIVE);
    let cell = |p: Vec3| (p / tolerance).floor().as_ivec3();
    let mut grid: HashMap<bevy::math::IVec3, Vec<u32>> = HashMap::new();
    let mut welded = Welded {
        positions: Vec::with_capacity(positions.len()),
        particle_of: Vec::with_capacity(positions.len()),
    };
    for &p in positions {
        let c = cell(p);
        let mut found = None;
        'search: for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let near = grid.get(&(c + bevy::math::IVec3::new(dx, dy, dz)));
                    for &k in near.into_iter().flatten() {
                        if welded.positions[k as usize].distance(p) <= tolerance {
                            found = Some(k);
                            break 'search;
                        }
                    }
                }
            }
        }
        let k = found.unwrap_or_else(|| {
            let k = welded.positions.len() as u32;
            welded.positions.push(p);
            grid.entry(c).or_default().push(k);
            k
        });
        welded.particle_of.push(k);
    }
    welded
}

/// Each particle's triangles, in increasing order: `faces[start[i]..start[i + 1]]`.
#[derive(Clone, Debug, Default)]
pub(super) struct VertexFaces {
    start: Vec<u32>,
    faces: Vec<u32>,
}

impl VertexFaces {
    /// The triangles of each of `n` particles.
    pub fn new(triangles: &[[u32; 3]], n: usize) -> Self {
        let mut start = vec![0u32; n + 1];
        for tri in triangles {
            for &v in tri {
                start[v as usize + 1] += 1;
            }
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut next = start.clone();
        let mut faces = vec![0u32; start[n] as usize];
        for (t, tri) in triangles.iter().enumerate() {
            for &v in tri {
                faces[next[v as usize] as usize] = t as u32;
                next[v as usize] += 1;
            }
        }
        Self { start, faces }
    }

    /// The triangles of particle `i`.
    #[inline]
    pub fn of(&self, i: usize) -> &[u32] {
        &self.faces[self.start[i] as usize..self.start[i + 1] as usize]
    }
}

/// What [`Springs::any_longer_than`] holds a spring's squared length against, over its
/// squared rest length: a few float steps below `max_stretch²`, so every spring a strain
/// limit's projection (`len > max_stretch · l0`) would move is seen.
pub(in crate::solver) fn squared_bound(max_stretch: f32) -> f32 {
    max_stretch * max_stretch * (1.0 - 1e-5)
}
