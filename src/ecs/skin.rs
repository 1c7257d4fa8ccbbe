//! Cloth on animated characters: a mesh-shaped cloth whose mesh is skinned follows its
//! bones, and a painted maximum distance keeps each vertex near where the body puts it
//! (NvCloth's motion constraints, Unreal's "max distance": 0 at a skirt's waist, growing
//! to its hem).
//!
//! When a cloth is built from a mesh with a `SkinnedMesh`, the plugin takes the skin off
//! the entity (the simulated mesh is drawn as simulated, not skinned again on the GPU)
//! and keeps it here. Each step it skins each particle's rest position on the CPU with
//! the same linear blend Bevy's shader uses (`Σ wₖ · (jointₖ's global transform ·
//! inverse bindposeₖ) · v`), from the joints' transforms as they are when the step
//! begins, and gives the solver those points and the distances as motion constraints.
//! A mesh that is not skinned can have distances too: its targets are its rest shape in
//! the entity's frame. A back stop ([`ClothBackStop`]) keeps each particle off a sphere
//! behind its target (Jolt's skinned constraints): the body's surface without a collider
//! per bone.

use bevy::math::Affine3A;
use bevy::mesh::skinning::{SkinnedMesh, SkinnedMeshInverseBindposes};
use bevy::mesh::{MeshVertexAttribute, VertexFormat};
use bevy::prelude::*;
use bevy::transform::helper::TransformHelper;

use crate::ecs::cloth::ClothSimulation;
use crate::ecs::mesh::MeshSource;
use crate::error::ClothError;

/// A mesh's per-vertex maximum distance, m (`Float32`): how far the cloth may move from
/// where the body (or the entity's frame) puts the vertex; 0 holds it there.
pub const ATTRIBUTE_MAX_DISTANCE: MeshVertexAttribute =
    MeshVertexAttribute::new("Cloth_MaxDistance", 2_094_662_831, VertexFormat::Float32);

/// A mesh's per-vertex back stop (`Float32x2`: distance, radius, m): see
/// [`ClothBackStop`].
pub const ATTRIBUTE_BACK_STOP: MeshVertexAttribute =
    MeshVertexAttribute::new("Cloth_BackStop", 3_187_430_519, VertexFormat::Float32x2);

/// A mesh-shaped cloth's back stops (Jolt's skinned constraints, NvCloth's separation
/// constraints, Chaos's backstop): each particle kept outside a sphere of `radius` whose
/// surface lies `distance` behind its target (where the skin, or the entity's frame,
/// puts the vertex) along the target's normal, so a cape or skirt cannot swing into the
/// body it lies on, with no collider per bone. "Behind" is against the way the mesh's
/// normals point (out of the body), or without normals the side its triangles face
/// (counter-clockwise winding). A back stop acts only where its distance is below the particle's maximum
/// distance ([`ClothMaxDistance`]). Without this component a mesh with an
/// [`ATTRIBUTE_BACK_STOP`] uses it. A welded vertex (a UV seam) takes its first copy's.
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[reflect(Component, Debug, PartialEq)]
pub enum ClothBackStop {
    /// One back stop for every vertex.
    Uniform {
        /// How far behind its target a particle may go, m.
        distance: f32,
        /// The sphere's radius, m (0: none; large: a plane `distance` behind).
        radius: f32,
    },
    /// The mesh's [`ATTRIBUTE_BACK_STOP`].
    Attribute,
    /// `[distance, radius]` per vertex of the mesh, by its own vertex indices, m.
    PerVertex(Vec<[f32; 2]>),
}

/// Where a mesh-shaped cloth ([`Cloth::from_mesh`](crate::Cloth::from_mesh)) reads each
/// vertex's maximum distance from its target (its skinned position, or its rest position
/// in the entity's frame). Without this component a mesh with an
/// [`ATTRIBUTE_MAX_DISTANCE`] uses it; a skinned mesh without either has its pins at
/// distance 0 and every other particle free. A welded vertex (a UV seam) takes the
/// smallest of its copies'.
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[reflect(Component, Debug, PartialEq)]
pub enum ClothMaxDistance {
    /// The mesh's [`ATTRIBUTE_MAX_DISTANCE`].
    Attribute,
    /// A channel of the mesh's vertex colour (`Mesh::ATTRIBUTE_COLOR`: 0 red, 1 green,
    /// 2 blue, 3 alpha), times `scale` m: what a painting tool writes.
    VertexColor {
        /// Which channel.
        channel: u8,
        /// Metres at a channel value of 1.
        scale: f32,
    },
    /// One distance per vertex of the mesh, by the mesh's own vertex indices, m
    /// (`f32::INFINITY`: free).
    PerVertex(Vec<f32>),
}

