//! `cloth stability`: where each method fails, the linear and the nonlinear stability maps.

use clap::Args;
use indicatif::ProgressBar;

use crate::args::*;
use crate::charts;
use bevy_cloth::params::Integrator;
use bevy_cloth_lab::stability::{
    self, MASS, MODELS, NONLINEAR_MODELS, NONLINEAR_TIMESTEP, Regime, STIFFNESS, TIMESTEP,
};

#[derive(Args)]
pub(crate) struct StabilityArgs {
    /// The models, comma separated (all when absent).
    #[arg(long, value_delimiter = ',', value_parser = stability_model)]
    pub(crate) models: Vec<&'static str>,
    #[command(flatten)]
    pub(crate) output: Output,
}

pub(crate) fn stability(args: StabilityArgs) -> Result<(), String> {
    let models = or_all(args.models, &MODELS);
    let per_map = STIFFNESS.len() * MASS.len();
    let nonlinear_models = NONLINEAR_MODELS
        .iter()
        .filter(|m| in_list(&models, m))
        .count();
    let bar = progress(
        per_map
            * (models.len() * 4 * TIMESTEP.len()
                + Regime::NONLINEAR.len() * nonlinear_models * NONLINEAR_TIMESTEP.len()),
        "cells",
    );
    let cells = linear_cells(&models, &bar)?;
    let nonlinear = nonlinear_cells(&models, &bar)?;
    bar.finish_and_clear();
    let thresholds = thresholds()?;
    // XPBD's panel shows the mass-spring lattice's explicit bound, which it ignores.
    let lattice = stability::lattice_factor();
    let factors = [lattice, 1.0, 1.0, lattice];
    if let Some(chart) = &args.output.chart {
        charts::stability(chart, &cells, &factors)?;
        let stem = chart
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("stability");
        charts::stability_nonlinear(
            &chart.with_file_name(format!("{stem}_nonlinear.png")),
            &nonlinear,
        )?;
    }
    if args.output.json {
        return print_json(&serde_json::json!({
            "cells": cells,
            "nonlinear": nonlinear,
            "thresholds": thresholds,
            "lattice_factor": factors[0],
        }));
    }
    print_linear(&models, &cells);
    print_nonlinear(&models, &nonlinear);
    print_thresholds(factors[0], &thresholds);
    Ok(())
}

/// Whether `model` (a name, perhaps followed by its variant) is among `models`.
fn in_list(models: &[&str], model: &str) -> bool {
    models.iter().any(|m| model.split(' ').next() == Some(*m))
}

