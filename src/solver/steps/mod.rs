//! The step as a pipeline. A step of `dt` is [`ClothSolver::begin_step`], that many
//! [`ClothSolver::substep`]s, then [`ClothSolver::end_step`]; [`ClothSolver::step`] runs
//! the three and returns a [`StepReport`].
//!
//! Each substep runs four stages in order (Sladović 2014 §3.2: every force from the old state
//! before any position changes):
//! 1. [`ClothSolver::accumulate_forces`]: gravity, wind, drag and the model's forces
//!    (springs, the goal or target pull);
//! 2. [`ClothSolver::integrate`]: the model's prediction (Verlet or semi-implicit Euler;
//!    the patch model's part lattice first);
//! 3. [`ClothSolver::fit_targets`]: the model's move toward its goals or targets (shape
//!    matching's velocity update, the patch model's single-particle parts);
//! 4. [`ClothSolver::constrain`]: the pins and grab driven to their place, the model's
//!    constraints (Provot's limit, XPBD's projection and tethers), self-collision
//!    (`self_contact.rs`), then contact (the last: no later correction pushes a particle
//!    back into a collider); it ends the substep and advances the clock.
//!
//! What differs between models lives in one file per model (`steps/*.rs`), each an
//! implementation of [`ModelSteps`]; the model is chosen once, when the step begins.
//! A new stage common to every model goes into `constrain` before contact; a model's
//! own stage into its file.

mod mass_spring;
mod patches;
mod shape_matching;
mod xpbd;

use std::time::Duration;

use bevy::math::Vec3;
use bevy::platform::time::Instant;

use super::{ClothSolver, SpringKind};
use crate::params::{Environment, Model, Substeps};

/// The stages of a step that differ from model to model, in the order they run.
pub(super) trait ModelSteps {
    /// Builds the model's state when it is missing or was built for other parameters;
    /// computes its goals or targets when `compute` asks or it was just built.
    fn build(&self, _cloth: &mut ClothSolver, _compute: bool) {}
    /// Gives the model's state this step's parameters, before the substeps are chosen.
    fn prepare(&self, _cloth: &mut ClothSolver, _dt: f32) {}
    /// Starts the step once its substeps are chosen; `ratio` is `h / last_h` when the
    /// substep length changed.
    fn begin(&self, _cloth: &mut ClothSolver, _dt: f32, _ratio: Option<f32>) {}
    /// Stage 1: every force on the particles (gravity, wind and drag included).
    fn forces(&self, cloth: &mut ClothSolver, env: &Environment);
    /// Stage 2: the particles' prediction from their forces.
    fn integrate(&self, cloth: &mut ClothSolver);
    /// Stage 3: the move toward goals or targets.
    fn fit_targets(&self, _cloth: &mut ClothSolver) {}
    /// Stage 4, between the drivers and contact: the model's constraints.
    fn constrain(&self, _cloth: &mut ClothSolver) {}
    /// In the step's last substep, after self-contact and before the motion
    /// constraints and contact: what the model takes back of what the substeps and
    /// self-contact left past its bounds.
    fn settle(&self, _cloth: &mut ClothSolver) {}
    /// After the substeps: tearing.
    fn end(&self, _cloth: &mut ClothSolver) {}
}

/// The mass-spring model has no parameters of its own.
pub(super) struct MassSpring;

/// The stages of `model`.
pub(super) fn model_steps(model: &Model) -> &dyn ModelSteps {
    match model {
        Model::MassSpring => &MassSpring,
        Model::ShapeMatching(sm) => sm,
        Model::Patches(patch) => patch,
        Model::Xpbd(xpbd) => xpbd,
    }
}

/// The most of its rest length a structural spring may change length or turn by in one
/// substep of a step a budget caps (`ClothSolver::speed_floor`).
const SPEED_REACH: f32 = 0.25;

