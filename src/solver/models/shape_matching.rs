//! Meshless shape matching (Sladović 2014 §2.3, §3.3; Müller et al. 2005): each cluster of
//! particles finds the rigid motion that best maps its rest shape onto its current shape;
//! the moved rest positions are the particles' goals.

use bevy::math::{Mat3, Quat, Vec3, Vec4};

use crate::params::{RotationMethod, ShapeMatchingParams};

/// One cluster: a set of particles matched together.
#[derive(Clone, Debug)]
struct Cluster {
    particles: Vec<u32>,
    /// `q_i = x_i0 − x_cm0` (Sladović 2014 eq. 5, 12), in the same order as `particles`.
    rest_offsets: Vec<Vec3>,
    /// `(Σ m q qᵀ)⁻¹`, regularised for a flat rest shape (for β blending).
    a_qq_inv: Mat3,
    /// The last rotation found, to warm-start the next.
    rotation: Quat,
    /// False until a rotation has been found once.
    warm: bool,
}

/// Clusters and goals of a shape-matching cloth.
#[derive(Clone, Debug)]
pub struct ShapeMatching {
    clusters: Vec<Cluster>,
    /// Goal position of every particle (the mean over the clusters that hold it).
    pub goals: Vec<Vec3>,
    /// `goal − position` of every particle, computed without forming the goal: what the
    /// forces use (see [`ShapeMatching::compute_goals`]).
    pub offsets: Vec<Vec3>,
    /// `1 / (number of clusters holding the particle)`.
    inv_cluster_count: Vec<f32>,
    /// The `k` of k×k clusters these were built for.
    pub(in crate::solver) built_for: u32,
}

impl ShapeMatching {
    /// Clusters over rest positions `rest` with masses `mass`: one for the whole cloth,
    /// or for a `grid` of (width, height), `k × k` clusters overlapping by one particle.
    pub fn new(rest: &[Vec3], mass: &[f32], grid: Option<(u32, u32)>, k: u32) -> Self {
        let n = rest.len();
        let members = cluster_members(n, grid, k);
        let mut count = vec![0.0f32; n];
        for &i in members.iter().flatten() {
            count[i as usize] += 1.0;
        }
        let inv_cluster_count: Vec<f32> = count.iter().map(|&c| 1.0 / c.max(1.0)).collect();
        let weight = |i: u32| mass[i as usize] * inv_cluster_count[i as usize];
        let clusters = members
            .into_iter()
            .map(|particles| {
                let com = centre_of_mass(&particles, rest, weight);
                let rest_offsets: Vec<Vec3> =
                    particles.iter().map(|&i| rest[i as usize] - com).collect();
                let mut a_qq = Mat3::ZERO;
                for (&i, q) in particles.iter().zip(&rest_offsets) {
                    a_qq += outer(*q * weight(i), *q);
                }
                Cluster {
                    particles,
                    rest_offsets,
                    a_qq_inv: regularised_inverse(a_qq),
                    rotation: Quat::IDENTITY,
                    warm: false,
                }
            })
            .collect();
        ShapeMatching {
            clusters,
            goals: rest.to_vec(),
            offsets: vec![Vec3::ZERO; n],
            inv_cluster_count,
            built_for: k,
        }
    }

    /// Forgets the warm-start rotations (after a reset).
    pub fn reset(&mut self) {
        for c in &mut self.clusters {
            c.rotation = Quat::IDENTITY;
            c.warm = false;
        }
    }

    /// Turns the warm-start rotations by `turn` (the cloth was carried rigidly by it).
    pub(in crate::solver) fn turn(&mut self, turn: Quat) {
        for c in &mut self.clusters {
            c.rotation = (turn * c.rotation).normalize();
        }
    }

