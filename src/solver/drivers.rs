//! Kinematic drivers: what moves particles by prescription rather than by force. Pins
//! follow the cloth's frame and a grabbed particle follows its tool, both over the
//! substeps of a step; seams shorten from their starting gap to their rest length over
//! the sewing time (seed 002 §1.4).

use super::{ClothSolver, SpringKind};

impl ClothSolver {
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
