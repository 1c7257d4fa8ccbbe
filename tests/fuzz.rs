//! Fuzzing: random and mutated scene, garment and pattern text and `--set`
//! pairs through the loaders and a few steps, and random edits of a running cloth through
//! reflection in a headless App, as the inspector makes them. Each case must end in a
//! clean error or a finite result. A seeded generator on stable Rust, so a failure is
//! repeatable: each case of the loader families runs under `catch_unwind`, and the test
//! fails at the end listing every failed case with its seed and its input; cases too
//! large to step here are counted and printed as skipped.
//!
//! `FUZZ_CASES=N` runs N cases in each of the three loader families and N/4 edits of a
//! running cloth (default 1,000: 3,250 in all, well under a minute); `FUZZ_SEED=S`
//! starts elsewhere.

use std::path::Path;

use bevy::math::Affine3A;
use bevy::prelude::*;
use bevy_cloth::headless::SceneRun;
use bevy_cloth::layout::garment::GarmentLayout;
use bevy_cloth::layout::pattern::Pattern;
use bevy_cloth::params::{Environment, Model, Substeps};
use bevy_cloth::prelude::*;
use bevy_cloth::scene::set_field;
use bevy_cloth::solver::ClothSolver;

/// xorshift64*: the same seed, the same cases.
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// How a case ended: stepped, refused with a clean error, or too large to step here.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Outcome {
    Ran,
    Refused,
    Skipped,
}

/// What a family of cases did, and the cases that failed (a panic, its seed and input).
#[derive(Default)]
struct Tally {
    ran: usize,
    refused: usize,
    skipped: usize,
    failures: Vec<String>,
}

impl Tally {
    /// Runs one case under `catch_unwind`: a panic is recorded with `case` (its seed and
    /// input) and the next case runs.
    fn run(&mut self, case: &str, work: impl FnOnce() -> Outcome) {
        match std::panic::catch_unwind(std::panic::AssertUnwindSafe(work)) {
            Ok(Outcome::Ran) => self.ran += 1,
            Ok(Outcome::Refused) => self.refused += 1,
            Ok(Outcome::Skipped) => self.skipped += 1,
            Err(payload) => {
                let message = payload
                    .downcast_ref::<String>()
                    .map(String::as_str)
                    .or_else(|| payload.downcast_ref::<&str>().copied())
                    .unwrap_or("a panic without a message");
                self.failures.push(format!("{case}: {message}"));
            }
        }
    }

    /// Prints what the family did and fails naming every failed case; `min` cases must
    /// have run and been refused each (a family that tests nothing fails too).
    fn finish(self, family: &str, min: usize) {
        println!(
            "{family}: {} ran, {} refused, {} skipped as too large, {} failed",
            self.ran,
            self.refused,
            self.skipped,
            self.failures.len()
        );
        assert!(
            self.failures.is_empty(),
            "{family}: {} cases failed:\n{}",
            self.failures.len(),
            self.failures.join("\n")
        );
        assert!(
            cases() < 100 || (self.ran >= min && self.refused >= min),
            "{family}: the cases test nothing"
        );
    }
}

/// A refusal is one line that says something.
fn clean(error: impl std::fmt::Display, case: &str) -> Outcome {
    let message = error.to_string();
    assert!(
        !message.is_empty() && !message.contains('\n'),
        "{case}: {message:?}"
    );
    Outcome::Refused
}

fn cases() -> usize {
    std::env::var("FUZZ_CASES")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(1_000)
}

fn first_seed() -> u64 {
    std::env::var("FUZZ_SEED")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(17)
}

/// Numbers that break careless code.
const EXTREMES: [&str; 22] = [
    "0",
    "-1",
    "1",
    "2",
    "65537",
    "4294967295",
    "4294967296",
    "2147483648",
    "18446744073709551615",
    "-0.0",
    "1e30",
    "-1e30",
    "1e-30",
    "NaN",
    "inf",
    "-inf",
    "0.5",
    "3.4e38",
    "99999999",
    "\"\"",
    "[]",
    "()",
];

fn asset(name: &str) -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("assets")
            .join(name),
    )
    .unwrap()
}

