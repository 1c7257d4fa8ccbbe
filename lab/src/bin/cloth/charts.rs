//! The `cloth` command line's charts, drawn with `plotters` to PNG and SVG side by side
//! (`docs/bench.png` and `docs/bench.svg`). Text uses egui's bundled Ubuntu Light, so no
//! system font is needed.

use std::ops::Range;
use std::path::Path;

use bevy_cloth::params::Integrator;
use bevy_cloth_lab::accuracy::Row;
use bevy_cloth_lab::fps::{AppFrame, MASLOVA_FPS};
use bevy_cloth_lab::peers::PeerRow;
use bevy_cloth_lab::stability::{Cell, MODELS, NONLINEAR_MODELS, Regime};
use bevy_cloth_lab::{BENCH_MODELS, BenchCell, SEED_COUNTS, SEED_MS};
use plotters::coord::Shift;
use plotters::coord::cartesian::Cartesian2d;
use plotters::coord::combinators::{LogCoord, WithKeyPoints};
use plotters::prelude::*;

pub(crate) const FONT: &str = "sans-serif";
pub(crate) const PALETTE: [RGBColor; 6] = [
    RGBColor(200, 40, 40),
    RGBColor(30, 100, 200),
    RGBColor(30, 150, 60),
    RGBColor(210, 130, 0),
    RGBColor(130, 50, 170),
    RGBColor(0, 160, 170),
];

pub(crate) type Result<T> = std::result::Result<T, String>;

fn register_font() -> Result<()> {
    plotters::style::register_font(FONT, FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT)
        .map_err(|_| "the bundled chart font could not be read".to_string())
}

/// A chart that draws itself on any plotters backend: the PNG and the SVG.
pub(crate) trait Chart {
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()>;
}

/// Draws `chart` to `png` (checked by [`check_path`] before measuring) and to the same
/// name with `.svg`.
pub(crate) fn both(png: &Path, size: (u32, u32), chart: &impl Chart) -> Result<()> {
    register_font()?;
    if let Some(dir) = png.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("--chart {}: {e}", png.display()))?;
    }
    {
        let root = BitMapBackend::new(png, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        chart.draw(&root)?;
        root.present()
            .map_err(|e| format!("--chart {}: {e}", png.display()))?;
    }
    let svg = png.with_extension("svg");
    let root = SVGBackend::new(&svg, size).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    chart.draw(&root)?;
    root.present()
        .map_err(|e| format!("--chart {}: {e}", svg.display()))?;
    Ok(())
}

/// Checks a `--chart` path before anything is measured.
pub fn check_path(png: &Path) -> Result<()> {
    if png.extension().and_then(|e| e.to_str()) != Some("png") {
        return Err(format!(
            "--chart {}: the file must end in .png (an .svg is written beside it)",
            png.display()
        ));
    }
    // Refused before the measurement, not after it: a folder, or a file in a folder
    // that is not there.
    if png.is_dir() {
        return Err(format!("--chart {}: a folder, not a file", png.display()));
    }
    let folder = png.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(folder) = folder.filter(|f| !f.is_dir()) {
        return Err(format!(
            "--chart {}: no folder {} to write it in",
            png.display(),
            folder.display()
        ));
    }
    Ok(())
}

/// A log range around `values` with some margin.
pub(crate) fn log_range(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return 0.1..10.0;
    }
    lo / 1.6..hi * 1.6
}

/// Ticks at 1, 2 and 5 times the powers of ten inside `range` (plotters' log axes label
/// only the powers, which leaves a narrow range bare).
pub(crate) fn ticks_125(range: &Range<f64>) -> Vec<f64> {
    let (lo, hi) = (
        range.start.log10().floor() as i32,
        range.end.log10().ceil() as i32,
    );
    (lo..=hi)
        .flat_map(|e| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(e)))
        .filter(|v| range.contains(v))
        .collect()
}

/// A tick label with as many decimals as the value needs.
pub(crate) fn tick_label(v: &f64) -> String {
    let decimals = (-v.log10().floor()).max(0.0) as usize;
    format!("{v:.decimals$}")
}

/// The legend of a chart's labelled series at `position`, in `size`-point text on a
/// translucent white box.
pub(crate) fn legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    size: u32,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(position)
        .label_font((FONT, size))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}

