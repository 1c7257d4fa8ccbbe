//! Fabric in physical units: what a textile lab measures (areal density, tensile and
//! shear stiffness per unit width, bending rigidity), from which the solver derives a
//! cloth's masses, springs and bending for any layout, so the same fabric at another
//! resolution is the same fabric.
//!
//! The presets are the ten fabrics Wang, O'Brien and Ramamoorthi measured ("Data-driven
//! elastic models for cloth: modeling and measurement", SIGGRAPH 2011), from the JSON
//! files ARCSim ships in `materials/`. How their numbers become ours (`docs/fabric.md`):
//! - `density` is kg/m² already;
//! - `stretching` holds, per strain sample, `[C11, C12, C22, C33]`, which ARCSim doubles
//!   before use (`evaluate_stretching_sample`) in the energy density
//!   `½ C11 ε₁₁² + C12 ε₁₁ε₂₂ + ½ C22 ε₂₂² + C33 ε₁₂²` (Green strain, `stretching_force`).
//!   At the smallest strain sample: the tensile stiffness along warp and weft is `2·C11`
//!   and `2·C22` (N/m); ours, isotropic, is their mean. The shear stiffness (energy
//!   `½ G γ²`, `γ = 2ε₁₂`) is `G = C33` as stored;
//! - `bending` holds, per direction (warp, diagonal, weft) and curvature sample, a
//!   stiffness `k` that ARCSim's hinge energy uses as `k l² θ² / (8 (A₀ + A₁))`
//!   (`bending_force`). On a regular mesh bent to curvature `κ`, `Σ l² θ² / (A₀ + A₁)` is
//!   `κ² A` (measured in `docs/fabric.md`), so that energy is `½ (k/4) κ² A`: the bending
//!   rigidity the fitted simulator applied is `B = k/4` (N·m). Ours is the mean of the
//!   three directions at the smallest curvature, over four.

use bevy::reflect::Reflect;
use serde::{Deserialize, Serialize};

use crate::error::ClothError;
use crate::params::check;

/// A fabric in physical units (SI). Isotropic: one stiffness in every direction.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(try_from = "FabricSpec", deny_unknown_fields)]
pub struct Fabric {
    /// Mass per area, kg/m² (a T-shirt knit 0.15–0.2, denim 0.3–0.4).
    pub areal_density: f32,
    /// Tensile stiffness per unit width, N/m: the force per metre of width that stretches
    /// the fabric by 100% at small strain (lateral contraction held).
    pub stretch: f32,
    /// In-plane shear stiffness per unit width, N/m (`τ = G γ`).
    pub shear: f32,
    /// Bending rigidity per unit width, N·m (`M = B κ`; Peirce's `B = ρ_A g c³`).
    pub bending: f32,
}

// The presets keep the material files' digits as published (more than an f32 holds).
#[allow(clippy::excessive_precision)]
impl Fabric {
    /// 11 oz black denim (jeans, 99% cotton).
    pub const DENIM: Fabric = Fabric::measured(
        0.324,
        [205.352, 10.234077, 1013.8863, 53.387184],
        [64.196457e-6, 73.384567e-6, 96.951576e-6],
    );
    /// Gray interlock knit (T-shirt, 60% cotton 40% polyester).
    pub const INTERLOCK: Fabric = Fabric::measured(
        0.187,
        [16.593832, -14.69599, 34.477123, 36.860302],
        [23.191698e-6, 24.749964e-6, 14.267624e-6],
    );
    /// Ivory rib knit (underwear, 95% cotton 5% spandex).
    pub const RIB_KNIT: Fabric = Fabric::measured(
        0.276,
        [42.871021, -0.234556, 65.166023, 83.175644],
        [46.237591e-6, 30.01593e-6, 32.243889e-6],
    );
    /// Camel ponte roma (jacket, 60% polyester 40% rayon).
    pub const PONTE: Fabric = Fabric::measured(
        0.284,
        [31.146198, -12.802702, 44.028667, 31.896357],
        [36.348366e-6, 33.013252e-6, 37.157593e-6],
    );
    /// Navy sparkle sweat (sweater, 96% polyester 4% spandex).
    pub const SWEATSHIRT: Fabric = Fabric::measured(
        0.224,
        [12.486332, -19.875324, 3.272434, 17.616289],
        [59.469658e-6, 40.072277e-6, 45.625023e-6],
    );
    /// White swim solid (swimsuit, 87% nylon 13% spandex).
    pub const SWIMSUIT: Fabric = Fabric::measured(
        0.204,
        [47.971176, 6.834521, 104.615456, 60.773663],
        [60.237942e-6, 58.803211e-6, 51.018833e-6],
    );
    /// Pink ribbon brown (blanket, 100% polyester).
    pub const POLYESTER: Fabric = Fabric::measured(
        0.228,
        [151.503906, 106.02816, 244.830673, 30.250183],
        [117.070122e-6, 87.509773e-6, 59.774277e-6],
    );
    /// White dots on black (tablecloth, 100% polyester).
    pub const TABLECLOTH: Fabric = Fabric::measured(
        0.128,
        [2002.08618, 0.345588, 2027.48559, 19.189022],
        [51.713814e-6, 40.65947e-6, 31.282822e-6],
    );
    /// Tango red jet set (jacket, 100% polyester).
    pub const JACKET: Fabric = Fabric::measured(
        0.113,
        [43.067627, 54.373299, 171.424835, 14.3147],
        [14.293814e-6, 21.9517e-6, 20.345654e-6],
    );
    /// Royal target (pants, 65% cotton 35% polyester).
    pub const TWILL: Fabric = Fabric::measured(
        0.22,
        [2016.55456, 9.170511, 2034.97644, 104.759674],
        [125.409805e-6, 107.997696e-6, 125.409805e-6],
    );

