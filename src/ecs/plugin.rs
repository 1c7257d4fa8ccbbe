//! `ClothPlugin`: the thin ECS layer over the solver.
//!
//! In the simulation schedule (`FixedUpdate` by default, 16 ms):
//! ```text
//! ClothSystems::Prepare      build / rebuild cloths, apply edited parameters, move pins
//! ClothSystems::Substeps     run the ClothSubstep schedule N times, which holds
//!     ClothSubstepSystems::AccumulateForces → Integrate → FitTargets → Constrain
//! ClothSystems::Finish       tearing (ClothTorn messages), step timing
//! ```
//! and in `PostUpdate`, once per frame after the fixed loop, `ClothSystems::WriteMesh`
//! writes positions and normals into each cloth's mesh buffers in place.
//!
//! A substep schedule (as avian's `SubstepSchedule`) makes each phase a real system set
//! that runs every substep, so a game can add its own forces in a system ordered
//! `.after(ClothSubstepSystems::AccumulateForces).before(ClothSubstepSystems::Integrate)` in
//! [`ClothSubstep`]. Each phase runs over all cloths in parallel.

use std::time::Duration;

use bevy::app::FixedUpdate;
use bevy::asset::{AssetEventSystems, AssetLoadError, LoadState};
use bevy::ecs::intern::Interned;
use bevy::ecs::schedule::{ScheduleLabel, SingleThreadedExecutor};
use bevy::platform::time::Instant;
use bevy::prelude::*;
use bevy::transform::helper::TransformHelper;

use crate::ecs::components::{
    AttachParticles, Cloth, ClothAttachments, ClothCollider, ClothEnvironment, ClothInvalid,
    ClothLod, ClothPause, ClothSimulation, ClothSleep, ClothStats, ClothTorn, ClothWake,
};
use crate::ecs::mesh::{MeshSource, cloth_mesh, mesh_triangles, write_mesh};
use crate::error::ClothError;
use crate::layout::garment::{Garment, GarmentLoader};
use crate::layout::shape::{ClothShape, Pins};
use crate::params::{
    ClothParams, Environment, GoalUpdate, Integrator, Model, PatchParams, RotationMethod,
    ShapeMatchingParams, SpringFamily, SpringParams, Substeps, Wind, WindField,
};
use crate::solver::{self, Layout};

/// The ordered system sets of the cloth simulation in the plugin's schedule (and, for
/// [`ClothSystems::WriteMesh`], `PostUpdate`).
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ClothSystems {
    /// Build new cloths, rebuild changed ones, apply parameter edits, move pins.
    Prepare,
    /// Run the [`ClothSubstep`] schedule as many times as the cloths need.
    Substeps,
    /// End each step ([`ClothSolver::end_step`](crate::solver::ClothSolver::end_step)):
    /// tear over-stretched springs and report them, record step time; a cloth whose
    /// step went non-finite keeps its last good state and gets [`ClothInvalid`].
    Finish,
    /// (In `PostUpdate`) write positions and normals into the meshes.
    WriteMesh,
}

/// The ordered system sets of one substep, in the [`ClothSubstep`] schedule only (a
/// system put in them in another schedule would never run with the cloth's substeps,
/// so they are a type of their own).
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ClothSubstepSystems {
    /// [`ClothSolver::accumulate_forces`](crate::solver::ClothSolver::accumulate_forces):
    /// every force from the old state (gravity, wind, drag; springs for mass-spring;
    /// the goal pull for shape matching; for the patch model, the part lattice's forces
    /// and the particles' pull toward their targets). Add forces after this set.
    AccumulateForces,
    /// [`ClothSolver::integrate`](crate::solver::ClothSolver::integrate): the prediction
    /// (Verlet or semi-implicit Euler; XPBD always the latter; the patch model's part
    /// lattice takes its whole substep here first).
    Integrate,
    /// [`ClothSolver::fit_targets`](crate::solver::ClothSolver::fit_targets): shape
    /// matching's velocity update, the patch model's targets (nothing for mass-spring
    /// and XPBD).
    FitTargets,
    /// [`ClothSolver::constrain`](crate::solver::ClothSolver::constrain): pins and grab
    /// driven, the model's constraints (Provot's limit; XPBD's projection and tethers),
    /// contact with the colliders; it ends the substep (the cloth's clock advances).
    Constrain,
}

/// The schedule run once per substep inside [`ClothSystems::Substeps`].
#[derive(ScheduleLabel, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ClothSubstep;

/// How many substeps this fixed step runs (the most any cloth needs) and which one is
/// running; each cloth takes part in the first `n` of them, `n` being its own count.
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct ClothSubstepPlan {
    /// Substeps to run in this step.
    pub count: u32,
    /// The substep running now.
    pub index: u32,
}