/// A log-log coordinate system with 1-2-5 ticks (see [`ticks_125`]).
type LogLog = Cartesian2d<WithKeyPoints<LogCoord<f64>>, WithKeyPoints<LogCoord<f64>>>;

/// A captioned log-log panel over `ranges` with its grid and the axes named `(x, y)`:
/// the frame of the accuracy and the peers charts.
fn log_log_panel<'a, DB: DrawingBackend>(
    panel: &'a DrawingArea<DB, Shift>,
    caption: String,
    (xs, ys): (Range<f64>, Range<f64>),
    (x, y): (&str, &str),
) -> Result<ChartContext<'a, DB, LogLog>> {
    let (x_ticks, y_ticks) = (ticks_125(&xs), ticks_125(&ys));
    let mut chart = ChartBuilder::on(panel)
        .caption(caption, (FONT, 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(65)
        .build_cartesian_2d(
            xs.log_scale().with_key_points(x_ticks),
            ys.log_scale().with_key_points(y_ticks),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x)
        .y_desc(y)
        .x_label_formatter(&tick_label)
        .y_label_formatter(&tick_label)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 16))
        .draw()
        .map_err(err)?;
    Ok(chart)
}

pub(crate) fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

// ----- bench --------------------------------------------------------------------------

/// `docs/bench.png`: ms per step against particles, log-log, one line per model, seed
/// 000's fig. 23 as hollow markers of the same colour; the full app's ms per frame and
/// Maslova's (from its frames per second) in black.
pub fn bench(png: &Path, cells: &[BenchCell], app: &[AppFrame]) -> Result<()> {
    both(png, (1100, 750), &Bench { cells, app })
}

/// The bench models' names in the legend, in the order of `BENCH_MODELS`.
const BENCH_NAMES: [&str; 6] = [
    "1 mass-spring",
    "2 shape matching (α = 1280 N/m)",
    "3a patches 2×2",
    "3b patches 4×4",
    "3c patches 8×8",
    "x XPBD (auto substeps)",
];

struct Bench<'a> {
    cells: &'a [BenchCell],
    app: &'a [AppFrame],
}

impl Chart for Bench<'_> {
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()> {
        let Bench { cells, app } = *self;
        let ys = cells
            .iter()
            .filter_map(|c| c.ms_per_step)
            .chain(SEED_MS.iter().flatten().copied())
            .chain(app.iter().filter_map(|a| a.ms_per_frame))
            .chain(MASLOVA_FPS.iter().map(|(_, f)| 1e3 / f));
        let xs = (SEED_COUNTS[0] as f64 / 1.5)..(SEED_COUNTS[SEED_COUNTS.len() - 1] as f64 * 1.5);
        let mut chart = ChartBuilder::on(area)
            .caption(
                "One 16 ms step: ours (lines) against the seeds (hollow)",
                (FONT, 24),
            )
            .margin(14)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(xs.log_scale(), log_range(ys).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("particles")
            .y_desc("ms per step (app: ms per frame)")
            .x_label_formatter(&|x| format!("{x:.0}"))
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 17))
            .draw()
            .map_err(err)?;
        for (m, model) in BENCH_MODELS.iter().enumerate() {
            let color = PALETTE[m];
            let ours: Vec<(f64, f64)> = cells
                .iter()
                .filter(|c| c.model == *model)
                .filter_map(|c| Some((c.particles as f64, c.ms_per_step?)))
                .collect();
            if !ours.is_empty() {
                chart
                    .draw_series(LineSeries::new(ours.clone(), color.stroke_width(2)))
                    .map_err(err)?
                    .label(BENCH_NAMES[m])
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                    });
                chart
                    .draw_series(ours.iter().map(|&p| Circle::new(p, 4, color.filled())))
                    .map_err(err)?;
            }
            // The seed's zeros (under its 1 ms resolution) have no place on a log axis.
            let seed = SEED_COUNTS
                .iter()
                .zip(SEED_MS.get(m).copied().unwrap_or_default())
                .filter(|(_, ms)| *ms > 0.0)
                .map(|(&c, ms)| TriangleMarker::new((c as f64, ms), 6, color.stroke_width(2)));
            let series = chart.draw_series(seed).map_err(err)?;
            if m == 0 {
                series
                    .label("Sladović 2014 fig. 23 (hollow triangles, model colour)")
                    .legend(|(x, y)| TriangleMarker::new((x + 10, y), 6, BLACK.stroke_width(2)));
            }
        }
        draw_app_lines(&mut chart, app)?;
        chart
            .draw_series(MASLOVA_FPS.iter().map(|&(c, f)| {
                EmptyElement::at((c as f64, 1e3 / f))
                    + Rectangle::new([(-5, -5), (5, 5)], BLACK.stroke_width(2))
            }))
            .map_err(err)?
            .label("Maslova table 4.1: 1000 / fps (hollow squares)")
            .legend(|(x, y)| {
                Rectangle::new([(x + 5, y - 5), (x + 15, y + 5)], BLACK.stroke_width(2))
            });
        legend(&mut chart, SeriesLabelPosition::UpperLeft, 15)?;
        Ok(())
    }
}

