//! Self-collision and cloth–cloth contact parameters.

use bevy::reflect::Reflect;
use serde::{Deserialize, Serialize};

/// Self-collision: every two particles of a cloth that are not joined by a spring keep
/// a distance `d` apart, with friction (Müller's "Ten Minute Physics" #15, the method of
/// NvCloth's self-collision). `d` is `distance`, at most the cloth's rest spacing `s`
/// (the median structural rest length); by default `0.75 s`, the least with a margin at
/// which a particle cannot slip through a grid triangle whose corners it must stay `d`
/// from (the widest gap, the hypotenuse's middle, is `s/√2` from them); larger, the
/// cloth acts as a sheet `d` thick and its folds jam where self-collision and its
/// stretch disagree. Another cloth's particles are kept `distance` away, by default the
/// full spacing (a sheared neighbour's triangles open wider than `s/√2`).
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SelfCollision {
    /// On or off.
    pub enabled: bool,
    /// The distance kept, m; `None`: three quarters of the rest spacing.
    pub distance: Option<f32>,
    /// Coulomb friction between touching particles (0: they slide freely).
    pub friction: f32,
}

impl Default for SelfCollision {
    fn default() -> Self {
        Self {
            enabled: false,
            distance: None,
            friction: 0.3,
        }
    }
}

impl SelfCollision {
    /// On, at three quarters of the rest spacing, with the default friction.
    pub fn on() -> Self {
        Self {
            enabled: true,
            ..Self::default()
        }
    }
}
