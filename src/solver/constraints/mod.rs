//! Constraints: what holds a cloth's particles to one another. XPBD's stretch and shear
//! (`xpbd.rs`, a mesh's kernel; `lattice/` a grid's, as stencil offsets over the lanes),
//! solved along lines exactly (`chains.rs`); bending (`bending.rs`); tethers
//! (`tethers.rs`). What holds it from outside (pins, attachments, motion constraints) is
//! in `drivers/`; what it touches, in `contact/`.

pub(super) mod bending;
pub(super) mod chains;
pub(super) mod lattice;
pub(super) mod tethers;
pub(super) mod xpbd;
