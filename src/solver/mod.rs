//! The physics core: pure Rust, no ECS. The plugin, the tests, the command line and the
//! benches all call the same [`ClothSolver::step`], so what is measured is what runs in a game.
//!
//! One step of `dt` is split into substeps of `h = dt / N`; each substep runs the phases
//! in a fixed order (seed 000 §3.2: all forces from the old state before any position
//! changes):
//! 1. [`ClothSolver::accumulate_forces`] — gravity, wind, drag, springs;
//! 2. [`ClothSolver::integrate`] — Verlet or semi-implicit Euler;
//! 3. [`ClothSolver::fit_targets`] — pull toward model goals (shape matching's velocity update);
//! 4. [`ClothSolver::constrain`] — pins, Provot strain limiting.
//!
//! After the substeps, [`ClothSolver::end_step`] tears over-stretched springs.

mod collide;
mod diagnostics;
mod drivers;
mod forces;
mod integrate;
mod interact;
mod lattice;
mod layout;
mod parallel;
pub mod patches;
pub mod shape_matching;
mod state;
mod substeps;
mod switch;
mod tethers;
pub mod topology;
mod xpbd;

pub use collide::{Collider, ColliderImpulse, ColliderShape, ConvexHull, Motion};
pub use diagnostics::{Energy, Strain};
pub use interact::Grab;
pub use layout::{Layout, MAX_PARTICLES};
pub use parallel::{for_each_indexed, pool as task_pool, set_parallel, threads};
pub use state::Particles;
use substeps::SubstepCache;
pub use substeps::unit_hash;
pub use topology::{SpringKind, Springs};

use bevy::math::{Affine3A, Vec3};

use crate::error::ClothError;
use crate::params::{ClothParams, Environment, Model};
use patches::Patches;
use shape_matching::ShapeMatching;

/// A simulated cloth: particles, springs, triangles and the step.
#[derive(Clone, Debug)]
pub struct ClothSolver {
    particles: Particles,
    springs: Springs,
    /// Particle positions in the cloth's own frame before any motion (for reset, pins).
    local_rest: Vec<Vec3>,
    grid: Option<(u32, u32)>,
    triangles: Vec<[u32; 3]>,
    triangle_springs: Vec<[u32; 3]>,
    spring_triangles: Vec<Vec<u32>>,
    triangle_visible: Vec<bool>,
    /// Each particle's triangles in increasing order (`start[i]..start[i + 1]` of
    /// `faces`), for normals gathered per particle.
    vertex_faces: topology::VertexFaces,
    faces_changed: bool,
    params: ClothParams,
    /// Pinned particles: the layout's (the first `fixed_pins`), then the attached ones
    /// (`drivers.rs`).
    pins: Vec<u32>,
    /// Each pin's world target when set from outside (an attachment), `None` for a pin
    /// that follows the frame.
    pin_goal: Vec<Option<Vec3>>,
    fixed_pins: usize,
    pin_from: Vec<Vec3>,
    pin_to: Vec<Vec3>,
    frame: Affine3A,
    time: f32,
    /// Current substep length `h`.
    h: f32,
    /// The previous step's `h`, to rescale Verlet's implicit velocity when `h` changes.
    last_h: f32,
    substeps: u32,
    substep_index: u32,
    under_resolved: bool,
    /// Automatic substeps remembered for (parameters, dt) (see [`SubstepCache`]).
    substep_cache: SubstepCache,
    /// XPBD's measured substeps of the last step, for (parameters, dt)
    /// ([`ClothSolver::xpbd_closed_loop`]); empty after a reset.
    xpbd_loop: substeps::SubstepLoop,
    torn_this_step: Vec<u32>,
    torn_count: usize,
    grab: Option<Grab>,
    /// The active model's own state (built lazily by the step).
    model: ModelState,
    /// The cloth's characteristic length L (mean structural rest length), for the
    /// shape-matching force law.
    length_scale: f32,
    /// Names and particle ranges of garment pieces (one range for other cloths).
    pieces: Vec<(String, std::ops::Range<u32>)>,
    /// Named runs of particles (a garment's `runs`).
    runs: Vec<(String, Vec<u32>)>,
    /// The length each seam spring starts at, before sewing.
    seam_start: Vec<f32>,
    /// Colliders in world space the particles are kept out of (see `collide.rs`).
    colliders: Vec<Collider>,
    /// The colliders before the last `set_colliders` (kept to tell a change, and for
    /// their storage).
    colliders_spare: Vec<Collider>,
    /// Each collider's bounding box grown by its thickness (`collide.rs`'s broad phase).
    collider_bounds: Vec<collide::Bounds>,
    /// Whether any collider moves (then each substep places them in `colliders_now`).
    colliders_move: bool,
    /// The moving colliders where they are at the current substep, and their boxes.
    colliders_now: Vec<Collider>,
    bounds_now: Vec<collide::Bounds>,
    /// Each moving collider's turn over the current substep.
    turns_now: Vec<bevy::math::Quat>,
    /// What the cloth gave each collider over the step (see `collide.rs`).
    collider_impulses: Vec<collide::ColliderImpulse>,
    /// A grid cloth's springs as stencil offsets (`lattice.rs`); `None` for meshes and
    /// garments.
    stencil: Option<lattice::Stencil>,
    /// Set by everything from outside that can move a resting cloth (see
    /// [`ClothSolver::take_disturbed`]); what a sleeping cloth is woken by.
    disturbed: bool,
    /// A model switch in progress (`switch.rs`).
    switch: Option<switch::Switch>,
}