/// The full app's ms per frame, a line per model (black, then grey).
fn draw_app_lines<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>,
    app: &[AppFrame],
) -> Result<()> {
    let mut app_models: Vec<&str> = app.iter().map(|a| a.model.as_str()).collect();
    app_models.dedup();
    for (i, model) in app_models.iter().enumerate() {
        let color = if i == 0 {
            BLACK
        } else {
            RGBColor(120, 120, 120)
        };
        let line: Vec<(f64, f64)> = app
            .iter()
            .filter(|a| a.model == *model)
            .filter_map(|a| Some((a.particles as f64, a.ms_per_frame?)))
            .collect();
        chart
            .draw_series(LineSeries::new(line.clone(), color.stroke_width(2)))
            .map_err(err)?
            .label(format!("full app, model {model}: ms per frame"))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
        chart
            .draw_series(line.iter().map(|&p| Circle::new(p, 4, color.filled())))
            .map_err(err)?;
    }
    Ok(())
}

// ----- accuracy -----------------------------------------------------------------------

const ACCURACY_MODELS: [&str; 4] = bevy_cloth_lab::stability::MODELS;

/// `docs/accuracy.png`: one panel per scene, cost (ms per simulated second) against
/// error, log-log; circles mass-spring, triangles shape matching, squares patches; the
/// Pareto frontier as a black staircase. Failed runs are not drawn (they are in the table).
pub fn accuracy(png: &Path, rows: &[Row]) -> Result<()> {
    let mut scenes: Vec<&str> = Vec::new();
    for r in rows {
        if !scenes.contains(&r.scene.as_str()) {
            scenes.push(&r.scene);
        }
    }
    let width = 520 * scenes.len().max(1) as u32;
    let scenes = &scenes;
    both(png, (width, 560), &Accuracy { rows, scenes })
}

struct Accuracy<'a> {
    rows: &'a [Row],
    scenes: &'a [&'a str],
}

impl Chart for Accuracy<'_> {
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()> {
        let Accuracy { rows, scenes } = *self;
        let panels = area.split_evenly((1, scenes.len().max(1)));
        for (panel, scene) in panels.iter().zip(scenes) {
            let rows: Vec<&Row> = rows.iter().filter(|r| r.scene == *scene).collect();
            // Failed runs have neither a time nor an error: not drawn.
            let ok: Vec<(&Row, f64, f64)> = rows
                .iter()
                .filter_map(|r| Some((*r, r.ms_per_second?, r.error?)))
                .collect();
            let xs = log_range(
                ok.iter()
                    .flat_map(|(r, _, _)| r.ms_range.map(|(lo, hi)| [lo, hi]))
                    .flatten(),
            );
            let ys = log_range(ok.iter().map(|(_, _, e)| *e));
            let converged = rows.iter().any(|r| r.pareto);
            let caption = if converged {
                scene.to_string()
            } else {
                format!("{scene} (reference not converged: no frontier)")
            };
            let axes = ("ms per simulated second", "RMS error / diagonal");
            let mut chart = log_log_panel(panel, caption, (xs, ys), axes)?;
            // The spread of each configuration's timed runs, fastest to slowest.
            chart
                .draw_series(ok.iter().filter_map(|(r, _, e)| {
                    let (lo, hi) = r.ms_range?;
                    Some(PathElement::new(vec![(lo, *e), (hi, *e)], BLACK.mix(0.5)))
                }))
                .map_err(err)?;
            draw_frontier(&mut chart, &ok)?;
            for (m, model) in ACCURACY_MODELS.iter().enumerate() {
                let color = PALETTE[m];
                let points: Vec<(f64, f64)> = ok
                    .iter()
                    .filter(|(r, _, _)| r.model == *model)
                    .map(|(_, ms, e)| (*ms, *e))
                    .collect();
                let style = color.filled();
                let anno =
                    match m {
                        0 => chart.draw_series(points.iter().map(|&p| Circle::new(p, 5, style))),
                        1 => chart
                            .draw_series(points.iter().map(|&p| TriangleMarker::new(p, 7, style))),
                        2 => chart.draw_series(points.iter().map(|&p| {
                            EmptyElement::at(p) + Rectangle::new([(-5, -5), (5, 5)], style)
                        })),
                        _ => chart.draw_series(
                            points
                                .iter()
                                .map(|&p| Cross::new(p, 6, color.stroke_width(3))),
                        ),
                    }
                    .map_err(err)?;
                anno.label(*model).legend(move |(x, y)| match m {
                    0 => Circle::new((x + 10, y), 5, style).into_dyn(),
                    1 => TriangleMarker::new((x + 10, y), 7, style).into_dyn(),
                    2 => Rectangle::new([(x + 5, y - 5), (x + 15, y + 5)], style).into_dyn(),
                    _ => Cross::new((x + 10, y), 6, color.stroke_width(3)).into_dyn(),
                });
            }
            legend(&mut chart, SeriesLabelPosition::LowerLeft, 14)?;
        }
        Ok(())
    }
}