/// Adds cloth simulation to an app.
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
pub struct ClothPlugin {
    /// The schedule the simulation steps in.
    pub schedule: Interned<dyn ScheduleLabel>,
    /// When set, `Time<Fixed>` is set to this period ([`ClothPlugin::with_timestep`]);
    /// `None` (the default) leaves the game's fixed rate alone.
    pub timestep: Option<Duration>,
}

impl Default for ClothPlugin {
    /// Steps in `FixedUpdate` at the game's fixed rate (`Time<Fixed>`, which the plugin
    /// does not change; Bevy's default is 64 Hz); with the `avian` feature in
    /// `FixedPostUpdate` after avian's physics step, so the cloth meets the bodies (and
    /// follows the attachments) where that step put them, where they are drawn.
    fn default() -> Self {
        let schedule = if cfg!(feature = "avian") {
            FixedPostUpdate.intern()
        } else {
            FixedUpdate.intern()
        };
        Self {
            schedule,
            timestep: None,
        }
    }
}

impl ClothPlugin {
    /// Steps cloths in `schedule` (its `Time` delta is the step) and leaves `Time<Fixed>`.
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

impl Plugin for ClothPlugin {
    fn build(&self, app: &mut App) {
        if let Some(step) = self.timestep {
            app.insert_resource(Time::<Fixed>::from_duration(step));
        }
        // In avian's schedule, after its step (see `Default`).
        #[cfg(feature = "avian")]
        app.configure_sets(
            self.schedule,
            ClothSystems::Prepare.after(avian3d::prelude::PhysicsSystems::Last),
        );
        register_types(app);
        app.init_resource::<ClothEnvironment>()
            .init_resource::<ClothPause>()
            .init_resource::<ClothSubstepPlan>()
            .init_resource::<PlacedColliders>()
            .add_message::<ClothTorn>()
            .add_message::<ClothWake>()
            .init_asset::<Garment>()
            .register_asset_loader(GarmentLoader)
            .add_systems(Update, watch_garments);

        app.add_schedule(substep_schedule());

        app.configure_sets(
            self.schedule,
            (
                ClothSystems::Prepare,
                ClothSystems::Substeps,
                ClothSystems::Finish,
            )
                .chain(),
        )
        .add_systems(
            self.schedule,
            (
                (
                    choose_levels,
                    build_cloths,
                    attach_cloths,
                    place_colliders,
                    wake_cloths,
                    recover_cloths,
                    begin_steps,
                )
                    .chain()
                    .in_set(ClothSystems::Prepare),
                run_substeps.in_set(ClothSystems::Substeps),
                finish_steps.in_set(ClothSystems::Finish),
            ),
        )
        .add_systems(
            PostUpdate,
            write_meshes
                .in_set(ClothSystems::WriteMesh)
                .before(AssetEventSystems),
        );
        #[cfg(feature = "avian")]
        app.add_systems(
            self.schedule,
            push_back_bodies
                .after(finish_steps)
                .in_set(ClothSystems::Finish),
        );
    }
}

/// The [`ClothSubstep`] schedule: the four stages in their sets, in order, on one thread
/// (each stage runs its cloths in parallel itself).
fn substep_schedule() -> Schedule {
    let mut substep = Schedule::new(ClothSubstep);
    substep.set_executor(SingleThreadedExecutor::new());
    substep.configure_sets(
        (
            ClothSubstepSystems::AccumulateForces,
            ClothSubstepSystems::Integrate,
            ClothSubstepSystems::FitTargets,
            ClothSubstepSystems::Constrain,
        )
            .chain(),
    );
    substep.add_systems((
        accumulate_forces.in_set(ClothSubstepSystems::AccumulateForces),
        integrate.in_set(ClothSubstepSystems::Integrate),
        fit_targets.in_set(ClothSubstepSystems::FitTargets),
        constrain.in_set(ClothSubstepSystems::Constrain),
    ));
    substep
}

/// Registers the plugin's parameter, shape and component types for reflection (the
/// inspector, scene files).
fn register_types(app: &mut App) {
    app.register_type::<Cloth>()
        .register_type::<ClothShape>()
        .register_type::<Pins>()
        .register_type::<ClothCollider>()
        .register_type::<crate::ecs::components::ColliderKind>()
        .register_type::<ClothParams>()
        .register_type::<SpringParams>()
        .register_type::<SpringFamily>()
        .register_type::<Integrator>()
        .register_type::<Substeps>()
        .register_type::<Model>()
        .register_type::<ShapeMatchingParams>()
        .register_type::<PatchParams>()
        .register_type::<crate::params::PatchTargets>()
        .register_type::<RotationMethod>()
        .register_type::<GoalUpdate>()
        .register_type::<Environment>()
        .register_type::<Wind>()
        .register_type::<WindField>()
        .register_type::<ClothEnvironment>()
        .register_type::<ClothPause>()
        .register_type::<ClothSleep>()
        .register_type::<ClothLod>();
}

/// Where a cloth's layout comes from when its description is not enough: the entity's
/// (or the remembered source) mesh, or the loaded garment; `None` while not loaded yet.
enum LayoutSource<'a> {
    Description,
    Mesh(Option<&'a Mesh>),
    Garment(Option<&'a Garment>),
}

/// Builds a cloth's solver and mesh. `Ok(None)`: its mesh or garment is not loaded yet.
fn build_one(
    cloth: &Cloth,
    frame: bevy::math::Affine3A,
    source: LayoutSource,
) -> Result<Option<(solver::ClothSolver, Mesh)>, ClothError> {
    cloth.validate()?;
    let (solver, uvs) = match (&cloth.shape, source) {
        (ClothShape::Garment { resolution, .. }, LayoutSource::Garment(garment)) => {
            let Some(garment) = garment else {
                return Ok(None);
            };
            (
                cloth.build_garment(garment.layout(*resolution)?, frame)?,
                None,
            )
        }
        (ClothShape::Mesh, LayoutSource::Mesh(mesh)) => {
            let Some(mesh) = mesh else {
                return Ok(None);
            };
            let MeshSource {
                positions,
                triangles,
                uvs,
            } = mesh_triangles(mesh)?;
            let layout = Layout::from_mesh(&positions, &triangles)?;
            let pins = cloth.pins.resolve_for(&layout)?;
            let solver = solver::ClothSolver::new(layout, &pins, &cloth.params, frame)?;
            (solver, uvs)
        }
        _ => (
            cloth
                .shape
                .build_solver(&cloth.pins, &cloth.params, frame)?,
            None,
        ),
    };
    let mesh = cloth_mesh(&solver, uvs);
    Ok(Some((solver, mesh)))
}

/// Remembers the mesh a mesh-shaped cloth was made from (its `Mesh3d` is replaced by the
/// simulated copy, so the source stays untouched).
#[derive(Component, Clone, Debug)]
struct ClothSourceMesh(Handle<Mesh>);

/// The garment asset a garment cloth is built from, and whether it changed on disk
/// since (hot reload).
#[derive(Component, Clone, Debug)]
struct ClothGarment {
    file: String,
    handle: Handle<Garment>,
    changed: bool,
}

/// Marks the cloths whose garment was reloaded (an edited garment or pattern file, or a
/// broken one fixed). Runs every frame, so no asset event is missed between fixed steps.
fn watch_garments(
    mut events: MessageReader<AssetEvent<Garment>>,
    mut cloths: Query<(&mut ClothGarment, Has<ClothSimulation>)>,
) {
    for event in events.read() {
        for (mut garment, built) in &mut cloths {
            let reloaded = match *event {
                // A built cloth's garment changed; an unbuilt one's arrived.
                AssetEvent::Modified { id } => id == garment.handle.id(),
                AssetEvent::LoadedWithDependencies { id } => !built && id == garment.handle.id(),
                _ => false,
            };
            garment.changed |= reloaded;
        }
    }
}

/// The garment of a garment cloth: its asset (loading it on first sight or when the file
/// changes), `Ok(None)` while loading, the loader's error when it failed.
fn garment_source<'a>(
    commands: &mut Commands,
    entity: Entity,
    file: &str,
    current: Option<&ClothGarment>,
    asset_server: &AssetServer,
    garments: &'a Assets<Garment>,
) -> Result<Option<&'a Garment>, ClothError> {
    let handle = match current {
        Some(current) if current.file == file => current.handle.clone(),
        _ => {
            let handle = asset_server.load::<Garment>(file.to_string());
            commands.entity(entity).insert(ClothGarment {
                file: file.to_string(),
                handle: handle.clone(),
                changed: false,
            });
            handle
        }
    };
    if let Some(garment) = garments.get(&handle) {
        return Ok(Some(garment));
    }
    match asset_server.load_state(&handle) {
        LoadState::Failed(e) => Err(load_error(file, &e)),
        _ => Ok(None),
    }
}

