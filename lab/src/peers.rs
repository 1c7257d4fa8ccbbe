//! Speed at equal accuracy against other solvers, in one run: a square cloth of `side × side`
//! particles 5 cm apart, hung in the XY plane from its whole top row (or its two top
//! corners), as inextensible as each solver allows, 60 frames of 1/60 s from rest under
//! gravity. Each solver gets the same grid, the same pins and the same frames; each is
//! timed frame by frame on the same machine in the same process, and its accuracy is read
//! the same way from its final positions:
//! - **strain**: the largest stretch of a structural neighbour pair (along a row or a
//!   column) over its rest length, minus 1 (0 is exact);
//! - **sag**: how far the bottom row's mean has dropped below where it started, over the
//!   cloth's rest height (what a viewer sees as stretch).
//!
//! The solvers:
//! - ours: XPBD with every in-plane family inextensible (`k = inf`), at fixed substeps,
//!   its stretch constraints solved along lines (the default) or swept (the solver
//!   before lines), with and without tethers;
//! - rapier-cloth-core 0.3 (CPU XPBD, area masses, long-range tethers to its pins), its
//!   steps a frame and iterations a step swept;
//! - [`Sticks`]: the classic position Verlet with stick projection (Jakobsen 2001,
//!   "Advanced Character Physics", which bevy_silk implements), its sweeps swept.
//!
//! A run that fails (a position not finite, or strain past 100%) gets no time and no rank.

use std::time::Instant;

use bevy::math::{Affine3A, Quat, Vec3};
use serde::Serialize;

use bevy_cloth::error::ClothError;
use bevy_cloth::lab::median;
use bevy_cloth::layout::shape::{ClothPins, ClothShape};
use bevy_cloth::params::{
    ClothParams, Environment, Model, SpringFamily, Substeps, XpbdParams, XpbdSolve,
};

/// Rest spacing of the grid, m.
pub const SPACING: f32 = 0.05;
/// Mass per particle, kg (rapier-cloth-core's default areal density, 0.2 kg/m², over a
/// 5 cm cell).
pub const NODE_MASS: f32 = 0.2 * SPACING * SPACING;
/// Velocity damping, 1/s (rapier-cloth-core's default; ours as drag `c = rate · m`).
pub const DAMPING_RATE: f32 = 0.1;
/// One frame, s.
pub const FRAME: f32 = 1.0 / 60.0;
/// Frames not timed at the start (caches, the pool's threads waking).
pub const WARMUP_FRAMES: usize = 5;

/// What holds the cloth up, and how it starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Hang {
    /// Its whole top row, hanging straight down at rest.
    TopRow,
    /// Its two top corners (the curtain), hanging in its plane.
    Corners,
    /// Its whole top row, starting level (in the XZ plane) and swinging down: the
    /// dynamic case, where the cloth is loaded by its own motion, not only its weight.
    Swing,
}

impl Hang {
    /// The pinned particle indices of a `side`-wide grid.
    pub fn pins(self, side: usize) -> Vec<u32> {
        match self {
            Hang::TopRow | Hang::Swing => (0..side as u32).collect(),
            Hang::Corners => vec![0, side as u32 - 1],
        }
    }

    /// The direction rows run from the top row: down, or level for the swing.
    fn down(self) -> Vec3 {
        match self {
            Hang::Swing => Vec3::Z,
            _ => -Vec3::Y,
        }
    }
}

/// One configuration of one solver.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum Peer {
    /// Our XPBD at `substeps` fixed substeps, with or without tethers to the pins, with
    /// or without self-collision (what it costs, beside the same run without).
    Ours {
        /// Substeps per frame.
        substeps: u32,
        /// Long-range attachments on.
        tethers: bool,
        /// Self-collision on (at the rest spacing).
        self_collision: bool,
        /// The stretch constraints solved along lines (`XpbdSolve::Lines`), or swept.
        lines: bool,
    },
    /// rapier-cloth-core: `steps` steps a frame of `iterations` iterations each.
    Rapier {
        /// Steps per frame (its substeps).
        steps: usize,
        /// Iterations per step.
        iterations: usize,
    },
    /// Verlet + sticks, `sweeps` Gauss–Seidel sweeps a frame.
    Sticks {
        /// Projection sweeps per frame.
        sweeps: usize,
    },
}

/// The solvers by the names `cloth peers --solvers` takes.
pub const PEER_SOLVERS: [&str; 6] = ["ours", "tethers", "lines", "self", "rapier", "sticks"];

