//! The crowd: characters walking their own loops across a square, each with a cape
//! (attached at the shoulders) and a skirt (skinned: held within a painted distance of
//! the hips, with a back stop), each cloth drawn through a finer proxy mesh, every few
//! seconds one of them teleported across the square, a gusty wind zone across its
//! middle. The headless twin of `examples/crowd.rs`: it times what a game's frame spends
//! on the cloth (driving the bodies' pins, targets, colliders and wind; the cloths'
//! step; drawing: normals and the proxies' vertices), on one thread and on the pool.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use bevy::math::{Affine3A, Quat, Vec3};
use serde::Serialize;

use bevy_cloth::headless::WHOLE_STRAIN;
use bevy_cloth::layout::shape::{ClothPins, ClothShape};
use bevy_cloth::params::{ClothParams, Environment, Turbulence, WindZone, ZoneShape};
use bevy_cloth::prelude::ClothBudget;
use bevy_cloth::solver::shapes::Capsule;
use bevy_cloth::solver::{
    self, BackStop, BudgetClaim, ClothSolver, Collider, ColliderShape, Layout, Motion, ProxyBinding,
};

/// How big the crowd is.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct CrowdSize {
    /// Characters, each with a cape and a skirt.
    pub characters: usize,
    /// The cape's particles across and down.
    pub cape: (u32, u32),
    /// The skirt's particles around and down.
    pub skirt: (u32, u32),
    /// How many times finer each way the drawn meshes are than the simulated ones.
    pub refine: u32,
    /// Seconds between teleports (one character at a time, in turn).
    pub teleport_every: f32,
    /// Whether the wind zone blows (through the air model on every triangle it reaches).
    pub wind: bool,
}

impl Default for CrowdSize {
    /// 50 characters: 100 cloths of 384 particles (38,400), drawn 3 × 3 finer.
    fn default() -> Self {
        CrowdSize {
            characters: 50,
            cape: (16, 24),
            skirt: (32, 12),
            refine: 3,
            teleport_every: 3.0,
            wind: true,
        }
    }
}

/// Shoulder height, hip height and the body's radius, m.
const SHOULDERS: f32 = 1.45;
const HIPS: f32 = 0.95;
const BODY_RADIUS: f32 = 0.17;

/// One character's walk: a loop about `centre` of `radius` at `speed`, and the offset a
/// teleport has put it at.
#[derive(Clone, Copy, Debug)]
struct Walk {
    centre: Vec3,
    radius: f32,
    speed: f32,
    phase: f32,
    away: bool,
}

impl Walk {
    /// Where the body is at time `t`: its rotation (facing along the loop) and position.
    fn pose(&self, t: f32) -> (Quat, Vec3) {
        let angle = self.phase + self.speed * t / self.radius;
        let (s, c) = angle.sin_cos();
        let jump = if self.away {
            Vec3::X * 12.0
        } else {
            Vec3::ZERO
        };
        let at = self.centre + self.radius * Vec3::new(c, 0.0, s) + jump;
        // Facing along the tangent (−sin, 0, cos), with a bob of the walk.
        let facing = Quat::from_rotation_y(-angle);
        (facing, at + Vec3::Y * 0.02 * (4.0 * angle).sin())
    }
}

/// A cloth drawn through a proxy: the simulation, its proxy binding and the drawn
/// buffers, its pins' rest offsets in the body's frame.
struct Drawn {
    cloth: ClothSolver,
    in_body: Vec<Vec3>,
    binding: ProxyBinding,
    normals: Vec<Vec3>,
    local: Vec<Vec3>,
    positions: Vec<[f32; 3]>,
    drawn_normals: Vec<[f32; 3]>,
}

impl Drawn {
    /// `cloth` drawn through a clone of `binding` (what binding worked out is shared by
    /// every cloth of the shape, as a game's instances of one cape share their asset's).
    fn new(cloth: ClothSolver, in_body: Vec<Vec3>, binding: &ProxyBinding) -> Self {
        let binding = binding.clone();
        let (n, m) = (cloth.particle_count(), binding.len());
        Drawn {
            cloth,
            in_body,
            binding,
            normals: vec![Vec3::ZERO; n],
            local: vec![Vec3::ZERO; n],
            positions: vec![[0.0; 3]; m],
            drawn_normals: vec![[0.0; 3]; m],
        }
    }