/// What a step did, returned by [`ClothSolver::step`] and [`ClothSolver::end_step`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport {
    /// The substeps the step planned (0: nothing happened, for a `dt` that is not
    /// positive and finite).
    pub substeps: u32,
    /// The substeps taken: `substeps`, unless the stages were called by hand a different
    /// number of times.
    pub taken: u32,
    /// The substeps the step needed: the automatic count before any cap (XPBD's
    /// accuracy target, or the explicit models' stable bound); `substeps` for a fixed
    /// count.
    pub needed: u32,
    /// The automatic substeps hit their cap, or the strain limiter's sweeps until within
    /// ran out of the step's budget (`limits::limiter_budget`): the step may be unstable
    /// or inaccurate.
    pub under_resolved: bool,
    /// XPBD needed more substeps than its budget
    /// ([`ClothSolver::set_substep_budget`](super::ClothSolver::set_substep_budget))
    /// allowed: the step gave accuracy (its strain past the target, `solver_strain`) to
    /// keep to its time. XPBD stays finite at any substep count, but not within its
    /// strain: the polyester flag of `assets/scenes/flag.ron` at 7 substeps in 5 m/s
    /// gusts stretched 63% (a last projection or three in the last substep changed that
    /// by a few points), at 30 substeps 14%.
    pub over_budget: bool,
    /// The fewest substeps a budget could cap this step at: enough that no structural
    /// spring, at its ends' relative speed, changes length or turns by more than a
    /// quarter of its rest length a substep; 0 when no budget applied.
    pub budget_floor: u32,
    /// The largest stretch `(l − l0)/l0` of a whole structural spring with a free end at
    /// the end of the step, when the step measured it (XPBD's automatic substeps do, each
    /// step); [`ClothSolver::strain`] measures it on demand.
    pub max_strain: Option<f32>,
    /// The largest structural stretch the model's constraints left in the last substep,
    /// before self-collision and contact moved particles: the solver's own error, which
    /// XPBD's automatic substeps hold to its target (measured when they run).
    pub solver_strain: Option<f32>,
    /// False when the step would have left a position or velocity non-finite: the cloth
    /// then keeps the positions of the last good step (or reset), at rest.
    pub finite: bool,
    /// Springs torn in the step.
    pub torn: usize,
    /// The step began with a teleport (the cloth carried with its drivers'
    /// jump, [`Teleport`](crate::params::Teleport)).
    pub teleported: Option<super::Teleported>,
    /// Wall time spent in each stage, summed over the substeps.
    pub time: StageTimes,
}

impl Default for StepReport {
    /// The report of no step: nothing done, nothing wrong.
    fn default() -> Self {
        StepReport {
            substeps: 0,
            taken: 0,
            needed: 0,
            under_resolved: false,
            over_budget: false,
            budget_floor: 0,
            max_strain: None,
            solver_strain: None,
            finite: true,
            torn: 0,
            teleported: None,
            time: StageTimes::default(),
        }
    }
}

/// Wall time per stage of a step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimes {
    /// `begin_step`: the model's state, the substep count, the drivers.
    pub begin: Duration,
    /// Stage 1, forces.
    pub forces: Duration,
    /// Stage 2, the prediction.
    pub integrate: Duration,
    /// Stage 3, goals and targets.
    pub fit_targets: Duration,
    /// Stage 4 but contact: the drivers and the model's constraints.
    pub constraints: Duration,
    /// Self-collision (its pairs are listed in `begin`).
    pub self_contact: Duration,
    /// Contact with the colliders.
    pub contact: Duration,
    /// `end_step`: the finite check, tearing, the strain measure.
    pub end: Duration,
}

impl StageTimes {
    /// The whole step.
    pub fn total(&self) -> Duration {
        self.begin
            + self.forces
            + self.integrate
            + self.fit_targets
            + self.constraints
            + self.self_contact
            + self.contact
            + self.end
    }
}

/// The positions at the end of the last good step (or the last reset) and the time
/// they were at, which a step that goes non-finite gives back. Reused storage: no
/// allocation once grown.
#[derive(Clone, Debug, Default)]
pub(super) struct Checkpoint {
    position: Vec<Vec3>,
    time: f32,
}

impl Checkpoint {
    /// Takes `position` at `time` as the new checkpoint when every position and
    /// velocity is finite; returns whether they were.
    pub fn take(&mut self, position: &[Vec3], velocity: &[Vec3], time: f32) -> bool {
        let finite = all_finite(position) && all_finite(velocity);
        if finite {
            self.position.clear();
            self.position.extend_from_slice(position);
            self.time = time;
        }
        finite
    }
}

/// Whether every component of `v` is finite, without a branch per element: `x·0` is 0
/// for a finite `x` and NaN otherwise, and a sum of zeros stays 0 (four sums, so the
/// additions do not wait on each other).
fn all_finite(v: &[Vec3]) -> bool {
    let mut sums = [Vec3::ZERO; 4];
    let chunks = v.chunks_exact(4);
    for x in chunks.remainder() {
        sums[0] += *x * 0.0;
    }
    for chunk in chunks {
        for (sum, x) in sums.iter_mut().zip(chunk) {
            *sum += *x * 0.0;
        }
    }
    sums.into_iter().sum::<Vec3>() == Vec3::ZERO
}

