//! Stage 1 of a substep, the forces the models share: gravity, wind and drag on every
//! particle, and Hooke springs (Maslova eq. 1.4) with damping along them.

use bevy::math::Vec3;

use super::parallel;
use super::state::ParticleChunk;
use super::{ClothSolver, Particles, SpringKind, Springs};
use crate::error::ClothError;
use crate::params::{Air, AirUpdate, Environment, WindZone, ZoneAt};

/// The wind zones blowing on a cloth ([`ClothSolver::set_wind_zones`]).
#[derive(Clone, Debug, Default)]
pub(super) struct Blowing {
    zones: Vec<WindZone>,
    /// The zones' clock less the cloth's, s.
    time_offset: f32,
    /// The zones' air velocity at each particle, worked out where it is at the start of
    /// each step (empty with no zones).
    at: Vec<Vec3>,
    /// The zones at the step's time (kept for its storage).
    now: Vec<ZoneAt>,
}

/// Each particle's share of the air's force as last worked out on the triangles
/// ([`AirUpdate`]): at the velocity it had then, with the drag's rate and its derivative
/// along the triangles' normals.
#[derive(Clone, Debug, Default)]
pub(super) struct AirLoad {
    /// The force, N.
    force: Vec<Vec3>,
    /// The drag rate `Σ ½ ρ C_d A |w·n| / 3`, N·s/m (of the backward-Euler factor).
    rate: Vec<f32>,
    /// `D = Σ ρ C_d A |w·n| n nᵀ / 3`, N·s/m, as (xx, yy, zz, xy, xz, yz).
    slope: Vec<[f32; 6]>,
    /// The velocity it was worked out at, m/s.
    velocity: Vec<Vec3>,
    /// Worked out in this step (cleared as each step starts).
    pub(super) current: bool,
}

impl AirLoad {
    fn clear(&mut self, n: usize) {
        for v in [&mut self.force, &mut self.velocity] {
            v.clear();
            v.resize(n, Vec3::ZERO);
        }
        self.rate.clear();
        self.rate.resize(n, 0.0);
        self.slope.clear();
        self.slope.resize(n, [0.0; 6]);
    }

    /// Particle `i`'s force at velocity `v`: `f₀ − D (v − v₀)`.
    #[inline(always)]
    fn at(&self, i: usize, v: Vec3) -> Vec3 {
        let [xx, yy, zz, xy, xz, yz] = self.slope[i];
        let d = v - self.velocity[i];
        let change = Vec3::new(
            xx * d.x + xy * d.y + xz * d.z,
            xy * d.x + yy * d.y + yz * d.z,
            xz * d.x + yz * d.y + zz * d.z,
        );
        self.force[i] - change
    }
}

impl ClothSolver {
    /// Sets every particle's force to gravity (Maslova eq. 1.6) and wind. The linear drag
    /// `−c v` (Sladović 2014 eq. 31) is not a force here: the integrators take it implicitly
    /// (`integrate.rs`), stable at any drag, mass and step. While its seams are being sewn, a garment is held as a
    /// tailor holds it: gravity and wind act once the seams are closed (otherwise the
    /// pieces would fall past the body in the time it takes to sew them).
    pub(super) fn external_forces(&mut self, env: &Environment) {
        let held = self.sewing();
        let g = if held {
            Vec3::ZERO
        } else {
            env.effective_gravity()
        };
        let has_wind = !held && env.wind.strength > 0.0 && env.wind.direction != Vec3::ZERO;
        let wind = env.wind.at_time(self.clock.time);
        let n = self.particles.len();
        let kernel = |ParticleChunk {
                          force,
                          mass,
                          represents,
                          position,
                          ..
                      }| {
            let n = force.len();
            let (f, mass, represents) = (&mut force[..n], &mass[..n], &represents[..n]);
            let x = &position[..n];
            for i in 0..n {
                f[i] = mass[i] * g;
                if has_wind {
                    f[i] += wind.vector_at(x[i]) * represents[i];
                }
            }
        };
        parallel::for_each(n, self.particles.chunks(), kernel);
        let still = self.params.fabric.is_some() && self.params.still_air;
        // Wind zones blow through the air model: still air's coefficients when the
        // environment has no air of its own.
        let zones = !self.wind.zones.is_empty();
        match env.air {
            _ if held => {}
            Some(air) => self.air_forces(&air),
            None if still || zones => self.air_forces(&Air::default()),
            None => {}
        }
    }

