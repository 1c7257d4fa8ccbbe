//! The cloth's render mesh: built once, then rewritten in place after each fixed step.

use bevy::asset::RenderAssetUsages;
use bevy::ecs::system::SystemState;
use bevy::math::Vec3;
use bevy::mesh::{Indices, Mesh, PrimitiveTopology, VertexAttributeValues};
use bevy::prelude::{Assets, Fixed, Local, Mesh3d, Query, Res, ResMut, Time, Visibility, World};

use crate::ecs::cloth::{ClothInterpolation, ClothSimulation};
use crate::ecs::proxy::{ProxyBound, give_to_mesh, place_proxy};

use crate::error::ClothError;
use crate::solver;

/// A mesh with one vertex per particle (positions in the cloth's local frame), smooth
/// normals, UVs and the visible triangles. `uvs` defaults to the grid's `(i/(w−1), j/(h−1))`.
pub fn cloth_mesh(cloth: &solver::ClothSolver, uvs: Option<Vec<[f32; 2]>>) -> Mesh {
    let n = cloth.particle_count();
    let uvs = uvs
        .filter(|u| u.len() == n)
        .unwrap_or_else(|| match cloth.grid_size() {
            Some((w, h)) => (0..n as u32)
                .map(|k| {
                    let (i, j) = (k % w, k / w);
                    [i as f32 / (w - 1) as f32, j as f32 / (h - 1) as f32]
                })
                .collect(),
            None => vec![[0.0, 0.0]; n],
        });
    let mut mesh = Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, vec![[0.0f32; 3]; n])
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, vec![[0.0f32, 0.0, 1.0]; n])
    .with_inserted_attribute(Mesh::ATTRIBUTE_UV_0, uvs)
    .with_inserted_indices(Indices::U32(Vec::new()));
    let mut normals = vec![Vec3::ZERO; n];
    write_mesh(&mut mesh, cloth, &mut normals, true);
    mesh
}

/// Writes positions and normals into the mesh's existing buffers (no new buffers), and
/// the index buffer too when `faces_changed` (a spring tore, or the mesh is new).
/// Positions are written in the cloth's frame, so the entity's transform places them.
pub fn write_mesh(
    mesh: &mut Mesh,
    cloth: &solver::ClothSolver,
    normals: &mut [Vec3],
    faces_changed: bool,
) {
    cloth.normals_into(normals);
    write_blended(mesh, cloth, normals, faces_changed, None);
}

/// [`write_mesh`] with the normals given, the positions drawn a fraction `t` of the way
/// from `from` (the positions when the last step began) to the cloth's now, when
/// `blend` is `Some((from, t))`.
fn write_blended(
    mesh: &mut Mesh,
    cloth: &solver::ClothSolver,
    normals: &[Vec3],
    faces_changed: bool,
    blend: Option<(&[Vec3], f32)>,
) {
    let to_local = cloth.frame().inverse();
    if let Some(VertexAttributeValues::Float32x3(out)) =
        mesh.attribute_mut(Mesh::ATTRIBUTE_POSITION)
    {
        let x = cloth.positions();
        match blend.filter(|(from, _)| from.len() == x.len()) {
            Some((from, t)) => solver::for_each_indexed(out, |i, o| {
                *o = to_local.transform_point3(from[i].lerp(x[i], t)).to_array();
            }),
            None => solver::for_each_indexed(out, |i, o| {
                *o = to_local.transform_point3(x[i]).to_array();
            }),
        }
    }
    if let Some(VertexAttributeValues::Float32x3(out)) = mesh.attribute_mut(Mesh::ATTRIBUTE_NORMAL)
    {
        solver::for_each_indexed(out, |i, o| {
            *o = to_local
                .transform_vector3(normals[i])
                .normalize_or(Vec3::Z)
                .to_array();
        });
    }
    if faces_changed {
        let visible = cloth.triangle_visible();
        let indices: Vec<u32> = cloth
            .triangles()
            .iter()
            .zip(visible)
            .filter(|(_, v)| **v)
            .flat_map(|(t, _)| *t)
            .collect();
        mesh.insert_indices(Indices::U32(indices));
    }
}

