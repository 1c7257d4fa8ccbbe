//! What level of detail saves: the `lod` example's curtain (48×40 particles,
//! 4 cm apart, top row pinned, the scene's wind) with `ClothLod`, a camera at each
//! distance in turn, in the whole app without a window: its level, its size on the view
//! and the median wall-clock ms of its step over 60 steps after 60 to settle; five
//! runs per distance, the median of their medians with the fastest and slowest.
//!
//! `cargo run -p bevy_cloth_lab --example lod_cost`
use bevy::camera::{Camera, PerspectiveProjection, Projection};
use bevy::prelude::*;
use bevy_cloth::headless::headless_app;
use bevy_cloth::prelude::*;

fn main() {
    println!(
        "| camera distance, m | level | model | size on the view | ms per step [fastest–slowest of 5 runs] |"
    );
    println!("|---:|---:|---|---:|---:|");
    for distance in [2.0f32, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0, 32.0] {
        let runs: Vec<(f32, usize, f32)> = (0..5).map(|_| run(distance)).collect();
        let mut ms: Vec<f32> = runs.iter().map(|r| r.0).collect();
        ms.sort_by(f32::total_cmp);
        let (_, level, fraction) = runs[0];
        let model = ClothLod::describe(level);
        println!(
            "| {distance} | {level} | {model} | {:.0}% | {:.3} [{:.3}–{:.3}] |",
            fraction * 100.0,
            ms[2],
            ms[0],
            ms[4]
        );
    }
}

/// One run at `distance`: the median ms per step, the level and the size on the view.
fn run(distance: f32) -> (f32, usize, f32) {
    {
        let mut app = headless_app();
        app.world_mut()
            .resource_mut::<ClothEnvironment>()
            .wind
            .strength = 6e-4;
        let cloth = app
            .world_mut()
            .spawn((
                Cloth::grid(48, 40, 0.04).with_pins(ClothPins::TopRow),
                ClothLod::default(),
                ClothSleep::never(),
                Transform::from_xyz(0.0, 2.2, 0.0),
            ))
            .id();
        app.world_mut().spawn((
            Camera::default(),
            Projection::Perspective(PerspectiveProjection::default()),
            Transform::from_xyz(0.0, 1.4, distance).looking_at(Vec3::new(0.0, 1.4, 0.0), Vec3::Y),
        ));
        for _ in 0..60 {
            app.update();
        }
        let mut times = Vec::new();
        for _ in 0..60 {
            app.update();
            times.push(
                app.world()
                    .get::<ClothSimulation>(cloth)
                    .unwrap()
                    .last_step_ms,
            );
        }
        times.sort_by(f32::total_cmp);
        let lod = app.world().get::<ClothLod>(cloth).unwrap();
        (times[times.len() / 2], lod.level, lod.screen_fraction)
    }
}