impl Peer {
    /// The solver's name in [`PEER_SOLVERS`].
    pub fn key(&self) -> &'static str {
        match self {
            Peer::Ours {
                self_collision: true,
                ..
            } => "self",
            Peer::Ours { lines: true, .. } => "lines",
            Peer::Ours { tethers: false, .. } => "ours",
            Peer::Ours { tethers: true, .. } => "tethers",
            Peer::Rapier { .. } => "rapier",
            Peer::Sticks { .. } => "sticks",
        }
    }

    /// The solver's name in the table.
    pub fn solver(&self) -> &'static str {
        match self {
            Peer::Ours {
                self_collision: true,
                ..
            } => "bevy_cloth XPBD lines + tethers + self-collision",
            Peer::Ours { lines: true, .. } => "bevy_cloth XPBD lines + tethers",
            Peer::Ours { tethers: false, .. } => "bevy_cloth XPBD sweep",
            Peer::Ours { tethers: true, .. } => "bevy_cloth XPBD sweep + tethers",
            Peer::Rapier { .. } => "rapier-cloth-core 0.3",
            Peer::Sticks { .. } => "Verlet + sticks",
        }
    }

    /// The configuration in the table.
    pub fn label(&self) -> String {
        match self {
            Peer::Ours { substeps, .. } => format!("{substeps} substeps"),
            Peer::Rapier { steps, iterations } => {
                format!("{steps} step(s) x {iterations} iterations")
            }
            Peer::Sticks { sweeps } => format!("{sweeps} sweeps"),
        }
    }
}

/// The default sweep: each solver from cheap and loose to dear and tight.
pub fn default_peers() -> Vec<Peer> {
    let mut peers = Vec::new();
    // The sweep (the solver before lines), alone and with tethers.
    for substeps in [5, 10, 20, 40, 80] {
        peers.push(Peer::Ours {
            substeps,
            tethers: false,
            self_collision: false,
            lines: false,
        });
    }
    for substeps in [1, 2, 5, 10, 20, 40, 80] {
        peers.push(Peer::Ours {
            substeps,
            tethers: true,
            self_collision: false,
            lines: false,
        });
    }
    // The default: lines and tethers.
    for substeps in [1, 2, 3, 4, 5, 10, 20, 40] {
        peers.push(Peer::Ours {
            substeps,
            tethers: true,
            self_collision: false,
            lines: true,
        });
    }
    // What self-collision costs: the configurations a game would pick, again with it on.
    for substeps in [2, 5, 10] {
        peers.push(Peer::Ours {
            substeps,
            tethers: true,
            self_collision: true,
            lines: true,
        });
    }
    for (steps, iterations) in [(1, 2), (1, 4), (1, 8), (1, 16), (2, 8), (4, 8)] {
        peers.push(Peer::Rapier { steps, iterations });
    }
    for sweeps in [5, 20, 40, 160] {
        peers.push(Peer::Sticks { sweeps });
    }
    peers
}

/// One measured configuration.
#[derive(Clone, Debug, Serialize)]
pub struct PeerRow {
    /// Particles across (and down).
    pub side: usize,
    /// How it hangs.
    pub hang: Hang,
    /// The solver.
    pub solver: String,
    /// Its configuration.
    pub label: String,
    /// The configuration as data.
    pub peer: Peer,
    /// ms per frame: median over the timed frames, and the 10th and 90th percentiles
    /// (`None` for a failed run).
    pub ms: Option<f64>,
    /// The 10th–90th percentile of the per-frame times.
    pub ms_spread: Option<(f64, f64)>,
    /// Largest structural stretch at the end (fraction; `None` when failed).
    pub strain: Option<f64>,
    /// Bottom row's mean drop over the rest height (fraction).
    pub sag: Option<f64>,
    /// Why the run failed, if it did.
    pub failed: Option<String>,
    /// The whole frame's time over its constraint projections, ns (an upper bound on one
    /// projection's cost: prediction, velocity and bookkeeping are in it too).
    pub ns_per_projection: Option<f64>,
}

/// A solver's cheapest configuration within a strain, on one side.
#[derive(Clone, Debug, Serialize)]
pub struct Cheapest {
    /// Particles across.
    pub side: usize,
    /// The strain it is within (fraction).
    pub within: f64,
    /// The solver.
    pub solver: String,
    /// Its cheapest configuration within it.
    pub label: String,
    /// Its median ms per frame.
    pub ms: f64,
    /// Its strain.
    pub strain: f64,
    /// rapier-cloth-core's cheapest ms within the same strain over this one's (`None`
    /// when rapier-cloth-core did not reach it or was not run).
    pub rapier_over: Option<f64>,
}