/// What a mesh-shaped cloth takes from its source mesh.
#[derive(Clone, Debug, Default)]
pub struct MeshSource {
    /// Vertex positions in the mesh's frame.
    pub positions: Vec<Vec3>,
    /// Triangles as vertex indices.
    pub triangles: Vec<[u32; 3]>,
    /// UVs, when the mesh has them.
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Each vertex of the mesh's particle (coincident vertices share one).
    pub particle_of: Vec<u32>,
    /// Each particle's first vertex (whose attributes it takes).
    pub first_vertex: Vec<u32>,
}

/// Reads a triangle-list mesh's positions, triangles and UVs, for a mesh-shaped cloth.
pub fn mesh_triangles(mesh: &Mesh) -> Result<MeshSource, ClothError> {
    let bad = |reason: &str| ClothError::BadMesh {
        reason: reason.to_string(),
    };
    if mesh.primitive_topology() != PrimitiveTopology::TriangleList {
        return Err(bad("only triangle lists can be cloth"));
    }
    let positions: Vec<Vec3> = match mesh.attribute(Mesh::ATTRIBUTE_POSITION) {
        Some(VertexAttributeValues::Float32x3(p)) => p.iter().map(|&p| Vec3::from(p)).collect(),
        _ => return Err(bad("it has no Float32x3 positions")),
    };
    let flat: Vec<u32> = match mesh.indices() {
        Some(indices) => indices.iter().map(|i| i as u32).collect(),
        None => (0..positions.len() as u32).collect(),
    };
    if let Some(i) = flat.iter().find(|&&i| i as usize >= positions.len()) {
        return Err(bad(&format!(
            "index {i} is past its {} vertices",
            positions.len()
        )));
    }
    if positions.iter().any(|p| !p.is_finite()) {
        return Err(bad("a vertex position is not finite"));
    }
    // One particle per place: coincident vertices (a non-indexed mesh, a UV seam) are
    // welded, the way `solver::ClothSolver::from_mesh` welds them, and keep the first UV.
    let welded = solver::topology::weld(&positions);
    let triangles = flat
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]].map(|v| welded.particle_of[v as usize]))
        .filter(|t: &[u32; 3]| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .collect();
    let mut first_vertex = vec![0u32; welded.positions.len()];
    for (v, &k) in welded.particle_of.iter().enumerate().rev() {
        first_vertex[k as usize] = v as u32;
    }
    let uvs = match mesh.attribute(Mesh::ATTRIBUTE_UV_0) {
        Some(VertexAttributeValues::Float32x2(uv)) if uv.len() == positions.len() => {
            Some(first_vertex.iter().map(|&v| uv[v as usize]).collect())
        }
        _ => None,
    };
    Ok(MeshSource {
        positions: welded.positions,
        triangles,
        uvs,
        particle_of: welded.particle_of,
        first_vertex,
    })
}