/// What a mesh-shaped cloth follows of its body (internal): each particle's rest
/// position in the mesh's frame, its skinning, its maximum distance.
#[derive(Component, Clone, Debug)]
pub(crate) struct ClothBody {
    rest: Vec<Vec3>,
    pub(crate) skin: Option<BodySkin>,
    max_distance: Vec<f32>,
    targets: Vec<Vec3>,
    /// Whether the particles have been put where the body is (on the first step).
    placed: bool,
}

/// A skinned cloth's skin: the entity's `SkinnedMesh` (taken off it) and each particle's
/// joints and weights.
#[derive(Clone, Debug)]
pub(crate) struct BodySkin {
    pub(crate) mesh: SkinnedMesh,
    joints: Vec<[u16; 4]>,
    weights: Vec<[f32; 4]>,
    matrices: Vec<Affine3A>,
}

impl ClothBody {
    /// The body of a cloth made of `mesh` (`source` is its welded layout), skinned by
    /// `skin`, with distances read as `max` says and `pins` (particles) at distance 0
    /// when skinned. `None`: a plain mesh without distances (a free cloth).
    pub(crate) fn read(
        mesh: &Mesh,
        source: &MeshSource,
        skin: Option<&SkinnedMesh>,
        max: Option<&ClothMaxDistance>,
        pins: &[u32],
        back_stopped: bool,
    ) -> Result<Option<Self>, ClothError> {
        let per_vertex = painted(mesh, max, source.particle_of.len())?;
        if skin.is_none() && per_vertex.is_none() && !back_stopped {
            return Ok(None);
        }
        let n = source.positions.len();
        let mut max_distance = vec![f32::INFINITY; n];
        if let Some(d) = &per_vertex {
            for (v, &k) in source.particle_of.iter().enumerate() {
                max_distance[k as usize] = max_distance[k as usize].min(d[v]);
            }
        }
        let skin = match skin {
            Some(skinned) => {
                // Pins hold to where the skin puts them.
                for &i in pins {
                    max_distance[i as usize] = 0.0;
                }
                Some(BodySkin::read(mesh, source, skinned)?)
            }
            None => None,
        };
        Ok(Some(Self {
            rest: source.positions.clone(),
            skin,
            max_distance,
            targets: Vec::new(),
            placed: false,
        }))
    }

    /// Each particle's target now: skinned by the joints' `matrices`
    /// (`global · inverse bindpose`), or its rest position in `frame`.
    fn aim(&mut self, frame: Affine3A) {
        self.targets.clear();
        match &self.skin {
            Some(skin) => {
                let m = &skin.matrices;
                self.targets
                    .extend(self.rest.iter().enumerate().map(|(i, &v)| {
                        let (j, w) = (skin.joints[i], skin.weights[i]);
                        (0..4)
                            .map(|k| m[j[k] as usize].transform_point3(v) * w[k])
                            .sum::<Vec3>()
                    }));
            }
            None => self
                .targets
                .extend(self.rest.iter().map(|&v| frame.transform_point3(v))),
        }
    }
}

