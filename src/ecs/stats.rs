//! Live statistics of a cloth, for inspectors and measurement.

use bevy::prelude::*;

use crate::params::Environment;
use crate::solver;

/// One sample of a cloth's statistics history.
#[derive(Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Debug, Default, PartialEq)]
pub struct StatSample {
    /// Simulated time, s.
    pub time: f32,
    /// Wall-clock time of that step, ms.
    pub step_ms: f32,
    /// Total energy after it, J.
    pub energy: f32,
}

/// Live statistics of a cloth, kept by the plugin when this component is present (it costs
/// one pass over the springs per step). For inspectors and measurement.
#[derive(Component, Clone, Debug, Default, Reflect)]
#[reflect(Component, Debug, Default)]
pub struct ClothStats {
    /// Particles.
    pub particles: usize,
    /// Acting springs.
    pub springs: usize,
    /// Springs torn since the last reset.
    pub torn: usize,
    /// Substeps in the last step.
    pub substeps: u32,
    /// True when automatic substeps hit their cap: the step may be unstable.
    pub under_resolved: bool,
    /// The substeps the last step needed (its accuracy target, or an explicit model's
    /// stable count), before any cap.
    pub needed_substeps: u32,
    /// True when the last step gave accuracy to keep to its frame budget
    /// ([`ClothBudget`](crate::ClothBudget)): it took fewer substeps than it needed.
    pub over_budget: bool,
    /// True when the cloth fell asleep at its last step (see [`ClothSleep`](crate::ClothSleep), which says
    /// whether it sleeps now): the other values are those of that step.
    pub asleep: bool,
    /// True while it is culled ([`ClothCulling`](crate::ClothCulling)): it takes no steps.
    pub culled: bool,
    /// Median step time over the last second of wall-clock steps, ms.
    pub step_ms_median: f32,
    /// Largest structural strain.
    pub max_strain: f32,
    /// Energies after the last step.
    pub energy: crate::solver::Energy,
    /// The last `HISTORY_SECONDS` of samples, oldest first.
    pub history: std::collections::VecDeque<StatSample>,
    #[reflect(ignore)]
    scratch: Vec<f32>,
}

impl ClothStats {
    /// Seconds of history kept.
    pub const HISTORY_SECONDS: f32 = 10.0;

    /// Records a finished step.
    pub fn record(&mut self, cloth: &solver::ClothSolver, env: &Environment, step_ms: f32) {
        self.particles = cloth.particle_count();
        self.springs = cloth.spring_count();
        self.torn = cloth.torn_count();
        self.substeps = cloth.substeps();
        self.under_resolved = cloth.under_resolved();
        self.needed_substeps = cloth.last_report().needed;
        self.over_budget = cloth.over_budget();
        self.max_strain = cloth.strain().max;
        self.energy = cloth.energy(env);
        let time = cloth.time();
        if self.history.back().is_some_and(|s| s.time > time) {
            self.history.clear(); // the cloth was reset
        }
        self.history.push_back(StatSample {
            time,
            step_ms,
            energy: self.energy.total(),
        });
        while self
            .history
            .front()
            .is_some_and(|s| s.time < time - Self::HISTORY_SECONDS)
        {
            self.history.pop_front();
        }
        self.scratch.clear();
        self.scratch.extend(
            self.history
                .iter()
                .rev()
                .take_while(|s| s.time >= time - 1.0)
                .map(|s| s.step_ms),
        );
        self.step_ms_median = crate::stats::median(&mut self.scratch);
    }
}