/// Writes each stepped cloth's positions and normals into its mesh (a proxied cloth's
/// into its [`ClothProxy`](crate::ClothProxy)'s, each render vertex placed on its
/// triangle). A cloth whose own
/// `Visibility` is `Hidden` is not written; it keeps its new state pending and is
/// written when shown. (Not for a hidden parent, whose effect is known only where
/// Bevy's visibility systems run; and not for frustum culling: Bevy takes a mesh's
/// bounding box from what was written, so an unwritten cloth that swings into view
/// would stay culled.)
///
/// With [`ClothInterpolation`] on, a cloth that moved in its last step is written every
/// frame, between where that step began and where it ended (its normals are the step's
/// end's, computed once a step).
///
/// Each cloth's normals and its proxy's vertices are worked out side by side on the
/// compute pool, then handed to the meshes one after another.
fn write_meshes(world: &mut World, mut state: Local<Option<SystemState<Drawing>>>) {
    let state = state.get_or_insert_with(|| SystemState::new(world));
    let Ok((mut meshes, interpolation, fixed, mut cloths)) = state.get_mut(world) else {
        return; // no fixed clock or no mesh assets: nothing is drawn
    };
    let blend = interpolation.is_some_and(|i| i.0);
    let t = fixed.overstep_fraction().clamp(0.0, 1.0);
    let due = |sim: &ClothSimulation, visibility: Option<&Visibility>| {
        (sim.mesh_dirty || blend && sim.blending) && visibility != Some(&Visibility::Hidden)
    };
    // Several cloths: side by side (a crowd's proxies took a fifth of its step when
    // placed one after another). An exclusive system, so that the calling thread works
    // beside the compute pool's (on two cores Bevy gives the pool one thread). One cloth:
    // below, with nothing allocated.
    let side_by_side =
        solver::threads() > 1 && cloths.iter().filter(|(sim, _, v, _)| due(sim, *v)).count() > 1;
    if side_by_side {
        let work = cloths
            .iter_mut()
            .filter(|(sim, _, visibility, _)| due(sim, *visibility))
            .map(|(sim, _, _, proxy)| {
                let n = proxy.as_ref().map_or(0, |p| p.len()) + sim.solver.particle_count();
                (n as u64, (sim, proxy))
            });
        solver::share_items(work, |(mut sim, mut proxy)| {
            prepare(&mut sim, proxy.as_deref_mut(), blend, t);
        });
    }
    // Then into the meshes, one after another (the assets are one resource).
    for (mut sim, mesh3d, visibility, mut proxy) in &mut cloths {
        if !due(&sim, visibility) {
            continue;
        }
        let Some(mut mesh) = meshes.get_mut(&mesh3d.0) else {
            continue;
        };
        let sim = &mut *sim;
        if !side_by_side {
            prepare(sim, proxy.as_deref_mut(), blend, t);
        }
        let faces_changed = sim.solver.take_faces_changed();
        match proxy {
            // A proxy's triangles are its own: torn faces stay drawn.
            Some(mut bound) => give_to_mesh(&mut mesh, &mut bound),
            None => {
                let from = blended(sim, blend, t);
                write_blended(&mut mesh, &sim.solver, &sim.normals, faces_changed, from);
            }
        }
        sim.mesh_dirty = false;
    }
}

/// A cloth's own drawing work: its normals once a step, and its proxy's render vertices
/// placed in the proxy's own buffers.
fn prepare(sim: &mut ClothSimulation, proxy: Option<&mut ProxyBound>, blend: bool, t: f32) {
    if sim.mesh_dirty {
        sim.solver.normals_into(&mut sim.normals);
    }
    if let Some(bound) = proxy {
        place_proxy(&sim.solver, bound, &sim.normals, blended(sim, blend, t));
    }
}

/// Where `sim` is drawn from when it is blended between its last two steps (`blend`
/// on and it moved), `t` of the way: the positions as its last step began.
fn blended(sim: &ClothSimulation, blend: bool, t: f32) -> Option<(&[Vec3], f32)> {
    (blend && sim.blending).then_some((sim.previous.as_slice(), t))
}

/// What [`write_meshes`] reads and writes.
type Drawing = (
    ResMut<'static, Assets<Mesh>>,
    Option<Res<'static, ClothInterpolation>>,
    Res<'static, Time<Fixed>>,
    Query<
        'static,
        'static,
        (
            &'static mut ClothSimulation,
            &'static Mesh3d,
            Option<&'static Visibility>,
            Option<&'static mut ProxyBound>,
        ),
    >,
);

/// Drawing: once a frame (in `PostUpdate`, [`ClothSystems::WriteMesh`]), each cloth's
/// positions and normals written into its mesh in place, between the last two fixed
/// steps when they are fixed ones ([`ClothInterpolation`]). Without it the cloths are
/// simulated and not drawn (a headless run, a server).
///
/// [`ClothSystems::WriteMesh`]: crate::ClothSystems::WriteMesh
pub struct ClothMeshPlugin;

impl bevy::app::Plugin for ClothMeshPlugin {
    fn build(&self, app: &mut bevy::app::App) {
        use bevy::prelude::IntoScheduleConfigs;
        app.add_systems(
            bevy::app::PostUpdate,
            write_meshes
                .in_set(crate::ClothSystems::WriteMesh)
                .before(bevy::asset::AssetEventSystems),
        );
    }
}
