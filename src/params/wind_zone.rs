//! Wind zones: regions of moving air (everywhere, a sphere or a box, fading at their
//! edge), with gusts in time and turbulence in space from seeded noise, whose velocities
//! add to the air's and act on a cloth's triangles through the air model ([`Air`]).
//! Unity's and Godot's wind zones, and the area forces of Jolt's soft bodies, in that
//! sense; the noise is value noise (Perlin 1985's lattice with random values in place of
//! gradients), hashed from the lattice point and the seed, so it needs no tables and
//! gives the same bits everywhere.
//!
//! [`Air`]: super::Air

use bevy::math::{Quat, Vec3};
use bevy::reflect::Reflect;
use serde::{Deserialize, Serialize};

use super::{quat_serde, vec3_serde};

use super::check;
use crate::error::ClothError;

/// Where a wind zone blows.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
pub enum ZoneShape {
    /// Everywhere, at full strength.
    Global,
    /// Within `radius` m of its centre.
    Sphere {
        /// Its radius, m.
        radius: f32,
    },
    /// Within a box of these half extents about its centre, turned with its rotation.
    Box {
        /// Half its size along each of its own axes, m.
        #[serde(with = "vec3_serde")]
        half_extents: Vec3,
    },
}

/// Gusts and turbulence of a wind zone, from seeded noise.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Turbulence {
    /// How much the strength swells and drops in time, as a share of it (0: steady; 0.5:
    /// between half and one and a half times).
    pub gust: f32,
    /// The time a gust takes, s (the spacing of the noise's lattice in time).
    pub gust_period: f32,
    /// How large the velocity's random part is, as a share of the zone's speed, in each
    /// direction.
    pub noise: f32,
    /// The size of a whirl of it, m (the spacing of the noise's lattice in space); the
    /// pattern drifts with the wind.
    pub scale: f32,
    /// The seed: two zones with different seeds gust and whirl differently.
    pub seed: u32,
}

impl Default for Turbulence {
    fn default() -> Self {
        Turbulence {
            gust: 0.0,
            gust_period: 2.0,
            noise: 0.0,
            scale: 1.0,
            seed: 0,
        }
    }
}

impl Turbulence {
    /// Checks the shares, period and size; the error names the field.
    fn validate(&self) -> Result<(), ClothError> {
        let share = |v: f32, most: f32| (0.0..=most).contains(&v);
        let (gust, period) = (self.gust, self.gust_period);
        let (noise, scale) = (self.noise, self.scale);
        for (field, value, ok, expected) in [
            (
                "wind_zone.turbulence.gust",
                gust,
                share(gust, 1.0),
                "a share from 0 to 1",
            ),
            (
                "wind_zone.turbulence.gust_period",
                period,
                period > 0.0,
                "a time > 0 s",
            ),
            (
                "wind_zone.turbulence.noise",
                noise,
                share(noise, 10.0),
                "a share from 0 to 10",
            ),
            (
                "wind_zone.turbulence.scale",
                scale,
                scale > 0.0,
                "a size > 0 m",
            ),
        ] {
            check(field, value, ok, expected)?;
        }
        Ok(())
    }
}

/// A region of moving air, placed in the world: its velocity, at full strength inside
/// and fading over the outer `falloff` share of its size to nothing at its edge, swelled
/// by gusts and stirred by turbulence. Cloths take the zones that reach them
/// (`ClothSolver::set_wind_zones`; the plugin's `ClothWindZone`; a scene file's
/// `wind_zones`).
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WindZone {
    /// Where it blows.
    pub shape: ZoneShape,
    /// Its centre, m.
    #[serde(with = "vec3_serde")]
    pub centre: Vec3,
    /// Its turn (a box's axes), as a quaternion `(x, y, z, w)`.
    #[serde(with = "quat_serde")]
    pub rotation: Quat,
    /// The air's velocity at full strength, m/s.
    #[serde(with = "vec3_serde")]
    pub velocity: Vec3,
    /// The outer share of its size (of the radius, or of each half extent) over which it
    /// fades to nothing, 0 to 1 (0: a hard edge). A global zone does not fade.
    pub falloff: f32,
    /// Gusts and turbulence.
    pub turbulence: Turbulence,
}

impl Default for WindZone {
    fn default() -> Self {
        WindZone {
            shape: ZoneShape::Global,
            centre: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            velocity: Vec3::ZERO,
            falloff: 0.0,
            turbulence: Turbulence::default(),
        }
    }
}