/// The active model's own state: none for mass-spring (or before the first step
/// builds it), the clusters and goals of shape matching, the part lattice and
/// targets of the patch model, or XPBD's coloured constraints. One at a time, by
/// construction.
#[derive(Clone, Debug)]
enum ModelState {
    None,
    ShapeMatching(ShapeMatching),
    Patches(Box<Patches>),
    Xpbd(Box<xpbd::Constraints>),
}

impl ModelState {
    fn shape_matching(&self) -> Option<&ShapeMatching> {
        match self {
            ModelState::ShapeMatching(s) => Some(s),
            _ => None,
        }
    }

    fn shape_matching_mut(&mut self) -> Option<&mut ShapeMatching> {
        match self {
            ModelState::ShapeMatching(s) => Some(s),
            _ => None,
        }
    }

    fn patches(&self) -> Option<&Patches> {
        match self {
            ModelState::Patches(p) => Some(p),
            _ => None,
        }
    }

    fn patches_mut(&mut self) -> Option<&mut Patches> {
        match self {
            ModelState::Patches(p) => Some(p),
            _ => None,
        }
    }
}

impl ClothSolver {
    /// Builds a cloth of `layout` placed by `frame` (local → world), with the particles
    /// `pins` held where they start (indices into the layout's positions).
    pub fn new(
        layout: Layout,
        pins: &[u32],
        params: &ClothParams,
        frame: Affine3A,
    ) -> Result<Self, ClothError> {
        layout.validate()?;
        let Layout {
            positions: local,
            springs: pairs,
            triangles,
            grid,
            pieces,
            runs,
        } = layout;
        let count = local.len();
        if let Some(&index) = pins.iter().find(|&&i| i as usize >= count) {
            return Err(ClothError::PinOutOfRange { index, count });
        }
        let pin_indices = pins.to_vec();
        params.validate()?;
        check_model_fits(params, grid)?;
        crate::limits::check_work(count, params)?;
        let springs = Springs::from_pairs(pairs, &local);
        let stencil =
            grid.and_then(|(w, _)| lattice::Stencil::new(&springs, w as usize, local.len()));
        let (triangle_springs, spring_triangles) =
            topology::triangle_edge_springs(&triangles, &springs);
        let n = local.len();
        let mut cloth = ClothSolver {
            particles: Particles::with_len(n),
            torn_this_step: Vec::with_capacity(springs.len()),
            springs,
            local_rest: local,
            grid,
            triangle_visible: vec![true; triangles.len()],
            vertex_faces: topology::VertexFaces::new(&triangles, n),
            triangles,
            triangle_springs,
            spring_triangles,
            faces_changed: true,
            params: *params,
            pin_from: Vec::with_capacity(pin_indices.len()),
            pin_to: Vec::with_capacity(pin_indices.len()),
            pin_goal: vec![None; pin_indices.len()],
            fixed_pins: pin_indices.len(),
            pins: pin_indices,
            frame,
            time: 0.0,
            h: 0.0,
            last_h: 0.0,
            substeps: 1,
            substep_index: 0,
            under_resolved: false,
            substep_cache: SubstepCache::default(),
            xpbd_loop: substeps::SubstepLoop::default(),
            torn_count: 0,
            grab: None,
            model: ModelState::None,
            length_scale: 1.0,
            runs,
            pieces: if pieces.is_empty() {
                vec![(String::from("cloth"), 0..n as u32)]
            } else {
                pieces
            },
            seam_start: Vec::new(),
            colliders: Vec::new(),
            colliders_spare: Vec::new(),
            collider_bounds: Vec::new(),
            colliders_move: false,
            colliders_now: Vec::new(),
            bounds_now: Vec::new(),
            turns_now: Vec::new(),
            collider_impulses: Vec::new(),
            stencil,
            disturbed: true,
            switch: None,
        };
        let seams = cloth.springs.ranges[SpringKind::Seam as usize].clone();
        cloth.seam_start = cloth.springs.rest_length[seams].to_vec();
        let structural = cloth.springs.ranges[SpringKind::Structural as usize].clone();
        if !structural.is_empty() {
            cloth.length_scale = cloth.springs.rest_length[structural.clone()]
                .iter()
                .sum::<f32>()
                / structural.len() as f32;
        }
        cloth.reset();
        Ok(cloth)
    }