/// For each side, strain in `within` and solver (in the rows' order): the cheapest run
/// that did not fail and is within the strain. Solvers that reach none are left out.
pub fn cheapest_within(rows: &[PeerRow], within: &[f64]) -> Vec<Cheapest> {
    let mut out = Vec::new();
    let mut sides: Vec<usize> = rows.iter().map(|r| r.side).collect();
    sides.sort_unstable();
    sides.dedup();
    for &side in &sides {
        for &limit in within {
            let best = |solver: &str| {
                rows.iter()
                    .filter(|r| r.side == side && r.solver == solver)
                    .filter_map(|r| Some((r, r.ms?, r.strain?)))
                    .filter(|(_, _, strain)| *strain <= limit)
                    .min_by(|a, b| a.1.total_cmp(&b.1))
            };
            let rapier = best(
                Peer::Rapier {
                    steps: 1,
                    iterations: 1,
                }
                .solver(),
            )
            .map(|(_, ms, _)| ms);
            let mut solvers: Vec<&str> = Vec::new();
            for r in rows {
                if !solvers.contains(&r.solver.as_str()) {
                    solvers.push(&r.solver);
                }
            }
            for solver in solvers {
                if let Some((r, ms, strain)) = best(solver) {
                    out.push(Cheapest {
                        side,
                        within: limit,
                        solver: solver.into(),
                        label: r.label.clone(),
                        ms,
                        strain,
                        rapier_over: rapier.map(|rapier| rapier / ms),
                    });
                }
            }
        }
    }
    out
}

/// A solver the bench can step frame by frame.
trait Frames {
    fn frame(&mut self) -> Result<(), String>;
    fn positions(&self) -> Vec<Vec3>;
    /// Constraint projections a frame: constraints × their iterations (substeps, or steps
    /// × iterations).
    fn projections(&self) -> f64;
}

/// Measures `peer` on the `side × side` cloth hung by `hang` over `frames` frames.
pub fn measure(side: usize, hang: Hang, peer: Peer, frames: usize) -> Result<PeerRow, String> {
    let mut solver: Box<dyn Frames> = match peer {
        Peer::Ours {
            substeps,
            tethers,
            self_collision,
            lines,
        } => {
            let mut params = ours_params(substeps, tethers, lines);
            params.self_collision.enabled = self_collision;
            Box::new(Ours::new(side, hang, &params)?)
        }
        Peer::Rapier { steps, iterations } => Box::new(Rapier::new(side, hang, steps, iterations)?),
        Peer::Sticks { sweeps } => Box::new(Sticks::new(side, hang, sweeps)),
    };
    let mut times = Vec::with_capacity(frames);
    let mut failed = None;
    for frame in 0..frames {
        let start = Instant::now();
        let result = solver.frame();
        let ms = start.elapsed().as_secs_f64() * 1e3;
        if let Err(e) = result {
            failed = Some(format!("frame {}: {e}", frame + 1));
            break;
        }
        if frame >= WARMUP_FRAMES.min(frames.saturating_sub(1)) {
            times.push(ms);
        }
    }
    let x = solver.positions();
    let (strain, sag) = accuracy(&x, &rest(side, hang), side);
    if failed.is_none() && !x.iter().all(|p| p.is_finite()) {
        failed = Some("a position is not finite".into());
    }
    // A NaN strain (a broken state) fails too.
    if failed.is_none() && (strain.is_nan() || strain > 1.0) {
        failed = Some(format!("strain {:.0}% (past 100%)", strain * 100.0));
    }
    let ok = failed.is_none();
    let projections = solver.projections();
    let spread = ok.then(|| {
        let mut sorted = times.clone();
        sorted.sort_by(f64::total_cmp);
        let at = |q: f64| sorted[((sorted.len() - 1) as f64 * q).round() as usize];
        (at(0.1), at(0.9))
    });
    Ok(PeerRow {
        side,
        hang,
        solver: peer.solver().into(),
        label: peer.label(),
        peer,
        ms: ok.then(|| median(&mut times)),
        ns_per_projection: ok.then(|| median(&mut times) * 1e6 / projections),
        ms_spread: spread,
        strain: ok.then_some(strain),
        sag: ok.then_some(sag),
        failed,
    })
}

/// `(strain, sag)` of a `side × side` row-major grid's positions that started at `rest`
/// (see the module doc).
pub fn accuracy(x: &[Vec3], rest: &[Vec3], side: usize) -> (f64, f64) {
    let mut strain = 0.0f64;
    for j in 0..side {
        for i in 0..side {
            let p = x[j * side + i];
            for q in [
                (i + 1 < side).then(|| x[j * side + i + 1]),
                x.get((j + 1) * side + i).copied(),
            ]
            .into_iter()
            .flatten()
            {
                strain = strain.max(f64::from(p.distance(q) / SPACING) - 1.0);
            }
        }
    }
    let mean_y = |x: &[Vec3]| {
        let bottom = &x[(side - 1) * side..];
        bottom.iter().map(|p| f64::from(p.y)).sum::<f64>() / side as f64
    };
    let sag = (mean_y(rest) - mean_y(x)) / ((side - 1) as f64 * f64::from(SPACING));
    (strain, sag)
}

