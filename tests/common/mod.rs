//! What several test files share (each uses part of it).
#![allow(dead_code)]

use bevy::math::Vec3A;
use bevy::prelude::*;
use bevy_cloth::prelude::*;
use bevy_cloth::solver::{ClothSolver, SpringKind};

/// A cloth of 6 × 6 particles 4 cm apart, without air drag, and where it lies flat (in
/// xz) with its middle at `centre`: on a platform's top at y = 0.1, `centre.y` = 0.106 puts
/// it at the platform's 5 mm thickness and 1 mm.
pub fn lying_cloth(centre: Vec3) -> (Cloth, Transform) {
    let cloth = Cloth::grid(6, 6, 0.04)
        .with_pins(ClothPins::None)
        .with_params(ClothParams {
            drag: 0.0,
            ..ClothParams::default()
        });
    let place = Transform::from_translation(centre)
        .with_rotation(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2));
    (cloth, place)
}

/// The mean position of a cloth's particles.
pub fn centroid(cloth: &ClothSolver) -> Vec3 {
    cloth.positions().iter().sum::<Vec3>() / cloth.positions().len() as f32
}

/// [`centroid`] of a cloth entity's simulation.
pub fn entity_centroid(app: &App, cloth: Entity) -> Vec3 {
    centroid(&app.world().get::<ClothSimulation>(cloth).unwrap().solver)
}

/// How many of the cloths' edges (their structural and shear springs) pass through a
/// triangle (of any of them) that does not share a particle with them: an exact
/// segment–triangle test over every pair, with a box test first.
pub fn edges_through_triangles(cloths: &[&ClothSolver]) -> usize {
    let mut x: Vec<Vec3A> = Vec::new();
    let mut edges: Vec<[u32; 2]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    // A garment's seams join two particles (one per piece) that sewing brings to one
    // point: they count as one vertex here (an edge at one end of a seam and a triangle
    // at the other share a corner, not a crossing).
    let mut same: Vec<u32> = Vec::new();
    for cloth in cloths {
        let offset = x.len() as u32;
        x.extend(cloth.positions().iter().map(|&p| Vec3A::from(p)));
        let springs = cloth.springs();
        same.extend((0..cloth.particle_count() as u32).map(|i| i + offset));
        for s in springs.ranges[SpringKind::Seam as usize].clone() {
            let (a, b) = (springs.a[s] + offset, springs.b[s] + offset);
            let (ra, rb) = (root(&same, a), root(&same, b));
            same[ra.max(rb) as usize] = ra.min(rb);
        }
        edges.extend(
            [SpringKind::Structural, SpringKind::Shear]
                .into_iter()
                .flat_map(|kind| springs.ranges[kind as usize].clone())
                .filter(|&s| springs.alive[s])
                .map(|s| [springs.a[s] + offset, springs.b[s] + offset]),
        );
        triangles.extend(cloth.triangles().iter().map(|t| t.map(|i| i + offset)));
    }
    let boxes = |ids: &[u32]| {
        let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        for &i in ids {
            lo = lo.min(x[i as usize]);
            hi = hi.max(x[i as usize]);
        }
        (lo, hi)
    };
    let edge_boxes: Vec<_> = edges.iter().map(|e| boxes(e)).collect();
    let mut crossing = 0;
    for t in &triangles {
        let (lo, hi) = boxes(t);
        for (e, (elo, ehi)) in edges.iter().zip(&edge_boxes) {
            if elo.cmpgt(hi).any() || ehi.cmplt(lo).any() {
                continue;
            }
            let corners = t.map(|i| root(&same, i));
            if corners.contains(&root(&same, e[0])) || corners.contains(&root(&same, e[1])) {
                continue;
            }
            let [a, b, c] = t.map(|i| x[i as usize]);
            if segment_hits_triangle(x[e[0] as usize], x[e[1] as usize], a, b, c) {
                crossing += 1;
            }
        }
    }
    crossing
}

/// The representative of `i` among the particles joined by seams (union–find).
fn root(same: &[u32], mut i: u32) -> u32 {
    while same[i as usize] != i {
        i = same[i as usize];
    }
    i
}

/// Whether the segment `p–q` meets the triangle `abc` (Möller–Trumbore with the
/// segment's parameter in [0, 1]).
pub fn segment_hits_triangle(p: Vec3A, q: Vec3A, a: Vec3A, b: Vec3A, c: Vec3A) -> bool {
    let (dir, e1, e2) = (q - p, b - a, c - a);
    let h = dir.cross(e2);
    let det = e1.dot(h);
    if det.abs() < 1e-12 {
        return false;
    }
    let s = p - a;
    let u = s.dot(h) / det;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let qv = s.cross(e1);
    let v = dir.dot(qv) / det;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let t = e2.dot(qv) / det;
    (0.0..=1.0).contains(&t)
}
