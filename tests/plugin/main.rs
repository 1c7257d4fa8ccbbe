//! Headless App tests of `ClothPlugin` (MinimalPlugins, manual time, no window), one file per feature, in one test binary (one link of Bevy).

#[path = "../common/mod.rs"]
mod common;

mod attach;
mod budget;
mod building;
mod colliders;
mod culling;
mod drawing;
mod keys;
mod stepping;
mod wind;
