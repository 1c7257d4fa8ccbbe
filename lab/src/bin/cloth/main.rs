//! `cloth`: the headless command line (`cloth --help`, `cloth <verb> --help`).
//!
//! `run` prints a JSON summary on stdout and dumps positions on request; `bench` prints
//! Sladović's (2014) timing table (fig. 23) beside ours and, with `--app`, Maslova's frame
//! rates beside the full app's; `accuracy` and `stability` print their tables. `--chart`
//! draws the chart to a PNG and an SVG beside it. Bad input exits with code 2 and a
//! one-line message naming the file, line and field; nothing panics on user input.

/// `println!` that exits quietly when stdout is closed (`cloth run … | head -3`) instead
/// of panicking as std's does; defined before the modules so that they use it too.
macro_rules! println {
    () => {
        crate::out(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        crate::out(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// Writes to stdout; a closed pipe ends the program quietly (exit 0: the reader had what
/// it wanted), any other failure with exit code 2.
fn out(args: std::fmt::Arguments) {
    if let Err(e) = std::io::stdout().write_fmt(args) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("error: stdout: {e}");
        std::process::exit(2);
    }
}

/// `print!` through [`out`], as `println!` above.
macro_rules! print {
    ($($arg:tt)*) => {
        crate::out(format_args!($($arg)*))
    };
}

mod charts;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};

use bevy_cloth::params::{Integrator, Model, ModelKind};
use bevy_cloth::prelude::*;
use bevy_cloth::solver;
use bevy_cloth_lab::accuracy::{self, Case};
use bevy_cloth_lab::baseline;
use bevy_cloth_lab::fps::{self, APP_COUNTS};
use bevy_cloth_lab::peers::{self, Hang, PEER_SOLVERS, Peer, PeerRow};
use bevy_cloth_lab::stability::{
    self, MASS, MODELS, NONLINEAR_MODELS, NONLINEAR_TIMESTEP, Regime, STIFFNESS, TIMESTEP,
};
use bevy_cloth_lab::{self as measure, BENCH_MODELS, BenchCell, SEED_COUNTS, SceneRun};

/// Headless runs and measurements of bevy_cloth.
#[derive(Parser)]
#[command(
    name = "cloth",
    about = "Headless runs and measurements of bevy_cloth (bad input: exit code 2, one line)"
)]
struct Cli {
    #[command(subcommand)]
    verb: Verb,
}

#[derive(Subcommand)]
enum Verb {
    /// Runs a scene headless: a JSON summary on stdout, positions dumped on request.
    Run(RunArgs),
    /// Sladović's (2014) timing table (fig. 23) beside ours; with --app, Maslova's frame rates.
    Bench(BenchArgs),
    /// Speed against accuracy, against a converged reference.
    Accuracy(AccuracyArgs),
    /// Where each method fails: the linear and the nonlinear stability maps.
    Stability(StabilityArgs),
    /// The cheapest configuration of your scene's cloth within an error, or the most
    /// accurate within a cost per step (the accuracy study on that scene).
    Choose(ChooseArgs),
    /// Drives a scene's cloth for minutes with gusty wind, grabs, cuts, tearing,
    /// parameter edits (and refused invalid ones), model switches and resets, checking
    /// every step for non-finite state and the memory for growth.
    Soak(SoakArgs),
    /// Speed at equal accuracy beside other solvers, in one run: a cloth hung from its top
    /// row (or corners) with our XPBD without and with tethers, rapier-cloth-core and a
    /// Verlet + sticks baseline, each over a sweep of its cost setting.
    Peers(PeersArgs),
    /// The cantilever test (ASTM D1388): a fabric strip 2.5 cm wide pushed over a ledge
    /// until its tip falls 41.5°; its bending length against `(B / (ρ_A g))^(1/3)`.
    Cantilever(CantileverArgs),
    /// The drape test (Cusick): a 30 cm circle of fabric clamped between 18 cm discs,
    /// its drape coefficient from its shadow, with a picture of the shadows side by side.
    Drape(DrapeArgs),
}

#[derive(Args)]
struct DrapeArgs {
    /// The fabric preset.
    #[arg(long, required_unless_present = "all")]
    fabric: Option<String>,
    /// Every preset.
    #[arg(long)]
    all: bool,
    /// Grid spacing in mm (at 10 mm the coefficient is off by up to 0.06 from its value at
    /// 7.5 and 5 mm).
    #[arg(long, default_value_t = 5.0)]
    spacing: f32,
    #[command(flatten)]
    output: Output,
}

