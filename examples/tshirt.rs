//! Maslova's T-shirt: two 0/1 pattern pieces (`assets/patterns/`) sewn together by seam
//! springs around a mannequin of capsules and spheres, settling onto it and fluttering in
//! the wind. The inspector edits node mass, stiffness, seams, the front and back colours,
//! the diffuse and specular coefficients and the light; the same camera, keys, tools and
//! screenshot mode as the curtain.
//!
//! `cargo run --example tshirt [-- --scene FILE] [--set key=value]… [--screenshot out.png --frames 240]…`

mod common;

use bevy::math::Vec3;

fn main() {
    common::run(
        "bevy_cloth — T-shirt",
        "assets/scenes/tshirt.ron",
        Vec3::new(0.0, 1.15, 0.0),
        2.4,
    );
}
