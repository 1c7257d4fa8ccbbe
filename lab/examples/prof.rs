//! Where a mass-spring substep's time goes: the timing table's 65,536-particle curtain
//! (top row pinned), ns per particle-substep in each phase (forces, integration, target
//! fitting, constraints), without and with the strain limiter (4 sweeps), beside the
//! bare kernel, at 5 substeps. `ONE=1` keeps the kernels on one thread; `NOWIND=1` switches
//! the wind off; `GENERAL=1` steps the same springs on the general path (as a mesh or a
//! garment would), not the grid's stencil.
//!
//! `cargo run -p bevy_cloth_lab --example prof`
use bevy_cloth::params::{Environment, Substeps};
use bevy_cloth::prelude::*;
use std::time::Instant;
fn main() {
    let n: usize = std::env::var("COUNT").map_or(65536, |c| c.parse().expect("COUNT"));
    let parallel = std::env::var("ONE").is_err();
    let general = std::env::var("GENERAL").is_ok();
    bevy_cloth::solver::set_parallel(parallel);
    for (label, limit, iters) in [("no limiter", None, 0), ("limiter 4", Some(0.1), 4)] {
        let params = ClothParams {
            strain_limit: limit,
            strain_limit_iterations: iters,
            ..ClothParams::seeds()
        };
        let (w, h) = bevy_cloth_lab::grid_for(n);
        let shape = ClothShape::Grid {
            width: w,
            height: h,
            spacing: 0.05,
        };
        let mut layout = shape.layout().unwrap();
        let pins = ClothPins::TopRow.resolve_for(&layout).unwrap();
        if general {
            layout.grid = None; // the same springs, told it is not a grid
        }
        let mut cloth = bevy_cloth::solver::ClothSolver::new(
            layout,
            &pins,
            &ClothParams {
                substeps: Substeps::Fixed(5),
                ..params
            },
            bevy::math::Affine3A::IDENTITY,
        )
        .unwrap();
        let mut env = Environment::default();
        if std::env::var("NOWIND").is_ok() {
            env.wind.strength = 0.0;
        }
        for _ in 0..3 {
            cloth.step(0.016, &env);
        }
        let mut t = [0.0f64; 4];
        let mut subs = 0;
        for _ in 0..7 {
            let k = cloth.begin_step(0.016);
            for _ in 0..k {
                let s = Instant::now();
                cloth.accumulate_forces(&env);
                t[0] += s.elapsed().as_secs_f64();
                let s = Instant::now();
                cloth.integrate();
                t[1] += s.elapsed().as_secs_f64();
                let s = Instant::now();
                cloth.fit_targets();
                t[2] += s.elapsed().as_secs_f64();
                let s = Instant::now();
                cloth.constrain();
                t[3] += s.elapsed().as_secs_f64();
                subs += 1;
            }
            cloth.end_step();
        }
        let per = |x: f64| x * 1e9 / (n as f64 * subs as f64);
        println!(
            "{label}: forces {:.1} integrate {:.1} fit {:.1} constrain {:.1} ns",
            per(t[0]),
            per(t[1]),
            per(t[2]),
            per(t[3])
        );
    }
    println!(
        "bare {:.1}",
        bevy_cloth_lab::baseline::ns_per_particle_substep(n, 7)
    );
}
