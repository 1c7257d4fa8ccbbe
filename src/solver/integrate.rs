//! Phases 2 and 3 of a substep: integration and constraints.

use super::parallel::{self, PIECE};
use super::{ClothSolver, ModelState, Particles, SpringKind, family_stiffness, xpbd};
use crate::params::{GoalUpdate, Integrator, Model};

impl ClothSolver {
    /// Advances every free particle by one substep `h` from its accumulated force.
    pub fn integrate(&mut self) {
        let h = self.h;
        if let Some(patches) = self.model.patches_mut() {
            // The part lattice takes its whole substep first, held by the pins at their
            // place at the end of this substep; particles follow.
            patches.parts.integrate();
            patches.parts.constrain();
            let t = (self.substep_index + 1) as f32 / self.substeps.max(1) as f32;
            let (from, to) = (&self.pin_from, &self.pin_to);
            patches.hold_parts(|k| from[k].lerp(to[k], t), h);
            if matches!(self.params.model, Model::Patches(patch) if patch.tiles) {
                return; // tiles: particles are placed on their targets, not integrated
            }
        }
        if let Model::Xpbd(_) = self.params.model {
            // XPBD's prediction from the external forces: `v += h f/m`, `x += h v`
            // (Macklin et al. 2019, algorithm 1), whatever the integrator setting.
            symplectic_euler(&mut self.particles, h);
            return;
        }
        match self.params.integrator {
            Integrator::Verlet => verlet(&mut self.particles, h),
            Integrator::SemiImplicitEuler => symplectic_euler(&mut self.particles, h),
        }
    }

    /// Müller et al. 2005's update for shape matching: after integration, every free
    /// particle moves the fraction α of the way to its goal (goals from the predicted
    /// positions), and its velocity takes the same change over `h`. Nothing for the other
    /// models.
    pub fn fit_targets(&mut self) {
        if let (Model::Patches(patch), Some(patches)) =
            (self.params.model, self.model.patches_mut())
        {
            let p = &mut self.particles;
            let h = self.h;
            if patch.tiles {
                // Tiles (Slika 12): every free particle on its target.
                patches.compute_targets(&p.position, &patch);
                for i in 0..p.position.len() {
                    if p.inv_mass[i] != 0.0 {
                        p.move_to(i, patches.targets[i], h);
                    }
                }
                return;
            }
            patches.advance_targets(&p.position, &patch, h);
            for i in 0..p.position.len() {
                // A particle that is a part of its own is its part's centre.
                if p.inv_mass[i] != 0.0 && patches.is_single(i) {
                    let target = patches.targets[i];
                    p.velocity[i] = (target - p.previous[i]) / h;
                    p.position[i] = target;
                }
            }
            return;
        }
        let (Model::ShapeMatching(sm), Some(state)) =
            (self.params.model, self.model.shape_matching_mut())
        else {
            return;
        };
        if sm.update != GoalUpdate::Velocity {
            return;
        }
        let p = &mut self.particles;
        state.compute_goals(&p.position, &p.mass, &sm);
        let h = self.h;
        for i in 0..p.position.len() {
            if p.inv_mass[i] == 0.0 {
                continue;
            }
            let delta = state.offsets[i] * sm.stiffness;
            p.position[i] += delta;
            p.velocity[i] += delta / h;
        }
    }

    /// Moves pinned particles along their path, applies Provot's strain limit and keeps
    /// particles out of the colliders; then advances the clock by one substep.
    pub fn constrain(&mut self) {
        self.substep_index += 1;
        let t = self.substep_index as f32 / self.substeps.max(1) as f32;
        let h = self.h;
        self.drive(t);
        // Strain limiting corrects springs; a model without acting springs has none.
        // XPBD's constraints (and its strain limit) are projected here, after the pins.
        match (self.params.strain_limit, self.params.model) {
            (Some(limit), Model::MassSpring) => self.limit_strain(limit, h),
            (_, Model::Xpbd(_)) => self.project_constraints(h),
            _ => {}
        }
        // Last, so no later correction pushes a particle back into a collider.
        self.collide();
        self.time += h;
    }

