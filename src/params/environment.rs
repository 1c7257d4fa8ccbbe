//! The world a cloth moves in: gravity, wind and air.

use crate::limits::{MAX_GRAVITY, MAX_WIND};
use bevy::math::Vec3;
use bevy::reflect::Reflect;
use serde::{Deserialize, Serialize};

use super::{check, vec3_serde};
use crate::error::ClothError;

/// The spatial pattern of the wind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Reflect, Serialize, Deserialize)]
pub enum WindField {
    /// The same force on every particle: `F = strength · d̂` (Sladović 2014 §3.2).
    #[default]
    Constant,
    /// Maslova listing 3.3: gusts from trigonometric functions of position and time.
    /// With `d̂ = +z` and strength 0.1 this is the listing's
    /// `(0.1 sin(10t), ·, 0.1 |sin(z + 10t)|)`; the listing's middle (y) line is missing
    /// from the seed text, so the vertical component here is 0.
    Trigonometric,
}

/// Wind as a direction, a strength (N per particle) and a field.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Wind {
    /// Where the wind blows to; normalised when used (a zero vector means no wind).
    #[serde(with = "vec3_serde")]
    pub direction: Vec3,
    /// Force per particle in N.
    pub strength: f32,
    /// Spatial and temporal pattern.
    pub field: WindField,
}

impl Default for Wind {
    fn default() -> Self {
        Self {
            direction: Vec3::Z,
            strength: 0.0,
            field: WindField::Constant,
        }
    }
}

impl Wind {
    /// Wind force on a particle at `position` at simulated time `time`.
    #[inline]
    pub fn force_at(&self, position: Vec3, time: f32) -> Vec3 {
        self.at_time(time).vector_at(position)
    }

    /// The wind at simulated time `time`, with what does not depend on position worked
    /// out once (the direction, the side, the gust's phase): the force loops call
    /// [`WindAt::vector_at`] per particle.
    #[inline]
    pub fn at_time(&self, time: f32) -> WindAt {
        let d = self.direction.normalize_or_zero();
        let side = Vec3::Y.cross(d).normalize_or(Vec3::X);
        let phase = 10.0 * time;
        WindAt {
            field: self.field,
            strength: self.strength,
            direction: d,
            side,
            phase,
            across: phase.sin(),
        }
    }
}

/// [`Wind`] at one moment (see [`Wind::at_time`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindAt {
    field: WindField,
    strength: f32,
    /// The normalised direction.
    direction: Vec3,
    /// The horizontal direction across it.
    side: Vec3,
    /// `10 t`.
    phase: f32,
    /// `sin(10 t)`.
    across: f32,
}

impl WindAt {
    /// The field's vector at `position`: the wind's force on a particle there (N) for a
    /// [`Wind`], the air's velocity there (m/s) for an [`Air`].
    #[inline]
    pub fn vector_at(&self, position: Vec3) -> Vec3 {
        let d = self.direction;
        match self.field {
            WindField::Constant => d * self.strength,
            // Maslova listing 3.3, rotated so that the listing's +z is `d`.
            WindField::Trigonometric => {
                let along = (position.dot(d) + self.phase).sin().abs();
                self.strength * (along * d + self.across * self.side)
            }
        }
    }
}

/// Air in physical units: a velocity (m/s) and the aerodynamic force it puts on each
/// triangle from its area, normal and the air's velocity relative to it, shared to its
/// corners, so the same air moves the same fabric the same way at any resolution and
/// mass. With `w` the air's velocity relative to the triangle (its corners' mean), `n`
/// its unit normal and `A` its area:
/// - drag, along the normal: `½ ρ C_d A (w·n) |w·n| n`;
/// - lift, across the relative flow in the plane of `w` and `n`:
///   `½ ρ C_l A (w·n) |w × n| ℓ`, `ℓ` the unit vector of `(n − (n·ŵ) ŵ)` (the flat-plate
///   force of Keckeisen et al. 2004, "Interactive cloth simulation in virtual
///   environments", §4, which separates the normal and tangential parts likewise).
///
/// Each particle takes a third of its triangles' force, scaled by `1 / (1 + h r)` with
/// `r` its drag rate `Σ ½ ρ C_d A |w·n| / 3m`: the backward-Euler step of the drag
/// linearised about the relative velocity, so a light fabric in a strong wind is carried
/// with the air without overshooting it, at any step (explicit drag diverges once
/// `h r > 2`). The per-particle [`Wind`] stays for the seeds' scenes.
///
/// How often the triangles are visited is [`AirUpdate`]: by default once a step, the
/// force linearised in each particle's velocity for the substeps after the first.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Air {
    /// The air's velocity far from the cloth, m/s (its pattern in space and time: `field`).
    #[serde(with = "vec3_serde")]
    pub velocity: Vec3,
    /// Its spatial and temporal pattern ([`WindField`]: constant, or Maslova's gusts).
    pub field: WindField,
    /// Its density, kg/m³ (1.2 at sea level and 20 °C).
    pub density: f32,
    /// The drag coefficient of a triangle facing the flow (a flat plate: about 1.2).
    pub drag: f32,
    /// The lift coefficient.
    pub lift: f32,
    /// How often the force is worked out on the triangles.
    pub update: AirUpdate,
}