impl ClothSolver {
    /// Advances the cloth by `dt` seconds: [`begin_step`](Self::begin_step), that many
    /// [`substep`](Self::substep)s, then [`end_step`](Self::end_step).
    pub fn step(&mut self, dt: f32, env: &Environment) -> StepReport {
        let n = self.begin_step(dt);
        for _ in 0..n {
            self.substep(env);
        }
        self.end_step()
    }

    /// One substep: the four stages in order.
    pub fn substep(&mut self, env: &Environment) {
        self.accumulate_forces(env);
        self.integrate();
        self.fit_targets();
        self.constrain();
    }

    /// Prepares a step of `dt` seconds and returns the number of substeps it takes (0 for a
    /// `dt` that is not positive and finite: nothing happens then).
    pub fn begin_step(&mut self, dt: f32) -> u32 {
        let n = self.plan_step(dt);
        self.start_substeps(dt, n);
        n
    }

    /// The first half of [`begin_step`](Self::begin_step): the step's sewing, model
    /// state and substep choice; returns the substeps this cloth needs (0 for a `dt` that
    /// is not positive and finite). Cloths in contact then start with the most any of
    /// them needs (`begin_together`).
    pub(crate) fn plan_step(&mut self, dt: f32) -> u32 {
        let start = Instant::now();
        self.report = StepReport::default();
        if !(dt > 0.0 && dt.is_finite()) {
            self.clock.substeps = 0;
            return 0;
        }
        self.follow_drivers(dt);
        self.stepping = self.params.model;
        let model = self.stepping;
        let steps = model_steps(&model);
        self.sew();
        // The automatic substep bound of a deformation-dependent pull needs this state's
        // goals or targets; otherwise the substeps compute their own.
        let auto = matches!(self.params.substeps, Substeps::Auto { .. });
        steps.build(self, auto && self.state_dependent_stiffness());
        steps.prepare(self, dt);
        let n = self.choose_substeps(dt);
        self.report.time.begin = start.elapsed();
        n
    }

    /// The second half of [`begin_step`](Self::begin_step): the clock, the model, the
    /// drivers and the contacts set for `n` substeps of a `dt` step (nothing for `n` 0).
    pub(crate) fn start_substeps(&mut self, dt: f32, n: u32) {
        if n == 0 {
            return;
        }
        let start = Instant::now();
        let model = self.stepping;
        let on = matches!(model, Model::Xpbd(_) | Model::MassSpring);
        self.self_contact.prepare(
            &self.particles,
            &self.structure.springs,
            &self.params.self_collision,
            on,
            dt,
        );
        let ratio = self.clock.begin(dt, n);
        model_steps(&model).begin(self, dt, ratio);
        let p = &self.particles.position;
        self.drivers.begin_step(p, &self.structure.local_rest);
        self.blow_at_particles();
        self.air.current = false;
        self.structure.torn_this_step.clear();
        self.touched.clear();
        self.touched.resize(self.particles.len(), false);
        self.contact
            .collider_impulses
            .fill(super::contact::ColliderImpulse::default());
        self.report.substeps = n;
        self.report.under_resolved = self.clock.under_resolved;
        self.report.over_budget = self.clock.over_budget;
        self.report.time.begin += start.elapsed();
    }

    /// This step's substeps: the fixed count, or the automatic one (the stable bound,
    /// or XPBD's measured loop), at most the work cap.
    /// A budget ([`ClothSolver::set_substep_budget`](crate::solver::ClothSolver::set_substep_budget))
    /// caps XPBD's count only: XPBD is stable at any count, so what a smaller one gives
    /// is accuracy; the explicit models' stable bound is kept whatever the budget.
    fn choose_substeps(&mut self, dt: f32) -> u32 {
        self.clock.over_budget = false;
        match self.params.substeps {
            Substeps::Fixed(n) => {
                self.clock.under_resolved = false;
                self.report.needed = n.max(1);
                n.max(1)
            }
            Substeps::Auto { max } => {
                let own = crate::limits::auto_substeps_cap(self.particles.len(), max);
                let budget = match (self.params.model, self.clock.budget) {
                    (Model::Xpbd(_), Some(b)) => {
                        self.report.budget_floor = self.speed_floor(dt);
                        Some(b.max(self.report.budget_floor))
                    }
                    _ => None,
                };
                let cap = budget.map_or(own, |b| b.min(own));
                // Shape matching's stiffness (and the patch pull's for p ≠ 1) depends on
                // the deformation: no cache. XPBD follows what it measures.
                let needed = if self.state_dependent_stiffness() {
                    self.stable_substeps(dt)
                } else if let Some(n) = self.xpbd_closed_loop(dt, cap) {
                    n
                } else {
                    self.refresh_substep_cache(dt)
                };
                let needed = needed.max(self.fabric_floor(dt));
                self.report.needed = needed;
                self.clock.under_resolved = needed > own;
                self.clock.over_budget = budget.is_some_and(|b| needed > b.min(own));
                needed.clamp(1, cap)
            }
        }
    }

