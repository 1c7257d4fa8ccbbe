//! Self-collision: a square cloth dropped onto a ball folds onto itself on the ground
//! without passing through (`assets/scenes/fold.ron`). The inspector switches
//! self-collision off to compare, and sets the distance kept and the friction. Orbit
//! camera, the curtain's keys and mouse tools.
//!
//! `cargo run --example fold [-- --scene FILE] [--set key=value]… [--screenshot out.png --frames 120]…`

mod common;

use bevy::math::Vec3;

fn main() {
    common::run(
        "bevy_cloth — fold",
        "assets/scenes/fold.ron",
        Vec3::new(0.0, 0.15, 0.0),
        1.6,
    );
}