    /// Takes the wind zones of `zones` that reach this cloth (its particles' bounding
    /// sphere, as it is now), their time `time` s (the world's clock, so that every cloth
    /// in a zone gusts together): they blow on it from its next substep, through the air
    /// model ([`Air`]; still air's coefficients when the environment has none), until
    /// they are set again. Returns how many reach it; a zone that fails its check
    /// ([`WindZone::validate`]) is refused, and none are taken.
    pub fn set_wind_zones(&mut self, zones: &[WindZone], time: f32) -> Result<usize, ClothError> {
        self.wind.zones.clear();
        for zone in zones {
            zone.validate()?;
        }
        let (centre, radius) = self.bounding_sphere();
        let wind = &mut self.wind;
        wind.zones
            .extend(zones.iter().filter(|z| z.reaches(centre, radius)).copied());
        wind.time_offset = time - self.clock.time;
        // Moving air moves a resting cloth: it wakes.
        if wind.zones.iter().any(|z| z.velocity != Vec3::ZERO) {
            self.disturbed = true;
        }
        Ok(wind.zones.len())
    }

    /// At a step's start: the wind zones' air velocity at each particle, at the zones'
    /// time. Once a step rather than at every triangle every substep: the zones' noise
    /// was two thirds of a 384-particle cape's step when it was worked out per triangle
    /// per substep (`cloth crowd`); a particle moves a few centimetres in a step, against
    /// whirls of tens of centimetres and gusts of a second.
    pub(super) fn blow_at_particles(&mut self) {
        let wind = &mut self.wind;
        wind.at.clear();
        if wind.zones.is_empty() {
            return;
        }
        let time = self.clock.time + wind.time_offset;
        wind.now.clear();
        wind.now.extend(wind.zones.iter().map(|z| z.at_time(time)));
        let now = &wind.now;
        wind.at.extend(
            self.particles
                .position
                .iter()
                .map(|&x| now.iter().map(|z| z.velocity_at(x)).sum::<Vec3>()),
        );
    }

    /// The wind zones blowing on this cloth (those [`set_wind_zones`](Self::set_wind_zones)
    /// found reach it).
    pub fn wind_zones(&self) -> &[WindZone] {
        &self.wind.zones
    }

    /// Adds the air's force on every shown triangle, a third to each corner, each
    /// particle's share scaled by the backward-Euler factor of its drag rate (see
    /// [`Air`]): worked out on the triangles at the step's first substep and taken
    /// linearised in the velocity at the others, or worked out every substep
    /// ([`AirUpdate`]).
    fn air_forces(&mut self, air: &Air) {
        let n = self.particles.len();
        let load = &self.air;
        if !load.current || load.force.len() != n || air.update == AirUpdate::Substep {
            self.air_on_triangles(air);
        }
        let (h, load, p) = (self.clock.h, &self.air, &mut self.particles);
        for i in 0..n {
            let w = p.inv_mass[i];
            if w != 0.0 {
                p.force[i] += load.at(i, p.velocity[i]) / (1.0 + h * load.rate[i] * w);
            }
        }
    }

