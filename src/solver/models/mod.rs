//! The models' own state: shape matching's clusters (Müller et al. 2005), the hybrid
//! patches (Sladović 2014) and a switch between models mid-run. Mass-spring and XPBD keep
//! theirs in `constraints/`; each model's step is in `steps/`.

pub mod patches;
pub mod shape_matching;
pub(super) mod switch;