    /// What a game's write-back does: the normals, and each drawn vertex placed (the
    /// example's meshes have no tangents). How long placing took.
    fn draw(&mut self) -> Duration {
        self.cloth.normals_into(&mut self.normals);
        let start = Instant::now();
        self.local.copy_from_slice(self.cloth.positions());
        self.binding.place(
            &self.local,
            &self.normals,
            &mut self.positions,
            &mut self.drawn_normals,
            None,
        );
        start.elapsed()
    }
}

/// A grid's rest positions in its own frame (x across, y down from 0), `k` times finer.
fn grid_points(w: u32, h: u32, spacing: f32, k: u32) -> Vec<Vec3> {
    let (fw, fh) = ((w - 1) * k + 1, (h - 1) * k + 1);
    let step = spacing / k as f32;
    (0..fw * fh)
        .map(|v| Vec3::new((v % fw) as f32 * step, -((v / fw) as f32) * step, 0.0))
        .collect()
}

/// A cone (a skirt) of `around × down` particles from the waist (radius 0.19 m at hip
/// height) flaring to 0.31 m 0.42 m below, `k` times finer; its triangles.
fn cone(around: u32, down: u32, k: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (fa, fd) = (around * k, (down - 1) * k + 1);
    let mut points = Vec::with_capacity((fa * fd) as usize);
    for j in 0..fd {
        let s = j as f32 / (fd - 1) as f32;
        for i in 0..fa {
            let a = std::f32::consts::TAU * i as f32 / fa as f32;
            let r = 0.19 + 0.12 * s;
            points.push(Vec3::new(r * a.sin(), HIPS - 0.42 * s, r * a.cos()));
        }
    }
    let mut triangles = Vec::new();
    for j in 0..fd - 1 {
        for i in 0..fa {
            let (a, b) = (j * fa + i, j * fa + (i + 1) % fa);
            triangles.push([a, a + fa, b]);
            triangles.push([b, a + fa, b + fa]);
        }
    }
    (points, triangles)
}

/// A character: its walk, its cape and its skirt, and the skirt's painted distances.
struct Character {
    walk: Walk,
    cape: Drawn,
    skirt: Drawn,
    cape_top: u32,
    skirt_radius: Vec<f32>,
    last_pose: (Quat, Vec3),
}

/// What one frame cost, ms.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct FrameCost {
    /// The bodies moved: pins, skinned targets, colliders and wind zones handed over.
    pub drive: f64,
    /// The cloths' step.
    pub step: f64,
    /// Drawing: normals and every proxy vertex placed.
    pub draw: f64,
    /// Of the drawing, placing the proxies' vertices: each cloth's placing timed and
    /// summed (on the pool, over both threads).
    pub place: f64,
}

/// The crowd.
pub struct Crowd {
    characters: Vec<Character>,
    zones: [WindZone; 1],
    env: Environment,
    dt: f32,
    time: f32,
    size: CrowdSize,
    /// Teleports so far.
    pub teleports: usize,
    /// A world budget shared among the cloths each step, as the plugin shares it.
    budget: Option<ClothBudget>,
    /// The budget's claims and caps, kept for their storage.
    shares: (Vec<BudgetClaim>, Vec<Option<u32>>),
    /// What the cloths gave to keep to the budget, since [`Self::count_from_now`].
    pub gave: Gave,
}

/// What a crowd's cloths gave to keep to a shared budget: cloth steps that needed more
/// substeps than their share, and the solver's own strain (the structural stretch its
/// constraints left, [`StepReport::solver_strain`](bevy_cloth::solver::StepReport))
/// in those steps and in the others.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Gave {
    /// Steps over budget, per cloth (capes and skirts in turn, character by character).
    pub steps: Vec<u32>,
    /// Cloth steps counted.
    pub cloth_steps: u64,
    /// The largest solver strain in a step over budget, and in a step within.
    pub strain: (f32, f32),
    /// Cloths the budget can cap (XPBD at automatic substeps); the others take what
    /// their stability asks for, whatever the budget.
    pub cappable: usize,
}