/// The cloth error behind a failed garment load (the loader's own, with file, line and
/// column), or the asset server's message (a missing file).
fn load_error(file: &str, error: &AssetLoadError) -> ClothError {
    if let AssetLoadError::AssetLoaderError(e) = error
        && let Some(e) = e.error().downcast_ref::<ClothError>()
    {
        return e.clone();
    }
    ClothError::Garment {
        file: file.to_string(),
        line: 1,
        column: 1,
        message: error.to_string(),
    }
}

#[allow(clippy::type_complexity, clippy::too_many_arguments)]
fn build_cloths(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    asset_server: Res<AssetServer>,
    garments: Res<Assets<Garment>>,
    transforms: TransformHelper,
    mut cloths: Query<(
        Entity,
        Ref<Cloth>,
        Option<&mut ClothSimulation>,
        Option<&Mesh3d>,
        Option<&ClothSourceMesh>,
        Option<&mut ClothGarment>,
        Has<ClothInvalid>,
    )>,
) {
    for (entity, cloth, sim, mesh3d, source, garment, invalid) in &mut cloths {
        let frame = transforms
            .compute_global_transform(entity)
            .map(|g| g.affine())
            .unwrap_or_default();
        let mut garment = garment;
        let reload = garment
            .as_mut()
            .is_some_and(|g| std::mem::take(&mut g.bypass_change_detection().changed));
        if let Some(mut sim) = sim {
            sim.solver.set_frame(frame);
            if !cloth.is_changed() && !reload {
                continue;
            }
            if sim.built_from == (cloth.shape.clone(), cloth.pins.clone()) && !reload {
                apply_params(&mut commands, entity, &mut sim, &cloth.params, invalid);
                continue;
            }
        } else if invalid && !cloth.is_changed() && !reload {
            continue;
        }
        let mut source_handle = None;
        let layout_source = match &cloth.shape {
            ClothShape::Mesh => {
                source_handle = source.map(|s| s.0.clone()).or(mesh3d.map(|m| m.0.clone()));
                LayoutSource::Mesh(source_handle.as_ref().and_then(|h| meshes.get(h)))
            }
            ClothShape::Garment { file, .. } => {
                let current = garment.as_deref();
                match garment_source(
                    &mut commands,
                    entity,
                    file,
                    current,
                    &asset_server,
                    &garments,
                ) {
                    Ok(garment) => LayoutSource::Garment(garment),
                    Err(e) => {
                        invalidate(&mut commands, entity, e);
                        continue;
                    }
                }
            }
            ClothShape::Grid { .. } => LayoutSource::Description,
        };
        match build_one(&cloth, frame, layout_source) {
            Ok(Some((solver, mesh))) => {
                let sim = ClothSimulation::new(solver, &cloth);
                let handle = meshes.add(mesh);
                let mut entity_commands = commands.entity(entity);
                entity_commands
                    .insert((sim, Mesh3d(handle)))
                    .remove::<ClothInvalid>();
                if let Some(source_handle) = source_handle {
                    entity_commands.insert(ClothSourceMesh(source_handle));
                }
            }
            Ok(None) => {}
            Err(e) => invalidate(&mut commands, entity, e),
        }
    }
}