impl WindZone {
    /// Checks the shape, velocity and turbulence; the error names the field.
    pub fn validate(&self) -> Result<(), ClothError> {
        let finite = self.centre.is_finite() && self.rotation.is_finite();
        check(
            "wind_zone.centre",
            0.0,
            finite,
            "a finite centre and rotation",
        )?;
        let speed = self.velocity.length();
        check(
            "wind_zone.velocity",
            speed,
            speed <= 1e3,
            "a finite velocity of at most 1,000 m/s",
        )?;
        match self.shape {
            ZoneShape::Global => {}
            ZoneShape::Sphere { radius } => {
                check("wind_zone.radius", radius, radius > 0.0, "a radius > 0 m")?
            }
            ZoneShape::Box { half_extents: e } => check(
                "wind_zone.half_extents",
                e.min_element(),
                e.is_finite() && e.min_element() > 0.0,
                "half extents > 0 m",
            )?,
        }
        let f = self.falloff;
        check(
            "wind_zone.falloff",
            f,
            (0.0..=1.0).contains(&f),
            "a share from 0 to 1",
        )?;
        self.turbulence.validate()
    }

    /// Whether it can reach anything within `radius` of `centre`: whether that ball meets
    /// the zone's sphere or box. A box is met by the ball's nearest point to it in the
    /// box's own axes, not by the sphere around the box: a long thin box (a wind along a
    /// street) reached every cloth within its half-length, each then taking the air model
    /// for nothing where the box's weight is 0.
    pub fn reaches(&self, centre: Vec3, radius: f32) -> bool {
        match self.shape {
            ZoneShape::Global => true,
            ZoneShape::Sphere { radius: reach } => self.centre.distance(centre) <= reach + radius,
            ZoneShape::Box { half_extents } => {
                let local = self.rotation.inverse() * (centre - self.centre);
                let outside = (local.abs() - half_extents).max(Vec3::ZERO);
                // A margin over the rounding of the turn, so that a ball that touches the
                // box is never told apart from it.
                outside.length() <= radius + 1e-5 * (1.0 + local.abs().max_element())
            }
        }
    }

    /// How strongly it blows at `x`, 0 to 1: 1 inside, fading (smoothly) over the outer
    /// `falloff` share of its size, 0 outside.
    pub fn weight_at(&self, x: Vec3) -> f32 {
        let depth = match self.shape {
            ZoneShape::Global => return 1.0,
            ZoneShape::Sphere { radius } => self.centre.distance(x) / radius,
            ZoneShape::Box { half_extents } => {
                let local = self.rotation.inverse() * (x - self.centre);
                (local.abs() / half_extents).max_element()
            }
        };
        if depth >= 1.0 {
            0.0
        } else if self.falloff <= 0.0 {
            1.0
        } else {
            let s = ((1.0 - depth) / self.falloff).min(1.0);
            s * s * (3.0 - 2.0 * s)
        }
    }

    /// The zone at time `t` (s), what does not depend on position worked out once.
    pub fn at_time(&self, t: f32) -> ZoneAt {
        let turbulence = self.turbulence;
        let gust = 1.0 + turbulence.gust * noise1(turbulence.seed, t / turbulence.gust_period);
        ZoneAt {
            zone: *self,
            gusting: self.velocity * gust,
            drift: self.velocity * t,
            stir: turbulence.noise * self.velocity.length() * gust,
        }
    }

    /// The air's velocity it adds at `x` at time `t`, m/s.
    pub fn velocity_at(&self, x: Vec3, t: f32) -> Vec3 {
        self.at_time(t).velocity_at(x)
    }
}

/// A [`WindZone`] at one moment ([`WindZone::at_time`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZoneAt {
    zone: WindZone,
    /// The velocity swelled by this moment's gust.
    gusting: Vec3,
    /// How far the turbulence has drifted with the wind.
    drift: Vec3,
    /// The turbulence's amplitude now, m/s.
    stir: f32,
}

impl ZoneAt {
    /// The air's velocity the zone adds at `x`, m/s.
    #[inline]
    pub fn velocity_at(&self, x: Vec3) -> Vec3 {
        let weight = self.zone.weight_at(x);
        if weight == 0.0 {
            return Vec3::ZERO;
        }
        let mut v = self.gusting;
        if self.stir > 0.0 {
            let t = &self.zone.turbulence;
            let q = (x - self.drift) / t.scale;
            let whirl = noise3x3(t.seed.wrapping_mul(3), q);
            v += self.stir * whirl;
        }
        weight * v
    }
}

/// A hash of a lattice point and a seed to a value in [−1, 1].
#[inline]
fn lattice(seed: u32, x: i32, y: i32, z: i32) -> f32 {
    mix(seeded(seed) ^ place(x, y, z))
}

/// A seed's part of a lattice point's hash.
#[inline]
fn seeded(seed: u32) -> u32 {
    seed.wrapping_mul(0x9e37_79b9)
}

/// A lattice point's part of its hash.
#[inline]
fn place(x: i32, y: i32, z: i32) -> u32 {
    (x as u32).wrapping_mul(0x8da6_b343)
        ^ (y as u32).wrapping_mul(0xd816_3841)
        ^ (z as u32).wrapping_mul(0xcb1a_b31f)
}