    /// The fewest substeps a budget may cap a step of `dt` at: enough that no structural
    /// spring at its ends' present relative speed changes length or turns by more than
    /// [`SPEED_REACH`] of its rest length in a substep (at least one). Past that, a
    /// substep's linearised solve of the lines no longer holds, the step ends far past
    /// the strain limit, and the budget's giving way to it (many substeps, which take
    /// that stretch back within one step and turn it into speed) fed the next capped
    /// step: a denim curtain capped at one substep alternated with steps of 35 to 200
    /// and reached 1,179% strain. A cloth carried along whole (a cape on a running
    /// body) moves its springs' ends together and needs nothing more.
    fn speed_floor(&self, dt: f32) -> u32 {
        let (v, s) = (&self.particles.velocity, &self.structure.springs);
        let mut rate = 0.0f32;
        for k in s.ranges[SpringKind::Structural as usize].clone() {
            if s.alive[k] {
                let (a, b) = (s.a[k] as usize, s.b[k] as usize);
                rate = rate.max((v[b] - v[a]).length() / s.rest_length[k]);
            }
        }
        let n = (rate * dt / SPEED_REACH).ceil();
        if n.is_finite() && n >= 1.0 {
            n.min(u32::MAX as f32) as u32
        } else {
            1
        }
    }

    /// Stage 1: clears and accumulates the forces on every free particle (gravity,
    /// Maslova eq. 1.6; wind; linear drag `−c v`, Sladović 2014 eq. 31; the model's). Reads only
    /// the old state, so the result does not depend on particle order (Sladović 2014 §3.2).
    /// Just after a model switch, the force that keeps the switch smooth (`switch.rs`).
    pub fn accumulate_forces(&mut self, env: &Environment) {
        let start = Instant::now();
        let model = self.stepping;
        model_steps(&model).forces(self, env);
        self.add_switch_force(env);
        self.report.time.forces += start.elapsed();
    }

    /// Stage 2: advances every free particle by one substep from its force.
    pub fn integrate(&mut self) {
        let start = Instant::now();
        let model = self.stepping;
        model_steps(&model).integrate(self);
        self.report.time.integrate += start.elapsed();
    }

    /// Stage 3: the move toward the model's goals or targets (nothing for mass-spring
    /// and XPBD).
    pub fn fit_targets(&mut self) {
        let start = Instant::now();
        let model = self.stepping;
        model_steps(&model).fit_targets(self);
        self.report.time.fit_targets += start.elapsed();
    }

    /// Stage 4: moves the pinned and grabbed particles along their path, projects the
    /// model's constraints, keeps particles out of the colliders; then ends the substep
    /// (the clock advances by `h`).
    pub fn constrain(&mut self) {
        let start = Instant::now();
        let (t, h) = (self.clock.end_of_substep(), self.clock.h);
        self.drivers.drive(&mut self.particles, t, h);
        let model = self.stepping;
        model_steps(&model).constrain(self);
        if self.clock.substep_index + 1 == self.clock.substeps {
            self.measure_solver_error();
        }
        let constrained = Instant::now();
        self.self_contact
            .resolve(&mut self.particles, h, &mut self.touched);
        if self.clock.substep_index + 1 == self.clock.substeps {
            model_steps(&model).settle(self);
        }
        let separated = Instant::now();
        self.drivers.motion.hold(&mut self.particles, t, h);
        let tau = self.clock.left_after_substep();
        let depenetration = self.params.max_depenetration_speed * h;
        let structure = &self.structure;
        self.contact.resolve(
            &mut self.particles,
            (tau, h, depenetration),
            |x, i| structure.normal_sum(x, i),
            &mut self.touched,
        );
        self.contact.carry(
            &mut self.particles,
            &self.structure.springs,
            self.structure.longest_edge,
            &mut self.touched,
        );
        self.contact.resolve_edges(
            &mut self.particles,
            &self.structure.springs,
            h,
            &mut self.touched,
        );
        self.clock.advance();
        self.report.taken += 1;
        self.report.time.constraints += constrained - start;
        self.report.time.self_contact += separated - constrained;
        self.report.time.contact += separated.elapsed();
    }

