//! The soak: a scene's cloth driven for minutes by everything a game and its
//! player can do to it — gusty wind, grabs and drags, cuts, tearing, parameter edits (valid
//! ones, and invalid ones that must be refused), model switches and resets — with every
//! step checked for non-finite state and the process's resident memory sampled for growth.

use std::time::{Duration, Instant};

use bevy::math::Vec3;
use serde::Serialize;

use bevy_cloth::headless::SceneRun;
use bevy_cloth::params::{
    ClothParams, Model, PatchParams, ShapeMatchingParams, Substeps, XpbdParams,
};
use bevy_cloth::scene::ClothScene;
use bevy_cloth::solver::ClothSolver;
use bevy_cloth::stats::StepTimes;

/// A small seeded generator (xorshift64*): the same seed drives the same soak.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from `seed` (any value).
    pub fn new(seed: u64) -> Self {
        Rng(seed ^ 0x9E37_79B9_7F4A_7C15 | 1)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform in `0..n` (0 for `n = 0`).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next_u64() % n as u64) as usize
        }
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f32) -> bool {
        self.unit() < p
    }
}

/// What a soak did and found.
#[derive(Clone, Debug, Default, Serialize)]
pub struct SoakSummary {
    /// Wall-clock seconds run.
    pub seconds: f64,
    /// Steps taken.
    pub steps: u64,
    /// Simulated seconds.
    pub simulated_seconds: f64,
    /// Grabs started (each dragged for a while, then released).
    pub grabs: u64,
    /// Cut strokes, and the springs they cut.
    pub cuts: u64,
    /// Springs cut by the strokes.
    pub springs_cut: u64,
    /// Springs torn by stretching (tearing switched on at random).
    pub springs_torn: u64,
    /// Valid parameter edits applied.
    pub edits: u64,
    /// Model switches among them.
    pub model_switches: u64,
    /// Invalid edits, every one refused with the old parameters kept.
    pub refused_edits: u64,
    /// Invalid edits that were accepted or changed the parameters (a bug).
    pub accepted_invalid_edits: u64,
    /// Resets.
    pub resets: u64,
    /// Steps after which a position or velocity was not finite (a bug: every edit keeps
    /// the automatic substeps, or XPBD, so no configuration is unstable by construction).
    pub non_finite_steps: u64,
    /// Steps after which a structural spring was past 100% strain (each reset after).
    pub unstable_steps: u64,
    /// Resident memory after the first tenth of the run, MB.
    pub rss_start_mb: f64,
    /// Largest resident memory sampled, MB.
    pub rss_peak_mb: f64,
    /// Resident memory at the end, MB.
    pub rss_end_mb: f64,
    /// Median and largest step time, ms.
    pub median_step_ms: f64,
    /// The largest step time, ms (a model switch's or a reset's included).
    pub max_step_ms: f64,
}

impl SoakSummary {
    /// No bug found: every step finite, every invalid edit refused, and the resident
    /// memory at the end within 16 MB (allocator noise) of where it settled.
    pub fn passed(&self) -> bool {
        self.non_finite_steps == 0
            && self.accepted_invalid_edits == 0
            && self.rss_end_mb - self.rss_start_mb <= 16.0
    }
}

/// The process's resident memory in MB (Linux `/proc/self/statm`; 0 elsewhere).
pub fn resident_mb() -> f64 {
    let pages = std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(1)?.parse::<f64>().ok())
        .unwrap_or(0.0);
    pages * 4096.0 / (1 << 20) as f64
}

/// A random valid edit of `base`: a model (patches only on grids), stiffness, mass, drag,
/// strain limit, tearing. Substeps stay automatic except XPBD's (stable at any count).
fn random_params(rng: &mut Rng, base: &ClothParams, grid: bool) -> ClothParams {
    let mut p = *base;
    p.model = match rng.below(if grid { 4 } else { 3 }) {
        0 => Model::MassSpring,
        1 => Model::Xpbd(XpbdParams::default()),
        2 => Model::ShapeMatching(ShapeMatchingParams {
            clusters: 1 + rng.below(4) as u32,
            ..ShapeMatchingParams::default()
        }),
        _ => {
            let size = [1, 2, 4, 8][rng.below(4)];
            Model::Patches(PatchParams {
                part_width: size,
                part_height: size,
                ..PatchParams::default()
            })
        }
    };
    p.substeps = match p.model {
        Model::Xpbd(_) if rng.chance(0.5) => Substeps::Fixed(5 + rng.below(30) as u32),
        _ => Substeps::default(),
    };
    let k = rng.range(5.0, 500.0);
    p.springs.structural.stiffness = k;
    p.springs.shear.stiffness = k * 0.5;
    p.springs.bend.stiffness = k * rng.range(0.05, 0.5);
    p.node_mass = base.node_mass * rng.range(0.5, 2.0);
    p.drag = base.drag * rng.range(0.0, 4.0);
    p.strain_limit = rng.chance(0.8).then(|| rng.range(0.05, 0.3));
    p.tear_ratio = rng.chance(0.3).then(|| rng.range(1.3, 3.0));
    p
}

/// A random invalid edit of `base` (the validation must refuse each).
fn invalid_params(rng: &mut Rng, base: &ClothParams) -> ClothParams {
    let mut p = *base;
    match rng.below(6) {
        0 => p.node_mass = -1.0,
        1 => p.springs.structural.stiffness = f32::NAN,
        2 => p.substeps = Substeps::Fixed(0),
        3 => p.drag = f32::INFINITY,
        4 => p.strain_limit_iterations = u32::MAX,
        _ => p.substeps = Substeps::Fixed(u32::MAX),
    }
    p
}

/// A grab lasts a while; its target wanders.
#[derive(Default)]
struct Grabbing {
    /// Steps left.
    left: u32,
    target: Vec3,
}