/// Applies edited parameters to a built cloth; bad ones pause it until they are fixed.
fn apply_params(
    commands: &mut Commands,
    entity: Entity,
    sim: &mut ClothSimulation,
    params: &ClothParams,
    invalid: bool,
) {
    match sim.solver.set_params(params) {
        Ok(()) if invalid => {
            commands.entity(entity).remove::<ClothInvalid>();
        }
        Ok(()) => {}
        Err(e) => {
            error!("cloth {entity}: {e}; the cloth is paused until this is fixed");
            commands.entity(entity).insert(ClothInvalid(e));
        }
    }
}

/// A cloth that cannot be built is not simulated, and says why.
fn invalidate(commands: &mut Commands, entity: Entity, error: ClothError) {
    error!("cloth {entity} is not simulated: {error}");
    commands
        .entity(entity)
        .insert(ClothInvalid(error))
        .remove::<ClothSimulation>();
}

/// A collider entity moving faster than this (m/s), or turning more than a quarter turn in
/// a step, is taken to have jumped there (a respawn, a teleport): it gets no motion.
pub const TELEPORT_SPEED: f32 = 100.0;

/// Each collider entity's pose (rotation, translation) at the last step, from which the
/// next step takes its motion.
#[derive(Default)]
struct ColliderPoses {
    before: bevy::ecs::entity::EntityHashMap<(Quat, Vec3)>,
    now: bevy::ecs::entity::EntityHashMap<(Quat, Vec3)>,
}

