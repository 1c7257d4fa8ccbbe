//! `cloth storm`: the flag from calm to a gale, self-collision off and on, each model that
//! takes a fabric; each cell's cost, substeps, strain and whether it held together, with
//! its chart.

use std::path::PathBuf;

use clap::Args;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::args::*;
use crate::charts::{self, Chart, FONT, PALETTE, Result, err, legend, log_range, ticks_125};
use bevy_cloth::prelude::ClothScene;
use bevy_cloth_lab::storm::{self, StormCell, StormModel, WINDS};

#[derive(Args)]
pub(crate) struct StormArgs {
    /// The models, comma separated: mass-spring, xpbd (accuracy first), xpbd-budget (the
    /// plugin's default frame budget). All when absent.
    #[arg(long, value_delimiter = ',', value_parser = storm_model)]
    pub(crate) models: Vec<StormModel>,
    /// The air speeds along the flag, m/s, comma separated (0 to 40). Default: 0, 3, 5,
    /// 10, 15, 20.
    #[arg(long, value_delimiter = ',', value_parser = wind)]
    pub(crate) winds: Vec<f32>,
    /// Simulated seconds a cell.
    #[arg(long, default_value_t = 10.0, value_parser = seconds)]
    pub(crate) seconds: f32,
    /// The flag's scene (its air is set to each speed; the first cloth is reported).
    #[arg(long, default_value_os_t = bevy_cloth::layout::garment::asset_path("scenes/flag.ron"))]
    pub(crate) scene: PathBuf,
    #[command(flatten)]
    pub(crate) output: Output,
}

fn storm_model(text: &str) -> std::result::Result<StormModel, String> {
    let names = StormModel::ALL.map(StormModel::name);
    let name = one_of(text, &names, "model")?;
    Ok(StormModel::ALL[names.iter().position(|n| *n == name).unwrap_or(0)])
}

fn wind(text: &str) -> std::result::Result<f32, String> {
    text.parse::<f32>()
        .ok()
        .filter(|v| (0.0..=40.0).contains(v))
        .ok_or_else(|| format!("`{text}` is not an air speed from 0 to 40 m/s"))
}

pub(crate) fn storm(args: StormArgs) -> std::result::Result<(), String> {
    let scene = ClothScene::load(&args.scene).map_err(|e| e.to_string())?;
    let models = if args.models.is_empty() {
        StormModel::ALL.to_vec()
    } else {
        args.models
    };
    let winds = if args.winds.is_empty() {
        WINDS.to_vec()
    } else {
        args.winds
    };
    let steps = (args.seconds / scene.timestep).round().max(1.0) as usize;
    // Timed on one thread, as the frame budget plans.
    bevy_cloth::solver::set_parallel(false);
    let bar = progress(models.len() * winds.len() * 2, "cells");
    let mut cells = Vec::new();
    for &model in &models {
        for on in [false, true] {
            for &w in &winds {
                cells.push(storm::cell(&scene, model, w, on, steps)?);
                bar.inc(1);
            }
        }
    }
    bar.finish_and_clear();
    bevy_cloth::solver::set_parallel(true);
    if let Some(chart) = &args.output.chart {
        charts::both(chart, (1300, 900), &Storm { cells: &cells })?;
    }
    if args.output.json {
        return print_json(&cells);
    }
    print_table(&cells, args.seconds);
    Ok(())
}

fn print_table(cells: &[StormCell], seconds: f32) {
    println!(
        "The flag, {seconds} s a cell on one thread; a cell that did not hold together (a \
         step non-finite or a spring past 50%) is not timed"
    );
    println!(
        "| model | air, m/s | self-collision | ms a step, median | slowest | most substeps | \
         steps over budget | largest strain | whole |"
    );
    println!("|---|---:|---|---:|---:|---:|---:|---:|---|");
    for c in cells {
        let (median, slowest) = if c.whole {
            (format!("{:.2}", c.median_ms), format!("{:.1}", c.max_ms))
        } else {
            ("–".into(), "–".into())
        };
        println!(
            "| {} | {} | {} | {median} | {slowest} | {} | {} | {:.1}% | {} |",
            c.model.name(),
            c.wind,
            if c.self_collision { "on" } else { "off" },
            c.most_substeps,
            c.steps_over_budget,
            100.0 * c.largest_strain,
            if c.whole { "yes" } else { "**no**" }
        );
    }
}