    /// Goals `g_i = G (x_i0 − x_cm0) + x_cm` (Sladović 2014 eq. 12) from the current positions,
    /// with `G = R` or Müller's `β A + (1 − β) R`. Allocates nothing.
    ///
    /// Each cluster weighs its particles by `m_i / n_i` (n_i: the clusters holding the
    /// particle), as lattice shape matching does (Rivers and James 2007), so the averaged
    /// goals conserve momentum with overlapping clusters too. The offsets
    /// `g_i − x_i = G q_i − (x_i − x_cm)` are formed from the small relative positions, and
    /// each cluster's weighted mean offset (zero in exact arithmetic) is removed: in `f32`
    /// it is the rounding of the centre of mass (1e-8–1e-6 m on a 144-particle cloth), a
    /// net force `α N δ` that accelerated the whole cloth at `δ α/m` and, at stiff pulls on
    /// light particles, pumped energy into it.
    pub fn compute_goals(&mut self, x: &[Vec3], mass: &[f32], params: &ShapeMatchingParams) {
        self.offsets.fill(Vec3::ZERO);
        let inv_count = &self.inv_cluster_count;
        let weight = |i: u32| mass[i as usize] * inv_count[i as usize];
        for c in &mut self.clusters {
            let com = centre_of_mass(&c.particles, x, weight); // Sladović 2014 eq. 4
            let mut a_pq = Mat3::ZERO;
            for (&i, q) in c.particles.iter().zip(&c.rest_offsets) {
                a_pq += outer((x[i as usize] - com) * weight(i), *q);
            }
            let rotation = match params.rotation {
                RotationMethod::QuaternionAverage => average_rotation(c, x, com),
                RotationMethod::PolarDecomposition => {
                    let start = if c.warm {
                        c.rotation
                    } else {
                        average_rotation(c, x, com)
                    };
                    extract_rotation(&a_pq, start)
                }
            };
            c.rotation = rotation;
            c.warm = true;
            let r = Mat3::from_quat(rotation);
            let g = if params.beta > 0.0 {
                (a_pq * c.a_qq_inv) * params.beta + r * (1.0 - params.beta)
            } else {
                r
            };
            let (mut mean, mut weights) = (bevy::math::DVec3::ZERO, 0.0f64);
            for (&i, q) in c.particles.iter().zip(&c.rest_offsets) {
                let d = g * *q - (x[i as usize] - com);
                self.offsets[i as usize] += d;
                mean += d.as_dvec3() * weight(i) as f64;
                weights += weight(i) as f64;
            }
            let mean = (mean / weights).as_vec3();
            for &i in &c.particles {
                self.offsets[i as usize] -= mean;
            }
        }
        for (((d, w), g), x) in self
            .offsets
            .iter_mut()
            .zip(&self.inv_cluster_count)
            .zip(&mut self.goals)
            .zip(x)
        {
            *d *= *w;
            *g = *x + *d;
        }
    }
}

/// Centre of `particles` under `weight`, summed in `f64` (in `f32` the sum's rounding
/// grows with the particle count).
fn centre_of_mass(particles: &[u32], x: &[Vec3], weight: impl Fn(u32) -> f32) -> Vec3 {
    let mut total = 0.0f64;
    let mut com = bevy::math::DVec3::ZERO;
    for &i in particles {
        total += weight(i) as f64;
        com += x[i as usize].as_dvec3() * weight(i) as f64;
    }
    (com / total).as_vec3()
}

