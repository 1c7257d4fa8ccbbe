//! Proxy meshes: a cloth simulated on a coarse mesh drawn with a finer one.

use std::collections::HashMap;

use bevy::mesh::{Mesh, VertexAttributeValues};
use bevy::prelude::*;

use bevy::math::{Affine3A, Vec3A};
use bevy::mesh::skinning::SkinnedMesh;
use bevy::transform::TransformSystems;

use crate::ecs::cloth::{ClothInvalid, ClothSimulation, pause_invalid};
use crate::ecs::events::ClothBuilt;
use crate::error::ClothError;
use crate::solver::ProxyBinding;

/// Draws a cloth with a render mesh of its own (finer than the simulation, with its own
/// UVs, tangents and material seams) instead of the simulation's mesh: each render
/// vertex is bound once, when the cloth is built, to the simulation triangle nearest it
/// at rest (its barycentric place and its height along the normal), then moved with it
/// every frame: positions, normals and tangents written in place (NvCloth's and Chaos
/// Cloth's skinning of a render mesh to a simulation mesh). The mesh's positions are in
/// the cloth entity's own frame, as the simulation's rest shape is. Once it is bound the
/// entity draws its own copy of it (its `Mesh3d` becomes the copy): the mesh itself stays
/// as it was, so that many cloths may be drawn through one mesh, as a crowd's capes are,
/// and cloths of one rest shape drawn through one mesh share their binding. A mesh that
/// cannot be bound (no positions, a simulation without triangles) is refused: the cloth
/// is paused with [`ClothError::BadMesh`].
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[reflect(Component)]
pub struct ClothProxy {
    /// The render mesh.
    pub mesh: Handle<Mesh>,
}

/// Draws a cloth with another entity's mesh: the render mesh of a pair exported in one
/// file (a glTF with a coarse simulation mesh and a fine render mesh, each found by its
/// `GltfMeshName`), as Chaos Cloth and Magica Cloth pair a render mesh with the mesh they
/// simulate. Once that entity's `Mesh3d` is loaded, the cloth gets a [`ClothProxy`] of it
/// and the entity is hidden: the cloth draws it.
///
/// Frames: when the render entity is skinned, its positions are in the skin's bind space,
/// as a skinned simulation mesh's are, and are bound as they are (glTF ignores a skinned
/// mesh node's own transform). Otherwise they are carried from the render entity's frame
/// into the cloth entity's, in a copy of the mesh when the two are placed apart. An entity
/// that is gone or has no `Mesh3d` is refused: the cloth is paused with
/// [`ClothError::BadMesh`].
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, Reflect)]
#[reflect(Component)]
pub struct ClothProxyEntity(pub Entity);

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
            .register_type::<ClothProxyEntity>()
            .add_observer(rebind_on_build)
            .add_systems(
                PostUpdate,
                (
                    adopt_proxy_entities.after(TransformSystems::Propagate),
                    bind_proxies,
                )
                    .chain()
                    .before(crate::ClothSystems::WriteMesh),
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

/// Gives each [`ClothProxyEntity`] cloth a [`ClothProxy`] of that entity's mesh once it is
/// loaded (in the cloth's frame), and hides the entity.
#[allow(clippy::type_complexity)]
fn adopt_proxy_entities(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    cloths: Query<
        (Entity, &ClothProxyEntity, &GlobalTransform),
        (
            Or<(Without<ClothProxy>, Changed<ClothProxyEntity>)>,
            Without<ClothInvalid>,
        ),
    >,
    renders: Query<(&Mesh3d, &GlobalTransform, Has<SkinnedMesh>)>,
) {
    for (entity, source, frame) in &cloths {
        let Ok((render, placed, skinned)) = renders.get(source.0) else {
            let reason = format!("proxy entity {}: it has no Mesh3d", source.0);
            pause_invalid(&mut commands, entity, ClothError::BadMesh { reason });
            continue;
        };
        let Some(mesh) = meshes.get(&render.0) else {
            continue; // still loading
        };
        // The render entity's frame seen from the cloth's.
        let apart = frame.affine().inverse() * placed.affine();
        let mesh = if skinned || apart.abs_diff_eq(Affine3A::IDENTITY, 1e-6) {
            render.0.clone()
        } else {
            let carried = carried(mesh, apart);
            meshes.add(carried)
        };
        commands.entity(entity).insert(ClothProxy { mesh });
        commands.entity(source.0).insert(Visibility::Hidden);
    }
}

/// A copy of `mesh` with its positions, normals and tangents moved by `by`.
fn carried(mesh: &Mesh, by: Affine3A) -> Mesh {
    let mut mesh = mesh.clone();
    let turn = by.matrix3;
    let normal = turn.inverse().transpose();
    // A mirroring move flips the tangents' handedness.
    let handed = turn.determinant().signum();
    if let Some(VertexAttributeValues::Float32x3(p)) = mesh.attribute_mut(Mesh::ATTRIBUTE_POSITION)
    {
        for p in p.iter_mut() {
            *p = by.transform_point3(Vec3::from(*p)).to_array();
        }
    }
    if let Some(VertexAttributeValues::Float32x3(n)) = mesh.attribute_mut(Mesh::ATTRIBUTE_NORMAL) {
        for n in n.iter_mut() {
            *n = (normal * Vec3A::from(*n)).normalize_or_zero().to_array();
        }
    }
    if let Some(VertexAttributeValues::Float32x4(t)) = mesh.attribute_mut(Mesh::ATTRIBUTE_TANGENT) {
        for t in t.iter_mut() {
            let turned = (turn * Vec3A::new(t[0], t[1], t[2])).normalize_or_zero();
            *t = [turned.x, turned.y, turned.z, t[3] * handed];
        }
    }
    mesh
}

/// Binds each built cloth's [`ClothProxy`] once its mesh is loaded, and draws the cloth
/// with it; a proxy changed for another mesh binds again.
#[allow(clippy::type_complexity)]
fn bind_proxies(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut bound_before: Local<Bindings>,
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
        match bound_before.bind(proxy.mesh.id(), mesh, &sim.solver) {
            Ok(binding) => {
                let (n, m) = (sim.solver.particle_count(), binding.len());
                let tangents = mesh.attribute(Mesh::ATTRIBUTE_TANGENT).is_some();
                // The cloth's own copy to draw into: the proxy's mesh stays as it was,
                // for the other cloths drawn through it (a crowd's capes) and to bind
                // again.
                let copy = mesh.clone();
                let drawn = meshes.add(copy);
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
                    Mesh3d(drawn),
                ));
            }
            Err(e) => pause_invalid(&mut commands, entity, e),
        }
    }
}