    /// Puts every particle back at its rest position in the current frame, at rest, with
    /// every spring whole and the clock at zero.
    pub fn reset(&mut self) {
        self.disturbed = true;
        self.grab = None;
        self.switch = None;
        match &mut self.model {
            ModelState::ShapeMatching(sm) => sm.reset(),
            // Rebuilt from the rest state by the next step.
            ModelState::Patches(_) => self.model = ModelState::None,
            ModelState::None | ModelState::Xpbd(_) => {}
        }
        // Attachments are dropped (their owner attaches again on its next step).
        self.pins.truncate(self.fixed_pins);
        self.pin_goal.clear();
        self.pin_goal.resize(self.fixed_pins, None);
        let mass = self.params.node_mass;
        let p = &mut self.particles;
        for (i, local) in self.local_rest.iter().enumerate() {
            let x = self.frame.transform_point3(*local);
            p.position[i] = x;
            p.previous[i] = x;
            p.velocity[i] = Vec3::ZERO;
            p.residue[i] = Vec3::ZERO;
            p.force[i] = Vec3::ZERO;
            p.mass[i] = mass * p.lump[i];
            p.inv_mass[i] = 1.0 / p.mass[i];
        }
        for &i in &self.pins {
            p.inv_mass[i as usize] = 0.0;
        }
        self.pin_to.clear();
        self.pin_to
            .extend(self.pins.iter().map(|&i| p.position[i as usize]));
        self.pin_from.clone_from(&self.pin_to);
        self.springs.alive.fill(true);
        self.sync_stencil();
        self.triangle_visible.fill(true);
        self.faces_changed = true;
        self.torn_count = 0;
        self.torn_this_step.clear();
        self.time = 0.0;
        self.last_h = 0.0;
        self.xpbd_loop = substeps::SubstepLoop::default();
    }

    // ----- parameters and frame -------------------------------------------------------

    /// The parameters in use.
    pub fn params(&self) -> &ClothParams {
        &self.params
    }

    /// Replaces the parameters; they act from the next substep. Invalid values are
    /// refused with an error and the old parameters stay.
    pub fn set_params(&mut self, params: &ClothParams) -> Result<(), ClothError> {
        params.validate()?;
        check_model_fits(params, self.grid)?;
        crate::limits::check_work(self.particles.len(), params)?;
        self.apply_params(params);
        Ok(())
    }

    /// [`ClothSolver::set_params`] for parameters known to be valid for this cloth (the
    /// patch lattice's, derived from the cloth's validated ones).
    pub(crate) fn apply_params(&mut self, params: &ClothParams) {
        self.disturbed |= *params != self.params;
        self.begin_switch(params);
        if params.node_mass != self.params.node_mass {
            for i in 0..self.particles.len() {
                self.particles.mass[i] = params.node_mass * self.particles.lump[i];
                if self.particles.inv_mass[i] != 0.0 {
                    self.particles.inv_mass[i] = 1.0 / self.particles.mass[i];
                }
            }
        }
        self.params = *params;
    }

    /// The frame (local → world) the pins follow.
    pub fn frame(&self) -> Affine3A {
        self.frame
    }

