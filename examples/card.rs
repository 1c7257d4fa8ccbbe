//! Sladović's (2014) shape-matching model (§2.3, §3.3): a stiff playing card hanging from one
//! corner, swinging and spinning in the wind, beside the same card as a mass-spring cloth.
//! Same camera, keys, mouse tools, inspector and screenshot mode as the curtain.
//!
//! `cargo run --example card [-- --scene FILE] [--set key=value]… [--screenshot out.png --frames 120]…`

mod common;

use bevy::math::Vec3;

fn main() {
    common::run(
        "bevy_cloth — card",
        "assets/scenes/card.ron",
        // Left of the cards, so they sit in the middle of the view beside the panel.
        Vec3::new(-0.07, 1.45, 0.0),
        0.42,
    );
}