#[derive(Args)]
struct CantileverArgs {
    /// The fabric preset (denim, interlock, rib-knit, ponte, sweatshirt, swimsuit,
    /// polyester, tablecloth, jacket, twill).
    #[arg(long, required_unless_present = "all")]
    fabric: Option<String>,
    /// Every preset.
    #[arg(long)]
    all: bool,
    /// The models, comma separated: xpbd, mass-spring.
    #[arg(long, value_delimiter = ',', default_values_t = [String::from("xpbd"), String::from("mass-spring")])]
    models: Vec<String>,
    /// Grid spacings in mm, comma separated (2.5 is the default resolution: 11
    /// particles across the strip).
    #[arg(long, value_delimiter = ',', default_values_t = [2.5])]
    spacing: Vec<f32>,
    /// Prints one JSON object a line instead of a table.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct SoakArgs {
    /// The scene file (RON).
    scene: PathBuf,
    /// Wall-clock minutes (at most 1,440).
    #[arg(long, default_value_t = 1.0, value_parser = minutes)]
    minutes: f32,
    /// Which of the scene's cloths (its index).
    #[arg(long, default_value_t = 0)]
    cloth: usize,
    /// The random generator's seed (the same seed, the same soak).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Prints JSON instead of a table.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct ChooseArgs {
    /// The scene file (RON).
    scene: PathBuf,
    /// Which of the scene's cloths (its index).
    #[arg(long, default_value_t = 0)]
    cloth: usize,
    /// The largest error against the converged reference (RMS particle distance over the
    /// cloth's diagonal): picks the cheapest configuration within it.
    #[arg(long = "max-error", value_parser = positive, required_unless_present = "budget_ms", conflicts_with = "budget_ms")]
    max_error: Option<f32>,
    /// The largest cost per step, ms: picks the most accurate configuration within it.
    #[arg(long = "budget-ms", value_parser = positive)]
    budget_ms: Option<f32>,
    /// Simulated seconds per run (at most 3,600).
    #[arg(long, default_value_t = 3.0, value_parser = seconds)]
    seconds: f32,
    /// Timed runs per configuration.
    #[arg(long, default_value_t = 3, value_parser = repeats)]
    repeats: usize,
    /// Writes a copy of the scene with the chosen configuration to FILE (RON).
    #[arg(long, value_name = "FILE")]
    write: Option<PathBuf>,
    /// Prints JSON instead of tables.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct RunArgs {
    /// The scene file (RON).
    scene: String,
    /// Steps to run (at most 10,000,000; streamed, nothing is allocated per step).
    #[arg(long, default_value_t = 300, value_parser = steps)]
    steps: usize,
    /// Replaces every cloth's model: mass-spring, shape-matching, patches or xpbd.
    #[arg(long, value_parser = model_kind)]
    model: Option<ModelKind>,
    /// Overrides a scene field, e.g. `environment.wind.strength=0` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Writes positions to FILE.json, FILE.csv or FILE_<step>.obj.
    #[arg(long, value_name = "FILE", value_parser = dump_path)]
    dump: Option<PathBuf>,
    /// Dumps every K steps.
    #[arg(long, value_name = "K", default_value_t = 10, value_parser = at_least_one)]
    every: usize,
    /// Keeps every kernel on one thread (the results are the same bits; for comparing).
    #[arg(long = "one-thread")]
    one_thread: bool,
}

/// What every measuring verb can write besides its tables.
#[derive(Args)]
struct Output {
    /// Prints JSON instead of tables.
    #[arg(long)]
    json: bool,
    /// Draws the chart to FILE.png (and an SVG beside it).
    #[arg(long, value_name = "FILE.png", value_parser = chart_path)]
    chart: Option<PathBuf>,
}

#[derive(Args)]
struct BenchArgs {
    /// The largest particle count (at most 262,144).
    #[arg(long, default_value_t = 65_536, value_parser = particles)]
    max: usize,
    /// fig. 23's models and `x` (XPBD), comma separated (all when absent).
    #[arg(long, value_delimiter = ',', value_parser = seed_model)]
    models: Vec<&'static str>,
    /// Timed steps per cell (5 from 16,384 particles up).
    #[arg(long, default_value_t = 15, value_parser = repeats)]
    repeats: usize,
    /// Also runs Maslova's experiment with the full app.
    #[arg(long)]
    app: bool,
    /// The models of the full-app experiment (implies --app; all when absent).
    #[arg(long = "app-models", value_delimiter = ',', value_parser = seed_model)]
    app_models: Vec<&'static str>,
    /// Skips the mass-spring kernel costs (plain substep, limiter sweep, one core
    /// against all) at 4,096, 16,384 and 65,536 particles.
    #[arg(long = "no-kernels")]
    no_kernels: bool,
    #[command(flatten)]
    output: Output,
}

#[derive(Args)]
struct AccuracyArgs {
    /// The scenes, comma separated: curtain, curtain-wind, card (all when absent).
    #[arg(long, value_delimiter = ',', value_parser = accuracy_scene)]
    scenes: Vec<&'static str>,
    /// Simulated seconds per run (at most 3,600).
    #[arg(long, default_value_t = 3.0, allow_negative_numbers = true, value_parser = seconds)]
    seconds: f32,
    /// Timed runs per configuration.
    #[arg(long, default_value_t = 5, value_parser = repeats)]
    repeats: usize,
    #[command(flatten)]
    output: Output,
}