/// The linear regime's maps: every model, integrator and substep rule over the stiffness,
/// mass and timestep grid; a line on stderr per map.
fn linear_cells(
    models: &[&'static str],
    bar: &ProgressBar,
) -> Result<Vec<stability::Cell>, String> {
    let mut cells = Vec::new();
    for &model in models {
        for integrator in Integrator::ALL {
            for auto in [false, true] {
                let (mut failed, mut total) = (0, 0);
                // Said before the map too: a slow model's map takes minutes (a progress
                // bar draws only on a terminal).
                let count = STIFFNESS.len() * MASS.len() * TIMESTEP.len();
                let on = if auto { "on" } else { "off" };
                bar.suspend(|| {
                    eprintln!("{model}, {integrator:?}, auto substeps {on}: {count} cells…")
                });
                for &k in &STIFFNESS {
                    for &m in &MASS {
                        for &dt in &TIMESTEP {
                            let cell =
                                stability::cell(Regime::Linear, model, integrator, auto, k, m, dt)
                                    .map_err(|e| e.to_string())?;
                            failed += cell.failure.is_some() as usize;
                            total += 1;
                            cells.push(cell);
                            bar.inc(1);
                        }
                    }
                }
                bar.suspend(|| {
                    eprintln!(
                        "{model}, {integrator:?}, auto substeps {}: {failed} of {total} cells fail",
                        if auto { "on" } else { "off" }
                    )
                });
            }
        }
    }
    Ok(cells)
}

/// The nonlinear regimes: Verlet with automatic substeps, the claim under test.
fn nonlinear_cells(models: &[&str], bar: &ProgressBar) -> Result<Vec<stability::Cell>, String> {
    let mut nonlinear = Vec::new();
    for regime in Regime::NONLINEAR {
        for model in NONLINEAR_MODELS.into_iter().filter(|m| in_list(models, m)) {
            let mut here = Vec::new();
            for &k in &STIFFNESS {
                for &m in &MASS {
                    for &dt in &NONLINEAR_TIMESTEP {
                        here.push(
                            stability::cell(regime, model, Integrator::Verlet, true, k, m, dt)
                                .map_err(|e| e.to_string())?,
                        );
                        bar.inc(1);
                    }
                }
            }
            let failed = here.iter().filter(|c| c.failure.is_some()).count();
            let persists = here
                .iter()
                .filter(|c| c.persists_at_4x == Some(true))
                .count();
            let capped = here.iter().filter(|c| c.under_resolved).count();
            bar.suspend(|| {
                eprintln!(
                    "{regime:?}, {model}: {failed} of {} cells fail ({persists} still at 4× the substeps), {capped} over the substep cap",
                    here.len()
                )
            });
            nonlinear.extend(here);
        }
    }
    Ok(nonlinear)
}

/// The measured stability thresholds of a single spring and of the lattice, against
/// their predictions.
fn thresholds() -> Result<Vec<stability::Threshold>, String> {
    let mut thresholds = Vec::new();
    for integrator in Integrator::ALL {
        for (k, m) in [(100.0, 1e-3), (1_000.0, 1e-4), (25_000.0, 1e-6)] {
            thresholds.push(stability::single_spring(k, m, integrator).map_err(|e| e.to_string())?);
            thresholds.push(stability::lattice(k, m, integrator).map_err(|e| e.to_string())?);
        }
    }
    Ok(thresholds)
}

/// The linear regime's table.
fn print_linear(models: &[&str], cells: &[stability::Cell]) {
    println!("Linear regime (free 12×12 cloth, 1% perturbation, no gravity, no limiter):");
    println!();
    println!(
        "| model | integrator | substeps | failed cells | over the substep cap | first failure: smallest ω₀·h that failed | largest ω₀·h that ran stable |"
    );
    println!("|---|---|---|---:|---:|---:|---:|");
    for &model in models {
        for integrator in Integrator::ALL {
            for auto in [false, true] {
                let here: Vec<_> = cells
                    .iter()
                    .filter(|c| c.model == model && c.integrator == integrator && c.auto == auto)
                    .collect();
                let wh = |c: &&stability::Cell| c.omega0 * c.timestep;
                let first_fail = here
                    .iter()
                    .filter(|c| c.failure.is_some())
                    .map(wh)
                    .fold(f32::INFINITY, f32::min);
                let last_ok = here
                    .iter()
                    .filter(|c| c.failure.is_none())
                    .map(wh)
                    .fold(0.0, f32::max);
                let failed = here.iter().filter(|c| c.failure.is_some()).count();
                let capped = here.iter().filter(|c| c.under_resolved).count();
                println!(
                    "| {model} | {integrator:?} | {} | {failed} of {} | {capped} | {} | {last_ok:.3} |",
                    if auto { "auto" } else { "1" },
                    here.len(),
                    if first_fail.is_finite() {
                        format!("{first_fail:.3}")
                    } else {
                        "none".into()
                    },
                );
            }
        }
    }
}

/// The nonlinear regimes' table (none when no model of them was asked for).
fn print_nonlinear(models: &[&str], nonlinear: &[stability::Cell]) {
    if !nonlinear.is_empty() {
        println!();
        println!(
            "Nonlinear regimes (Verlet, automatic substeps; limiter on; {} stiffnesses × {} masses × {} timesteps each):",
            STIFFNESS.len(),
            MASS.len(),
            NONLINEAR_TIMESTEP.len()
        );
        println!();
        println!(
            "| regime | model | failed cells | still failing at 4× the substeps (the model's) | stable at 4× (the bound's) | over the substep cap | first failures |"
        );
        println!("|---|---|---:|---:|---:|---:|---|");
        for regime in Regime::NONLINEAR {
            for model in NONLINEAR_MODELS.into_iter().filter(|m| in_list(models, m)) {
                let here: Vec<_> = nonlinear
                    .iter()
                    .filter(|c| c.regime == regime && c.model == model)
                    .collect();
                let failed: Vec<_> = here.iter().filter(|c| c.failure.is_some()).collect();
                let capped = here.iter().filter(|c| c.under_resolved).count();
                let kinds: Vec<String> = failed
                    .iter()
                    .take(3)
                    .map(|c| {
                        format!(
                            "{:?} at k {} N/m, m {:.3} g, h {:.0} ms",
                            c.failure.expect("failed"),
                            c.stiffness,
                            c.mass * 1e3,
                            c.timestep * 1e3
                        )
                    })
                    .collect();
                let persists = failed
                    .iter()
                    .filter(|c| c.persists_at_4x == Some(true))
                    .count();
                println!(
                    "| {regime:?} | {model} | {} of {} | {persists} | {} | {capped} | {} |",
                    failed.len(),
                    here.len(),
                    failed.len() - persists,
                    kinds.join("; ")
                );
            }
        }
    }
}

/// The lattice's factor and the thresholds' table.
fn print_thresholds(lattice_factor: f32, thresholds: &[stability::Threshold]) {
    println!();
    println!(
        "ω_max/√(k/m) of the {0}×{0} lattice: {1:.3}",
        stability::PROBE_SIZE,
        lattice_factor
    );
    println!();
    println!(
        "| case | k, N/m | m, g | ω_max, rad/s | predicted 2/ω_max, ms | auto substeps' bound, ms | measured, ms | measured / predicted |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    for t in thresholds {
        println!(
            "| {} | {} | {:.3} | {:.0} | {:.4} | {:.4} | {:.4} | {:.3} |",
            t.case,
            t.stiffness,
            t.mass * 1e3,
            t.omega_max,
            t.predicted * 1e3,
            t.auto_bound * 1e3,
            t.measured * 1e3,
            t.measured / t.predicted
        );
    }
}
