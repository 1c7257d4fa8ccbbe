//! Proxy meshes: a render mesh finer than the simulation, each of its vertices bound to
//! its nearest simulation triangle (by the barycentric coordinates of its projection onto
//! the triangle's plane, and its height along the triangle's normal), and moved with it
//! every frame: the skinning of a render mesh to a simulation mesh of NvCloth and Chaos
//! Cloth. Pure geometry: it reads positions and normals and writes positions, normals
//! and tangents.

use std::sync::Arc;

use bevy::math::{Vec3, Vec3A, Vec4};

use super::unit::{BATCH, all_scale, length_recips, scaled_or, squared_lengths};

mod nearest;

use nearest::{Buckets, usable};

/// One render vertex's place on the simulation mesh: 16 bytes, all that placing reads
/// of it (the vertices are the most numerous thing drawn, so their bytes are most of
/// what placing reads from memory).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Bound {
    /// Its triangle, in [`ProxyBinding::triangles`].
    triangle: u32,
    /// The barycentric weights of its projection on the triangle's plane of the second
    /// and third corners (the first's is one less both; outside `[0, 1]` for a vertex
    /// beyond the triangle's edge).
    weights: [f32; 2],
    /// Its height above the plane along the triangle's normal, m.
    height: f32,
}

/// A triangle as placing reads it this frame: its first corner and its two edges from
/// it, its unit normal, and its corners' normals the same way (the first, and the others
/// less it), so that a vertex on it is two multiply-adds from each. Worked out once a
/// frame for the four or so vertices on each triangle, in four-lane vectors (`Vec3A`):
/// a vertex's sums are then one vector instruction each, not three.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Face {
    origin: Vec3A,
    edges: [Vec3A; 2],
    normal: Vec3A,
    normals: [Vec3A; 3],
}

impl Face {
    /// The point at `weights` on the triangle, `height` along its normal.
    #[inline(always)]
    fn point(&self, [v, w]: [f32; 2], height: f32) -> Vec3A {
        self.origin + v * self.edges[0] + w * self.edges[1] + height * self.normal
    }

    /// The blend of its corners' normals at `weights`.
    #[inline(always)]
    fn blend(&self, [v, w]: [f32; 2]) -> Vec3A {
        self.normals[0] + v * self.normals[1] + w * self.normals[2]
    }
}

/// Every render vertex bound to a simulation triangle ([`ProxyBinding::bind`]), and
/// placed on it again ([`ProxyBinding::place`]).
///
/// Its clones share what binding worked out (each vertex's triangle, weights, height and
/// tangent), and each keeps its own last normals: cloths of one rest shape drawn through
/// one mesh, a crowd's capes, read it from memory once a frame, not once a cloth (shared
/// by the crowd's hundred cloths, placing took 8% less: 2.30 against 2.51 ms a frame on
/// one thread).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ProxyBinding {
    shared: Arc<Binding>,
    /// Each of its triangles' unit normal when last placed: a triangle of no area keeps
    /// it.
    last_normals: Vec<Vec3A>,
    /// And its first edge's direction and the direction across it, for the tangents.
    frames: Vec<(Vec3, Vec3)>,
}

/// What [`ProxyBinding::bind`] works out, which placing only reads.
#[derive(Debug, Default, PartialEq)]
struct Binding {
    bound: Vec<Bound>,
    /// Each vertex's tangent in its triangle's frame (along the first edge, across it,
    /// along the normal), and the bitangent's sign; none when bound without tangents.
    tangents: Vec<Vec4>,
    /// The triangles some vertex is bound to.
    triangles: Vec<[u32; 3]>,
}

/// The frame of triangle `t` of `x`: its first edge's direction, the direction across it
/// in the plane, and its unit normal (`None` for a triangle of no area).
#[inline]
fn frame(x: &[Vec3], [a, b, c]: [u32; 3]) -> Option<(Vec3, Vec3, Vec3)> {
    let (a, b, c) = (x[a as usize], x[b as usize], x[c as usize]);
    let normal = (b - a).cross(c - a).try_normalize()?;
    let along = (b - a).try_normalize()?;
    Some((along, normal.cross(along), normal))
}