impl ColliderPoses {
    /// The motion of `entity` from its last pose to `transform` over `dt` (none the first
    /// time it is seen, or after a jump); remembers `transform` for the next step.
    fn motion(&mut self, entity: Entity, transform: &GlobalTransform, dt: f32) -> solver::Motion {
        let (_, rotation, translation) = transform.to_scale_rotation_translation();
        self.now.insert(entity, (rotation, translation));
        let Some(&before) = self.before.get(&entity) else {
            return solver::Motion::NONE;
        };
        let motion = solver::Motion::between(before, (rotation, translation), dt);
        let jumped = motion.linear.length() > TELEPORT_SPEED
            || motion.angular.length() * dt > std::f32::consts::FRAC_PI_2;
        if jumped { solver::Motion::NONE } else { motion }
    }

    /// Ends a step: its poses are the next step's `before`.
    fn end_step(&mut self) {
        std::mem::swap(&mut self.before, &mut self.now);
        self.now.clear();
    }
}

/// The entity of each collider the cloths were given this step, in their order.
#[derive(Resource, Default)]
struct PlacedColliders(Vec<Entity>);

/// Gives every cloth the colliders where their entities are now, each with its motion
/// since the last step (so the solver sweeps it through the step and friction carries the
/// cloth along): each collider's world placement is computed once per step, then copied to
/// every cloth.
#[allow(clippy::too_many_arguments)]
fn place_colliders(
    time: Res<Time>,
    transforms: TransformHelper,
    colliders: Query<(Entity, &ClothCollider)>,
    #[cfg(feature = "avian")] avian_colliders: Query<
        (
            Entity,
            &avian3d::prelude::Collider,
            Option<&avian3d::prelude::Friction>,
        ),
        Without<ClothCollider>,
    >,
    mut cloths: Query<&mut ClothSimulation>,
    mut world_colliders: Local<Vec<solver::Collider>>,
    mut poses: Local<ColliderPoses>,
    mut placed: ResMut<PlacedColliders>,
    #[cfg(feature = "avian")] mut hulls: Local<crate::ecs::avian::HullCache>,
) {
    let dt = time.delta_secs();
    world_colliders.clear();
    placed.0.clear();
    for (entity, collider) in &colliders {
        let Ok(transform) = transforms.compute_global_transform(entity) else {
            continue;
        };
        world_colliders.push(solver::Collider {
            motion: poses.motion(entity, &transform, dt),
            ..collider.to_world(&transform)
        });
        placed.0.push(entity);
    }
    // avian bodies' colliders (`ecs/avian.rs`), unless the entity has its own.
    #[cfg(feature = "avian")]
    for (entity, collider, friction) in &avian_colliders {
        let Ok(transform) = transforms.compute_global_transform(entity) else {
            continue;
        };
        if let Some(c) =
            crate::ecs::avian::to_solver_collider(collider, &transform, friction, &mut hulls)
        {
            world_colliders.push(solver::Collider {
                motion: poses.motion(entity, &transform, dt),
                ..c
            });
            placed.0.push(entity);
        }
    }
    poses.end_step();
    #[cfg(feature = "avian")]
    hulls.end_step();
    for mut sim in &mut cloths {
        if !(world_colliders.is_empty() && sim.solver.colliders().is_empty()) {
            sim.solver.set_colliders(world_colliders.iter().cloned());
        }
    }
}

/// The cloth pushes back (the `avian` feature): every cloth that stepped gives each avian
/// dynamic body among its colliders the impulse of its particles' contacts with it
/// ([`solver::ClothSolver::collider_impulses`]), so a ball dropped on a hammock is held.
#[cfg(feature = "avian")]
fn push_back_bodies(
    placed: Res<PlacedColliders>,
    cloths: Query<(&ClothSimulation, &StepProgress), Without<ClothInvalid>>,
    mut bodies: Query<(&avian3d::prelude::RigidBody, avian3d::prelude::Forces)>,
    mut totals: Local<Vec<solver::ColliderImpulse>>,
) {
    use avian3d::prelude::WriteRigidBodyForces;
    totals.clear();
    totals.resize(placed.0.len(), solver::ColliderImpulse::default());
    for (sim, progress) in &cloths {
        if progress.substeps == 0 {
            continue;
        }
        for (total, impulse) in totals.iter_mut().zip(sim.solver.collider_impulses()) {
            total.linear += impulse.linear;
            total.angular += impulse.angular;
        }
    }
    for (&entity, total) in placed.0.iter().zip(totals.iter()) {
        if *total == solver::ColliderImpulse::default() {
            continue;
        }
        let Ok((body, mut forces)) = bodies.get_mut(entity) else {
            continue;
        };
        if body.is_dynamic() {
            // The linear impulse at the origin and the angular one about it: about the
            // centre of mass c that is `angular − c × linear`, as the impulse needs.
            forces.apply_linear_impulse_at_point(total.linear, Vec3::ZERO);
            forces.apply_angular_impulse(total.angular);
        }
    }
}

