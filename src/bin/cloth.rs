//! `cloth`: the headless command line.
//!
//! ```text
//! cloth run SCENE [--steps N] [--model mass-spring|shape-matching|patches]
//!                 [--set key=value]... [--dump FILE.json|.csv|.obj] [--every K]
//! cloth bench [--max PARTICLES] [--models 1,2,3a,3b,3c] [--repeats N] [--json]
//! ```
//! `run` prints a JSON summary on stdout; `bench` prints seed 000's timing table (Slika
//! 23) beside ours. Bad input exits with code 2 and a one-line message naming the file,
//! line and field; nothing panics on user input.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bevy_cloth::measure::{self, SEED_COUNTS, SEED_MODELS, SceneRun};
use bevy_cloth::prelude::*;
use bevy_cloth::solver;

const USAGE: &str = "usage: cloth run SCENE [--steps N] [--model mass-spring|shape-matching|patches] [--set key=value]... [--dump FILE.json|.csv|.obj] [--every K]
       cloth bench [--max PARTICLES] [--models 1,2,3a,3b,3c] [--repeats N] [--json]";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("run") => run(&args[1..]),
        Some("bench") => bench(&args[1..]),
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

fn bench(args: &[String]) -> Result<(), String> {
    let opts = options(args, &["--max", "--models", "--repeats"], &["--json"])?;
    if let Some(extra) = opts.positional.first() {
        return Err(format!("bench takes no argument `{extra}`\n{USAGE}"));
    }
    let max: usize = opts.number("--max", 65_536)?;
    let repeats: usize = opts.number("--repeats", 15)?;
    let models: Vec<&str> = opts
        .get("--models")
        .map_or(SEED_MODELS.to_vec(), |m| m.split(',').collect());
    if let Some(bad) = models.iter().find(|m| !SEED_MODELS.contains(m)) {
        return Err(format!("--models: no model `{bad}` (1, 2, 3a, 3b, 3c)"));
    }
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
            eprintln!(
                "model {model:>2}, {count:>6} particles: {:8.3} ms per step ({} substeps)",
                cell.ms_per_step, cell.substeps
            );
            cells.push(cell);
        }
    }
    if opts.switches.iter().any(|s| s == "--json") {
        let json = serde_json::to_string_pretty(&cells).map_err(|e| e.to_string())?;
        println!("{json}");
        return Ok(());
    }
    println!("ms per 16 ms step: ours (median) / seed 000 Slika 23; substeps per step in brackets");
    print!("{:>8}", "model");
    for c in &counts {
        print!(" {c:>17}");
    }
    println!();
    for &model in &models {
        print!("{model:>8}");
        for &count in &counts {
            let cell = cells
                .iter()
                .find(|c| c.model == model && c.particles == count)
                .expect("measured");
            let ours = format!("{:.3}[{}]", cell.ms_per_step, cell.substeps);
            let seed = cell.seed_ms.map_or("-".to_string(), |s| format!("{s:.0}"));
            print!(" {:>17}", format!("{ours}/{seed}"));
        }
        println!();
    }
    Ok(())
}