/// The start: column `i` at `x = i·spacing`, row `j` `j·spacing` from the top row along
/// [`Hang::down`].
pub fn rest(side: usize, hang: Hang) -> Vec<Vec3> {
    (0..side * side)
        .map(|k| {
            let (i, j) = ((k % side) as f32, (k / side) as f32);
            Vec3::X * (i * SPACING) + hang.down() * (j * SPACING)
        })
        .collect()
}

fn gravity() -> Vec3 {
    Vec3::new(0.0, -9.81, 0.0)
}

// ----- ours -----------------------------------------------------------------------------

/// Our parameters for the bench: XPBD at `substeps`, structural and shear inextensible,
/// bend at the default stiffness, the bench's mass and damping; the stretch solved along
/// lines or swept.
pub fn ours_params(substeps: u32, tethers: bool, lines: bool) -> ClothParams {
    let mut params = ClothParams {
        model: Model::Xpbd(XpbdParams {
            tethers,
            solve: if lines {
                XpbdSolve::Lines
            } else {
                XpbdSolve::Sweep
            },
            ..XpbdParams::default()
        }),
        node_mass: NODE_MASS,
        drag: DAMPING_RATE * NODE_MASS,
        substeps: Substeps::Fixed(substeps),
        strain_limit: None,
        ..ClothParams::seeds()
    };
    params.springs.structural = SpringFamily::new(f32::INFINITY);
    params.springs.shear = SpringFamily::new(f32::INFINITY);
    params.springs.damping = 0.0;
    params
}

struct Ours {
    cloth: bevy_cloth::solver::ClothSolver,
    env: Environment,
}

impl Ours {
    fn new(side: usize, hang: Hang, params: &ClothParams) -> Result<Self, String> {
        let cloth = ours(side, hang, params).map_err(|e: ClothError| e.to_string())?;
        let mut env = Environment::default();
        env.wind.strength = 0.0;
        env.gravity = gravity();
        Ok(Self { cloth, env })
    }
}

/// Our cloth of the bench: the `side × side` grid at [`SPACING`], hung by `hang` (its top
/// row's middle at the bench's origin, turned level for the swing), with `params`.
pub fn ours(
    side: usize,
    hang: Hang,
    params: &ClothParams,
) -> Result<bevy_cloth::solver::ClothSolver, ClothError> {
    let shape = ClothShape::Grid {
        width: side as u32,
        height: side as u32,
        spacing: SPACING,
    };
    // The grid hangs down −y from the middle of its top edge: moved to the bench's
    // origin, and turned level (rows along +z) for the swing.
    let half = (side - 1) as f32 * SPACING * 0.5;
    let level = match hang {
        Hang::Swing => Quat::from_rotation_x(std::f32::consts::FRAC_PI_2),
        _ => Quat::IDENTITY,
    };
    let frame = Affine3A::from_rotation_translation(level, Vec3::new(half, 0.0, 0.0));
    let pins = ClothPins::Indices(hang.pins(side));
    shape.build_solver(&pins, params, frame)
}

impl Frames for Ours {
    fn frame(&mut self) -> Result<(), String> {
        self.cloth.step(FRAME, &self.env);
        Ok(())
    }

    fn positions(&self) -> Vec<Vec3> {
        self.cloth.positions().to_vec()
    }

    fn projections(&self) -> f64 {
        f64::from(self.cloth.substeps()) * self.cloth.spring_count() as f64
    }
}

// ----- rapier-cloth-core ----------------------------------------------------------------

struct Rapier {
    cloth: rapier_cloth_core::Cloth,
    solver: rapier_cloth_core::Solver,
    settings: rapier_cloth_core::SolverSettings,
    steps: usize,
}

fn to_rapier(v: Vec3) -> rapier_cloth_core::Vec3 {
    rapier_cloth_core::Vec3::new(v.x, v.y, v.z)
}