/// The barycentric weights of `b` and `c` at `p`'s projection onto the plane of `a b c`,
/// and its height above that plane along `normal`.
fn project(p: Vec3, [a, b, c]: [Vec3; 3], normal: Vec3) -> ([f32; 2], f32) {
    let height = (p - a).dot(normal);
    let q = p - height * normal;
    let (e0, e1, e2) = (b - a, c - a, q - a);
    let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
    let (d20, d21) = (e2.dot(e0), e2.dot(e1));
    let denominator = d00 * d11 - d01 * d01;
    let v = (d11 * d20 - d01 * d21) / denominator;
    let w = (d00 * d21 - d01 * d20) / denominator;
    ([v, w], height)
}

impl ProxyBinding {
    /// Binds each of `render` (with its tangents, if any) to the triangle of `triangles`
    /// over `x` nearest it, all in one frame (the simulation's rest, or its positions
    /// when the render mesh is bound). Triangles of no area are passed over. `None` when
    /// there is no triangle to bind to.
    pub fn bind(
        x: &[Vec3],
        triangles: &[[u32; 3]],
        render: &[Vec3],
        tangents: Option<&[Vec4]>,
    ) -> Option<Self> {
        let usable = usable(x, triangles);
        if usable.is_empty() {
            return None;
        }
        let buckets = Buckets::new(&usable);
        let mut index_of = std::collections::HashMap::new();
        let mut used: Vec<[u32; 3]> = Vec::new();
        let mut turned = Vec::new();
        let mut bound = Vec::with_capacity(render.len());
        for (v, &p) in render.iter().enumerate() {
            let best = buckets.nearest(x, p);
            let (along, across, normal) = frame(x, best).expect("usable");
            let (weights, height) = project(p, best.map(|i| x[i as usize]), normal);
            if let Some(tangents) = tangents {
                turned.push(tangents.get(v).map_or(Vec4::ZERO, |t| {
                    let t3 = t.truncate();
                    Vec4::new(t3.dot(along), t3.dot(across), t3.dot(normal), t.w)
                }));
            }
            let triangle = *index_of.entry(best).or_insert_with(|| {
                used.push(best);
                used.len() as u32 - 1
            });
            bound.push(Bound {
                triangle,
                weights,
                height,
            });
        }
        Some(ProxyBinding {
            last_normals: vec![Vec3A::Z; used.len()],
            frames: vec![(Vec3::X, Vec3::Y); used.len()],
            shared: Arc::new(Binding {
                bound,
                tangents: turned,
                triangles: used,
            }),
        })
    }

    /// Whether it shares what binding worked out with `other` (one is a clone of the
    /// other, or of a third).
    pub fn shares_with(&self, other: &ProxyBinding) -> bool {
        Arc::ptr_eq(&self.shared, &other.shared)
    }

    /// How many bindings share what this one's binding worked out, itself included.
    pub(crate) fn sharers(&self) -> usize {
        Arc::strong_count(&self.shared)
    }

    /// How many render vertices it binds.
    pub fn len(&self) -> usize {
        self.shared.bound.len()
    }

    /// Whether it binds none.
    pub fn is_empty(&self) -> bool {
        self.shared.bound.is_empty()
    }

    /// Render vertex `v`'s place over `x`: its bound point on its triangle, at its height
    /// along the triangle's normal (what [`place`](Self::place) writes, to the bit).
    pub fn point(&self, x: &[Vec3], v: usize) -> Vec3 {
        let b = &self.shared.bound[v];
        let corner = |i: u32| [x[i as usize].into(), Vec3A::ZERO];
        let mut face = Face::of(self.shared.triangles[b.triangle as usize].map(corner));
        face.normal = face.normal.normalize_or(Vec3A::ZERO);
        face.point(b.weights, b.height).into()
    }

