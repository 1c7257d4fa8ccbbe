//! `cloth run`: a scene headless, a JSON summary, positions dumped on request.

use std::io::Write;
use std::path::{Path, PathBuf};

use clap::Args;

use crate::args::*;
use bevy_cloth::params::ModelKind;
use bevy_cloth::prelude::*;
use bevy_cloth::solver;
use bevy_cloth_lab::SceneRun;

#[derive(Args)]
pub(crate) struct RunArgs {
    /// The scene file (RON).
    pub(crate) scene: String,
    /// Steps to run (at most 10,000,000; streamed, nothing is allocated per step).
    #[arg(long, default_value_t = 300, value_parser = steps)]
    pub(crate) steps: usize,
    /// Replaces every cloth's model: mass-spring, shape-matching, patches or xpbd.
    #[arg(long, value_parser = model_kind)]
    pub(crate) model: Option<ModelKind>,
    /// Overrides a scene field, e.g. `environment.wind.strength=0` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub(crate) set: Vec<String>,
    /// Writes positions to FILE.json, FILE.csv or FILE_<step>.obj.
    #[arg(long, value_name = "FILE", value_parser = dump_path)]
    pub(crate) dump: Option<PathBuf>,
    /// Dumps every K steps.
    #[arg(long, value_name = "K", default_value_t = 10, value_parser = at_least_one)]
    pub(crate) every: usize,
    /// Keeps every kernel on one thread (the results are the same bits; for comparing).
    #[arg(long = "one-thread")]
    pub(crate) one_thread: bool,
    /// No progress bar and no summary line on stderr (the JSON on stdout stays).
    #[arg(long)]
    pub(crate) quiet: bool,
    /// Runs inside the plugin's default frame budget (`ClothBudget::default()`: 4 ms a
    /// step for all cloths, no cap of one cloth's own) instead of accuracy first.
    #[arg(long)]
    pub(crate) budget: bool,
    /// The budget's milliseconds for all cloths a step (implies --budget).
    #[arg(long, value_name = "MS")]
    pub(crate) budget_ms: Option<f32>,
    /// The budget's milliseconds for any one cloth a step (implies --budget).
    #[arg(long, value_name = "MS")]
    pub(crate) cloth_budget_ms: Option<f32>,
    /// Prints where the step's time goes: each stage's milliseconds a step and share,
    /// summed over the cloths (from their step reports), and the time outside them.
    #[arg(long)]
    pub(crate) stages: bool,
}

impl RunArgs {
    /// The frame budget the flags ask for (`None`: accuracy first), checked.
    fn frame_budget(&self) -> Result<Option<ClothBudget>, String> {
        if !(self.budget || self.budget_ms.is_some() || self.cloth_budget_ms.is_some()) {
            return Ok(None);
        }
        let mut budget = ClothBudget::default();
        if let Some(ms) = self.budget_ms {
            budget.milliseconds = Some(ms);
        }
        if let Some(ms) = self.cloth_budget_ms {
            budget.per_cloth_milliseconds = Some(ms);
        }
        budget.validate().map_err(|e| e.to_string())?;
        Ok(Some(budget))
    }
}

/// The scene file with `--model` and every `--set` applied; refused without cloths.
fn load_scene(args: &RunArgs) -> Result<ClothScene, String> {
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
    Ok(scene)
}

pub(crate) fn run(args: RunArgs) -> Result<(), String> {
    bevy_cloth::solver::set_parallel(!args.one_thread);
    let scene_path = &args.scene;
    let scene = load_scene(&args)?;
    let (steps, every, timestep) = (args.steps, args.every, scene.timestep);
    // The solver's clock (its substeps' sum); a scene with no cloths has only the steps.
    let clock = |step: usize, cloths: &[(String, solver::ClothSolver)]| {
        cloths
            .first()
            .map_or(step as f32 * timestep, |(_, cloth)| cloth.time())
    };
    let mut run = SceneRun::new(&scene).map_err(|e| format!("{scene_path}: {e}"))?;
    run.budget = args.frame_budget()?;
    let mut dump = match &args.dump {
        Some(path) => Some(Dump::new(path)?),
        None => None,
    };
    if let Some(d) = &mut dump {
        d.frame(0, 0.0, &run.cloths)?;
    }
    let mut dump_error = None;
    // On a terminal only (indicatif hides it elsewhere), and not with --quiet.
    let bar = if args.quiet {
        indicatif::ProgressBar::hidden()
    } else {
        progress(steps, "steps")
    };
    let mut stages = Stages::default();
    let summary = run.run(steps, |step, cloths| {
        bar.set_position(step as u64);
        if args.stages {
            stages.add(cloths);
        }
        if let Some(d) = &mut dump
            && step % every == 0
            && dump_error.is_none()
            && let Err(e) = d.frame(step, clock(step, cloths), cloths)
        {
            dump_error = Some(e);
        }
    });
    bar.finish_and_clear();
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
    if !args.quiet {
        say_summary(scene_path, &summary);
    }
    if args.stages {
        stages.say();
    }
    let json = serde_json::to_string_pretty(&summary).map_err(|e| e.to_string())?;
    println!("{json}");
    Ok(())
}

