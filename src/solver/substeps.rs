//! The substep rule of the explicit models: how many substeps keep a step stable (the
//! bound of each model: springs, shape-matching goals, the patch pull and its lattice),
//! and the one cache that spares recomputing it while nothing it depends on changes.

use bevy::math::Vec3;

use super::patches::Patches;
use super::shape_matching::ShapeMatching;
use super::{ClothSolver, ModelState, SpringKind, pull_scale};
use crate::params::{ClothParams, GoalUpdate, Model, PatchParams, ShapeMatchingParams, Substeps};

/// Automatic substeps remembered for (the parameters but their substep setting, dt).
/// Tearing only removes stiffness, so a cached count stays stable after a tear and the
/// step never recomputes (or allocates) for it. The part lattice of the patch model, a
/// cloth itself, uses its own.
#[derive(Clone, Debug, Default)]
pub(super) struct SubstepCache(Option<(ClothParams, f32, u32)>);

impl SubstepCache {
    /// The parameters as the bound sees them: the substep setting is what the bound
    /// decides, not what it depends on.
    fn key(params: &ClothParams) -> ClothParams {
        ClothParams {
            substeps: Substeps::Fixed(1),
            ..*params
        }
    }

    pub(super) fn get(&self, params: &ClothParams, dt: f32) -> Option<u32> {
        match self.0 {
            Some((p, d, n)) if p == Self::key(params) && d == dt => Some(n),
            _ => None,
        }
    }

    pub(super) fn set(&mut self, params: &ClothParams, dt: f32, n: u32) {
        self.0 = Some((Self::key(params), dt, n));
    }
}

impl ClothSolver {
    /// The stable substeps for `dt` from the cache, computed and remembered when the
    /// parameters or `dt` changed.
    pub(super) fn refresh_substep_cache(&mut self, dt: f32) -> u32 {
        if let Some(n) = self.clock.substep_cache.get(&self.params, dt) {
            return n;
        }
        let n = self.stable_substeps(dt);
        self.clock.substep_cache = SubstepCache(Some((SubstepCache::key(&self.params), dt, n)));
        n
    }

    /// The stable substeps for `dt`: the cached value when it is current, otherwise
    /// computed now.
    pub(super) fn cached_substeps(&self, dt: f32) -> u32 {
        self.clock
            .substep_cache
            .get(&self.params, dt)
            .unwrap_or_else(|| self.stable_substeps(dt))
    }

    /// The number of substeps that keeps an explicit step of `dt` stable for this cloth.
    ///
    /// Symplectic Euler (and Verlet, the same recurrence) on `x'' = −ω² x − γ x'` is stable
    /// while `h²ω² + 2hγ < 4` (Jury's test on its 2×2 update matrix); with no damping this
    /// is the lattice bound `ω_max·h < 2`. For springs, ω_max and the damping rate γ are
    /// estimated by power iteration with a margin, capped by Gershgorin's bounds (which
    /// overestimate ω_max of a grid by ~1.4×, so they cost ~1.4× the substeps). A safety
    /// factor of 0.8 on the right-hand side covers the geometric stiffness of stretched
    /// springs.
    ///
    /// XPBD is stable at any substep count; its automatic substeps follow its accuracy
    /// target instead (`xpbd_substeps`).
    pub fn stable_substeps(&self, dt: f32) -> u32 {
        let (omega2, gamma) = match (&self.params.model, &self.model) {
            (Model::Xpbd(xpbd), _) => return self.xpbd_substeps(dt, xpbd.max_stretch_error),
            (Model::ShapeMatching(sm), ModelState::ShapeMatching(state)) => {
                self.goal_frequency(sm, state)
            }
            (Model::Patches(patch), ModelState::Patches(patches)) => {
                let lattice = patches.lattice_substeps(dt);
                if patch.tiles {
                    return lattice; // no pull to resolve
                }
                let pull = self.pull_frequency(patch, patches);
                return substeps_for(dt, pull.0, pull.1).max(lattice);
            }
            _ => self.spring_frequency(),
        };
        substeps_for(dt, omega2, gamma)
    }