    /// Provot (1995): springs longer than `(1 + limit)·l0` are shortened to that length,
    /// each end moved by its share of inverse mass (seed 000 eq. 2); Gauss–Seidel sweeps
    /// over the structural and shear springs. Velocities take the same correction over `h`.
    /// With `strain_limit_tolerance`, sweeping stops once a sweep finds every spring
    /// within `(1 + limit + tolerance)·l0`.
    fn limit_strain(&mut self, limit: f32, h: f32) {
        let sweeps = self.params.strain_limit_iterations;
        if let Some(stencil) = &mut self.stencil {
            let springs = self.params.springs;
            let enabled = |kind| match kind {
                SpringKind::Structural => springs.structural.enabled,
                SpringKind::Shear => springs.shear.enabled,
                _ => false,
            };
            let past = self
                .params
                .strain_limit_tolerance
                .map(|tolerance| 1.0 + limit + tolerance);
            stencil.limit_strain(&mut self.particles, enabled, limit, sweeps, past, h);
            return;
        }
        match self.params.strain_limit_tolerance {
            None => {
                for _ in 0..sweeps {
                    self.limit_strain_sweep::<false>(limit, f32::INFINITY, h);
                }
            }
            Some(tolerance) => {
                let past = 1.0 + limit + tolerance;
                for _ in 0..sweeps {
                    if !self.limit_strain_sweep::<true>(limit, past, h) {
                        break;
                    }
                }
            }
        }
    }