    /// Every preset with its name in scene files.
    pub const PRESETS: [(&'static str, Fabric); 10] = [
        ("denim", Fabric::DENIM),
        ("interlock", Fabric::INTERLOCK),
        ("rib-knit", Fabric::RIB_KNIT),
        ("ponte", Fabric::PONTE),
        ("sweatshirt", Fabric::SWEATSHIRT),
        ("swimsuit", Fabric::SWIMSUIT),
        ("polyester", Fabric::POLYESTER),
        ("tablecloth", Fabric::TABLECLOTH),
        ("jacket", Fabric::JACKET),
        ("twill", Fabric::TWILL),
    ];

    /// A preset from an ARCSim material file's numbers (see the module doc): its density,
    /// the first stretching sample `[C11, C12, C22, C33]` as stored, and the first
    /// bending sample of each direction as stored.
    const fn measured(density: f32, stretching: [f32; 4], bending: [f32; 3]) -> Fabric {
        Fabric {
            areal_density: density,
            stretch: stretching[0] + stretching[2],
            shear: stretching[3],
            bending: (bending[0] + bending[1] + bending[2]) / 12.0,
        }
    }

    /// The preset called `name` (see [`Fabric::PRESETS`]).
    pub fn named(name: &str) -> Result<Fabric, ClothError> {
        Fabric::PRESETS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, f)| f)
            .ok_or_else(|| ClothError::UnknownFabric {
                name: name.to_string(),
            })
    }

    /// The name of the preset this fabric is, if it is one.
    pub fn name(&self) -> Option<&'static str> {
        Fabric::PRESETS
            .iter()
            .find(|(_, f)| f == self)
            .map(|&(n, _)| n)
    }

    /// Peirce's bending length `c = (B / (ρ_A g))^(1/3)`, m: half the overhang at which
    /// a strip's tip falls to 41.5° in the cantilever test (ASTM D1388).
    pub fn bending_length(&self, g: f32) -> f32 {
        (self.bending / (self.areal_density * g)).cbrt()
    }

    /// The spring stiffnesses of a square grid of this fabric, N/m, whatever its spacing:
    /// `(structural, shear)`. On a square lattice with diagonal springs, a stretch `ε`
    /// along a row stores `½ (k_s + k_d) ε²` per area and a shear `γ` stores `½ k_d γ²`,
    /// so `k_d = G` and `k_s = Y − G`. A fabric softer in stretch than twice in shear
    /// (a knit's `Y < 2G`) keeps `k_d = Y/2`: its shear is then softer than measured.
    pub fn grid_springs(&self) -> (f32, f32) {
        let shear = self.shear.min(0.5 * self.stretch);
        (self.stretch - shear, shear)
    }

    /// Checks every value is positive and finite.
    pub fn validate(&self) -> Result<(), ClothError> {
        check(
            "fabric.areal_density",
            self.areal_density,
            self.areal_density > 0.0 && self.areal_density <= 1e3,
            "a density above 0, at most 1,000 kg/m²",
        )?;
        for (field, value) in [
            ("fabric.stretch", self.stretch),
            ("fabric.shear", self.shear),
        ] {
            check(
                field,
                value,
                value > 0.0 && value <= crate::limits::MAX_STIFFNESS,
                format!(
                    "a stiffness above 0, at most {:e} N/m (limits::MAX_STIFFNESS)",
                    crate::limits::MAX_STIFFNESS
                ),
            )?;
        }
        check(
            "fabric.bending",
            self.bending,
            (0.0..=1.0).contains(&self.bending),
            "a bending rigidity from 0 to 1 N·m",
        )
    }
}

impl Default for Fabric {
    /// The T-shirt knit ([`Fabric::INTERLOCK`]).
    fn default() -> Self {
        Fabric::INTERLOCK
    }
}

/// A fabric in a scene file: a preset's name (`fabric: Some("denim")`) or the numbers.
#[derive(Deserialize)]
#[serde(untagged)]
enum FabricSpec {
    Named(String),
    Measured(MeasuredFabric),
}

/// A fabric's numbers in a scene file, every one of them and no other key (a misspelt
/// key is refused, not dropped).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeasuredFabric {
    areal_density: f32,
    stretch: f32,
    shear: f32,
    bending: f32,
}

impl TryFrom<FabricSpec> for Fabric {
    type Error = ClothError;

    fn try_from(spec: FabricSpec) -> Result<Self, ClothError> {
        match spec {
            FabricSpec::Named(name) => Fabric::named(&name),
            FabricSpec::Measured(MeasuredFabric {
                areal_density,
                stretch,
                shear,
                bending,
            }) => Ok(Fabric {
                areal_density,
                stretch,
                shear,
                bending,
            }),
        }
    }
}
