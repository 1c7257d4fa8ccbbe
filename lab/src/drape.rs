//! The drape test (Cusick 1968; BS 5058, ISO 9073-9's geometry): a circle of fabric 30 cm
//! across clamped level between two discs 18 cm across drapes under its own weight; its
//! drape coefficient is the share of the annulus its shadow still covers,
//! `DC = (A_shadow − A_disc) / (A_fabric − A_disc)`: 1 for a board, near 0 for a fabric
//! that hangs straight down.
//!
//! The circle is cut from a square grid centred on a particle (the particles within
//! 15 cm of the centre, the grid's triangles among them, its structural and shear
//! springs), the particles within 9 cm and half a cell pinned (the discs: a pinned ring's
//! hinges bend as if clamped half a cell inside it, `cantilever.rs`), and the fabric given by [`Fabric`]. XPBD at its automatic
//! substeps (with a fabric they keep its springs' and hinges' softening in bounds), a
//! drag rate of 5/s, 4 s from level. The shadow is the drawn triangles projected on the ground,
//! rasterised at 0.5 mm.

use bevy::math::{Affine3A, Quat, Vec3};
use serde::Serialize;

use bevy_cloth::fabric::Fabric;
use bevy_cloth::params::{ClothParams, Environment, Model, Substeps};
use bevy_cloth::solver::topology::{SpringKind, grid_spring_pairs, grid_triangles};
use bevy_cloth::solver::{ClothSolver, Layout};

/// The fabric circle's radius, m.
pub const FABRIC_RADIUS: f32 = 0.15;
/// The discs' radius, m.
pub const DISC_RADIUS: f32 = 0.09;
/// The shadow's pixel, m.
const PIXEL: f32 = 0.0005;

/// One drape measurement.
#[derive(Clone, Debug, Serialize)]
pub struct Drape {
    /// The preset's name.
    pub fabric: String,
    /// The grid spacing, m.
    pub spacing: f32,
    /// The substeps of the last step.
    pub substeps: u32,
    /// The drape coefficient (the specimens' mean).
    pub coefficient: f64,
    /// The specimens' least and greatest coefficient.
    pub spread: (f64, f64),
    /// The shadow's area, m².
    pub shadow: f64,
    /// The fabric's bending length `(B/(ρ_A g))^(1/3)`, m.
    pub bending_length: f32,
    /// The draped triangles projected on the ground, `(x, z)` corners, m.
    #[serde(skip)]
    pub outline: Vec<[(f32, f32); 3]>,
}

/// The circle of fabric: its layout (level, in the local xy plane) and the particles the
/// discs clamp.
pub fn circle(spacing: f32) -> (Layout, Vec<u32>) {
    // An odd side, so a particle sits at the centre and the cut is symmetric (an even
    // one moved denim's coefficient from 0.63 to 0.48 at 1 cm).
    let side = 2 * (FABRIC_RADIUS / spacing).round() as u32 + 1;
    let half = (side - 1) as f32 * spacing * 0.5;
    let at = |i: u32| {
        let (c, r) = (i % side, i / side);
        Vec3::new(c as f32 * spacing - half, r as f32 * spacing - half, 0.0)
    };
    let inside = |i: u32| at(i).length() <= FABRIC_RADIUS + 1e-6;
    // Grid index → kept particle index.
    let mut index = vec![u32::MAX; (side * side) as usize];
    let mut positions = Vec::new();
    for i in 0..side * side {
        if inside(i) {
            index[i as usize] = positions.len() as u32;
            positions.push(at(i));
        }
    }
    let kept = |i: u32| index[i as usize] != u32::MAX;
    let springs = grid_spring_pairs(side, side)
        .into_iter()
        .filter(|&(kind, a, b)| {
            matches!(kind, SpringKind::Structural | SpringKind::Shear) && kept(a) && kept(b)
        })
        .map(|(kind, a, b)| (kind, index[a as usize], index[b as usize]))
        .collect();
    let triangles = grid_triangles(side, side)
        .into_iter()
        .filter(|t| t.iter().all(|&i| kept(i)))
        .map(|t| t.map(|i| index[i as usize]))
        .collect();
    let clamped = positions
        .iter()
        .enumerate()
        .filter(|(_, x)| x.length() <= DISC_RADIUS + 0.5 * spacing + 1e-6)
        .map(|(i, _)| i as u32)
        .collect();
    let layout = Layout {
        positions,
        springs,
        triangles,
        ..Layout::default()
    };
    (layout, clamped)
}