impl Gave {
    /// Cloths that gave accuracy at least once: capes, skirts.
    pub fn cloths(&self) -> (usize, usize) {
        let gave = |k: usize| {
            self.steps
                .iter()
                .skip(k)
                .step_by(2)
                .filter(|&&n| n > 0)
                .count()
        };
        (gave(0), gave(1))
    }

    /// Cloth steps over budget, all told.
    pub fn total(&self) -> u64 {
        self.steps.iter().map(|&n| u64::from(n)).sum()
    }
}

/// The rest shapes every character's cloths share: the cape's and the skirt's layouts
/// (their rest positions in the body's frame), their finer drawn meshes bound to them,
/// and the skirt's painted distances.
struct Shapes {
    cape: (Layout, ProxyBinding),
    skirt: (Layout, ProxyBinding),
    skirt_radius: Vec<f32>,
    cape_top: u32,
}

impl Shapes {
    fn new(size: &CrowdSize) -> Self {
        let (cw, ch) = size.cape;
        let (around, down) = size.skirt;
        let spacing = 0.035;
        // Hung from the shoulders, just behind the body.
        let shoulders = Vec3::new(
            -((cw - 1) as f32) * spacing * 0.5,
            SHOULDERS,
            -BODY_RADIUS - 0.03,
        );
        let on_back = |k| -> Vec<Vec3> {
            grid_points(cw, ch, spacing, k)
                .into_iter()
                .map(|p| p + shoulders)
                .collect()
        };
        let (skirt_rest, skirt_triangles) = cone(around, down, 1);
        // The cape is the grid the example's `Cloth::grid` lays out (its structural,
        // shear and bend springs), its particles where `on_back` puts them.
        let shape = ClothShape::Grid {
            width: cw,
            height: ch,
            spacing,
        };
        let mut cape_grid = shape.layout().expect("a grid");
        cape_grid.positions = on_back(1);
        let skirt = Layout::from_mesh(&skirt_rest, &skirt_triangles).expect("a mesh");
        let bound = |layout: &Layout, fine: &[Vec3]| {
            ProxyBinding::bind(&layout.positions, &layout.triangles, fine, None)
                .expect("a cloth with triangles")
        };
        Shapes {
            cape: {
                let binding = bound(&cape_grid, &on_back(size.refine));
                (cape_grid, binding)
            },
            skirt: {
                let binding = bound(&skirt, &cone(around, down, size.refine).0);
                (skirt, binding)
            },
            skirt_radius: (0..around * down)
                .map(|k| 0.2 * ((k / around) as f32 / (down - 1) as f32).powi(2))
                .collect(),
            cape_top: cw,
        }
    }
}

impl Character {
    /// Character `c` of a square `side` loops across, its cloths with `params`, put on
    /// its body at its first step.
    fn new(c: usize, side: usize, shapes: &Shapes, params: &ClothParams) -> Self {
        let (row, column) = (c / side, c % side);
        let walk = Walk {
            centre: Vec3::new(column as f32 * 3.0, 0.0, row as f32 * 3.0),
            radius: 0.8 + 0.15 * (c % 4) as f32,
            speed: 1.0 + 0.1 * (c % 5) as f32,
            phase: c as f32 * 0.7,
            away: false,
        };
        let pose = walk.pose(0.0);
        let frame = Affine3A::from_rotation_translation(pose.0, pose.1);
        let (cape_layout, cape_binding) = &shapes.cape;
        let (skirt_layout, skirt_binding) = &shapes.skirt;
        let (cape_rest, skirt_rest) = (&cape_layout.positions, &skirt_layout.positions);
        let mut cape = solver_of(cape_layout.clone(), params, frame);
        let mut skirt = solver_of(skirt_layout.clone(), params, frame);
        let targets: Vec<Vec3> = skirt_rest
            .iter()
            .map(|&p| frame.transform_point3(p))
            .collect();
        skirt
            .set_motion_constraints(&targets, &shapes.skirt_radius)
            .expect("painted");
        let stop = BackStop {
            distance: 0.01,
            radius: 0.3,
        };
        skirt
            .set_back_stops(&vec![stop; skirt_rest.len()])
            .expect("stops");
        for cloth in [&mut cape, &mut skirt] {
            cloth.teleport_next_step(bevy_cloth::params::TeleportMode::Reset);
        }
        Character {
            walk,
            cape: Drawn::new(cape, cape_rest.clone(), cape_binding),
            skirt: Drawn::new(skirt, skirt_rest.clone(), skirt_binding),
            cape_top: shapes.cape_top,
            skirt_radius: shapes.skirt_radius.clone(),
            last_pose: pose,
        }
    }