    /// Works out each particle's share of the air's force on the shown triangles, its
    /// drag rate and the rate's change along their normals, at the cloth's shape and
    /// velocity now.
    fn air_on_triangles(&mut self, air: &Air) {
        let time = self.clock.time;
        let (s, p) = (&self.structure, &self.particles);
        let load = &mut self.air;
        load.clear(p.len());
        load.velocity.copy_from_slice(&p.velocity);
        load.current = true;
        let flow = air.at_time(time);
        let zones = &self.wind.at;
        for (t, corners) in s.triangles.iter().enumerate() {
            if !s.triangle_visible[t] {
                continue;
            }
            let [a, b, c] = corners.map(|i| i as usize);
            let (xa, xb, xc) = (p.position[a], p.position[b], p.position[c]);
            let cross = (xb - xa).cross(xc - xa);
            let centre = (xa + xb + xc) / 3.0;
            let moving = (p.velocity[a] + p.velocity[b] + p.velocity[c]) / 3.0;
            let blowing = if zones.is_empty() {
                Vec3::ZERO
            } else {
                (zones[a] + zones[b] + zones[c]) / 3.0
            };
            let w = flow.vector_at(centre) + blowing - moving;
            let Some((share, rate, slope)) = corner_load(air, cross, w) else {
                continue;
            };
            for i in [a, b, c] {
                load.force[i] += share;
                load.rate[i] += rate;
                for (sum, add) in load.slope[i].iter_mut().zip(slope) {
                    *sum += add;
                }
            }
        }
    }

    /// Adds every acting spring's force: on a grid by its stencil, on a mesh in rows by
    /// theirs and the springs kept apart from it by the general path (`lattice.rs`), on
    /// any other cloth by the general path.
    pub(super) fn spring_forces(&mut self) {
        let damping = self.params.springs.damping;
        let k = SpringKind::ALL.map(|kind| self.stiffness(kind));
        let (structure, p) = (&mut self.structure, &mut self.particles);
        if let Some(stencil) = &mut structure.stencil {
            stencil.spring_forces(p, |kind| k[kind as usize], damping);
            return;
        }
        let apart = match &mut structure.rows {
            Some(rows) => {
                rows.stencil
                    .spring_forces(p, |kind| k[kind as usize], damping);
                Some(rows.apart.as_slice())
            }
            None => None,
        };
        let s = &structure.springs;
        for kind in SpringKind::ALL {
            let k = k[kind as usize];
            if k == 0.0 {
                continue;
            }
            let range = s.ranges[kind as usize].clone();
            // A particle cloth's springs all take their family's constant; only the patch
            // model's part lattice scales them one by one. Two instances of one loop, so
            // the common case reads no per-spring factor.
            let scale = s.stiffness_scale.as_deref();
            match (apart, scale) {
                (None, None) => spring_forces(s, p, range, k, damping, |_| 1.0),
                (None, Some(scale)) => spring_forces(s, p, range, k, damping, |i| scale[i]),
                (Some(apart), _) => {
                    // The family's springs kept apart (they are in index order).
                    let at = |i: usize| apart.partition_point(|&s| (s as usize) < i);
                    let springs = apart[at(range.start)..at(range.end)].iter();
                    let springs = springs.map(|&s| s as usize);
                    spring_forces(s, p, springs, k, damping, |i| s.scale(i));
                }
            }
        }
    }

    /// Adds an external force (N) to particle `i` for the current substep. Call it between
    /// `accumulate_forces` and `integrate` (in the plugin: after
    /// `ClothSubstepSystems::AccumulateForces`, before `ClothSubstepSystems::Integrate`).
    pub fn add_force(&mut self, i: usize, force: Vec3) {
        if let Some(f) = self.particles.force.get_mut(i) {
            *f += force;
        }
    }
}