    /// The stretch a family's springs may take: 0 when inextensible, the strain limit when
    /// limited (structural and shear), `None` when neither (or switched off).
    pub(super) fn family_bound(&self, kind: SpringKind) -> Option<f32> {
        let k = super::family_stiffness(&self.params.springs_in_use(), kind);
        let limited = matches!(kind, SpringKind::Structural | SpringKind::Shear);
        match (k > 0.0, k == f32::INFINITY) {
            (false, _) => None,
            (true, true) => Some(0.0),
            (true, false) => self.params.strain_limit.filter(|_| limited),
        }
    }

    /// The largest stretch `(l − l0)/l0` of a whole structural spring with a free end (0
    /// when none is stretched).
    pub(super) fn structural_strain(&self) -> f32 {
        let (x, w) = (&self.particles.position, &self.particles.inv_mass);
        let s = &self.structure.springs;
        let mut worst = 0.0f32;
        for k in s.ranges[SpringKind::Structural as usize].clone() {
            let (a, b) = (s.a[k] as usize, s.b[k] as usize);
            if s.alive[k] && w[a] + w[b] > 0.0 {
                let stretch = x[a].distance(x[b]) / s.rest_length[k] - 1.0;
                // A NaN (a broken state) is no stretch here; `is_stable` reports it.
                worst = worst.max(stretch);
            }
        }
        worst
    }

    /// [`Self::structural_strain`] over the springs none of whose ends self-collision or
    /// contact moved in the step in progress.
    pub(super) fn untouched_structural_strain(&self) -> f32 {
        let (x, w) = (&self.particles.position, &self.particles.inv_mass);
        let s = &self.structure.springs;
        let touched = |i: usize| self.touched.get(i).copied().unwrap_or(false);
        let mut worst = 0.0f32;
        for k in s.ranges[SpringKind::Structural as usize].clone() {
            let (a, b) = (s.a[k] as usize, s.b[k] as usize);
            if s.alive[k] && w[a] + w[b] > 0.0 && !touched(a) && !touched(b) {
                worst = worst.max(x[a].distance(x[b]) / s.rest_length[k] - 1.0);
            }
        }
        worst
    }

    /// True when the explicit bound depends on the current deformation.
    pub(super) fn state_dependent_stiffness(&self) -> bool {
        match self.params.model {
            Model::ShapeMatching(_) => true,
            Model::Patches(p) => p.exponent != 1.0 && !p.tiles,
            Model::MassSpring | Model::Xpbd(_) => false,
        }
    }

    /// `(ω², γ)` of the patch model's pull toward the targets, damped at
    /// `ratio · 2√(α m)`.
    fn pull_frequency(&self, patch: &PatchParams, patches: &Patches) -> (f32, f32) {
        let omega2 = self.pull_omega2(&patches.targets, patch.stiffness, patch.exponent);
        let gamma = patch.particle_damping_ratio
            * 2.0
            * (patch.stiffness * self.max_free_inv_mass()).sqrt();
        (omega2, gamma)
    }

    /// ω² bound of a pull `α (d/L)^(p−1) d` toward `targets` over a step: its stiffness
    /// along `d` is `p α (d/L)^(p−1)` and across `d` it is `α (d/L)^(p−1)`, so the larger
    /// of the two is `max(p, 1) α (d/L)^(p−1)` ([`pull_stiffness`]). The bound must hold
    /// wherever the particle goes within the step, not only where it is now: for p < 1
    /// the stiffness peaks at the goal (inside the clamp), which a particle far from it
    /// now may pass, so that peak is used; for p > 1 it grows with `d`, so `d` is taken
    /// as far as the particle's kinetic energy could carry it against the pull
    /// ([`pull_reach`]). The target moves with the particle (centre of mass, rotation,
    /// interpolation), bounded by a factor 2. Over the free particles. (The cloth
    /// stability map's nonlinear regimes found the bound from the current `d` too loose:
    /// most failures of a crumpled cloth at p = 0.5 and 3 went away at 4× the substeps.)
    fn pull_omega2(&self, targets: &[Vec3], stiffness: f32, exponent: f32) -> f32 {
        let p = &self.particles;
        let l = self.structure.length_scale;
        (0..p.len())
            .filter(|&i| p.inv_mass[i] > 0.0)
            .map(|i| {
                // p ≤ 1: the peak at the goal (p = 1: the same stiffness everywhere).
                let d = if exponent > 1.0 {
                    let energy = 0.5 * p.mass[i] * p.velocity[i].length_squared();
                    let now = targets[i].distance(p.position[i]);
                    pull_reach(now, energy, stiffness, l, exponent)
                } else {
                    0.0
                };
                2.0 * stiffness * pull_stiffness(d, l, exponent) * p.inv_mass[i]
            })
            .fold(0.0, f32::max)
    }

