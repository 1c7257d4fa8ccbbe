//! Proxy meshes: a cloth simulated on a coarse mesh drawn with a finer one.

use bevy::mesh::{Mesh, VertexAttributeValues};
use bevy::prelude::*;

use crate::ecs::cloth::{ClothSimulation, pause_invalid};
use crate::ecs::events::ClothBuilt;
use crate::error::ClothError;
use crate::solver::ProxyBinding;

/// Draws a cloth with a render mesh of its own (finer than the simulation, with its own
/// UVs, tangents and material seams) instead of the simulation's mesh: each render
/// vertex is bound once, when the cloth is built, to the simulation triangle nearest it
/// at rest (its barycentric place and its height along the normal), then moved with it
/// every frame: positions, normals and tangents written in place (NvCloth's and Chaos
/// Cloth's skinning of a render mesh to a simulation mesh). The mesh's positions are in
/// the cloth entity's own frame, as the simulation's rest shape is; the entity's
/// `Mesh3d` becomes this mesh once it is bound. A mesh that cannot be bound (no
/// positions, a simulation without triangles) is refused: the cloth is paused with
/// [`ClothError::BadMesh`].
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[reflect(Component)]
pub struct ClothProxy {
    /// The render mesh.
    pub mesh: Handle<Mesh>,
}

/// A proxy bound to its cloth, with the frame's scratch (the simulation's positions and
/// normals in the cloth's frame) and the render vertices placed on them, written by
/// [`place_proxy`] (each cloth on its own, side by side) and then handed to the mesh by
/// [`give_to_mesh`].
#[derive(Component, Debug)]
pub(crate) struct ProxyBound {
    binding: ProxyBinding,
    local: Vec<Vec3>,
    normals: Vec<Vec3>,
    /// The render vertices' positions, normals and (when the mesh has them) tangents:
    /// swapped with the mesh's own buffers each frame, so nothing is copied or allocated.
    placed: Placed,
}

/// A proxy's render vertices as last placed, in buffers of the mesh's own kinds.
#[derive(Debug, Default)]
struct Placed {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    tangents: Option<Vec<[f32; 4]>>,
}

/// Proxy meshes: [`ClothProxy`] cloths drawn with their own finer meshes. In
/// [`ClothPlugin`](crate::ClothPlugin), beside [`ClothMeshPlugin`](crate::ClothMeshPlugin),
/// which writes them.
pub struct ClothProxyPlugin;

impl Plugin for ClothProxyPlugin {
    fn build(&self, app: &mut App) {
        app.register_type::<ClothProxy>()
            .add_observer(rebind_on_build)
            .add_systems(
                PostUpdate,
                bind_proxies.before(crate::ClothSystems::WriteMesh),
            );
    }
}

/// A cloth built again (a new shape) binds its proxy again.
fn rebind_on_build(
    built: On<ClothBuilt>,
    mut commands: Commands,
    proxies: Query<(), With<ClothProxy>>,
) {
    if proxies.contains(built.entity) {
        commands.entity(built.entity).remove::<ProxyBound>();
    }
}

/// Binds each built cloth's [`ClothProxy`] once its mesh is loaded, and draws the cloth
/// with it; a proxy changed for another mesh binds again.
#[allow(clippy::type_complexity)]
fn bind_proxies(
    mut commands: Commands,
    meshes: Res<Assets<Mesh>>,
    mut cloths: Query<
        (
            Entity,
            Ref<ClothProxy>,
            &mut ClothSimulation,
            Has<ProxyBound>,
        ),
        Or<(Without<ProxyBound>, Changed<ClothProxy>)>,
    >,
) {
    for (entity, proxy, mut sim, bound) in &mut cloths {
        if bound && !proxy.is_changed() {
            continue;
        }
        let Some(mesh) = meshes.get(&proxy.mesh) else {
            continue;
        };
        match bind(mesh, &sim.solver) {
            Ok(binding) => {
                let (n, m) = (sim.solver.particle_count(), binding.len());
                let tangents = mesh.attribute(Mesh::ATTRIBUTE_TANGENT).is_some();
                // Drawn on it from the next write, moving or not.
                sim.mesh_dirty = true;
                commands.entity(entity).insert((
                    ProxyBound {
                        binding,
                        local: vec![Vec3::ZERO; n],
                        normals: vec![Vec3::ZERO; n],
                        placed: Placed {
                            positions: vec![[0.0; 3]; m],
                            normals: vec![[0.0; 3]; m],
                            tangents: tangents.then(|| vec![[0.0; 4]; m]),
                        },
                    },
                    Mesh3d(proxy.mesh.clone()),
                ));
            }
            Err(e) => pause_invalid(&mut commands, entity, e),
        }
    }
}

