//! What drawing a proxy costs, in its two parts, alone: 100 cloths of 16 × 24 particles
//! (the crowd's capes), each drawn through a grid 3 × 3 times finer (3,196 vertices, 8.3
//! times the particles), crumpled differently every round. Each round works out every
//! cloth's smooth normals (`ClothSolver::normals_into`), then places its vertices on
//! them (`ProxyBinding::place`, no tangents, as the crowd draws); the median and least
//! of 200 rounds after 20 of each part, ms a round, and ns a particle or a vertex.
//!
//! `cargo run -p bevy_cloth_lab --example place_cost`

use std::time::Instant;

use bevy::math::{Affine3A, Vec3};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::ProxyBinding;

/// The points of a `w × h` grid's `rest`, `k` times finer each way (bilinear in its cells).
fn refined(rest: &[Vec3], w: u32, h: u32, k: u32) -> Vec<Vec3> {
    let (fw, fh) = ((w - 1) * k + 1, (h - 1) * k + 1);
    let at = |i: u32, j: u32| rest[(j.min(h - 1) * w + i.min(w - 1)) as usize];
    (0..fw * fh)
        .map(|v| {
            let (fi, fj) = (v % fw, v / fw);
            let (i, j) = (fi / k, fj / k);
            let (s, t) = ((fi % k) as f32 / k as f32, (fj % k) as f32 / k as f32);
            let top = at(i, j).lerp(at(i + 1, j), s);
            top.lerp(at(i, j + 1).lerp(at(i + 1, j + 1), s), t)
        })
        .collect()
}

fn main() {
    let (w, h, k) = (16u32, 24u32, 3u32);
    let cape = ClothShape::Grid {
        width: w,
        height: h,
        spacing: 0.04,
    }
    .build_solver(&ClothPins::None, &ClothParams::seeds(), Affine3A::IDENTITY)
    .expect("a grid builds");
    let (rest, tris) = (cape.rest_positions(), cape.triangles());
    let fine = refined(rest, w, h, k);
    let mut cloths: Vec<ProxyBinding> = (0..100)
        .map(|_| ProxyBinding::bind(rest, tris, &fine, None).expect("triangles"))
        .collect();
    // Crumpled out of the grid's plane, differently each round.
    let out = (rest[1] - rest[0])
        .cross(rest[w as usize] - rest[0])
        .normalize();
    let m = fine.len();
    let (mut positions, mut normals) = (vec![[0.0f32; 3]; m], vec![[0.0f32; 3]; m]);
    let (mut times, mut normal_times) = (Vec::new(), Vec::new());
    let mut smooth = vec![Vec3::ZERO; rest.len()];
    for round in 0..220 {
        let phase = round as f32 * 0.1;
        let bend = |v: usize| {
            let (i, j) = ((v as u32 % w) as f32, (v as u32 / w) as f32);
            (0.36 * i + phase).sin() * (0.2 * j).cos()
        };
        let x: Vec<Vec3> = (0..rest.len())
            .map(|v| rest[v] + 0.05 * bend(v) * out)
            .collect();
        let n: Vec<Vec3> = (0..rest.len())
            .map(|v| (out + 0.3 * bend(v) * (rest[1] - rest[0]).normalize()).normalize())
            .collect();
        let start = Instant::now();
        for _ in 0..cloths.len() {
            cape.normals_into(&mut smooth);
            std::hint::black_box(&mut smooth);
        }
        if round >= 20 {
            normal_times.push(start.elapsed().as_secs_f64() * 1e3);
        }
        let start = Instant::now();
        for binding in &mut cloths {
            binding.place(&x, &n, &mut positions, &mut normals, None);
        }
        if round >= 20 {
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
        std::hint::black_box(&positions);
    }
    normal_times.sort_by(f64::total_cmp);
    let (median, least) = (normal_times[normal_times.len() / 2], normal_times[0]);
    let particles = (rest.len() * cloths.len()) as f64;
    println!(
        "normals of {particles} particles: median {median:.3} ms (least {least:.3}), {:.2} ns a particle",
        median * 1e6 / particles
    );
    times.sort_by(f64::total_cmp);
    let (median, least) = (times[times.len() / 2], times[0]);
    let vertices = (m * cloths.len()) as f64;
    println!(
        "{} vertices on {} particles: median {median:.3} ms (least {least:.3}), {:.2} ns a vertex",
        vertices,
        rest.len() * cloths.len(),
        median * 1e6 / vertices
    );
}