    /// One Gauss–Seidel sweep of [`Self::limit_strain`]. With `TRACK`, returns whether a
    /// spring was longer than `past·l0` (not yet converged); the fixed-sweep limiter
    /// compiles without that test.
    fn limit_strain_sweep<const TRACK: bool>(&mut self, limit: f32, past: f32, h: f32) -> bool {
        let s = &self.springs;
        let p = &mut self.particles;
        let mut unconverged = false;
        for kind in [SpringKind::Structural, SpringKind::Shear] {
            if !self.params.springs.structural.enabled && kind == SpringKind::Structural
                || !self.params.springs.shear.enabled && kind == SpringKind::Shear
            {
                continue;
            }
            for idx in s.ranges[kind as usize].clone() {
                if !s.alive[idx] {
                    continue;
                }
                let (a, b) = (s.a[idx] as usize, s.b[idx] as usize);
                let (wa, wb) = (p.inv_mass[a], p.inv_mass[b]);
                let w = wa + wb;
                if w == 0.0 {
                    continue;
                }
                let d = p.position[b] - p.position[a];
                let len = d.length();
                let max = (1.0 + limit) * s.rest_length[idx];
                if len <= max {
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

    /// XPBD: every spring's constraint projected once (`xpbd.rs`; a grid's on its
    /// stencil, `lattice/xpbd.rs`), the strain limit with the structural and shear ones,
    /// then the tethers to the pins (`tethers.rs`).
    fn project_constraints(&mut self, h: f32) {
        let ModelState::Xpbd(constraints) = &mut self.model else {
            return;
        };
        let (c, limit) = (self.params.springs.damping, self.params.strain_limit);
        let families = SpringKind::ALL.map(|kind| {
            let k = family_stiffness(&self.params.springs, kind);
            let limited = matches!(kind, SpringKind::Structural | SpringKind::Shear);
            xpbd::Family::new(k, c, h, limit.filter(|_| limited))
        });
        match &mut self.stencil {
            Some(stencil) => stencil.project_xpbd(&mut self.particles, &families, h),
            None => constraints.project(&mut self.particles, &families, h),
        }
        // Last, so the bound they keep holds at the end of the substep.
        constraints
            .tethers
            .project(&mut self.particles, &self.pins, h);
    }

    /// Builds XPBD's tethers to the pins again when the pins, the torn springs or the
    /// material's bounds changed (`tethers.rs`); drops them when switched off. A family's
    /// length is bounded when it is inextensible (the tether's slack 0) or strain limited
    /// (the slack the limit); the slack is the larger of the bounded families'.
    pub(super) fn refresh_tethers(&mut self) {
        let Model::Xpbd(xpbd) = self.params.model else {
            return;
        };
        let bounds = [
            self.family_bound(SpringKind::Structural),
            self.family_bound(SpringKind::Shear),
        ];
        let ModelState::Xpbd(constraints) = &mut self.model else {
            return;
        };
        let on = xpbd.tethers && bounds[0].is_some();
        let pins: &[u32] = if on { &self.pins } else { &[] };
        let slack = bounds.iter().flatten().fold(0.0f32, |a, &b| a.max(b));
        constraints.tethers.refresh(
            &self.springs,
            self.torn_count,
            pins,
            bounds.map(|b| b.is_some()),
            slack,
            self.particles.len(),
        );
    }

    /// Keeps Verlet's implicit velocity `(x − x_prev)/h` when `h` changes by `ratio`.
    pub(super) fn rescale_verlet_velocity(&mut self, ratio: f32) {
        if self.params.integrator != Integrator::Verlet
            || matches!(self.params.model, Model::Xpbd(_))
        {
            return;
        }
        let p = &mut self.particles;
        for i in 0..p.position.len() {
            if p.inv_mass[i] != 0.0 {
                p.previous[i] = p.position[i] - (p.position[i] - p.previous[i]) * ratio;
                p.residue[i] *= ratio;
            }
        }
    }
}

/// One Verlet substep of every free particle, in pieces over the compute pool.
fn verlet(p: &mut Particles, h: f32) {
    let (n, h2) = (p.len(), h * h);
    // Seed 002 eq. 1.12 prints `+ a Δt²/2`; substituting eq. 1.10 into 1.9
    // drops the `x_{n−1}` Taylor term, and the correct Störmer–Verlet step is
    // `x' = 2x − x_prev + a Δt²` (with the ½, free fall would reach only g t²/4).
    // Written as `x' = x + ((x − x_prev) + a Δt²)` with compensated summation:
    // in `f32` a displacement under half the spacing of floats at `x` is lost
    // when added, and the plain form then recomputes `x − x_prev = 0`: at 512
    // substeps of 16 ms a curtain at y = 2 m never started to fall (g Δt² = 1e-8
    // m against 1.2e-7 m). What rounding drops is carried to the next substep.
    let pieces = p
        .position
        .chunks_mut(PIECE)
        .zip(p.previous.chunks_mut(PIECE))
        .zip(p.residue.chunks_mut(PIECE))
        .zip(p.velocity.chunks_mut(PIECE))
        .zip(p.force.chunks(PIECE).zip(p.inv_mass.chunks(PIECE)));
    parallel::for_each(
        n,
        pieces,
        |((((position, previous), residue), velocity), (force, inv_mass))| {
            let particles = position
                .iter_mut()
                .zip(previous)
                .zip(residue)
                .zip(velocity)
                .zip(force.iter().zip(inv_mass));
            for ((((x, previous), residue), velocity), (force, &w)) in particles {
                if w == 0.0 {
                    continue;
                }
                let step = (*x - *previous) + *residue + *force * (w * h2);
                let next = *x + step;
                *residue = step - (next - *x);
                *previous = *x;
                *x = next;
                *velocity = step / h;
            }
        },
    );
}

/// One symplectic Euler substep of every free particle, in pieces over the compute pool.
fn symplectic_euler(p: &mut Particles, h: f32) {
    let n = p.len();
    // Seed 000 eq. 21–22: the new velocity first, then the position from it.
    let pieces = p
        .position
        .chunks_mut(PIECE)
        .zip(p.previous.chunks_mut(PIECE))
        .zip(p.velocity.chunks_mut(PIECE))
        .zip(p.force.chunks(PIECE).zip(p.inv_mass.chunks(PIECE)));
    parallel::for_each(
        n,
        pieces,
        |(((position, previous), velocity), (force, inv_mass))| {
            let particles = position
                .iter_mut()
                .zip(previous)
                .zip(velocity)
                .zip(force.iter().zip(inv_mass));
            for (((x, previous), velocity), (force, &w)) in particles {
                if w == 0.0 {
                    continue;
                }
                *velocity += *force * (w * h);
                *previous = *x;
                *x += *velocity * h;
            }
        },
    );
}