#[derive(Args)]
struct PeersArgs {
    /// Particles across (and down) the square cloth, comma separated (2 to 512).
    #[arg(long, value_delimiter = ',', default_values_t = [16, 64, 256], value_parser = side)]
    sides: Vec<usize>,
    /// What holds it: its whole top row (`top-row`), its two top corners (`corners`), or
    /// its top row with the cloth starting level and swinging down (`swing`).
    #[arg(long, default_value = "top-row", value_parser = hang)]
    hang: Hang,
    /// Frames of 1/60 s per run (the first 5 are not timed).
    #[arg(long, default_value_t = 60, value_parser = steps)]
    frames: usize,
    /// The solvers, comma separated: ours (XPBD swept), tethers (swept + tethers), lines (lines + tethers, the default), self (lines + tethers + self-collision), rapier, sticks (all when absent).
    #[arg(long, value_delimiter = ',', value_parser = peer_solver)]
    solvers: Vec<&'static str>,
    /// Keeps our kernels on one thread (the peers always run on one).
    #[arg(long = "one-thread")]
    one_thread: bool,
    #[command(flatten)]
    output: Output,
}

#[derive(Args)]
struct StabilityArgs {
    /// The models, comma separated (all when absent).
    #[arg(long, value_delimiter = ',', value_parser = stability_model)]
    models: Vec<&'static str>,
    #[command(flatten)]
    output: Output,
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help and --version
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            // One line naming the problem, as for every other bad input.
            let line = bevy_cloth::error::one_line(&e.render().to_string());
            eprintln!("error: {line}");
            return ExitCode::from(2);
        }
    };
    let result = match cli.verb {
        Verb::Run(args) => run(args),
        Verb::Bench(args) => bench(args),
        Verb::Accuracy(args) => accuracy(args),
        Verb::Stability(args) => stability(args),
        Verb::Choose(args) => choose(args),
        Verb::Soak(args) => soak(args),
        Verb::Peers(args) => peers(args),
        Verb::Cantilever(args) => cantilever(args),
        Verb::Drape(args) => drape(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
    }
}

fn model_kind(text: &str) -> Result<ModelKind, String> {
    text.parse().map_err(|e: ClothError| e.to_string())
}

fn at_least_one(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!("`{text}` is not a whole number of at least 1")),
    }
}

/// A whole number from 1 to `limit` (`what` names the limit in `limits.rs`).
fn count_within(text: &str, limit: usize, what: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(n) if (1..=limit).contains(&n) => Ok(n),
        _ => Err(format!(
            "`{text}` is not a whole number from 1 to {limit} (limits::{what})"
        )),
    }
}

fn steps(text: &str) -> Result<usize, String> {
    count_within(text, bevy_cloth::limits::MAX_STEPS, "MAX_STEPS")
}

fn repeats(text: &str) -> Result<usize, String> {
    count_within(text, bevy_cloth::limits::MAX_REPEATS, "MAX_REPEATS")
}

fn particles(text: &str) -> Result<usize, String> {
    count_within(text, bevy_cloth::limits::MAX_PARTICLES, "MAX_PARTICLES")
}

fn seconds(text: &str) -> Result<f32, String> {
    let (seconds, limit) = (positive(text)?, bevy_cloth::limits::MAX_SECONDS);
    if seconds > limit {
        return Err(format!(
            "`{text}` is more than {limit} s (limits::MAX_SECONDS)"
        ));
    }
    Ok(seconds)
}

fn minutes(text: &str) -> Result<f32, String> {
    let minutes = positive(text)?;
    if minutes > 1440.0 {
        return Err(format!("`{text}` is more than a day (1,440 minutes)"));
    }
    Ok(minutes)
}

fn positive(text: &str) -> Result<f32, String> {
    text.parse::<f32>()
        .ok()
        .filter(|x| *x > 0.0 && x.is_finite())
        .ok_or_else(|| format!("`{text}` is not a positive number"))
}

/// One of `known`, or an error naming the known ones.
fn one_of(text: &str, known: &[&'static str], what: &str) -> Result<&'static str, String> {
    known
        .iter()
        .find(|k| **k == text)
        .copied()
        .ok_or_else(|| format!("no {what} `{text}` ({})", known.join(", ")))
}

fn seed_model(text: &str) -> Result<&'static str, String> {
    one_of(text, &BENCH_MODELS, "model")
}

fn stability_model(text: &str) -> Result<&'static str, String> {
    one_of(text, &MODELS, "model")
}

fn side(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(n) if (2..=512).contains(&n) => Ok(n),
        _ => Err(format!("`{text}` is not a side from 2 to 512 particles")),
    }
}

fn hang(text: &str) -> Result<Hang, String> {
    match text {
        "top-row" => Ok(Hang::TopRow),
        "corners" => Ok(Hang::Corners),
        "swing" => Ok(Hang::Swing),
        _ => Err(format!("no hang `{text}` (top-row, corners, swing)")),
    }
}

fn peer_solver(text: &str) -> Result<&'static str, String> {
    one_of(text, &PEER_SOLVERS, "solver")
}

