//! Phase 1 of a substep: every force from the old state.

use super::parallel::{self, PIECE};
use super::{ClothSolver, Particles, SpringKind, Springs, pull_scale};
use crate::params::{Environment, GoalUpdate, Model, PatchParams, ShapeMatchingParams};

impl ClothSolver {
    /// Clears and accumulates the forces on every free particle: gravity (seed 002
    /// eq. 1.6), wind, linear drag `−c v` (seed 000 eq. 31) and the springs. Reads only the
    /// old state, so the result does not depend on particle order (seed 000 §3.2). Just
    /// after a model switch, the force that keeps the switch smooth (`switch.rs`).
    pub fn accumulate_forces(&mut self, env: &Environment) {
        self.model_forces(env);
        self.add_switch_force(env);
    }

    /// [`ClothSolver::accumulate_forces`] of the model alone.
    fn model_forces(&mut self, env: &Environment) {
        if let Model::Patches(patch) = self.params.model {
            // External forces act on the part centres (one-way coupling, see patches.rs).
            self.pull_forces(env, &patch);
            return;
        }
        // While its seams are being sewn, a garment is held as a tailor holds it: gravity
        // and wind act once the seams are closed (otherwise the pieces would fall past the
        // body in the time it takes to sew them).
        let held = self.sewing();
        let g = if held {
            bevy::math::Vec3::ZERO
        } else {
            env.effective_gravity()
        };
        let drag = self.params.drag;
        let has_wind =
            !held && env.wind.strength > 0.0 && env.wind.direction != bevy::math::Vec3::ZERO;
        let wind = env.wind.at_time(self.time);
        let p = &mut self.particles;
        let pieces = p.force.chunks_mut(PIECE).zip(
            p.mass
                .chunks(PIECE)
                .zip(p.lump.chunks(PIECE))
                .zip(p.velocity.chunks(PIECE).zip(p.position.chunks(PIECE))),
        );
        parallel::for_each(
            p.position.len(),
            pieces,
            |(force, ((mass, lump), (v, x)))| {
                let particles = force
                    .iter_mut()
                    .zip(mass.iter().zip(lump).zip(v.iter().zip(x)));
                for (f, ((&mass, &lump), (&v, &x))) in particles {
                    *f = mass * g - drag * lump * v;
                    if has_wind {
                        *f += wind.force_at(x) * lump;
                    }
                }
            },
        );
        match self.params.model {
            Model::ShapeMatching(sm) => {
                self.goal_forces(&sm);
                return;
            }
            // XPBD's springs are constraints, projected after the prediction (`xpbd.rs`).
            Model::Xpbd(_) => return,
            Model::MassSpring | Model::Patches(_) => {}
        }

        let damping = self.params.springs.damping;
        if self.stencil.is_some() {
            let k = SpringKind::ALL.map(|kind| self.stiffness(kind));
            if let Some(stencil) = &mut self.stencil {
                stencil.spring_forces(&mut self.particles, |kind| k[kind as usize], damping);
            }
            return;
        }
        for kind in SpringKind::ALL {
            let k = self.stiffness(kind);
            if k == 0.0 {
                continue;
            }
            let range = self.springs.ranges[kind as usize].clone();
            // A particle cloth's springs all take their family's constant; only the patch
            // model's part lattice scales them one by one. Two instances of one loop, so
            // the common case reads no per-spring factor.
            let (s, p) = (&self.springs, &mut self.particles);
            match s.stiffness_scale.as_deref() {
                None => spring_forces(s, p, range, k, damping, |_| 1.0),
                Some(scale) => spring_forces(s, p, range, k, damping, |i| scale[i]),
            }
        }
    }

