//! 100 small cloths (15×20 particles of 5 cm, XPBD, top row pinned, 10 substeps, kept
//! awake, in wind) stepped by the full headless app, where the plugin steps each cloth's
//! substeps in one task on the compute pool, against the same 100 solvers
//! stepped one after another on this thread with no app: median ms per 16 ms step of 120
//! after 20 warm-up steps, three rounds.
//!
//! `cargo run --example many_cloths`
use std::time::Instant;

use bevy::math::Affine3A;
use bevy::prelude::*;
use bevy_cloth::headless::headless_app;
use bevy_cloth::params::{Environment, Model, Substeps, XpbdParams};
use bevy_cloth::prelude::{Cloth, ClothParams, ClothPins, ClothShape, ClothSleep};
use bevy_cloth_lab::median;

const CLOTHS: usize = 100;

fn params() -> ClothParams {
    ClothParams {
        model: Model::Xpbd(XpbdParams::default()),
        substeps: Substeps::Fixed(10),
        ..ClothParams::seeds()
    }
}

fn app_ms() -> f64 {
    let mut app = headless_app();
    for k in 0..CLOTHS {
        app.world_mut().spawn((
            Cloth::grid(15, 20, 0.05)
                .with_pins(ClothPins::TopRow)
                .with_params(params()),
            Transform::from_xyz((k % 10) as f32, 2.0, (k / 10) as f32),
            ClothSleep::never(),
        ));
    }
    for _ in 0..20 {
        app.update();
    }
    let mut times: Vec<f64> = (0..120)
        .map(|_| {
            let start = Instant::now();
            app.update();
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    median(&mut times)
}

fn loop_ms() -> f64 {
    let shape = ClothShape::Grid {
        width: 15,
        height: 20,
        spacing: 0.05,
    };
    let mut cloths: Vec<_> = (0..CLOTHS)
        .map(|k| {
            let at = Vec3::new((k % 10) as f32, 2.0, (k / 10) as f32);
            shape
                .build_solver(
                    &ClothPins::TopRow,
                    &params(),
                    Affine3A::from_translation(at),
                )
                .expect("a valid cloth")
        })
        .collect();
    let env = Environment::default();
    let mut step = || {
        for c in cloths.iter_mut() {
            c.step(0.016, &env);
        }
    };
    for _ in 0..20 {
        step();
    }
    let mut times: Vec<f64> = (0..120)
        .map(|_| {
            let start = Instant::now();
            step();
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    median(&mut times)
}

fn main() {
    for round in 0..3 {
        let (one, app) = (loop_ms(), app_ms());
        println!(
            "round {round}: one after another on one thread {one:.2} ms per step; the app (both cores) {app:.2} ms per frame; {:.2}x",
            one / app
        );
    }
}
