//! Every limit on a size, count or repetition that comes from a file, a flag or the
//! inspector, in one place (README, *Limits*). Each is checked before anything it sizes is
//! allocated or looped over, so bad input is refused in well under a second with a bounded
//! amount of memory.

/// Particles in one cloth (a grid, a garment after refinement, a mesh): 512² (about
/// 60 MB of solver state; a 256² curtain already takes ~15 ms a step on two cores).
pub const MAX_PARTICLES: usize = 1 << 18;

/// Nodes (0s and 1s) in one pattern file, and in one piece after refinement.
pub const MAX_PATTERN_NODES: usize = 1 << 20;

/// The largest refinement of a garment's patterns (`resolution`).
pub const MAX_RESOLUTION: u32 = 64;

/// Bytes of one scene, garment or pattern file (read whole).
pub const MAX_FILE_BYTES: u64 = 16 << 20;

/// Substeps of one step, fixed or the automatic count's cap (`substeps: Auto(max)`): the
/// accuracy study's references take up to ~20,000.
pub const MAX_SUBSTEPS: u32 = 1 << 16;

/// Strain-limiter sweeps per substep (fixed, or the cap with a tolerance).
pub const MAX_LIMITER_SWEEPS: u32 = 1 << 10;

/// Work of one step, particles × substeps: a fixed count over it is refused; an
/// automatic count is capped at it (and the cloth reports `under_resolved`). At ~50 ns
/// per particle-substep, about 3 s of one core per step.
pub const MAX_WORK_PER_STEP: u64 = 1 << 26;

/// Sweeps until within (`strain_limit_tolerance`) of one step of `substeps`: on average
/// [`LIMITER_SWEEPS_PER_SUBSTEP`] a substep, and at least [`MAX_LIMITER_SWEEPS`] (any one
/// substep may take its most). A limiter that cannot converge, fighting a collider or a
/// seam, took its 500 sweeps every substep: the T-shirt inside a capsule of radius 100 km
/// cost 503 ms a step at 36 substeps, 91 ms with this budget (`cloth run`, the median of
/// 50 steps, which now warn). Steps that converge are not cut: the T-shirt scene's own
/// (3.1 ms) and Maslova's corners on it (`tests/garment.rs`; 0.001 g at 100 and 25,000
/// N/m: 39 and 369 ms at 454 and 4,040 substeps, the same strain as without the budget).
/// At 32 sweeps a substep the 1 g, 100 N/m corner (12 substeps) ran out of it.
pub fn limiter_budget(substeps: u32) -> u32 {
    substeps
        .saturating_mul(LIMITER_SWEEPS_PER_SUBSTEP)
        .max(MAX_LIMITER_SWEEPS)
}

/// See [`limiter_budget`].
pub const LIMITER_SWEEPS_PER_SUBSTEP: u32 = 128;

/// Work of one step's fixed limiter sweeps, particles × substeps × sweeps (with a
/// tolerance the sweeps stop early and only [`MAX_LIMITER_SWEEPS`] applies).
pub const MAX_SWEEP_WORK_PER_STEP: u64 = 1 << 28;

/// Steps of one headless run (`cloth run --steps`): 44 hours of simulated time at 16 ms.
pub const MAX_STEPS: usize = 10_000_000;

/// Simulated seconds of one measured run (`cloth accuracy` / `cloth choose --seconds`).
pub const MAX_SECONDS: f32 = 3_600.0;

/// Gravity's magnitude, m/s² (100 g): past it nothing is cloth, and a float overflows
/// within a few steps.
pub const MAX_GRAVITY: f32 = 1_000.0;

/// Wind strength, N per particle (a 0.5 g particle then accelerates at 2·10⁶ m/s²).
pub const MAX_WIND: f32 = 1_000.0;

/// A particle's mass, kg: Maslova's range is 1e-6 to 1e-3; past these, forces and
/// accelerations leave `f32`'s range within a few steps.
pub const MIN_NODE_MASS: f32 = 1e-9;
/// See [`MIN_NODE_MASS`].
pub const MAX_NODE_MASS: f32 = 1e3;

/// A spring family's (or a pull's) stiffness, N/m (Maslova's stiffest is 25,000; XPBD
/// also takes `inf`).
pub const MAX_STIFFNESS: f32 = 1e9;

/// Spring damping and drag, N·s/m.
pub const MAX_DAMPING: f32 = 1e6;

/// A scene item's distance from the origin, m, and its rotation angles, degrees (finite).
pub const MAX_POSITION: f32 = 1e5;

/// A grid's or a garment's spacing between neighbouring particles, m.
pub const MAX_SPACING: f32 = 10.0;

/// Self-collision's distance, m, at least: 0.1 mm, thinner than any fabric. Far below
/// it, the contact grid over a cloth's box would need more cells than an `i32` counts
/// (a distance of 1e-9 m once overflowed it).
pub const MIN_SELF_COLLISION_DISTANCE: f32 = 1e-4;

/// Cloths in one scene, and colliders.
pub const MAX_SCENE_ITEMS: usize = 1 << 12;

use std::io::Read;

/// Reads a file whole, refusing one over [`MAX_FILE_BYTES`] without reading more than
/// that (a device such as `/dev/zero` reports no size and never ends).
pub(crate) fn read_file(path: &std::path::Path) -> std::io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(std::io::Error::other(format!(
            "the file is larger than the limit of {MAX_FILE_BYTES} bytes"
        )));
    }
    Ok(bytes)
}

/// A file's name as an error message shows it: on one line ([`escape_controls`]).
pub(crate) fn shown_path(path: &std::path::Path) -> String {
    escape_controls(&path.display().to_string())
}

/// `text` with its control characters (a newline in a mistyped path or piece name)
/// escaped, so an error message that quotes it stays on one line.
pub(crate) fn escape_controls(text: &str) -> String {
    let mut shown = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_control() {
            shown.extend(c.escape_default());
        } else {
            shown.push(c);
        }
    }
    shown
}

/// [`read_file`] as UTF-8 text.
pub(crate) fn read_text(path: &std::path::Path) -> std::io::Result<String> {
    String::from_utf8(read_file(path)?)
        .map_err(|_| std::io::Error::new(std::io::ErrorKind::InvalidData, "not UTF-8 text"))
}
/// The most automatic substeps a cloth of `particles` may take per step: its `max`,
/// lowered to keep particles × substeps within [`MAX_WORK_PER_STEP`] (at least 1).
pub(crate) fn auto_substeps_cap(particles: usize, max: u32) -> u32 {
    let budget = MAX_WORK_PER_STEP / (particles.max(1) as u64);
    max.min(budget.min(u32::MAX as u64) as u32).max(1)
}

/// Timed repeats of one measurement (`--repeats`).
pub const MAX_REPEATS: usize = 1_000;
