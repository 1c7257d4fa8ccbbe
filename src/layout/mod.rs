//! What a cloth is made from, one layer above the solver: shapes (grids) and pins, 0/1
//! pattern files and garment files (also as a Bevy asset). Each becomes a
//! [`crate::solver::Layout`] and pin indices; meshes do too, through
//! [`crate::solver::Layout::from_mesh`].

pub mod garment;
pub mod pattern;
pub mod shape;
