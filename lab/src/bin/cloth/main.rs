//! `cloth`: the headless command line.
//!
//! ```text
//! cloth run SCENE [--steps N] [--model mass-spring|shape-matching|patches]
//!                 [--set key=value]... [--dump FILE.json|.csv|.obj] [--every K]
//! cloth bench [--max PARTICLES] [--models 1,2,3a,3b,3c] [--repeats N] [--app]
//!             [--app-models 1,3b] [--json] [--chart FILE.png]
//! cloth accuracy [--scenes curtain,curtain-wind,card] [--seconds S] [--repeats N] [--json]
//!                [--chart FILE.png]
//! cloth stability [--models mass-spring,shape-matching,patches] [--json] [--chart FILE.png]
//! ```
//! `run` prints a JSON summary on stdout; `bench` prints seed 000's timing table (Slika
//! 23) beside ours and, with `--app`, seed 002's frame rates beside the full app's;
//! `accuracy` and `stability` print their tables. `--chart` draws the chart to a PNG and
//! an SVG beside it. Bad input exits with code 2 and a one-line message naming the file,
//! line and field; nothing panics on user input.

mod charts;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bevy_cloth::prelude::*;
use bevy_cloth::solver;
use bevy_cloth_lab::accuracy::{self, Case};
use bevy_cloth_lab::fps::{self, APP_COUNTS};
use bevy_cloth_lab::stability::{
    self, MASS, MODELS, NONLINEAR_MODELS, NONLINEAR_TIMESTEP, Regime, STIFFNESS, TIMESTEP,
};
use bevy_cloth_lab::{self as measure, BenchCell, SEED_COUNTS, SEED_MODELS, SceneRun};

const USAGE: &str = "usage: cloth run SCENE [--steps N] [--model mass-spring|shape-matching|patches] [--set key=value]... [--dump FILE.json|.csv|.obj] [--every K]
       cloth bench [--max PARTICLES] [--models 1,2,3a,3b,3c] [--repeats N] [--app] [--app-models 1,3b] [--json] [--chart FILE.png]
       cloth accuracy [--scenes curtain,curtain-wind,card] [--seconds S] [--json] [--chart FILE.png]
       cloth stability [--models mass-spring,shape-matching,patches] [--json] [--chart FILE.png]";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("run") => run(&args[1..]),
        Some("bench") => bench(&args[1..]),
        Some("accuracy") => accuracy(&args[1..]),
        Some("stability") => stability(&args[1..]),
        Some("-h" | "--help") => {
            println!("{USAGE}");
            Ok(())
        }
        Some(other) => Err(format!("unknown command `{other}`\n{USAGE}")),
        None => Err(USAGE.to_string()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
    }
}

/// Splits `--flag value` options; `positional` collects the rest.
struct Options {
    pairs: Vec<(String, String)>,
    switches: Vec<String>,
    positional: Vec<String>,
}

fn options(args: &[String], with_value: &[&str], switches: &[&str]) -> Result<Options, String> {
    let mut out = Options {
        pairs: Vec::new(),
        switches: Vec::new(),
        positional: Vec::new(),
    };
    let mut it = args.iter();
    while let Some(arg) = it.next() {
        if with_value.contains(&arg.as_str()) {
            let value = it.next().ok_or_else(|| format!("{arg} needs a value"))?;
            out.pairs.push((arg.clone(), value.clone()));
        } else if switches.contains(&arg.as_str()) {
            out.switches.push(arg.clone());
        } else if arg.starts_with("--") {
            return Err(format!("unknown option `{arg}`\n{USAGE}"));
        } else {
            out.positional.push(arg.clone());
        }
    }
    Ok(out)
}

impl Options {
    fn switch(&self, flag: &str) -> bool {
        self.switches.iter().any(|s| s == flag)
    }

    fn get(&self, flag: &str) -> Option<&str> {
        self.pairs
            .iter()
            .rev()
            .find(|(f, _)| f == flag)
            .map(|(_, v)| v.as_str())
    }

    fn number<T: std::str::FromStr>(&self, flag: &str, default: T) -> Result<T, String> {
        match self.get(flag) {
            None => Ok(default),
            Some(v) => v
                .parse()
                .map_err(|_| format!("{flag}: `{v}` is not a whole number")),
        }
    }
}

