//! Meshless shape matching's step (Müller et al. 2005; Sladović 2014 §3.3–§4): gravity, wind
//! and drag, integrated; each cluster's goal positions from the best rigid (or linear)
//! fit of its rest shape; then either a force `α (|d|/L)^(p−1) d` toward the goals
//! (the seed's force update) or the paper's velocity update, a fraction α of the way
//! there after integration.

use bevy::math::DVec3;

use super::ModelSteps;
use crate::params::{Environment, GoalUpdate, ShapeMatchingParams};
use crate::solver::shape_matching::ShapeMatching;
use crate::solver::{ClothSolver, ModelState, pull_scale};

impl ModelSteps for ShapeMatchingParams {
    fn build(&self, cloth: &mut ClothSolver, compute: bool) {
        let k = self.clusters;
        let built = cloth
            .model
            .shape_matching()
            .is_none_or(|s| s.built_for != k);
        if built {
            let state = ShapeMatching::new(
                &cloth.structure.local_rest,
                &cloth.particles.mass,
                cloth.structure.grid,
                k,
            );
            cloth.model = ModelState::ShapeMatching(state);
        }
        if let Some(state) = cloth.model.shape_matching_mut()
            && (compute || built)
        {
            state.compute_goals(&cloth.particles.position, &cloth.particles.mass, self);
        }
    }

    fn begin(&self, cloth: &mut ClothSolver, _dt: f32, ratio: Option<f32>) {
        cloth.rescale_verlet_velocity(ratio);
    }

    fn forces(&self, cloth: &mut ClothSolver, env: &Environment) {
        cloth.external_forces(env);
        goal_forces(cloth, self);
    }

    fn integrate(&self, cloth: &mut ClothSolver) {
        cloth.integrate_particles(cloth.params.drag);
    }

    /// The velocity update: after integration, every free particle moves the fraction α
    /// of the way to its goal (goals from the predicted positions), and its velocity
    /// takes the same change over `h`.
    fn fit_targets(&self, cloth: &mut ClothSolver) {
        let Some(state) = cloth.model.shape_matching_mut() else {
            return;
        };
        if self.update != GoalUpdate::Velocity {
            return;
        }
        let p = &mut cloth.particles;
        state.compute_goals(&p.position, &p.mass, self);
        let h = cloth.clock.h;
        for i in 0..p.position.len() {
            if p.inv_mass[i] == 0.0 {
                continue;
            }
            let delta = state.offsets[i] * self.stiffness;
            p.position[i] += delta;
            p.velocity[i] += delta / h;
        }
    }
}

/// The pull toward the goals (Sladović 2014 §3.3, §4): particle damping `−c v`, and for the
/// force update `α (|d|/L)^(p−1) d` with `d = g − x` from goals of the current
/// positions.
fn goal_forces(cloth: &mut ClothSolver, sm: &ShapeMatchingParams) {
    let force_update = sm.update == GoalUpdate::Force;
    if force_update && let Some(state) = cloth.model.shape_matching_mut() {
        state.compute_goals(&cloth.particles.position, &cloth.particles.mass, sm);
    }
    let p = &mut cloth.particles;
    for i in 0..p.position.len() {
        p.force[i] -= sm.damping * p.velocity[i];
    }
    let (Some(state), true) = (cloth.model.shape_matching(), force_update) else {
        return;
    };
    let (l, exponent) = (cloth.structure.length_scale, sm.exponent);
    if exponent == 1.0 {
        // The offsets already sum to zero (mean removed per cluster).
        for i in 0..p.position.len() {
            p.force[i] += state.offsets[i] * sm.stiffness;
        }
        return;
    }
    // For p ≠ 1 each particle's own scale (|d|/L)^(p−1) undoes the zero sum of the
    // offsets: take the net force back out, shared by mass, so the goal forces conserve
    // momentum (pinned particles take their share, so a pin still holds).
    let (mut net, mut mass) = (DVec3::ZERO, 0.0f64);
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