/// The bindings made so far, by their proxy mesh and a fingerprint of what was bound (the
/// mesh's positions and tangents, the simulation's rest positions and triangles): a cloth
/// bound as another was shares its binding (what binding worked out is read from memory
/// once a frame for all of them). Entries no cloth holds any longer are dropped when the
/// next is made.
#[derive(Default)]
struct Bindings(HashMap<(AssetId<Mesh>, u64), ProxyBinding>);

impl Bindings {
    /// `mesh` (the asset `id`) bound to `cloth`'s rest triangles: a clone of a binding
    /// made before from the same mesh and rest shape, or bound afresh.
    fn bind(
        &mut self,
        id: AssetId<Mesh>,
        mesh: &Mesh,
        cloth: &crate::solver::ClothSolver,
    ) -> Result<ProxyBinding, ClothError> {
        let (positions, tangents) = render_vertices(mesh)?;
        let (rest, triangles) = (cloth.rest_positions(), cloth.triangles());
        let key = (
            id,
            fingerprint(&positions, tangents.as_deref(), rest, triangles),
        );
        if let Some(before) = self.0.get(&key)
            // The fingerprint is a hash: the binding is taken only if it puts every
            // vertex back where it is.
            && before.len() == positions.len()
            && (0..positions.len()).all(|v| before.point(rest, v).distance(positions[v]) < 1e-5)
        {
            return Ok(before.clone());
        }
        let binding = ProxyBinding::bind(rest, triangles, &positions, tangents.as_deref())
            .ok_or_else(|| bad_proxy("the simulation has no triangles to bind it to"))?;
        self.0.retain(|_, kept| kept.sharers() > 1);
        self.0.insert(key, binding.clone());
        Ok(binding)
    }
}

/// A hash of what a binding is made from.
fn fingerprint(
    positions: &[Vec3],
    tangents: Option<&[Vec4]>,
    rest: &[Vec3],
    triangles: &[[u32; 3]],
) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut hasher = std::hash::DefaultHasher::new();
    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
    positions.iter().for_each(|&p| bits(p).hash(&mut hasher));
    tangents.map(<[Vec4]>::len).hash(&mut hasher);
    for t in tangents.unwrap_or_default() {
        t.to_array().map(f32::to_bits).hash(&mut hasher);
    }
    rest.iter().for_each(|&p| bits(p).hash(&mut hasher));
    triangles.hash(&mut hasher);
    hasher.finish()
}

/// A proxy mesh refused, for `reason`.
fn bad_proxy(reason: &str) -> ClothError {
    ClothError::BadMesh {
        reason: format!("proxy mesh: {reason}"),
    }
}

/// `mesh`'s positions and tangents (if it has them), checked: finite positions, and
/// normals to write.
fn render_vertices(mesh: &Mesh) -> Result<(Vec<Vec3>, Option<Vec<Vec4>>), ClothError> {
    let positions: Vec<Vec3> = match mesh.attribute(Mesh::ATTRIBUTE_POSITION) {
        Some(VertexAttributeValues::Float32x3(p)) => p.iter().map(|&p| Vec3::from(p)).collect(),
        _ => return Err(bad_proxy("it has no Float32x3 positions")),
    };
    if positions.iter().any(|p| !p.is_finite()) {
        return Err(bad_proxy("a vertex position is not finite"));
    }
    if !matches!(
        mesh.attribute(Mesh::ATTRIBUTE_NORMAL),
        Some(VertexAttributeValues::Float32x3(n)) if n.len() == positions.len()
    ) {
        return Err(bad_proxy("it has no Float32x3 normals to write"));
    }
    let tangents: Option<Vec<Vec4>> = match mesh.attribute(Mesh::ATTRIBUTE_TANGENT) {
        Some(VertexAttributeValues::Float32x4(t)) => {
            Some(t.iter().map(|&t| Vec4::from(t)).collect())
        }
        _ => None,
    };
    Ok((positions, tangents))
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
        *out = to_local.transform_vector3(*n);
    }
    crate::solver::unit::normalize_each_or(local_normals, Vec3::Z);
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