/// Holds each [`ClothAttachments`] cloth's particles at their entities' global
/// transforms for this step (the solver reaches them over its substeps). The particles and
/// their points in the target's frame are chosen the first time (and again when the cloth
/// is rebuilt); a target without a transform (despawned) lets its particles go.
fn attach_cloths(
    transforms: TransformHelper,
    mut cloths: Query<(Entity, &mut ClothSimulation, &mut ClothAttachments)>,
) {
    for (entity, mut sim, mut attachments) in &mut cloths {
        let rebuilt = sim.is_added();
        let solver = &mut sim.solver;
        for attachment in &mut attachments.0 {
            if rebuilt {
                attachment.held = None;
            }
            let Ok(frame) = transforms.compute_global_transform(attachment.target) else {
                for &(i, _) in attachment.held() {
                    solver.detach(i);
                }
                continue;
            };
            let held = attachment
                .held
                .get_or_insert_with(|| choose_held(entity, &attachment.particles, solver, &frame));
            let attached = held
                .iter()
                .try_for_each(|&(i, local)| solver.attach(i, frame.transform_point(local)));
            if let Err(e) = attached {
                warn!("cloth attachment: {e}; choosing its particles again");
                attachment.held = None;
            }
        }
    }
}

/// The particles an attachment holds and each one's point in the target's frame (`frame`
/// where the target is now): given, or where the particle is now.
fn choose_held(
    cloth: Entity,
    particles: &AttachParticles,
    solver: &solver::ClothSolver,
    frame: &GlobalTransform,
) -> Vec<(u32, Vec3)> {
    let x = solver.positions();
    let to_local = frame.affine().inverse();
    let here = |i: u32| (i, to_local.transform_point3(x[i as usize]));
    match particles {
        AttachParticles::At(points) => points
            .iter()
            .copied()
            .filter(|&(i, local)| (i as usize) < x.len() && local.is_finite())
            .collect(),
        AttachParticles::Indices(list) => list
            .iter()
            .copied()
            .filter(|&i| (i as usize) < x.len())
            .map(here)
            .collect(),
        AttachParticles::Nearest { point, count } => {
            let at = frame.transform_point(*point);
            let mut order: Vec<u32> = (0..x.len() as u32).collect();
            order.sort_by(|&a, &b| {
                x[a as usize]
                    .distance_squared(at)
                    .total_cmp(&x[b as usize].distance_squared(at))
            });
            order.truncate(*count as usize);
            order.into_iter().map(here).collect()
        }
        AttachParticles::Run(name) => match solver.run(name) {
            Some(run) => run.iter().copied().map(here).collect(),
            None => {
                error!("cloth {cloth}: no run named `{name}` to attach");
                Vec::new()
            }
        },
    }
}

/// Per-cloth bookkeeping of the step in progress.
#[derive(Component, Clone, Copy, Debug, Default)]
struct StepProgress {
    substeps: u32,
    elapsed: Duration,
}

/// Sets each [`ClothLod`] cloth's level from its size on the active camera's view: the
/// bounding sphere of its particles, `radius / (distance · tan(fov/2))` for a perspective
/// camera (`radius / half height` for an orthographic one). A new level sets the cloth's
/// model (its own at 0, patches above), which `build_cloths` then applies.
fn choose_levels(
    transforms: TransformHelper,
    cameras: Query<(Entity, &Camera, &Projection)>,
    mut cloths: Query<(&mut Cloth, &mut ClothLod, &ClothSimulation)>,
) {
    let Some((camera, _, projection)) = cameras.iter().find(|(_, c, _)| c.is_active) else {
        return;
    };
    // Computed here rather than read from `GlobalTransform`, which a headless app
    // without transform propagation does not update.
    let Ok(eye) = transforms.compute_global_transform(camera) else {
        return;
    };
    for (mut cloth, mut lod, sim) in &mut cloths {
        if sim.solver.grid_size().is_none() {
            continue;
        }
        let (centre, radius) = sim.solver.bounding_sphere();
        let fraction = match projection {
            Projection::Perspective(p) => {
                let distance = eye.translation().distance(centre).max(f32::EPSILON);
                radius / (distance * (p.fov * 0.5).tan())
            }
            Projection::Orthographic(o) => radius / (o.area.height() * 0.5).max(f32::EPSILON),
            Projection::Custom(_) => continue,
        };
        let lod = lod.bypass_change_detection();
        lod.screen_fraction = fraction;
        let level = lod.next_level(lod.level, fraction);
        if level == lod.level {
            continue;
        }
        if lod.level == 0 {
            lod.full = Some(cloth.params.model);
        }
        lod.level = level;
        cloth.params.model = match level {
            0 => lod.full.take().unwrap_or(cloth.params.model),
            l => Model::Patches(PatchParams {
                part_width: ClothLod::PART_SIZES[l - 1],
                part_height: ClothLod::PART_SIZES[l - 1],
                ..PatchParams::default()
            }),
        };
    }
}

