//! Value parsers and what several verbs share: the `--chart` and `--json` options,
//! progress bars, `or_all`, the fabrics a verb is asked for.

use std::path::PathBuf;

use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};

use crate::charts;
use bevy_cloth::params::ModelKind;
use bevy_cloth::prelude::*;
use bevy_cloth_lab::BENCH_MODELS;
use bevy_cloth_lab::peers::{Hang, PEER_SOLVERS};
use bevy_cloth_lab::stability::MODELS;

/// What every measuring verb can write besides its tables.
#[derive(Args)]
pub(crate) struct Output {
    /// Prints JSON instead of tables.
    #[arg(long)]
    pub(crate) json: bool,
    /// Draws the chart to FILE.png (and an SVG beside it).
    #[arg(long, value_name = "FILE.png", value_parser = chart_path)]
    pub(crate) chart: Option<PathBuf>,
}

pub(crate) fn model_kind(text: &str) -> Result<ModelKind, String> {
    text.parse().map_err(|e: ClothError| e.to_string())
}

pub(crate) fn at_least_one(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!("`{text}` is not a whole number of at least 1")),
    }
}

/// A whole number from 1 to `limit` (`what` names the limit in `limits.rs`).
pub(crate) fn count_within(text: &str, limit: usize, what: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(n) if (1..=limit).contains(&n) => Ok(n),
        _ => Err(format!(
            "`{text}` is not a whole number from 1 to {limit} (limits::{what})"
        )),
    }
}

pub(crate) fn steps(text: &str) -> Result<usize, String> {
    count_within(text, bevy_cloth::limits::MAX_STEPS, "MAX_STEPS")
}

pub(crate) fn repeats(text: &str) -> Result<usize, String> {
    count_within(text, bevy_cloth::limits::MAX_REPEATS, "MAX_REPEATS")
}

pub(crate) fn particles(text: &str) -> Result<usize, String> {
    count_within(text, bevy_cloth::limits::MAX_PARTICLES, "MAX_PARTICLES")
}

pub(crate) fn seconds(text: &str) -> Result<f32, String> {
    let (seconds, limit) = (positive(text)?, bevy_cloth::limits::MAX_SECONDS);
    if seconds > limit {
        return Err(format!(
            "`{text}` is more than {limit} s (limits::MAX_SECONDS)"
        ));
    }
    Ok(seconds)
}

pub(crate) fn minutes(text: &str) -> Result<f32, String> {
    let minutes = positive(text)?;
    if minutes > 1440.0 {
        return Err(format!("`{text}` is more than a day (1,440 minutes)"));
    }
    Ok(minutes)
}

pub(crate) fn positive(text: &str) -> Result<f32, String> {
    text.parse::<f32>()
        .ok()
        .filter(|x| *x > 0.0 && x.is_finite())
        .ok_or_else(|| format!("`{text}` is not a positive number"))
}

/// One of `known`, or an error naming the known ones.
pub(crate) fn one_of(
    text: &str,
    known: &[&'static str],
    what: &str,
) -> Result<&'static str, String> {
    known
        .iter()
        .find(|k| **k == text)
        .copied()
        .ok_or_else(|| format!("no {what} `{text}` ({})", known.join(", ")))
}

pub(crate) fn seed_model(text: &str) -> Result<&'static str, String> {
    one_of(text, &BENCH_MODELS, "model")
}

pub(crate) fn stability_model(text: &str) -> Result<&'static str, String> {
    one_of(text, &MODELS, "model")
}

pub(crate) fn side(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(n) if (2..=512).contains(&n) => Ok(n),
        _ => Err(format!("`{text}` is not a side from 2 to 512 particles")),
    }
}

pub(crate) fn hang(text: &str) -> Result<Hang, String> {
    match text {
        "top-row" => Ok(Hang::TopRow),
        "corners" => Ok(Hang::Corners),
        "swing" => Ok(Hang::Swing),
        _ => Err(format!("no hang `{text}` (top-row, corners, swing)")),
    }
}

pub(crate) fn peer_solver(text: &str) -> Result<&'static str, String> {
    one_of(text, &PEER_SOLVERS, "solver")
}

pub(crate) fn accuracy_scene(text: &str) -> Result<&'static str, String> {
    one_of(text, &ACCURACY_SCENES, "scene")
}

pub(crate) fn chart_path(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    charts::check_path(&path)?;
    Ok(path)
}

/// The models asked for, or all of `known` when none were.
pub(crate) fn or_all(asked: Vec<&'static str>, known: &[&'static str]) -> Vec<&'static str> {
    if asked.is_empty() {
        known.to_vec()
    } else {
        asked
    }
}

/// A progress bar on stderr for a long verb, counting `unit`s (drawn only on a terminal;
/// the verb's own summary lines go through [`ProgressBar::suspend`], so they are printed
/// either way).
pub(crate) fn progress(total: usize, unit: &str) -> ProgressBar {
    let bar = ProgressBar::new(total as u64);
    let template = format!("[{{bar:30}}] {{pos}}/{{len}} {unit}, {{elapsed}} (about {{eta}} left)");
    if let Ok(style) = ProgressStyle::with_template(&template) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

/// The accuracy study's scenes.
pub(crate) const ACCURACY_SCENES: [&str; 3] = ["curtain", "curtain-wind", "card"];

pub(crate) fn print_json<T: serde::Serialize>(value: &T) -> Result<(), String> {
    let json = serde_json::to_string_pretty(value).map_err(|e| e.to_string())?;
    println!("{json}");
    Ok(())
}

/// The presets `--fabric NAME` or `--all` name.
pub(crate) fn chosen_fabrics(
    fabric: &Option<String>,
    all: bool,
) -> Result<Vec<(String, bevy_cloth::fabric::Fabric)>, String> {
    use bevy_cloth::fabric::Fabric;
    match (fabric, all) {
        (_, true) => Ok(Fabric::PRESETS
            .iter()
            .map(|&(n, f)| (n.to_string(), f))
            .collect()),
        (Some(name), false) => Ok(vec![(
            name.clone(),
            Fabric::named(name).map_err(|e| e.to_string())?,
        )]),
        (None, false) => Err("give --fabric NAME or --all".into()),
    }
}
