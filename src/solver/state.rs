//! Particle state as structure-of-arrays.

use bevy::math::Vec3;

/// Every particle's state, one array per quantity (structure-of-arrays).
#[derive(Clone, Debug, Default)]
pub struct Particles {
    /// Position `x` in world space, m.
    pub position: Vec<Vec3>,
    /// Position at the start of the last substep (Verlet's `x_{n−1}`).
    pub previous: Vec<Vec3>,
    /// Velocity `v` in m/s (integrated by Euler, `(x − x_prev)/h` for Verlet).
    pub velocity: Vec<Vec3>,
    /// The part of Verlet's last displacement that rounding the position lost, carried
    /// into the next one (compensated summation); zero for Euler.
    pub residue: Vec<Vec3>,
    /// Mass `m` in kg (kept for pinned particles too, for energies and centres of mass).
    pub mass: Vec<f32>,
    /// `1/m`, or 0 for a pinned particle.
    pub inv_mass: Vec<f32>,
    /// Force accumulated in the current substep, N.
    pub force: Vec<Vec3>,
    /// How many particles' worth each node is (1 for a particle; a part centre of the
    /// patch model counts its particles): scales mass, wind and drag.
    pub represents: Vec<f32>,
}

impl Particles {
    /// `n` particles at the origin.
    pub fn with_len(n: usize) -> Self {
        Self {
            position: vec![Vec3::ZERO; n],
            previous: vec![Vec3::ZERO; n],
            velocity: vec![Vec3::ZERO; n],
            residue: vec![Vec3::ZERO; n],
            mass: vec![0.0; n],
            inv_mass: vec![0.0; n],
            force: vec![Vec3::ZERO; n],
            represents: vec![1.0; n],
        }
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Moves particle `i` to `target` kinematically over a substep of `h`: the velocity
    /// that takes it there, and the previous position where it was.
    #[inline]
    pub fn move_to(&mut self, i: usize, target: Vec3, h: f32) {
        self.previous[i] = self.position[i];
        self.velocity[i] = (target - self.position[i]) / h;
        self.position[i] = target;
    }

    /// True when particle `i` is pinned.
    pub fn is_pinned(&self, i: usize) -> bool {
        self.inv_mass[i] == 0.0
    }
}

/// One piece of [`Particles`]' lanes (up to [`CHUNK`](super::parallel::CHUNK) particles
/// from the same start), named, for the kernels that run piece by piece.
pub(super) struct ParticleChunk<'a> {
    pub position: &'a mut [Vec3],
    pub previous: &'a mut [Vec3],
    pub velocity: &'a mut [Vec3],
    pub residue: &'a mut [Vec3],
    pub force: &'a mut [Vec3],
    pub mass: &'a [f32],
    pub inv_mass: &'a [f32],
    pub represents: &'a [f32],
}

impl Particles {
    /// The lanes cut into chunks of [`CHUNK`](super::parallel::CHUNK) particles, each
    /// piece's lanes under their names.
    pub(super) fn chunks(&mut self) -> impl Iterator<Item = ParticleChunk<'_>> {
        use super::parallel::CHUNK;
        let moving = self
            .position
            .chunks_mut(CHUNK)
            .zip(self.previous.chunks_mut(CHUNK))
            .zip(self.velocity.chunks_mut(CHUNK))
            .zip(self.residue.chunks_mut(CHUNK))
            .zip(self.force.chunks_mut(CHUNK));
        let fixed = self
            .mass
            .chunks(CHUNK)
            .zip(self.inv_mass.chunks(CHUNK))
            .zip(self.represents.chunks(CHUNK));
        moving.zip(fixed).map(
            |(
                ((((position, previous), velocity), residue), force),
                ((mass, inv_mass), represents),
            )| {
                ParticleChunk {
                    position,
                    previous,
                    velocity,
                    residue,
                    force,
                    mass,
                    inv_mass,
                    represents,
                }
            },
        )
    }
}

/// Marks particle `i` as moved by contact or self-collision (a slice shorter than the cloth, from stages
/// called by hand before any step began, marks nothing).
pub(in crate::solver) fn mark(touched: &mut [bool], i: usize) {
    if let Some(t) = touched.get_mut(i) {
        *t = true;
    }
}
