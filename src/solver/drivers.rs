//! Kinematic drivers: what moves particles by prescription rather than by force. Pins
//! follow the cloth's frame and a grabbed particle follows its tool, both over the
//! substeps of a step; seams shorten from their starting gap to their rest length over
//! the sewing time (seed 002 §1.4).

use bevy::math::Vec3;

use super::{ClothSolver, ModelState, SpringKind};
use crate::error::ClothError;

impl ClothSolver {
    /// Holds particle `i` at the world point `target`: an attachment to an outside body
    /// (a character's shoulder, a mast) that the caller moves every step. Like a pin the
    /// particle is kinematic and goes from where it is to `target` over the next step's
    /// substeps, so a body moving each step is followed with no lag beyond that step.
    /// Calling it again for an attached particle (or a pin) moves its target. It lasts
    /// until [`ClothSolver::detach`] or a reset; the patch model's parts are rebuilt to
    /// hang from it.
    pub fn attach(&mut self, i: u32, target: Vec3) -> Result<(), ClothError> {
        let count = self.particles.len();
        if i as usize >= count {
            return Err(ClothError::PinOutOfRange { index: i, count });
        }
        if !(target.is_finite() && target.length() <= crate::limits::MAX_POSITION) {
            return Err(ClothError::InvalidParameter {
                field: "attachment target",
                value: target.length(),
                expected: "a finite point within 1e5 m (limits::MAX_POSITION)",
            });
        }
        if let Some(k) = self.pins.iter().position(|&p| p == i) {
            self.disturbed |= self.pin_goal[k] != Some(target);
            self.pin_goal[k] = Some(target);
            return Ok(());
        }
        let x = self.particles.position[i as usize];
        self.pins.push(i);
        self.pin_goal.push(Some(target));
        self.pin_from.push(x);
        self.pin_to.push(x);
        self.particles.inv_mass[i as usize] = 0.0;
        self.held_changed();
        Ok(())
    }

    /// Lets an attached particle go (a pin of the layout goes back to following the
    /// frame). False when it was neither.
    pub fn detach(&mut self, i: u32) -> bool {
        let Some(k) = self.pins.iter().position(|&p| p == i) else {
            return false;
        };
        if k < self.fixed_pins {
            self.pin_goal[k] = None;
        } else {
            self.pins.remove(k);
            self.pin_goal.remove(k);
            self.pin_from.remove(k);
            self.pin_to.remove(k);
            let p = &mut self.particles;
            p.inv_mass[i as usize] = 1.0 / p.mass[i as usize];
            self.held_changed();
        }
        self.disturbed = true;
        true
    }

    /// The particles held from outside ([`ClothSolver::attach`]), in order.
    pub fn attached(&self) -> &[u32] {
        &self.pins[self.fixed_pins..]
    }

    /// The set of held particles changed: the patch model's part lattice is rebuilt (its
    /// parts hang from the pins) by the next step.
    fn held_changed(&mut self) {
        if matches!(self.model, ModelState::Patches(_)) {
            self.model = ModelState::None;
        }
        self.disturbed = true;
    }

    /// Moves the pinned and grabbed particles to where their drivers put them a fraction
    /// `t` through the step, with the velocity that takes them there this substep.
    pub(super) fn drive(&mut self, t: f32) {
        let h = self.h;
        for (k, &i) in self.pins.iter().enumerate() {
            let target = self.pin_from[k].lerp(self.pin_to[k], t);
            self.particles.move_to(i as usize, target, h);
        }
        if let Some(g) = self.grab {
            self.particles
                .move_to(g.particle as usize, g.from.lerp(g.target, t), h);
        }
    }

    /// Seam springs shrink from their starting gap to `seam_rest_length` over `sew_time`
    /// seconds of simulated time (a tailor sewing the pieces together).
    pub(super) fn sew(&mut self) {
        let s = &self.params.springs;
        let progress = if s.sew_time > 0.0 {
            (self.time / s.sew_time).min(1.0)
        } else {
            1.0
        };
        let seams = self.springs.ranges[SpringKind::Seam as usize].clone();
        for (rest, &start) in self.springs.rest_length[seams]
            .iter_mut()
            .zip(&self.seam_start)
        {
            *rest = start + (s.seam_rest_length - start) * progress;
        }
    }

    /// True while the seams of a garment are still being sewn (see `sew_time`).
    pub fn sewing(&self) -> bool {
        !self.seam_start.is_empty()
            && self.time < self.params.springs.sew_time
            && self.params.springs.seam.effective() > 0.0
    }
}