/// A triangle's air load on each of its corners: a third of its flat-plate force, its
/// drag rate and the rate's derivative in velocity `2 rate n nᵀ` (as xx, yy, zz, xy, xz,
/// yz), for the triangle's area vector `cross = 2A n` and the air's velocity `w` relative
/// to it; `None` for a triangle of no area. Every term is written in `cross` and `w`, with one square root
/// (of `|cross|² |w|²`) where the unit normal, the area, the unit flow and the lift's
/// direction took four, a triangle's chain of them the air's cost.
#[inline(always)]
fn corner_load(air: &Air, cross: Vec3, w: Vec3) -> Option<(Vec3, f32, [f32; 6])> {
    let cross2 = cross.length_squared();
    if cross2 <= 0.0 {
        return None;
    }
    let half_rho = 0.5 * air.density;
    // `w·n 2A`; `w·n |w·n| A n = wc |wc| cross / (2 |cross|²)`.
    let (wc, w2) = (w.dot(cross), w.length_squared());
    let over_cross2 = 1.0 / cross2;
    let drag = air.drag * wc * wc.abs() * over_cross2 * cross;
    // `(w·n) |w × n| A ℓ = (w·n) A (|w|² n − (w·n) w) / |w|`
    // `= wc (|w|² cross − wc w) / (2 |cross| |w|)`.
    // `|wc| ≤ |cross| |w|`: the quotient is at most 1, and `|cross| |w|` is 0 only where
    // the lift vanishes.
    let reach = (cross2 * w2).sqrt();
    let lift = if reach > 0.0 {
        air.lift * (wc / reach) * (w2 * cross - wc * w)
    } else {
        Vec3::ZERO
    };
    // The ½ of the area and the third to each corner.
    let share = half_rho * (drag + lift) / 6.0;
    let rate = half_rho * air.drag * wc.abs() / 6.0;
    let (d, m) = (2.0 * rate * over_cross2, cross);
    let slope = [
        d * m.x * m.x,
        d * m.y * m.y,
        d * m.z * m.z,
        d * m.x * m.y,
        d * m.x * m.z,
        d * m.y * m.z,
    ];
    Some((share, rate, slope))
}

