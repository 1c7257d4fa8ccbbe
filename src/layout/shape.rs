//! What a cloth looks like before it moves: its shape and where it is pinned.

use bevy::math::{Affine3A, Vec3};
use bevy::reflect::Reflect;
use serde::{Deserialize, Serialize};

use crate::error::ClothError;
use crate::params::ClothParams;
use crate::solver::{self, Layout, MAX_PARTICLES, topology};

/// The initial layout of a cloth's particles.
#[derive(Clone, Debug, PartialEq, Reflect, Serialize, Deserialize)]
pub enum ClothShape {
    /// A `width × height` grid hanging in the local XY plane: particle `(i, j)` starts at
    /// `(i·spacing − (width−1)·spacing/2, −j·spacing, 0)`, so the local origin is the middle
    /// of the top edge (where a curtain rod would be). Sladović 2014 §3.2's construction.
    Grid {
        /// Particles across (i).
        width: u32,
        /// Particles down (j).
        height: u32,
        /// Distance between neighbours in m: the structural rest length.
        spacing: f32,
    },
    /// The vertices and triangles of the entity's own `Mesh3d`: each vertex becomes a
    /// particle, each edge a structural spring, and the two far corners of each pair of
    /// triangles sharing an edge a bend spring.
    Mesh,
    /// A garment: 0/1 pattern pieces stitched by seams (Maslova §1.4), from a garment file
    /// (see [`crate::layout::garment`]); the local origin is the garment file's origin.
    Garment {
        /// The garment file, relative to the `assets` folder (or absolute).
        file: String,
        /// 1 = the patterns as drawn; n = the same outline on an n-times finer grid.
        resolution: u32,
    },
}

impl Default for ClothShape {
    fn default() -> Self {
        ClothShape::Grid {
            width: 32,
            height: 32,
            spacing: 0.05,
        }
    }
}

impl ClothShape {
    /// The layout of a grid (Sladović 2014 §3.2's construction): particle `(i, j)` at
    /// `(i·spacing − (width−1)·spacing/2, −j·spacing, 0)`, structural, shear and bend
    /// springs, two triangles per cell. A mesh or a garment is laid out from its data
    /// ([`Layout::from_mesh`], [`crate::layout::garment::GarmentLayout::into_layout`]): an
    /// error here.
    pub fn layout(&self) -> Result<Layout, ClothError> {
        self.validate()?;
        match *self {
            ClothShape::Grid {
                width,
                height,
                spacing,
            } => {
                let half = (width - 1) as f32 * spacing * 0.5;
                let positions = (0..height)
                    .flat_map(|j| {
                        (0..width).map(move |i| {
                            Vec3::new(i as f32 * spacing - half, -(j as f32) * spacing, 0.0)
                        })
                    })
                    .collect();
                Ok(Layout {
                    positions,
                    springs: topology::grid_spring_pairs(width, height),
                    triangles: topology::grid_triangles(width, height),
                    grid: Some((width, height)),
                    pieces: Vec::new(),
                    runs: Vec::new(),
                })
            }
            ClothShape::Mesh => Err(ClothError::ShapeNeedsSource {
                shape: "mesh-shaped",
                source_of: "mesh (`Layout::from_mesh`)",
            }),
            ClothShape::Garment { .. } => Err(ClothError::ShapeNeedsSource {
                shape: "garment",
                source_of: "garment file (`GarmentLayout`)",
            }),
        }
    }

    /// The solver cloth of a grid shape, pinned by `pins`, placed by `frame`.
    pub fn build_solver(
        &self,
        pins: &ClothPins,
        params: &ClothParams,
        frame: Affine3A,
    ) -> Result<solver::ClothSolver, ClothError> {
        let layout = self.layout()?;
        let pins = pins.resolve_for(&layout)?;
        solver::ClothSolver::new(layout, &pins, params, frame)
    }

