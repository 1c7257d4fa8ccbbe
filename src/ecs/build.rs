//! Building: a cloth's solver and mesh from its description (a grid, a mesh, a garment
//! file loaded as an asset and hot-reloaded), rebuilt when its shape or pins change;
//! edited parameters applied in place; an invalid cloth paused with the reason.

use bevy::asset::{AssetLoadError, LoadState};
use bevy::prelude::*;
use bevy::transform::helper::TransformHelper;

use crate::ecs::cloth::{Cloth, ClothInvalid, ClothSimulation, pause_invalid};
use crate::ecs::events::ClothBuilt;
use crate::ecs::mesh::{MeshSource, cloth_mesh, mesh_triangles};
use crate::error::ClothError;
use crate::layout::garment::Garment;
use crate::layout::shape::ClothShape;
use crate::params::ClothParams;
use crate::solver::{self, Layout};

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
pub(crate) struct ClothSourceMesh(Handle<Mesh>);

/// The garment asset a garment cloth is built from, and whether it changed on disk
/// since (hot reload).
#[derive(Component, Clone, Debug)]
pub(crate) struct ClothGarment {
    file: String,
    handle: Handle<Garment>,
    changed: bool,
}

/// Marks the cloths whose garment was reloaded (an edited garment or pattern file, or a
/// broken one fixed). Runs every frame, so no asset event is missed between fixed steps.
pub(crate) fn watch_garments(
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
pub(crate) fn build_cloths(
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
                commands.trigger(ClothBuilt { entity });
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
        // Paused until the parameters are fixed.
        Err(e) => pause_invalid(commands, entity, e),
    }
}

/// A cloth that cannot be built is not simulated, and says why.
fn invalidate(commands: &mut Commands, entity: Entity, error: ClothError) {
    pause_invalid(commands, entity, error);
    commands.entity(entity).remove::<ClothSimulation>();
}