    /// Moves the body to its pose at `t` (a teleport across the square when `jumps`),
    /// and hands its cloths their pins, skinned targets, the body's capsule and `zones`.
    fn move_to(&mut self, t: f32, dt: f32, jumps: bool, zones: &[WindZone]) {
        if jumps {
            self.walk.away = !self.walk.away;
        }
        let pose = self.walk.pose(t);
        let body = Affine3A::from_rotation_translation(pose.0, pose.1);
        for i in 0..self.cape_top {
            let goal = body.transform_point3(self.cape.in_body[i as usize]);
            self.cape.cloth.attach(i, goal).expect("a top-row particle");
        }
        let skirt = &mut self.skirt;
        let targets: Vec<Vec3> = skirt
            .in_body
            .iter()
            .map(|&p| body.transform_point3(p))
            .collect();
        skirt
            .cloth
            .set_motion_constraints(&targets, &self.skirt_radius)
            .expect("painted");
        // The body: a capsule from hips to shoulders, swept from its last pose (a
        // teleported body is not swept across the gap).
        let motion = if jumps {
            Motion::NONE
        } else {
            Motion::between(self.last_pose, pose, dt)
        };
        let capsule = Collider {
            shape: ColliderShape::from(Capsule {
                a: pose.1 + Vec3::Y * (HIPS - 0.3),
                b: pose.1 + Vec3::Y * (SHOULDERS - 0.05),
                radius: BODY_RADIUS,
            }),
            thickness: 0.01,
            friction: 0.3,
            motion,
        };
        self.last_pose = pose;
        for cloth in [&mut self.cape.cloth, &mut self.skirt.cloth] {
            cloth.set_colliders([capsule.clone()]);
            cloth.set_wind_zones(zones, t).expect("a checked zone");
        }
    }

    fn draw(&mut self) -> Duration {
        self.cape.draw() + self.skirt.draw()
    }
}

/// A gusty wind across the middle of a square `side` loops across (3 m each).
fn wind_across(side: usize) -> WindZone {
    let extent = side as f32 * 3.0;
    WindZone {
        shape: ZoneShape::Box {
            half_extents: Vec3::new(extent, 2.0, 2.5),
        },
        centre: Vec3::new(extent * 0.5, 1.0, extent * 0.5),
        velocity: Vec3::new(5.0, 0.0, 1.5),
        falloff: 0.3,
        turbulence: Turbulence {
            gust: 0.4,
            gust_period: 1.2,
            noise: 0.3,
            scale: 0.8,
            seed: 11,
        },
        ..WindZone::default()
    }
}

impl Crowd {
    /// Builds the crowd of `size`, each cloth with `params`.
    pub fn new(size: CrowdSize, params: &ClothParams) -> Self {
        let shapes = Shapes::new(&size);
        let side = (size.characters as f32).sqrt().ceil() as usize;
        Crowd {
            characters: (0..size.characters)
                .map(|c| Character::new(c, side, &shapes, params))
                .collect(),
            zones: [wind_across(side)],
            env: Environment::default(),
            dt: 1.0 / 60.0,
            time: 0.0,
            size,
            teleports: 0,
            budget: None,
            shares: Default::default(),
            gave: Gave::default(),
        }
    }

