//! Building: a cloth's solver and mesh from its description (a grid, a mesh, a garment
//! file loaded as an asset and hot-reloaded), rebuilt when its shape or pins change;
//! edited parameters applied in place; an invalid cloth paused with the reason.

use bevy::asset::{AssetLoadError, LoadState};
use bevy::prelude::*;
use bevy::transform::helper::TransformHelper;

use crate::ecs::attach::ClothAttachments;
use crate::ecs::cloth::{Cloth, ClothInvalid, ClothSimulation, pause_invalid};
use crate::ecs::events::ClothBuilt;
use bevy::mesh::skinning::SkinnedMesh;

use crate::ecs::mesh::{cloth_mesh, mesh_triangles};
use crate::ecs::skin::{ClothBackStop, ClothBody, ClothMaxDistance};
use crate::error::ClothError;
use crate::layout::garment::{Garment, GarmentLoader};
use crate::layout::shape::{ClothPins, ClothShape};
use crate::params::ClothParams;
use crate::solver::{self, Layout};

/// Where a cloth's layout comes from when its description is not enough: the entity's
/// (or the remembered source) mesh, or the loaded garment; `None` while not loaded yet.
enum LayoutSource<'a> {
    Description,
    Mesh(Option<&'a Mesh>),
    Garment(Option<&'a Garment>),
}

/// What a mesh-shaped cloth may follow: the entity's skin (or the one taken off it at
/// the last build) and where its maximum distances come from.
#[derive(Clone, Copy, Default)]
struct BodySource<'a> {
    skin: Option<&'a SkinnedMesh>,
    max: Option<&'a ClothMaxDistance>,
    back: Option<&'a ClothBackStop>,
}

impl<'a> BodySource<'a> {
    /// The entity's skin (or the one taken off it when it was last built, kept in its
    /// `body`), and its painted max distance and back stop.
    fn of(
        skin: Option<&'a SkinnedMesh>,
        body: Option<&'a ClothBody>,
        max: Option<&'a ClothMaxDistance>,
        back: Option<&'a ClothBackStop>,
    ) -> Self {
        let skin = skin.or(body.and_then(|b| b.skin.as_ref().map(|s| &s.mesh)));
        BodySource { skin, max, back }
    }
}

/// A built cloth: its solver, its mesh, and for a mesh-shaped cloth its body.
struct BuiltCloth {
    solver: solver::ClothSolver,
    mesh: Mesh,
    body: Option<ClothBody>,
}

/// Builds a cloth's solver and mesh. `Ok(None)`: its mesh or garment is not loaded yet.
fn build_one(
    cloth: &Cloth,
    frame: bevy::math::Affine3A,
    source: LayoutSource,
    body: BodySource,
) -> Result<Option<BuiltCloth>, ClothError> {
    cloth.validate()?;
    let plain = |solver: solver::ClothSolver| BuiltCloth {
        mesh: cloth_mesh(&solver, None),
        solver,
        body: None,
    };
    let built = match (&cloth.shape, source) {
        (ClothShape::Garment { resolution, .. }, LayoutSource::Garment(garment)) => {
            let Some(garment) = garment else {
                return Ok(None);
            };
            plain(cloth.build_garment(garment.layout(*resolution)?, frame)?)
        }
        (ClothShape::Mesh, LayoutSource::Mesh(mesh)) => {
            let Some(mesh) = mesh else {
                return Ok(None);
            };
            build_from_mesh(cloth, mesh, frame, body)?
        }
        _ => {
            let painted = [
                (body.max.is_some(), "ClothMaxDistance"),
                (body.back.is_some(), "ClothBackStop"),
            ];
            if let Some(&(_, component)) = painted.iter().find(|(on, _)| *on) {
                return Err(ClothError::PaintNeedsMesh { component });
            }
            plain(
                cloth
                    .shape
                    .build_solver(&cloth.pins, &cloth.params, frame)?,
            )
        }
    };
    Ok(Some(built))
}