/// One mutation of `text`: a number replaced by an extreme, a line deleted or doubled, a
/// span deleted, random bytes, a bracket changed, or the text cut short.
fn mutate(text: &str, rng: &mut Rng) -> String {
    let mut s = text.to_string();
    for _ in 0..1 + rng.below(3) {
        let len = s.len();
        if len == 0 {
            return s;
        }
        let at = floor_char(&s, rng.below(len));
        s = match rng.below(7) {
            0 | 1 => {
                // A number (a run of digits, '.', '-', 'e') replaced by an extreme.
                let starts: Vec<usize> = s
                    .char_indices()
                    .filter(|(_, c)| c.is_ascii_digit())
                    .map(|(i, _)| i)
                    .collect();
                if starts.is_empty() {
                    s
                } else {
                    let start = *rng.pick(&starts);
                    let end = s[start..]
                        .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | 'e' | '-')))
                        .map_or(s.len(), |e| start + e);
                    format!("{}{}{}", &s[..start], rng.pick(&EXTREMES), &s[end..])
                }
            }
            2 => {
                let lines: Vec<&str> = s.lines().collect();
                let k = rng.below(lines.len());
                let mut out: Vec<&str> = lines.clone();
                if rng.below(2) == 0 {
                    out.remove(k);
                } else {
                    out.insert(k, lines[k]);
                }
                out.join("\n")
            }
            3 => {
                let end = floor_char(&s, (at + 1 + rng.below(40)).min(len));
                format!("{}{}", &s[..at], &s[end..])
            }
            4 => {
                let junk: String = (0..1 + rng.below(8))
                    .map(|_| {
                        *rng.pick(&['(', ')', '[', ']', ',', ':', '"', '0', '1', '\n', 'x', '#'])
                    })
                    .collect();
                format!("{}{}{}", &s[..at], junk, &s[at..])
            }
            5 => {
                const FROM: [&str; 5] = ["(", ")", "[", "]", ":"];
                const TO: [&str; 5] = ["[", "]", "(", ")", ""];
                let (from, to) = (FROM[rng.below(5)], TO[rng.below(5)]);
                s.replacen(from, to, 1)
            }
            _ => s[..at].to_string(),
        };
    }
    s
}

