//! Maslova's experiment (table 4.1): frames per second against the number of masses,
//! here with the whole Bevy app and no window: `MinimalPlugins`, assets, `ClothPlugin`
//! stepping on `FixedUpdate` and writing the mesh back every frame. Time is advanced by
//! exactly one 16 ms fixed step per frame, so a frame's wall-clock time is what one
//! step of the game costs; frames per second are `1000 / ms`.

use std::time::Instant;

use bevy::mesh::Mesh3d;
use bevy::prelude::*;

use crate::{BENCH_CHECK_STEPS, BENCH_PINS, bench_params, grid_for, median};
use bevy_cloth::error::ClothError;
use bevy_cloth::headless::headless_app;
use bevy_cloth::prelude::{Cloth, ClothSimulation};

/// Maslova's table 4.1: masses and the frames per second it reported.
pub const MASLOVA_FPS: [(usize, f64); 10] = [
    (100, 60.0),
    (300, 50.0),
    (500, 31.0),
    (700, 22.0),
    (900, 16.0),
    (1100, 13.0),
    (1300, 10.0),
    (1600, 8.0),
    (3600, 5.0),
    (6400, 3.0),
];

/// Table 4.1's counts continued to 65,536 masses.
pub const APP_COUNTS: [usize; 12] = [
    100, 300, 500, 700, 900, 1100, 1300, 1600, 3600, 6400, 16_384, 65_536,
];

/// One row of the experiment.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct AppFrame {
    /// fig. 23's model name (see [`crate::seed_model_params`]).
    pub model: String,
    /// Masses (particles).
    pub particles: usize,
    /// Median wall-clock ms of one frame (one fixed step, mesh write-back); `None` when
    /// the cloth failed within [`BENCH_CHECK_STEPS`] frames (not timed).
    pub ms_per_frame: Option<f64>,
    /// `1000 / ms_per_frame`.
    pub fps: Option<f64>,
    /// The first frame (1-based) after which the cloth was not stable; `None`: stable
    /// for all [`BENCH_CHECK_STEPS`] frames.
    pub failed_at_frame: Option<usize>,
    /// Maslova's frames per second at this count, when it has one.
    pub seed_fps: Option<f64>,
}

/// Runs the app with one curtain of `count` particles (5 cm grid, top row pinned,
/// default gravity and wind) of `model`: `warmup` frames, then the median of `frames`,
/// then untimed frames up to [`BENCH_CHECK_STEPS`]; the cloth is checked after every
/// frame, as in [`super::bench_cell`], and a row whose cloth failed is not timed.
pub fn app_frame(
    model: &str,
    count: usize,
    warmup: usize,
    frames: usize,
) -> Result<AppFrame, ClothError> {
    let params = bench_params(model)?;
    let (width, height) = grid_for(count);
    let mut app = headless_app();
    let entity = app
        .world_mut()
        .spawn((
            Cloth::grid(width, height, 0.05)
                .with_pins(BENCH_PINS)
                .with_params(params),
            Transform::from_xyz(0.0, 2.0, 0.0),
        ))
        .id();
    // Before the plugin has built the simulation (the first frame) there is nothing to
    // check; after the warm-up it must exist (below).
    let stable = |app: &App| {
        app.world()
            .get::<ClothSimulation>(entity)
            .is_none_or(|sim| sim.solver.is_stable())
    };
    let warmup = warmup.max(2);
    let mut failed_at_frame = None;
    for frame in 1..=warmup {
        app.update();
        if failed_at_frame.is_none() && !stable(&app) {
            failed_at_frame = Some(frame);
        }
    }
    if app.world().get::<Mesh3d>(entity).is_none()
        || app.world().get::<ClothSimulation>(entity).is_none()
    {
        return Err(ClothError::NotMeasurable {
            reason: "the plugin made no mesh for the cloth".into(),
        });
    }
    let mut times = Vec::with_capacity(frames);
    for frame in warmup + 1..=(warmup + frames.max(1)).max(BENCH_CHECK_STEPS) {
        if failed_at_frame.is_some() {
            break;
        }
        let start = Instant::now();
        app.update();
        if times.len() < frames.max(1) {
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
        if !stable(&app) {
            failed_at_frame = Some(frame);
        }
    }
    let ms = failed_at_frame.is_none().then(|| median(&mut times));
    Ok(AppFrame {
        model: model.to_string(),
        particles: count,
        ms_per_frame: ms,
        fps: ms.map(|ms| 1e3 / ms),
        failed_at_frame,
        seed_fps: MASLOVA_FPS
            .iter()
            .find(|(c, _)| *c == count)
            .map(|(_, f)| *f),
    })
}
