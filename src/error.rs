//! Typed errors for bad input: they name what is wrong and never panic.

use std::borrow::Cow;

use bevy::reflect::Reflect;
use thiserror::Error;

/// What can be wrong with a cloth description.
///
/// (Reflected as an opaque value: an inspector shows it whole.)
#[derive(Clone, Debug, Error, PartialEq, Reflect)]
#[reflect(opaque, Debug, PartialEq, Clone)]
#[non_exhaustive]
pub enum ClothError {
    /// A number outside its allowed range (or not finite).
    #[error("`{field}` must be {expected}, got {value}")]
    InvalidParameter {
        /// The field, as written in a scene file.
        field: &'static str,
        /// The value given.
        value: f32,
        /// What is allowed (a limit's value taken from its constant in `limits`).
        expected: Cow<'static, str>,
    },
    /// A grid needs at least 2×2 particles to have a spring and a face.
    #[error("a grid cloth needs at least 2×2 particles, got {width}×{height}")]
    GridTooSmall {
        /// Particles across.
        width: u32,
        /// Particles down.
        height: u32,
    },
    /// A grid so large it would not fit in memory or in 32-bit indices.
    #[error("a grid of {width}×{height} particles is larger than the limit of {limit}")]
    GridTooLarge {
        /// Particles across.
        width: u32,
        /// Particles down.
        height: u32,
        /// The largest particle count allowed.
        limit: usize,
    },
    /// A step's work (particles × substeps, or × fixed limiter sweeps) over its limit
    /// (see [`crate::limits`]).
    #[error(
        "`{field}`: {particles} particles × {per_particle} per step is over the limit of {limit} (limits.rs; fewer substeps or sweeps, or a smaller cloth)"
    )]
    TooMuchWork {
        /// The field to lower.
        field: &'static str,
        /// Particles of the cloth.
        particles: usize,
        /// Substeps (or substeps × sweeps) per step.
        per_particle: u64,
        /// The limit.
        limit: u64,
    },
    /// A pin names a particle that does not exist.
    #[error("`pins`: pin index {index} is out of range: the cloth has {count} particles")]
    PinOutOfRange {
        /// The pin index given.
        index: u32,
        /// How many particles the cloth has.
        count: usize,
    },
    /// An attachment that holds none of the cloth's particles (every index past the cloth,
    /// no garment run of its name, or a count of 0): the cloth would fall instead of
    /// hanging, so it is not simulated until its attachments change.
    #[error(
        "`ClothAttachments[{attachment}].particles`: {reason}; the cloth is not simulated until its attachments change"
    )]
    AttachmentHoldsNothing {
        /// The attachment's place in `ClothAttachments`.
        attachment: usize,
        /// What it asked for, and what the cloth has.
        reason: String,
    },
    /// A mesh given as a cloth has no usable triangles or positions.
    #[error("the mesh cannot be a cloth: {reason}")]
    BadMesh {
        /// What is missing.
        reason: String,
    },
    /// A layout (particles, springs, triangles, pieces) the solver cannot build from.
    #[error("the layout cannot be a cloth: {reason}")]
    BadLayout {
        /// What is wrong.
        reason: String,
    },
    /// A model that needs a grid (the patch model: its parts are blocks of rows and
    /// columns) was given a cloth without one.
    #[error("the {model} model needs a grid cloth")]
    ModelNeedsGrid {
        /// The model.
        model: &'static str,
    },
    /// A feature the model does not have was switched on.
    #[error("the {model} model has no {feature}: use xpbd or mass-spring")]
    ModelLacks {
        /// The model.
        model: &'static str,
        /// The feature.
        feature: &'static str,
    },
    /// A shape that is laid out from data it does not hold itself (a mesh from the
    /// entity's `Mesh3d`, a garment from its file) was asked for its layout directly.
    #[error("a {shape} cloth is laid out from its {source_of}")]
    ShapeNeedsSource {
        /// The shape.
        shape: &'static str,
        /// Where its layout comes from.
        source_of: &'static str,
    },
    /// A component that paints a mesh's vertices (a maximum distance, a back stop) was
    /// put on a cloth that is not made of a mesh.
    #[error(
        "`{component}` paints a mesh's vertices: it needs a cloth made of a mesh (`Cloth::from_mesh`)"
    )]
    PaintNeedsMesh {
        /// The component.
        component: &'static str,
    },
    /// A garment whose patterns give no faces.
    #[error("the garment has no faces")]
    EmptyGarment,
    /// A model name that is none of the known ones.
    #[error("no model `{name}`; known: {known}")]
    UnknownModel {
        /// The name given.
        name: String,
        /// The names that exist.
        known: &'static str,
    },
    /// A fabric preset name that does not exist.
    #[error(
        "unknown fabric {name:?}: the presets are denim, interlock, rib-knit, ponte, sweatshirt, swimsuit, polyester, tablecloth, jacket, twill"
    )]
    UnknownFabric {
        /// The name given.
        name: String,
    },
    /// A fabric was given to a cloth with no triangles (a rope or a lattice of springs):
    /// its masses and bending come from the triangles' areas.
    #[error("a fabric needs a cloth with triangles (its masses and bending come from their areas)")]
    FabricNeedsSurface,
    /// A step would have left a position or velocity non-finite (an absurd parameter,
    /// force or edit): the cloth kept the state it had before that step, and is paused
    /// until it is reset or its parameters change.
    #[error(
        "the step at t = {time} s ({substeps} substeps) went non-finite; the cloth keeps its last good state until it is reset or its parameters change"
    )]
    NonFinite {
        /// The simulated time the failed step started at, s.
        time: f32,
        /// Its substeps.
        substeps: u32,
    },
    /// A measurement asked of a case it cannot measure (the lab's instruments).
    #[error("cannot measure: {reason}")]
    NotMeasurable {
        /// Why.
        reason: String,
    },
    /// A pattern file is malformed (names the file, line and column).
    #[error("{0}")]
    Pattern(#[from] crate::layout::pattern::PatternError),
    /// A garment file is malformed, or its pieces and seams do not fit together.
    #[error("{file}:{line}:{column}: {}", crate::limits::escape_controls(message))]
    Garment {
        /// The garment file.
        file: String,
        /// 1-based line (of the piece or seam at fault, when known).
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        message: String,
    },
}