    /// Moves the pins' frame; pinned particles move there over the next step, smoothly
    /// across its substeps, and drag the cloth along.
    pub fn set_frame(&mut self, frame: Affine3A) {
        self.disturbed |= frame != self.frame;
        self.frame = frame;
    }

    /// True once after anything from outside could have moved the cloth since the last
    /// call: new parameters, a moved frame (the pins), a collider that changed within
    /// reach of the cloth, a grab, a drag or a release, a tear or a cut, a reset, or
    /// mutable access to the particles. A sleeping cloth (the plugin's `ClothSleep`)
    /// wakes on it; the step itself never sets it.
    pub fn take_disturbed(&mut self) -> bool {
        std::mem::take(&mut self.disturbed)
    }

    // ----- the step -------------------------------------------------------------------

    /// Advances the cloth by `dt` seconds: [`begin_step`](Self::begin_step), that many
    /// [`substep`](Self::substep)s, then [`end_step`](Self::end_step).
    pub fn step(&mut self, dt: f32, env: &Environment) {
        let n = self.begin_step(dt);
        for _ in 0..n {
            self.substep(env);
        }
        self.end_step();
    }

    /// One substep: forces, integration, constraints.
    pub fn substep(&mut self, env: &Environment) {
        self.accumulate_forces(env);
        self.integrate();
        self.fit_targets();
        self.constrain();
    }

    /// Prepares a step of `dt` seconds and returns the number of substeps it takes (0 for a
    /// `dt` that is not positive and finite: nothing happens then).
    pub fn begin_step(&mut self, dt: f32) -> u32 {
        if !(dt > 0.0 && dt.is_finite()) {
            self.substeps = 0;
            return 0;
        }
        // The automatic substep bound of a deformation-dependent pull needs this state's
        // goals or targets; otherwise the substeps compute their own.
        let auto = matches!(self.params.substeps, crate::params::Substeps::Auto { .. });
        self.prepare_model(auto && self.state_dependent_stiffness());
        self.sew();
        if let ModelState::Xpbd(constraints) = &mut self.model {
            // This step's seam lengths, torn springs, pins.
            if self.stencil.is_none() {
                constraints.sync(&self.springs);
            }
            self.refresh_tethers();
        }
        if let (Model::Patches(patch), Some(patches)) =
            (self.params.model, self.model.patches_mut())
        {
            // The lattice gets this step's parameters before its substeps are chosen.
            patches.set_params(&self.params, &patch, 1);
            patches.refresh_lattice_substeps(dt);
        }
        let n = match self.params.substeps {
            crate::params::Substeps::Fixed(n) => {
                self.under_resolved = false;
                n.max(1)
            }
            crate::params::Substeps::Auto { max } => {
                let cap = crate::limits::auto_substeps_cap(self.particles.len(), max);
                // Shape matching's stiffness (and the patch pull's for p ≠ 1) depends on
                // the deformation: no cache. XPBD follows what it measures.
                let needed = if self.state_dependent_stiffness() {
                    self.stable_substeps(dt)
                } else if let Some(n) = self.xpbd_closed_loop(dt, cap) {
                    n
                } else {
                    self.refresh_substep_cache(dt)
                };
                self.under_resolved = needed > cap;
                needed.clamp(1, cap)
            }
        };
        self.substeps = n;
        self.substep_index = 0;
        self.h = dt / n as f32;
        if self.last_h > 0.0 && self.last_h != self.h {
            self.rescale_verlet_velocity(self.h / self.last_h);
        }
        self.last_h = self.h;
        if let (Model::Patches(patch), Some(patches)) =
            (self.params.model, self.model.patches_mut())
        {
            patches.set_params(&self.params, &patch, n);
            patches.parts.set_frame(self.frame);
            patches.parts.begin_step(dt);
        }
        // Pins move from where they are to where the frame puts them, over the substeps.
        std::mem::swap(&mut self.pin_from, &mut self.pin_to);
        for (k, &i) in self.pins.iter().enumerate() {
            self.pin_to[k] = self.pin_goal[k]
                .unwrap_or_else(|| self.frame.transform_point3(self.local_rest[i as usize]));
            self.pin_from[k] = self.particles.position[i as usize];
        }
        if let Some(g) = &mut self.grab {
            g.from = self.particles.position[g.particle as usize];
        }
        self.torn_this_step.clear();
        self.collider_impulses
            .fill(collide::ColliderImpulse::default());
        n
    }