    /// The largest inverse mass of a free particle.
    fn max_free_inv_mass(&self) -> f32 {
        self.particles.inv_mass.iter().copied().fold(0.0, f32::max)
    }

    /// `(ω_max², γ_max)` of the spring lattice for the automatic substeps: the power
    /// iteration's estimates ([`Self::lattice_eigenvalue`], [`POWER_ITERATIONS`]) at the
    /// current shape times [`POWER_MARGIN`], never above Gershgorin's bounds. Drag adds
    /// at most its largest rate to γ.
    ///
    /// Grids and meshes; a garment's springs keep Gershgorin's bounds, as the seams
    /// closing while it is sewn turn its springs far from where an estimate was taken.
    /// With the estimate the T-shirt failed `the_seed_material_range_stays_stable_on_the_mannequin`:
    /// the stiffest material gained energy, and with seams counted as springs of length 0
    /// (`c I`, see [`Self::lattice_eigenvalue`]) the lightest, softest one went unstable.
    /// A mesh without seams is a lattice as a grid is, and Gershgorin's bound overstates
    /// its need: the crowd's skirt (a 32 × 12 cone) took 8 substeps by the bound, 7 by
    /// the estimate, where the crowd's 16 × 24 cape takes 6.
    ///
    /// A fabric's bending adds Gershgorin's bound of its hinges ([`Self::bending_gershgorin`]):
    /// the largest eigenvalue of a sum is at most the sum of the largest.
    fn spring_frequency(&self) -> (f32, f32) {
        let (omega2_bound, gamma_bound) = self.spring_gershgorin();
        let bending = self.bending_gershgorin();
        let seams = &self.structure.springs.ranges[SpringKind::Seam as usize];
        if !seams.is_empty() {
            return (omega2_bound + bending, gamma_bound);
        }
        let damping = self.params.springs.damping;
        let omega2 = self.lattice_eigenvalue(|kind| self.stiffness(kind), true, POWER_ITERATIONS);
        let spring_gamma = self.lattice_eigenvalue(
            |kind| {
                if self.stiffness(kind) > 0.0 {
                    damping
                } else {
                    0.0
                }
            },
            false,
            POWER_ITERATIONS,
        );
        // (Drag is implicit, `integrate.rs`: it bounds no step.)
        (
            (omega2 * POWER_MARGIN).min(omega2_bound) + bending,
            (spring_gamma * POWER_MARGIN).min(gamma_bound),
        )
    }

    /// Gershgorin's bound on `ω_max²` of a fabric's bending hinges, `max_i 2 B Σ_h |K_i| Σ|K| /
    /// ((A0 + A1) m_i)` (0 without a fabric).
    fn bending_gershgorin(&self) -> f32 {
        let Some(fabric) = self.params.fabric else {
            return 0.0;
        };
        let mut rows = vec![0.0f32; self.particles.len()];
        self.structure.hinges.add_gershgorin_rows(&mut rows);
        rows.iter()
            .zip(&self.particles.inv_mass)
            .fold(0.0f32, |most, (row, w)| {
                most.max(2.0 * fabric.bending * row * w)
            })
    }

