//! The mass-spring model's step (Sladović 2014 §3.2 and Maslova §1): spring and external forces,
//! Verlet or semi-implicit Euler, Provot's strain limit, tearing.

use super::{MassSpring, ModelSteps};
use crate::params::Environment;
use crate::solver::{ClothSolver, ModelState, SpringKind};

impl ModelSteps for MassSpring {
    fn build(&self, cloth: &mut ClothSolver, _compute: bool) {
        cloth.model = ModelState::None;
    }

    fn begin(&self, cloth: &mut ClothSolver, _dt: f32, ratio: Option<f32>) {
        cloth.rescale_verlet_velocity(ratio);
    }

    fn forces(&self, cloth: &mut ClothSolver, env: &Environment) {
        cloth.external_forces(env);
        cloth.spring_forces();
        if let Some(fabric) = cloth.params.fabric {
            let hinges = &cloth.structure.hinges;
            hinges.add_forces(&mut cloth.particles, fabric.bending);
        }
    }

    fn integrate(&self, cloth: &mut ClothSolver) {
        cloth.integrate_particles(cloth.params.drag);
    }

    /// Strain limiting corrects springs (after the pins are driven).
    fn constrain(&self, cloth: &mut ClothSolver) {
        if let Some(limit) = cloth.params.strain_limit {
            cloth.limit_strain(limit, cloth.clock.h);
        }
    }

    fn end(&self, cloth: &mut ClothSolver) {
        cloth.tear_overstretched();
    }
}

/// A spring whose squared length is under this share of its squared limit is within it
/// whatever the rounding of the square and the square root (a few units in the last place
/// of `f32`).
const WITHIN_SQUARED: f32 = 1.0 - 1e-5;

impl ClothSolver {
    /// Provot (1995): springs longer than `(1 + limit)·l0` are shortened to that length,
    /// each end moved by its share of inverse mass (Sladović 2014 eq. 2); Gauss–Seidel sweeps
    /// over the structural and shear springs. Velocities take the same correction over `h`.
    /// With `strain_limit_tolerance`, sweeping stops once a sweep finds every spring
    /// within `(1 + limit + tolerance)·l0`.
    ///
    /// The sweeps until within draw on the step's budget (`limits::limiter_budget`): a
    /// limiter that cannot converge (fighting a collider or a seam) would otherwise take
    /// its most sweeps every substep. Once the budget is spent each substep sweeps once,
    /// and the step reports itself under-resolved.
    fn limit_strain(&mut self, limit: f32, h: f32) {
        let most = self.params.strain_limit_iterations;
        let past = self
            .params
            .strain_limit_tolerance
            .map(|tolerance| 1.0 + limit + tolerance);
        let sweeps = match past {
            Some(_) => most.min(self.clock.limiter_sweeps_left.max(1)),
            None => most,
        };
        let (run, within) = if let Some(stencil) = &mut self.structure.stencil {
            let springs = self.params.springs_in_use();
            let enabled = |kind| match kind {
                SpringKind::Structural => springs.structural.enabled,
                SpringKind::Shear => springs.shear.enabled,
                _ => false,
            };
            stencil.limit_strain(&mut self.particles, enabled, limit, sweeps, past, h)
        } else {
            let (mut run, mut within) = (0, past.is_none());
            while run < sweeps {
                run += 1;
                let unconverged = match past {
                    None => self.limit_strain_sweep::<false>(limit, f32::INFINITY, h),
                    Some(past) => self.limit_strain_sweep::<true>(limit, past, h),
                };
                if past.is_some() && !unconverged {
                    within = true;
                    break;
                }
            }
            (run, within)
        };
        if past.is_some() {
            let left = &mut self.clock.limiter_sweeps_left;
            *left = left.saturating_sub(run);
            if !within && sweeps < most {
                self.clock.under_resolved = true;
            }
        }
    }

    /// One Gauss–Seidel sweep of [`Self::limit_strain`]. With `TRACK`, returns whether a
    /// spring was longer than `past·l0` (not yet converged); the fixed-sweep limiter
    /// compiles without that test.
    fn limit_strain_sweep<const TRACK: bool>(&mut self, limit: f32, past: f32, h: f32) -> bool {
        let s = &self.structure.springs;
        let p = &mut self.particles;
        let mut unconverged = false;
        let springs = self.params.springs_in_use();
        for kind in [SpringKind::Structural, SpringKind::Shear] {
            if !springs.structural.enabled && kind == SpringKind::Structural
                || !springs.shear.enabled && kind == SpringKind::Shear
            {
                continue;
            }
            for idx in s.ranges[kind as usize].clone() {
                if !s.alive[idx] {
                    continue;
                }
                let (a, b) = (s.a[idx] as usize, s.b[idx] as usize);
                let d = p.position[b] - p.position[a];
                let max = (1.0 + limit) * s.rest_length[idx];
                // Most springs are within their limit: the squared length tells them apart
                // without a square root (a margin under the rounding of both sides, so
                // the springs corrected are exactly those with `len > max`).
                let squared = d.length_squared();
                if squared <= WITHIN_SQUARED * max * max {
                    continue;
                }
                let len = squared.sqrt();
                if len <= max {
                    continue;
                }
                let (wa, wb) = (p.inv_mass[a], p.inv_mass[b]);
                let w = wa + wb;
                if w == 0.0 {
                    continue;
                }
                if TRACK {
                    unconverged |= len > past * s.rest_length[idx];
                }
                let correction = d * ((len - max) / (len * w));
                p.position[a] += correction * wa;
                p.position[b] -= correction * wb;
                p.velocity[a] += correction * (wa / h);
                p.velocity[b] -= correction * (wb / h);
            }
        }
        unconverged
    }
}
