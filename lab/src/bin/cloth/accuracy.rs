//! `cloth accuracy`: speed against accuracy, against a converged reference.

use clap::Args;

use crate::args::*;
use crate::charts;
use bevy_cloth::prelude::*;
use bevy_cloth_lab::accuracy::{self, Case};

#[derive(Args)]
pub(crate) struct AccuracyArgs {
    /// The scenes, comma separated: curtain, curtain-wind, card (all when absent).
    #[arg(long, value_delimiter = ',', value_parser = accuracy_scene)]
    pub(crate) scenes: Vec<&'static str>,
    /// Simulated seconds per run (at most 3,600).
    #[arg(long, default_value_t = 3.0, allow_negative_numbers = true, value_parser = seconds)]
    pub(crate) seconds: f32,
    /// Timed runs per configuration.
    #[arg(long, default_value_t = 5, value_parser = repeats)]
    pub(crate) repeats: usize,
    #[command(flatten)]
    pub(crate) output: Output,
}

/// The accuracy study's cases: the curtain without and with its wind, and the card.
pub(crate) fn accuracy_cases(names: &[&str], seconds: f32) -> Result<Vec<Case>, String> {
    let load = |file: &str| {
        let path = bevy_cloth::layout::garment::asset_path(&format!("scenes/{file}"));
        ClothScene::load(&path).map_err(|e| e.to_string())
    };
    let mut cases = Vec::new();
    for &name in names {
        let case = match name {
            "curtain" => {
                let mut scene = load("curtain.ron")?;
                scene.environment.wind.strength = 0.0;
                Case::new(name, &scene, 0, seconds)
            }
            "curtain-wind" => Case::new(name, &load("curtain.ron")?, 0, seconds),
            // The card scene's mass-spring card is the reference.
            "card" => Case::new(name, &load("card.ron")?, 1, seconds),
            other => {
                return Err(format!(
                    "--scenes: no scene `{other}` (curtain, curtain-wind, card)"
                ));
            }
        };
        cases.push(case.map_err(|e| e.to_string())?);
    }
    Ok(cases)
}

pub(crate) fn accuracy(args: AccuracyArgs) -> Result<(), String> {
    let (seconds, repeats) = (args.seconds, args.repeats);
    let names = or_all(args.scenes, &ACCURACY_SCENES);
    let cases = accuracy_cases(&names, seconds)?;
    let mut references = Vec::new();
    let mut rows = Vec::new();
    let total = cases
        .iter()
        .map(|c| accuracy::configs(&c.base()).len())
        .sum();
    let bar = progress(total, "configurations");
    for case in &cases {
        let configs = accuracy::configs(&case.base());
        bar.suspend(|| {
            eprintln!(
                "{}: reference and {} configurations",
                case.name,
                configs.len()
            )
        });
        let (reference, case_rows) = accuracy::measure(case, &configs, repeats, |r| {
            bar.suspend(|| {
                eprintln!(
                    "  {:<15} {:<36} {:>10} ms/s  error {}",
                    r.model,
                    r.label,
                    r.ms_per_second.map_or("-".into(), |ms| format!("{ms:.1}")),
                    r.error.map_or("failed".into(), |e| format!("{e:.2e}"))
                )
            });
            bar.inc(1);
        })
        .map_err(|e| e.to_string())?;
        references.push(reference);
        rows.extend(case_rows);
    }
    bar.finish_and_clear();
    if let Some(chart) = &args.output.chart {
        charts::accuracy(chart, &rows)?;
    }
    if args.output.json {
        return print_json(&serde_json::json!({ "references": references, "rows": rows }));
    }
    print_tables(&references, &rows, repeats);
    Ok(())
}

/// The references' table, then every configuration's cost and errors.
fn print_tables(references: &[accuracy::Reference], rows: &[accuracy::Row], repeats: usize) {
    println!(
        "| scene | reference substeps per step | its change when halved | smallest error reported | converged (< 5%) |"
    );
    println!("|---|---:|---:|---:|---|");
    for r in references {
        println!(
            "| {} | {} | {:.2e} | {:.2e} | {} |",
            r.scene,
            r.substeps,
            r.halving_change,
            r.smallest_error,
            if r.converged { "yes" } else { "no" }
        );
    }
    println!();
    println!(
        "| scene | model | configuration | ms per simulated s, median [fastest–slowest of {repeats}] | substeps | error | final drape error | max strain | energy drift | Pareto |"
    );
    println!("|---|---|---|---:|---:|---:|---:|---:|---:|---|");
    for r in rows {
        let error = match (r.error, r.failed_at) {
            (Some(e), _) => format!("{e:.2e}"),
            (None, Some(t)) => format!("fails at {t:.2} s"),
            (None, None) => "-".into(),
        };
        let time = match (r.ms_per_second, r.ms_range) {
            (Some(ms), Some((lo, hi))) => format!("{ms:.1} [{lo:.1}–{hi:.1}]"),
            _ => "-".into(),
        };
        println!(
            "| {} | {} | {} | {time} | {:.1} | {error} | {} | {:.1}% | {} | {} |",
            r.scene,
            r.model,
            r.label,
            r.substeps,
            r.final_error.map_or("-".into(), |e| format!("{e:.2e}")),
            r.max_strain * 100.0,
            r.energy_drift.map_or("-".into(), |e| format!("{e:+.2e}")),
            if r.pareto { "yes" } else { "" }
        );
    }
}