/// The seed's and the point's parts of a hash, mixed to a value in [−1, 1].
#[inline]
fn mix(mut h: u32) -> f32 {
    h ^= h >> 15;
    h = h.wrapping_mul(0x2c1b_3c6d);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297a_2d39);
    h ^= h >> 15;
    (h >> 8) as f32 / (1u32 << 23) as f32 - 1.0
}

/// The smooth fade `3s² − 2s³` between lattice points.
#[inline]
fn fade(s: f32) -> f32 {
    s * s * (3.0 - 2.0 * s)
}

/// Value noise in time, in [−1, 1], smooth, 0 mean.
fn noise1(seed: u32, t: f32) -> f32 {
    let (i, s) = (t.floor(), fade(t - t.floor()));
    let i = i as i32;
    let (a, b) = (lattice(seed, i, 0, 0), lattice(seed, i + 1, 0, 0));
    a + (b - a) * s
}

/// Value noise in space, in [−1, 1], smooth, 0 mean: the lattice's values trilinearly
/// blended with [`fade`]. (The zones draw three at once, [`noise3x3`]; this one is
/// what they are checked against.)
#[cfg(test)]
fn noise3(seed: u32, p: Vec3) -> f32 {
    let cell = p.floor();
    let (i, j, k) = (cell.x as i32, cell.y as i32, cell.z as i32);
    let f = p - cell;
    let (u, v, w) = (fade(f.x), fade(f.y), fade(f.z));
    let mut along_y = [0.0f32; 2];
    for (dz, out) in along_y.iter_mut().enumerate() {
        let k = k + dz as i32;
        let row = |j| {
            let a = lattice(seed, i, j, k);
            a + (lattice(seed, i + 1, j, k) - a) * u
        };
        let (a, b) = (row(j), row(j + 1));
        *out = a + (b - a) * v;
    }
    along_y[0] + (along_y[1] - along_y[0]) * w
}