    /// Places every render vertex over the simulation's positions `x` (and its smooth
    /// vertex `normals`): each at its bound point at its height along its triangle's
    /// normal, its normal the blend of its corners' by its weights, its tangent turned
    /// with its triangle and made square to that normal. `tangents` is written only when
    /// given. Each triangle is worked out once (its first corner, edges, normal and
    /// corners' normals, in four-lane vectors), then the vertices a batch at a time.
    /// Triangles' and vertices' normals are made unit a batch at a time, their square
    /// roots and divisions side by side (one vertex after another waited on each one's
    /// in turn: they were two fifths of placing), and a batch whose blends all have a
    /// length is scaled without a test a vertex.
    pub fn place(
        &mut self,
        x: &[Vec3],
        normals: &[Vec3],
        positions: &mut [[f32; 3]],
        out_normals: &mut [[f32; 3]],
        tangents: Option<&mut [[f32; 4]]>,
    ) {
        SCRATCH.with_borrow_mut(|(faces, corners)| {
            // Each particle's position and normal in four-lane vectors once, where each
            // of its six or so triangles converted them again.
            corners.clear();
            let normals = normals
                .iter()
                .map(|&n| n.into())
                .chain(std::iter::repeat(Vec3A::ZERO));
            corners.extend(x.iter().zip(normals).map(|(&p, n)| [p.into(), n]));
            faces.clear();
            faces.extend(
                self.shared
                    .triangles
                    .iter()
                    .map(|t| Face::of(t.map(|i| corners[i as usize]))),
            );
            // Each face's normal made unit a batch at a time; a triangle of no area this
            // frame keeps its last normal (and frame).
            for (faces, last) in faces
                .chunks_mut(BATCH)
                .zip(self.last_normals.chunks_mut(BATCH))
            {
                let mut normals = [Vec3A::ZERO; BATCH];
                for (n, face) in normals.iter_mut().zip(faces.iter()) {
                    *n = face.normal;
                }
                let rcp = length_recips(squared_lengths(&normals));
                if all_scale(&rcp) {
                    for ((face, last), r) in faces.iter_mut().zip(last).zip(rcp) {
                        face.normal *= r;
                        *last = face.normal;
                    }
                } else {
                    for ((face, last), r) in faces.iter_mut().zip(last).zip(rcp) {
                        face.normal = scaled_or(face.normal, r, *last);
                        *last = face.normal;
                    }
                }
            }
            self.place_on(faces, x, positions, out_normals, tangents);
        });
    }

    /// [`Self::place`] over this frame's `faces` of its triangles.
    fn place_on(
        &mut self,
        faces: &[Face],
        x: &[Vec3],
        positions: &mut [[f32; 3]],
        out_normals: &mut [[f32; 3]],
        mut tangents: Option<&mut [[f32; 4]]>,
    ) {
        if tangents.is_some() {
            for (f, &t) in self.frames.iter_mut().zip(&self.shared.triangles) {
                *f = frame(x, t).map_or(*f, |(along, across, _)| (along, across));
            }
        }
        for (c, batch) in self.shared.bound.chunks(BATCH).enumerate() {
            let first = c * BATCH;
            let positions = &mut positions[first..first + batch.len()];
            let out_normals = &mut out_normals[first..first + batch.len()];
            let mut blend = [Vec3A::ZERO; BATCH];
            for ((b, out), blend) in batch.iter().zip(positions).zip(&mut blend) {
                let face = &faces[b.triangle as usize];
                *out = Vec3::from(face.point(b.weights, b.height)).to_array();
                *blend = face.blend(b.weights);
            }
            // The blends made unit in place: the drawn normals.
            let rcp = length_recips(squared_lengths(&blend));
            let scale = all_scale(&rcp);
            if scale && tangents.is_none() {
                // No tangents to make square to them: the unit normals are written only.
                for ((blend, out), r) in blend.iter().zip(out_normals).zip(rcp) {
                    *out = Vec3::from(*blend * r).to_array();
                }
            } else if scale {
                for ((smooth, out), r) in blend.iter_mut().zip(out_normals).zip(rcp) {
                    *smooth *= r;
                    *out = Vec3::from(*smooth).to_array();
                }
            } else {
                // A blend of no length (corners' normals that cancel) takes its
                // triangle's normal; so does the batch's tail past the last vertex.
                for (((b, smooth), out), r) in
                    batch.iter().zip(&mut blend).zip(out_normals).zip(rcp)
                {
                    *smooth = scaled_or(*smooth, r, faces[b.triangle as usize].normal);
                    *out = Vec3::from(*smooth).to_array();
                }
            }
            if let Some(tangents) = tangents.as_deref_mut() {
                let tangents = &mut tangents[first..first + batch.len()];
                self.turn_tangents(faces, (first, batch), &blend, tangents);
            }
        }
    }