    /// Gershgorin bounds `(ω_max², γ_max)` of the spring lattice:
    /// `ω_max² ≤ max_i 2·Σ_j k_ij / m_i`, `γ ≤ max_i 2·Σ_j c_ij / m_i` (the drag is
    /// implicit).
    fn spring_gershgorin(&self) -> (f32, f32) {
        let n = self.particles.len();
        let mut k_sum = vec![0.0f32; n];
        let mut c_sum = vec![0.0f32; n];
        let damping = self.params.springs.damping;
        for kind in SpringKind::ALL {
            let k = self.stiffness(kind);
            let c = if k > 0.0 { damping } else { 0.0 };
            if k == 0.0 && c == 0.0 {
                continue;
            }
            for s in self.structure.springs.ranges[kind as usize].clone() {
                if self.structure.springs.alive[s] {
                    for p in [self.structure.springs.a[s], self.structure.springs.b[s]] {
                        k_sum[p as usize] += k * self.structure.springs.scale(s);
                        c_sum[p as usize] += c;
                    }
                }
            }
        }
        let (mut omega2, mut gamma) = (0.0f32, 0.0f32);
        for i in 0..n {
            let w = self.particles.inv_mass[i];
            omega2 = omega2.max(2.0 * k_sum[i] * w);
            gamma = gamma.max(2.0 * c_sum[i] * w);
        }
        (omega2, gamma)
    }

    /// The largest eigenvalue of `M⁻¹A` for the spring lattice linearised at its current
    /// shape, with `c_s` = `coefficient(family)` × the spring's factor. With `transverse`
    /// (stiffness: ω_max²) `A` is each spring's Hessian `c_s [d̂ d̂ᵀ + t (I − d̂ d̂ᵀ)]`,
    /// `t = max(0, 1 − l0/l)` (0 at rest length; a stretched spring resists sideways too;
    /// a seam, sewn to length 0, is `c_s I` whatever its direction); without it (damping
    /// along the spring: γ_max) `c_s d̂ d̂ᵀ`. Power iteration on the symmetric
    /// `M^−½ A M^−½` from a fixed pseudo-random start, read as a Rayleigh quotient: never
    /// above the true value, and within a few per cent of it after 30 iterations on a grid
    /// (test `the_power_iteration_finds_the_lattice_eigenvalue`).
    pub fn lattice_eigenvalue(
        &self,
        coefficient: impl Fn(SpringKind) -> f32,
        transverse: bool,
        iterations: u32,
    ) -> f32 {
        let p = &self.particles;
        let n = p.len();
        let root_w: Vec<f32> = p.inv_mass.iter().map(|w| w.sqrt()).collect();
        let springs = self.linearised_springs(coefficient, transverse);
        let mut u: Vec<Vec3> = (0..n)
            .map(|i| {
                Vec3::new(unit_hash(i, 0), unit_hash(i, 1), unit_hash(i, 2)) * root_w[i].signum()
            })
            .collect();
        let mut y = vec![Vec3::ZERO; n];
        let mut lambda = 0.0f64;
        for _ in 0..iterations {
            let norm = u
                .iter()
                .map(|v| v.as_dvec3().length_squared())
                .sum::<f64>()
                .sqrt();
            if norm == 0.0 {
                return 0.0;
            }
            u.iter_mut()
                .for_each(|v| *v = (v.as_dvec3() / norm).as_vec3());
            // y = M^−½ A M^−½ u
            y.fill(Vec3::ZERO);
            for &(a, b, d, c, t) in &springs {
                let r = u[b] * root_w[b] - u[a] * root_w[a];
                let f = (d * ((1.0 - t) * d.dot(r)) + r * t) * c;
                y[a] -= f;
                y[b] += f;
            }
            for (y, w) in y.iter_mut().zip(&root_w) {
                *y *= *w;
            }
            lambda = u.iter().zip(&y).map(|(u, y)| f64::from(u.dot(*y))).sum();
            std::mem::swap(&mut u, &mut y);
        }
        lambda.max(0.0) as f32
    }

