//! A storm: where each method fails in the weather a game has. The polyester flag of
//! `assets/scenes/flag.ron` (31 × 21 particles, 4 cm, its first column pinned by a pole)
//! in gusty air from calm to a gale, with self-collision off and on, for each model that
//! takes a fabric: mass-spring (its substeps from its stability bound), XPBD with accuracy
//! first (its substeps from its stretch target) and XPBD inside the plugin's default frame
//! budget. Each cell's cost, the substeps it took, its strain and whether it held together.
//!
//! The air blows along the flag with a tenth of its speed across it (at 5 m/s the
//! scene's own `(5, 0, 0.5)`), in the scene's gusts.

use bevy::math::Vec3;
use serde::Serialize;

use bevy_cloth::headless::SceneRun;
use bevy_cloth::params::Model;
use bevy_cloth::prelude::{ClothBudget, ClothScene};

/// The air speeds of the map, m/s: calm to a gale (Beaufort 8 begins at 17.2 m/s).
pub const WINDS: [f32; 6] = [0.0, 3.0, 5.0, 10.0, 15.0, 20.0];

/// How a cell's cloth is solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum StormModel {
    /// Mass-spring with the fabric's springs, at the substeps its stability bound asks.
    MassSpring,
    /// XPBD along lines with the fabric, at the substeps its accuracy target asks.
    Xpbd,
    /// XPBD inside [`ClothBudget::default`]: what a game gets from the plugin.
    XpbdBudget,
}

impl StormModel {
    /// Every model of the map, in the order of its tables.
    pub const ALL: [StormModel; 3] = [
        StormModel::MassSpring,
        StormModel::Xpbd,
        StormModel::XpbdBudget,
    ];

    /// The name in tables, charts and `--models`.
    pub const fn name(self) -> &'static str {
        match self {
            StormModel::MassSpring => "mass-spring",
            StormModel::Xpbd => "xpbd",
            StormModel::XpbdBudget => "xpbd-budget",
        }
    }
}

/// One cell of the storm: a model in one wind, self-collision off or on.
#[derive(Clone, Debug, Serialize)]
pub struct StormCell {
    /// The model.
    pub model: StormModel,
    /// The air's speed along the flag, m/s.
    pub wind: f32,
    /// Whether the flag kept apart from itself.
    pub self_collision: bool,
    /// Steps run.
    pub steps: usize,
    /// Median wall time of a step, ms (one thread).
    pub median_ms: f64,
    /// The slowest step, ms.
    pub max_ms: f64,
    /// The most substeps a step took.
    pub most_substeps: u32,
    /// Steps that gave accuracy to keep to the budget.
    pub steps_over_budget: usize,
    /// The largest structural strain at the end of any step.
    pub largest_strain: f32,
    /// Every step finite with no structural spring past
    /// [`WHOLE_STRAIN`](bevy_cloth::headless::WHOLE_STRAIN).
    pub whole: bool,
}

/// Runs `scene` (the flag) for `steps` steps as `model` in air of `wind` m/s along it,
/// self-collision `on` or off, on the calling thread's share of the pool (the caller
/// keeps it to one thread for timing).
pub fn cell(
    scene: &ClothScene,
    model: StormModel,
    wind: f32,
    on: bool,
    steps: usize,
) -> Result<StormCell, String> {
    let mut scene = scene.clone();
    let air = scene
        .environment
        .air
        .as_mut()
        .ok_or("the storm's scene has no air to blow")?;
    air.velocity = Vec3::new(wind, 0.0, 0.1 * wind);
    for entry in &mut scene.cloths {
        let params = &mut entry.cloth.params;
        params.self_collision.enabled = on;
        if model == StormModel::MassSpring {
            params.model = Model::MassSpring;
        }
    }
    let mut run = SceneRun::new(&scene).map_err(|e| e.to_string())?;
    if model == StormModel::XpbdBudget {
        run.budget = Some(ClothBudget::default());
    }
    let summary = run.run(steps, |_, _| {});
    let seen = summary
        .cloths
        .first()
        .ok_or("the storm's scene has no cloth")?;
    Ok(StormCell {
        model,
        wind,
        self_collision: on,
        steps,
        median_ms: summary.median_ms_per_step,
        max_ms: summary.max_ms_per_step,
        most_substeps: seen.most_substeps,
        steps_over_budget: seen.steps_over_budget,
        largest_strain: seen.largest_strain,
        whole: seen.whole,
    })
}
