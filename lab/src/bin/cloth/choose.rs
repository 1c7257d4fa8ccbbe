//! `cloth choose`: the cheapest configuration of a scene's cloth within an error, or the most accurate within a cost.

use std::path::Path;

use std::path::PathBuf;

use clap::Args;

use crate::args::*;
use bevy_cloth::params::Model;
use bevy_cloth::prelude::*;
use bevy_cloth_lab::accuracy::{self, Case};

#[derive(Args)]
pub(crate) struct ChooseArgs {
    /// The scene file (RON).
    pub(crate) scene: PathBuf,
    /// Which of the scene's cloths (its index).
    #[arg(long, default_value_t = 0)]
    pub(crate) cloth: usize,
    /// The largest error against the converged reference (RMS particle distance over the
    /// cloth's diagonal): picks the cheapest configuration within it.
    #[arg(long = "max-error", value_parser = positive, required_unless_present = "budget_ms", conflicts_with = "budget_ms")]
    pub(crate) max_error: Option<f32>,
    /// The largest cost per step, ms: picks the most accurate configuration within it.
    #[arg(long = "budget-ms", value_parser = positive)]
    pub(crate) budget_ms: Option<f32>,
    /// Simulated seconds per run (at most 3,600).
    #[arg(long, default_value_t = 3.0, value_parser = seconds)]
    pub(crate) seconds: f32,
    /// Timed runs per configuration.
    #[arg(long, default_value_t = 3, value_parser = repeats)]
    pub(crate) repeats: usize,
    /// Writes a copy of the scene with the chosen configuration to FILE (RON).
    #[arg(long, value_name = "FILE")]
    pub(crate) write: Option<PathBuf>,
    /// Prints JSON instead of tables.
    #[arg(long)]
    pub(crate) json: bool,
}

/// `cloth choose`: the accuracy study on the user's scene ([`accuracy::measure`], the
/// reference its cloth as mass-spring at 100× the substeps with a converged limiter),
/// then the configuration the goal asks for ([`bevy_cloth_lab::choose::pick`]).
pub(crate) fn choose(args: ChooseArgs) -> Result<(), String> {
    use bevy_cloth_lab::choose::{self, Goal};
    // Refused before any work.
    let goal = match (args.max_error, args.budget_ms) {
        (Some(e), _) => Goal::MaxError(e as f64),
        (None, Some(b)) => Goal::BudgetMs(b as f64),
        (None, None) => return Err("give --max-error or --budget-ms".into()),
    };
    let scene = ClothScene::load(&args.scene).map_err(|e| e.to_string())?;
    let Some(entry) = scene.cloths.get(args.cloth) else {
        return Err(format!(
            "--cloth {}: the scene has {} cloths",
            args.cloth,
            scene.cloths.len()
        ));
    };
    let name = if entry.name.is_empty() {
        format!("cloth {}", args.cloth)
    } else {
        entry.name.clone()
    };
    // The reference is the cloth's springs as mass-spring, whatever model it runs now.
    let case = Case::new(&name, &scene, args.cloth, args.seconds).map_err(|e| e.to_string())?;
    // Every configuration that applies: the patch model needs a grid, and a fabric in
    // physical units takes only mass-spring and XPBD (the others refuse it).
    let grid = matches!(entry.cloth.shape, ClothShape::Grid { .. });
    let configs: Vec<_> = accuracy::configs(&case.base())
        .into_iter()
        .filter(|c| grid || !matches!(c.params.model, Model::Patches(_)))
        .filter(|c| c.params.validate().is_ok())
        .collect();
    let bar = progress(configs.len(), "configurations");
    let (reference, rows) = accuracy::measure(&case, &configs, args.repeats, |_| bar.inc(1))
        .map_err(|e| e.to_string())?;
    bar.finish_and_clear();
    let timestep = scene.timestep as f64;
    let chosen = choose::pick(&rows, goal, timestep);
    let overrides = chosen
        .map(|i| choose::overrides(args.cloth, &configs[i].params))
        .unwrap_or_default();
    if let (Some(i), Some(file)) = (chosen, &args.write) {
        let mut edited = scene.clone();
        edited.cloths[args.cloth].cloth.params = configs[i].params;
        let text = ron::ser::to_string_pretty(&edited, ron::ser::PrettyConfig::default())
            .map_err(|e| e.to_string())?;
        std::fs::write(file, text).map_err(|e| format!("{}: {e}", file.display()))?;
    }
    if args.json {
        print_json(&serde_json::json!({
            "reference": reference,
            "rows": rows,
            "chosen": chosen,
            "overrides": overrides,
        }))?;
    } else {
        print_reference(&name, &reference);
        print_rows(&rows, goal, timestep, chosen);
        if let Some(i) = chosen {
            let write = args.write.as_deref();
            print_chosen(configs[i].model, &configs[i].label, &overrides, write);
        }
    }
    match chosen {
        Some(_) => Ok(()),
        None => Err(match goal {
            Goal::MaxError(e) => format!("no configuration is within an error of {e}"),
            Goal::BudgetMs(b) => format!("no configuration costs {b} ms per step or less"),
        }),
    }
}

/// The reference's substeps and how converged it is.
fn print_reference(name: &str, reference: &accuracy::Reference) {
    println!(
        "{name}: reference {} substeps per step, its change when halved {:.2e} ({})",
        reference.substeps,
        reference.halving_change,
        if reference.converged {
            "converged"
        } else {
            "not converged: errors below that cannot be told apart"
        }
    );
    println!();
}

/// Every configuration's cost and error, marking those the goal admits and the chosen.
fn print_rows(
    rows: &[accuracy::Row],
    goal: bevy_cloth_lab::choose::Goal,
    timestep: f64,
    chosen: Option<usize>,
) {
    println!("| model | configuration | ms per step | error | within |");
    println!("|---|---|---:|---:|---|");
    for (i, r) in rows.iter().enumerate() {
        let ms = r.ms_per_second.map(|ms| ms * timestep);
        let within = ms.zip(r.error).is_some_and(|(ms, e)| goal.admits(ms, e));
        println!(
            "| {} | {} | {} | {} | {}{} |",
            r.model,
            r.label,
            ms.map_or("-".into(), |ms| format!("{ms:.3}")),
            r.error.map_or("failed".into(), |e| format!("{e:.2e}")),
            if within { "yes" } else { "" },
            if chosen == Some(i) { " ← chosen" } else { "" }
        );
    }
    println!();
}

/// The chosen configuration, the `--set` overrides that give it, and the file written.
fn print_chosen(model: &str, label: &str, overrides: &[String], write: Option<&Path>) {
    println!("chosen: {model} {label}");
    println!("overrides:");
    for o in overrides {
        println!("  --set '{o}'");
    }
    if let Some(file) = write {
        println!("wrote {}", file.display());
    }
}
