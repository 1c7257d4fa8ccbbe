//! Does the calm curtain's accuracy reference converge when its mirror symmetry is broken?
//! The reference (100× the automatic substeps, limiter converged) against one at twice
//! the substeps, RMS distance over the diagonal, for the calm curtain as the accuracy
//! study runs it and with a constant sideways wind of 1e-6 N per particle (about 1/5000
//! of a particle's weight) that breaks its left-right symmetry.
//!
//! `cargo run -p bevy_cloth_lab --example reference_check`
use bevy::math::Vec3;
use bevy_cloth::params::{Wind, WindField};
use bevy_cloth::prelude::*;
use bevy_cloth_lab::accuracy::{Case, REFERENCE_FACTOR};

fn main() {
    let path = bevy_cloth::layout::garment::asset_path("scenes/curtain.ron");
    for (label, strength) in [("symmetric", 0.0f32), ("sideways wind 1e-6 N", 1e-6)] {
        let mut scene = ClothScene::load(&path).expect("curtain scene");
        scene.environment.wind = Wind {
            direction: Vec3::X,
            strength,
            field: WindField::Constant,
        };
        let case = Case::new("curtain", &scene, 0, 3.0).expect("case");
        let (substeps, reference) = case.reference(REFERENCE_FACTOR).expect("reference");
        let (_, finer) = case.reference(2 * REFERENCE_FACTOR).expect("finer");
        let change = reference
            .error_against(&finer)
            .map_or(f64::INFINITY, |e| e.0);
        println!("{label}: reference at {substeps} substeps changes by {change:.3e} when halved");
    }
}