/// Drapes `fabric` at grid `spacing` (m) with `model` and measures it.
///
/// A flat circle buckles into folds, and how many depends on what starts the buckling:
/// one specimen's coefficient moved by up to ±15% with the substep count. So, as the
/// standard tests three specimens, [`SPECIMENS`] specimens are draped, each starting
/// with its free particles lifted or lowered by up to 1 mm (a fixed pseudo-random pattern
/// per specimen), and the coefficient is their mean; `spread` is their range.
pub fn drape(name: &str, fabric: Fabric, spacing: f32, model: Model) -> Result<Drape, String> {
    let specimens = (0..SPECIMENS)
        .map(|k| specimen(name, fabric, spacing, model, k))
        .collect::<Result<Vec<_>, _>>()?;
    let coefficients: Vec<f64> = specimens.iter().map(|d| d.coefficient).collect();
    let lo = coefficients.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = coefficients
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let mean = coefficients.iter().sum::<f64>() / coefficients.len() as f64;
    let mut first = specimens.into_iter().next().ok_or("no specimen")?;
    first.coefficient = mean;
    first.spread = (lo, hi);
    Ok(first)
}

/// Specimens a drape coefficient is the mean of.
pub const SPECIMENS: u64 = 5;

/// One specimen of [`drape`]: `seed` picks its starting ripple.
fn specimen(
    name: &str,
    fabric: Fabric,
    spacing: f32,
    model: Model,
    seed: u64,
) -> Result<Drape, String> {
    let (layout, clamped) = circle(spacing);
    // The cut circle's own area (its edge is a staircase of cells, a few % short of πR²).
    let flat = shadow_area(&flat_outline(&layout));
    let params = ClothParams {
        model,
        fabric: Some(fabric),
        substeps: Substeps::Auto { max: 8192 },
        strain_limit: None,
        drag: 5.0 * fabric.areal_density * spacing * spacing,
        ..ClothParams::seeds()
    };
    // Level: the local xy plane turned to the ground's, 1 m up.
    let level = Affine3A::from_rotation_translation(
        Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
        Vec3::Y,
    );
    let mut cloth =
        ClothSolver::new(layout, &clamped, &params, level).map_err(|e| e.to_string())?;
    let p = cloth.particles_mut();
    for i in 0..p.len() {
        if p.inv_mass[i] > 0.0 {
            let lift = 0.001 * bevy_cloth::lab::unit_hash(i, seed);
            p.position[i].y += lift;
            p.previous[i].y += lift;
        }
    }
    let mut env = Environment::default();
    env.wind.strength = 0.0;
    for _ in 0..250 {
        cloth.step(0.016, &env);
    }
    if !cloth.is_stable() {
        return Err(format!("{name}: the drape went unstable"));
    }
    let x = cloth.positions();
    let outline: Vec<[(f32, f32); 3]> = cloth
        .triangles()
        .iter()
        .map(|t| t.map(|i| (x[i as usize].x, x[i as usize].z)))
        .collect();
    let shadow = shadow_area(&outline);
    let disc = std::f64::consts::PI * f64::from(DISC_RADIUS).powi(2);
    Ok(Drape {
        fabric: name.to_string(),
        spacing,
        substeps: cloth.substeps(),
        coefficient: (shadow - disc) / (flat - disc),
        spread: (0.0, 0.0),
        shadow,
        bending_length: fabric.bending_length(9.81),
        outline,
    })
}