fn accuracy_scene(text: &str) -> Result<&'static str, String> {
    one_of(text, &ACCURACY_SCENES, "scene")
}

fn chart_path(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    charts::check_path(&path)?;
    Ok(path)
}

fn dump_path(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    DumpKind::of(&path)?;
    Ok(path)
}

/// The models asked for, or all of `known` when none were.
fn or_all(asked: Vec<&'static str>, known: &[&'static str]) -> Vec<&'static str> {
    if asked.is_empty() {
        known.to_vec()
    } else {
        asked
    }
}

/// A progress bar on stderr for a long verb, counting `unit`s (drawn only on a terminal;
/// the verb's own summary lines go through [`ProgressBar::suspend`], so they are printed
/// either way).
fn progress(total: usize, unit: &str) -> ProgressBar {
    let bar = ProgressBar::new(total as u64);
    let template = format!("[{{bar:30}}] {{pos}}/{{len}} {unit}, {{elapsed}} (about {{eta}} left)");
    if let Ok(style) = ProgressStyle::with_template(&template) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

/// The accuracy study's scenes.
const ACCURACY_SCENES: [&str; 3] = ["curtain", "curtain-wind", "card"];

fn run(args: RunArgs) -> Result<(), String> {
    bevy_cloth::solver::set_parallel(!args.one_thread);
    let scene_path = &args.scene;
    let mut scene = ClothScene::load(scene_path).map_err(|e| e.to_string())?;
    if let Some(model) = args.model {
        // `{model:?}` is the variant's name in a scene file (`MassSpring`, …).
        scene
            .apply_override(&format!("cloth.params.model={model:?}"))
            .map_err(|e| e.to_string())?;
    }
    for spec in &args.set {
        scene.apply_override(spec).map_err(|e| e.to_string())?;
    }
    if scene.cloths.is_empty() {
        return Err(format!(
            "{scene_path}: the scene has no cloths: nothing to run"
        ));
    }
    let (steps, every, timestep) = (args.steps, args.every, scene.timestep);
    // The solver's clock (its substeps' sum); a scene with no cloths has only the steps.
    let clock = |step: usize, cloths: &[(String, solver::ClothSolver)]| {
        cloths
            .first()
            .map_or(step as f32 * timestep, |(_, cloth)| cloth.time())
    };
    let mut run = SceneRun::new(&scene).map_err(|e| format!("{scene_path}: {e}"))?;
    let mut dump = match &args.dump {
        Some(path) => Some(Dump::new(path)?),
        None => None,
    };
    if let Some(d) = &mut dump {
        d.frame(0, 0.0, &run.cloths)?;
    }
    let mut dump_error = None;
    let summary = run.run(steps, |step, cloths| {
        if let Some(d) = &mut dump
            && step % every == 0
            && dump_error.is_none()
            && let Err(e) = d.frame(step, clock(step, cloths), cloths)
        {
            dump_error = Some(e);
        }
    });
    if let Some(e) = dump_error {
        return Err(e);
    }
    if let Some(d) = dump {
        d.finish()?;
    }
    for cloth in summary.cloths.iter().filter(|c| c.under_resolved) {
        eprintln!(
            "warning: `{}` needed more automatic substeps than its cap (substeps.max, or \
             limits::MAX_WORK_PER_STEP for its {} particles), or more strain-limiter sweeps \
             than a step's budget (limits::limiter_budget): it ran at {} substeps and may be \
             unstable or inaccurate",
            cloth.name, cloth.particles, cloth.substeps
        );
    }
    let json = serde_json::to_string_pretty(&summary).map_err(|e| e.to_string())?;
    println!("{json}");
    Ok(())
}

/// Particle positions every K steps: JSON (one document), CSV (one row per particle) or
/// OBJ (one file per frame, `NAME_000010.obj`, with the cloth's triangles).
struct Dump {
    path: PathBuf,
    kind: DumpKind,
    out: Option<std::io::BufWriter<std::fs::File>>,
    frames: usize,
}

#[derive(PartialEq)]
enum DumpKind {
    Json,
    Csv,
    Obj,
}

impl DumpKind {
    /// The kind a dump file's extension asks for.
    fn of(path: &Path) -> Result<Self, String> {
        match path.extension().and_then(|e| e.to_str()) {
            Some("json") => Ok(DumpKind::Json),
            Some("csv") => Ok(DumpKind::Csv),
            Some("obj") => Ok(DumpKind::Obj),
            _ => Err(format!(
                "--dump {}: the file must end in .json, .csv or .obj",
                path.display()
            )),
        }
    }
}

impl Dump {
    fn new(path: &Path) -> Result<Self, String> {
        let kind = DumpKind::of(path)?;
        let mut dump = Dump {
            path: path.to_path_buf(),
            kind,
            out: None,
            frames: 0,
        };
        if dump.kind != DumpKind::Obj {
            dump.out = Some(dump.create(path)?);
            let header = match dump.kind {
                DumpKind::Csv => "step,time,cloth,particle,x,y,z\n",
                _ => "{\"frames\":[\n",
            };
            dump.write(header)?;
        }
        Ok(dump)
    }

    fn create(&self, path: &Path) -> Result<std::io::BufWriter<std::fs::File>, String> {
        std::fs::File::create(path)
            .map(std::io::BufWriter::new)
            .map_err(|e| format!("--dump {}: {e}", path.display()))
    }

    fn write(&mut self, text: &str) -> Result<(), String> {
        let path = self.path.display().to_string();
        self.out
            .as_mut()
            .expect("open")
            .write_all(text.as_bytes())
            .map_err(|e| format!("--dump {path}: {e}"))
    }

    fn frame(
        &mut self,
        step: usize,
        time: f32,
        cloths: &[(String, solver::ClothSolver)],
    ) -> Result<(), String> {
        let mut text = String::new();
        match self.kind {
            DumpKind::Csv => {
                for (c, (_, cloth)) in cloths.iter().enumerate() {
                    for (i, p) in cloth.positions().iter().enumerate() {
                        text += &format!("{step},{time},{c},{i},{},{},{}\n", p.x, p.y, p.z);
                    }
                }
                self.write(&text)
            }
            DumpKind::Json => {
                let positions: Vec<Vec<[f32; 3]>> = cloths
                    .iter()
                    .map(|(_, c)| c.positions().iter().map(|p| p.to_array()).collect())
                    .collect();
                let frame = serde_json::json!({ "step": step, "time": time, "cloths": positions });
                let separator = if self.frames == 0 { "" } else { ",\n" };
                self.frames += 1;
                self.write(&format!("{separator}{frame}"))
            }
            DumpKind::Obj => {
                let stem = self.path.with_extension("");
                let path = PathBuf::from(format!("{}_{step:06}.obj", stem.display()));
                let mut base = 1;
                for (name, cloth) in cloths {
                    text += &format!("o {name}\n");
                    for p in cloth.positions() {
                        text += &format!("v {} {} {}\n", p.x, p.y, p.z);
                    }
                    for (t, visible) in cloth.triangles().iter().zip(cloth.triangle_visible()) {
                        if *visible {
                            text += &format!(
                                "f {} {} {}\n",
                                t[0] as usize + base,
                                t[1] as usize + base,
                                t[2] as usize + base
                            );
                        }
                    }
                    base += cloth.particle_count();
                }
                std::fs::write(&path, text).map_err(|e| format!("--dump {}: {e}", path.display()))
            }
        }
    }

    fn finish(mut self) -> Result<(), String> {
        if self.kind == DumpKind::Json {
            self.write("\n]}\n")?;
        }
        if let Some(out) = self.out.as_mut() {
            out.flush()
                .map_err(|e| format!("--dump {}: {e}", self.path.display()))?;
        }
        Ok(())
    }
}

fn print_json<T: serde::Serialize>(value: &T) -> Result<(), String> {
    let json = serde_json::to_string_pretty(value).map_err(|e| e.to_string())?;
    println!("{json}");
    Ok(())
}

/// The counts at which `bench` measures the mass-spring kernel costs.
const KERNEL_COUNTS: [usize; 3] = [4_096, 16_384, 65_536];

/// The kernel costs as a table: one core per substep against the bare kernel, a limiter
/// sweep against a plain substep, all cores against one.
fn print_kernels(kernels: &[bevy_cloth_lab::KernelCosts]) {
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

fn bench(args: BenchArgs) -> Result<(), String> {
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
    let mut cells = Vec::new();
    for &model in &models {
        for &count in &counts {
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
    let mut kernels = Vec::new();
    if !args.no_kernels {
        for count in KERNEL_COUNTS.into_iter().filter(|&c| c <= max) {
            let costs =
                bevy_cloth_lab::kernel_costs(count, repeats.min(9)).map_err(|e| e.to_string())?;
            eprintln!("kernel costs, {count:>6} particles: {costs:?}");
            kernels.push(costs);
        }
    }
    let mut frames = Vec::new();
    if with_app {
        for &model in &app_models {
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
    }
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
        println!(
            "ms per 16 ms step: ours (median) / Sladović 2014 fig. 23; substeps per step in brackets; \
             `failed` where the cloth passed 100% strain or went non-finite (not timed)"
        );
        print!("{:>8}", "model");
        for c in &counts {
            print!(" {c:>17}");
        }
        println!();
        print_by_model(&cells, counts.len(), |cell| {
            let seed = cell.seed_ms.map_or("-".to_string(), |s| format!("{s:.0}"));
            match cell.ms_per_step {
                Some(ms) => format!("{ms:.3}[{}]/{seed}", cell.substeps),
                None => format!("failed/{seed}"),
            }
        });
        println!();
        println!("spread of the timed steps: fastest–slowest, ms");
        print_by_model(&cells, counts.len(), |cell| match cell.ms_range {
            Some((lo, hi)) => format!("{lo:.3}–{hi:.3}"),
            None => "failed".to_string(),
        });
        println!();
        println!(
            "speed-up over Sladović 2014 (its ms / ours; - where it printed 0 ms or our cloth failed)"
        );
        print_by_model(&cells, counts.len(), |cell| {
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
        for ns in &bare {
            print!(" {:>17}", format!("{ns:.2}"));
        }
        println!();
        print_by_model(&cells, counts.len(), |cell| {
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
    print_kernels(&kernels);
    if !frames.is_empty() {
        println!();
        println!("| model | masses | ms per frame | fps | Maslova fps |");
        println!("|---|---:|---:|---:|---:|");
        for f in &frames {
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
    Ok(())
}

/// One row per model of `cells` (measured model by model, `per_model` counts each),
/// each cell as `show` writes it.
fn print_by_model(cells: &[BenchCell], per_model: usize, show: impl Fn(&BenchCell) -> String) {
    for row in cells.chunks(per_model.max(1)) {
        print!("{:>8}", row[0].model);
        for cell in row {
            print!(" {:>17}", show(cell));
        }
        println!();
    }
}

/// The accuracy study's cases: the curtain without and with its wind, and the card.
fn accuracy_cases(names: &[&str], seconds: f32) -> Result<Vec<Case>, String> {
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

fn accuracy(args: AccuracyArgs) -> Result<(), String> {
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
    println!(
        "| scene | reference substeps per step | its change when halved | smallest error reported | converged (< 5%) |"
    );
    println!("|---|---:|---:|---:|---|");
    for r in &references {
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
    for r in &rows {
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
    Ok(())
}

fn stability(args: StabilityArgs) -> Result<(), String> {
    let models = or_all(args.models, &MODELS);
    let in_list = |model: &str| models.iter().any(|m| model.split(' ').next() == Some(*m));
    let per_map = STIFFNESS.len() * MASS.len();
    let nonlinear_models = NONLINEAR_MODELS.iter().filter(|m| in_list(m)).count();
    let bar = progress(
        per_map
            * (models.len() * 4 * TIMESTEP.len()
                + Regime::NONLINEAR.len() * nonlinear_models * NONLINEAR_TIMESTEP.len()),
        "cells",
    );
    let mut cells = Vec::new();
    for &model in &models {
        for integrator in Integrator::ALL {
            for auto in [false, true] {
                let (mut failed, mut total) = (0, 0);
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
    // The nonlinear regimes: Verlet with automatic substeps, the claim under test.
    let mut nonlinear = Vec::new();
    for regime in Regime::NONLINEAR {
        for model in NONLINEAR_MODELS.into_iter().filter(|m| in_list(m)) {
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
    bar.finish_and_clear();
    let mut thresholds = Vec::new();
    for integrator in Integrator::ALL {
        for (k, m) in [(100.0, 1e-3), (1_000.0, 1e-4), (25_000.0, 1e-6)] {
            thresholds.push(stability::single_spring(k, m, integrator).map_err(|e| e.to_string())?);
            thresholds.push(stability::lattice(k, m, integrator).map_err(|e| e.to_string())?);
        }
    }
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
    println!("Linear regime (free 12×12 cloth, 1% perturbation, no gravity, no limiter):");
    println!();
    println!(
        "| model | integrator | substeps | failed cells | over the substep cap | first failure: smallest ω₀·h that failed | largest ω₀·h that ran stable |"
    );
    println!("|---|---|---|---:|---:|---:|---:|");
    for &model in &models {
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
            for model in NONLINEAR_MODELS.into_iter().filter(|m| in_list(m)) {
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
    println!();
    println!(
        "ω_max/√(k/m) of the {0}×{0} lattice: {1:.3}",
        stability::PROBE_SIZE,
        factors[0]
    );
    println!();
    println!(
        "| case | k, N/m | m, g | ω_max, rad/s | predicted 2/ω_max, ms | auto substeps' bound, ms | measured, ms | measured / predicted |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    for t in &thresholds {
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
    Ok(())
}

/// `cloth choose`: the accuracy study on the user's scene ([`accuracy::measure`], the
/// reference its cloth as mass-spring at 100× the substeps with a converged limiter),
/// then the configuration the goal asks for ([`bevy_cloth_lab::choose::pick`]).
fn choose(args: ChooseArgs) -> Result<(), String> {
    use bevy_cloth_lab::choose::{self, Goal};
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
    // Every configuration that applies: the patch model needs a grid.
    let grid = matches!(entry.cloth.shape, ClothShape::Grid { .. });
    let configs: Vec<_> = accuracy::configs(&case.base())
        .into_iter()
        .filter(|c| grid || !matches!(c.params.model, Model::Patches(_)))
        .collect();
    let bar = progress(configs.len(), "configurations");
    let (reference, rows) = accuracy::measure(&case, &configs, args.repeats, |_| bar.inc(1))
        .map_err(|e| e.to_string())?;
    bar.finish_and_clear();
    let goal = match (args.max_error, args.budget_ms) {
        (Some(e), _) => Goal::MaxError(e as f64),
        (None, Some(b)) => Goal::BudgetMs(b as f64),
        (None, None) => return Err("give --max-error or --budget-ms".into()),
    };
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
        if let Some(i) = chosen {
            println!("chosen: {} {}", configs[i].model, configs[i].label);
            println!("overrides:");
            for o in &overrides {
                println!("  --set '{o}'");
            }
            if let Some(file) = &args.write {
                println!("wrote {}", file.display());
            }
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

/// `cloth soak`: the soak, a status line a minute on stderr, the summary on stdout; exit
/// code 1 when it found a bug (non-finite state, an invalid edit accepted, memory growth).
fn soak(args: SoakArgs) -> Result<(), String> {
    let scene = ClothScene::load(&args.scene).map_err(|e| e.to_string())?;
    let duration = std::time::Duration::from_secs_f32(args.minutes * 60.0);
    let mut next = 60.0;
    let summary = bevy_cloth_lab::soak::soak(&scene, args.cloth, duration, args.seed, |s| {
        if s.seconds >= next {
            next += 60.0;
            eprintln!(
                "{:.0} s: {} steps, {} non-finite, {:.1} MB resident",
                s.seconds,
                s.steps,
                s.non_finite_steps,
                bevy_cloth_lab::soak::resident_mb()
            );
        }
    })?;
    if args.json {
        print_json(&summary)?;
    } else {
        let s = &summary;
        println!("| soak of {} | |", args.scene.display());
        println!("|---|---:|");
        for (what, value) in [
            ("wall-clock s", format!("{:.0}", s.seconds)),
            ("steps", s.steps.to_string()),
            ("simulated s", format!("{:.0}", s.simulated_seconds)),
            ("grabs", s.grabs.to_string()),
            (
                "cut strokes / springs cut",
                format!("{} / {}", s.cuts, s.springs_cut),
            ),
            ("springs torn by stretching", s.springs_torn.to_string()),
            (
                "valid edits / model switches",
                format!("{} / {}", s.edits, s.model_switches),
            ),
            (
                "invalid edits refused / accepted",
                format!("{} / {}", s.refused_edits, s.accepted_invalid_edits),
            ),
            ("resets", s.resets.to_string()),
            (
                "steps with non-finite state",
                s.non_finite_steps.to_string(),
            ),
            (
                "steps past 100% strain (reset)",
                s.unstable_steps.to_string(),
            ),
            (
                "resident MB settled / peak / end",
                format!(
                    "{:.1} / {:.1} / {:.1}",
                    s.rss_start_mb, s.rss_peak_mb, s.rss_end_mb
                ),
            ),
            (
                "step ms median / max",
                format!("{:.3} / {:.1}", s.median_step_ms, s.max_step_ms),
            ),
            ("passed", s.passed().to_string()),
        ] {
            println!("| {what} | {value} |");
        }
    }
    if summary.passed() {
        Ok(())
    } else {
        eprintln!("error: the soak found a problem (see the summary)");
        std::process::exit(1);
    }
}

/// `cloth peers`: every configuration of every solver on every side, in one run; the
/// table, then each solver's cheapest configuration within 1% and within 0.1% strain and
/// its cost against rapier-cloth-core's in the same run.
/// The presets `--fabric NAME` or `--all` name.
fn chosen_fabrics(
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

fn drape(args: DrapeArgs) -> Result<(), String> {
    let fabrics = chosen_fabrics(&args.fabric, args.all)?;
    if !(2.5..=30.0).contains(&args.spacing) {
        return Err(format!(
            "a spacing of {} mm; from 2.5 to 30 mm",
            args.spacing
        ));
    }
    if !args.output.json {
        println!(
            "| fabric | bending length mm | B µN·m | drape coefficient (mean of 5) | least–most |"
        );
        println!("|---|---:|---:|---:|---:|");
    }
    let mut drapes = Vec::new();
    for (name, fabric) in &fabrics {
        let xpbd = bevy_cloth::params::Model::Xpbd(bevy_cloth::params::XpbdParams {
            tethers: false,
            ..Default::default()
        });
        let d = bevy_cloth_lab::drape::drape(name, *fabric, args.spacing * 1e-3, xpbd)?;
        if args.output.json {
            println!("{}", serde_json::to_string(&d).map_err(|e| e.to_string())?);
        } else {
            println!(
                "| {} | {:.1} | {:.2} | {:.3} | {:.3}–{:.3} |",
                d.fabric,
                d.bending_length * 1e3,
                fabric.bending * 1e6,
                d.coefficient,
                d.spread.0,
                d.spread.1
            );
        }
        drapes.push(d);
    }
    if let Some(png) = &args.output.chart {
        charts::drape(png, &drapes)?;
    }
    Ok(())
}

fn cantilever(args: CantileverArgs) -> Result<(), String> {
    use bevy_cloth_lab::cantilever::{self, StripModel};
    let fabrics = chosen_fabrics(&args.fabric, args.all)?;
    let models = args
        .models
        .iter()
        .map(|m| match m.as_str() {
            "xpbd" => Ok(StripModel::Xpbd),
            "mass-spring" => Ok(StripModel::MassSpring),
            other => Err(format!("no model `{other}` here; known: xpbd, mass-spring")),
        })
        .collect::<Result<Vec<_>, _>>()?;
    if let Some(s) = args.spacing.iter().find(|s| !(0.5..=12.5).contains(*s)) {
        return Err(format!("a spacing of {s} mm; from 0.5 to 12.5 mm"));
    }
    if !args.json {
        println!(
            "| fabric | model | spacing mm | expected c mm | clamped: overhang mm | c mm | error | ledge: overhang mm | c mm | error | elastica overhang mm |"
        );
        println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    }
    for (name, fabric) in &fabrics {
        for &model in &models {
            for &mm in &args.spacing {
                let m = cantilever::measure(name, *fabric, model, mm * 1e-3)?;
                if args.json {
                    println!("{}", serde_json::to_string(&m).map_err(|e| e.to_string())?);
                } else {
                    println!(
                        "| {} | {:?} | {mm} | {:.2} | {:.2} | {:.2} | {:+.1}% | {:.2} | {:.2} | {:+.1}% | {:.2} |",
                        m.fabric,
                        m.model,
                        m.expected * 1e3,
                        m.overhang * 1e3,
                        m.measured * 1e3,
                        m.error * 100.0,
                        m.ledge_overhang * 1e3,
                        m.ledge_measured * 1e3,
                        m.ledge_error * 100.0,
                        m.elastica_overhang * 1e3,
                    );
                }
            }
        }
    }
    Ok(())
}

fn peers(args: PeersArgs) -> Result<(), String> {
    let solvers = or_all(args.solvers, &PEER_SOLVERS);
    if args.one_thread {
        solver::set_parallel(false);
    }
    let configs: Vec<Peer> = peers::default_peers()
        .into_iter()
        .filter(|p| solvers.contains(&p.key()))
        .collect();
    let bar = progress(configs.len() * args.sides.len(), "runs");
    let mut rows: Vec<PeerRow> = Vec::new();
    for &side in &args.sides {
        for &peer in &configs {
            let row = peers::measure(side, args.hang, peer, args.frames)?;
            bar.suspend(|| {
                eprintln!(
                    "  {:>6} {:<26} {:<26} {}",
                    side * side,
                    row.solver,
                    row.label,
                    match (&row.failed, row.ms, row.strain) {
                        (Some(why), _, _) => format!("failed: {why}"),
                        (None, Some(ms), Some(strain)) =>
                            format!("{ms:.3} ms  strain {:.3}%", strain * 100.0),
                        _ => String::new(),
                    }
                )
            });
            bar.inc(1);
            rows.push(row);
        }
    }
    bar.finish_and_clear();
    if let Some(chart) = &args.output.chart {
        charts::peers(chart, &rows)?;
    }
    let best = peers::cheapest_within(&rows, &[0.01, 0.001]);
    if args.output.json {
        return print_json(&serde_json::json!({
            "threads": solver::threads(),
            "frames": args.frames,
            "warmup_frames": peers::WARMUP_FRAMES,
            "rows": rows,
            "cheapest": best,
        }));
    }
    println!(
        "{} frames of 1/60 s per run, the first {} not timed; ours on {} thread(s), the others on one.",
        args.frames,
        peers::WARMUP_FRAMES,
        solver::threads()
    );
    println!();
    println!(
        "| particles | solver | configuration | ms per frame, median [p10–p90] | ns per projection | strain | sag |"
    );
    println!("|---:|---|---|---:|---:|---:|---:|");
    for r in &rows {
        let (time, ns, strain, sag) = match (r.ms, r.ms_spread, r.strain, r.sag) {
            (Some(ms), Some((lo, hi)), Some(strain), Some(sag)) => (
                format!("{ms:.3} [{lo:.3}–{hi:.3}]"),
                r.ns_per_projection
                    .map_or("-".into(), |ns| format!("{ns:.2}")),
                format!("{:.3}%", strain * 100.0),
                format!("{:.3}%", sag * 100.0),
            ),
            _ => (
                "-".into(),
                "-".into(),
                format!("failed: {}", r.failed.as_deref().unwrap_or("")),
                "-".into(),
            ),
        };
        println!(
            "| {} | {} | {} | {time} | {ns} | {strain} | {sag} |",
            r.side * r.side,
            r.solver,
            r.label
        );
    }
    println!();
    println!(
        "The cheapest configuration of each solver within a strain, and rapier-cloth-core's cost over its:"
    );
    println!();
    println!(
        "| particles | strain within | solver | configuration | ms per frame | strain | rapier / it |"
    );
    println!("|---:|---:|---|---|---:|---:|---:|");
    for b in &best {
        println!(
            "| {} | {}% | {} | {} | {:.3} | {:.3}% | {} |",
            b.side * b.side,
            b.within * 100.0,
            b.solver,
            b.label,
            b.ms,
            b.strain * 100.0,
            b.rapier_over.map_or("-".into(), |r| format!("{r:.2}x"))
        );
    }
    Ok(())
}