    /// Each whole spring of a family with `coefficient(family) > 0` linearised at the
    /// current shape for [`Self::lattice_eigenvalue`]: its ends, direction, `c_s` and
    /// transverse share `t`.
    fn linearised_springs(
        &self,
        coefficient: impl Fn(SpringKind) -> f32,
        transverse: bool,
    ) -> Vec<(usize, usize, Vec3, f32, f32)> {
        let (p, s) = (&self.particles, &self.structure.springs);
        SpringKind::ALL
            .into_iter()
            .map(|kind| (kind, coefficient(kind)))
            .filter(|&(_, c)| c > 0.0)
            .flat_map(|(kind, c)| s.ranges[kind as usize].clone().map(move |i| (i, kind, c)))
            .filter(|&(i, _, _)| s.alive[i])
            .map(|(i, kind, c)| {
                let (a, b) = (s.a[i] as usize, s.b[i] as usize);
                let d = p.position[b] - p.position[a];
                let len = d.length();
                let t = match (transverse, kind) {
                    (false, _) => 0.0,
                    (true, SpringKind::Seam) => 1.0,
                    (true, _) if len > 0.0 => (1.0 - s.rest_length[i] / len).clamp(0.0, 1.0),
                    (true, _) => 0.0,
                };
                (a, b, d.normalize_or_zero(), c * s.scale(i), t)
            })
            .collect()
    }

    /// `(ω_max², γ_max)` of shape matching's goal force at the current deformation (see
    /// `pull_omega2`). Müller's velocity update cannot overshoot: only the goal damping
    /// bounds its step (the drag is implicit).
    fn goal_frequency(&self, sm: &ShapeMatchingParams, state: &ShapeMatching) -> (f32, f32) {
        let omega2 = match sm.update {
            GoalUpdate::Force => self.pull_omega2(&state.goals, sm.stiffness, sm.exponent),
            GoalUpdate::Velocity => 0.0,
        };
        (omega2, sm.damping * self.max_free_inv_mass())
    }
}

/// Power iterations for the automatic substeps' ω_max and γ_max estimates.
pub const POWER_ITERATIONS: u32 = 30;

/// Factor on the estimated ω_max² and γ_max: the Rayleigh quotient after
/// [`POWER_ITERATIONS`] is below the true value, and a draped cloth's springs turn from
/// where they were when it was taken.
const POWER_MARGIN: f32 = 1.25;

/// A fixed pseudo-random number in [−1, 1] for particle `i` and `axis`: the power
/// iteration's start, and the lab's perturbed cloths.
pub fn unit_hash(i: usize, axis: u64) -> f32 {
    let mut x = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ ((axis + 1) << 32);
    x ^= x >> 31;
    x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x ^= x >> 29;
    (x % 2_000_001) as f32 / 1_000_000.0 - 1.0
}

/// Substeps that keep `h = dt/N` inside the explicit bound `h²ω² + 2hγ < 4` with a safety
/// factor of 0.8 (see [`ClothSolver::stable_substeps`]).
fn substeps_for(dt: f32, omega2: f32, gamma: f32) -> u32 {
    const SAFETY: f64 = 0.8;
    // h_max = (−γ + √(γ² + 4sω²))/ω², written as 4s/(γ + √(γ² + 4sω²)) (the same for
    // ω² > 0, 2s/γ for ω² = 0) and in f64: the first form cancels to 0 for a large γ and
    // overflows past γ ~ 1e19, and both had turned an unbounded need into 1 substep.
    let (omega2, gamma) = (omega2.max(0.0) as f64, gamma.max(0.0) as f64);
    let denominator = gamma + (gamma * gamma + 4.0 * SAFETY * omega2).sqrt();
    if denominator == 0.0 {
        return 1; // no stiffness, no damping: any step is stable
    }
    let n = (dt as f64 * denominator / (4.0 * SAFETY)).ceil();
    if n.is_nan() {
        u32::MAX // a NaN stiffness is refused by validation; never 1 by accident
    } else {
        n.clamp(1.0, u32::MAX as f64) as u32
    }
}