/// The Pareto frontier of `ok` (row, ms, error) as a staircase.
fn draw_frontier<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, LogLog>,
    ok: &[(&Row, f64, f64)],
) -> Result<()> {
    let mut frontier: Vec<(f64, f64)> = ok
        .iter()
        .filter(|(r, _, _)| r.pareto)
        .map(|(_, ms, e)| (*ms, *e))
        .collect();
    frontier.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut stairs = Vec::new();
    for (i, p) in frontier.iter().enumerate() {
        if i > 0 {
            stairs.push((p.0, frontier[i - 1].1));
        }
        stairs.push(*p);
    }
    chart
        .draw_series(LineSeries::new(stairs, BLACK.stroke_width(1)))
        .map_err(err)?
        .label("Pareto frontier")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(1)));
    Ok(())
}

// ----- stability ----------------------------------------------------------------------

/// `docs/stability.png`: a panel per model (rows) and integrator with automatic
/// substeps off and on (columns); a cell is drawn at (timestep, `√(k/m)`), green when it
/// ran stable, a red cross when it failed, an orange square when the automatic substeps
/// hit their cap (8192; a cross on it when it also failed). The line is the explicit
/// bound `ω_max·h = 2` with `ω_max = factor·√(k/m)`, `factors` per model as in
/// [`MODELS`].
pub fn stability(png: &Path, cells: &[Cell], factors: &[f32; 4]) -> Result<()> {
    let columns = [
        (Integrator::Verlet, false, "Verlet, 1 substep"),
        (Integrator::SemiImplicitEuler, false, "Euler, 1 substep"),
        (Integrator::Verlet, true, "Verlet, auto substeps"),
        (Integrator::SemiImplicitEuler, true, "Euler, auto substeps"),
    ];
    let mut panels = Vec::new();
    for (m, model) in MODELS.iter().enumerate() {
        for (integrator, auto, name) in columns {
            panels.push(Panel {
                title: format!("{model}: {name}"),
                bound: Some(factors[m]),
                cells: cells
                    .iter()
                    .filter(|c| {
                        c.regime == Regime::Linear
                            && c.model == *model
                            && c.integrator == integrator
                            && c.auto == auto
                    })
                    .collect(),
            });
        }
    }
    let title = "Linear regime: stable (green), failed (red ×), over the substep cap (orange); line: ω_max·h = 2";
    both(
        png,
        (1500, 1400),
        &Stability {
            title,
            panels: &panels,
            grid: (MODELS.len(), columns.len()),
        },
    )
}

