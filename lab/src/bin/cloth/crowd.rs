//! `cloth crowd`: the crowd example's headless twin, timed on one thread and on the pool.

use clap::Args;

use bevy_cloth::prelude::*;
use bevy_cloth_lab::crowd::{self, CrowdSize};

#[derive(Args)]
pub(crate) struct CrowdArgs {
    /// Characters, each with a cape and a skirt (1 to 400).
    #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u32).range(1..=400))]
    pub(crate) characters: u32,
    /// Frames timed, after the warm-up (1 to 100,000).
    #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub(crate) frames: u32,
    /// Frames run before timing (the cloths settle on their bodies).
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(0..=100_000))]
    pub(crate) warm: u32,
    /// Without the wind zone (no air model on the cloths).
    #[arg(long)]
    pub(crate) calm: bool,
    /// Prints the JSON object instead of a table.
    #[arg(long)]
    pub(crate) json: bool,
    /// Every cloth's parameters, as a scene file writes them (RON, fields left out take
    /// their defaults), e.g. `(model: Xpbd((max_stretch_error: 0.03)))`. Default: the
    /// example's (`crowd::params`: mass-spring, the limiter with a 1% tolerance).
    #[arg(long)]
    pub(crate) params: Option<String>,
    /// Milliseconds all the crowd's cloths may take in one step, shared among them as
    /// the plugin's `ClothBudget` shares them (at its planned cost a particle-substep;
    /// only XPBD at automatic substeps is capped). Default: none, accuracy first.
    #[arg(long)]
    pub(crate) budget_ms: Option<f32>,
}

pub(crate) fn crowd(args: CrowdArgs) -> Result<(), String> {
    let size = CrowdSize {
        characters: args.characters as usize,
        wind: !args.calm,
        ..CrowdSize::default()
    };
    let params = match &args.params {
        Some(text) => {
            let params: ClothParams = ron::from_str(text).map_err(|e| format!("--params: {e}"))?;
            params.validate().map_err(|e| format!("--params: {e}"))?;
            params
        }
        None => crowd::params(),
    };
    let budget = match args.budget_ms {
        Some(ms) => {
            let budget = ClothBudget {
                milliseconds: Some(ms),
                ..ClothBudget::default()
            };
            budget.validate().map_err(|e| format!("--budget-ms: {e}"))?;
            Some(budget)
        }
        None => None,
    };
    let frames = (args.warm as usize, args.frames as usize);
    let cost = crowd::measure(size, &params, budget, frames);
    if !cost.whole {
        let gave = if cost.budget_ms.is_some() {
            format!(
                "; {} of {} cloth steps over budget",
                cost.gave.total(),
                cost.gave.cloth_steps
            )
        } else {
            String::new()
        };
        return Err(format!(
            "a cloth of the crowd did not hold together (a step non-finite or a spring past \
             {:.0}%; the most in a timed frame {:.1}%{gave}): not timed",
            100.0 * bevy_cloth::headless::WHOLE_STRAIN,
            cost.strain[2] * 100.0
        ));
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string(&cost).map_err(|e| e.to_string())?
        );
        return Ok(());
    }
    print_table(&cost, &args);
    Ok(())
}

/// The crowd's cost as a table: its make-up, each part of a frame on one thread and on
/// the pool, the rest of the frame's share and placing's.
fn print_table(cost: &crowd::CrowdCost, args: &CrowdArgs) {
    let size = cost.size;
    println!(
        "{} characters, {} cloths: {} particles simulated, {} vertices drawn; {}; {} frames after \
         {} warm-up, {} teleports; {}–{} substeps; largest strain in a frame: median {:.1}%, \
         most {:.1}%",
        size.characters,
        2 * size.characters,
        cost.particles,
        cost.drawn,
        if size.wind { "a wind zone" } else { "calm" },
        args.frames,
        args.warm,
        cost.teleports,
        cost.substeps.0,
        cost.substeps.1,
        cost.strain[0] * 100.0,
        cost.strain[2] * 100.0
    );
    println!(
        "| ms a frame, median [min–max] | one thread | {} threads | speed-up |",
        cost.threads
    );
    println!("|---|---:|---:|---:|");
    let row = |name: &str, one: [f64; 3], pool: [f64; 3]| {
        println!(
            "| {name} | {:.2} [{:.2}–{:.2}] | {:.2} [{:.2}–{:.2}] | {:.2}× |",
            one[0],
            one[1],
            one[2],
            pool[0],
            pool[1],
            pool[2],
            one[0] / pool[0]
        );
    };
    let (one, pool) = (cost.one_thread, cost.pool);
    row("cloth step", one.step, pool.step);
    println!(
        "| cloth step, 99th percentile | {:.2} | {:.2} | |",
        one.step_p99, pool.step_p99
    );
    row(
        "driving (pins, targets, colliders, wind)",
        one.drive,
        pool.drive,
    );
    row("drawing (normals, proxies)", one.draw, pool.draw);
    println!(
        "the rest of the frame against the step (pool): {:.1}% (driving {:.1}%, drawing {:.1}%)",
        100.0 * (pool.drive[0] + pool.draw[0]) / pool.step[0],
        100.0 * pool.drive[0] / pool.step[0],
        100.0 * pool.draw[0] / pool.step[0]
    );
    println!(
        "of the drawing on one thread, placing the proxies' {:.1}× as many vertices: {:.2} ms \
         [{:.2}–{:.2}], {:.1}% of the step (the rest is the simulation's normals, which a cloth \
         drawn without a proxy needs too)",
        cost.drawn as f64 / cost.particles as f64,
        one.place[0],
        one.place[1],
        one.place[2],
        100.0 * one.place[0] / one.step[0]
    );
    if let Some(ms) = cost.budget_ms {
        print_gave(ms, &cost.gave);
    }
}

/// Which cloths gave accuracy to keep to the budget of `ms`, and how much.
fn print_gave(ms: f32, gave: &crowd::Gave) {
    if gave.cappable == 0 {
        println!(
            "a budget of {ms} ms a step: it caps only XPBD at automatic substeps, and none of \
             these cloths is; each took what its stability asks for"
        );
        return;
    }
    let (capes, skirts) = gave.cloths();
    let within = if gave.total() < gave.cloth_steps {
        format!("{:.1}%", 100.0 * gave.strain.1)
    } else {
        "none".into()
    };
    println!(
        "a budget of {ms} ms a step shared by the cloths: {} of {} cloth steps over budget \
         ({:.1}%), by {capes} capes and {skirts} skirts; the solver's largest strain {:.1}% \
         in a step over budget, {within} in a step within",
        gave.total(),
        gave.cloth_steps,
        100.0 * gave.total() as f64 / gave.cloth_steps.max(1) as f64,
        100.0 * gave.strain.0,
    );
}
