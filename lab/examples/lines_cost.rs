//! What one pass of XPBD's stretch constraints costs per constraint, lines against the
//! sweep in one run: the peer bench's swinging cloth (`SIDE`, 64, particles a side,
//! `SUBSTEPS`, 5) with only the structural family on (inextensible, no tethers), so the
//! constraint stage is that family's solve alone; its time per frame (median over 55
//! frames after 5, alternating the two solvers frame by frame) over substeps × structural
//! constraints. Add `ONE=1` for one thread.
//!
//! `cargo run -p bevy_cloth_lab --example lines_cost`
use bevy_cloth::params::{Environment, SpringFamily, XpbdSolve};
use bevy_cloth::solver::ClothSolver;
use bevy_cloth_lab::peers::{FRAME, Hang, ours, ours_params};

fn main() {
    let side: usize = std::env::var("SIDE").map_or(64, |s| s.parse().expect("SIDE"));
    let substeps: u32 = std::env::var("SUBSTEPS").map_or(5, |s| s.parse().expect("SUBSTEPS"));
    bevy_cloth::solver::set_parallel(std::env::var("ONE").is_err());
    let build = |solve: XpbdSolve| -> ClothSolver {
        let mut params = ours_params(substeps, false, solve == XpbdSolve::Lines);
        params.springs.shear = SpringFamily::off(f32::INFINITY);
        params.springs.bend = SpringFamily::off(0.0);
        params.springs.bend_diagonal = SpringFamily::off(0.0);
        ours(side, Hang::Swing, &params).expect("builds")
    };
    let mut cloths = [build(XpbdSolve::Lines), build(XpbdSolve::Sweep)];
    let mut env = Environment::default();
    env.wind.strength = 0.0;
    let constraints = (2 * side * (side - 1)) as f64;
    let mut times: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
    for f in 0..60 {
        for (cloth, times) in cloths.iter_mut().zip(&mut times) {
            cloth.step(FRAME, &env);
            if f >= 5 {
                let t = cloth.last_report().time.constraints.as_secs_f64();
                times.push(t * 1e9 / (constraints * f64::from(substeps)));
            }
        }
    }
    for (name, times) in ["lines", "sweep"].iter().zip(&mut times) {
        times.sort_by(f64::total_cmp);
        let at = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize];
        println!(
            "{name}: {:.2} ns per structural constraint per pass (10th-90th percentile {:.2}-{:.2}), {side}x{side}, {substeps} substeps",
            at(0.5),
            at(0.1),
            at(0.9)
        );
    }
    let strain = |c: &ClothSolver| c.strain().max * 100.0;
    println!(
        "strain after 1 s: lines {:.3}%, sweep {:.3}%",
        strain(&cloths[0]),
        strain(&cloths[1])
    );
}
