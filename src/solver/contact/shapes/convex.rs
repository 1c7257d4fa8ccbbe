//! A convex polyhedron: a physics engine's convex hull, placed.

use std::sync::Arc;

use bevy::math::{Quat, Vec3};

use super::{Placement, Shape, check_point};
use crate::error::ClothError;

/// A convex polyhedron (a physics engine's convex hull), placed: a point `x` of the world
/// is `rotation⁻¹ (x − center)` in the hull's own frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Convex {
    /// Where the hull's origin is, m.
    pub center: Vec3,
    /// Its orientation.
    pub rotation: Quat,
    /// The hull, in its own frame (shared: placing it copies no geometry).
    pub hull: Arc<ConvexHull>,
}

impl Shape for Convex {
    fn distance(&self, x: Vec3) -> (f32, Vec3) {
        let (d, n) = self.hull.distance(self.rotation.inverse() * (x - self.center));
        (d, self.rotation * n)
    }

    fn distance_within(&self, x: Vec3, reach: f32) -> Option<(f32, Vec3)> {
        // The farthest face plane is never farther than the surface: past `reach` there,
        // no need of the exact distance.
        let local = self.rotation.inverse() * (x - self.center);
        let farthest = self.hull.farthest_plane(local);
        if farthest.1 >= reach {
            return None;
        }
        let (d, n) = self.hull.distance_given(local, farthest);
        Some((d, self.rotation * n))
    }

    fn extent(&self) -> (Vec3, Vec3) {
        let r = Vec3::splat(self.hull.radius);
        (self.center - r, self.center + r)
    }

    /// Placed rigidly (a scale would need a new hull; it is not applied).
    fn placed(&self, placement: &Placement) -> Self {
        Self {
            center: placement.point(self.center),
            rotation: placement.rotation * self.rotation,
            hull: self.hull.clone(),
        }
    }

    fn validate(&self) -> Result<(), ClothError> {
        check_point("center", self.center)
    }
}

/// A convex polyhedron in its own frame: its corners and its faces (each a plane and the
/// loop of corners round it), for exact signed distances: inside, minus the distance to the
/// nearest face plane; outside, the distance to the nearest point of the nearest face
/// polygon (its inside, an edge or a corner).
#[derive(Debug)]
pub struct ConvexHull {
    vertices: Vec<Vec3>,
    faces: Vec<HullFace>,
    /// The farthest corner from the origin (the bounding sphere), m.
    radius: f32,
}

#[derive(Debug, PartialEq)]
struct HullFace {
    /// Outward unit normal.
    normal: Vec3,
    /// `normal · x` on the face's plane.
    offset: f32,
    /// Its corners, in order round `normal` (counter-clockwise seen from outside).
    corners: Vec<u32>,
}

/// The same hull (one shared allocation, as placed colliders are) without comparing
/// its geometry; else the same corners and faces.
impl PartialEq for ConvexHull {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self, other)
            || (self.radius == other.radius
                && self.vertices == other.vertices
                && self.faces == other.faces)
    }
}