/// [`noise3`] at `p` for the seeds `seed + 1`, `seed + 2` and `seed + 3`, to the bit,
/// side by side: the cell, its fades and each lattice point's part of the hash worked
/// out once for the three (the turbulence's three components, every particle a zone
/// reaches, every step).
#[inline]
fn noise3x3(seed: u32, p: Vec3) -> Vec3 {
    let cell = p.floor();
    let (i, j, k) = (cell.x as i32, cell.y as i32, cell.z as i32);
    let f = p - cell;
    let (u, v, w) = (fade(f.x), fade(f.y), fade(f.z));
    let seeds = [1, 2, 3].map(|s| seeded(seed.wrapping_add(s)));
    let at = |x, y, z| {
        let point = place(x, y, z);
        Vec3::from_array(seeds.map(|s| mix(s ^ point)))
    };
    let mut along_y = [Vec3::ZERO; 2];
    for (dz, out) in along_y.iter_mut().enumerate() {
        let k = k + dz as i32;
        let row = |j| {
            let a = at(i, j, k);
            a + (at(i + 1, j, k) - a) * u
        };
        let (a, b) = (row(j), row(j + 1));
        *out = a + (b - a) * v;
    }
    along_y[0] + (along_y[1] - along_y[0]) * w
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The three noises of a zone's turbulence drawn at once are the three drawn one by
    /// one, to the bit, and the hash split into a seed's and a point's parts is the hash
    /// in one expression: at points across cell boundaries, negative and far from 0.
    #[test]
    fn three_noises_at_once_are_three_one_by_one() {
        let whole = |seed: u32, x: i32, y: i32, z: i32| {
            mix(seed.wrapping_mul(0x9e37_79b9)
                ^ (x as u32).wrapping_mul(0x8da6_b343)
                ^ (y as u32).wrapping_mul(0xd816_3841)
                ^ (z as u32).wrapping_mul(0xcb1a_b31f))
        };
        for k in -600..600 {
            let f = k as f32;
            let p = Vec3::new(f * 0.173, (0.37 * f).sin() * 9.0 - 2.0, f * -0.061 + 0.5);
            let p = if k % 7 == 0 { p.floor() } else { p };
            let seed = (k as u32).wrapping_mul(2_654_435_761);
            let three = noise3x3(seed, p);
            for (s, got) in three.to_array().into_iter().enumerate() {
                let one = noise3(seed.wrapping_add(s as u32 + 1), p);
                assert_eq!(got.to_bits(), one.to_bits(), "{p} seed {seed} lane {s}");
            }
            let (x, y, z) = (k, k * 31 - 7, -k * 17);
            assert_eq!(lattice(seed, x, y, z), whole(seed, x, y, z));
        }
    }

    /// The noise stays in [−1, 1], is continuous across lattice cells, averages about
    /// 0, depends on its seed and passes through the lattice's values.
    #[test]
    fn noise_is_bounded_smooth_and_seeded() {
        let (mut sum, mut n) = (0.0f64, 0);
        for k in 0..4000 {
            let p = Vec3::new(k as f32 * 0.137, k as f32 * 0.071, -(k as f32) * 0.053);
            let v = noise3(7, p);
            assert!((-1.0..=1.0).contains(&v), "{v}");
            sum += v as f64;
            n += 1;
            let near = noise3(7, p + Vec3::splat(1e-4));
            assert!((v - near).abs() < 1e-2, "jump {v} to {near} at {p}");
        }
        assert!((sum / n as f64).abs() < 0.1, "mean {}", sum / n as f64);
        let p = Vec3::new(0.3, 1.7, 2.2);
        assert_ne!(noise3(1, p), noise3(2, p));
        // At a lattice point it is that point's value, in every direction.
        for (x, y, z) in [(2, -3, 5), (-1, 0, 7), (0, 0, 0)] {
            let at = Vec3::new(x as f32, y as f32, z as f32);
            assert_eq!(noise3(1, at), lattice(1, x, y, z), "at {at}");
        }
        assert!((noise1(3, 4.999_9) - noise1(3, 5.0)).abs() < 1e-3);
    }

    /// A sphere blows at full strength inside `1 − falloff` of its radius, fades to
    /// nothing at its edge and not beyond; a turned box by its own axes.
    #[test]
    fn a_zone_blows_inside_and_fades_at_its_edge() {
        let sphere = WindZone {
            shape: ZoneShape::Sphere { radius: 2.0 },
            centre: Vec3::new(1.0, 0.0, 0.0),
            velocity: Vec3::X * 5.0,
            falloff: 0.5,
            ..WindZone::default()
        };
        assert_eq!(
            sphere.velocity_at(Vec3::new(1.5, 0.0, 0.0), 0.0),
            Vec3::X * 5.0
        );
        let fading = sphere.weight_at(Vec3::new(2.5, 0.0, 0.0));
        assert!(fading > 0.0 && fading < 1.0, "{fading}");
        assert_eq!(sphere.weight_at(Vec3::new(3.0, 0.0, 0.0)), 0.0);
        assert_eq!(sphere.weight_at(Vec3::new(4.0, 0.0, 0.0)), 0.0);
        let turned = WindZone {
            shape: ZoneShape::Box {
                half_extents: Vec3::new(3.0, 1.0, 1.0),
            },
            rotation: Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
            ..sphere
        };
        // Its long axis now runs along z.
        assert!(turned.weight_at(Vec3::new(1.0, 0.0, 2.5)) > 0.0);
        assert_eq!(turned.weight_at(Vec3::new(3.5, 0.0, 0.0)), 0.0);
    }

    /// A ball reaches a box when it meets the box itself: the turned 6 × 2 × 2 m box
    /// above (long along z) is reached by a ball beside its long side or past its end
    /// only when the ball touches it, though each lies within the sphere around it.
    #[test]
    fn a_box_is_reached_by_the_balls_that_meet_it() {
        let long = WindZone {
            shape: ZoneShape::Box {
                half_extents: Vec3::new(3.0, 1.0, 1.0),
            },
            centre: Vec3::new(1.0, 0.0, 0.0),
            rotation: Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
            ..WindZone::default()
        };
        // Beside its long side (x = 2 at its face): 0.5 m off, a ball of 0.4 does not
        // reach, one of 0.6 does.
        assert!(!long.reaches(Vec3::new(2.5, 0.0, 1.0), 0.4));
        assert!(long.reaches(Vec3::new(2.5, 0.0, 1.0), 0.6));
        // Past its end (z = 3) and its corner.
        assert!(!long.reaches(Vec3::new(1.0, 0.0, 3.5), 0.4));
        assert!(long.reaches(Vec3::new(1.0, 0.0, 3.5), 0.6));
        let corner = Vec3::new(2.0, 1.0, 3.0) + Vec3::ONE * 0.3;
        assert!(!long.reaches(corner, 0.5));
        assert!(long.reaches(corner, 0.53));
        // Inside, and a ball around it.
        assert!(long.reaches(Vec3::new(1.0, 0.0, 2.0), 0.0));
        assert!(long.reaches(Vec3::new(9.0, 0.0, 0.0), 9.0));
        // The sphere around the box (radius 3.3) met each of the balls told apart above.
        let around = Vec3::new(3.0, 1.0, 1.0).length();
        for (far, r) in [
            (Vec3::new(2.5, 0.0, 1.0), 0.4),
            (Vec3::new(1.0, 0.0, 3.5), 0.4),
            (corner, 0.5),
        ] {
            assert!(far.distance(long.centre) <= around + r);
        }
    }
}
