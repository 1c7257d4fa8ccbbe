//! Kinematic drivers: what moves particles by prescription rather than by force. Pins
//! follow the cloth's frame and a grabbed particle follows its tool, both over the
//! substeps of a step; seams shorten from their starting gap to their rest length over
//! the sewing time (seed 002 §1.4).

use bevy::math::{Affine3A, Vec3};

use super::{ClothSolver, Grab, ModelState, Particles, SpringKind};
use crate::error::ClothError;

/// What holds particles from outside: the pins (the layout's, then the attached ones),
/// the frame they follow, and a grab.
#[derive(Clone, Debug)]
pub(super) struct Drivers {
    /// Pinned particles: the layout's (the first `fixed_pins`), then the attached ones.
    pub pins: Vec<u32>,
    /// Each pin's world target when set from outside (an attachment), `None` for a pin
    /// that follows the frame.
    pub pin_goal: Vec<Option<Vec3>>,
    pub fixed_pins: usize,
    /// Where each pin was at the start of the step, and where it ends it.
    pub pin_from: Vec<Vec3>,
    pub pin_to: Vec<Vec3>,
    /// The frame (local → world) the pins follow.
    pub frame: Affine3A,
    pub grab: Option<Grab>,
}

impl Drivers {
    /// The layout's `pins`, following `frame`.
    pub fn new(pins: &[u32], frame: Affine3A) -> Self {
        Drivers {
            pin_from: Vec::with_capacity(pins.len()),
            pin_to: Vec::with_capacity(pins.len()),
            pin_goal: vec![None; pins.len()],
            fixed_pins: pins.len(),
            pins: pins.to_vec(),
            frame,
            grab: None,
        }
    }

    /// Drops the attachments and the grab; the pins hold their particles where they are.
    pub fn reset(&mut self, p: &mut Particles) {
        self.grab = None;
        self.pins.truncate(self.fixed_pins);
        self.pin_goal.clear();
        self.pin_goal.resize(self.fixed_pins, None);
        for &i in &self.pins {
            p.inv_mass[i as usize] = 0.0;
        }
        self.pin_to.clear();
        self.pin_to
            .extend(self.pins.iter().map(|&i| p.position[i as usize]));
        self.pin_from.clone_from(&self.pin_to);
    }

    /// Starts a step: pins go from where they are to where the frame (or their goal) puts
    /// them, over the substeps; a grab from where its particle is.
    pub fn begin_step(&mut self, x: &[Vec3], local_rest: &[Vec3]) {
        std::mem::swap(&mut self.pin_from, &mut self.pin_to);
        for (k, &i) in self.pins.iter().enumerate() {
            self.pin_to[k] = self.pin_goal[k]
                .unwrap_or_else(|| self.frame.transform_point3(local_rest[i as usize]));
            self.pin_from[k] = x[i as usize];
        }
        if let Some(g) = &mut self.grab {
            g.from = x[g.particle as usize];
        }
    }

    /// Where pin `k` is a fraction `t` through the step.
    pub fn pin_at(&self, k: usize, t: f32) -> Vec3 {
        self.pin_from[k].lerp(self.pin_to[k], t)
    }

    /// Moves the pinned and grabbed particles to where their drivers put them a fraction
    /// `t` through the step, with the velocity that takes them there this substep of `h`.
    pub fn drive(&self, p: &mut Particles, t: f32, h: f32) {
        for (k, &i) in self.pins.iter().enumerate() {
            p.move_to(i as usize, self.pin_at(k, t), h);
        }
        if let Some(g) = self.grab {
            p.move_to(g.particle as usize, g.from.lerp(g.target, t), h);
        }
    }
}

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
        if let Some(k) = self.drivers.pins.iter().position(|&p| p == i) {
            self.disturbed |= self.drivers.pin_goal[k] != Some(target);
            self.drivers.pin_goal[k] = Some(target);
            return Ok(());
        }
        let x = self.particles.position[i as usize];
        self.drivers.pins.push(i);
        self.drivers.pin_goal.push(Some(target));
        self.drivers.pin_from.push(x);
        self.drivers.pin_to.push(x);
        self.particles.inv_mass[i as usize] = 0.0;
        self.held_changed();
        Ok(())
    }

    /// Lets an attached particle go (a pin of the layout goes back to following the
    /// frame). False when it was neither.
    pub fn detach(&mut self, i: u32) -> bool {
        let Some(k) = self.drivers.pins.iter().position(|&p| p == i) else {
            return false;
        };
        if k < self.drivers.fixed_pins {
            self.drivers.pin_goal[k] = None;
        } else {
            self.drivers.pins.remove(k);
            self.drivers.pin_goal.remove(k);
            self.drivers.pin_from.remove(k);
            self.drivers.pin_to.remove(k);
            let p = &mut self.particles;
            p.inv_mass[i as usize] = 1.0 / p.mass[i as usize];
            self.held_changed();
        }
        self.disturbed = true;
        true
    }

    /// The particles held from outside ([`ClothSolver::attach`]), in order.
    pub fn attached(&self) -> &[u32] {
        &self.drivers.pins[self.drivers.fixed_pins..]
    }

    /// The set of held particles changed: the patch model's part lattice is rebuilt (its
    /// parts hang from the pins) by the next step.
    fn held_changed(&mut self) {
        if matches!(self.model, ModelState::Patches(_)) {
            self.model = ModelState::None;
        }
        self.disturbed = true;
    }

    /// Seam springs shrink from their starting gap to `seam_rest_length` over `sew_time`
    /// seconds of simulated time (a tailor sewing the pieces together).
    pub(super) fn sew(&mut self) {
        let s = &self.params.springs;
        let progress = if s.sew_time > 0.0 {
            (self.clock.time / s.sew_time).min(1.0)
        } else {
            1.0
        };
        let seams = self.structure.springs.ranges[SpringKind::Seam as usize].clone();
        for (rest, &start) in self.structure.springs.rest_length[seams]
            .iter_mut()
            .zip(&self.structure.seam_start)
        {
            *rest = start + (s.seam_rest_length - start) * progress;
        }
    }

    /// True while the seams of a garment are still being sewn (see `sew_time`).
    pub fn sewing(&self) -> bool {
        !self.structure.seam_start.is_empty()
            && self.clock.time < self.params.springs.sew_time
            && self.params.springs.seam.effective() > 0.0
    }
}
