//! The full app (headless: `MinimalPlugins`, assets, `ClothPlugin` on its 16 ms fixed step,
//! mesh write-back every frame) with one 256×256 XPBD cloth of 5 cm hung from its top
//! row: inextensible (structural and shear `inf`), tethers on, at 1, 2 and 5 substeps,
//! kept awake (a cloth hanging at rest would fall asleep and cost nothing).
//! Prints the median ms per frame of 120 frames after 20 warm-up frames, frames per
//! second, and the largest structural strain at the end; one thread and both cores.
//!
//! `cargo run -p bevy_cloth_lab --example xpbd_app` (or `--example xpbd_app` from the
//! workspace root, which shares the tests' build).
use std::time::Instant;

use bevy::prelude::*;
use bevy_cloth::headless::headless_app;
use bevy_cloth::prelude::{Cloth, ClothPins, ClothSimulation, ClothSleep};
use bevy_cloth_lab::median;
use bevy_cloth_lab::peers::ours_params;

fn main() {
    for parallel in [false, true] {
        bevy_cloth::solver::set_parallel(parallel);
        for substeps in [1, 2, 5] {
            let mut app = headless_app();
            let entity = app
                .world_mut()
                .spawn((
                    Cloth::grid(256, 256, 0.05)
                        .with_pins(ClothPins::TopRow)
                        .with_params(ours_params(substeps, true, true)),
                    Transform::from_xyz(0.0, 2.0, 0.0),
                    ClothSleep::never(),
                ))
                .id();
            for _ in 0..20 {
                app.update();
            }
            let mut times = Vec::new();
            for _ in 0..120 {
                let start = Instant::now();
                app.update();
                times.push(start.elapsed().as_secs_f64() * 1e3);
            }
            let sim = app.world().get::<ClothSimulation>(entity).expect("built");
            let strain = sim.solver.strain().max;
            let stable = sim.solver.is_stable();
            let ms = median(&mut times);
            println!(
                "{} thread(s), {substeps} substep(s): {ms:.2} ms per frame ({:.0} fps), strain {:.3}%, stable {stable}",
                bevy_cloth::solver::threads(),
                1e3 / ms,
                strain * 100.0
            );
        }
    }
}
