//! `ClothPlugin`: the thin ECS layer over the solver, as a group of one plugin per
//! feature, each in its own file with its components, systems and registrations:
//! the core here (the cloth, its building and stepping, the events), garments as assets
//! (`build.rs`), colliders (`colliders.rs`), attachments (`attach.rs`), motion
//! constraints from skinned meshes (`skin.rs`), sleeping (`sleep.rs`), level of detail
//! (`lod.rs`), culling (`culling.rs`), wind zones (`wind.rs`), proxy meshes (`proxy.rs`), the mesh write-back (`mesh.rs`) and, with the `avian` feature, avian's
//! bodies (`avian.rs`, added by the game). A game leaves a feature out with
//! `ClothPlugin::default().build().disable::<ClothLodPlugin>()`.
//!
//! In the simulation schedule (`FixedPostUpdate` by default, at the game's fixed rate):
//! ```text
//! ClothSystems::Prepare      in the order of ClothPrepareSystems: level of detail, build /
//!                            rebuild cloths and apply edited parameters, attachments,
//!                            skinned bodies, colliders and wind zones, waking, begin
//!                            each cloth's step
//! ClothSystems::Substeps     run the ClothSubstep schedule N times, which holds
//!     ClothSubstepSystems::AccumulateForces → Integrate → FitTargets → Constrain
//! ClothSystems::Finish       end each step: tearing, statistics, events; then sleep
//! ```
//! and in `PostUpdate`, once per frame after the fixed loop, `ClothSystems::WriteMesh`
//! writes positions and normals into each cloth's mesh buffers in place, drawn between
//! the last two fixed steps by `Time<Fixed>`'s overstep ([`ClothInterpolation`]).
//!
//! A substep schedule (as avian's `SubstepSchedule`) makes each phase a real system set
//! that runs every substep, so a game can add its own forces in a system ordered
//! `.after(ClothSubstepSystems::AccumulateForces).before(ClothSubstepSystems::Integrate)` in
//! [`ClothSubstep`](crate::ClothSubstep).

use std::time::Duration;

use bevy::app::PluginGroupBuilder;
use bevy::ecs::intern::Interned;
use bevy::ecs::schedule::ScheduleLabel;
use bevy::prelude::*;

use crate::ecs::attach::ClothAttachPlugin;
use crate::ecs::budget::ClothBudgetPlugin;
use crate::ecs::build::{ClothGarmentPlugin, build_cloths};
use crate::ecs::cloth::{
    Cloth, ClothEnvironment, ClothInterpolation, ClothInvalid, ClothPause, ClothSimulation,
};
use crate::ecs::colliders::ClothCollidersPlugin;
use crate::ecs::culling::ClothCullingPlugin;
use crate::ecs::events::{
    ClothBecameInvalid, ClothBuilt, ClothTeleport, ClothTeleported, ClothTorn,
};
use crate::ecs::lod::ClothLodPlugin;
use crate::ecs::mesh::ClothMeshPlugin;
use crate::ecs::proxy::ClothProxyPlugin;
use crate::ecs::skin::ClothSkinPlugin;
use crate::ecs::sleep::ClothSleepPlugin;
use crate::ecs::stats::{ClothStats, StatSample};
use crate::ecs::step::{
    ClothSubstepPlan, begin_steps, finish_steps, recover_cloths, request_teleports, run_substeps,
    substep_schedule,
};
use crate::ecs::wind::ClothWindPlugin;
use crate::layout::shape::{ClothPins, ClothShape};
use crate::params::{
    Air, ClothParams, Environment, GoalUpdate, Integrator, Model, PatchParams, PatchTargets,
    RotationMethod, SelfCollision, ShapeMatchingParams, SpringFamily, SpringParams, Substeps, Wind,
    WindField, XpbdParams, XpbdSolve,
};

/// The ordered system sets of the cloth simulation in the plugin's schedule (and, for
/// [`ClothSystems::WriteMesh`], `PostUpdate`).
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ClothSystems {
    /// Build new cloths, rebuild changed ones, apply parameter edits, move pins
    /// ([`ClothPrepareSystems`] orders its parts).
    Prepare,
    /// Run the [`ClothSubstep`](crate::ClothSubstep) schedule as many times as the cloths need.
    Substeps,
    /// End each step ([`ClothSolver::end_step`](crate::solver::ClothSolver::end_step)):
    /// tear over-stretched springs and report them, record step time; a cloth whose
    /// step went non-finite keeps its last good state and gets [`ClothInvalid`].
    Finish,
    /// (In `PostUpdate`) write positions and normals into the meshes.
    WriteMesh,
}

