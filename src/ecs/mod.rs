//! The Bevy layer: the cloth components, `ClothPlugin` with its system sets and systems,
//! the render mesh written in place, and the opt-in keyboard controls. It owns each
//! solver inside a component and knows nothing of how a layout is made.

#[cfg(feature = "avian")]
pub mod avian;
pub mod components;
pub mod controls;
pub mod mesh;
pub mod plugin;
