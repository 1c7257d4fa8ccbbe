//! `cloth choose`: the accuracy study ([`crate::accuracy`]) on the user's own
//! scene, and the configuration it asks for: the cheapest whose error against the
//! converged reference is within a budget, or the most accurate whose cost per step is
//! within a budget. The answer comes as `--set` overrides and as an edited copy of the
//! scene.

use bevy_cloth::params::{ClothParams, Model};

use crate::accuracy::Row;

/// What to choose for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Goal {
    /// The cheapest configuration whose error (RMS distance to the reference over the
    /// cloth's diagonal) is at most this.
    MaxError(f64),
    /// The most accurate configuration whose median cost per step is at most this many
    /// ms.
    BudgetMs(f64),
}

impl Goal {
    /// Whether a configuration that costs `ms_per_step` with `error` meets the goal.
    pub fn admits(self, ms_per_step: f64, error: f64) -> bool {
        match self {
            Goal::MaxError(budget) => error <= budget,
            Goal::BudgetMs(budget) => ms_per_step <= budget,
        }
    }
}

/// The row of `rows` that `goal` picks (`None` when no measured row qualifies); a run
/// that failed has no time and no error and is never picked. `timestep`: the scene's
/// step, s, to turn a cost per simulated second into one per step.
pub fn pick(rows: &[Row], goal: Goal, timestep: f64) -> Option<usize> {
    let admitted = rows
        .iter()
        .enumerate()
        .filter_map(|(i, r)| Some((i, r.ms_per_second? * timestep, r.error?)))
        .filter(|&(_, ms, error)| goal.admits(ms, error));
    // Within an error: the cheapest. Within a cost: the most accurate.
    match goal {
        Goal::MaxError(_) => admitted.min_by(|a, b| a.1.total_cmp(&b.1)),
        Goal::BudgetMs(_) => admitted.min_by(|a, b| a.2.total_cmp(&b.2)),
    }
    .map(|(i, _, _)| i)
}

/// `--set` overrides that turn cloth `index`'s parameters into `chosen`: the model (its
/// variant, then each of its fields by reflection path), the integrator, the substeps
/// and the limiter's sweeps and tolerance.
pub fn overrides(index: usize, chosen: &ClothParams) -> Vec<String> {
    let at = |field: &str, value: String| format!("cloths[{index}].params.{field}={value}");
    let mut out = Vec::new();
    match chosen.model {
        Model::MassSpring => out.push(at("model", "MassSpring".into())),
        Model::ShapeMatching(sm) => {
            out.push(at("model", "ShapeMatching".into()));
            out.push(at("model.0.stiffness", sm.stiffness.to_string()));
            out.push(at("model.0.clusters", sm.clusters.to_string()));
            out.push(at("model.0.damping", sm.damping.to_string()));
        }
        Model::Patches(p) => {
            out.push(at("model", "Patches".into()));
            out.push(at("model.0.part_width", p.part_width.to_string()));
            out.push(at("model.0.part_height", p.part_height.to_string()));
            out.push(at("model.0.stiffness", p.stiffness.to_string()));
        }
        Model::Xpbd(x) => {
            out.push(at("model", "Xpbd".into()));
            out.push(at(
                "model.0.max_stretch_error",
                x.max_stretch_error.to_string(),
            ));
            out.push(at("model.0.tethers", x.tethers.to_string()));
        }
    }
    out.push(at("integrator", format!("{:?}", chosen.integrator)));
    out.push(at(
        "substeps",
        match chosen.substeps {
            bevy_cloth::params::Substeps::Fixed(n) => n.to_string(),
            bevy_cloth::params::Substeps::Auto { .. } => "auto".into(),
        },
    ));
    out.push(at(
        "strain_limit_iterations",
        chosen.strain_limit_iterations.to_string(),
    ));
    out.push(at(
        "strain_limit_tolerance",
        chosen
            .strain_limit_tolerance
            .map_or("none".into(), |t| t.to_string()),
    ));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(ms: Option<f64>, error: Option<f64>) -> Row {
        Row {
            scene: "s".into(),
            model: "mass-spring",
            label: String::new(),
            ms_per_second: ms,
            ms_range: ms.map(|m| (m, m)),
            substeps: 1.0,
            error,
            final_error: error,
            max_strain: 0.0,
            energy_drift: None,
            failed_at: None,
            pareto: false,
        }
    }

    #[test]
    fn the_cheapest_within_the_error_and_the_most_accurate_within_the_cost() {
        let rows = [
            row(Some(10.0), Some(3e-2)),
            row(Some(40.0), Some(1e-2)),
            row(Some(20.0), Some(1.5e-2)),
            row(None, None), // failed: never picked
            row(Some(5.0), Some(9e-2)),
        ];
        assert_eq!(pick(&rows, Goal::MaxError(2e-2), 0.016), Some(2));
        assert_eq!(pick(&rows, Goal::MaxError(1e-3), 0.016), None);
        // 0.5 ms per 16 ms step is 31.25 ms per simulated second.
        assert_eq!(pick(&rows, Goal::BudgetMs(0.5), 0.016), Some(2));
        assert_eq!(pick(&rows, Goal::BudgetMs(0.01), 0.016), None);
    }
}
