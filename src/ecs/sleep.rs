//! Sleeping: a still cloth skips its steps until something can move it.

use bevy::prelude::*;

use crate::ecs::cloth::{ClothEnvironment, ClothInvalid, ClothSimulation};
use crate::ecs::events::{ClothAwoke, ClothFellAsleep};
use crate::ecs::stats::ClothStats;
use crate::ecs::step::StepProgress;
use crate::params::Environment;

/// Sleeping: a cloth whose every free particle moves slower than `speed` for
/// `after` seconds falls asleep: its step is skipped and its mesh not rewritten. It wakes
/// within one step on anything that can move it: an edit of its parameters, a change of
/// gravity or wind (`ClothEnvironment`), its transform moving (the pins), a collider
/// changing within reach of it, a grab, drag, release, cut or reset (anything that calls
/// the solver's mutating tools), or a [`ClothWake`] message from the game. Added to every
/// [`Cloth`](crate::Cloth) by the plugin; `enabled: false` keeps a cloth always awake.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component, Default)]
pub struct ClothSleep {
    /// Whether this cloth may fall asleep.
    pub enabled: bool,
    /// The speed below which a particle counts as still, m/s.
    pub speed: f32,
    /// How long every particle must stay still before the cloth sleeps, s.
    pub after: f32,
    /// Whether it sleeps now (set by the plugin).
    pub asleep: bool,
    /// Simulated seconds it has been still (set by the plugin).
    pub still_for: f32,
}

impl Default for ClothSleep {
    /// 1 mm/s for 1 s.
    fn default() -> Self {
        Self {
            enabled: true,
            speed: 1e-3,
            after: 1.0,
            asleep: false,
            still_for: 0.0,
        }
    }
}

impl ClothSleep {
    /// A cloth that never sleeps.
    pub fn never() -> Self {
        Self {
            enabled: false,
            ..Self::default()
        }
    }

    /// Wakes it (and restarts the stillness count).
    pub fn wake(&mut self) {
        self.asleep = false;
        self.still_for = 0.0;
    }

    /// Counts a step of `dt` in which the fastest particle moved at `speed`; falls asleep
    /// once still for long enough. Returns whether it is asleep.
    pub fn observe(&mut self, speed: f32, dt: f32) -> bool {
        // A NaN speed counts as moving.
        let still = speed < self.speed;
        if !self.enabled || !still {
            self.wake();
            return false;
        }
        self.still_for += dt;
        self.asleep = self.still_for >= self.after;
        self.asleep
    }
}

/// Wakes a sleeping cloth (see [`ClothSleep`]): the game's own reason to move it.
#[derive(Message, Clone, Copy, Debug, PartialEq, Eq, Reflect)]
#[reflect(Debug, PartialEq)]
pub struct ClothWake(pub Entity);

/// Wakes the sleeping cloths that something may move (see [`ClothSleep`]): the solver's
/// own record of outside changes (parameters, frame, colliders within reach, tools), a
/// change of gravity or wind, a [`ClothWake`] message, or sleeping switched off.
fn wake_cloths(
    mut commands: Commands,
    env: Res<ClothEnvironment>,
    mut last_env: Local<Option<Environment>>,
    mut messages: MessageReader<ClothWake>,
    mut woken: Local<Vec<Entity>>,
    mut cloths: Query<(Entity, &mut ClothSimulation, &mut ClothSleep)>,
) {
    let env_changed = last_env.is_some_and(|last| last != **env);
    *last_env = Some(**env);
    // Kept between steps for its storage: no allocation once grown.
    woken.clear();
    woken.extend(messages.read().map(|m| m.0));
    for (entity, mut sim, mut sleep) in &mut cloths {
        // Read by every step, so a disturbance is never left over for later.
        let disturbed = sim.bypass_change_detection().solver.take_disturbed();
        if sleep.asleep && (disturbed || env_changed || !sleep.enabled || woken.contains(&entity)) {
            // `ClothStats::asleep` follows at the step this lets run.
            sleep.wake();
            commands.trigger(ClothAwoke { entity });
        }
    }
}

/// Sleeping ([`ClothSleep`], added to every cloth): a still cloth skips its steps, and
/// wakes on whatever can move it.
pub struct ClothSleepPlugin;

impl Plugin for ClothSleepPlugin {
    fn build(&self, app: &mut App) {
        let schedule = crate::ecs::plugin::ClothSchedule::of(app);
        // Every cloth can sleep (a game turns it off per cloth with `ClothSleep::never()`).
        app.register_required_components::<crate::Cloth, ClothSleep>()
            .register_type::<ClothSleep>()
            .register_type::<ClothWake>()
            .register_type::<ClothAwoke>()
            .register_type::<ClothFellAsleep>()
            .add_message::<ClothWake>()
            .add_systems(
                schedule,
                (
                    wake_cloths.in_set(crate::ecs::plugin::ClothPrepareSystems::Wake),
                    observe_sleep
                        .after(crate::ecs::step::finish_steps)
                        .in_set(crate::ClothSystems::Finish),
                ),
            );
    }
}

/// After each step: a cloth that stepped counts its fastest particle toward falling
/// asleep ([`ClothSleep::observe`]), and says so in its statistics.
#[allow(clippy::type_complexity)]
fn observe_sleep(
    mut commands: Commands,
    time: Res<Time>,
    mut cloths: Query<
        (
            Entity,
            &ClothSimulation,
            &StepProgress,
            &mut ClothSleep,
            Option<&mut ClothStats>,
        ),
        Without<ClothInvalid>,
    >,
) {
    for (entity, sim, progress, mut sleep, stats) in &mut cloths {
        if progress.substeps == 0 || !sim.solver.last_report().finite {
            continue;
        }
        let speed = if sleep.enabled {
            sim.solver.max_speed()
        } else {
            f32::INFINITY
        };
        let was_asleep = sleep.asleep;
        let asleep = sleep.observe(speed, time.delta_secs());
        if asleep && !was_asleep {
            commands.trigger(ClothFellAsleep { entity });
        }
        if let Some(mut stats) = stats {
            stats.asleep = asleep;
        }
    }
}