impl Rapier {
    fn new(side: usize, hang: Hang, steps: usize, iterations: usize) -> Result<Self, String> {
        use rapier_cloth_core::{Cloth, ClothMaterial, GridBuilder, Solver, SolverSettings};
        let size = (side - 1) as f32 * SPACING;
        // Rows from the top edge at the origin along [`Hang::down`], as [`rest`].
        let mesh = GridBuilder::new(side, side)
            .size(size, size)
            .axes(to_rapier(Vec3::X), to_rapier(hang.down()))
            .build()
            .map_err(|e| e.to_string())?;
        let material = ClothMaterial {
            surface_density: NODE_MASS / (SPACING * SPACING),
            stretch_compliance: 0.0,
            damping: DAMPING_RATE,
            ..ClothMaterial::default()
        };
        let mut cloth = Cloth::new(mesh, material).map_err(|e| e.to_string())?;
        let rest = rest(side, hang);
        for i in hang.pins(side) {
            cloth
                .pin(i, to_rapier(rest[i as usize]))
                .map_err(|e| e.to_string())?;
        }
        let settings = SolverSettings {
            iterations,
            ..SolverSettings::default()
        };
        Ok(Self {
            cloth,
            solver: Solver::new(),
            settings,
            steps,
        })
    }
}

impl Frames for Rapier {
    fn frame(&mut self) -> Result<(), String> {
        let h = FRAME / self.steps as f32;
        for _ in 0..self.steps {
            self.solver
                .step(&mut self.cloth, h, to_rapier(gravity()), &self.settings)
                .map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    fn projections(&self) -> f64 {
        let mesh = self.cloth.mesh();
        let constraints = mesh.edges().len() + mesh.hinges().len();
        (self.steps * self.settings.iterations * constraints) as f64
    }

    fn positions(&self) -> Vec<Vec3> {
        self.cloth
            .positions()
            .iter()
            .map(|p| Vec3::new(p.x, p.y, p.z))
            .collect()
    }
}

// ----- Verlet + sticks ------------------------------------------------------------------

/// Position Verlet with stick projection (Jakobsen 2001): a step moves every free
/// particle by `x − x_prev` (damped) plus `g·dt²`, then `sweeps` Gauss–Seidel sweeps set
/// every stick (structural and shear) back to its rest length, each end by half, a pinned
/// end not at all. Written here as the baseline bevy_silk implements, on one core.
pub struct Sticks {
    x: Vec<Vec3>,
    previous: Vec<Vec3>,
    free: Vec<bool>,
    sticks: Vec<(u32, u32, f32)>,
    sweeps: usize,
}

impl Sticks {
    /// The bench's cloth as sticks.
    pub fn new(side: usize, hang: Hang, sweeps: usize) -> Self {
        let x = rest(side, hang);
        let mut free = vec![true; x.len()];
        for i in hang.pins(side) {
            free[i as usize] = false;
        }
        let index = |i: usize, j: usize| (j * side + i) as u32;
        let mut sticks = Vec::new();
        for j in 0..side {
            for i in 0..side {
                let mut add = |a: u32, b: u32| {
                    sticks.push((a, b, x[a as usize].distance(x[b as usize])));
                };
                if i + 1 < side {
                    add(index(i, j), index(i + 1, j));
                }
                if j + 1 < side {
                    add(index(i, j), index(i, j + 1));
                }
                if i + 1 < side && j + 1 < side {
                    add(index(i, j), index(i + 1, j + 1));
                    add(index(i + 1, j), index(i, j + 1));
                }
            }
        }
        Self {
            previous: x.clone(),
            x,
            free,
            sticks,
            sweeps,
        }
    }
}

impl Frames for Sticks {
    fn frame(&mut self) -> Result<(), String> {
        let keep = 1.0 - DAMPING_RATE * FRAME;
        let fall = gravity() * FRAME * FRAME;
        for ((x, previous), &free) in self.x.iter_mut().zip(&mut self.previous).zip(&self.free) {
            if free {
                let next = *x + (*x - *previous) * keep + fall;
                *previous = *x;
                *x = next;
            }
        }
        for _ in 0..self.sweeps {
            for &(a, b, rest) in &self.sticks {
                let (a, b) = (a as usize, b as usize);
                let d = self.x[b] - self.x[a];
                let len = d.length();
                if len <= f32::EPSILON {
                    continue;
                }
                let push = d * ((len - rest) / len);
                match (self.free[a], self.free[b]) {
                    (true, true) => {
                        self.x[a] += push * 0.5;
                        self.x[b] -= push * 0.5;
                    }
                    (true, false) => self.x[a] += push,
                    (false, true) => self.x[b] -= push,
                    (false, false) => {}
                }
            }
        }
        Ok(())
    }

    fn positions(&self) -> Vec<Vec3> {
        self.x.clone()
    }

    fn projections(&self) -> f64 {
        (self.sweeps * self.sticks.len()) as f64
    }
}
