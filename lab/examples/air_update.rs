//! The air once a step against every substep (`AirUpdate::Step`, the default, against
//! `AirUpdate::Substep`), side by side: a 31 × 21 polyester flag held along one edge in
//! air at 5 and 12 m/s, and the same cloth hung from its top row in a 3 m/s breeze across
//! it and in still air, on XPBD and mass-spring, 5 s of 16.7 ms steps. For each: the
//! tracked corner's mean place and its RMS motion about it over the last 3 s, the largest
//! structural strain at the end, and the median step time (one thread).
//!
//! `cargo run -p bevy_cloth_lab --example air_update`
use std::time::Instant;

use bevy::math::{Affine3A, Vec3};
use bevy_cloth::fabric::Fabric;
use bevy_cloth::layout::shape::{ClothPins, ClothShape};
use bevy_cloth::params::{Air, AirUpdate, ClothParams, Environment, Model, XpbdParams};

const WIDTH: u32 = 31;
const HEIGHT: u32 = 21;

struct Outcome {
    mean: Vec3,
    rms: f32,
    strain: f32,
    ms: f64,
}

fn run(update: AirUpdate, wind: Vec3, flag: bool, model: Model) -> Outcome {
    let params = ClothParams {
        model,
        fabric: Some(Fabric::POLYESTER),
        ..ClothParams::seeds()
    };
    let pins = if flag {
        ClothPins::Indices((0..HEIGHT).map(|j| j * WIDTH).collect())
    } else {
        ClothPins::TopRow
    };
    let shape = ClothShape::Grid {
        width: WIDTH,
        height: HEIGHT,
        spacing: 0.04,
    };
    let mut cloth = shape
        .build_solver(&pins, &params, Affine3A::IDENTITY)
        .expect("the cloth builds");
    let env = Environment {
        air: Some(Air {
            velocity: wind,
            update,
            ..Air::default()
        }),
        ..Environment::default()
    };
    // The fly end's top corner of a flag, the hem's middle of a hung cloth.
    let tracked = if flag {
        WIDTH - 1
    } else {
        (HEIGHT - 1) * WIDTH + WIDTH / 2
    } as usize;
    let (mut track, mut ms) = (Vec::new(), Vec::new());
    for step in 0..300 {
        let start = Instant::now();
        cloth.step(1.0 / 60.0, &env);
        ms.push(start.elapsed().as_secs_f64() * 1e3);
        if step >= 120 {
            track.push(cloth.positions()[tracked]);
        }
    }
    assert!(cloth.is_stable(), "the cloth failed: not timed");
    ms.sort_by(f64::total_cmp);
    let mean = track.iter().copied().sum::<Vec3>() / track.len() as f32;
    let spread = track.iter().map(|p| p.distance_squared(mean)).sum::<f32>();
    Outcome {
        mean,
        rms: (spread / track.len() as f32).sqrt(),
        strain: cloth.strain().max,
        ms: ms[ms.len() / 2],
    }
}

fn main() {
    bevy_cloth::solver::set_parallel(false);
    println!("| cloth | model | air | mean place, m | RMS motion, m | strain | ms a step |");
    println!("|---|---|---|---|---:|---:|---:|");
    let cases = [
        ("flag, 5 m/s", Vec3::new(5.0, 0.0, 0.5), true),
        ("flag, 12 m/s", Vec3::new(12.0, 0.0, 1.0), true),
        ("hung, 3 m/s across", Vec3::new(0.0, 0.0, 3.0), false),
        ("hung, still air", Vec3::ZERO, false),
    ];
    for (name, wind, flag) in cases {
        for (model_name, model) in [
            ("XPBD", Model::Xpbd(XpbdParams::default())),
            ("mass-spring", Model::MassSpring),
        ] {
            for update in [AirUpdate::Substep, AirUpdate::Step] {
                let o = run(update, wind, flag, model);
                println!(
                    "| {name} | {model_name} | {update:?} | ({:.3}, {:.3}, {:.3}) | {:.4} | {:.2}% | {:.2} |",
                    o.mean.x,
                    o.mean.y,
                    o.mean.z,
                    o.rms,
                    o.strain * 100.0,
                    o.ms
                );
            }
        }
    }
}
