//! The bare kernel every model is compared with: a grid cloth as plain arrays, one lane
//! per coordinate, structural + shear + bend springs as stencil offsets, position Verlet,
//! gravity, the top row pinned; nothing else (no damping, wind, limiter, colliders,
//! tearing, sewing or bookkeeping), one core. Its cost per particle-substep is the floor
//! the bench's ratios are measured against, in the same run.

use std::time::Instant;

use crate::grid_for;
use bevy_cloth::lab::median;

/// A grid cloth reduced to the arithmetic of one mass-spring substep.
pub struct BareGrid {
    width: usize,
    /// Position lanes (x, y, z), previous positions, forces.
    x: [Vec<f32>; 3],
    previous: [Vec<f32>; 3],
    force: [Vec<f32>; 3],
    /// `h² / m` for a free particle, 0 for a pinned one (the top row).
    step_scale: Vec<f32>,
    /// Per stencil offset: (column offset, row offset, stiffness, rest length).
    stencil: Vec<(isize, usize, f32, f32)>,
    /// Per stencil offset, 1 where the spring from particle `i` exists, else 0.
    masks: Vec<Vec<f32>>,
    /// One spring's force per pair, reused.
    scratch: [Vec<f32>; 3],
    gravity: f32,
}

impl BareGrid {
    /// `count` particles (as the bench's curtain, [`grid_for`]), `spacing` m apart, of
    /// `mass` kg, springs of `k` N/m (structural; shear and bend at half, Sladović's (2014) 2:1:1).
    pub fn new(count: usize, spacing: f32, mass: f32, k: f32) -> Self {
        let (width, height) = grid_for(count);
        let (width, height) = (width as usize, height as usize);
        let n = width * height;
        let mut x = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        for j in 0..height {
            for i in 0..width {
                x[0][j * width + i] = i as f32 * spacing;
                x[1][j * width + i] = -(j as f32) * spacing;
            }
        }
        let diagonal = spacing * std::f32::consts::SQRT_2;
        let stencil = vec![
            (1, 0, k, spacing),
            (0, 1, k, spacing),
            (1, 1, k / 2.0, diagonal),
            (-1, 1, k / 2.0, diagonal),
            (2, 0, k / 2.0, 2.0 * spacing),
            (0, 2, k / 2.0, 2.0 * spacing),
        ];
        let masks = stencil
            .iter()
            .map(|&(dx, dy, _, _)| {
                (0..n)
                    .map(|p| {
                        let (i, j) = ((p % width) as isize, p / width);
                        let inside = (0..width as isize).contains(&(i + dx)) && j + dy < height;
                        f32::from(u8::from(inside))
                    })
                    .collect()
            })
            .collect();
        let h = 0.016 / 8.0;
        let step_scale = (0..n)
            .map(|p| if p < width { 0.0 } else { h * h / mass })
            .collect();
        Self {
            width,
            previous: x.clone(),
            x,
            force: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            step_scale,
            stencil,
            masks,
            scratch: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            gravity: -9.81 * mass,
        }
    }

    /// Particles.
    pub fn len(&self) -> usize {
        self.x[0].len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// One substep of 2 ms (the default curtain's 16 ms / 8): forces, then Verlet.
    pub fn substep(&mut self) {
        let n = self.len();
        self.force[0].fill(0.0);
        self.force[1].fill(self.gravity);
        self.force[2].fill(0.0);
        for (s, &(dx, dy, k, rest)) in self.stencil.iter().enumerate() {
            // Pairs (p, p + offset): p from `first` on; the mask zeroes pairs that wrap.
            let offset = dy * self.width;
            let first = if dx < 0 { dx.unsigned_abs() } else { 0 };
            let offset = (offset as isize + dx) as usize;
            let pairs = n - offset - first;
            let [sx, sy, sz] = &mut self.scratch;
            let (a, b) = (first..first + pairs, first + offset..n);
            let [x, y, z] = &self.x;
            for (((((fx, fy), fz), m), (xa, xb)), ((ya, yb), (za, zb))) in sx[..pairs]
                .iter_mut()
                .zip(&mut sy[..pairs])
                .zip(&mut sz[..pairs])
                .zip(&self.masks[s][a.clone()])
                .zip(x[a.clone()].iter().zip(&x[b.clone()]))
                .zip(
                    y[a.clone()]
                        .iter()
                        .zip(&y[b.clone()])
                        .zip(z[a.clone()].iter().zip(&z[b.clone()])),
                )
            {
                let (ddx, ddy, ddz) = (xb - xa, yb - ya, zb - za);
                let len = (ddx * ddx + ddy * ddy + ddz * ddz).sqrt();
                let scale = m * k * (len - rest) / len.max(f32::MIN_POSITIVE);
                *fx = ddx * scale;
                *fy = ddy * scale;
                *fz = ddz * scale;
            }
            for (lane, scratch) in self.force.iter_mut().zip(&self.scratch) {
                for (f, s) in lane[a.clone()].iter_mut().zip(&scratch[..pairs]) {
                    *f += s;
                }
                for (f, s) in lane[b.clone()].iter_mut().zip(&scratch[..pairs]) {
                    *f -= s;
                }
            }
        }
        for ((x, previous), force) in self.x.iter_mut().zip(&mut self.previous).zip(&self.force) {
            for (((x, previous), f), w) in x
                .iter_mut()
                .zip(previous.iter_mut())
                .zip(force)
                .zip(&self.step_scale)
            {
                let next = *x + (*x - *previous) * f32::from(u8::from(*w != 0.0)) + f * w;
                *previous = *x;
                *x = next;
            }
        }
    }

    /// The lowest point, m (a check that the kernel does move the cloth).
    pub fn lowest(&self) -> f32 {
        self.x[1].iter().copied().fold(f32::INFINITY, f32::min)
    }
}

/// The bare kernel's median ns per particle-substep on a `count`-particle grid: `repeats`
/// timings of 8 substeps each (one 16 ms step of the default curtain), after a warm-up.
pub fn ns_per_particle_substep(count: usize, repeats: usize) -> f64 {
    let params = bevy_cloth::params::ClothParams::seeds();
    let k = params.springs.structural.stiffness;
    let mut grid = BareGrid::new(count, 0.05, params.node_mass, k);
    for _ in 0..8 {
        grid.substep();
    }
    let mut times: Vec<f64> = (0..repeats.max(1))
        .map(|_| {
            let start = Instant::now();
            for _ in 0..8 {
                grid.substep();
            }
            start.elapsed().as_secs_f64() * 1e9 / (8 * count) as f64
        })
        .collect();
    median(&mut times)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The kernel is a cloth: it falls under gravity from its pinned top row and stays
    /// finite, and a particle in free fall for one substep moves `g h²`.
    #[test]
    fn the_bare_kernel_hangs_from_its_top_row() {
        let mut grid = BareGrid::new(64, 0.05, 0.001, 20.0);
        let start = grid.lowest();
        grid.substep();
        let h = 0.016 / 8.0;
        assert!((start - grid.lowest() - 9.81 * h * h).abs() < 1e-7);
        for _ in 0..800 {
            grid.substep();
        }
        assert!(grid.lowest().is_finite() && grid.lowest() < start);
        assert!(
            grid.x[1][..8].iter().all(|&y| y == 0.0),
            "the top row holds"
        );
    }
}
