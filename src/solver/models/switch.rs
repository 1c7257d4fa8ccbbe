//! A model switch without a jump (level of detail, or a model changed in the inspector).
//!
//! Two models of one cloth accelerate it differently at the same state: the patch
//! model's lattice is stiffer than the particles' springs, a particle cloth's springs are
//! not balanced at the shape the parts left it in. Switched instantly, the new model
//! snaps toward its own equilibrium in the first steps (a settled 24×24 curtain moved 2–6
//! mm in the switch step against 0.1 mm in a normal one) and rings about it.
//!
//! So the switch matches accelerations: at the switch the old model is stepped once more
//! on a copy, which gives each particle's acceleration `a` over that step; the new model
//! then gets an extra force `m a − F_new` on each node it integrates (the particles of a
//! force-based cloth, the part centres of the patch model), which makes its first step
//! accelerate the cloth as the old model would have, and the extra force fades out with
//! a smoothstep over [`EASE_TIME`] — several periods of the cloth's stiffest motion, so
//! it moves to the new equilibrium without ringing. Models that hold the cloth by
//! projection (XPBD, shape matching) take no extra force: there is no force to match.

use bevy::math::Vec3;

use crate::params::{Environment, Model};
use crate::solver::ClothSolver;
use crate::solver::patches::{EASE_TIME, ease_share};

/// A switch in progress.
#[derive(Clone, Debug)]
pub(in crate::solver) struct Switch {
    /// The cloth with the old model, until its one step has been taken.
    old: Option<Box<ClothSolver>>,
    /// The extra force on each node the new model integrates (empty until computed).
    correction: Vec<Vec3>,
    /// Seconds of the fade left.
    left: f32,
}

impl Switch {
    /// A switch away from `old`'s model, a copy of the cloth before the switch.
    pub(in crate::solver) fn new(old: ClothSolver) -> Self {
        Switch {
            old: Some(Box::new(old)),
            correction: Vec::new(),
            left: EASE_TIME,
        }
    }
}

impl ClothSolver {
    /// Starts a switch from the current model to `params`' (call before taking them).
    /// Nothing for a cloth that has not moved yet.
    pub(in crate::solver) fn begin_switch(&mut self, params: &crate::params::ClothParams) {
        if self.clock.time == 0.0 || !changes_model(self.params.model, params.model) {
            return;
        }
        let mut old = self.clone();
        old.switch = None;
        self.switch = Some(Switch::new(old));
    }

    /// Adds the switch's extra force to this substep's forces (after they are
    /// accumulated); on the first substep after the switch, computes it from the old
    /// model's step (see the module doc). Allocates only then.
    pub(in crate::solver) fn add_switch_force(&mut self, env: &Environment) {
        let Some(mut switch) = self.switch.take() else {
            return;
        };
        if let Some(mut old) = switch.old.take() {
            let dt = self.clock.step_length();
            old.step(dt, env);
            // x(dt) = x + v dt + a dt²/2 over the step, for each particle.
            let p = &self.particles;
            let accel: Vec<Vec3> = (0..p.len())
                .map(|i| {
                    2.0 * (old.particles.position[i] - p.position[i] - p.velocity[i] * dt)
                        / (dt * dt)
                })
                .collect();
            switch.correction = match (&self.params.model, self.model.patches()) {
                (Model::Patches(_), Some(patches)) => {
                    let lattice = &patches.parts.particles;
                    let pulled = patches.part_sums(|i| p.mass[i] * accel[i]);
                    (0..lattice.len())
                        .map(|k| pulled[k] - lattice.force[k])
                        .collect()
                }
                (Model::MassSpring, _) => (0..p.len())
                    .map(|i| p.mass[i] * accel[i] - p.force[i])
                    .collect(),
                _ => Vec::new(),
            };
        }
        let share = ease_share(switch.left);
        let forces = match self.model.patches_mut() {
            Some(patches) => &mut patches.parts.particles.force,
            None => &mut self.particles.force,
        };
        if forces.len() == switch.correction.len() {
            for (f, c) in forces.iter_mut().zip(&switch.correction) {
                *f += *c * share;
            }
        }
        switch.left -= self.clock.h;
        if switch.left > 0.0 {
            self.switch = Some(switch);
        }
    }
}

/// True when going from `from` to `to` changes what moves the cloth (another model, or
/// the patch model at another part size).
fn changes_model(from: Model, to: Model) -> bool {
    match (from, to) {
        (Model::Patches(a), Model::Patches(b)) => a.lattice_key() != b.lattice_key(),
        (a, b) => std::mem::discriminant(&a) != std::mem::discriminant(&b),
    }
}