fn run(args: &[String]) -> Result<(), String> {
    let opts = options(
        args,
        &["--steps", "--model", "--set", "--dump", "--every"],
        &[],
    )?;
    let [scene_path] = &opts.positional[..] else {
        return Err(format!("run needs one scene file\n{USAGE}"));
    };
    let mut scene = ClothScene::load(scene_path).map_err(|e| e.to_string())?;
    if let Some(model) = opts.get("--model") {
        let name = match model {
            "mass-spring" => "MassSpring",
            "shape-matching" => "ShapeMatching",
            "patches" => "Patches",
            other => {
                return Err(format!(
                    "--model: `{other}` is not mass-spring, shape-matching or patches"
                ));
            }
        };
        scene
            .apply_override(&format!("cloth.params.model={name}"))
            .map_err(|e| e.to_string())?;
    }
    for (flag, spec) in &opts.pairs {
        if flag == "--set" {
            scene.apply_override(spec).map_err(|e| e.to_string())?;
        }
    }
    let steps: usize = opts.number("--steps", 300)?;
    let every: usize = opts.number("--every", 10)?;
    if every == 0 {
        return Err("--every: must be at least 1".into());
    }
    let mut run = SceneRun::new(&scene).map_err(|e| format!("{scene_path}: {e}"))?;
    let mut dump = match opts.get("--dump") {
        Some(path) => Some(Dump::new(Path::new(path))?),
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
            && let Err(e) = d.frame(step, cloths[0].1.time(), cloths)
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

impl Dump {
    fn new(path: &Path) -> Result<Self, String> {
        let kind = match path.extension().and_then(|e| e.to_str()) {
            Some("json") => DumpKind::Json,
            Some("csv") => DumpKind::Csv,
            Some("obj") => DumpKind::Obj,
            _ => {
                return Err(format!(
                    "--dump {}: the file must end in .json, .csv or .obj",
                    path.display()
                ));
            }
        };
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
        cloths: &[(String, solver::Cloth)],
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

/// The models of `--models` (comma separated), each one of `known`.
fn model_list<'a>(
    opts: &'a Options,
    flag: &str,
    known: &[&'a str],
) -> Result<Vec<&'a str>, String> {
    let models: Vec<&str> = opts
        .get(flag)
        .map_or(known.to_vec(), |m| m.split(',').collect());
    if let Some(bad) = models.iter().find(|m| !known.contains(m)) {
        return Err(format!("{flag}: no model `{bad}` ({})", known.join(", ")));
    }
    Ok(models)
}

/// The options of a measuring verb (`bench`, `accuracy`, `stability`): no positional
/// argument, and a `--chart` path that is checked before anything is measured.
fn verb_options(
    verb: &str,
    args: &[String],
    with_value: &[&str],
    switches: &[&str],
) -> Result<Options, String> {
    let opts = options(args, with_value, switches)?;
    if let Some(extra) = opts.positional.first() {
        return Err(format!("{verb} takes no argument `{extra}`\n{USAGE}"));
    }
    if let Some(chart) = opts.get("--chart") {
        charts::check_path(Path::new(chart))?;
    }
    Ok(opts)
}

fn print_json<T: serde::Serialize>(value: &T) -> Result<(), String> {
    let json = serde_json::to_string_pretty(value).map_err(|e| e.to_string())?;
    println!("{json}");
    Ok(())
}

fn bench(args: &[String]) -> Result<(), String> {
    let opts = verb_options(
        "bench",
        args,
        &["--max", "--models", "--repeats", "--app-models", "--chart"],
        &["--json", "--app"],
    )?;
    let max: usize = opts.number("--max", 65_536)?;
    let repeats: usize = opts.number("--repeats", 15)?;
    let models = model_list(&opts, "--models", &SEED_MODELS)?;
    let app_models = model_list(&opts, "--app-models", &SEED_MODELS)?;
    let with_app = opts.switch("--app") || opts.get("--app-models").is_some();
    let counts: Vec<usize> = SEED_COUNTS.into_iter().filter(|&c| c <= max).collect();
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
    if let Some(chart) = opts.get("--chart") {
        charts::bench(Path::new(chart), &cells, &frames)?;
    }
    if opts.switch("--json") {
        return print_json(&serde_json::json!({ "solver": cells, "app": frames }));
    }
    if !cells.is_empty() {
        println!(
            "ms per 16 ms step: ours (median) / seed 000 Slika 23; substeps per step in brackets; \
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
            "speed-up over seed 000 (its ms / ours; - where it printed 0 ms or our cloth failed)"
        );
        print_by_model(&cells, counts.len(), |cell| {
            match (cell.seed_ms, cell.ms_per_step) {
                (Some(seed), Some(ms)) if seed > 0.0 => format!("{:.0}×", seed / ms),
                _ => "-".to_string(),
            }
        });
    }
    if !frames.is_empty() {
        println!();
        println!("| model | masses | ms per frame | fps | seed 002 fps |");
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
        let path = bevy_cloth::garment::asset_path(&format!("scenes/{file}"));
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

fn number_f32(opts: &Options, flag: &str, default: f32) -> Result<f32, String> {
    match opts.get(flag) {
        None => Ok(default),
        Some(v) => v
            .parse::<f32>()
            .ok()
            .filter(|x| *x > 0.0 && x.is_finite())
            .ok_or_else(|| format!("{flag}: `{v}` is not a positive number")),
    }
}

fn accuracy(args: &[String]) -> Result<(), String> {
    let opts = verb_options(
        "accuracy",
        args,
        &["--scenes", "--seconds", "--chart", "--repeats"],
        &["--json"],
    )?;
    let seconds = number_f32(&opts, "--seconds", 3.0)?;
    let repeats: usize = opts.number("--repeats", 5)?;
    let names: Vec<&str> = opts
        .get("--scenes")
        .map_or(vec!["curtain", "curtain-wind", "card"], |s| {
            s.split(',').collect()
        });
    let cases = accuracy_cases(&names, seconds)?;
    let mut references = Vec::new();
    let mut rows = Vec::new();
    for case in &cases {
        let configs = accuracy::configs(&case.base());
        eprintln!(
            "{}: reference and {} configurations",
            case.name,
            configs.len()
        );
        let (reference, case_rows) = accuracy::measure(case, &configs, repeats, |r| {
            eprintln!(
                "  {:<15} {:<36} {:>10} ms/s  error {}",
                r.model,
                r.label,
                r.ms_per_second.map_or("-".into(), |ms| format!("{ms:.1}")),
                r.error.map_or("failed".into(), |e| format!("{e:.2e}"))
            );
        })
        .map_err(|e| e.to_string())?;
        references.push(reference);
        rows.extend(case_rows);
    }
    if let Some(chart) = opts.get("--chart") {
        charts::accuracy(Path::new(chart), &rows)?;
    }
    if opts.switch("--json") {
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

fn stability(args: &[String]) -> Result<(), String> {
    let opts = verb_options("stability", args, &["--models", "--chart"], &["--json"])?;
    let models = model_list(&opts, "--models", &MODELS)?;
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
                        }
                    }
                }
                eprintln!(
                    "{model}, {integrator:?}, auto substeps {}: {failed} of {total} cells fail",
                    if auto { "on" } else { "off" }
                );
            }
        }
    }
    // The nonlinear regimes: Verlet with automatic substeps, the claim under test.
    let mut nonlinear = Vec::new();
    let in_list = |model: &str| models.iter().any(|m| model.split(' ').next() == Some(*m));
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
                    }
                }
            }
            let failed = here.iter().filter(|c| c.failure.is_some()).count();
            let persists = here
                .iter()
                .filter(|c| c.persists_at_4x == Some(true))
                .count();
            let capped = here.iter().filter(|c| c.under_resolved).count();
            eprintln!(
                "{regime:?}, {model}: {failed} of {} cells fail ({persists} still at 4× the substeps), {capped} over the substep cap",
                here.len()
            );
            nonlinear.extend(here);
        }
    }
    let mut thresholds = Vec::new();
    for integrator in Integrator::ALL {
        for (k, m) in [(100.0, 1e-3), (1_000.0, 1e-4), (25_000.0, 1e-6)] {
            thresholds.push(stability::single_spring(k, m, integrator).map_err(|e| e.to_string())?);
            thresholds.push(stability::lattice(k, m, integrator).map_err(|e| e.to_string())?);
        }
    }
    let factors = [stability::lattice_factor(), 1.0, 1.0];
    if let Some(chart) = opts.get("--chart") {
        let chart = Path::new(chart);
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
    if opts.switch("--json") {
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
