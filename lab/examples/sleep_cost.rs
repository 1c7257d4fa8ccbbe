//! What a sleeping cloth costs: the whole app without a window (as Maslova's
//! frame experiment, `fps.rs`) with a 16,384-particle curtain awake and asleep, and with
//! no cloth, frame after frame in turn so a slow moment of the machine falls on all three.
//! The cloth's cost is its app's frame time less the empty app's; the ratio is asleep
//! over awake. The cloth is put to sleep by hand (`ClothSleep::asleep`) so that both
//! states are the same cloth at the same moment; nothing wakes it (checked).
//!
//! `cargo run -p bevy_cloth_lab --example sleep_cost`
use std::time::Instant;

use bevy::prelude::*;
use bevy_cloth::headless::headless_app;
use bevy_cloth::prelude::*;

fn app_with(cloth: bool) -> (App, Option<Entity>) {
    let mut app = headless_app();
    let entity = cloth.then(|| {
        app.world_mut()
            .spawn((
                Cloth::grid(128, 128, 0.05).with_pins(ClothPins::TopRow),
                Transform::from_xyz(0.0, 2.0, 0.0),
            ))
            .id()
    });
    for _ in 0..5 {
        app.update();
    }
    (app, entity)
}

fn frame_ms(app: &mut App) -> f64 {
    let start = Instant::now();
    app.update();
    start.elapsed().as_secs_f64() * 1e3
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let (mut empty, _) = app_with(false);
    let (mut awake, _) = app_with(true);
    let (mut asleep, e) = app_with(true);
    let e = e.expect("a cloth");
    let mut sleep = asleep.world_mut().get_mut::<ClothSleep>(e).unwrap();
    sleep.asleep = true;
    sleep.still_for = sleep.after;
    let (mut t_empty, mut t_awake, mut t_asleep) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..200 {
        t_empty.push(frame_ms(&mut empty));
        t_awake.push(frame_ms(&mut awake));
        t_asleep.push(frame_ms(&mut asleep));
    }
    assert!(
        asleep.world().get::<ClothSleep>(e).unwrap().asleep,
        "the sleeping cloth was woken"
    );
    let (empty, awake, asleep) = (median(t_empty), median(t_awake), median(t_asleep));
    println!(
        "median ms per frame over 200 frames each: empty app {empty:.4}, awake 16,384-particle cloth {awake:.4}, asleep {asleep:.4}"
    );
    println!(
        "the cloth's cost asleep / awake: {:.2}%",
        100.0 * (asleep - empty).max(0.0) / (awake - empty)
    );
}