/// `docs/stability_nonlinear.png`: the nonlinear regimes (rows) for each model of
/// [`NONLINEAR_MODELS`] (columns), Verlet with automatic substeps; colours as in
/// [`stability`].
pub fn stability_nonlinear(png: &Path, cells: &[Cell]) -> Result<()> {
    let mut panels = Vec::new();
    for regime in Regime::NONLINEAR {
        for model in NONLINEAR_MODELS {
            panels.push(Panel {
                title: format!("{regime:?}: {model}"),
                bound: None,
                cells: cells
                    .iter()
                    .filter(|c| c.regime == regime && c.model == model)
                    .collect(),
            });
        }
    }
    let title = "Nonlinear regimes, Verlet, automatic substeps: stable (green), failed (red ×), over the substep cap (orange)";
    both(
        png,
        (2900, 1000),
        &Stability {
            title,
            panels: &panels,
            grid: (Regime::NONLINEAR.len(), NONLINEAR_MODELS.len()),
        },
    )
}

struct Panel<'a> {
    title: String,
    /// `ω_max/√(k/m)` for the line `ω_max·h = 2`, if drawn.
    bound: Option<f32>,
    cells: Vec<&'a Cell>,
}

struct Stability<'a> {
    title: &'a str,
    panels: &'a [Panel<'a>],
    grid: (usize, usize),
}

impl Chart for Stability<'_> {
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()> {
        let (title, body) = area.split_vertically(40);
        title.titled(self.title, (FONT, 22)).map_err(err)?;
        let areas = body.split_evenly(self.grid);
        let xs = 0.0007f64..0.05;
        let ys = log_range(
            self.panels
                .iter()
                .flat_map(|p| p.cells.iter().map(|c| c.omega0 as f64)),
        );
        for (area, panel) in areas.iter().zip(self.panels) {
            let mut chart = ChartBuilder::on(area)
                .caption(&panel.title, (FONT, 16))
                .margin(8)
                .x_label_area_size(35)
                .y_label_area_size(55)
                .build_cartesian_2d(xs.clone().log_scale(), ys.clone().log_scale())
                .map_err(err)?;
            chart
                .configure_mesh()
                .x_desc("h, s")
                .y_desc("√(k/m), rad/s")
                .y_label_formatter(&|y| format!("{y:.0}"))
                .label_style((FONT, 12))
                .axis_desc_style((FONT, 13))
                .x_labels(4)
                .y_labels(5)
                .draw()
                .map_err(err)?;
            if let Some(factor) = panel.bound {
                let bound: Vec<(f64, f64)> = (0..=60)
                    .map(|j| {
                        let h = xs.start * (xs.end / xs.start).powf(j as f64 / 60.0);
                        (h, 2.0 / (factor as f64 * h))
                    })
                    .filter(|(_, w)| ys.contains(w))
                    .collect();
                chart
                    .draw_series(LineSeries::new(bound, BLACK.stroke_width(2)))
                    .map_err(err)?;
            }
            let at = |c: &Cell| (c.timestep as f64, c.omega0 as f64);
            chart
                .draw_series(panel.cells.iter().filter(|c| c.under_resolved).map(|c| {
                    EmptyElement::at(at(c))
                        + Rectangle::new([(-5, -5), (5, 5)], PALETTE[3].filled())
                }))
                .map_err(err)?;
            chart
                .draw_series(
                    panel
                        .cells
                        .iter()
                        .filter(|c| c.failure.is_none() && !c.under_resolved)
                        .map(|c| Circle::new(at(c), 4, PALETTE[2].filled())),
                )
                .map_err(err)?;
            chart
                .draw_series(
                    panel
                        .cells
                        .iter()
                        .filter(|c| c.failure.is_some())
                        .map(|c| Cross::new(at(c), 5, PALETTE[0].stroke_width(2))),
                )
                .map_err(err)?;
        }
        Ok(())
    }
}

// ----- peers --------------------------------------------------------------------------

/// `docs/peers.png`: one panel per cloth size, strain against ms per frame (log-log), one
/// line per solver through its configurations, cheap to dear; the 1% and 0.1% strains
/// as dashed lines. Failed runs are not drawn (they are in the table).
pub fn peers(png: &Path, rows: &[PeerRow]) -> Result<()> {
    let mut sides: Vec<usize> = rows.iter().map(|r| r.side).collect();
    sides.sort_unstable();
    sides.dedup();
    let width = 520 * sides.len().max(1) as u32;
    both(
        png,
        (width, 560),
        &Peers {
            rows,
            sides: &sides,
        },
    )
}

struct Peers<'a> {
    rows: &'a [PeerRow],
    sides: &'a [usize],
}