    /// Finishes a step: springs stretched past the tear ratio break and hide the faces
    /// they border (seed 000 §3.2). Returns the springs torn in this step.
    pub fn end_step(&mut self) -> &[u32] {
        if let Some(patches) = self.model.patches_mut() {
            // A torn part spring splits the cloth between its two parts: hide the faces
            // that straddle them (on tear events only).
            patches.parts.end_step();
            let lattice = &patches.parts.springs;
            for &k in patches.parts.last_torn() {
                let (a, b) = (
                    lattice.a[k as usize] as usize,
                    lattice.b[k as usize] as usize,
                );
                for (t, tri) in self.triangles.iter().enumerate() {
                    let parts = tri.map(|v| patches.part_of(v));
                    if parts.contains(&a) && parts.contains(&b) {
                        self.triangle_visible[t] = false;
                        self.faces_changed = true;
                    }
                }
            }
        }
        if let (Some(ratio), Model::MassSpring | Model::Xpbd(_)) =
            (self.params.tear_ratio, self.params.model)
        {
            let x = &self.particles.position;
            let s = &mut self.springs;
            // Seams are sewn to a rest length of 0 and do not tear.
            for k in 0..s.ranges[SpringKind::Seam as usize].start {
                if s.alive[k]
                    && x[s.a[k] as usize].distance_squared(x[s.b[k] as usize])
                        > (ratio * s.rest_length[k]).powi(2)
                {
                    s.alive[k] = false;
                    if let Some(stencil) = &mut self.stencil {
                        stencil.tear(k);
                    }
                    self.torn_this_step.push(k as u32);
                    for &t in &self.spring_triangles[k] {
                        self.triangle_visible[t as usize] = false;
                    }
                    self.faces_changed = true;
                }
            }
            self.torn_count += self.torn_this_step.len();
        }
        &self.torn_this_step
    }

    /// The springs torn by the last `end_step`.
    pub fn last_torn(&self) -> &[u32] {
        &self.torn_this_step
    }

    /// Tears spring `s` by hand (e.g. a cut with the mouse). Returns false if it was
    /// already torn or does not exist.
    pub fn tear(&mut self, s: u32) -> bool {
        let k = s as usize;
        if k >= self.springs.len() || !self.springs.alive[k] {
            return false;
        }
        self.disturbed = true;
        self.springs.alive[k] = false;
        if let Some(stencil) = &mut self.stencil {
            stencil.tear(k);
        }
        for &t in &self.spring_triangles[k] {
            self.triangle_visible[t as usize] = false;
        }
        self.faces_changed = true;
        self.torn_count += 1;
        true
    }

    /// Mirrors the springs' rest lengths, factors and alive flags into the stencil.
    fn sync_stencil(&mut self) {
        if let Some(stencil) = &mut self.stencil {
            stencil.sync(&self.springs);
        }
    }