    /// Checks sizes; a grid smaller than 2×2 or with a bad spacing is an error.
    pub fn validate(&self) -> Result<(), ClothError> {
        if let ClothShape::Grid {
            width,
            height,
            spacing,
        } = *self
        {
            if width < 2 || height < 2 {
                return Err(ClothError::GridTooSmall { width, height });
            }
            if width as usize * height as usize > MAX_PARTICLES {
                return Err(ClothError::GridTooLarge {
                    width,
                    height,
                    limit: MAX_PARTICLES,
                });
            }
            if !(spacing > 0.0 && spacing <= crate::limits::MAX_SPACING) {
                return Err(ClothError::InvalidParameter {
                    field: "shape.spacing",
                    value: spacing,
                    expected: "a distance from 0 (excluded) to 10 m (limits::MAX_SPACING)".into(),
                });
            }
        }
        if let ClothShape::Garment { resolution, .. } = *self
            && !(1..=crate::layout::garment::MAX_RESOLUTION).contains(&resolution)
        {
            return Err(ClothError::InvalidParameter {
                field: "shape.resolution",
                value: resolution as f32,
                expected: "a resolution of 1 to 64".into(),
            });
        }
        Ok(())
    }
}

/// Which particles are held in place. Pinned particles follow the cloth's frame (for an
/// entity, its transform), so moving the frame moves the cloth.
#[derive(Clone, Debug, Default, PartialEq, Reflect, Serialize, Deserialize)]
pub enum ClothPins {
    /// Nothing is pinned: the cloth falls.
    None,
    /// The whole top row of a grid (j = 0).
    TopRow,
    /// The two top corners of a grid (Sladović 2014 fig. 5).
    TopCorners,
    /// The default: the top corners, as [`ClothPins::TopCorners`], unless the cloth's
    /// entity has [`ClothAttachments`](crate::ClothAttachments), then nothing (a cape held
    /// by its body is not also nailed to the world). Give the pins explicitly to keep
    /// both.
    #[default]
    Auto,
    /// Particles by index: `j·width + i` for a grid; for a cloth made of a mesh, the
    /// mesh's own vertex indices, each pinning the particle its vertex was welded into
    /// (the copies of a vertex along a UV seam are one particle).
    Indices(Vec<u32>),
}

impl ClothPins {
    /// The pins a cloth has: [`ClothPins::Auto`] is nothing when the cloth is `attached`
    /// to another entity and its top corners otherwise; the others are themselves
    /// (borrowed: the plugin compares them every step, and a list of indices is not copied
    /// for that).
    pub fn when_attached(&self, attached: bool) -> std::borrow::Cow<'_, ClothPins> {
        use std::borrow::Cow;
        match self {
            ClothPins::Auto if attached => Cow::Owned(ClothPins::None),
            ClothPins::Auto => Cow::Owned(ClothPins::TopCorners),
            pins => Cow::Borrowed(pins),
        }
    }

    /// The pinned particle indices of `layout` (see [`ClothPins::resolve`]).
    pub fn resolve_for(&self, layout: &Layout) -> Result<Vec<u32>, ClothError> {
        self.resolve(&layout.positions, layout.grid.map(|g| g.0))
    }

    /// The pinned particle indices. A grid of `grid_width` columns pins by row and column;
    /// a mesh (no grid) pins its highest vertices for `TopRow` and the leftmost and
    /// rightmost of those for `TopCorners`.
    pub fn resolve(
        &self,
        positions: &[Vec3],
        grid_width: Option<u32>,
    ) -> Result<Vec<u32>, ClothError> {
        let count = positions.len();
        let indices: Vec<u32> = match (self, grid_width) {
            (ClothPins::None, _) => Vec::new(),
            (ClothPins::TopRow, Some(w)) => (0..w).collect(),
            (ClothPins::TopCorners | ClothPins::Auto, Some(w)) => vec![0, w - 1],
            (ClothPins::TopRow | ClothPins::TopCorners | ClothPins::Auto, None) => {
                let top = positions
                    .iter()
                    .map(|p| p.y)
                    .fold(f32::NEG_INFINITY, f32::max);
                let eps = 1e-4 * (1.0 + top.abs());
                let row: Vec<u32> = (0..count as u32)
                    .filter(|&i| positions[i as usize].y >= top - eps)
                    .collect();
                if matches!(self, ClothPins::TopCorners | ClothPins::Auto) && row.len() > 2 {
                    let by_x = |a: &&u32, b: &&u32| {
                        positions[**a as usize]
                            .x
                            .total_cmp(&positions[**b as usize].x)
                    };
                    let left = *row.iter().min_by(by_x).expect("row is not empty");
                    let right = *row.iter().max_by(by_x).expect("row is not empty");
                    vec![left, right]
                } else {
                    row
                }
            }
            (ClothPins::Indices(list), _) => list.clone(),
        };
        if let Some(&index) = indices.iter().find(|&&i| i as usize >= count) {
            return Err(ClothError::PinOutOfRange { index, count });
        }
        Ok(indices)
    }
}
