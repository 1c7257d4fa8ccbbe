//! What motion constraints cost when a body holds many particles at distance 0 (a
//! garment painted 0 over most of it): `ClothSolver::set_motion_constraints` on an
//! `N × N` grid with every particle's distance 0 and targets that move each step, then
//! the step itself, medians of 60 steps after 10, for N = 32, 64 and 128.
//!
//! `cargo run -p bevy_cloth_lab --example motion_cost`

use std::time::Instant;

use bevy::math::{Affine3A, Vec3};
use bevy_cloth::params::Environment;
use bevy_cloth::prelude::*;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let env = Environment::default();
    println!("particles | set_motion_constraints, ms | step, ms");
    for side in [32u32, 64, 128] {
        let shape = ClothShape::Grid {
            width: side,
            height: side,
            spacing: 0.02,
        };
        let mut solver = shape
            .build_solver(&ClothPins::None, &ClothParams::seeds(), Affine3A::IDENTITY)
            .expect("a grid builds");
        let rest = solver.positions().to_vec();
        let distance = vec![0.0; rest.len()];
        let (mut set, mut step) = (Vec::new(), Vec::new());
        for frame in 0..70 {
            let shift = Vec3::new(0.01 * frame as f32, 0.0, 0.0);
            let targets: Vec<Vec3> = rest.iter().map(|&x| x + shift).collect();
            let start = Instant::now();
            solver
                .set_motion_constraints(&targets, &distance)
                .expect("valid constraints");
            let set_ms = start.elapsed().as_secs_f64() * 1e3;
            let start = Instant::now();
            solver.step(0.016, &env);
            let step_ms = start.elapsed().as_secs_f64() * 1e3;
            if frame >= 10 {
                set.push(set_ms);
                step.push(step_ms);
            }
        }
        println!(
            "{:>9} | {:>26.3} | {:>8.3}",
            rest.len(),
            median(set),
            median(step)
        );
    }
}
