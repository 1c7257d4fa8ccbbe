//! What several test files share (each uses part of it).
#![allow(dead_code)]

use bevy::prelude::*;
use bevy_cloth::prelude::*;
use bevy_cloth::solver::ClothSolver;

/// A cloth of 6 × 6 particles 4 cm apart, without air drag, and where it lies flat (in
/// xz) with its middle at `centre`: on a platform's top at y = 0.1, `centre.y` = 0.106 puts
/// it at the platform's 5 mm thickness and 1 mm.
pub fn lying_cloth(centre: Vec3) -> (Cloth, Transform) {
    let cloth = Cloth::grid(6, 6, 0.04)
        .with_pins(ClothPins::None)
        .with_params(ClothParams {
            drag: 0.0,
            ..ClothParams::default()
        });
    let place = Transform::from_translation(centre)
        .with_rotation(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2));
    (cloth, place)
}

/// The mean position of a cloth's particles.
pub fn centroid(cloth: &ClothSolver) -> Vec3 {
    cloth.positions().iter().sum::<Vec3>() / cloth.positions().len() as f32
}

/// [`centroid`] of a cloth entity's simulation.
pub fn entity_centroid(app: &App, cloth: Entity) -> Vec3 {
    centroid(&app.world().get::<ClothSimulation>(cloth).unwrap().solver)
}
