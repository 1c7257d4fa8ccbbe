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
    let cost = crowd::measure(size, &params, args.warm as usize, args.frames as usize);
    let health = cost.strain[2];
    if !cost.stable {
        return Err(format!(
            "a cloth of the crowd failed (largest strain {:.1}%): not timed",
            health * 100.0
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
}
