//! Proxy meshes: a render mesh finer than the simulation, each of its vertices bound to
//! its nearest simulation triangle (by the barycentric coordinates of its projection onto
//! the triangle's plane, and its height along the triangle's normal), and moved with it
//! every frame: the skinning of a render mesh to a simulation mesh of NvCloth and Chaos
//! Cloth. Pure geometry: it reads positions and normals and writes positions, normals
//! and tangents.

use bevy::math::{Vec3, Vec4};

/// One render vertex's place on the simulation mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Bound {
    /// Its triangle, in [`ProxyBinding::triangles`].
    triangle: u32,
    /// The triangle's corners.
    corners: [u32; 3],
    /// The barycentric weights of the vertex's projection on the triangle's plane (they
    /// sum to 1; outside `[0, 1]` for a vertex beyond the triangle's edge).
    weights: [f32; 3],
    /// Its height above the plane along the triangle's normal, m.
    height: f32,
    /// Its tangent in the triangle's frame (along the first edge, across it, along the
    /// normal), and the bitangent's sign.
    tangent: Vec4,
}

/// Every render vertex bound to a simulation triangle ([`ProxyBinding::bind`]), and
/// placed on it again ([`ProxyBinding::place`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ProxyBinding {
    bound: Vec<Bound>,
    /// The triangles some vertex is bound to.
    triangles: Vec<[u32; 3]>,
    /// Each of those triangles' frame this frame (scratch of [`ProxyBinding::place`]).
    frames: Vec<(Vec3, Vec3, Vec3)>,
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

/// The barycentric weights of `p`'s projection onto the plane of `a b c`, and its height
/// above that plane along `normal`.
fn project(p: Vec3, [a, b, c]: [Vec3; 3], normal: Vec3) -> ([f32; 3], f32) {
    let height = (p - a).dot(normal);
    let q = p - height * normal;
    let (e0, e1, e2) = (b - a, c - a, q - a);
    let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
    let (d20, d21) = (e2.dot(e0), e2.dot(e1));
    let denominator = d00 * d11 - d01 * d01;
    let v = (d11 * d20 - d01 * d21) / denominator;
    let w = (d00 * d21 - d01 * d20) / denominator;
    ([1.0 - v - w, v, w], height)
}

/// The point of triangle `a b c` nearest `p` (Ericson 2005, "Real-Time Collision
/// Detection", §5.1.5), as its squared distance from `p`.
fn nearest_squared(p: Vec3, [a, b, c]: [Vec3; 3]) -> f32 {
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

/// The triangle of `usable` (corners, centre, reach) over `x` nearest `p`; those whose
/// sphere is farther than the nearest so far are passed over.
fn nearest_triangle(x: &[Vec3], usable: &[([u32; 3], Vec3, f32)], p: Vec3) -> [u32; 3] {
    let (mut best, mut best_d2) = (usable[0].0, f32::INFINITY);
    for &(t, centre, reach) in usable {
        let far = p.distance(centre) - reach;
        if far > 0.0 && far * far >= best_d2 {
            continue;
        }
        let d2 = nearest_squared(p, t.map(|i| x[i as usize]));
        if d2 < best_d2 {
            (best, best_d2) = (t, d2);
        }
    }
    best
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
        // Each usable triangle's corners, centre and reach, for a quick rejection.
        let usable: Vec<([u32; 3], Vec3, f32)> = triangles
            .iter()
            .filter(|&&t| frame(x, t).is_some())
            .map(|&t| {
                let p = t.map(|i| x[i as usize]);
                let centre = (p[0] + p[1] + p[2]) / 3.0;
                let reach = p.iter().map(|q| q.distance(centre)).fold(0.0, f32::max);
                (t, centre, reach)
            })
            .collect();
        if usable.is_empty() {
            return None;
        }
        let mut index_of = std::collections::HashMap::new();
        let mut used: Vec<[u32; 3]> = Vec::new();
        let bound = render
            .iter()
            .enumerate()
            .map(|(v, &p)| {
                let best = nearest_triangle(x, &usable, p);
                let (along, across, normal) = frame(x, best).expect("usable");
                let (weights, height) = project(p, best.map(|i| x[i as usize]), normal);
                let tangent = tangents.and_then(|t| t.get(v)).map_or(Vec4::ZERO, |t| {
                    let t3 = t.truncate();
                    Vec4::new(t3.dot(along), t3.dot(across), t3.dot(normal), t.w)
                });
                let triangle = *index_of.entry(best).or_insert_with(|| {
                    used.push(best);
                    used.len() as u32 - 1
                });
                Bound {
                    triangle,
                    corners: best,
                    weights,
                    height,
                    tangent,
                }
            })
            .collect();
        let frames = vec![(Vec3::X, Vec3::Y, Vec3::Z); used.len()];
        Some(ProxyBinding {
            bound,
            triangles: used,
            frames,
        })
    }

    /// How many render vertices it binds.
    pub fn len(&self) -> usize {
        self.bound.len()
    }

    /// Whether it binds none.
    pub fn is_empty(&self) -> bool {
        self.bound.is_empty()
    }

    /// Render vertex `v`'s place over `x`: its bound point on its triangle, at its height
    /// along the triangle's normal (what [`place`](Self::place) writes).
    pub fn point(&self, x: &[Vec3], v: usize) -> Vec3 {
        let b = &self.bound[v];
        let p = b.corners.map(|i| x[i as usize]);
        let on = b.weights[0] * p[0] + b.weights[1] * p[1] + b.weights[2] * p[2];
        let normal = frame(x, b.corners).map_or(Vec3::ZERO, |(_, _, n)| n);
        on + b.height * normal
    }

    /// Places every render vertex over the simulation's positions `x` (and its smooth
    /// vertex `normals`): each at its bound point at its height along its triangle's
    /// normal, its normal the blend of its corners' by its weights, its tangent turned
    /// with its triangle and made square to that normal. `tangents` is written only when
    /// given. Each triangle's frame is worked out once, then every vertex in one pass.
    pub fn place(
        &mut self,
        x: &[Vec3],
        normals: &[Vec3],
        positions: &mut [[f32; 3]],
        out_normals: &mut [[f32; 3]],
        mut tangents: Option<&mut [[f32; 4]]>,
    ) {
        for (f, &t) in self.frames.iter_mut().zip(&self.triangles) {
            *f = frame(x, t).unwrap_or(*f);
        }
        for (v, b) in self.bound.iter().enumerate() {
            let (along, across, normal) = self.frames[b.triangle as usize];
            let [i, j, k] = b.corners.map(|i| i as usize);
            let w = b.weights;
            let on = w[0] * x[i] + w[1] * x[j] + w[2] * x[k];
            positions[v] = (on + b.height * normal).to_array();
            let smooth =
                (w[0] * normals[i] + w[1] * normals[j] + w[2] * normals[k]).normalize_or(normal);
            out_normals[v] = smooth.to_array();
            if let Some(tangents) = tangents.as_deref_mut() {
                let t = b.tangent;
                let turned = t.x * along + t.y * across + t.z * normal;
                // At right angles to the drawn (smooth) normal (Gram–Schmidt).
                let tangent = (turned - turned.dot(smooth) * smooth).normalize_or(along);
                tangents[v] = tangent.extend(t.w).to_array();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
