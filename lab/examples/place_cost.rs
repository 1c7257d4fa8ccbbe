//! What placing a proxy's render vertices costs, alone: 100 cloths of 16 × 24 particles
//! (the crowd's capes), each drawn through a grid 3 × 3 times finer (3,196 vertices, 8.3
//! times the particles), crumpled differently every round. Each round places every
//! cloth's vertices once (`ProxyBinding::place`, no tangents, as the crowd draws); the
//! median and least of 200 rounds after 20, ms a round, and ns a vertex.
//!
//! `cargo run -p bevy_cloth_lab --example place_cost`

use std::time::Instant;

use bevy::math::Vec3;
use bevy_cloth::solver::ProxyBinding;

/// A `w × h` grid of `spacing` m cells, `k` times finer, crumpled `bend` m by `phase`.
fn grid(w: u32, h: u32, spacing: f32, k: u32, bend: f32, phase: f32) -> Vec<Vec3> {
    let (fw, fh) = ((w - 1) * k + 1, (h - 1) * k + 1);
    let step = spacing / k as f32;
    (0..fw * fh)
        .map(|v| {
            let (i, j) = ((v % fw) as f32 * step, (v / fw) as f32 * step);
            Vec3::new(i, -j, bend * (9.0 * i + phase).sin() * (5.0 * j).cos())
        })
        .collect()
}

fn triangles(w: u32, h: u32) -> Vec<[u32; 3]> {
    let mut t = Vec::new();
    for j in 0..h - 1 {
        for i in 0..w - 1 {
            let v = j * w + i;
            t.push([v, v + 1, v + w]);
            t.push([v + 1, v + w + 1, v + w]);
        }
    }
    t
}

fn main() {
    let (w, h, spacing, k) = (16u32, 24u32, 0.04f32, 3u32);
    let rest = grid(w, h, spacing, 1, 0.0, 0.0);
    let fine = grid(w, h, spacing, k, 0.0, 0.0);
    let tris = triangles(w, h);
    let mut cloths: Vec<ProxyBinding> = (0..100)
        .map(|_| ProxyBinding::bind(&rest, &tris, &fine, None).expect("triangles"))
        .collect();
    let m = fine.len();
    let (mut positions, mut normals) = (vec![[0.0f32; 3]; m], vec![[0.0f32; 3]; m]);
    let mut times = Vec::new();
    for round in 0..220 {
        let x = grid(w, h, spacing, 1, 0.05, round as f32 * 0.1);
        let n: Vec<Vec3> = x
            .iter()
            .map(|p| Vec3::new(-0.3 * p.z, 0.1, 1.0).normalize())
            .collect();
        let start = Instant::now();
        for binding in &mut cloths {
            binding.place(&x, &n, &mut positions, &mut normals, None);
        }
        if round >= 20 {
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
        std::hint::black_box(&positions);
    }
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
