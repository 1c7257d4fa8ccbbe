//! What the solver reports about a cloth and does not need to step it: energies, strain,
//! stability, normals for drawing.

use bevy::math::Vec3;

use super::parallel;
use super::{ClothSolver, SpringKind, family_stiffness};
use crate::params::{Environment, SpringParams};

/// Energies of a cloth in J, for measurement (see [`ClothSolver::energy`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, bevy::reflect::Reflect)]
pub struct Energy {
    /// `Σ ½ m v²` over free particles.
    pub kinetic: f32,
    /// `Σ −m g·x` over free particles (zero at the world origin).
    pub gravitational: f32,
    /// `Σ ½ k (l − l0)²` over acting springs, and a fabric's bending energy.
    pub spring: f32,
}

impl Energy {
    /// Kinetic + gravitational + spring energy.
    pub fn total(&self) -> f32 {
        self.kinetic + self.gravitational + self.spring
    }
}

/// Stretch of the structural springs, `(l − l0)/l0`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Strain {
    /// The largest stretch (negative when every spring is compressed).
    pub max: f32,
    /// The mean of `|l − l0|/l0`.
    pub mean: f32,
}

impl ClothSolver {
    /// The failure test of the measurements (DESIGN.md): every position and velocity is
    /// finite and no structural spring is stretched past 100%.
    pub fn is_stable(&self) -> bool {
        self.is_finite() && self.strain().max <= 1.0
    }

    /// True when every position and velocity is finite.
    pub fn is_finite(&self) -> bool {
        self.particles.position.iter().all(|p| p.is_finite())
            && self.particles.velocity.iter().all(|v| v.is_finite())
    }

    /// Kinetic, gravitational and spring energy (with a fabric's bending) of the particles under `env`, the same
    /// quantity for every model: the springs count at the cloth's spring parameters
    /// (`params.springs`) whichever model moves the particles, so a shape-matched or
    /// patch cloth is measured as the same cloth a mass-spring run would be (its goal
    /// pull or part lattice is not counted).
    pub fn energy(&self, env: &Environment) -> Energy {
        let g = env.effective_gravity();
        let p = &self.particles;
        let mut e = Energy::default();
        for i in 0..p.len() {
            if p.inv_mass[i] > 0.0 {
                e.kinetic += 0.5 * p.mass[i] * p.velocity[i].length_squared();
                e.gravitational -= p.mass[i] * g.dot(p.position[i]);
            }
        }
        e.spring = self.spring_energy(&self.params.springs_in_use()) + self.bending_energy();
        e
    }

    /// A fabric's bending energy (the quadratic bending model, `bending.rs`); 0 without.
    fn bending_energy(&self) -> f32 {
        self.params.fabric.map_or(0.0, |f| {
            self.structure
                .hinges
                .energy(&self.particles.position, f.bending)
        })
    }

    /// `Σ ½ k (l − l0)²` over the whole springs, with each family's stiffness from
    /// `springs`; an inextensible family (XPBD's `k = inf`) stores none.
    fn spring_energy(&self, springs: &SpringParams) -> f32 {
        let x = &self.particles.position;
        let s = &self.structure.springs;
        let mut energy = 0.0;
        for kind in SpringKind::ALL {
            let k = family_stiffness(springs, kind);
            if k == 0.0 || k == f32::INFINITY {
                continue;
            }
            for i in s.ranges[kind as usize].clone() {
                if s.alive[i] {
                    let l = x[s.a[i] as usize].distance(x[s.b[i] as usize]);
                    energy += 0.5 * k * s.scale(i) * (l - s.rest_length[i]).powi(2);
                }
            }
        }
        energy
    }

    /// The centre and radius of a sphere around every particle (the centre of their
    /// bounding box and its half diagonal), for level of detail.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        super::contact::Bounds::around(&self.particles.position).sphere()
    }

    /// The largest speed of a free particle, m/s (0 for none): what a sleeping cloth's
    /// stillness is measured by.
    pub fn max_speed(&self) -> f32 {
        let p = &self.particles;
        let fastest = p
            .velocity
            .iter()
            .zip(&p.inv_mass)
            .filter(|(_, w)| **w > 0.0)
            .map(|(v, _)| v.length_squared())
            .fold(0.0f32, f32::max);
        fastest.sqrt()
    }

    /// Stretch of the whole structural springs.
    pub fn strain(&self) -> Strain {
        let x = &self.particles.position;
        let s = &self.structure.springs;
        let mut max = f32::NEG_INFINITY;
        let (mut sum, mut count) = (0.0f32, 0usize);
        for k in s.ranges[SpringKind::Structural as usize].clone() {
            if s.alive[k] {
                let l = x[s.a[k] as usize].distance(x[s.b[k] as usize]);
                let e = (l - s.rest_length[k]) / s.rest_length[k];
                max = max.max(e);
                sum += e.abs();
                count += 1;
            }
        }
        if count == 0 {
            return Strain::default();
        }
        Strain {
            max,
            mean: sum / count as f32,
        }
    }

    /// Smooth vertex normals (area-weighted over the visible triangles) into `out`, which
    /// must hold one entry per particle; in pieces over the compute pool for a large
    /// cloth (whose tasks are the only allocation).
    pub fn normals_into(&self, out: &mut [Vec3]) {
        let x = &self.particles.position;
        // On one thread each triangle is scattered onto its corners; over the pool each
        // particle gathers its own triangles (written by one piece only). Both add in
        // increasing triangle order: the same sums, to the bit.
        if parallel::on_this_thread(parallel::PARALLEL_FROM, out.len()) {
            self.structure.normal_sums_into(x, out);
            super::unit::normalize_each_or(out, Vec3::Z);
            return;
        }
        parallel::for_each_indexed(out, |i, n| {
            *n = self.structure.normal_sum(x, i).normalize_or(Vec3::Z);
        });
    }
}