fn floor_char(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// Steps a solver three times if its work is small (the limits themselves are tested in
/// `lab/tests/cli.rs`; here the point is panics and non-finite state, not cost), and
/// asserts a finite result unless its fixed substeps are below its stable count (an
/// explicit method past its bound may blow up: a measured failure, not a bug).
fn step_a_few(cloth: &mut ClothSolver, env: &Environment, dt: f32, case: &str) -> Outcome {
    let substeps = match cloth.params().substeps {
        Substeps::Fixed(n) => n as usize,
        Substeps::Auto { .. } => cloth.stable_substeps(dt) as usize,
    };
    if cloth.particle_count().saturating_mul(substeps.max(1)) > 200_000 {
        return Outcome::Skipped;
    }
    for _ in 0..3 {
        cloth.step(dt, env);
    }
    let explicit_past_bound = (matches!(cloth.params().substeps, Substeps::Fixed(n) if n < cloth.stable_substeps(dt))
        || cloth.under_resolved())
        && !matches!(cloth.params().model, Model::Xpbd(_));
    assert!(
        cloth.is_finite() || explicit_past_bound,
        "{case}: not finite after 3 steps ({:?})",
        cloth.params()
    );
    Outcome::Ran
}

/// Builds and steps a scene's cloths: refused cleanly, stepped, or too large to step.
fn run_scene(scene: &ClothScene, case: &str) -> Outcome {
    let big = scene.cloths.iter().any(|c| match c.cloth.shape {
        ClothShape::Grid { width, height, .. } => width as usize * height as usize > 20_000,
        _ => false,
    });
    if big {
        return Outcome::Skipped;
    }
    match SceneRun::new(scene) {
        Err(e) => clean(e, case),
        Ok(mut run) => {
            let (env, dt) = (run.environment, run.timestep);
            let mut outcome = Outcome::Ran;
            for (_, cloth) in &mut run.cloths {
                if step_a_few(cloth, &env, dt, case) == Outcome::Skipped {
                    outcome = Outcome::Skipped;
                }
            }
            outcome
        }
    }
}

#[test]
fn mutated_scene_files_load_cleanly_or_fail_cleanly() {
    let sources = [
        "curtain",
        "card",
        "tshirt",
        "curtains_lod",
        "fold",
        "denim_curtain",
        "stack",
    ]
    .map(|name| asset(&format!("scenes/{name}.ron")));
    let mut tally = Tally::default();
    for k in 0..cases() {
        let seed = first_seed() + k as u64;
        let mut rng = Rng::new(seed);
        let source: &String = rng.pick(&sources);
        let text = mutate(source, &mut rng);
        // The case names its seed and the first line the mutation changed.
        let changed: Vec<&str> = text
            .lines()
            .zip(source.lines())
            .filter(|(a, b)| a != b)
            .map(|(a, _)| a.trim())
            .take(4)
            .collect();
        let changed = changed.join(" | ");
        let case = format!("scene case seed {seed} ({changed})");
        tally.run(&case, || {
            match ClothScene::parse(&text, Path::new("fuzz.ron")) {
                Err(e) => clean(e, &case),
                Ok(scene) => run_scene(&scene, &case),
            }
        });
    }
    tally.finish("scenes", 1);
}

#[test]
fn mutated_garments_and_patterns_load_cleanly_or_fail_cleanly() {
    let garment = asset("patterns/tshirt.ron");
    let (front_0, back_0) = (
        asset("patterns/tshirt_front.txt"),
        asset("patterns/tshirt_back.txt"),
    );
    let mut tally = Tally::default();
    for k in 0..cases() {
        let seed = first_seed() + k as u64;
        let mut rng = Rng::new(seed);
        let case = format!("garment case seed {seed}");
        // Mutate one of the three files (or none), at resolution 1–3.
        let which = rng.below(4);
        let text = if which == 0 {
            mutate(&garment, &mut rng)
        } else {
            garment.clone()
        };
        let front = if which == 1 {
            mutate(&front_0, &mut rng)
        } else {
            front_0.clone()
        };
        let back = if which == 2 {
            mutate(&back_0, &mut rng)
        } else {
            back_0.clone()
        };
        let resolution = 1 + rng.below(3) as u32;
        let changed: Vec<String> = [(&text, &garment), (&front, &front_0), (&back, &back_0)]
            .iter()
            .flat_map(|(a, b)| {
                a.lines()
                    .zip(b.lines())
                    .filter(|(x, y)| x != y)
                    .map(|(x, _)| x.trim().to_string())
                    .take(3)
                    .collect::<Vec<_>>()
            })
            .collect();
        let case = format!(
            "{case} at resolution {resolution} ({})",
            changed.join(" | ")
        );
        let read = |name: &str| match name {
            "tshirt_front.txt" => Pattern::parse(front.as_bytes(), name),
            "tshirt_back.txt" => Pattern::parse(back.as_bytes(), name),
            other => Pattern::parse(b"", other),
        };
        // The pattern parser alone on random bytes, drawn before the case so that the
        // seed's draws do not depend on how the case ends.
        let bytes: Vec<u8> = (0..rng.below(64))
            .map(|_| *rng.pick(b"0011\n \t#x\xff\r"))
            .collect();
        tally.run(&case, || {
            let _ = Pattern::parse(&bytes, "random.txt");
            match GarmentLayout::parse(&text, "fuzz.ron", resolution, read) {
                Err(e) => clean(e, &case),
                Ok(layout) => {
                    let params = ClothParams::seeds();
                    let frame = Affine3A::IDENTITY;
                    match ClothSolver::new(layout.into_layout(), &[], &params, frame) {
                        Err(e) => clean(e, &case),
                        Ok(mut cloth) => {
                            step_a_few(&mut cloth, &Environment::default(), 0.016, &case)
                        }
                    }
                }
            }
        });
    }
    tally.finish("garments", 1);
}

/// Keys of every kind of field `--set` reaches.
const KEYS: [&str; 41] = [
    "timestep",
    "environment.gravity",
    "environment.wind.strength",
    "environment.wind.direction",
    "environment.wind.field",
    "cloth.shape.width",
    "cloth.shape.height",
    "cloth.shape.spacing",
    "cloth.pins",
    "cloth.params.model",
    "cloth.params.model.0.part_width",
    "cloth.params.model.0.clusters",
    "cloth.params.model.0.stiffness",
    "cloth.params.node_mass",
    "cloth.params.springs.structural.stiffness",
    "cloth.params.springs.structural.enabled",
    "cloth.params.springs.damping",
    "cloth.params.drag",
    "cloth.params.integrator",
    "cloth.params.substeps",
    "cloth.params.strain_limit",
    "cloth.params.strain_limit_iterations",
    "cloth.params.tear_ratio",
    "cloths[7].params.drag",
    "cloths[0].pitch_degrees",
    "cloths[0].yaw_degrees",
    "cloth.params.self_collision.enabled",
    "cloth.params.self_collision.distance",
    "cloth.params.self_collision.friction",
    "cloth.params.fabric",
    "cloth.params.still_air",
    "cloth.params.model.0.max_stretch_error",
    "cloth.params.model.0.tethers",
    "cloth.params.model.0.solve",
    "environment.air",
    "environment.air.velocity",
    "environment.air.density",
    "environment.air.drag",
    "environment.air.lift",
    "environment.air.field",
    "environment.gravity_enabled",
];

/// Values for them: the extremes, and the words the keys take.
fn value(rng: &mut Rng) -> String {
    let words = [
        "auto",
        "none",
        "true",
        "false",
        "Patches",
        "Xpbd",
        "ShapeMatching",
        "MassSpring",
        "TopRow",
        "None",
        "Verlet",
        "Trigonometric",
        "1,2,3",
        "0,0,0",
        "1,2",
        "NaN,0,0",
        "8",
        "40",
        "0.001",
        "1e-30",
        "1e-9",
        "denim",
        "velvet",
        "Some(\"tablecloth\")",
        "Some((areal_density: 1e-9, stretch: 1, shear: 1, bending: 1))",
        "Some((velocity: (0, 0, 3)))",
        "Some(())",
        "Lines",
        "Sweep",
        "Xpbd(())",
    ];
    if rng.below(2) == 0 {
        rng.pick(&EXTREMES).to_string()
    } else {
        rng.pick(&words).to_string()
    }
}

#[test]
fn random_set_pairs_apply_cleanly_or_fail_cleanly() {
    let curtain =
        ClothScene::parse(&asset("scenes/curtain.ron"), Path::new("curtain.ron")).unwrap();
    let mut tally = Tally::default();
    for k in 0..cases() {
        let seed = first_seed() + k as u64;
        let mut rng = Rng::new(seed);
        let specs: Vec<String> = (0..1 + rng.below(3))
            .map(|_| format!("{}={}", rng.pick(&KEYS), value(&mut rng)))
            .collect();
        let case = format!("--set case seed {seed}: {}", specs.join(" "));
        tally.run(&case, || {
            let mut scene = curtain.clone();
            let mut outcome = Outcome::Ran;
            for spec in &specs {
                if let Err(e) = scene.apply_override(spec) {
                    outcome = clean(e, &case);
                }
            }
            // The pairs that applied, stepped; the case counts as refused if any was.
            match (run_scene(&scene, &case), outcome) {
                (Outcome::Skipped, _) => Outcome::Skipped,
                (_, outcome) => outcome,
            }
        });
    }
    tally.finish("--set", 1);
}

#[test]
fn random_edits_of_a_running_cloth_never_panic_and_invalid_ones_recover() {
    // As the inspector edits: reflection on the live `Cloth` and `ClothEnvironment`.
    let mut app = bevy_cloth::headless::headless_app();
    let cloth = app
        .world_mut()
        .spawn((
            Cloth::grid(12, 10, 0.05).with_pins(ClothPins::TopRow),
            Transform::from_xyz(0.0, 2.0, 0.0),
        ))
        .id();
    let good = app.world().get::<Cloth>(cloth).unwrap().clone();
    let good_env = *app.world().resource::<ClothEnvironment>();
    let (mut refused, mut invalid_seen, mut ran) = (0, 0, 0);
    let edits = cases() / 4;
    for k in 0..edits {
        let seed = first_seed() + k as u64;
        let mut rng = Rng::new(seed);
        let key = rng.pick(&KEYS);
        let v = value(&mut rng);
        if let Some(path) = key.strip_prefix("environment.") {
            let mut env = app.world_mut().resource_mut::<ClothEnvironment>();
            if set_field(&mut env.0, path, &v).is_err() {
                refused += 1;
            }
        } else if let Some(path) = key.strip_prefix("cloth.") {
            let mut c = app.world_mut().get_mut::<Cloth>(cloth).unwrap();
            if set_field(c.as_mut(), path, &v).is_err() {
                refused += 1;
            }
        }
        // A shape or work too large to step here is put back (refused by the limits, and
        // measured in the CLI test); the rest runs two frames.
        let sizes_ok = {
            let c = app.world().get::<Cloth>(cloth).unwrap();
            match c.shape {
                ClothShape::Grid { width, height, .. } => {
                    (width as usize) * (height as usize) <= 4_096
                }
                _ => true,
            }
        };
        if !sizes_ok {
            *app.world_mut().get_mut::<Cloth>(cloth).unwrap() = good.clone();
        }
        app.update();
        app.update();
        ran += 1;
        if app.world().get::<ClothInvalid>(cloth).is_some() {
            invalid_seen += 1;
            // Valid again: it recovers (rebuilt or resumed) within two frames.
            *app.world_mut().get_mut::<Cloth>(cloth).unwrap() = good.clone();
            *app.world_mut().resource_mut::<ClothEnvironment>() = good_env;
            app.update();
            app.update();
            assert!(
                app.world().get::<ClothInvalid>(cloth).is_none(),
                "edit seed {seed}: did not recover"
            );
            assert!(app.world().get::<ClothSimulation>(cloth).is_some());
        }
        if rng.below(8) == 0 {
            // Now and then back to the good cloth, so edits do not pile up forever.
            *app.world_mut().get_mut::<Cloth>(cloth).unwrap() = good.clone();
            *app.world_mut().resource_mut::<ClothEnvironment>() = good_env;
        }
    }
    println!(
        "plugin: {ran} edits run, {refused} refused by the path or value, {invalid_seen} made the cloth invalid and recovered"
    );
    assert!(
        cases() < 400 || (invalid_seen > 0 && refused > 0),
        "the edits test nothing"
    );
}