/// What the player does in a step, by chance: grabs and drags, cuts, edits (valid and
/// invalid: `base` and whether the cloth is a `grid` bound them), resets; counted in
/// `summary`.
fn act(
    cloth: &mut ClothSolver,
    rng: &mut Rng,
    summary: &mut SoakSummary,
    grab: &mut Grabbing,
    (base, grid): (&ClothParams, bool),
) -> Result<(), String> {
    if grab.left > 0 {
        grab.left -= 1;
        grab.target += Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 0.0) * 0.01;
        cloth.drag_grab(grab.target);
        if grab.left == 0 {
            cloth.release_grab();
        }
    } else if rng.chance(0.01) {
        let i = rng.below(cloth.particle_count()) as u32;
        if cloth.grab(i) {
            summary.grabs += 1;
            grab.left = 20 + rng.below(100) as u32;
            grab.target = cloth.positions()[i as usize];
        }
    }
    if rng.chance(0.005) {
        // A stroke through the cloth's middle from a camera in front of it.
        let (centre, radius) = cloth.bounding_sphere();
        let eye = centre + Vec3::Z * (3.0 * radius + 1.0);
        let far = |rng: &mut Rng| {
            let aim = centre + Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 0.0) * radius;
            eye + (aim - eye) * 3.0
        };
        let (b, c) = (far(rng), far(rng));
        summary.cuts += 1;
        summary.springs_cut += cloth.cut(eye, b, c) as u64;
    }
    if rng.chance(0.004) {
        let before = *cloth.params();
        let params = random_params(rng, base, grid);
        cloth
            .set_params(&params)
            .map_err(|e| format!("a valid edit was refused: {e}"))?;
        summary.edits += 1;
        if std::mem::discriminant(&before.model) != std::mem::discriminant(&params.model) {
            summary.model_switches += 1;
        }
    }
    if rng.chance(0.002) {
        let before = *cloth.params();
        let params = invalid_params(rng, &before);
        match cloth.set_params(&params) {
            Err(_) if *cloth.params() == before => summary.refused_edits += 1,
            _ => summary.accepted_invalid_edits += 1,
        }
    }
    if rng.chance(0.001) {
        cloth.reset();
        summary.resets += 1;
    }
    Ok(())
}

/// Soaks cloth `index` of `scene` for `duration` of wall-clock time, or `most_steps`
/// steps if they come first, with `seed` (the same seed and steps, the same soak).
/// `progress` is called about once a second with the summary so far.
pub fn soak(
    scene: &ClothScene,
    index: usize,
    (duration, most_steps): (Duration, Option<u64>),
    seed: u64,
    mut progress: impl FnMut(&SoakSummary),
) -> Result<SoakSummary, String> {
    let mut run = SceneRun::new(scene).map_err(|e| e.to_string())?;
    if index >= run.cloths.len() {
        return Err(format!(
            "--cloth {index}: the scene has {} cloths",
            run.cloths.len()
        ));
    }
    let base_env = run.environment;
    let dt = run.timestep;
    let mut env = base_env;
    let (_, cloth) = &mut run.cloths[index];
    let base = *cloth.params();
    let grid = cloth.grid_size().is_some();
    let mut rng = Rng::new(seed);
    let mut summary = SoakSummary::default();
    let mut times = StepTimes::default();
    let start = Instant::now();
    let mut last_report = start;
    let mut settled = false;
    let mut grab = Grabbing::default();
    let steps_left = |done: u64| most_steps.is_none_or(|most| done < most);
    while start.elapsed() < duration && steps_left(summary.steps) {
        let t = summary.steps as f32 * dt;
        // Gusty wind: the scene's, swelling and turning, with random gusts.
        env.wind.strength = base_env.wind.strength.max(2e-4)
            * (1.0 + (0.7 * t).sin() + if rng.chance(0.02) { 4.0 } else { 0.0 });
        env.wind.direction = Vec3::new((0.3 * t).sin(), 0.0, (0.3 * t).cos());
        // What the player does.
        act(cloth, &mut rng, &mut summary, &mut grab, (&base, grid))?;
        let clock = Instant::now();
        cloth.step(dt, &env);
        let torn = cloth.last_torn().len() as u64;
        summary.springs_torn += torn;
        times.push(clock.elapsed().as_secs_f64() * 1e3);
        summary.max_step_ms = summary.max_step_ms.max(clock.elapsed().as_secs_f64() * 1e3);
        summary.steps += 1;
        if !cloth.is_finite() {
            summary.non_finite_steps += 1;
            cloth.reset();
        } else if !cloth.is_stable() {
            summary.unstable_steps += 1;
            cloth.reset();
        }
        // Memory: settled after the first tenth of the run, then sampled every second.
        let tenth = most_steps.is_some_and(|most| summary.steps >= most / 10);
        if !settled && (start.elapsed() >= duration / 10 || tenth) {
            settled = true;
            summary.rss_start_mb = resident_mb();
        }
        if last_report.elapsed() >= Duration::from_secs(1) {
            last_report = Instant::now();
            let rss = resident_mb();
            summary.rss_peak_mb = summary.rss_peak_mb.max(rss);
            summary.seconds = start.elapsed().as_secs_f64();
            progress(&summary);
        }
    }
    summary.seconds = start.elapsed().as_secs_f64();
    summary.simulated_seconds = summary.steps as f64 * dt as f64;
    summary.rss_end_mb = resident_mb();
    summary.rss_peak_mb = summary.rss_peak_mb.max(summary.rss_end_mb);
    if !settled {
        summary.rss_start_mb = summary.rss_end_mb;
    }
    summary.median_step_ms = times.median();
    Ok(summary)
}