/// The largest stiffness of the pull `(d/L)^(p−1) d` per unit α at distance `d`: along
/// `d` it is `p (d/L)^(p−1)`, across `d` it is `(d/L)^(p−1)`, so `max(p, 1) (d/L)^(p−1)`
/// (inside the clamp at `d/L = 0.05` the pull is linear: both are the clamped scale).
#[inline]
fn pull_stiffness(d: f32, length_scale: f32, exponent: f32) -> f32 {
    let clamped = d / length_scale < 0.05;
    let factor = if clamped { 1.0 } else { exponent.max(1.0) };
    factor * pull_scale(d, length_scale, exponent)
}

/// How far from its goal a particle at distance `d` with kinetic energy `energy` can get
/// against the pull `α (d/L)^(p−1) d` if the goal stood still: its potential is
/// `α L² (d/L)^(p+1) / (p+1)`, so `d_max/L = ((d/L)^(p+1) + (p+1) E / (α L²))^(1/(p+1))`.
#[inline]
fn pull_reach(d: f32, energy: f32, stiffness: f32, length_scale: f32, exponent: f32) -> f32 {
    let l = length_scale;
    let potential = (d / l).powf(exponent + 1.0);
    let kinetic = (exponent + 1.0) * energy / (stiffness * l * l).max(f32::MIN_POSITIVE);
    l * (potential + kinetic).powf(1.0 / (exponent + 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest singular value of the Jacobian of `f(d) = (|d|/L)^(p−1) d` at `d`, by
    /// central differences.
    fn jacobian_norm(d: Vec3, l: f32, p: f32) -> f32 {
        let f = |d: Vec3| d.as_dvec3() * pull_scale(d.length(), l, p) as f64;
        let eps = d.length() * 1e-3;
        let columns: Vec<bevy::math::DVec3> = [Vec3::X, Vec3::Y, Vec3::Z]
            .iter()
            .map(|&e| (f(d + e * eps) - f(d - e * eps)) / (2.0 * eps as f64))
            .collect();
        let j = bevy::math::DMat3::from_cols(columns[0], columns[1], columns[2]);
        // Power iteration on JᵀJ.
        let mut v = bevy::math::DVec3::new(0.3, 0.5, 0.8).normalize();
        for _ in 0..200 {
            v = (j.transpose() * (j * v)).normalize();
        }
        (j * v).length() as f32
    }

    #[test]
    fn the_reach_of_a_pull_is_where_its_kinetic_energy_runs_out() {
        // A particle on a fixed goal's pull, released at d0 with speed v toward nothing:
        // integrate the 1-D motion finely and compare its farthest point with the reach.
        let (alpha, l, m) = (50.0f32, 0.02f32, 1e-4f32);
        for p in [1.5f32, 2.0, 3.0] {
            let (mut x, mut v) = (0.01f64, 0.3f64);
            let reach = pull_reach(x as f32, 0.5 * m * (v * v) as f32, alpha, l, p) as f64;
            let mut farthest = x;
            let h = 1e-7;
            for _ in 0..2_000_000 {
                let a = -(alpha as f64) * (x / l as f64).powf(p as f64 - 1.0) * x / m as f64;
                v += a * h;
                x += v * h;
                farthest = farthest.max(x);
                if v < 0.0 {
                    break;
                }
            }
            assert!(
                (farthest - reach).abs() < 1e-3 * reach,
                "p {p}: {farthest} vs {reach}"
            );
        }
    }

    #[test]
    fn the_pull_bound_covers_its_stiffness_along_and_across_the_pull() {
        // For p < 1 the pull is stiffer across d than along it; a bound from the axial
        // stiffness p·(d/L)^(p−1) alone is too small by 1/p.
        let l = 0.05;
        for p in [0.5, 0.75, 1.0, 2.0, 3.0] {
            for ratio in [0.01, 0.1, 0.3, 1.0, 2.5] {
                let d = Vec3::new(0.6, -0.3, 0.74).normalize() * (ratio * l);
                let exact = jacobian_norm(d, l, p);
                let bound = pull_stiffness(d.length(), l, p);
                assert!(
                    bound >= exact * 0.999 && bound <= exact * 1.01,
                    "p {p}, d/L {ratio}: bound {bound}, largest stiffness {exact}"
                );
            }
        }
    }
}