/// A mesh-shaped cloth: its solver, its mesh (with the source's UVs) and its body (skin,
/// painted max distance).
fn build_from_mesh(
    cloth: &Cloth,
    mesh: &Mesh,
    frame: bevy::math::Affine3A,
    body: BodySource,
) -> Result<BuiltCloth, ClothError> {
    let mut source = mesh_triangles(mesh)?;
    let back_stops = crate::ecs::skin::back_stops(mesh, &source, body.back)?;
    if !back_stops.is_empty() && crate::ecs::skin::wound_against_normals(mesh, &source) {
        // The back stops go behind the side the mesh's normals face: its triangles are
        // wound to face the same way.
        for t in &mut source.triangles {
            t.swap(1, 2);
        }
    }
    let layout = Layout::from_mesh(&source.positions, &source.triangles)?;
    let pins = match &cloth.pins {
        // The mesh's own vertex indices, each to the particle it was welded into.
        ClothPins::Indices(vertices) => {
            let count = source.particle_of.len();
            let mut pins = vertices
                .iter()
                .map(|&v| {
                    let particle = source.particle_of.get(v as usize).copied();
                    particle.ok_or(ClothError::PinOutOfRange { index: v, count })
                })
                .collect::<Result<Vec<u32>, _>>()?;
            pins.sort_unstable();
            pins.dedup();
            pins
        }
        pins => pins.resolve_for(&layout)?,
    };
    let back_stopped = !back_stops.is_empty();
    let body = ClothBody::read(mesh, &source, body.skin, body.max, &pins, back_stopped)?;
    // A skinned cloth's pins follow its skin (distance 0), not the entity's frame.
    let frame_pins = if body.as_ref().is_some_and(|b| b.skin.is_some()) {
        Vec::new()
    } else {
        pins
    };
    let mut solver = solver::ClothSolver::new(layout, &frame_pins, &cloth.params, frame)?;
    solver.set_back_stops(&back_stops)?;
    let mesh = cloth_mesh(&solver, source.uvs);
    Ok(BuiltCloth { solver, mesh, body })
}

/// Remembers the mesh a mesh-shaped cloth was made from (its `Mesh3d` is replaced by the
/// simulated copy, so the source stays untouched).
#[derive(Component, Clone, Debug)]
pub(crate) struct ClothSourceMesh(Handle<Mesh>);

/// The garment asset a garment cloth is built from, and whether it changed on disk
/// since (hot reload).
#[derive(Component, Clone, Debug)]
pub(crate) struct ClothGarment {
    file: String,
    handle: Handle<Garment>,
    changed: bool,
}

/// Garments as assets: pattern, seam and garment files loaded in the background and
/// hot-reloaded ([`Garment`], `GarmentLoader`); a cloth of [`ClothShape::Garment`] needs it.
pub struct ClothGarmentPlugin;

impl Plugin for ClothGarmentPlugin {
    fn build(&self, app: &mut App) {
        app.init_asset::<Garment>()
            .register_asset_loader(GarmentLoader)
            .add_systems(Update, watch_garments);
    }
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
    garments: Option<&'a Assets<Garment>>,
) -> Result<Option<&'a Garment>, ClothError> {
    let Some(garments) = garments else {
        return Err(ClothError::Garment {
            file: file.to_string(),
            line: 1,
            column: 1,
            message: "garments are loaded by ClothGarmentPlugin, left out of this app".into(),
        });
    };
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

/// Where a cloth's layout comes from (see [`LayoutSource`]), and for a mesh-shaped cloth
/// the handle of its source mesh (remembered, or the entity's `Mesh3d`); a garment's
/// asset is loaded on first sight.
#[allow(clippy::type_complexity)]
fn layout_source<'a>(
    cloth: &Cloth,
    (source, mesh3d, garment): (
        Option<&ClothSourceMesh>,
        Option<&Mesh3d>,
        Option<&ClothGarment>,
    ),
    meshes: &'a Assets<Mesh>,
    (commands, entity): (&mut Commands, Entity),
    (asset_server, garments): (&AssetServer, Option<&'a Assets<Garment>>),
) -> Result<(LayoutSource<'a>, Option<Handle<Mesh>>), ClothError> {
    Ok(match &cloth.shape {
        ClothShape::Mesh => {
            let handle = source.map(|s| s.0.clone()).or(mesh3d.map(|m| m.0.clone()));
            let mesh = handle.as_ref().and_then(|h| meshes.get(h));
            (LayoutSource::Mesh(mesh), handle)
        }
        ClothShape::Garment { file, .. } => {
            let found = garment_source(commands, entity, file, garment, asset_server, garments)?;
            (LayoutSource::Garment(found), None)
        }
        ClothShape::Grid { .. } => (LayoutSource::Description, None),
    })
}

/// Every cloth, with what building it reads: its simulation, mesh, source mesh, garment,
/// whether it was refused, whether it is attached (no default pins), and its skin, body
/// and painted max distance.
type ClothsToBuild<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        Ref<'static, Cloth>,
        Option<&'static mut ClothSimulation>,
        Option<&'static Mesh3d>,
        Option<&'static ClothSourceMesh>,
        Option<&'static mut ClothGarment>,
        (Has<ClothInvalid>, Has<ClothAttachments>),
        (
            Option<&'static SkinnedMesh>,
            Option<&'static ClothBody>,
            Option<Ref<'static, ClothMaxDistance>>,
            Option<Ref<'static, ClothBackStop>>,
        ),
    ),
>;