/// The strain past which a cloth is not whole, %, drawn on the strain panels.
const WHOLE: f64 = 100.0 * bevy_cloth::headless::WHOLE_STRAIN as f64;
/// The default frame budget's milliseconds a step, drawn on the cost panels.
const BUDGET: f64 = 4.0;

/// `docs/storm.png`: the largest strain (top) and the median step (bottom) against the
/// air's speed, self-collision off (left) and on (right), a line per model; a cell that
/// did not hold together is a red cross on the strain panel and left off the cost panel;
/// dashed, the 50% of a whole cloth and the default budget's 4 ms.
struct Storm<'a> {
    cells: &'a [StormCell],
}

impl Chart for Storm<'_> {
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()> {
        let (title, body) = area.split_vertically(40);
        title
            .titled(
                "The flag in a storm: largest strain and median step against the air's speed",
                (FONT, 22),
            )
            .map_err(err)?;
        let panels = body.split_evenly((2, 2));
        let winds = self.cells.iter().map(|c| c.wind as f64);
        let top = winds.clone().fold(1.0f64, f64::max);
        // The 50% past which a cloth is not whole, and the default budget's 4 ms, in view.
        let strains = self.cells.iter().map(|c| 100.0 * c.largest_strain as f64);
        let strain = log_range(strains.chain([WHOLE]));
        let timed = self.cells.iter().filter(|c| c.whole).map(|c| c.median_ms);
        let cost = log_range(timed.chain([BUDGET]));
        for (k, on) in [false, true].into_iter().enumerate() {
            let side = if on { "on" } else { "off" };
            let caption = format!("largest strain, %, self-collision {side}");
            self.panel(&panels[k], caption, (top, strain.clone()), on, true)?;
            let caption = format!("median step, ms, self-collision {side}");
            self.panel(&panels[2 + k], caption, (top, cost.clone()), on, false)?;
        }
        Ok(())
    }
}

impl Storm<'_> {
    /// One panel: strain (`strain`) or cost against the wind, a line per model, and its
    /// dashed line.
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        caption: String,
        (top, ys): (f64, std::ops::Range<f64>),
        on: bool,
        strain: bool,
    ) -> Result<()> {
        let mut chart = ChartBuilder::on(area)
            .caption(caption, (FONT, 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(
                0.0..top * 1.05,
                ys.clone().log_scale().with_key_points(ticks_125(&ys)),
            )
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("air along the flag, m/s")
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 15))
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| charts::tick_label(y))
            .draw()
            .map_err(err)?;
        let line = if strain { WHOLE } else { BUDGET };
        chart
            .draw_series(DashedLineSeries::new(
                [(0.0, line), (top * 1.05, line)],
                4,
                4,
                BLACK.mix(0.5).stroke_width(1),
            ))
            .map_err(err)?;
        let value = |c: &StormCell| {
            if strain {
                100.0 * c.largest_strain as f64
            } else {
                c.median_ms
            }
        };
        for (k, model) in StormModel::ALL.into_iter().enumerate() {
            let color = PALETTE[k + 1];
            let line: Vec<(f64, f64)> = self
                .cells
                .iter()
                .filter(|c| c.model == model && c.self_collision == on && (strain || c.whole))
                .map(|c| (c.wind as f64, value(c)))
                .collect();
            if line.is_empty() {
                continue;
            }
            chart
                .draw_series(LineSeries::new(line.clone(), color.stroke_width(2)))
                .map_err(err)?
                .label(model.name())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
            chart
                .draw_series(line.iter().map(|&p| Circle::new(p, 4, color.filled())))
                .map_err(err)?;
        }
        if strain {
            let broken = self
                .cells
                .iter()
                .filter(|c| c.self_collision == on && !c.whole);
            chart
                .draw_series(
                    broken.map(|c| {
                        Cross::new((c.wind as f64, value(c)), 7, PALETTE[0].stroke_width(3))
                    }),
                )
                .map_err(err)?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft, 14)
    }
}