impl Chart for Peers<'_> {
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()> {
        let panels = area.split_evenly((1, self.sides.len().max(1)));
        let mut solvers: Vec<&str> = Vec::new();
        for r in self.rows {
            if !solvers.contains(&r.solver.as_str()) {
                solvers.push(&r.solver);
            }
        }
        for (panel, &side) in panels.iter().zip(self.sides) {
            let ok: Vec<(&PeerRow, f64, f64)> = self
                .rows
                .iter()
                .filter(|r| r.side == side)
                .filter_map(|r| Some((r, r.ms?, r.strain?.max(1e-6))))
                .collect();
            let xs = log_range(ok.iter().map(|(_, ms, _)| *ms));
            let ys = log_range(ok.iter().map(|(_, _, s)| *s).chain([1e-3, 1e-2]));
            let caption = format!("{} particles ({side}×{side})", side * side);
            let axes = ("ms per frame (median)", "largest structural strain");
            let mut chart = log_log_panel(panel, caption, (xs.clone(), ys), axes)?;
            for strain in [1e-2, 1e-3] {
                chart
                    .draw_series(DashedLineSeries::new(
                        [(xs.start, strain), (xs.end, strain)],
                        4,
                        4,
                        BLACK.mix(0.4).stroke_width(1),
                    ))
                    .map_err(err)?;
            }
            for (k, solver) in solvers.iter().enumerate() {
                let color = PALETTE[k % PALETTE.len()];
                let mut points: Vec<(f64, f64)> = ok
                    .iter()
                    .filter(|(r, _, _)| r.solver == *solver)
                    .map(|(_, ms, s)| (*ms, *s))
                    .collect();
                points.sort_by(|a, b| a.0.total_cmp(&b.0));
                chart
                    .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))
                    .map_err(err)?
                    .label(*solver)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                    });
                chart
                    .draw_series(points.iter().map(|&p| Circle::new(p, 4, color.filled())))
                    .map_err(err)?;
            }
            legend(&mut chart, SeriesLabelPosition::UpperRight, 13)?;
        }
        Ok(())
    }
}

/// The drape test's shadows, one panel per fabric side by side (two rows of five), each
/// with the discs and the flat circle outlined and its drape coefficient.
struct DrapePanels<'a>(&'a [bevy_cloth_lab::drape::Drape]);

impl Chart for DrapePanels<'_> {
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()> {
        use bevy_cloth_lab::drape::{DISC_RADIUS, FABRIC_RADIUS};
        let columns = self.0.len().clamp(1, 5);
        let rows = self.0.len().div_ceil(columns);
        let panels = area.split_evenly((rows, columns));
        let reach = f64::from(FABRIC_RADIUS) * 1.08;
        for (panel, d) in panels.iter().zip(self.0) {
            let caption = format!(
                "{}: DC {:.2} (c {:.1} cm)",
                d.fabric,
                d.coefficient,
                d.bending_length * 100.0
            );
            let mut chart = ChartBuilder::on(panel)
                .caption(caption, (FONT, 16))
                .margin(6)
                .build_cartesian_2d(-reach..reach, -reach..reach)
                .map_err(|e| e.to_string())?;
            let fill = PALETTE[1].mix(0.8).filled();
            chart
                .draw_series(d.outline.iter().map(|t| {
                    Polygon::new(
                        t.iter()
                            .map(|&(x, z)| (f64::from(x), f64::from(z)))
                            .collect::<Vec<_>>(),
                        fill,
                    )
                }))
                .map_err(|e| e.to_string())?;
            for (r, colour) in [
                (DISC_RADIUS, BLACK),
                (FABRIC_RADIUS, RGBColor(150, 150, 150)),
            ] {
                let ring = (0..=96).map(|k| {
                    let a = k as f64 / 96.0 * std::f64::consts::TAU;
                    (f64::from(r) * a.cos(), f64::from(r) * a.sin())
                });
                chart
                    .draw_series(LineSeries::new(ring, colour.stroke_width(1)))
                    .map_err(|e| e.to_string())?;
            }
        }
        Ok(())
    }
}

/// Draws the drape test's panels to `png` and an SVG beside it.
pub fn drape(png: &Path, drapes: &[bevy_cloth_lab::drape::Drape]) -> Result<()> {
    let columns = drapes.len().clamp(1, 5) as u32;
    let rows = drapes.len().div_ceil(columns as usize) as u32;
    both(png, (260 * columns, 280 * rows), &DrapePanels(drapes))
}