/// Wakes the sleeping cloths that something may move (see [`ClothSleep`]): the solver's
/// own record of outside changes (parameters, frame, colliders within reach, tools), a
/// change of gravity or wind, a [`ClothWake`] message, or sleeping switched off.
fn wake_cloths(
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
        }
    }
}

/// A cloth paused because a step went non-finite runs again once it has been reset
/// (its last report is no longer a failure); a valid change of its parameters lifts
/// the pause too (`apply_params`).
fn recover_cloths(
    mut commands: Commands,
    cloths: Query<(Entity, &ClothSimulation, &ClothInvalid)>,
) {
    for (entity, sim, invalid) in &cloths {
        if matches!(invalid.0, ClothError::NonFinite { .. }) && sim.solver.last_report().finite {
            commands.entity(entity).remove::<ClothInvalid>();
        }
    }
}

#[allow(clippy::type_complexity)]
fn begin_steps(
    mut commands: Commands,
    time: Res<Time>,
    mut pause: ResMut<ClothPause>,
    mut plan: ResMut<ClothSubstepPlan>,
    mut cloths: Query<
        (
            Entity,
            &mut ClothSimulation,
            Option<&mut StepProgress>,
            Option<&ClothSleep>,
        ),
        Without<ClothInvalid>,
    >,
) {
    let dt = time.delta_secs();
    let run = !pause.paused || pause.pending_steps > 0;
    if pause.paused && run {
        pause.pending_steps -= 1;
    }
    plan.count = 0;
    plan.index = 0;
    for (entity, mut sim, progress, sleep) in &mut cloths {
        let start = Instant::now();
        let awake = sleep.is_none_or(|s| !s.asleep);
        let substeps = if run && awake {
            sim.solver.begin_step(dt)
        } else {
            0
        };
        let progress_now = StepProgress {
            substeps,
            elapsed: start.elapsed(),
        };
        match progress {
            Some(mut p) => *p = progress_now,
            None => {
                commands.entity(entity).insert(progress_now);
            }
        }
        plan.count = plan.count.max(substeps);
    }
}

/// The plugin's own systems in the [`ClothSubstep`] schedule (`substep_schedule`'s four, one
/// per stage).
const OWN_SUBSTEP_SYSTEMS: usize = 4;

/// Runs the step's substeps. When a game has put systems between the stages
/// ([`ClothSubstepSystems`]), every substep runs the [`ClothSubstep`] schedule, each
/// stage over all cloths in parallel. Otherwise each cloth takes all its substeps in one
/// task on the compute pool: the same calls in the same order per cloth (the same bits),
/// one fork-join per step instead of four per substep, which is what many small cloths
/// cost most.
fn run_substeps(
    world: &mut World,
    mut cloths: Local<Option<QueryState<ActiveCloth, Without<ClothInvalid>>>>,
) {
    let count = world.resource::<ClothSubstepPlan>().count;
    if count == 0 {
        return;
    }
    let schedules = world.resource::<Schedules>();
    let others = schedules
        .get(ClothSubstep)
        .is_none_or(|s| s.systems_len() != OWN_SUBSTEP_SYSTEMS);
    if others {
        for index in 0..count {
            world.resource_mut::<ClothSubstepPlan>().index = index;
            world.run_schedule(ClothSubstep);
        }
        return;
    }
    let env = **world.resource::<ClothEnvironment>();
    let cloths = cloths.get_or_insert_with(|| world.query_filtered());
    // The solver's pool, not `Query::par_iter_mut`: on two cores Bevy gives its compute
    // pool one thread, and `par_iter_mut` then runs on the calling thread alone; a scope
    // has the calling thread work beside the pool's.
    let active = cloths.iter_mut(world);
    solver::task_pool().scope(|scope| {
        for (mut sim, mut progress) in active {
            scope.spawn(async move {
                let start = Instant::now();
                for _ in 0..progress.substeps {
                    sim.solver.substep(&env);
                }
                progress.elapsed += start.elapsed();
            });
        }
    });
}

