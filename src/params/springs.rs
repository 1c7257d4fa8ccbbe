//! The spring families of a mass-spring grid (Sladović 2014 §2.2) and their stiffness.

use bevy::reflect::Reflect;
use serde::{Deserialize, Serialize};

/// One family of springs (Sladović 2014 §2.2, fig. 1): whether it exists and how stiff it is.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SpringFamily {
    /// Switch the whole family off (Sladović 2014 §4, figs. 18–20 show cloth without each family).
    pub enabled: bool,
    /// Hooke constant `k` in N/m (Maslova eq. 1.4).
    pub stiffness: f32,
}

impl Default for SpringFamily {
    fn default() -> Self {
        Self {
            enabled: true,
            stiffness: 100.0,
        }
    }
}

impl SpringFamily {
    /// An enabled family with the given stiffness.
    pub fn new(stiffness: f32) -> Self {
        Self {
            enabled: true,
            stiffness,
        }
    }

    /// A switched-off family (keeps its stiffness so switching it back on restores it).
    pub fn off(stiffness: f32) -> Self {
        Self {
            enabled: false,
            stiffness,
        }
    }

    /// The stiffness that acts: 0 when switched off.
    pub fn effective(&self) -> f32 {
        if self.enabled { self.stiffness } else { 0.0 }
    }
}

/// The four spring families of a grid cloth and the damping along springs.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SpringParams {
    /// Horizontal and vertical neighbours (i±1, j±1), rest length = spacing.
    pub structural: SpringFamily,
    /// Diagonal neighbours, rest length = √2·spacing.
    pub shear: SpringFamily,
    /// Every second particle (i±2, j±2), rest length = 2·spacing.
    pub bend: SpringFamily,
    /// Every second particle diagonally, rest length = 2√2·spacing (Sladović 2014 §2.2, optional).
    pub bend_diagonal: SpringFamily,
    /// Damping along each spring in N·s/m: `F = c ((v_b − v_a)·d̂) d̂`.
    pub damping: f32,
    /// Seam springs joining garment pieces (Maslova §1.4).
    pub seam: SpringFamily,
    /// The length a seam spring is sewn to, m (0: the two edges meet).
    pub seam_rest_length: f32,
    /// Seconds over which seams are sewn: a seam spring's rest length shrinks linearly
    /// from the gap it starts with to `seam_rest_length`, as a tailor pulls the edges
    /// together (0 sews at once). Meanwhile the garment is held: gravity and wind act on
    /// it from the end of sewing.
    pub sew_time: f32,
}

impl Default for SpringParams {
    /// Sladović 2014 §4's structural:shear:bend ratio of 2:1:1, at a stiffness soft enough that
    /// a 0.5 g-per-node cloth drapes and folds under its own weight; the strain limiter
    /// (Provot 1995) keeps the stretch below 10%. Stiffer springs make a board-like sheet
    /// that will not buckle, and cost more substeps.
    fn default() -> Self {
        Self::from_structural(20.0)
    }
}

impl SpringParams {
    /// All families from one structural stiffness with the seed's 2:1:1 ratio.
    pub fn from_structural(stiffness: f32) -> Self {
        Self {
            structural: SpringFamily::new(stiffness),
            shear: SpringFamily::new(stiffness * 0.5),
            bend: SpringFamily::new(stiffness * 0.5),
            bend_diagonal: SpringFamily::off(stiffness * 0.25),
            damping: 0.0,
            seam: SpringFamily::new(stiffness),
            seam_rest_length: 0.0,
            sew_time: 1.0,
        }
    }
}