/// Binds `mesh`'s vertices to `cloth`'s rest triangles.
fn bind(mesh: &Mesh, cloth: &crate::solver::ClothSolver) -> Result<ProxyBinding, ClothError> {
    let bad = |reason: &str| ClothError::BadMesh {
        reason: format!("proxy mesh: {reason}"),
    };
    let positions: Vec<Vec3> = match mesh.attribute(Mesh::ATTRIBUTE_POSITION) {
        Some(VertexAttributeValues::Float32x3(p)) => p.iter().map(|&p| Vec3::from(p)).collect(),
        _ => return Err(bad("it has no Float32x3 positions")),
    };
    if positions.iter().any(|p| !p.is_finite()) {
        return Err(bad("a vertex position is not finite"));
    }
    if !matches!(
        mesh.attribute(Mesh::ATTRIBUTE_NORMAL),
        Some(VertexAttributeValues::Float32x3(n)) if n.len() == positions.len()
    ) {
        return Err(bad("it has no Float32x3 normals to write"));
    }
    let tangents: Option<Vec<Vec4>> = match mesh.attribute(Mesh::ATTRIBUTE_TANGENT) {
        Some(VertexAttributeValues::Float32x4(t)) => {
            Some(t.iter().map(|&t| Vec4::from(t)).collect())
        }
        _ => None,
    };
    ProxyBinding::bind(
        cloth.rest_positions(),
        cloth.triangles(),
        &positions,
        tangents.as_deref(),
    )
    .ok_or_else(|| bad("the simulation has no triangles to bind it to"))
}

impl ProxyBound {
    /// Its render vertices.
    pub(crate) fn len(&self) -> usize {
        self.binding.len()
    }
}

/// Places a proxied cloth's render vertices in its own buffers: its simulation's
/// positions (drawn a fraction `t` of the way from `from` when blending) and `normals`
/// taken into its frame, and each render vertex placed on them. Reads nothing but the
/// cloth, so the cloths are placed side by side.
pub(crate) fn place_proxy(
    cloth: &crate::solver::ClothSolver,
    bound: &mut ProxyBound,
    normals: &[Vec3],
    blend: Option<(&[Vec3], f32)>,
) {
    let to_local = cloth.frame().inverse();
    let x = cloth.positions();
    let ProxyBound {
        binding,
        local,
        normals: local_normals,
        placed,
    } = bound;
    for (i, out) in local.iter_mut().enumerate() {
        let p = match blend {
            Some((from, t)) if from.len() == x.len() => from[i].lerp(x[i], t),
            _ => x[i],
        };
        *out = to_local.transform_point3(p);
    }
    for (out, n) in local_normals.iter_mut().zip(normals) {
        *out = to_local.transform_vector3(*n).normalize_or(Vec3::Z);
    }
    binding.place(
        local,
        local_normals,
        &mut placed.positions,
        &mut placed.normals,
        placed.tangents.as_deref_mut(),
    );
}

/// Hands the render vertices [`place_proxy`] placed to `mesh`, swapping its buffers
/// for them (its old ones are placed on next time). A mesh whose vertices are no longer
/// the bound ones (another mesh under the same handle) is left as it is.
pub(crate) fn give_to_mesh(mesh: &mut Mesh, bound: &mut ProxyBound) {
    let m = bound.binding.len();
    let placed = &mut bound.placed;
    let fits = |a: Option<&VertexAttributeValues>| a.is_some_and(|a| a.len() == m);
    if !fits(mesh.attribute(Mesh::ATTRIBUTE_POSITION))
        || !fits(mesh.attribute(Mesh::ATTRIBUTE_NORMAL))
    {
        return;
    }
    let swap = |mesh: &mut Mesh, attribute, mine: &mut Vec<[f32; 3]>| {
        if let Some(VertexAttributeValues::Float32x3(theirs)) = mesh.attribute_mut(attribute) {
            std::mem::swap(theirs, mine);
        }
    };
    swap(mesh, Mesh::ATTRIBUTE_POSITION, &mut placed.positions);
    swap(mesh, Mesh::ATTRIBUTE_NORMAL, &mut placed.normals);
    if let (Some(VertexAttributeValues::Float32x4(theirs)), Some(mine)) = (
        mesh.attribute_mut(Mesh::ATTRIBUTE_TANGENT),
        placed.tangents.as_mut(),
    ) && theirs.len() == m
    {
        std::mem::swap(theirs, mine);
    }
}