    /// The crowd with a world budget shared among its cloths each step (`None`: each
    /// takes what its accuracy asks for).
    pub fn with_budget(mut self, budget: Option<ClothBudget>) -> Self {
        self.budget = budget;
        self
    }

    /// Counts what the cloths give to the budget from the next step on.
    pub fn count_from_now(&mut self) {
        self.gave = Gave {
            steps: vec![0; 2 * self.characters.len()],
            cappable: self.cloths().filter(|c| c.budget_caps()).count(),
            ..Gave::default()
        };
    }

    /// Every cloth.
    pub fn cloths(&self) -> impl Iterator<Item = &ClothSolver> {
        self.characters
            .iter()
            .flat_map(|c| [&c.cape.cloth, &c.skirt.cloth])
    }

    /// Particles in all the cloths, and drawn vertices.
    pub fn counts(&self) -> (usize, usize) {
        self.characters.iter().fold((0, 0), |(p, v), c| {
            (
                p + c.cape.cloth.particle_count() + c.skirt.cloth.particle_count(),
                v + c.cape.binding.len() + c.skirt.binding.len(),
            )
        })
    }

    /// One frame: the bodies move (one teleports when its turn comes), the cloths step
    /// (side by side on the pool with `pool`, else one after another on this thread),
    /// and are drawn. What each part cost.
    pub fn frame(&mut self, pool: bool) -> FrameCost {
        let (dt, t) = (self.dt, self.time + self.dt);
        let start = Instant::now();
        let turn = (t / self.size.teleport_every) as usize;
        let due = (self.time / self.size.teleport_every) as usize != turn;
        let jumper = due.then(|| turn % self.characters.len());
        self.teleports += jumper.is_some() as usize;
        self.drive(pool, (t, dt), jumper);
        let drive = start.elapsed();
        let start = Instant::now();
        self.step_cloths(pool);
        let step = start.elapsed();
        self.tally();
        let start = Instant::now();
        let place = self.draw(pool);
        let draw = start.elapsed();
        self.time = t;
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
        FrameCost {
            drive: ms(drive),
            step: ms(step),
            draw: ms(draw),
            place: ms(place),
        }
    }

    /// Shares the budget among the cloths from their last steps' needs, as the plugin
    /// does at the start of a fixed step (every cloth at the same priority).
    fn share(&mut self) {
        let Some(budget) = &self.budget else {
            return;
        };
        let (claims, caps) = &mut self.shares;
        claims.clear();
        claims.extend(self.characters.iter().flat_map(|c| {
            [&c.cape.cloth, &c.skirt.cloth].map(|cloth| BudgetClaim::of(cloth, 1.0))
        }));
        budget.share(claims, caps);
        let cloths = self
            .characters
            .iter_mut()
            .flat_map(|c| [&mut c.cape.cloth, &mut c.skirt.cloth]);
        for (cloth, &cap) in cloths.zip(caps.iter()) {
            cloth.set_substep_budget(cap);
        }
    }

    /// Adds the last step's cloths to [`Self::gave`], once counting has begun.
    fn tally(&mut self) {
        if self.gave.steps.is_empty() {
            return;
        }
        let gave = &mut self.gave;
        for (k, cloth) in self
            .characters
            .iter()
            .flat_map(|c| [&c.cape.cloth, &c.skirt.cloth])
            .enumerate()
        {
            let report = cloth.last_report();
            let strain = report.solver_strain.unwrap_or(0.0);
            if report.over_budget {
                gave.steps[k] += 1;
                gave.strain.0 = gave.strain.0.max(strain);
            } else {
                gave.strain.1 = gave.strain.1.max(strain);
            }
            gave.cloth_steps += 1;
        }
    }

