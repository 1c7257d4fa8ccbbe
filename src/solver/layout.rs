//! What a solver cloth is built from: resolved plain data (particle positions, springs by
//! family, triangles, the grid size when there is one, garment pieces). Shapes, garment
//! files and meshes are turned into a [`Layout`] one layer up (`ClothShape::layout`,
//! `GarmentLayout::into_layout`, [`Layout::from_mesh`]); the solver never sees them.

use std::ops::Range;

use bevy::math::Vec3;

use super::topology::{self, SpringKind};
use crate::error::ClothError;

pub use crate::limits::MAX_PARTICLES;

/// Resolved plain data of a cloth, in its own (local) frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Layout {
    /// Particle rest (and start) positions.
    pub positions: Vec<Vec3>,
    /// Springs: `(family, a, b)`; rest lengths come from the positions.
    pub springs: Vec<(SpringKind, u32, u32)>,
    /// Triangles drawn (none for a rope or a lattice).
    pub triangles: Vec<[u32; 3]>,
    /// `(width, height)` when the particles are a row-major grid (the patch model needs it).
    pub grid: Option<(u32, u32)>,
    /// `(name, particle range)` of each garment piece; empty: one piece, `cloth`.
    pub pieces: Vec<(String, Range<u32>)>,
    /// `(name, particles)` of each named run of particles (a garment's `runs`).
    pub runs: Vec<(String, Vec<u32>)>,
}

impl Layout {
    /// A triangle mesh: vertices become particles (coincident ones welded into one, see
    /// [`topology::weld`]), edges structural springs, and the far corners of triangles
    /// sharing an edge bend springs. Triangles that welding collapses are dropped.
    pub fn from_mesh(positions: &[Vec3], triangles: &[[u32; 3]]) -> Result<Self, ClothError> {
        if positions.len() < 3 || triangles.is_empty() {
            return Err(ClothError::BadMesh {
                reason: format!(
                    "{} vertices and {} triangles; at least 3 and 1 are needed",
                    positions.len(),
                    triangles.len()
                ),
            });
        }
        check_positions(positions)?;
        if let Some(t) = triangles.iter().find(|t| {
            t.iter().any(|&v| v as usize >= positions.len())
                || t[0] == t[1]
                || t[1] == t[2]
                || t[0] == t[2]
        }) {
            return Err(ClothError::BadMesh {
                reason: format!("triangle {t:?} is degenerate or indexes past the vertices"),
            });
        }
        let welded = topology::weld(positions);
        let triangles: Vec<[u32; 3]> = triangles
            .iter()
            .map(|t| t.map(|v| welded.particle_of[v as usize]))
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
            .collect();
        if triangles.is_empty() {
            return Err(ClothError::BadMesh {
                reason: "every triangle collapses when coincident vertices are welded".into(),
            });
        }
        Ok(Self {
            springs: topology::mesh_spring_pairs(&triangles),
            positions: welded.positions,
            triangles,
            ..Self::default()
        })
    }

    /// Explicit structural springs between particles (ropes, single springs, custom
    /// lattices); no triangles, so nothing is drawn.
    pub fn from_springs(positions: &[Vec3], springs: &[[u32; 2]]) -> Result<Self, ClothError> {
        let layout = Self {
            positions: positions.to_vec(),
            springs: springs
                .iter()
                .map(|s| (SpringKind::Structural, s[0], s[1]))
                .collect(),
            ..Self::default()
        };
        layout.validate()?;
        Ok(layout)
    }

    /// Checks what the solver relies on: at least one particle and at most
    /// [`MAX_PARTICLES`], finite positions, springs and triangles between distinct
    /// particles that exist, a grid size that matches the particle count, pieces and runs inside.
    pub fn validate(&self) -> Result<(), ClothError> {
        let n = self.positions.len();
        if n == 0 {
            return Err(ClothError::BadLayout {
                reason: "the cloth has no particles".into(),
            });
        }
        check_positions(&self.positions)?;
        let exists = |i: u32| (i as usize) < n;
        if let Some((kind, a, b)) = self
            .springs
            .iter()
            .find(|&&(_, a, b)| a == b || !exists(a) || !exists(b))
        {
            return Err(ClothError::BadLayout {
                reason: format!("{kind:?} spring [{a}, {b}] joins a particle to itself or to none"),
            });
        }
        if let Some(t) = self
            .triangles
            .iter()
            .find(|t| !t.iter().all(|&v| exists(v)) || t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
        {
            return Err(ClothError::BadLayout {
                reason: format!("triangle {t:?} is degenerate or indexes past the particles"),
            });
        }
        if let Some((w, h)) = self.grid
            && w as usize * h as usize != n
        {
            return Err(ClothError::BadLayout {
                reason: format!("a {w}×{h} grid of {n} particles"),
            });
        }
        if let Some((name, range)) = self.pieces.iter().find(|(_, r)| r.end as usize > n) {
            return Err(ClothError::BadLayout {
                reason: format!("piece {name} ends at particle {} of {n}", range.end),
            });
        }
        if let Some((name, _)) = self
            .runs
            .iter()
            .find(|(_, particles)| particles.iter().any(|&i| !exists(i)))
        {
            return Err(ClothError::BadLayout {
                reason: format!("run {name} holds a particle past the {n} there are"),
            });
        }
        Ok(())
    }
}

/// At most [`MAX_PARTICLES`] positions, all finite.
fn check_positions(positions: &[Vec3]) -> Result<(), ClothError> {
    if positions.len() > MAX_PARTICLES {
        return Err(ClothError::BadMesh {
            reason: format!("{} vertices is more than the limit", positions.len()),
        });
    }
    if let Some(p) = positions.iter().find(|p| !p.is_finite()) {
        return Err(ClothError::BadMesh {
            reason: format!("a vertex position is not finite: {p}"),
        });
    }
    Ok(())
}
