//! The curtain of Sladović 2014 §3.2: a cloth hanging from its two top corners, swaying under
//! gravity and wind. Orbit camera (left-drag away from the cloth rotates, middle-drag pans,
//! wheel zooms), the seed's keys, mouse tools (left-drag on the cloth grabs, right-drag
//! cuts) and an egui inspector for every parameter.
//!
//! `cargo run --example curtain [-- --scene FILE] [--set key=value]… [--screenshot out.png --frames 120]…`

mod common;

use bevy::math::Vec3;

fn main() {
    common::run(
        "bevy_cloth — curtain",
        "assets/scenes/curtain.ron",
        Vec3::new(0.0, 1.4, 0.0),
        3.4,
    );
}