/// Builds every cloth that is new or whose shape, pins, garment or painted max distance
/// changed; applies changed params alone in place; refuses what is invalid.
pub(crate) fn build_cloths(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    asset_server: Res<AssetServer>,
    garments: Option<Res<Assets<Garment>>>,
    transforms: TransformHelper,
    mut cloths: ClothsToBuild,
) {
    for (
        entity,
        cloth,
        sim,
        mesh3d,
        source,
        mut garment,
        (invalid, attached),
        (skin, body, max, back),
    ) in &mut cloths
    {
        // Where it is now (the fixed step runs before this frame's transforms propagate).
        let frame = transforms
            .compute_global_transform(entity)
            .map(|g| g.affine());
        let frame = frame.unwrap_or_default();
        let forced = reloaded_or_repainted(garment.as_mut(), max.as_ref(), back.as_ref());
        // The pins it has: `Auto` pins nothing on an attached cloth.
        let pins = cloth.pins.when_attached(attached);
        let forced = forced || sim.as_ref().is_some_and(|s| s.built_from.1 != *pins);
        if !wants_build(&mut commands, entity, &cloth, sim, frame, forced, invalid) {
            continue;
        }
        let cloth = &Cloth {
            pins: pins.into_owned(),
            ..Cloth::clone(&cloth)
        };
        let (layout_source, source_handle) = match layout_source(
            cloth,
            (source, mesh3d, garment.as_deref()),
            &meshes,
            (&mut commands, entity),
            (&asset_server, garments.as_deref()),
        ) {
            Ok(found) => found,
            Err(e) => {
                invalidate(&mut commands, entity, e);
                continue;
            }
        };
        let body_source = BodySource::of(skin, body, max.as_deref(), back.as_deref());
        match build_one(cloth, frame, layout_source, body_source) {
            Ok(Some(b)) => {
                insert_built(&mut commands, entity, cloth, b, &mut meshes, source_handle)
            }
            Ok(None) => {}
            Err(e) => invalidate(&mut commands, entity, e),
        }
    }
}

/// Whether a reloaded garment or a repainted max distance or back stop rebuilds the
/// cloth, as a changed shape does (each read every time: `|`, not `||`, so the garment's
/// flag is taken).
fn reloaded_or_repainted(
    garment: Option<&mut Mut<ClothGarment>>,
    max: Option<&Ref<ClothMaxDistance>>,
    back: Option<&Ref<ClothBackStop>>,
) -> bool {
    garment.is_some_and(|g| std::mem::take(&mut g.bypass_change_detection().changed))
        | max.is_some_and(|m| m.is_changed())
        | back.is_some_and(|b| b.is_changed())
}

/// Whether a cloth must be built (again): always when it has no simulation, unless it was
/// refused and has not changed since; for one simulated, when its shape or pins changed
/// (or `forced`: its garment reloaded, its max distance repainted, an attachment added to
/// or taken from a cloth of default pins). A simulated cloth
/// follows its `frame` here, and a change of its params alone is applied in place.
fn wants_build(
    commands: &mut Commands,
    entity: Entity,
    cloth: &Ref<Cloth>,
    sim: Option<Mut<ClothSimulation>>,
    frame: bevy::math::Affine3A,
    forced: bool,
    invalid: bool,
) -> bool {
    let changed = cloth.is_changed() || forced;
    let Some(mut sim) = sim else {
        return changed || !invalid;
    };
    sim.solver.set_frame(frame);
    if !changed {
        return false;
    }
    // A change of pins that matters is `forced` (the caller compares the pins it has).
    if sim.built_from.0 == cloth.shape && !forced {
        apply_params(commands, entity, &mut sim, &cloth.params, invalid);
        return false;
    }
    true
}

/// Puts a built cloth on its entity: the simulation, its `mesh` (the entity's `Mesh3d`
/// now; the mesh it was made from, if any, kept as its `source`), and its body or none; a
/// skinned cloth's skin comes off the entity, so it is drawn as simulated. Then tells
/// observers it was built.
fn insert_built(
    commands: &mut Commands,
    entity: Entity,
    cloth: &Cloth,
    BuiltCloth { solver, mesh, body }: BuiltCloth,
    meshes: &mut Assets<Mesh>,
    source: Option<Handle<Mesh>>,
) {
    let sim = ClothSimulation::new(solver, cloth);
    let mut entity_commands = commands.entity(entity);
    entity_commands
        .insert((sim, Mesh3d(meshes.add(mesh))))
        .remove::<ClothInvalid>();
    match body {
        Some(body) => entity_commands.insert(body).remove::<SkinnedMesh>(),
        None => entity_commands.remove::<ClothBody>(),
    };
    if let Some(source) = source {
        entity_commands.insert(ClothSourceMesh(source));
    }
    commands.trigger(ClothBuilt { entity });
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
        // Paused until the parameters are fixed.
        Err(e) => pause_invalid(commands, entity, e),
    }
}

/// A cloth that cannot be built is not simulated, and says why.
fn invalidate(commands: &mut Commands, entity: Entity, error: ClothError) {
    pause_invalid(commands, entity, error);
    commands.entity(entity).remove::<ClothSimulation>();
}