/// `a bᵀ`.
pub(in crate::solver) fn outer(a: Vec3, b: Vec3) -> Mat3 {
    Mat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// `A_qq⁻¹`, made invertible for a flat (rank 2) or straight (rank 1) rest shape by adding
/// a small multiple of the identity: the missing directions then map to ~0, so β blending
/// stretches only within the cloth.
fn regularised_inverse(a_qq: Mat3) -> Mat3 {
    let scale = (a_qq.x_axis.x + a_qq.y_axis.y + a_qq.z_axis.z) / 3.0;
    let reg = a_qq + Mat3::IDENTITY * (1e-3 * scale.max(f32::MIN_POSITIVE));
    let inv = reg.inverse();
    if inv.is_finite() { inv } else { Mat3::ZERO }
}

/// Sladović 2014 eq. 6–9: per particle, the rotation of the rest offset onto the current
/// offset; the quaternions summed component-wise and normalised once, so every particle
/// weighs the same whatever its place in the order. Each quaternion is flipped into the
/// hemisphere of the cluster's previous rotation first (q and −q are the same rotation;
/// the thesis does not say, and without it a sum can cancel to nothing). A fixed
/// reference, not the running sum, keeps the flips independent of the order too.
fn average_rotation(c: &Cluster, x: &[Vec3], com: Vec3) -> Quat {
    let reference = Vec4::from(c.rotation);
    let mut sum = Vec4::ZERO;
    for (&i, q) in c.particles.iter().zip(&c.rest_offsets) {
        let p = x[i as usize] - com;
        let (Some(from), Some(to)) = (q.try_normalize(), p.try_normalize()) else {
            continue;
        };
        let r = Vec4::from(Quat::from_rotation_arc(from, to));
        sum += if reference.dot(r) < 0.0 { -r } else { r };
    }
    match sum.try_normalize() {
        Some(v) => Quat::from_vec4(v),
        None => Quat::IDENTITY,
    }
}

/// The rotation part of `A` (Sladović 2014 eq. 15–16) by the iterative method of Müller,
/// Bender, Chentanez and Macklin (2016), "A robust method to extract the rotational part
/// of deformations": maximise tr(Rᵀ A) by rotating `R` about `ω = Σ r_i × a_i / |Σ r_i·a_i|`.
/// Works for rank-deficient `A` (flat or straight shapes), never yields a reflection or a
/// NaN, and is continuous in time when warm-started.
pub(in crate::solver) fn extract_rotation(a: &Mat3, start: Quat) -> Quat {
    let norm =
        (a.x_axis.length_squared() + a.y_axis.length_squared() + a.z_axis.length_squared()).sqrt();
    if !(norm > 0.0 && norm.is_finite()) {
        return start;
    }
    let a = *a * (1.0 / norm);
    let mut q = start.normalize();
    for _ in 0..100 {
        let r = Mat3::from_quat(q);
        let torque = r.x_axis.cross(a.x_axis) + r.y_axis.cross(a.y_axis) + r.z_axis.cross(a.z_axis);
        let align = r.x_axis.dot(a.x_axis) + r.y_axis.dot(a.y_axis) + r.z_axis.dot(a.z_axis);
        let omega = torque / (align.abs() + 1e-9);
        let angle = omega.length();
        if angle < 1e-7 {
            break;
        }
        q = (Quat::from_axis_angle(omega / angle, angle) * q).normalize();
    }
    if q.is_finite() { q } else { start }
}

/// The particles of each cluster: all `n` in one, or for a `grid` of (width, height)
/// `k × k` blocks of rows and columns overlapping their neighbours by one particle.
fn cluster_members(n: usize, grid: Option<(u32, u32)>, k: u32) -> Vec<Vec<u32>> {
    let Some((w, h)) = grid.filter(|_| k > 1) else {
        return vec![(0..n as u32).collect()];
    };
    let span = |c: u32, count: u32| {
        let k = k.min(count - 1).max(1);
        let lo = (c.min(k - 1) * (count - 1)) / k;
        let hi = ((c.min(k - 1) + 1) * (count - 1)).div_ceil(k);
        (lo.saturating_sub(1), (hi + 1).min(count - 1))
    };
    let (kx, ky) = (k.min(w - 1), k.min(h - 1));
    let mut clusters = Vec::new();
    for cy in 0..ky {
        for cx in 0..kx {
            let (i0, i1) = span(cx, w);
            let (j0, j1) = span(cy, h);
            clusters.push(
                (j0..=j1)
                    .flat_map(|j| (i0..=i1).map(move |i| j * w + i))
                    .collect(),
            );
        }
    }
    clusters
}
