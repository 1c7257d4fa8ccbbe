//! `ClothSolver` tests, one file per concern, in one test binary.

#[path = "../common/mod.rs"]
mod common;

mod analytic;
mod budget;
mod kernels;
mod stability;
mod structure;
mod wind;
