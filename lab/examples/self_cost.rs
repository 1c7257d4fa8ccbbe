//! Where self-collision's time goes on the peer bench's swinging cloth: the step's
//! stages (median over 55 frames after 5) with self-collision off and on, at `SIDE`
//! (64) particles a side and `SUBSTEPS` (5).
//!
//! `cargo run -p bevy_cloth_lab --example self_cost`
use bevy_cloth::params::{Environment, SelfCollision};
use bevy_cloth_lab::peers::{FRAME, Hang, ours, ours_params};
use std::time::Duration;

fn main() {
    let side: usize = std::env::var("SIDE").map_or(64, |s| s.parse().expect("SIDE"));
    let substeps: u32 = std::env::var("SUBSTEPS").map_or(5, |s| s.parse().expect("SUBSTEPS"));
    bevy_cloth::solver::set_parallel(std::env::var("ONE").is_err());
    for on in [false, true] {
        let mut params = ours_params(substeps, true, false);
        if on {
            params.self_collision = SelfCollision::on();
        }
        let mut cloth = ours(side, Hang::Swing, &params).expect("builds");
        let mut env = Environment::default();
        env.wind.strength = 0.0;
        let mut rows: Vec<[Duration; 4]> = Vec::new();
        for f in 0..60 {
            cloth.step(FRAME, &env);
            let t = cloth.last_report().time;
            if f >= 5 {
                rows.push([t.begin, t.constraints, t.self_contact, t.total()]);
            }
        }
        let median = |k: usize| {
            let mut v: Vec<f64> = rows.iter().map(|r| r[k].as_secs_f64() * 1e3).collect();
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        println!(
            "self-collision {}: begin {:.3} ms, constraints {:.3}, self {:.3}, total {:.3} (pairs {}, listed {} times in 60 steps)",
            if on { "on " } else { "off" },
            median(0),
            median(1),
            median(2),
            median(3),
            cloth.self_collision_pairs(),
            cloth.self_collision_listings()
        );
    }
}
