//! `cloth bench`: Sladović's (2014) timing table beside ours; with `--app`, Maslova's frame rates beside the full app's.

use clap::Args;

use crate::args::*;
use crate::charts;
use bevy_cloth_lab::baseline;
use bevy_cloth_lab::fps::{self, APP_COUNTS};
use bevy_cloth_lab::{self as measure, BENCH_MODELS, BenchCell, SEED_COUNTS};

#[derive(Args)]
pub(crate) struct BenchArgs {
    /// The largest particle count (at most 262,144).
    #[arg(long, default_value_t = 65_536, value_parser = particles)]
    pub(crate) max: usize,
    /// fig. 23's models and `x` (XPBD), comma separated (all when absent).
    #[arg(long, value_delimiter = ',', value_parser = seed_model)]
    pub(crate) models: Vec<&'static str>,
    /// Timed steps per cell (5 from 16,384 particles up).
    #[arg(long, default_value_t = 15, value_parser = repeats)]
    pub(crate) repeats: usize,
    /// Also runs Maslova's experiment with the full app.
    #[arg(long)]
    pub(crate) app: bool,
    /// The models of the full-app experiment (implies --app; all when absent).
    #[arg(long = "app-models", value_delimiter = ',', value_parser = seed_model)]
    pub(crate) app_models: Vec<&'static str>,
    /// Skips the mass-spring kernel costs (plain substep, limiter sweep, one core
    /// against all) at 4,096, 16,384 and 65,536 particles.
    #[arg(long = "no-kernels")]
    pub(crate) no_kernels: bool,
    #[command(flatten)]
    pub(crate) output: Output,
}

/// The counts at which `bench` measures the mass-spring kernel costs.
pub(crate) const KERNEL_COUNTS: [usize; 3] = [4_096, 16_384, 65_536];

