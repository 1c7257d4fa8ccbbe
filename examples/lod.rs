//! Level of detail: four curtains at 0, 5, 11 and 25 m from the first, each
//! with `ClothLod`: the near one runs its own model (mass-spring), the farther ones the
//! patch model with larger parts as they shrink on the screen; zoom or orbit and watch
//! the levels change in the inspector (each cloth's level, size on screen and step time).
//!
//! `cargo run --example lod [-- --screenshot out.png --frames 120]`

mod common;

use bevy::math::Vec3;

fn main() {
    common::run(
        "bevy_cloth — level of detail",
        "assets/scenes/curtains_lod.ron",
        Vec3::new(2.5, 1.4, -1.0),
        4.5,
    );
}