/// Hooke springs `F = k (|l| − l0) l/|l|` (Maslova eq. 1.4) plus damping along the
/// spring, over the `springs` of `s` (indices), each scaled by `scale(spring)`. Each spring
/// pushes its ends with equal and opposite forces; dividing by each end's mass in
/// `integrate` shares the motion by inverse mass, as Sladović 2014 eq. 2 asks.
#[inline(always)]
pub(super) fn spring_forces(
    s: &Springs,
    p: &mut Particles,
    springs: impl IntoIterator<Item = usize>,
    k: f32,
    damping: f32,
    scale: impl Fn(usize) -> f32,
) {
    for idx in springs {
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

#[cfg(test)]
mod tests {
    use bevy::math::DVec3;

    use super::*;

    /// Each particle's third of its triangles' flat-plate force and drag rate over `cloth`
    /// in `air` (uniform), as [`Air`] writes them, with unit vectors, in `f64`.
    fn flat_plate(cloth: &ClothSolver, air: &Air) -> (Vec<DVec3>, Vec<f64>) {
        let n = cloth.particles.len();
        let (mut force, mut rate) = (vec![DVec3::ZERO; n], vec![0.0f64; n]);
        let (x, v) = (&cloth.particles.position, &cloth.particles.velocity);
        let half_rho = 0.5 * air.density as f64;
        for t in &cloth.structure.triangles {
            let [a, b, c] = t.map(|i| i as usize);
            let cross = (x[b] - x[a]).as_dvec3().cross((x[c] - x[a]).as_dvec3());
            let (area, normal) = (0.5 * cross.length(), cross.normalize());
            let moving = (v[a] + v[b] + v[c]).as_dvec3() / 3.0;
            let w = air.velocity.as_dvec3() - moving;
            let wn = w.dot(normal);
            let drag = half_rho * air.drag as f64 * area * wn * wn.abs() * normal;
            let lift_dir = (normal - normal.dot(w.normalize()) * w.normalize()).normalize();
            let lift = half_rho * air.lift as f64 * area * wn * w.cross(normal).length() * lift_dir;
            for i in [a, b, c] {
                force[i] += (drag + lift) / 3.0;
                rate[i] += half_rho * air.drag as f64 * area * wn.abs() / 3.0;
            }
        }
        (force, rate)
    }

    /// The air's load on a crumpled, moving grid in a breeze is the flat-plate force of
    /// [`Air`] on each triangle (drag `½ ρ C_d A (w·n)|w·n| n`, lift `½ ρ C_l A (w·n)
    /// |w × n| ℓ`), a third to each corner, and its drag rate `½ ρ C_d A |w·n| / 3`: as
    /// written there, with unit normals and directions, in `f64`.
    #[test]
    fn the_air_on_each_triangle_is_the_flat_plate_force() {
        use crate::layout::shape::{ClothPins, ClothShape};
        let shape = ClothShape::Grid {
            width: 4,
            height: 3,
            spacing: 0.1,
        };
        let mut cloth = shape
            .build_solver(
                &ClothPins::None,
                &crate::params::ClothParams::seeds(),
                bevy::math::Affine3A::IDENTITY,
            )
            .unwrap();
        let n = cloth.particles.len();
        for i in 0..n {
            let f = i as f32;
            cloth.particles.position[i] += Vec3::new(0.01 * f.sin(), 0.0, 0.04 * (1.7 * f).cos());
            cloth.particles.velocity[i] = Vec3::new(0.3 * (0.7 * f).cos(), -0.2, 0.5 * f.sin());
        }
        // A breeze along each of three directions (the last nearly in the cloth's plane).
        for velocity in [
            Vec3::new(0.0, 0.0, 3.0),
            Vec3::new(1.0, -2.0, 0.5),
            Vec3::new(4.0, 0.0, 0.05),
        ] {
            let air = Air {
                velocity,
                ..Air::default()
            };
            cloth.air_on_triangles(&air);
            let (force, rate) = flat_plate(&cloth, &air);
            for i in 0..n {
                let got = cloth.air.force[i].as_dvec3();
                assert!(
                    (got - force[i]).length() <= 1e-5 * force[i].length().max(1e-6),
                    "{velocity} {i}: {got} against {}",
                    force[i]
                );
                let r = cloth.air.rate[i] as f64;
                assert!(
                    (r - rate[i]).abs() <= 1e-5 * rate[i],
                    "{i}: {r} against {}",
                    rate[i]
                );
            }
        }
    }

    /// One spring's force against Hooke's law with damping along the spring, in `f64`:
    /// `F = (k (|d| − l0) + c (v_b − v_a)·d̂) d̂` on the first end, its opposite on the
    /// second.
    #[test]
    fn one_spring_pulls_its_ends_by_hookes_law_with_damping_along_it() {
        let rest = [Vec3::ZERO, Vec3::new(0.5, 0.0, 0.0)];
        let springs = Springs::from_pairs(vec![(SpringKind::Structural, 0, 1)], &rest);
        let mut p = Particles::with_len(2);
        p.position = vec![Vec3::new(0.1, 0.2, -0.3), Vec3::new(0.4, -0.1, 0.5)];
        p.velocity = vec![Vec3::new(0.3, -0.2, 0.1), Vec3::new(-0.5, 0.4, 0.2)];
        let (k, c) = (120.0, 0.7);
        spring_forces(&springs, &mut p, 0..1, k, c, |_| 1.0);

        let d = (p.position[1] - p.position[0]).as_dvec3();
        let dir = d / d.length();
        let along = (p.velocity[1] - p.velocity[0]).as_dvec3().dot(dir);
        let f: DVec3 = dir * (k as f64 * (d.length() - 0.5) + c as f64 * along);
        assert!(
            (p.force[0].as_dvec3() - f).length() < 1e-5 * f.length(),
            "{f}"
        );
        assert!((p.force[1].as_dvec3() + f).length() < 1e-5 * f.length());
    }
}