/// Each vertex's maximum distance as `max` says (or from the mesh's
/// [`ATTRIBUTE_MAX_DISTANCE`] without it), checked: one per vertex, none negative.
/// `None`: no distances.
fn painted(
    mesh: &Mesh,
    max: Option<&ClothMaxDistance>,
    vertices: usize,
) -> Result<Option<Vec<f32>>, ClothError> {
    use bevy::mesh::VertexAttributeValues::{Float32, Float32x4};
    let bad = |reason: String| ClothError::BadMesh { reason };
    let max = match max {
        Some(max) => max.clone(),
        None if mesh.attribute(ATTRIBUTE_MAX_DISTANCE).is_some() => ClothMaxDistance::Attribute,
        None => return Ok(None),
    };
    let d = match max {
        ClothMaxDistance::Attribute => match mesh.attribute(ATTRIBUTE_MAX_DISTANCE) {
            Some(Float32(d)) => d.clone(),
            _ => return Err(bad("it has no Float32 Cloth_MaxDistance attribute".into())),
        },
        ClothMaxDistance::VertexColor { channel, scale } => {
            match (mesh.attribute(Mesh::ATTRIBUTE_COLOR), channel) {
                (Some(Float32x4(c)), 0..=3) => {
                    c.iter().map(|c| c[channel as usize] * scale).collect()
                }
                _ => {
                    return Err(bad(format!(
                        "max distance from colour channel {channel}: it needs Float32x4 \
                         vertex colours and a channel from 0 to 3"
                    )));
                }
            }
        }
        ClothMaxDistance::PerVertex(d) => d,
    };
    if d.len() != vertices {
        return Err(bad(format!(
            "{} max distances for its {vertices} vertices",
            d.len()
        )));
    }
    if let Some(r) = d.iter().find(|r| r.is_nan() || **r < 0.0) {
        return Err(bad(format!("a max distance of {r} m (at least 0)")));
    }
    Ok(Some(d))
}

/// Each particle's back stop as `back` says (or from the mesh's [`ATTRIBUTE_BACK_STOP`]
/// without it), its first vertex's; empty: none. The values are checked by the solver.
pub(crate) fn back_stops(
    mesh: &Mesh,
    source: &MeshSource,
    back: Option<&ClothBackStop>,
) -> Result<Vec<crate::solver::BackStop>, ClothError> {
    use crate::solver::BackStop;
    use bevy::mesh::VertexAttributeValues::Float32x2;
    let back = match back {
        Some(back) => back,
        None if mesh.attribute(ATTRIBUTE_BACK_STOP).is_some() => &ClothBackStop::Attribute,
        None => return Ok(Vec::new()),
    };
    let per_vertex = match back {
        &ClothBackStop::Uniform { distance, radius } => {
            return Ok(vec![BackStop { distance, radius }; source.positions.len()]);
        }
        ClothBackStop::Attribute => match mesh.attribute(ATTRIBUTE_BACK_STOP) {
            Some(Float32x2(d)) => d,
            _ => {
                return Err(ClothError::BadMesh {
                    reason: "it has no Float32x2 Cloth_BackStop attribute".into(),
                });
            }
        },
        ClothBackStop::PerVertex(d) => d,
    };
    let vertices = source.particle_of.len();
    if per_vertex.len() != vertices {
        return Err(ClothError::BadMesh {
            reason: format!(
                "{} back stops for its {vertices} vertices",
                per_vertex.len()
            ),
        });
    }
    Ok(source
        .first_vertex
        .iter()
        .map(|&v| {
            let [distance, radius] = per_vertex[v as usize];
            BackStop { distance, radius }
        })
        .collect())
}

/// Whether a mesh's triangles are wound (counter-clockwise) to face against its normals
/// (`Mesh::ATTRIBUTE_NORMAL`), taken over the whole mesh: each triangle's area vector
/// against its corners' normals. False without normals.
pub(crate) fn wound_against_normals(mesh: &Mesh, source: &MeshSource) -> bool {
    let Some(bevy::mesh::VertexAttributeValues::Float32x3(normals)) =
        mesh.attribute(Mesh::ATTRIBUTE_NORMAL)
    else {
        return false;
    };
    let x = &source.positions;
    let normal = |k: u32| {
        let v = source.first_vertex[k as usize] as usize;
        normals.get(v).map_or(Vec3::ZERO, |&n| Vec3::from(n))
    };
    let agreement: f32 = source
        .triangles
        .iter()
        .map(|&[a, b, c]| {
            let area = (x[b as usize] - x[a as usize]).cross(x[c as usize] - x[a as usize]);
            area.dot(normal(a) + normal(b) + normal(c))
        })
        .sum();
    agreement < 0.0
}

