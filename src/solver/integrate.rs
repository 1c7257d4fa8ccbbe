//! Stage 2 of a substep, the integrators the models share: Störmer–Verlet and
//! semi-implicit (symplectic) Euler, piece by piece over the compute pool.

use super::parallel;
use super::state::ParticleChunk;
use super::{ClothSolver, Particles};
use crate::params::Integrator;

impl ClothSolver {
    /// Advances every free particle by one substep `h` from its force, by the
    /// integrator the parameters choose, with linear drag `drag` (N·s/m per particle,
    /// scaled by its represents) taken implicitly.
    pub(super) fn integrate_particles(&mut self, drag: f32) {
        let h = self.clock.h;
        match self.params.integrator {
            Integrator::Verlet => verlet(&mut self.particles, h, drag),
            Integrator::SemiImplicitEuler => {
                symplectic_euler::<false>(&mut self.particles, h, drag)
            }
        }
    }

    /// Keeps Verlet's implicit velocity `(x − x_prev)/h` when `h` changes by `ratio`.
    pub(super) fn rescale_verlet_velocity(&mut self, ratio: Option<f32>) {
        let Some(ratio) = ratio else {
            return;
        };
        if self.params.integrator != Integrator::Verlet {
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

/// The factor implicit linear drag scales a substep's new velocity by: `v' = (v + h a) /
/// (1 + h c/m)`, the backward-Euler step of `m dv/dt = F − c v`. It lies in (0, 1] for
/// any drag, mass and step (explicit `v' = v + h (a − c v/m)` diverges once `h c/m > 2`:
/// at Maslova's lightest material, 0.001 g, with 0.005 N·s/m drag, from h = 0.4 ms).
#[inline]
fn drag_factor(h: f32, drag: f32, represents: f32, inv_mass: f32) -> f32 {
    1.0 / (1.0 + h * drag * represents * inv_mass)
}

/// One Verlet substep of every free particle, in pieces over the compute pool, with
/// implicit drag.
pub(super) fn verlet(p: &mut Particles, h: f32, drag: f32) {
    let (n, h2) = (p.len(), h * h);
    // Maslova eq. 1.12 prints `+ a Δt²/2`; substituting eq. 1.10 into 1.9
    // drops the `x_{n−1}` Taylor term, and the correct Störmer–Verlet step is
    // `x' = 2x − x_prev + a Δt²` (with the ½, free fall would reach only g t²/4).
    // Written as `x' = x + ((x − x_prev) + a Δt²)` with compensated summation:
    // in `f32` a displacement under half the spacing of floats at `x` is lost
    // when added, and the plain form then recomputes `x − x_prev = 0`: at 512
    // substeps of 16 ms a curtain at y = 2 m never started to fall (g Δt² = 1e-8
    // m against 1.2e-7 m). What rounding drops is carried to the next substep.
    let kernel = |ParticleChunk {
                      position,
                      previous,
                      residue,
                      velocity,
                      force,
                      inv_mass,
                      represents,
                      ..
                  }| {
        let n = position.len();
        let (x, previous, residue) = (&mut position[..n], &mut previous[..n], &mut residue[..n]);
        let (v, f, w, represents) = (
            &mut velocity[..n],
            &force[..n],
            &inv_mass[..n],
            &represents[..n],
        );
        for i in 0..n {
            if w[i] == 0.0 {
                continue;
            }
            // `h v' = (h v + h² a) / (1 + h c/m)`, Verlet's `h v` being `x − x_prev`.
            let step = ((x[i] - previous[i]) + residue[i] + f[i] * (w[i] * h2))
                * drag_factor(h, drag, represents[i], w[i]);
            let next = x[i] + step;
            residue[i] = step - (next - x[i]);
            previous[i] = x[i];
            x[i] = next;
            v[i] = step / h;
        }
    };
    parallel::for_each(n, p.chunks(), kernel);
}

/// `x + r += delta`, keeping in `r` what rounding `x` lost (Kahan's compensated sum;
/// Fast2Sum, exact while `|x| ≥ |delta + r|`), for a position or one coordinate of it.
#[inline(always)]
pub(super) fn compensated_add<T>(x: &mut T, r: &mut T, delta: T)
where
    T: Copy + std::ops::Add<Output = T> + std::ops::Sub<Output = T>,
{
    let t = delta + *r;
    let s = *x + t;
    *r = t - (s - *x);
    *x = s;
}

/// One symplectic Euler substep of every free particle, in pieces over the compute pool,
/// with implicit drag. `COMPENSATED`: the position's step `h v` is added with what
/// rounding lost kept in the residue (as Verlet's), so a step far below a float spacing
/// of the position still moves it over many substeps.
pub(crate) fn symplectic_euler<const COMPENSATED: bool>(p: &mut Particles, h: f32, drag: f32) {
    let n = p.len();
    // Sladović 2014 eq. 21–22: the new velocity first, then the position from it.
    let kernel = |ParticleChunk {
                      position,
                      previous,
                      velocity,
                      residue,
                      force,
                      inv_mass,
                      represents,
                      ..
                  }| {
        let n = position.len();
        let (x, previous, v) = (&mut position[..n], &mut previous[..n], &mut velocity[..n]);
        let (f, w, represents, residue) = (
            &force[..n],
            &inv_mass[..n],
            &represents[..n],
            &mut residue[..n],
        );
        for i in 0..n {
            if w[i] == 0.0 {
                continue;
            }
            v[i] = (v[i] + f[i] * (w[i] * h)) * drag_factor(h, drag, represents[i], w[i]);
            previous[i] = x[i];
            if COMPENSATED {
                compensated_add(&mut x[i], &mut residue[i], v[i] * h);
            } else {
                x[i] += v[i] * h;
            }
        }
    };
    parallel::for_each(n, p.chunks(), kernel);
}

#[cfg(test)]
mod tests {
    use bevy::math::Vec3;

    use super::*;

    /// One particle under a constant force: Verlet's step is `x' = 2x − x_prev + a h²`
    /// (Maslova eq. 1.9–1.10, corrected, see [`verlet`]) with `v = (x' − x)/h`;
    /// symplectic Euler's `v' = v + a h`, `x' = x + v' h` (Sladović 2014 eq. 21–22). A pinned
    /// particle (`1/m = 0`) stays.
    #[test]
    fn one_particle_steps_as_the_integrators_formulas() {
        let (h, a) = (0.01f32, Vec3::new(0.0, -9.81, 2.0));
        let start = |p: &mut Particles| {
            p.position = vec![Vec3::new(1.0, 2.0, 3.0), Vec3::ONE];
            p.previous = vec![Vec3::new(0.99, 2.01, 3.0), Vec3::ONE];
            p.velocity = vec![Vec3::new(1.0, -1.0, 0.0), Vec3::ZERO];
            p.mass = vec![0.5, 0.5];
            p.inv_mass = vec![2.0, 0.0];
            p.force = vec![a * 0.5, a * 0.5];
        };
        let mut p = Particles::with_len(2);
        start(&mut p);
        verlet(&mut p, h, 0.0);
        let expected = 2.0 * Vec3::new(1.0, 2.0, 3.0) - Vec3::new(0.99, 2.01, 3.0) + a * h * h;
        assert!(p.position[0].distance(expected) < 1e-6, "{}", p.position[0]);
        let v = (p.position[0] - Vec3::new(1.0, 2.0, 3.0)) / h;
        assert!(p.velocity[0].distance(v) < 1e-3);
        assert_eq!(p.position[1], Vec3::ONE);

        start(&mut p);
        symplectic_euler::<false>(&mut p, h, 0.0);
        let v = Vec3::new(1.0, -1.0, 0.0) + a * h;
        assert!(p.velocity[0].distance(v) < 1e-6);
        assert!(p.position[0].distance(Vec3::new(1.0, 2.0, 3.0) + v * h) < 1e-6);
        assert_eq!((p.position[1], p.velocity[1]), (Vec3::ONE, Vec3::ZERO));
    }
}
