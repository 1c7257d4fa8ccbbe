//! The hybrid patch model's step (Sladović 2014 §4): a lattice of parts (a small mass-spring
//! cloth of its own, `patches.rs`) takes its whole substep first, held by the pins; each
//! particle is then pulled toward its target on its part's frame, or (tiles) placed on
//! it.

use super::ModelSteps;
use crate::params::{Environment, PatchParams};
use crate::solver::parallel;
use crate::solver::patches::Patches;
use crate::solver::{ClothSolver, ModelState, pull_scale};

impl ModelSteps for PatchParams {
    /// Builds the part lattice when missing or built for another part size (from the
    /// particles' state, so a switch keeps the motion), follows the grab, and computes
    /// the targets when asked or just built.
    fn build(&self, cloth: &mut ClothSolver, compute: bool) {
        let key = self.lattice_key();
        let built = cloth.model.patches().is_none_or(|p| p.built_for != key);
        if built {
            cloth.model = ModelState::None;
            if let Some(patches) = build_lattice(cloth, self) {
                cloth.model = ModelState::Patches(Box::new(patches));
            }
        }
        let Some(patches) = cloth.model.patches_mut() else {
            return;
        };
        // A grabbed particle drags its part along (particles only follow parts).
        match cloth.drivers.grab {
            Some(g) => {
                let part = patches.part_of(g.particle) as u32;
                let offset = patches.parts.positions()[part as usize]
                    - cloth.particles.position[g.particle as usize];
                if patches.parts.grabbed().is_none_or(|pg| pg.particle != part) {
                    patches.parts.grab(part);
                }
                patches.parts.drag_grab(g.target + offset);
            }
            None => patches.parts.release_grab(),
        }
        if compute || built {
            patches.compute_targets(&cloth.particles.position, self);
        }
    }

    /// The lattice gets this step's parameters before its substeps are chosen.
    fn prepare(&self, cloth: &mut ClothSolver, dt: f32) {
        if let Some(patches) = cloth.model.patches_mut() {
            patches.set_params(&cloth.params, self, 1);
            patches.refresh_lattice_substeps(dt);
        }
    }

    fn begin(&self, cloth: &mut ClothSolver, dt: f32, ratio: Option<f32>) {
        cloth.rescale_verlet_velocity(ratio);
        let n = cloth.clock.substeps;
        if let Some(patches) = cloth.model.patches_mut() {
            patches.set_params(&cloth.params, self, n);
            patches.parts.set_frame(cloth.drivers.frame);
            patches.parts.begin_step(dt);
        }
    }

    /// External forces act on the part centres (one-way coupling); each particle's pull
    /// toward its target `α (|d|/L)^(p−1) d` is damped at `ratio · 2√(α m)` on its
    /// velocity relative to the target (damping the absolute velocity would be a drag
    /// the lattice never feels). With tiles the particles sit on their targets: no pull.
    fn forces(&self, cloth: &mut ClothSolver, env: &Environment) {
        let Some(patches) = cloth.model.patches_mut() else {
            return;
        };
        patches.parts.accumulate_forces(env);
        if self.tiles {
            return;
        }
        let (l, exponent) = (cloth.structure.length_scale, self.exponent);
        let p = &mut cloth.particles;
        let (targets, target_velocity) = (&patches.targets, &patches.target_velocity);
        let (x, v, mass) = (&p.position, &p.velocity, &p.mass);
        parallel::for_each_indexed(&mut p.force, |i, f| {
            let d = targets[i] - x[i];
            let scale = pull_scale(d.length(), l, exponent);
            let damping = self.particle_damping_ratio * 2.0 * (self.stiffness * mass[i]).sqrt();
            let relative = v[i] - target_velocity[i];
            *f = d * (self.stiffness * scale) - damping * relative;
        });
    }

    /// The part lattice takes its whole substep first, held by the pins at their place at
    /// the end of this substep; the particles follow (integrated; tiles: not at all).
    fn integrate(&self, cloth: &mut ClothSolver) {
        let h = cloth.clock.h;
        if let Some(patches) = cloth.model.patches_mut() {
            patches.parts.integrate();
            patches.parts.constrain();
            let t = cloth.clock.end_of_substep();
            let drivers = &cloth.drivers;
            patches.hold_parts(|k| drivers.pin_at(k, t), h);
            if self.tiles {
                return;
            }
        }
        // No drag on the particles: the lattice feels it (a drag here the lattice would
        // never feel, as the pull's damping is relative).
        cloth.integrate_particles(0.0);
    }

    /// Tiles (fig. 12): every free particle on its target. Otherwise the targets move
    /// with their parts, and a particle that is a part of its own is its part's centre.
    fn fit_targets(&self, cloth: &mut ClothSolver) {
        let Some(patches) = cloth.model.patches_mut() else {
            return;
        };
        let p = &mut cloth.particles;
        let h = cloth.clock.h;
        if self.tiles {
            patches.compute_targets(&p.position, self);
            for i in 0..p.position.len() {
                if p.inv_mass[i] != 0.0 {
                    p.move_to(i, patches.targets[i], h);
                }
            }
            return;
        }
        patches.advance_targets(&p.position, self, h);
        for i in 0..p.position.len() {
            if p.inv_mass[i] != 0.0 && patches.is_single(i) {
                let target = patches.targets[i];
                p.velocity[i] = (target - p.previous[i]) / h;
                p.position[i] = target;
            }
        }
    }

    /// A torn part spring splits the cloth between its two parts: the faces that
    /// straddle them are hidden (on tear events only).
    fn end(&self, cloth: &mut ClothSolver) {
        let Some(patches) = cloth.model.patches_mut() else {
            return;
        };
        patches.parts.end_step();
        let lattice = &patches.parts.structure.springs;
        let structure = &mut cloth.structure;
        for &k in patches.parts.last_torn() {
            let (a, b) = (
                lattice.a[k as usize] as usize,
                lattice.b[k as usize] as usize,
            );
            for (t, tri) in structure.triangles.iter().enumerate() {
                let parts = tri.map(|v| patches.part_of(v));
                if parts.contains(&a) && parts.contains(&b) {
                    structure.triangle_visible[t] = false;
                    structure.faces_changed = true;
                }
            }
        }
    }
}

/// A part lattice for the cloth's rest shape and pins, taking over the particles' motion
/// (`None` for a cloth that is not a grid).
fn build_lattice(cloth: &ClothSolver, patch: &PatchParams) -> Option<Patches> {
    let grid = cloth.structure.grid?;
    let pins = &cloth.drivers.pins;
    let frame = cloth.drivers.frame;
    let local = &cloth.structure.local_rest;
    let mut patches = Patches::new(local, grid, pins, &cloth.params, patch, frame).ok()?;
    let moved = cloth.clock.time > 0.0;
    patches.adopt_state(&cloth.particles, pins, cloth.clock.last_h, patch, moved);
    patches
        .parts
        .set_colliders(cloth.contact.colliders.iter().cloned());
    Some(patches)
}
