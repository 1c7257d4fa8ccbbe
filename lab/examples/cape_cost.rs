//! A game's cape, headless: 16 × 26 particles (416) of denim, 3.5 cm apart, its top row
//! held round the back of a capsule (radius 0.3 m, 1.6 m tall) that runs a circle of 3 m
//! radius at 4 m/s, through still air, kept out of the capsule. Two seconds to settle into
//! the run, then three measured: the cost of a step (median and p10–p90 of 188 steps, one
//! thread) and the structural strain (the mean over the steps of each step's largest, and
//! the largest of all), on lines and on the sweep at their automatic substeps, and a
//! reference on lines at fixed 200 and 400 substeps (which agree: it has converged).
//!
//! `cargo run -p bevy_cloth_lab --example cape_cost`
use std::time::Instant;

use bevy::math::{Affine3A, Quat, Vec3};
use bevy_cloth::fabric::Fabric;
use bevy_cloth::layout::shape::{ClothPins, ClothShape};
use bevy_cloth::params::{Air, ClothParams, Environment, Model, Substeps, XpbdParams, XpbdSolve};
use bevy_cloth::solver::{Collider, ColliderShape, Motion};

const DT: f32 = 0.016;
const RADIUS: f32 = 0.3;
const HALF_LENGTH: f32 = 0.5;
const LOOP: f32 = 3.0;
const SPEED: f32 = 4.0;
const WIDTH: u32 = 16;
const HEIGHT: u32 = 26;
const SPACING: f32 = 0.035;
const SETTLE: usize = 125;
const MEASURED: usize = 188;

/// The body's pose at time `t`: on the circle, facing along it (its −z forward).
fn body(t: f32) -> (Quat, Vec3) {
    let angle = SPEED / LOOP * t;
    let at = Vec3::new(LOOP * angle.cos(), RADIUS + HALF_LENGTH, LOOP * angle.sin());
    let forward = Vec3::new(-angle.sin(), 0.0, angle.cos());
    (Quat::from_rotation_arc(Vec3::NEG_Z, forward), at)
}

/// Where the top row's particle `i` is held, in the body's frame: on an arc 3 cm out
/// from the back (+z), a spacing apart, at shoulder height.
fn collar(i: u32) -> Vec3 {
    let r = RADIUS + 0.03;
    let angle = (i as f32 - (WIDTH - 1) as f32 * 0.5) * SPACING / r;
    Vec3::new(r * angle.sin(), 0.42, r * angle.cos())
}

struct Run {
    substeps: Vec<u32>,
    ms: Vec<f64>,
    max_strain: Vec<f32>,
    /// Each stage's time summed over the measured steps, s: begin, forces, prediction,
    /// constraints, contact, end.
    stages: [f64; 6],
}

fn run(solve: XpbdSolve, substeps: Substeps) -> Run {
    let params = ClothParams {
        model: Model::Xpbd(XpbdParams {
            solve,
            ..XpbdParams::default()
        }),
        fabric: Some(Fabric::DENIM),
        substeps,
        ..ClothParams::seeds()
    };
    let (turn, at) = body(0.0);
    let frame = Affine3A::from_rotation_translation(turn, at + turn * collar(WIDTH / 2));
    let shape = ClothShape::Grid {
        width: WIDTH,
        height: HEIGHT,
        spacing: SPACING,
    };
    let mut cloth = shape
        .build_solver(&ClothPins::None, &params, frame)
        .expect("the cape builds");
    let env = Environment {
        air: Some(Air::default()),
        ..Environment::default()
    };
    let mut out = Run {
        substeps: Vec::new(),
        ms: Vec::new(),
        max_strain: Vec::new(),
        stages: [0.0; 6],
    };
    let mut before = body(0.0);
    for step in 1..=SETTLE + MEASURED {
        let now = body(step as f32 * DT);
        for i in 0..WIDTH {
            cloth
                .attach(i, now.1 + now.0 * collar(i))
                .expect("a top-row particle");
        }
        let up = now.0 * Vec3::Y * HALF_LENGTH;
        cloth.set_colliders([Collider {
            shape: ColliderShape::Capsule(bevy_cloth::solver::shapes::Capsule {
                a: now.1 - up,
                b: now.1 + up,
                radius: RADIUS,
            }),
            thickness: 0.01,
            friction: 0.3,
            motion: Motion::between(before, now, DT),
        }]);
        before = now;
        let start = Instant::now();
        let report = cloth.step(DT, &env);
        let ms = start.elapsed().as_secs_f64() * 1e3;
        assert!(report.finite, "the cape stays finite");
        if step > SETTLE {
            out.substeps.push(report.substeps);
            out.ms.push(ms);
            out.max_strain.push(cloth.strain().max);
            let t = report.time;
            let stages = [
                t.begin,
                t.forces,
                t.integrate,
                t.constraints,
                t.contact,
                t.end,
            ];
            for (sum, d) in out.stages.iter_mut().zip(stages) {
                *sum += d.as_secs_f64();
            }
        }
    }
    out
}

fn main() {
    bevy_cloth::solver::set_parallel(false);
    let auto = Substeps::Auto { max: 8192 };
    let runs = [
        ("lines, automatic", XpbdSolve::Lines, auto),
        ("sweep, automatic", XpbdSolve::Sweep, auto),
        (
            "lines, fixed 200 (reference)",
            XpbdSolve::Lines,
            Substeps::Fixed(200),
        ),
        (
            "lines, fixed 400 (reference)",
            XpbdSolve::Lines,
            Substeps::Fixed(400),
        ),
    ];
    println!(
        "| run | substeps (median) | ms per step, median [p10–p90] | strain: mean of each step's max | largest |"
    );
    println!("|---|---:|---:|---:|---:|");
    let mut shares = Vec::new();
    for (name, solve, substeps) in runs {
        let mut r = run(solve, substeps);
        r.ms.sort_by(f64::total_cmp);
        r.substeps.sort_unstable();
        let at = |q: f64| r.ms[((r.ms.len() - 1) as f64 * q).round() as usize];
        let mean = r.max_strain.iter().sum::<f32>() / r.max_strain.len() as f32;
        let largest = r.max_strain.iter().copied().fold(f32::MIN, f32::max);
        println!(
            "| {name} | {} | {:.3} [{:.3}–{:.3}] | {:.3}% | {:.3}% |",
            r.substeps[r.substeps.len() / 2],
            at(0.5),
            at(0.1),
            at(0.9),
            mean * 100.0,
            largest * 100.0
        );
        shares.push((name, r.stages));
    }
    println!("\nWhere a step's time goes (share of the summed stages):");
    for (name, stages) in shares {
        let total: f64 = stages.iter().sum();
        let names = [
            "begin",
            "forces",
            "prediction",
            "constraints",
            "contact",
            "end",
        ];
        let parts: Vec<String> = names
            .iter()
            .zip(stages)
            .map(|(n, s)| format!("{n} {:.0}%", 100.0 * s / total))
            .collect();
        println!("- {name}: {}", parts.join(", "));
    }
}