    /// Finishes a step. A step that left a position or velocity non-finite is undone (the
    /// positions at the end of the last good step come back, at rest) and says so; otherwise
    /// springs stretched past the tear ratio break (Sladović 2014 §3.2).
    pub fn end_step(&mut self) -> StepReport {
        let start = Instant::now();
        if self.report.substeps == 0 {
            return self.report;
        }
        // The limiter may have spent its budget during the substeps.
        self.report.under_resolved = self.clock.under_resolved;
        let (p, time) = (&self.particles, self.clock.time);
        self.report.finite = self.checkpoint.take(&p.position, &p.velocity, time);
        if self.report.finite {
            let model = self.stepping;
            model_steps(&model).end(self);
            self.report.max_strain = self.measure_closed_loop();
        } else {
            self.restore_checkpoint();
        }
        self.report.torn = self.structure.torn_this_step.len()
            + self
                .model
                .patches()
                .map_or(0, |p| p.parts.last_torn().len());
        self.report.time.end = start.elapsed();
        self.report
    }

    /// The report of the last step (or of the step in progress, so far).
    pub fn last_report(&self) -> StepReport {
        self.report
    }

    /// Puts the particles back where the checkpoint has them, at rest; everything else a
    /// step derives from them starts over from there (Verlet's previous positions, the
    /// patch model's lattice, shape matching's goals, XPBD's substep loop).
    fn restore_checkpoint(&mut self) {
        let (p, c) = (&mut self.particles, &self.checkpoint);
        p.position.clone_from(&c.position);
        p.previous.clone_from(&c.position);
        p.velocity.fill(Vec3::ZERO);
        p.residue.fill(Vec3::ZERO);
        p.force.fill(Vec3::ZERO);
        self.clock.time = c.time;
        self.clock.xpbd_loop = Default::default();
        self.switch = None;
        self.model = super::ModelState::None;
    }

    /// Takes the current positions as the state a failed step goes back to (after a
    /// reset).
    pub(super) fn save_checkpoint(&mut self) {
        let (p, time) = (&self.particles, self.clock.time);
        self.checkpoint.take(&p.position, &p.velocity, time);
    }

    /// The bound on the structural springs' length XPBD's closed loop holds them to, when
    /// the loop runs (XPBD at automatic substeps, the structural length bounded).
    fn closed_loop_bound(&self) -> Option<f32> {
        let bound = self.family_bound(SpringKind::Structural)?;
        matches!(
            (self.stepping, self.params.substeps),
            (Model::Xpbd(_), Substeps::Auto { .. })
        )
        .then_some(bound)
    }

    /// The closed loop's measure, in the last substep, after the model's constraints and
    /// before self-collision, the motion constraints and contact move particles, over the
    /// structural springs none of whose ends self-collision or contact moved in the
    /// step: what the constraints leave is the solver's error, which more substeps shrink
    /// (as `h²`); what those pushes leave (and what the constraints leave of it a substep
    /// later) is not, and more substeps do not shrink it. Counted, the pushes took a
    /// polyester flag in 5 m/s air with self-collision to the substep cap (8,192), and a
    /// cloth started through a ball from 6 substeps to 175.
    fn measure_solver_error(&mut self) {
        if let Some(bound) = self.closed_loop_bound() {
            let strain = self.untouched_structural_strain();
            self.clock.xpbd_loop.measured(strain - bound);
            self.report.solver_strain = Some(strain);
        }
    }

    /// XPBD's closed loop at automatic substeps, when the structural springs' length is
    /// bounded: the largest structural strain the step left, for the report (`None`
    /// otherwise). The loop's own measure was taken in the last substep
    /// ([`Self::measure_solver_error`]); a step whose substeps were run by hand a
    /// different number of times gives it this one.
    fn measure_closed_loop(&mut self) -> Option<f32> {
        let bound = self.closed_loop_bound()?;
        let strain = self.structural_strain();
        if self.report.solver_strain.is_none() {
            self.clock.xpbd_loop.measured(strain - bound);
        }
        Some(strain)
    }
}