/// The kernel costs as a table: one core per substep against the bare kernel, a limiter
/// sweep against a plain substep, all cores against one.
pub(crate) fn print_kernels(kernels: &[bevy_cloth_lab::KernelCosts]) {
    if kernels.is_empty() {
        return;
    }
    let ns = |v: Option<f64>| v.map_or("failed".to_string(), |v| format!("{v:.2}"));
    println!();
    println!(
        "mass-spring curtain, one core unless said: ns per particle-substep of the bare kernel, \
         a plain substep (no limiter) [× bare], one limiter sweep [× plain]; ms per step on one \
         core and on all, and the speed-up"
    );
    println!(
        "| particles | substeps | bare | plain | sweep | 1 core ms | {} threads ms | speed-up |",
        kernels[0].threads
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|");
    for k in kernels {
        let ratio = |a: Option<f64>, b: Option<f64>| {
            a.zip(b)
                .map_or("-".to_string(), |(a, b)| format!("{:.2}", a / b))
        };
        println!(
            "| {} | {} | {:.2} | {} [{}×] | {} [{}×] | {} | {} | {}× |",
            k.particles,
            k.substeps,
            k.bare_ns,
            ns(k.plain_ns),
            ratio(k.plain_ns, Some(k.bare_ns)),
            ns(k.sweep_ns),
            ratio(k.sweep_ns, k.plain_ns),
            ns(k.one_core_ms),
            ns(k.all_cores_ms),
            ratio(k.one_core_ms, k.all_cores_ms),
        );
    }
}

pub(crate) fn bench(args: BenchArgs) -> Result<(), String> {
    let (max, repeats) = (args.max, args.repeats);
    let models = or_all(args.models, &BENCH_MODELS);
    let with_app = args.app || !args.app_models.is_empty();
    let app_models = or_all(args.app_models, &BENCH_MODELS);
    let counts: Vec<usize> = SEED_COUNTS.into_iter().filter(|&c| c <= max).collect();
    // The bare kernel first, in this run: the ratios below are to it.
    let bare: Vec<f64> = counts
        .iter()
        .map(|&count| {
            let ns = baseline::ns_per_particle_substep(count, repeats.max(5));
            eprintln!("bare kernel, {count:>6} particles: {ns:6.2} ns per particle-substep");
            ns
        })
        .collect();
    let cells = solver_cells(&models, &counts, repeats)?;
    let kernels = if args.no_kernels {
        Vec::new()
    } else {
        kernel_rows(max, repeats)?
    };
    let frames = if with_app {
        app_frames(&app_models, max)?
    } else {
        Vec::new()
    };
    if let Some(chart) = &args.output.chart {
        charts::bench(chart, &cells, &frames)?;
    }
    if args.output.json {
        let bare: Vec<_> = counts
            .iter()
            .zip(&bare)
            .map(|(count, ns)| serde_json::json!({ "particles": count, "ns_per_particle_substep": ns }))
            .collect();
        return print_json(&serde_json::json!({
            "solver": cells,
            "bare_kernel": bare,
            "kernels": kernels,
            "app": frames
        }));
    }
    if !cells.is_empty() {
        print_solver_tables(&cells, &counts, &bare);
    }
    print_kernels(&kernels);
    print_frames(&frames);
    Ok(())
}

/// The solver's cost per step, model by model at each count; a line on stderr per cell.
fn solver_cells(
    models: &[&'static str],
    counts: &[usize],
    repeats: usize,
) -> Result<Vec<BenchCell>, String> {
    let mut cells = Vec::new();
    for &model in models {
        for &count in counts {
            // Fewer repeats for the large cloths keep the whole table to a few minutes.
            let repeats = if count >= 16_384 {
                repeats.min(5)
            } else {
                repeats
            };
            let cell =
                measure::bench_cell(model, count, 3, repeats.max(1)).map_err(|e| e.to_string())?;
            match (cell.ms_per_step, cell.failed_at_step) {
                (Some(ms), _) => eprintln!(
                    "model {model:>2}, {count:>6} particles: {ms:8.3} ms per step ({} substeps)",
                    cell.substeps
                ),
                (None, step) => eprintln!(
                    "model {model:>2}, {count:>6} particles: FAILED after step {} (strain {:.0}%): not timed",
                    step.unwrap_or(0),
                    cell.max_strain * 100.0
                ),
            }
            cells.push(cell);
        }
    }
    Ok(cells)
}

/// The mass-spring kernel costs at each of [`KERNEL_COUNTS`] up to `max`.
fn kernel_rows(max: usize, repeats: usize) -> Result<Vec<bevy_cloth_lab::KernelCosts>, String> {
    let mut kernels = Vec::new();
    for count in KERNEL_COUNTS.into_iter().filter(|&c| c <= max) {
        let costs =
            bevy_cloth_lab::kernel_costs(count, repeats.min(9)).map_err(|e| e.to_string())?;
        eprintln!("kernel costs, {count:>6} particles: {costs:?}");
        kernels.push(costs);
    }
    Ok(kernels)
}

/// The full app's frames, model by model at each of [`APP_COUNTS`] up to `max`.
fn app_frames(app_models: &[&'static str], max: usize) -> Result<Vec<fps::AppFrame>, String> {
    let mut frames = Vec::new();
    for &model in app_models {
        for count in APP_COUNTS.into_iter().filter(|&c| c <= max) {
            let frames_measured = if count >= 16_384 { 20 } else { 100 };
            // Every app starts from idle worker threads: Bevy's executor runs a small
            // app's frame in 0.1 ms or 0.5 ms depending on the state it finds its
            // threads in (the README's Results), and this makes the rows comparable.
            std::thread::sleep(std::time::Duration::from_millis(500));
            let row =
                fps::app_frame(model, count, 5, frames_measured).map_err(|e| e.to_string())?;
            match (row.ms_per_frame, row.fps) {
                (Some(ms), Some(fps)) => eprintln!(
                    "app, model {model:>2}, {count:>6} particles: {ms:8.3} ms per frame, {fps:7.1} fps"
                ),
                _ => eprintln!(
                    "app, model {model:>2}, {count:>6} particles: FAILED after frame {}: not timed",
                    row.failed_at_frame.unwrap_or(0)
                ),
            }
            frames.push(row);
        }
    }
    Ok(frames)
}

/// The solver's tables: cost per step against Sladović's, its spread, the speed-up, and
/// the cost per particle-substep against the bare kernel's.
fn print_solver_tables(cells: &[BenchCell], counts: &[usize], bare: &[f64]) {
    println!(
        "ms per 16 ms step: ours (median) / Sladović 2014 fig. 23; substeps per step in brackets; \
         `failed` where the cloth passed 100% strain or went non-finite (not timed)"
    );
    print!("{:>8}", "model");
    for c in counts {
        print!(" {c:>17}");
    }
    println!();
    print_by_model(cells, counts.len(), |cell| {
        let seed = cell.seed_ms.map_or("-".to_string(), |s| format!("{s:.0}"));
        match cell.ms_per_step {
            Some(ms) => format!("{ms:.3}[{}]/{seed}", cell.substeps),
            None => format!("failed/{seed}"),
        }
    });
    println!();
    println!("spread of the timed steps: fastest–slowest, ms");
    print_by_model(cells, counts.len(), |cell| match cell.ms_range {
        Some((lo, hi)) => format!("{lo:.3}–{hi:.3}"),
        None => "failed".to_string(),
    });
    println!();
    println!(
        "speed-up over Sladović 2014 (its ms / ours; - where it printed 0 ms or our cloth failed)"
    );
    print_by_model(cells, counts.len(), |cell| {
        match (cell.seed_ms, cell.ms_per_step) {
            (Some(seed), Some(ms)) if seed > 0.0 => format!("{:.0}×", seed / ms),
            _ => "-".to_string(),
        }
    });
    println!();
    println!(
        "ns per particle-substep, and in brackets × the bare kernel's (SoA grid, structural + \
         shear + bend, Verlet, one core) in this run"
    );
    print!("{:>8}", "bare");
    for ns in bare {
        print!(" {:>17}", format!("{ns:.2}"));
    }
    println!();
    print_by_model(cells, counts.len(), |cell| {
        let bare = counts
            .iter()
            .position(|&c| c == cell.particles)
            .map(|i| bare[i]);
        match (cell.ms_per_substep, bare) {
            (Some(ms), Some(bare)) => {
                let ns = ms * 1e6 / cell.particles as f64;
                format!("{ns:.1}[{:.1}×]", ns / bare)
            }
            _ => "failed".to_string(),
        }
    });
}

/// The full app's table beside Maslova's frame rates.
fn print_frames(frames: &[fps::AppFrame]) {
    if !frames.is_empty() {
        println!();
        println!("| model | masses | ms per frame | fps | Maslova fps |");
        println!("|---|---:|---:|---:|---:|");
        for f in frames {
            let seed = f.seed_fps.map_or("-".to_string(), |s| format!("{s:.0}"));
            let (ms, fps) = match (f.ms_per_frame, f.fps, f.failed_at_frame) {
                (Some(ms), Some(fps), _) => (format!("{ms:.3}"), format!("{fps:.0}")),
                (_, _, frame) => (
                    format!("failed at frame {}", frame.unwrap_or(0)),
                    "-".to_string(),
                ),
            };
            println!("| {} | {} | {ms} | {fps} | {seed} |", f.model, f.particles);
        }
    }
}

/// One row per model of `cells` (measured model by model, `per_model` counts each),
/// each cell as `show` writes it.
pub(crate) fn print_by_model(
    cells: &[BenchCell],
    per_model: usize,
    show: impl Fn(&BenchCell) -> String,
) {
    for row in cells.chunks(per_model.max(1)) {
        print!("{:>8}", row[0].model);
        for cell in row {
            print!(" {:>17}", show(cell));
        }
        println!();
    }
}