/// A cloth that takes part in the step: its simulation and progress.
type ActiveCloth = (&'static mut ClothSimulation, &'static mut StepProgress);

/// Runs one solver phase on every cloth that takes part in the current substep, in
/// parallel, adding the time it took to that cloth's step time.
fn for_each_active(
    plan: &ClothSubstepPlan,
    cloths: &mut Query<(&mut ClothSimulation, &mut StepProgress), Without<ClothInvalid>>,
    phase: impl Fn(&mut solver::ClothSolver) + Sync + Send,
) {
    cloths.par_iter_mut().for_each(|(mut sim, mut progress)| {
        if plan.index < progress.substeps {
            let start = Instant::now();
            phase(&mut sim.solver);
            progress.elapsed += start.elapsed();
        }
    });
}

type ActiveCloths<'w, 's> = Query<'w, 's, ActiveCloth, Without<ClothInvalid>>;

fn accumulate_forces(
    plan: Res<ClothSubstepPlan>,
    env: Res<ClothEnvironment>,
    mut cloths: ActiveCloths,
) {
    for_each_active(&plan, &mut cloths, |c| c.accumulate_forces(&env));
}

fn integrate(plan: Res<ClothSubstepPlan>, mut cloths: ActiveCloths) {
    for_each_active(&plan, &mut cloths, solver::ClothSolver::integrate);
}

fn fit_targets(plan: Res<ClothSubstepPlan>, mut cloths: ActiveCloths) {
    for_each_active(&plan, &mut cloths, solver::ClothSolver::fit_targets);
}

fn constrain(plan: Res<ClothSubstepPlan>, mut cloths: ActiveCloths) {
    for_each_active(&plan, &mut cloths, solver::ClothSolver::constrain);
}

#[allow(clippy::type_complexity)]
fn finish_steps(
    mut commands: Commands,
    mut torn: MessageWriter<ClothTorn>,
    env: Res<ClothEnvironment>,
    time: Res<Time>,
    mut cloths: Query<
        (
            Entity,
            &mut ClothSimulation,
            &StepProgress,
            Option<&mut ClothStats>,
            Option<&mut ClothSleep>,
        ),
        Without<ClothInvalid>,
    >,
) {
    for (entity, mut sim, progress, stats, sleep) in &mut cloths {
        if progress.substeps == 0 {
            continue;
        }
        let start = Instant::now();
        let sim = &mut *sim;
        let report = sim.solver.end_step();
        if !report.finite {
            let error = ClothError::NonFinite {
                time: sim.solver.time(),
                substeps: report.substeps,
            };
            error!("cloth {entity}: {error}");
            commands.entity(entity).insert(ClothInvalid(error));
            sim.mesh_dirty = true;
            continue;
        }
        for &spring in sim.solver.last_torn() {
            let s = spring as usize;
            let particles = [sim.solver.springs().a[s], sim.solver.springs().b[s]];
            torn.write(ClothTorn {
                cloth: entity,
                spring,
                particles,
            });
        }
        let asleep = sleep.is_some_and(|mut sleep| {
            let speed = if sleep.enabled {
                sim.solver.max_speed()
            } else {
                f32::INFINITY
            };
            sleep.observe(speed, time.delta_secs())
        });
        sim.last_step_ms = (progress.elapsed + start.elapsed()).as_secs_f32() * 1e3;
        sim.mesh_dirty = true;
        if let Some(mut stats) = stats {
            stats.record(&sim.solver, &env, sim.last_step_ms);
            stats.asleep = asleep;
        }
    }
}

/// Writes each stepped cloth's positions and normals into its mesh. A cloth whose own
/// `Visibility` is `Hidden` is not written; it keeps its new state pending and is
/// written when shown. (Not for a hidden parent, whose effect is known only where
/// Bevy's visibility systems run; and not for frustum culling: Bevy takes a mesh's
/// bounding box from what was written, so an unwritten cloth that swings into view
/// would stay culled.)
fn write_meshes(
    mut meshes: ResMut<Assets<Mesh>>,
    mut cloths: Query<(&mut ClothSimulation, &Mesh3d, Option<&Visibility>)>,
) {
    for (mut sim, mesh3d, visibility) in &mut cloths {
        if !sim.mesh_dirty || visibility == Some(&Visibility::Hidden) {
            continue;
        }
        let Some(mut mesh) = meshes.get_mut(&mesh3d.0) else {
            continue;
        };
        let sim = &mut *sim;
        let faces_changed = sim.solver.take_faces_changed();
        write_mesh(&mut mesh, &sim.solver, &mut sim.normals, faces_changed);
        sim.mesh_dirty = false;
    }
}