    /// Builds or drops the model state (shape-matching clusters, patch lattice) when the
    /// model changes. Goals or targets of the current state are computed when `compute`
    /// asks for them or the state was just built; the substeps compute their own.
    fn prepare_model(&mut self, compute: bool) {
        match self.params.model {
            Model::ShapeMatching(sm) => {
                let k = sm.clusters;
                let built = self.model.shape_matching().is_none_or(|s| s.built_for != k);
                if built {
                    self.model = ModelState::ShapeMatching(ShapeMatching::new(
                        &self.local_rest,
                        &self.particles.mass,
                        self.grid,
                        k,
                    ));
                }
                if let Some(state) = self.model.shape_matching_mut()
                    && (compute || built)
                {
                    state.compute_goals(&self.particles.position, &self.particles.mass, &sm);
                }
            }
            Model::Patches(patch) => {
                let key = patch.lattice_key();
                let built = self.model.patches().is_none_or(|p| p.built_for != key);
                if built {
                    self.model = ModelState::None;
                    if let Some(grid) = self.grid
                        && let Ok(mut patches) = Patches::new(
                            &self.local_rest,
                            grid,
                            &self.pins,
                            &self.params,
                            &patch,
                            self.frame,
                        )
                    {
                        patches.adopt_state(
                            &self.particles,
                            &self.pins,
                            self.last_h,
                            &patch,
                            self.time > 0.0,
                        );
                        patches.parts.set_colliders(self.colliders.iter().cloned());
                        self.model = ModelState::Patches(Box::new(patches));
                    }
                }
                if let Some(patches) = self.model.patches_mut() {
                    // A grabbed particle drags its part along (particles only follow parts).
                    match self.grab {
                        Some(g) => {
                            let part = patches.part_of(g.particle) as u32;
                            let offset = patches.parts.positions()[part as usize]
                                - self.particles.position[g.particle as usize];
                            if patches.parts.grabbed().is_none_or(|pg| pg.particle != part) {
                                patches.parts.grab(part);
                            }
                            patches.parts.drag_grab(g.target + offset);
                        }
                        None => patches.parts.release_grab(),
                    }
                    if compute || built {
                        patches.compute_targets(&self.particles.position, &patch);
                    }
                }
            }
            // A cloth's springs never change (they only tear): built once per switch.
            Model::Xpbd(_) => {
                if !matches!(self.model, ModelState::Xpbd(_)) {
                    let n = self.particles.len();
                    // A grid is projected on its stencil: no constraint lists.
                    let general = self.stencil.is_none();
                    let constraints = xpbd::Constraints::new(&self.springs, n, general);
                    self.model = ModelState::Xpbd(Box::new(constraints));
                }
            }
            Model::MassSpring => self.model = ModelState::None,
        }
    }

    /// The patch model's state (part lattice and targets), if that is the model.
    pub fn patches(&self) -> Option<&Patches> {
        self.model.patches()
    }

    /// The shape-matching goals (after the last goal computation), if that is the model.
    pub fn goals(&self) -> Option<&[Vec3]> {
        self.model.shape_matching().map(|s| &s.goals[..])
    }

    /// The shape-matching state, if that is the model.
    pub fn shape_matching(&self) -> Option<&ShapeMatching> {
        self.model.shape_matching()
    }

    /// Computes the shape-matching goals of the current positions now (outside a step).
    pub fn update_goals(&mut self) {
        self.prepare_model(true);
    }

    /// The acting stiffness of a spring kind under the current parameters (0 for every
    /// kind when the model has no springs; XPBD's constraints have the springs'
    /// stiffness, `inf` for an inextensible one).
    pub fn stiffness(&self, kind: SpringKind) -> f32 {
        if !matches!(self.params.model, Model::MassSpring | Model::Xpbd(_)) {
            return 0.0;
        }
        family_stiffness(&self.params.springs, kind)
    }

    // ----- queries --------------------------------------------------------------------

    /// Particle state (positions, velocities, masses, forces).
    pub fn particles(&self) -> &Particles {
        &self.particles
    }

    /// Mutable particle state, for tools that move particles (grab) between steps.
    pub fn particles_mut(&mut self) -> &mut Particles {
        self.disturbed = true;
        &mut self.particles
    }

    /// Particle positions in world space.
    pub fn positions(&self) -> &[Vec3] {
        &self.particles.position
    }

    /// The springs, torn ones included (see `Springs::alive`).
    pub fn springs(&self) -> &Springs {
        &self.springs
    }

    /// All triangles, hidden ones included.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// For each triangle, the springs along its edges (`u32::MAX` where none).
    pub fn triangle_springs(&self) -> &[[u32; 3]] {
        &self.triangle_springs
    }

    /// Whether each triangle is still drawn (false once a spring on its edge tore).
    pub fn triangle_visible(&self) -> &[bool] {
        &self.triangle_visible
    }

    /// True once after faces were hidden (or on a new cloth); clears the flag.
    pub fn take_faces_changed(&mut self) -> bool {
        std::mem::take(&mut self.faces_changed)
    }

    /// The indices of the pinned particles.
    pub fn pins(&self) -> &[u32] {
        &self.pins
    }

    /// The name and particle range of each garment piece (one range holding every
    /// particle for other cloths).
    pub fn pieces(&self) -> &[(String, std::ops::Range<u32>)] {
        &self.pieces
    }