    /// Writes the tangents of the `batch` of vertices from `first`, turned with their
    /// triangles and made square to their drawn normals `smooth` (Gram–Schmidt).
    #[inline(always)]
    fn turn_tangents(
        &self,
        faces: &[Face],
        (first, batch): (usize, &[Bound]),
        smooth: &[Vec3A; BATCH],
        out: &mut [[f32; 4]],
    ) {
        let tangent = |k: usize| {
            self.shared
                .tangents
                .get(first + k)
                .copied()
                .unwrap_or(Vec4::ZERO)
        };
        let mut square = [Vec3A::ZERO; BATCH];
        for (k, b) in batch.iter().enumerate() {
            let (along, across) = self.frames[b.triangle as usize];
            let (along, across) = (Vec3A::from(along), Vec3A::from(across));
            let normal = faces[b.triangle as usize].normal;
            let t = tangent(k);
            let turned = t.x * along + t.y * across + t.z * normal;
            square[k] = turned - turned.dot(smooth[k]) * smooth[k];
        }
        let rcp = length_recips(squared_lengths(&square));
        for (k, (b, out)) in batch.iter().zip(out).enumerate() {
            let along = self.frames[b.triangle as usize].0.into();
            *out = Vec3::from(scaled_or(square[k], rcp[k], along))
                .extend(tangent(k).w)
                .to_array();
        }
    }
}

impl Face {
    /// The triangle of three corners (each its position and normal), its `normal` not
    /// yet unit: the cross product of its edges, twice its area (made unit with the same
    /// bits as [`frame`]'s).
    #[inline(always)]
    fn of([[a, na], [b, nb], [c, nc]]: [[Vec3A; 2]; 3]) -> Face {
        let edges = [b - a, c - a];
        Face {
            origin: a,
            edges,
            normal: edges[0].cross(edges[1]),
            normals: [na, nb - na, nc - na],
        }
    }
}

thread_local! {
    /// This thread's faces of the binding it is placing ([`ProxyBinding::place`]) and its
    /// particles' positions and normals in four-lane vectors, worked out afresh each
    /// call: one buffer a thread, warm in its cache, where one a binding (112 bytes a
    /// triangle, 8 MB for the crowd's hundred cloths) was read back from memory every
    /// frame only to be overwritten.
    #[allow(clippy::type_complexity)]
    static SCRATCH: std::cell::RefCell<(Vec<Face>, Vec<[Vec3A; 2]>)> =
        const { std::cell::RefCell::new((Vec::new(), Vec::new())) };
}

#[cfg(test)]
mod tests {
    use super::nearest::nearest_squared;
    use super::*;

    /// A `w × h` sheet of 0.1 m cells, crumpled `bend` m out of its plane, and its
    /// triangles (two a cell).
    fn sheet(w: u32, h: u32, bend: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let x = (0..w * h)
            .map(|v| {
                let (i, j) = ((v % w) as f32, (v / w) as f32);
                Vec3::new(0.1 * i, 0.1 * j, bend * (1.7 * i).sin() * (0.9 * j).cos())
            })
            .collect();
        let mut triangles = Vec::new();
        for j in 0..h - 1 {
            for i in 0..w - 1 {
                let v = j * w + i;
                triangles.push([v, v + 1, v + w]);
                triangles.push([v + 1, v + w + 1, v + w]);
            }
        }
        (x, triangles)
    }