/// The parts of [`ClothSystems::Prepare`], in the order they run; each feature's plugin
/// puts its systems in its part.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ClothPrepareSystems {
    /// Level of detail picks each cloth's model ([`ClothLodPlugin`]); culled cloths are
    /// marked ([`ClothCullingPlugin`]).
    Levels,
    /// New cloths are built, changed ones rebuilt, edited parameters applied.
    Build,
    /// Attached particles follow their bodies ([`ClothAttachPlugin`]).
    Attach,
    /// Skinned bodies move their cloths' motion constraints ([`ClothSkinPlugin`]).
    Skin,
    /// The colliders are placed and given to the cloths ([`ClothCollidersPlugin`]), and
    /// the wind zones that reach each cloth ([`ClothWindPlugin`]).
    Colliders,
    /// Sleeping cloths that something may move wake ([`ClothSleepPlugin`]).
    Wake,
    /// Each cloth's step begins.
    Begin,
}

/// Adds cloth simulation to an app: a group of one plugin per feature (see the module
/// docs); each can be left out with `ClothPlugin::default().build().disable::<…>()`.
///
/// ```no_run
/// use bevy::prelude::*;
/// use bevy_cloth::prelude::*;
/// App::new()
///     .add_plugins((DefaultPlugins, ClothPlugin::default()))
///     .add_systems(Startup, |mut commands: Commands| {
///         commands.spawn((Cloth::grid(32, 32, 0.05), Transform::from_xyz(0.0, 2.0, 0.0)));
///     })
///     .run();
/// ```
#[derive(Clone, Copy, Debug)]
pub struct ClothPlugin {
    /// The schedule the simulation steps in.
    pub schedule: Interned<dyn ScheduleLabel>,
    /// When set, `Time<Fixed>` is set to this period ([`ClothPlugin::with_timestep`]);
    /// `None` (the default) leaves the game's fixed rate alone.
    pub timestep: Option<Duration>,
}

impl Default for ClothPlugin {
    /// Steps in `FixedPostUpdate` (after the game's `FixedUpdate` systems have moved its
    /// bodies and characters), at the game's fixed rate (`Time<Fixed>`, which the plugin
    /// does not change; Bevy's default is 64 Hz). The same with or without the `avian`
    /// feature: with avian, add `ClothAvianPlugin`, which orders the cloth after avian's
    /// step in that schedule.
    fn default() -> Self {
        Self::new(FixedPostUpdate)
    }
}

impl ClothPlugin {
    /// Steps cloths in `schedule` (its `Time` delta is the step) and leaves `Time<Fixed>`.
    ///
    /// `ClothPlugin::new(PostUpdate)` steps once a frame, by the frame's time, after
    /// Bevy's animation has posed the joints and the transforms are propagated: the
    /// choice for cloth on a character animated by an `AnimationClip`, whose skin is then
    /// read in the pose it is drawn in (on the fixed clock it would be read a frame
    /// late, as the animation runs after the fixed steps).
    pub fn new(schedule: impl ScheduleLabel) -> Self {
        Self {
            schedule: schedule.intern(),
            timestep: None,
        }
    }

    /// Also sets the app's fixed timestep (`Time<Fixed>`, which every `FixedUpdate`
    /// system and avian follow) to `timestep`; the examples ask for 16 ms, the step of
    /// the thesis's measurements.
    pub fn with_timestep(mut self, timestep: Duration) -> Self {
        self.timestep = Some(timestep);
        self
    }
}

impl PluginGroup for ClothPlugin {
    fn build(self) -> PluginGroupBuilder {
        PluginGroupBuilder::start::<Self>()
            .add(ClothCorePlugin {
                schedule: self.schedule,
                timestep: self.timestep,
            })
            .add(ClothGarmentPlugin)
            .add(ClothLodPlugin)
            .add(ClothCullingPlugin)
            .add(ClothAttachPlugin)
            .add(ClothSkinPlugin)
            .add(ClothCollidersPlugin)
            .add(ClothSleepPlugin)
            .add(ClothWindPlugin)
            .add(ClothMeshPlugin)
            .add(ClothProxyPlugin)
            .add(ClothBudgetPlugin)
    }
}

/// The core of [`ClothPlugin`]: the cloth, its parameters, building and stepping, the
/// substep schedule, pausing, statistics and the events; the system sets the feature
/// plugins put their systems in. The other plugins of the group need it.
pub struct ClothCorePlugin {
    /// The schedule the simulation steps in.
    pub schedule: Interned<dyn ScheduleLabel>,
    /// `Time<Fixed>`'s period to set, if any.
    pub timestep: Option<Duration>,
}