impl BodySkin {
    /// The skin `skinned` of a cloth made of `mesh` (`source` its welded layout): each
    /// particle's joints and weights, its first vertex's.
    fn read(mesh: &Mesh, source: &MeshSource, skinned: &SkinnedMesh) -> Result<Self, ClothError> {
        use bevy::mesh::VertexAttributeValues::{Float32x4, Uint16x4};
        let bad = |reason: String| ClothError::BadMesh { reason };
        let (Some(Uint16x4(j)), Some(Float32x4(w))) = (
            mesh.attribute(Mesh::ATTRIBUTE_JOINT_INDEX),
            mesh.attribute(Mesh::ATTRIBUTE_JOINT_WEIGHT),
        ) else {
            return Err(bad(
                "it is skinned but has no Uint16x4 joint indices and Float32x4 joint weights"
                    .into(),
            ));
        };
        let joints: Vec<[u16; 4]> = source.first_vertex.iter().map(|&v| j[v as usize]).collect();
        if let Some(k) = joints
            .iter()
            .flatten()
            .find(|&&k| k as usize >= skinned.joints.len())
        {
            return Err(bad(format!(
                "joint index {k} is past its skin's {} joints",
                skinned.joints.len()
            )));
        }
        Ok(Self {
            mesh: skinned.clone(),
            joints,
            weights: source.first_vertex.iter().map(|&v| w[v as usize]).collect(),
            matrices: Vec::new(),
        })
    }
}

/// Gives each cloth with a body its motion constraints for this step: the targets where
/// its skin (from its joints' transforms now) or its frame puts each particle, and the
/// distances. On a cloth's first step its particles are put at their targets.
fn move_bodies(
    transforms: TransformHelper,
    bindposes: Option<Res<Assets<SkinnedMeshInverseBindposes>>>,
    mut cloths: Query<(Entity, &mut ClothSimulation, &mut ClothBody)>,
) {
    let (transforms, inverse) = (&transforms, bindposes.as_deref());
    // Side by side, as the cloths step: each one's skin and targets are its own.
    let bodies = cloths
        .iter_mut()
        .map(|c| (c.1.solver.particle_count() as u64, c));
    crate::solver::share_items(bodies, |(entity, mut sim, mut body)| {
        move_body(entity, &mut sim, &mut body, transforms, inverse);
    });
}

/// [`move_bodies`] for one cloth.
fn move_body(
    entity: Entity,
    sim: &mut ClothSimulation,
    body: &mut ClothBody,
    transforms: &TransformHelper,
    bindposes: Option<&Assets<SkinnedMeshInverseBindposes>>,
) {
    if let Some(skin) = &mut body.skin {
        let Some(inverse) = bindposes.and_then(|b| b.get(&skin.mesh.inverse_bindposes)) else {
            return; // not loaded yet (or no renderer's skinning in this app)
        };
        skin.matrices.clear();
        for (&joint, inverse) in skin.mesh.joints.iter().zip(inverse.iter()) {
            match transforms.compute_global_transform(joint) {
                Ok(global) => skin
                    .matrices
                    .push(global.affine() * Affine3A::from_mat4(*inverse)),
                Err(_) => break,
            }
        }
        if skin.matrices.len() != skin.mesh.joints.len() {
            warn_once!("cloth {entity}: a joint of its skin has no transform; not moved");
            return;
        }
    }
    body.aim(sim.solver.frame());
    if !body.placed {
        let p = sim.solver.particles_mut();
        for (i, &x) in body.targets.iter().enumerate() {
            p.position[i] = x;
            p.previous[i] = x;
            p.velocity[i] = Vec3::ZERO;
        }
        body.placed = true;
    }
    if let Err(e) = sim
        .solver
        .set_motion_constraints(&body.targets, &body.max_distance)
    {
        warn_once!("cloth {entity}: {e}");
    }
}

/// Cloth on skinned characters: a cloth made of a skinned mesh follows its skin, each
/// particle within its painted [`ClothMaxDistance`] of where the skin puts it and off its
/// [`ClothBackStop`].
pub struct ClothSkinPlugin;

impl Plugin for ClothSkinPlugin {
    fn build(&self, app: &mut App) {
        let schedule = crate::ecs::plugin::ClothSchedule::of(app);
        app.register_type::<ClothMaxDistance>()
            .register_type::<ClothBackStop>()
            .add_systems(
                schedule,
                move_bodies.in_set(crate::ecs::plugin::ClothPrepareSystems::Skin),
            );
    }
}