    /// A render vertex on, above and beyond a triangle is put back where it was over the
    /// rest it was bound on, and moves rigidly with the triangle.
    #[test]
    fn bound_vertices_follow_their_triangle() {
        let x = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
        let triangles = [[0, 1, 2], [1, 3, 2]];
        let render = [
            Vec3::new(0.2, 0.2, 0.0),
            Vec3::new(0.7, 0.6, 0.05),
            Vec3::new(1.1, 0.5, -0.02),
        ];
        let tangents = [Vec4::new(1.0, 0.0, 0.0, 1.0); 3];
        let mut binding = ProxyBinding::bind(&x, &triangles, &render, Some(&tangents)).unwrap();
        for (v, &p) in render.iter().enumerate() {
            assert!(binding.point(&x, v).distance(p) < 1e-6, "{v}");
        }
        let turn = bevy::math::Quat::from_rotation_x(0.7);
        let moved: Vec<Vec3> = x.iter().map(|&p| turn * p + Vec3::splat(2.0)).collect();
        let normals = vec![turn * Vec3::Z; 4];
        let (mut out, mut out_n, mut out_t) =
            (vec![[0.0; 3]; 3], vec![[0.0; 3]; 3], vec![[0.0; 4]; 3]);
        binding.place(&moved, &normals, &mut out, &mut out_n, Some(&mut out_t));
        for (v, &p) in render.iter().enumerate() {
            let want = turn * p + Vec3::splat(2.0);
            assert!(
                Vec3::from(out[v]).distance(want) < 1e-5,
                "{v}: {:?}",
                out[v]
            );
            assert!(Vec3::from(out_n[v]).distance(turn * Vec3::Z) < 1e-5);
            assert!(Vec3::from_slice(&out_t[v][..3]).distance(turn * Vec3::X) < 1e-5);
        }
    }

    /// 19 render vertices over the first cells of a 5 × 4 [`sheet`] (the first two over
    /// its first corner) and their tangents (every third of no length: the first edge
    /// stands in).
    fn scattered_vertices() -> (Vec<Vec3>, Vec<Vec4>) {
        let render = (0..19)
            .map(|k| match k {
                0 => Vec3::new(0.02, 0.03, 0.0),
                1 => Vec3::new(0.03, 0.02, 0.01),
                _ => {
                    let f = k as f32;
                    Vec3::new(
                        0.02 * f,
                        0.3 * (0.37 * f).sin().abs(),
                        0.01 * (1.3 * f).cos(),
                    )
                }
            })
            .collect();
        let tangents = (0..19)
            .map(|k| match k % 3 {
                0 => Vec4::new(1.0, 0.0, 0.0, 1.0),
                1 => Vec4::new(0.0, 0.0, 0.0, -1.0),
                _ => Vec4::new(0.6, 0.8, 0.1, 1.0),
            })
            .collect();
        (render, tangents)
    }

    /// Placing a batch at a time gives each vertex the same bits as placing it alone with
    /// glam's `normalize_or`: on a crumpled sheet, for a count of vertices that is not a
    /// whole number of batches, with some corners' normals of no length (the triangle's
    /// normal stands in) and a tangent of no length (the first edge stands in).
    #[test]
    fn placing_in_batches_is_placing_one_by_one() {
        let (w, h) = (5u32, 4u32);
        let (rest, triangles) = sheet(w, h, 0.0);
        let (render, tangents) = scattered_vertices();
        let mut binding = ProxyBinding::bind(&rest, &triangles, &render, Some(&tangents)).unwrap();
        let x = sheet(w, h, 0.04).0;
        let normals: Vec<Vec3> = (0..w * h)
            .map(|v| match (v % w, v / w) {
                (0..2, 0..2) => Vec3::ZERO,
                (i, j) => Vec3::new(0.1 * i as f32, -0.2 * j as f32, 1.0),
            })
            .collect();
        let (mut out, mut out_n, mut out_t) =
            (vec![[0.0; 3]; 19], vec![[0.0; 3]; 19], vec![[0.0; 4]; 19]);
        binding.place(&x, &normals, &mut out, &mut out_n, Some(&mut out_t));
        for (v, b) in binding.shared.bound.iter().enumerate() {
            let corners = binding.shared.triangles[b.triangle as usize];
            let (along, across, normal) = frame(&x, corners).unwrap();
            let [i, j, k] = corners.map(|i| i as usize);
            let [p, q] = b.weights;
            let on = x[i] + p * (x[j] - x[i]) + q * (x[k] - x[i]);
            let blend = normals[i] + p * (normals[j] - normals[i]) + q * (normals[k] - normals[i]);
            let smooth = blend.normalize_or(normal);
            let t = binding.shared.tangents[v];
            let turned = t.x * along + t.y * across + t.z * normal;
            let tangent = (turned - turned.dot(smooth) * smooth).normalize_or(along);
            assert_eq!(out[v], (on + b.height * normal).to_array(), "{v}");
            assert_eq!(out_n[v], smooth.to_array(), "{v}");
            assert_eq!(out_t[v], tangent.extend(t.w).to_array(), "{v}");
        }
        // Without tangents (the unit normals written, not kept): the same bits.
        let (mut bare, mut bare_n) = (vec![[0.0; 3]; 19], vec![[0.0; 3]; 19]);
        binding.place(&x, &normals, &mut bare, &mut bare_n, None);
        assert_eq!((bare, bare_n), (out.clone(), out_n.clone()));
        // Both stand-ins were taken for the second vertex: its corners' normals and its
        // tangent have no length.
        let corners = binding.shared.triangles[binding.shared.bound[1].triangle as usize];
        let (along, _, normal) = frame(&x, corners).unwrap();
        assert_eq!(out_n[1], normal.to_array());
        assert_eq!(Vec3::from_slice(&out_t[1][..3]), along);
    }