impl Plugin for ClothCorePlugin {
    fn build(&self, app: &mut App) {
        if let Some(step) = self.timestep {
            app.insert_resource(Time::<Fixed>::from_duration(step));
        }
        app.insert_resource(ClothSchedule(self.schedule));
        // Drawn between fixed steps only when the steps are fixed ones.
        let fixed = [
            FixedFirst.intern(),
            FixedPreUpdate.intern(),
            FixedUpdate.intern(),
            FixedPostUpdate.intern(),
            FixedLast.intern(),
        ];
        app.insert_resource(ClothInterpolation(fixed.contains(&self.schedule)));
        register_types(app);
        app.init_resource::<ClothEnvironment>()
            .init_resource::<ClothPause>()
            .init_resource::<ClothSubstepPlan>()
            .add_message::<ClothTorn>()
            .add_message::<ClothTeleport>()
            .add_observer(crate::ecs::cloth::log_invalid);

        app.add_schedule(substep_schedule());
        // Stepping in `PostUpdate` is stepping after the frame's animation: the step
        // begins once Bevy's animation and transform propagation have posed the joints
        // (what a skinned cloth and its bone colliders read) and ends before the meshes
        // are written, so a cloth is drawn with the pose of the frame it is drawn in, as
        // game engines run cloth after animation.
        if self.schedule == PostUpdate.intern() {
            app.configure_sets(
                PostUpdate,
                (
                    ClothSystems::Prepare.after(TransformSystems::Propagate),
                    ClothSystems::Finish.before(ClothSystems::WriteMesh),
                ),
            );
        }

        configure_sets(app, self.schedule);
    }
}

/// The core's system sets in `schedule` and its systems in them: Prepare (in the order of
/// [`ClothPrepareSystems`]), Substeps, Finish.
fn configure_sets(app: &mut App, schedule: Interned<dyn ScheduleLabel>) {
    use ClothPrepareSystems as P;
    app.configure_sets(
        schedule,
        (
            ClothSystems::Prepare,
            ClothSystems::Substeps,
            ClothSystems::Finish,
        )
            .chain(),
    )
    .configure_sets(
        schedule,
        (
            P::Levels,
            P::Build,
            P::Attach,
            P::Skin,
            P::Colliders,
            P::Wake,
            P::Begin,
        )
            .chain()
            .in_set(ClothSystems::Prepare),
    )
    .add_systems(
        schedule,
        (
            build_cloths.in_set(P::Build),
            request_teleports.in_set(P::Colliders),
            (recover_cloths, begin_steps).chain().in_set(P::Begin),
            run_substeps.in_set(ClothSystems::Substeps),
            finish_steps.in_set(ClothSystems::Finish),
        ),
    );
}

/// The schedule the cloths step in (the plugin's), for plugins that add to the step.
#[derive(Resource, Clone, Copy, Debug)]
pub(crate) struct ClothSchedule(pub(crate) Interned<dyn ScheduleLabel>);

impl ClothSchedule {
    /// The schedule of the core plugin, which the feature plugins add their systems to.
    pub(crate) fn of(app: &App) -> Interned<dyn ScheduleLabel> {
        app.world()
            .get_resource::<ClothSchedule>()
            .expect("ClothCorePlugin comes first in ClothPlugin's group")
            .0
    }
}

/// Registers the core's parameter, shape, component, resource, message and event types
/// for reflection (the inspector, scene files); each feature plugin registers its own.
fn register_types(app: &mut App) {
    app.register_type::<Cloth>()
        .register_type::<ClothShape>()
        .register_type::<ClothPins>()
        .register_type::<ClothParams>()
        .register_type::<SpringParams>()
        .register_type::<SpringFamily>()
        .register_type::<Integrator>()
        .register_type::<Substeps>()
        .register_type::<Model>()
        .register_type::<ShapeMatchingParams>()
        .register_type::<PatchParams>()
        .register_type::<XpbdParams>()
        .register_type::<XpbdSolve>()
        .register_type::<SelfCollision>()
        .register_type::<PatchTargets>()
        .register_type::<RotationMethod>()
        .register_type::<GoalUpdate>()
        .register_type::<Environment>()
        .register_type::<Wind>()
        .register_type::<WindField>()
        .register_type::<Air>()
        .register_type::<ClothEnvironment>()
        .register_type::<ClothPause>()
        .register_type::<ClothInterpolation>()
        .register_type::<ClothSimulation>()
        .register_type::<ClothInvalid>()
        .register_type::<crate::error::ClothError>()
        .register_type::<ClothStats>()
        .register_type::<StatSample>()
        .register_type::<crate::solver::Energy>()
        .register_type::<ClothTorn>()
        .register_type::<ClothTeleport>()
        .register_type::<ClothTeleported>()
        .register_type::<crate::params::Teleport>()
        .register_type::<crate::params::TeleportMode>()
        .register_type::<ClothBecameInvalid>()
        .register_type::<ClothBuilt>();
}
