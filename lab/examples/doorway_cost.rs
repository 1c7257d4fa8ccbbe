//! The doorway example headless: `examples/doorway.rs` as it is (its own `scene` plugin
//! function), with the plugin's defaults, air 0 and 10 m/s, self-collision off and on
//! (and in the gale, accuracy first: `ClothBudget::UNLIMITED`),
//! each run for `SECONDS` of 16 ms fixed steps on one thread. For each: the whole cloth
//! stage a step (`ClothStageStats::step_ms`: the six strips and the work they share),
//! median, 99th percentile and slowest; the largest structural strain of any strip in any
//! step; the steps any strip gave accuracy to the budget; and the substeps (summed over
//! the strips) in the first second against seconds 2–3, before the body sets off.
//!
//! `cargo run -p bevy_cloth_lab --example doorway_cost [-- SECONDS]` (default 120)
use bevy::prelude::*;
use bevy_cloth::headless::WHOLE_STRAIN;
use bevy_cloth::prelude::*;

#[allow(dead_code)]
#[path = "../../examples/doorway.rs"]
mod doorway;

/// Steps in a second of the headless app's 16 ms fixed steps.
const STEPS_A_SECOND: usize = 62;

struct Measured {
    stage_ms: Vec<f32>,
    strain: f32,
    over_budget: usize,
    substeps: Vec<u32>,
    /// The first step at which a strip passed 50% strain or went non-finite.
    broke: Option<usize>,
}

fn measure(setup: doorway::Doorway, budget: ClothBudget, steps: usize) -> Measured {
    let mut app = doorway::headless(setup, budget);
    let mut sims = app.world_mut().query::<&ClothSimulation>();
    let mut m = Measured {
        stage_ms: Vec::with_capacity(steps),
        strain: 0.0,
        over_budget: 0,
        substeps: Vec::with_capacity(steps),
        broke: None,
    };
    for step in 0..steps {
        app.update();
        let stage = app.world().resource::<ClothStageStats>();
        m.stage_ms.push(stage.step_ms);
        m.over_budget += usize::from(stage.over_budget > 0);
        let mut substeps = 0;
        for sim in sims.iter(app.world()) {
            let strain = sim.solver.strain().max;
            let whole = sim.solver.is_finite() && strain <= WHOLE_STRAIN;
            if !whole && m.broke.is_none() {
                m.broke = Some(step);
            }
            m.strain = m.strain.max(strain);
            substeps += sim.solver.substeps();
        }
        m.substeps.push(substeps);
    }
    m
}

fn quantile(sorted: &[f32], q: f32) -> f32 {
    sorted[((sorted.len() - 1) as f32 * q).round() as usize]
}

fn mean(v: &[u32]) -> f32 {
    v.iter().map(|&n| n as f32).sum::<f32>() / v.len().max(1) as f32
}

fn main() {
    let seconds: f32 = std::env::args()
        .nth(1)
        .map(|s| s.parse().expect("seconds"))
        .unwrap_or(120.0);
    let steps = (seconds * STEPS_A_SECOND as f32) as usize;
    assert!(
        steps >= 3 * STEPS_A_SECOND,
        "at least 3 s: the strips settle first"
    );
    bevy_cloth::solver::set_parallel(false);
    println!(
        "| air, m/s | self-collision | budget | gap, cm | stage ms a step: median / p99 / slowest | largest strain | steps over budget | substeps, first second / seconds 2–3 |"
    );
    println!("|---:|---|---|---:|---|---:|---:|---|");
    // The plugin's default budget in every weather, then accuracy first in the gale,
    // then the strips 4.5 cm apart (past the distance self-collision keeps between
    // cloths, the spacing) in the gale.
    let runs = [
        (0.0, false, false, 0.02),
        (0.0, true, false, 0.02),
        (10.0, false, false, 0.02),
        (10.0, true, false, 0.02),
        (10.0, false, true, 0.02),
        (10.0, true, true, 0.02),
        (10.0, true, false, 0.045),
        (10.0, true, true, 0.045),
    ];
    for (wind, self_collision, unlimited, gap) in runs {
        let setup = doorway::Doorway {
            wind,
            self_collision,
            gap,
        };
        let budget = if unlimited {
            ClothBudget::UNLIMITED
        } else {
            ClothBudget::default()
        };
        let mut m = measure(setup, budget, steps);
        let first = mean(&m.substeps[..STEPS_A_SECOND]);
        let rest = mean(&m.substeps[2 * STEPS_A_SECOND..3 * STEPS_A_SECOND]);
        m.stage_ms.sort_by(f32::total_cmp);
        // A run that did not hold together is not timed.
        let cost = match m.broke {
            Some(step) => format!(
                "not timed: a strip passed 50% at {:.1} s",
                step as f32 / STEPS_A_SECOND as f32
            ),
            None => format!(
                "{:.2} / {:.2} / {:.1}",
                quantile(&m.stage_ms, 0.5),
                quantile(&m.stage_ms, 0.99),
                quantile(&m.stage_ms, 1.0)
            ),
        };
        println!(
            "| {wind} | {} | {} | {:.1} | {cost} | {:.1}% | {} of {steps} | {first:.0} / {rest:.0} ({:.2}×) |",
            if self_collision { "on" } else { "off" },
            if unlimited { "none" } else { "default" },
            100.0 * gap,
            100.0 * m.strain,
            m.over_budget,
            first / rest,
        );
    }
}