    /// A triangle pressed flat keeps the normal it had when last placed, and its vertices
    /// stand off it along that normal; the triangles made unit in its batch, and in the
    /// whole batches beside it, get their own normals (the bits of [`frame`]'s).
    #[test]
    fn a_flattened_triangle_keeps_its_last_normal() {
        let (w, h) = (5u32, 4u32);
        let (rest, triangles) = sheet(w, h, 0.02);
        // A vertex above each triangle's centre: 24 triangles in use, three batches.
        let render: Vec<Vec3> = triangles
            .iter()
            .map(|t| t.iter().map(|&i| rest[i as usize]).sum::<Vec3>() / 3.0 + 0.01 * Vec3::Z)
            .collect();
        let mut binding = ProxyBinding::bind(&rest, &triangles, &render, None).unwrap();
        assert_eq!(binding.shared.triangles.len(), 24);
        let n = render.len();
        let (mut out, mut out_n) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
        let normals = vec![Vec3::Z; rest.len()];
        binding.place(&rest, &normals, &mut out, &mut out_n, None);
        // Corners 7, 8 and 13 pressed to one point: the triangles with two or three of
        // them have no area.
        let mut x = sheet(w, h, 0.05).0;
        let p = Vec3::new(0.25, 0.15, 0.03);
        for i in [7, 8, 13] {
            x[i] = p;
        }
        binding.place(&x, &normals, &mut out, &mut out_n, None);
        let mut flat = 0;
        for (v, b) in binding.shared.bound.iter().enumerate() {
            let corners = binding.shared.triangles[b.triangle as usize];
            let normal = match frame(&x, corners) {
                Some((_, _, normal)) => normal,
                None => {
                    flat += 1;
                    frame(&rest, corners).unwrap().2
                }
            };
            let [i, j, k] = corners.map(|i| x[i as usize]);
            let [s, t] = b.weights;
            let on = i + s * (j - i) + t * (k - i);
            assert_eq!(out[v], (on + b.height * normal).to_array(), "{v}");
        }
        assert!(flat >= 2, "{flat} flattened");
    }

    /// The search ring by ring through the cells finds the triangle a search over every
    /// triangle finds (of those equally near, the first): for points on a crumpled sheet's
    /// corners and edges (where two or more triangles are equally near), above it,
    /// beside it and far off it.
    #[test]
    fn the_bucketed_search_finds_the_nearest_triangle() {
        let (x, triangles) = sheet(13, 9, 0.03);
        let usable = usable(&x, &triangles);
        assert_eq!(usable.len(), triangles.len());
        let buckets = Buckets::new(&usable);
        let every = |p: Vec3| {
            let d2 = |t: [u32; 3]| nearest_squared(p, t.map(|i| x[i as usize]));
            usable
                .iter()
                .map(|u| u.0)
                .reduce(|best, t| if d2(t) < d2(best) { t } else { best })
                .unwrap()
        };
        let mut points: Vec<Vec3> = x.clone();
        points.extend(x.windows(2).map(|p| (p[0] + p[1]) * 0.5));
        for k in 0..400 {
            let f = k as f32;
            let spread = if k % 4 == 0 { 8.0 } else { 1.5 };
            points.push(Vec3::new(
                spread * ((0.37 * f).sin() * 0.5 + 0.3),
                spread * ((0.71 * f).cos() * 0.5 + 0.3),
                0.2 * spread * (1.3 * f).sin(),
            ));
        }
        for p in points {
            assert_eq!(buckets.nearest(&x, p), every(p), "{p}");
        }
    }
}
