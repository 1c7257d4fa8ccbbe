//! What a default cloth costs and how far it stretches, beside the models the recipes
//! recommend: the 64 × 64 cloth of `cloth peers --hang swing` (5 cm apart, its top row
//! pinned, starting level and swinging down under gravity), each parameter set for 2 s
//! of 1/60 s frames on one thread, side by side a frame each in turn. The median frame,
//! the substeps and the largest structural strain of any frame.
//!
//! `cargo run -p bevy_cloth_lab --example default_cost`
use std::time::Instant;

use bevy::math::Vec3;
use bevy_cloth::params::{ClothParams, Environment, Fabric, Model, XpbdParams};
use bevy_cloth_lab::median;
use bevy_cloth_lab::peers::{self, FRAME, Hang};

fn main() {
    let xpbd = |fabric: Fabric| ClothParams {
        model: Model::Xpbd(XpbdParams::default()),
        fabric: Some(fabric),
        ..ClothParams::default()
    };
    let sets = [
        ("ClothParams::seeds()", ClothParams::seeds()),
        ("ClothParams::default()", ClothParams::default()),
        ("XPBD, denim", xpbd(Fabric::DENIM)),
        ("XPBD, twill", xpbd(Fabric::TWILL)),
        ("XPBD, polyester", xpbd(Fabric::POLYESTER)),
        ("XPBD, interlock", xpbd(Fabric::INTERLOCK)),
    ];
    bevy_cloth::solver::set_parallel(false);
    let mut cloths: Vec<_> = sets
        .iter()
        .map(|(_, p)| peers::ours(64, Hang::Swing, p).expect("a valid cloth"))
        .collect();
    let env = Environment {
        gravity: Vec3::new(0.0, -9.81, 0.0),
        ..Environment::default()
    };
    let frames = 120;
    let mut ms = vec![Vec::new(); sets.len()];
    let mut substeps = vec![Vec::new(); sets.len()];
    let mut strain = vec![0.0f32; sets.len()];
    for _ in 0..frames {
        for (k, cloth) in cloths.iter_mut().enumerate() {
            let start = Instant::now();
            cloth.step(FRAME, &env);
            ms[k].push(start.elapsed().as_secs_f64() * 1e3);
            substeps[k].push(f64::from(cloth.substeps()));
            assert!(cloth.is_stable(), "{} failed", sets[k].0);
            strain[k] = strain[k].max(cloth.strain().max);
        }
    }
    println!(
        "| 64 × 64 swinging, 2 s, one thread | ms a frame (median) | substeps (median) | largest strain |"
    );
    println!("|---|---:|---:|---:|");
    for (k, (name, _)) in sets.iter().enumerate() {
        println!(
            "| {name} | {:.2} | {:.0} | {:.1}% |",
            median(&mut ms[k]),
            median(&mut substeps[k]),
            100.0 * strain[k]
        );
    }
}