/// The run for a person, on stderr: steps, simulated time, the median step, and per cloth
/// its particles, substeps, largest strain and whether it stayed stable.
fn say_summary(scene: &str, summary: &bevy_cloth::headless::RunSummary) {
    eprintln!(
        "{scene}: {} steps ({:.2} s simulated), {:.3} ms a step (median), {:.3} ms the \
         slowest, {:.0} ns a particle-substep",
        summary.steps,
        summary.simulated_seconds,
        summary.median_ms_per_step,
        summary.max_ms_per_step,
        summary.ns_per_particle_substep
    );
    for c in &summary.cloths {
        eprintln!(
            "  {}: {} particles, {} substeps a step at the end ({} the most; steps capped {}, \
             over budget {}), largest strain {:.2}% at the end ({:.2}% the most), {}",
            if c.name.is_empty() { "cloth" } else { &c.name },
            c.particles,
            c.substeps,
            c.most_substeps,
            c.steps_under_resolved,
            c.steps_over_budget,
            c.max_strain * 100.0,
            c.largest_strain * 100.0,
            if c.whole {
                "whole throughout"
            } else {
                "NOT whole (non-finite or past 50% strain)"
            }
        );
    }
}

/// Each stage's time, summed over the run's steps and its cloths (`--stages`), and the
/// wall time between the steps' ends.
#[derive(Default)]
struct Stages {
    /// Per stage, in [`Stages::NAMES`]' order.
    time: [std::time::Duration; 8],
    /// From the first step's end to the last's: the steps after the first, whole.
    wall: std::time::Duration,
    /// Steps whose wall time is in `wall`.
    steps: usize,
    last: Option<std::time::Instant>,
}

impl Stages {
    const NAMES: [&str; 8] = [
        "begin (state, substeps, drivers, pair lists)",
        "forces (gravity, air, springs)",
        "integrate",
        "fit targets",
        "constraints (drivers and the model's)",
        "self-collision",
        "contact",
        "end (finite check, tears, strain)",
    ];

    /// Adds the step just ended.
    fn add(&mut self, cloths: &[(String, solver::ClothSolver)]) {
        let now = std::time::Instant::now();
        if let Some(last) = self.last {
            self.wall += now - last;
            self.steps += 1;
            for (_, cloth) in cloths {
                let t = cloth.last_report().time;
                let each = [
                    t.begin,
                    t.forces,
                    t.integrate,
                    t.fit_targets,
                    t.constraints,
                    t.self_contact,
                    t.contact,
                    t.end,
                ];
                for (sum, d) in self.time.iter_mut().zip(each) {
                    *sum += d;
                }
            }
        }
        self.last = Some(now);
    }

    /// The table, on stderr.
    fn say(&self) {
        let steps = self.steps.max(1) as f64;
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3 / steps;
        let sum: std::time::Duration = self.time.iter().sum();
        eprintln!(
            "where a step's time goes, over {} steps (the first left out), all cloths:",
            self.steps
        );
        for (name, &d) in Self::NAMES.iter().zip(&self.time) {
            eprintln!(
                "  {name:<44} {:>8.3} ms  {:>5.1}%",
                ms(d),
                100.0 * d.as_secs_f64() / sum.as_secs_f64().max(1e-12)
            );
        }
        eprintln!("  {:<44} {:>8.3} ms", "the stages", ms(sum));
        eprintln!(
            "  {:<44} {:>8.3} ms  (outside the stages: {:.3} ms: what cloths share, such as \
             cloth-cloth contact's lists and the budget's shares, and the run's own)",
            "the whole step, wall time",
            ms(self.wall),
            ms(self.wall.saturating_sub(sum))
        );
    }
}

/// Particle positions every K steps: JSON (one document), CSV (one row per particle) or
/// OBJ (one file per frame, `NAME_000010.obj`, with the cloth's triangles).
pub(crate) struct Dump {
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

fn dump_path(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    DumpKind::of(&path)?;
    Ok(path)
}