impl Default for Air {
    fn default() -> Self {
        Self {
            velocity: Vec3::ZERO,
            field: WindField::Constant,
            density: 1.2,
            drag: 1.2,
            lift: 0.3,
            update: AirUpdate::default(),
        }
    }
}

/// How often [`Air`]'s force is worked out on the triangles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Reflect, Serialize, Deserialize)]
pub enum AirUpdate {
    /// On the triangles at a step's first substep; at the others, each particle's force
    /// is that one plus the drag's change with its velocity since, along its triangles'
    /// normals: `f = f₀ − D (v − v₀)`, `D = Σ ρ C_d A |w·n| n nᵀ / 3` (the drag's
    /// derivative, for a particle moving with its triangles). The linearisation an
    /// implicit integrator makes once a step (Baraff and Witkin 1998), for the air alone:
    /// the cloth's shape is the step's first (a normal turns a few degrees in 16 ms), its
    /// speed every substep's, so the air still damps each substep. A fraction of the
    /// cost: the triangles' areas, normals and flow once a step instead of every substep.
    #[default]
    Step,
    /// On the triangles at every substep: the force of the cloth's shape and speed then.
    Substep,
}

impl Air {
    /// The air at simulated time `time`, what does not depend on position worked out
    /// once: its velocity at a position is the returned pattern's
    /// [`WindAt::vector_at`] (a per-triangle loop calls it).
    pub fn at_time(&self, time: f32) -> WindAt {
        Wind {
            direction: self.velocity,
            strength: self.velocity.length(),
            field: self.field,
        }
        .at_time(time)
    }

    /// Checks the velocity, density and coefficients.
    pub fn validate(&self) -> Result<(), ClothError> {
        check(
            "air.velocity",
            self.velocity.length(),
            self.velocity.is_finite() && self.velocity.length() <= 1e3,
            "a finite velocity of at most 1,000 m/s",
        )?;
        for (field, value, most) in [
            ("air.density", self.density, 1e3),
            ("air.drag", self.drag, 100.0),
            ("air.lift", self.lift, 100.0),
        ] {
            check(
                field,
                value,
                (0.0..=most).contains(&value),
                "a value from 0 to its most (density 1,000 kg/m³, coefficients 100)",
            )?;
        }
        Ok(())
    }
}

/// Gravity and wind: the world a cloth lives in.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Environment {
    /// Acceleration of gravity in m/s² (Maslova eq. 1.6).
    #[serde(with = "vec3_serde")]
    pub gravity: Vec3,
    /// Switch gravity off without forgetting its value (Sladović's (2014) G key).
    pub gravity_enabled: bool,
    /// The wind as a force per particle (the seeds' scenes).
    pub wind: Wind,
    /// Air in physical units (`None`: no aerodynamic force; still air is `Some` with a
    /// zero velocity, and drags a falling cloth to its terminal velocity).
    pub air: Option<Air>,
}

impl Default for Environment {
    fn default() -> Self {
        Self {
            gravity: Vec3::new(0.0, -9.81, 0.0),
            gravity_enabled: true,
            wind: Wind::default(),
            air: None,
        }
    }
}

impl Environment {
    /// The gravity that acts: zero when switched off.
    pub fn effective_gravity(&self) -> Vec3 {
        if self.gravity_enabled {
            self.gravity
        } else {
            Vec3::ZERO
        }
    }

    /// Checks gravity and wind for non-finite values.
    pub fn validate(&self) -> Result<(), ClothError> {
        let g = self.gravity;
        check(
            "gravity",
            g.length(),
            g.is_finite() && g.length() <= crate::limits::MAX_GRAVITY,
            format!("a finite vector of at most {MAX_GRAVITY} m/s² (limits::MAX_GRAVITY)"),
        )?;
        let w = &self.wind;
        check(
            "wind.direction",
            w.direction.length(),
            w.direction.is_finite(),
            "a finite vector",
        )?;
        check(
            "wind.strength",
            w.strength,
            (0.0..=crate::limits::MAX_WIND).contains(&w.strength),
            format!("a strength from 0 to {MAX_WIND} N (limits::MAX_WIND)"),
        )?;
        self.air.as_ref().map_or(Ok(()), Air::validate)
    }
}