    /// The particles of the named run (a garment file's `runs`), or `None`.
    pub fn run(&self, name: &str) -> Option<&[u32]> {
        self.runs
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, particles)| particles.as_slice())
    }

    /// Replaces the colliders the particles are kept out of (world space); reuses its
    /// storage, so calling it every step allocates nothing once it has grown.
    pub fn set_colliders(&mut self, colliders: impl IntoIterator<Item = Collider>) {
        // The last colliders go to the spare list (both keep their storage: no
        // allocation once grown).
        std::mem::swap(&mut self.colliders, &mut self.colliders_spare);
        self.colliders.clear();
        self.colliders.extend(colliders);
        // One impulse sum per collider (zeroed by each step).
        self.collider_impulses
            .resize(self.colliders.len(), collide::ColliderImpulse::default());
        let before = &self.colliders_spare;
        if *before == self.colliders {
            return; // the same colliders (the plugin sets them every step): all derived holds
        }
        // Only a change within reach of the cloth can move it: the boxes of the colliders
        // that differ against the cloth's.
        let cloth = collide::Bounds::around(&self.particles.position);
        let near = |c: &Collider| c.bounds().overlaps(&cloth);
        let changed = self.colliders.iter().filter(|c| !before.contains(c));
        let gone = before.iter().filter(|c| !self.colliders.contains(c));
        self.disturbed |= changed.chain(gone).any(near);
        self.collider_bounds.clear();
        self.collider_bounds
            .extend(self.colliders.iter().map(Collider::bounds));
        self.colliders_move = self.colliders.iter().any(|c| !c.motion.is_still());
        // The part centres meet the colliders too: otherwise the targets sink into a
        // collider and pull the particles in after it.
        if let Some(patches) = self.model.patches_mut() {
            patches.parts.set_colliders(self.colliders.iter().cloned());
        }
    }

    /// The colliders in use.
    pub fn colliders(&self) -> &[Collider] {
        &self.colliders
    }

    /// `(width, height)` for a grid cloth.
    pub fn grid_size(&self) -> Option<(u32, u32)> {
        self.grid
    }

    /// Number of particles.
    pub fn particle_count(&self) -> usize {
        self.particles.len()
    }

    /// Number of springs that still act (whole and of an enabled family).
    pub fn spring_count(&self) -> usize {
        if let Some(patches) = self.model.patches() {
            return patches.spring_count();
        }
        SpringKind::ALL
            .into_iter()
            .filter(|&k| self.stiffness(k) > 0.0)
            .map(|k| {
                self.springs.ranges[k as usize]
                    .clone()
                    .filter(|&s| self.springs.alive[s])
                    .count()
            })
            .sum()
    }

    /// Number of springs torn since the last reset.
    pub fn torn_count(&self) -> usize {
        self.torn_count + self.model.patches().map_or(0, Patches::torn_count)
    }

    /// Simulated time since the last reset, in s.
    pub fn time(&self) -> f32 {
        self.time
    }

    /// Substeps used by the last step.
    pub fn substeps(&self) -> u32 {
        self.substeps
    }

    /// True when automatic substeps hit their maximum: the step may be unstable.
    pub fn under_resolved(&self) -> bool {
        self.under_resolved
    }
}

/// The acting stiffness of family `kind` in `springs` (0 when switched off).
fn family_stiffness(springs: &crate::params::SpringParams, kind: SpringKind) -> f32 {
    match kind {
        SpringKind::Structural => springs.structural.effective(),
        SpringKind::Shear => springs.shear.effective(),
        SpringKind::Bend => springs.bend.effective(),
        SpringKind::BendDiagonal => springs.bend_diagonal.effective(),
        SpringKind::Seam => springs.seam.effective(),
    }
}

/// The patch model needs a grid cloth (its parts are blocks of rows and columns).
fn check_model_fits(params: &ClothParams, grid: Option<(u32, u32)>) -> Result<(), ClothError> {
    if matches!(params.model, Model::Patches(_)) && grid.is_none() {
        return Err(ClothError::ModelNeedsGrid { model: "patch" });
    }
    Ok(())
}

/// The scale `(d/L)^(p−1)` of the pull `α (d/L)^(p−1) d` toward a goal or target used by
/// shape matching and the patch model (seed 000 §4's exponent p), with `d/L` kept ≥ 0.05
/// so that `p < 1` stays finite at the goal.
#[inline]
pub(crate) fn pull_scale(d: f32, length_scale: f32, exponent: f32) -> f32 {
    if exponent == 1.0 {
        1.0
    } else {
        (d / length_scale).max(0.05).powf(exponent - 1.0)
    }
}