impl ConvexHull {
    /// A hull from its corners and, per face, its outward normal and corners (in any
    /// order). Refused: non-finite or fewer than 4 corners, fewer than 4 faces, a face
    /// with fewer than 3 corners or an index past the corners, a face whose corners are
    /// off its plane, or a corner in front of a face's plane (not convex, or a wrong
    /// normal) — each by more than 1e-4 of the hull's size.
    pub fn new(vertices: Vec<Vec3>, faces: Vec<(Vec3, Vec<u32>)>) -> Result<Self, String> {
        if vertices.len() < 4 || !vertices.iter().all(|v| v.is_finite()) {
            return Err(format!(
                "a hull needs at least 4 finite corners, got {}",
                vertices.len()
            ));
        }
        if faces.len() < 4 {
            return Err(format!(
                "a hull needs at least 4 faces, got {}",
                faces.len()
            ));
        }
        let radius = vertices.iter().map(|v| v.length()).fold(0.0, f32::max);
        let size = vertices
            .iter()
            .flat_map(|a| vertices.iter().map(move |b| a.distance(*b)))
            .fold(0.0, f32::max);
        let faces = faces.into_iter().enumerate();
        let out = faces
            .map(|(k, (normal, corners))| hull_face(&vertices, k, normal, corners, size))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            vertices,
            faces: out,
            radius,
        })
    }

    /// The face whose plane `x` is farthest in front of, and that distance (negative
    /// inside): a lower bound of the distance from the hull, exact inside.
    fn farthest_plane(&self, x: Vec3) -> (usize, f32) {
        self.faces
            .iter()
            .enumerate()
            .map(|(k, f)| (k, f.normal.dot(x) - f.offset))
            .fold((0, f32::MIN), |a, b| if b.1 > a.1 { b } else { a })
    }

    /// Signed distance from the surface and the outward normal at the nearest surface
    /// point, for `x` in the hull's frame.
    fn distance(&self, x: Vec3) -> (f32, Vec3) {
        self.distance_given(x, self.farthest_plane(x))
    }

    /// [`Self::distance`] given `x`'s [`Self::farthest_plane`].
    fn distance_given(&self, x: Vec3, (k, d): (usize, f32)) -> (f32, Vec3) {
        if d <= 0.0 {
            return (d, self.faces[k].normal);
        }
        // Outside: the nearest point of the faces `x` is in front of.
        let mut best = (f32::INFINITY, Vec3::ZERO);
        for face in &self.faces {
            let s = face.normal.dot(x) - face.offset;
            if s <= 0.0 {
                continue;
            }
            let q = x - face.normal * s;
            let corner = |j: usize| self.vertices[face.corners[j % face.corners.len()] as usize];
            let inside = (0..face.corners.len()).all(|j| {
                let (a, b) = (corner(j), corner(j + 1));
                (b - a).cross(q - a).dot(face.normal) >= 0.0
            });
            let nearest = if inside {
                q
            } else {
                (0..face.corners.len())
                    .map(|j| {
                        let (a, b) = (corner(j), corner(j + 1));
                        let t = ((x - a).dot(b - a)
                            / (b - a).length_squared().max(f32::MIN_POSITIVE))
                        .clamp(0.0, 1.0);
                        a + (b - a) * t
                    })
                    .min_by(|p, r| p.distance_squared(x).total_cmp(&r.distance_squared(x)))
                    .unwrap_or(q)
            };
            let length = nearest.distance(x);
            if length < best.0 {
                best = (length, nearest);
            }
        }
        let normal = (x - best.1).try_normalize().unwrap_or(self.faces[k].normal);
        (best.0, normal)
    }
}

/// Face `k` of a hull of `vertices` (of diameter `size`): its unit normal, its plane's
/// offset and its corners ordered round the normal; refused when it has no normal,
/// fewer than 3 corners (or one past the corners), is not flat, or has a corner in
/// front of it (see [`ConvexHull::new`]).
fn hull_face(
    vertices: &[Vec3],
    k: usize,
    normal: Vec3,
    mut corners: Vec<u32>,
    size: f32,
) -> Result<HullFace, String> {
    let Some(normal) = normal.try_normalize() else {
        return Err(format!("face {k} has no normal"));
    };
    if corners.len() < 3 || corners.iter().any(|&i| i as usize >= vertices.len()) {
        return Err(format!(
            "face {k} needs 3 or more of the {} corners",
            vertices.len()
        ));
    }
    // Order the corners round the normal, by angle about their centroid.
    let mid = corners.iter().map(|&i| vertices[i as usize]).sum::<Vec3>() / corners.len() as f32;
    let u = normal.any_orthonormal_vector();
    let w = normal.cross(u);
    let angle = |i: u32| {
        let d = vertices[i as usize] - mid;
        d.dot(w).atan2(d.dot(u))
    };
    corners.sort_by(|&a, &b| angle(a).total_cmp(&angle(b)));
    let offset = corners
        .iter()
        .map(|&i| normal.dot(vertices[i as usize]))
        .fold(f32::MIN, f32::max);
    if corners
        .iter()
        .any(|&i| offset - normal.dot(vertices[i as usize]) > 1e-4 * size)
    {
        return Err(format!("face {k} is not flat"));
    }
    if let Some(v) = vertices
        .iter()
        .find(|v| normal.dot(**v) - offset > 1e-4 * size)
    {
        return Err(format!("corner {v} is in front of face {k}: not convex"));
    }
    Ok(HullFace {
        normal,
        offset,
        corners,
    })
}