    /// Steps every cloth: side by side on the pool (`solver::run_cloths`, as the plugin
    /// does), or one after another here; within the budget's shares, if it has one.
    fn step_cloths(&mut self, pool: bool) {
        self.share();
        let dt = self.dt;
        let mut cloths: Vec<&mut ClothSolver> = self
            .characters
            .iter_mut()
            .flat_map(|c| [&mut c.cape.cloth, &mut c.skirt.cloth])
            .collect();
        if !pool {
            for cloth in cloths.iter_mut() {
                cloth.step(dt, &self.env);
            }
            return;
        }
        let mut flagged: Vec<(&mut ClothSolver, bool)> =
            cloths.iter_mut().map(|c| (&mut **c, true)).collect();
        solver::begin_cloths(&mut flagged, dt);
        drop(flagged);
        solver::run_cloths(&mut cloths, &self.env);
        // Each cloth's end of step side by side too, as the plugin's `finish_steps`.
        let each = cloths.iter_mut().map(|c| (c.particle_count() as u64, c));
        solver::share_items(each, |cloth| {
            cloth.end_step();
        });
    }

    /// Moves every body to its pose at time `t` (a step of `dt`), character `jumper`
    /// teleporting: on the pool as [`Self::draw`] shares the characters, as the plugin's
    /// driving systems share the cloths, or one after another here.
    fn drive(&mut self, pool: bool, (t, dt): (f32, f32), jumper: Option<usize>) {
        let zones = if self.size.wind { &self.zones[..] } else { &[] };
        each_character(&mut self.characters, pool, |k, c| {
            c.move_to(t, dt, jumper == Some(k), zones);
        });
    }

    /// Draws every cloth: on the pool, or one after another here. How long placing the
    /// proxies' vertices took, summed over the cloths.
    fn draw(&mut self, pool: bool) -> Duration {
        let placing = AtomicU64::new(0);
        each_character(&mut self.characters, pool, |_, c| {
            let ns = c.draw().as_nanos() as u64;
            placing.fetch_add(ns, Ordering::Relaxed);
        });
        Duration::from_nanos(placing.into_inner())
    }

    /// The largest structural strain over every cloth now, and whether every one is
    /// stable.
    pub fn health(&self) -> (f32, bool) {
        self.cloths().fold((0.0f32, true), |(s, ok), c| {
            (s.max(c.strain().max), ok && c.is_stable())
        })
    }
}

/// `work` on each of `characters` with its index: on the pool, shared out among the
/// threads as the plugin shares its cloths (`solver::share_items`: each thread takes the
/// next character when done with its last; each one's cloths are its own), or one after
/// another here.
fn each_character(
    characters: &mut [Character],
    pool: bool,
    work: impl Fn(usize, &mut Character) + Sync,
) {
    if !pool {
        characters
            .iter_mut()
            .enumerate()
            .for_each(|(k, c)| work(k, c));
        return;
    }
    let each = characters.iter_mut().enumerate().map(|c| (1, c));
    solver::share_items(each, |(k, c)| work(k, c));
}

/// The crowd's cloths, as the example's: the seeds' mass-spring, its strain limiter
/// sweeping until every spring is within 1% of its limit, at most eight times (most of
/// the crowd is calm and stops after one; the capes in the gusts take more).
pub fn params() -> ClothParams {
    ClothParams {
        strain_limit_tolerance: Some(0.01),
        strain_limit_iterations: 8,
        ..ClothParams::seeds()
    }
}

/// A solver of `layout` (in the body's frame), placed by `frame`.
fn solver_of(layout: Layout, params: &ClothParams, frame: Affine3A) -> ClothSolver {
    let pins = ClothPins::None.resolve_for(&layout).expect("no pins");
    ClothSolver::new(layout, &pins, params, frame).expect("valid")
}