    /// Shape matching's pull toward the goals (seed 000 §3.3, §4): particle damping
    /// `−c v`, and for the force update `α (|d|/L)^(p−1) d` with `d = g − x` from goals of
    /// the current positions.
    fn goal_forces(&mut self, sm: &ShapeMatchingParams) {
        let force_update = sm.update == GoalUpdate::Force;
        if force_update && let Some(state) = self.model.shape_matching_mut() {
            state.compute_goals(&self.particles.position, &self.particles.mass, sm);
        }
        let p = &mut self.particles;
        for i in 0..p.position.len() {
            p.force[i] -= sm.damping * p.velocity[i];
        }
        let (Some(state), true) = (self.model.shape_matching(), force_update) else {
            return;
        };
        let (l, exponent) = (self.length_scale, sm.exponent);
        if exponent == 1.0 {
            // The offsets already sum to zero (mean removed per cluster).
            for i in 0..p.position.len() {
                p.force[i] += state.offsets[i] * sm.stiffness;
            }
            return;
        }
        // For p ≠ 1 each particle's own scale (|d|/L)^(p−1) undoes the zero sum of the
        // offsets: take the net force back out, shared by mass, so the goal forces
        // conserve momentum (pinned particles take their share, so a pin still holds).
        let (mut net, mut mass) = (bevy::math::DVec3::ZERO, 0.0f64);
        for i in 0..p.position.len() {
            let d = state.offsets[i];
            let f = d * (sm.stiffness * pull_scale(d.length(), l, exponent));
            net += f.as_dvec3();
            mass += p.mass[i] as f64;
            p.force[i] += f;
        }
        let per_kg = (net / mass.max(f64::MIN_POSITIVE)).as_vec3();
        for i in 0..p.position.len() {
            p.force[i] -= per_kg * p.mass[i];
        }
    }

    /// The patch model: the part lattice's forces, and each particle's pull toward its
    /// target `α (|d|/L)^(p−1) d` damped at `ratio · 2√(α m)` on its velocity relative to
    /// the target (damping the absolute velocity would be a drag the lattice never
    /// feels). With tiles the particles sit on their targets: no pull at all.
    fn pull_forces(&mut self, env: &Environment, patch: &PatchParams) {
        let Some(patches) = self.model.patches_mut() else {
            return;
        };
        patches.parts.accumulate_forces(env);
        if patch.tiles {
            return;
        }
        let (l, exponent) = (self.length_scale, patch.exponent);
        let p = &mut self.particles;
        let (targets, target_velocity) = (&patches.targets, &patches.target_velocity);
        let (x, v, mass) = (&p.position, &p.velocity, &p.mass);
        parallel::for_each_indexed(&mut p.force, |i, f| {
            let d = targets[i] - x[i];
            let scale = pull_scale(d.length(), l, exponent);
            let damping = patch.particle_damping_ratio * 2.0 * (patch.stiffness * mass[i]).sqrt();
            let relative = v[i] - target_velocity[i];
            *f = d * (patch.stiffness * scale) - damping * relative;
        });
    }

    /// Adds an external force (N) to particle `i` for the current substep. Call it between
    /// `accumulate_forces` and `integrate` (in the plugin: after
    /// `ClothSubstepSystems::AccumulateForces`, before `ClothSubstepSystems::Integrate`).
    pub fn add_force(&mut self, i: usize, force: bevy::math::Vec3) {
        if let Some(f) = self.particles.force.get_mut(i) {
            *f += force;
        }
    }
}

/// Hooke springs `F = k (|l| − l0) l/|l|` (seed 002 eq. 1.4) plus damping along the
/// spring, over the springs `range` of `s`, each scaled by `scale(spring)`. Each spring
/// pushes its ends with equal and opposite forces; dividing by each end's mass in
/// `integrate` shares the motion by inverse mass, as seed 000 eq. 2 asks.
#[inline(always)]
fn spring_forces(
    s: &Springs,
    p: &mut Particles,
    range: std::ops::Range<usize>,
    k: f32,
    damping: f32,
    scale: impl Fn(usize) -> f32,
) {
    for idx in range {
        if !s.alive[idx] {
            continue;
        }
        let (a, b) = (s.a[idx] as usize, s.b[idx] as usize);
        let d = p.position[b] - p.position[a];
        let len = d.length();
        if len <= f32::EPSILON {
            continue;
        }
        let dir = d / len;
        let mut magnitude = k * scale(idx) * (len - s.rest_length[idx]);
        if damping > 0.0 {
            magnitude += damping * (p.velocity[b] - p.velocity[a]).dot(dir);
        }
        let f = dir * magnitude;
        p.force[a] += f;
        p.force[b] -= f;
    }
}