/// The layout's triangles as they lie flat (local x, y).
fn flat_outline(layout: &Layout) -> Vec<[(f32, f32); 3]> {
    let x = &layout.positions;
    layout
        .triangles
        .iter()
        .map(|t| t.map(|i| (x[i as usize].x, x[i as usize].y)))
        .collect()
}

/// The area the triangles cover, m², counted on pixels of [`PIXEL`] (a pixel is covered
/// when its centre lies in a triangle).
pub fn shadow_area(triangles: &[[(f32, f32); 3]]) -> f64 {
    let reach = FABRIC_RADIUS + 0.01;
    let n = (2.0 * reach / PIXEL).ceil() as usize;
    let mut covered = vec![false; n * n];
    let pixel = |v: f32| ((v + reach) / PIXEL).floor();
    for t in triangles {
        let (lo_x, hi_x) = bounds(t.map(|p| p.0));
        let (lo_z, hi_z) = bounds(t.map(|p| p.1));
        let (i0, i1) = (
            pixel(lo_x).max(0.0) as usize,
            (pixel(hi_x) as usize).min(n - 1),
        );
        let (j0, j1) = (
            pixel(lo_z).max(0.0) as usize,
            (pixel(hi_z) as usize).min(n - 1),
        );
        for j in j0..=j1 {
            for i in i0..=i1 {
                let centre = (
                    (i as f32 + 0.5) * PIXEL - reach,
                    (j as f32 + 0.5) * PIXEL - reach,
                );
                if inside(t, centre) {
                    covered[j * n + i] = true;
                }
            }
        }
    }
    covered.iter().filter(|&&c| c).count() as f64 * f64::from(PIXEL).powi(2)
}

fn bounds(v: [f32; 3]) -> (f32, f32) {
    (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]))
}

/// Whether `p` lies in triangle `t` (either winding).
fn inside(t: &[(f32, f32); 3], p: (f32, f32)) -> bool {
    let side = |a: (f32, f32), b: (f32, f32)| (b.0 - a.0) * (p.1 - a.1) - (b.1 - a.1) * (p.0 - a.0);
    let (d0, d1, d2) = (side(t[0], t[1]), side(t[1], t[2]), side(t[2], t[0]));
    (d0 >= 0.0 && d1 >= 0.0 && d2 >= 0.0) || (d0 <= 0.0 && d1 <= 0.0 && d2 <= 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shadow_of_the_flat_circle_is_its_triangles_area() {
        let (layout, _) = circle(0.005);
        let outline = flat_outline(&layout);
        let area = shadow_area(&outline);
        let exact: f64 = outline
            .iter()
            .map(|t| {
                let (a, b, c) = (t[0], t[1], t[2]);
                0.5 * f64::from(((b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0)).abs())
            })
            .sum();
        assert!(
            (area / exact - 1.0).abs() < 0.01,
            "{area} m² against {exact}"
        );
        // The staircase edge of 5 mm cells loses a few % of the circle.
        let circle = std::f64::consts::PI * 0.15f64.powi(2);
        assert!(
            (exact / circle - 1.0).abs() < 0.04,
            "{exact} m² of {circle}"
        );
    }

    #[test]
    fn a_stiffer_fabric_drapes_wider() {
        // Knit, denim, twill: bending lengths 14.1, 18.3 and 24.0 mm (and rigidities
        // 5.2, 19.5 and 29.9 µN·m) in that order; their drape coefficients must follow.
        let xpbd = Model::Xpbd(bevy_cloth::params::XpbdParams {
            tethers: false,
            ..Default::default()
        });
        let dc = |f: Fabric| drape("", f, 0.01, xpbd).unwrap().coefficient;
        let (knit, denim, twill) = (dc(Fabric::INTERLOCK), dc(Fabric::DENIM), dc(Fabric::TWILL));
        assert!(
            0.0 < knit && knit < denim && denim < twill && twill < 1.0,
            "{knit} {denim} {twill}"
        );
    }
}