/// The crowd's cost: the median and spread of each part of a frame over `frames` after
/// `warm` frames, on one thread and on the pool (two crowds, a frame of each in turn).
#[derive(Clone, Debug, Serialize)]
pub struct CrowdCost {
    /// The crowd.
    pub size: CrowdSize,
    /// Particles simulated, vertices drawn.
    pub particles: usize,
    /// Vertices drawn.
    pub drawn: usize,
    /// The pool's threads.
    pub threads: usize,
    /// One thread: median (min–max) ms of the step, the drive and the drawing.
    pub one_thread: PartCosts,
    /// The pool.
    pub pool: PartCosts,
    /// Teleports in the pool's run.
    pub teleports: usize,
    /// The largest structural strain of any cloth in a frame, over the pool's timed
    /// frames: median, min, max.
    pub strain: [f64; 3],
    /// The substeps of the cloths' last step: fewest, most.
    pub substeps: (u32, u32),
    /// Whether every cloth held together: in every frame of the pool's run (warm-up
    /// included) finite and no structural spring past
    /// [`WHOLE_STRAIN`](bevy_cloth::headless::WHOLE_STRAIN), and finite at the end of
    /// both runs.
    pub whole: bool,
    /// The world budget the cloths shared, ms a step at its planned cost (`None`: none).
    pub budget_ms: Option<f32>,
    /// What the pool's cloths gave to keep to it over the timed frames.
    pub gave: Gave,
}

/// Medians and ranges of a frame's parts, ms.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct PartCosts {
    /// The cloths' step: median, min, max.
    pub step: [f64; 3],
    /// The step's 99th percentile.
    pub step_p99: f64,
    /// Driving the bodies.
    pub drive: [f64; 3],
    /// Drawing.
    pub draw: [f64; 3],
    /// Of the drawing, placing the proxies' vertices.
    pub place: [f64; 3],
}

/// The 99th percentile of `v` (nearest rank).
fn p99(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let rank = (0.99 * v.len() as f64).ceil() as usize;
    v[rank.clamp(1, v.len()) - 1]
}

fn spread(mut v: Vec<f64>) -> [f64; 3] {
    v.sort_by(f64::total_cmp);
    let (least, most) = (v[0], v[v.len() - 1]);
    [super::median(&mut v), least, most]
}

/// Runs two crowds of `size` with `params` (sharing `budget` among each crowd's cloths,
/// if given) side by side for `warm + frames` frames, one on one thread and one on the
/// pool, a frame of each in turn (so that the machine's noise falls on both alike), and
/// gives each part's cost.
pub fn measure(
    size: CrowdSize,
    params: &ClothParams,
    budget: Option<ClothBudget>,
    (warm, frames): (usize, usize),
) -> CrowdCost {
    let mut crowds = [0, 1].map(|_| Crowd::new(size, params).with_budget(budget));
    let mut costs: [Vec<FrameCost>; 2] = [Vec::new(), Vec::new()];
    let (mut strains, mut whole) = (Vec::new(), true);
    for f in 0..warm + frames {
        for (k, crowd) in crowds.iter_mut().enumerate() {
            if f == warm {
                crowd.count_from_now();
            }
            let pool = k == 1;
            solver::set_parallel(pool);
            let cost = crowd.frame(pool);
            // The two crowds are the same bits: the pool's is checked every frame.
            if pool {
                let (strain, stable) = crowd.health();
                whole &= stable && strain <= WHOLE_STRAIN;
                if f >= warm {
                    strains.push(strain as f64);
                }
            }
            if f >= warm {
                costs[k].push(cost);
            }
        }
    }
    solver::set_parallel(true);
    let parts = costs.map(|c| PartCosts {
        step: spread(c.iter().map(|c| c.step).collect()),
        step_p99: p99(c.iter().map(|c| c.step).collect()),
        drive: spread(c.iter().map(|c| c.drive).collect()),
        draw: spread(c.iter().map(|c| c.draw).collect()),
        place: spread(c.iter().map(|c| c.place).collect()),
    });
    let health = crowds.each_ref().map(|c| c.health());
    let (particles, drawn) = crowds[0].counts();
    CrowdCost {
        size,
        particles,
        drawn,
        threads: solver::threads(),
        one_thread: parts[0],
        pool: parts[1],
        teleports: crowds[1].teleports,
        strain: spread(strains),
        substeps: crowds[1].cloths().fold((u32::MAX, 0), |(least, most), c| {
            (least.min(c.substeps()), most.max(c.substeps()))
        }),
        whole: whole && health[0].1 && health[1].1,
        budget_ms: budget.and_then(|b| b.milliseconds),
        gave: crowds[1].gave.clone(),
    }
}