#[cfg(test)]
mod tests {
    use super::*;
    use bevy::asset::RenderAssetUsages;
    use bevy::mesh::PrimitiveTopology;

    /// A cloth bound as another was (the same proxy mesh, the same rest shape) shares its
    /// binding; another mesh, or another rest shape, binds afresh; a binding no cloth holds
    /// any longer is dropped when the next is made.
    #[test]
    fn cloths_bound_alike_share_their_binding() {
        use crate::layout::shape::{ClothPins, ClothShape};
        let solver = |spacing: f32| {
            ClothShape::Grid {
                width: 4,
                height: 3,
                spacing,
            }
            .build_solver(
                &ClothPins::None,
                &crate::params::ClothParams::seeds(),
                Affine3A::IDENTITY,
            )
            .unwrap()
        };
        let (cloth, wider) = (solver(0.1), solver(0.2));
        // The simulation's own vertices, a little off its plane, drawn as the proxy.
        let render: Vec<[f32; 3]> = cloth
            .rest_positions()
            .iter()
            .map(|p| (*p + Vec3::Z * 0.01).to_array())
            .collect();
        let mut mesh = Mesh::new(PrimitiveTopology::TriangleList, RenderAssetUsages::all());
        mesh.insert_attribute(Mesh::ATTRIBUTE_NORMAL, vec![[0.0, 0.0, 1.0]; render.len()]);
        mesh.insert_attribute(Mesh::ATTRIBUTE_POSITION, render);
        let (id, other) = (AssetId::<Mesh>::default(), AssetId::<Mesh>::invalid());
        let mut bindings = Bindings::default();
        let first = bindings.bind(id, &mesh, &cloth).unwrap();
        let second = bindings.bind(id, &mesh, &cloth).unwrap();
        assert!(first.shares_with(&second));
        assert_eq!(first, second);
        let third = bindings.bind(other, &mesh, &cloth).unwrap();
        assert!(!third.shares_with(&first), "another mesh binds afresh");
        let fourth = bindings.bind(id, &mesh, &wider).unwrap();
        assert!(
            !fourth.shares_with(&first),
            "another rest shape binds afresh"
        );
        assert_eq!(bindings.0.len(), 3);
        drop((first, second, third));
        bindings.bind(other, &mesh, &wider).unwrap();
        assert_eq!(bindings.0.len(), 2, "the two no cloth held are dropped");
    }

    /// A mesh carried by a stretching, mirroring move keeps its normals perpendicular to
    /// its moved surface and flips its tangents' handedness.
    #[test]
    fn a_carried_mesh_keeps_its_normals_on_its_surface() {
        let mut mesh = Mesh::new(PrimitiveTopology::TriangleList, RenderAssetUsages::all());
        let flat = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 1.0]];
        let a = Vec3::from(flat[1]) - Vec3::from(flat[0]);
        let b = Vec3::from(flat[2]) - Vec3::from(flat[0]);
        let n = a.cross(b).normalize();
        mesh.insert_attribute(Mesh::ATTRIBUTE_POSITION, flat);
        mesh.insert_attribute(Mesh::ATTRIBUTE_NORMAL, vec![n.to_array(); 3]);
        mesh.insert_attribute(Mesh::ATTRIBUTE_TANGENT, vec![[1.0, 0.0, 0.0, 1.0]; 3]);
        let by = Affine3A::from_scale_rotation_translation(
            Vec3::new(-1.0, 3.0, 0.5),
            Quat::from_rotation_y(0.7),
            Vec3::new(2.0, -1.0, 4.0),
        );
        let moved = carried(&mesh, by);
        let Some(VertexAttributeValues::Float32x3(p)) = moved.attribute(Mesh::ATTRIBUTE_POSITION)
        else {
            panic!("positions")
        };
        let Some(VertexAttributeValues::Float32x3(normals)) =
            moved.attribute(Mesh::ATTRIBUTE_NORMAL)
        else {
            panic!("normals")
        };
        let Some(VertexAttributeValues::Float32x4(t)) = moved.attribute(Mesh::ATTRIBUTE_TANGENT)
        else {
            panic!("tangents")
        };
        let [p0, p1, p2] = [p[0], p[1], p[2]].map(Vec3::from);
        assert!(p0.abs_diff_eq(Vec3::new(2.0, -1.0, 4.0), 1e-6));
        let normal = Vec3::from(normals[0]);
        assert!((normal.length() - 1.0).abs() < 1e-5);
        assert!(normal.dot(p1 - p0).abs() < 1e-5 && normal.dot(p2 - p0).abs() < 1e-5);
        assert_eq!(t[0][3], -1.0, "a mirror flips the handedness");
    }
}
