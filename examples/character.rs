//! A character walking in a circle, wearing a skirt and a cape. The character is a
//! skinned mesh built in code (as Bevy's custom skinned mesh example builds one: joints
//! as entities, joint indices and weights on the vertices, inverse bindposes), walked by
//! an `AnimationClip` of its joints, built in code. The cloths step after the animation
//! (`ClothPlugin::new(PostUpdate)`). The skirt is a cloth made of a skinned mesh
//! (`Cloth::from_mesh` on an entity with a `SkinnedMesh`): the plugin skins it on the CPU
//! every step and keeps each vertex within its painted maximum distance
//! (`ATTRIBUTE_MAX_DISTANCE`: 0 at the waist, growing to the hem) of where the skin puts
//! it, and out of a sphere 2 cm behind it (`ClothBackStop`: the hips without a collider).
//! Its legs are capsules spanning their joints (`ClothColliderSpan`), so they push
//! the skirt as they swing; the cape hangs from the spine joint (`ClothAttachments`)
//! against a capsule on the back. Orbit camera and inspector as in the other examples.
//!
//! `cargo run --example character [-- --screenshot out.png --frames 120]`

// The shared example code; this example builds its own scene, so it uses part of it.
#[allow(dead_code)]
mod common;

use std::f32::consts::TAU;

use bevy::animation::{AnimatedBy, AnimationTargetId, animated_field};
use bevy::asset::RenderAssetUsages;
use bevy::math::curve::{Interval, SampleAutoCurve};
use bevy::mesh::skinning::{SkinnedMesh, SkinnedMeshInverseBindposes};
use bevy::mesh::{Indices, PrimitiveTopology, VertexAttributeValues};
use bevy::prelude::*;
use bevy_cloth::ATTRIBUTE_MAX_DISTANCE;
use bevy_cloth::prelude::*;
use bevy_panorbit_camera::PanOrbitCamera;

/// The hips' height, and the thigh's and shin's lengths (m).
const HIP: f32 = 0.92;
const THIGH: f32 = 0.42;
const SHIN: f32 = 0.42;
/// The hip joints' distance from the middle, and the spine joint's height over the hips.
const HIP_WIDTH: f32 = 0.09;
const SPINE: f32 = 0.28;
/// The walk: a circle of this radius (m), once round in `LAP` s, a stride every `STRIDE` s.
const RADIUS: f32 = 0.7;
const LAP: f32 = 6.0;
const STRIDE: f32 = 1.0;
/// The skirt's rings (waist to hem) and points round each ring; its maximum distance at
/// the hem (m).
const SKIRT_ROWS: u32 = 14;
const SKIRT_AROUND: u32 = 36;
const HEM_DISTANCE: f32 = 0.22;

/// A joint of the character and what the walk does with it.
#[derive(Component, Clone, Copy)]
enum Joint {
    Hips,
    Spine,
    /// A thigh, and its side (+1 left, −1 right).
    Thigh(f32),
    Knee(f32),
}

fn main() {
    let args = common::ExampleArgs::parse("");
    // The cloths step after the animation, once a frame: the skirt's skin is read in the
    // pose the body is drawn in.
    common::app_with("bevy_cloth — character", args, ClothPlugin::new(PostUpdate))
        .add_plugins(common::tools::ToolsPlugin)
        .add_systems(Startup, (setup, animate).chain())
        .add_systems(Update, follow)
        .run();
}

/// Plays the walk on the skeleton: the hips hold the animation player, and every joint
/// is a target of the clip, named by its `Name`.
fn animate(
    mut commands: Commands,
    mut clips: ResMut<Assets<AnimationClip>>,
    mut graphs: ResMut<Assets<AnimationGraph>>,
    joints: Query<(Entity, &Joint, &Name)>,
) {
    let Some((hips, ..)) = joints.iter().find(|(_, j, _)| matches!(j, Joint::Hips)) else {
        return;
    };
    let mut targets = Vec::new();
    for (entity, &joint, name) in &joints {
        let target = AnimationTargetId::from_name(name);
        commands.entity(entity).insert((target, AnimatedBy(hips)));
        targets.push((joint, target));
    }
    let (graph, walk) = AnimationGraph::from_clip(clips.add(walk_clip(&targets)));
    let mut player = AnimationPlayer::default();
    player.play(walk).repeat();
    commands
        .entity(hips)
        .insert((player, AnimationGraphHandle(graphs.add(graph))));
}

/// Where a point `v` of the body in its bind pose is weighted, for the body's joints
/// (hips, spine, left thigh, left knee, right thigh, right knee): joint indices and
/// weights, blending over `blend` m about a joint.
fn body_weights(v: Vec3) -> ([u16; 4], [f32; 4]) {
    let blend = |y: f32, at: f32, width: f32| ((at + width - y) / (2.0 * width)).clamp(0.0, 1.0);
    if v.y > HIP - 0.06 {
        // The torso: the hips below, the spine above.
        let up = 1.0 - blend(v.y, HIP + 0.1, 0.1);
        ([0, 1, 0, 0], [1.0 - up, up, 0.0, 0.0])
    } else {
        let (thigh, knee) = if v.x > 0.0 { (2, 3) } else { (4, 5) };
        let below = blend(v.y, HIP - THIGH, 0.05);
        ([thigh, knee, 0, 0], [1.0 - below, below, 0.0, 0.0])
    }
}

/// A tube of rings about the y axis at `centre` (x, z), from `(y, radius)` pairs, as
/// positions, normals and triangle indices appended to the given lists.
fn tube(
    centre: Vec2,
    rings: &[(f32, f32)],
    around: u32,
    positions: &mut Vec<Vec3>,
    normals: &mut Vec<Vec3>,
    indices: &mut Vec<u32>,
) {
    let first = positions.len() as u32;
    for &(y, r) in rings {
        for i in 0..=around {
            let a = TAU * i as f32 / around as f32;
            let radial = Vec3::new(a.sin(), 0.0, a.cos());
            positions.push(Vec3::new(centre.x, y, centre.y) + radial * r);
            normals.push(radial);
        }
    }
    let row = around + 1;
    for j in 0..rings.len() as u32 - 1 {
        for i in 0..around {
            let a = first + j * row + i;
            indices.extend([a, a + 1, a + row, a + 1, a + row + 1, a + row]);
        }
    }
}

/// The body as one skinned mesh in its bind pose (feet on the ground at the origin,
/// facing +z): a torso and two legs, each a tube of rings.
fn body_mesh() -> Mesh {
    let (mut positions, mut normals, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    let torso = [
        (HIP - 0.08, 0.13),
        (HIP + 0.05, 0.16),
        (HIP + 0.25, 0.15),
        (HIP + 0.45, 0.17),
        (HIP + 0.52, 0.1),
        (HIP + 0.56, 0.05),
    ];
    tube(
        Vec2::ZERO,
        &torso,
        20,
        &mut positions,
        &mut normals,
        &mut indices,
    );
    for side in [1.0, -1.0] {
        let leg: Vec<(f32, f32)> = (0..=10)
            .map(|k| {
                let y = HIP - 0.02 - (THIGH + SHIN - 0.04) * k as f32 / 10.0;
                (y, 0.075 - 0.03 * k as f32 / 10.0)
            })
            .collect();
        let x = side * HIP_WIDTH;
        tube(
            Vec2::new(x, 0.0),
            &leg,
            14,
            &mut positions,
            &mut normals,
            &mut indices,
        );
    }
    let (joints, weights): (Vec<[u16; 4]>, Vec<[f32; 4]>) =
        positions.iter().map(|&v| body_weights(v)).unzip();
    skinned_mesh(positions, normals, indices, joints, weights)
}

/// A triangle mesh with the joint indices and weights a `SkinnedMesh` needs.
fn skinned_mesh(
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    indices: Vec<u32>,
    joints: Vec<[u16; 4]>,
    weights: Vec<[f32; 4]>,
) -> Mesh {
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, normals)
    .with_inserted_attribute(
        Mesh::ATTRIBUTE_JOINT_INDEX,
        VertexAttributeValues::Uint16x4(joints),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_JOINT_WEIGHT, weights)
    .with_inserted_indices(Indices::U32(indices))
}

/// The skirt in the bind pose: an A-line cone from the waist to above the knees, skinned
/// wholly to the hips (its one joint), its maximum distance painted 0 at the waist and
/// growing as the square of the way down to `HEM_DISTANCE` at the hem.
fn skirt_mesh() -> Mesh {
    let (mut positions, mut normals, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    let rings: Vec<(f32, f32)> = (0..SKIRT_ROWS)
        .map(|j| {
            let down = j as f32 / (SKIRT_ROWS - 1) as f32;
            (HIP + 0.04 - 0.42 * down, 0.185 + 0.14 * down)
        })
        .collect();
    tube(
        Vec2::ZERO,
        &rings,
        SKIRT_AROUND,
        &mut positions,
        &mut normals,
        &mut indices,
    );
    let distance: Vec<f32> = positions
        .iter()
        .map(|p| HEM_DISTANCE * ((HIP + 0.04 - p.y) / 0.42).clamp(0.0, 1.0).powi(2))
        .collect();
    let n = positions.len();
    let joints = vec![[0; 4]; n];
    skinned_mesh(
        positions,
        normals,
        indices,
        joints,
        vec![[1.0, 0.0, 0.0, 0.0]; n],
    )
    .with_inserted_attribute(ATTRIBUTE_MAX_DISTANCE, distance)
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut bindposes: ResMut<Assets<SkinnedMeshInverseBindposes>>,
) {
    // The skeleton, each joint placed relative to its parent; the walk moves them.
    let hips = commands
        .spawn((
            Transform::from_xyz(RADIUS, HIP, 0.0),
            Joint::Hips,
            Name::new("hips"),
        ))
        .id();
    let spine = commands
        .spawn((
            Transform::from_xyz(0.0, SPINE, 0.0),
            Joint::Spine,
            ChildOf(hips),
            Name::new("spine"),
        ))
        .id();
    let mut legs = Vec::new();
    for (side, name) in [(1.0, "left"), (-1.0, "right")] {
        let thigh = commands
            .spawn((
                Transform::from_xyz(side * HIP_WIDTH, -0.02, 0.0),
                Joint::Thigh(side),
                ChildOf(hips),
                Name::new(format!("{name} thigh")),
            ))
            .id();
        let knee = commands
            .spawn((
                Transform::from_xyz(0.0, -THIGH, 0.0),
                Joint::Knee(side),
                ChildOf(thigh),
                Name::new(format!("{name} knee")),
            ))
            .id();
        let ankle = commands
            .spawn((Transform::from_xyz(0.0, -SHIN, 0.0), ChildOf(knee)))
            .id();
        // The legs as colliders from joint to joint: they push the skirt.
        commands.spawn((
            ClothCollider::capsule(0.08, 0.0),
            ClothColliderSpan {
                from: thigh,
                to: knee,
            },
            Name::new(format!("{name} thigh collider")),
        ));
        commands.spawn((
            ClothCollider::capsule(0.06, 0.0),
            ClothColliderSpan {
                from: knee,
                to: ankle,
            },
            Name::new(format!("{name} shin collider")),
        ));
        legs.push((thigh, knee));
    }
    // The bind pose: each joint's global transform with the feet at the origin.
    let hips_bind = Mat4::from_translation(Vec3::new(0.0, HIP, 0.0));
    let thigh_bind =
        |side: f32| hips_bind * Mat4::from_translation(Vec3::new(side * HIP_WIDTH, -0.02, 0.0));
    let knee_bind =
        |side: f32| thigh_bind(side) * Mat4::from_translation(Vec3::new(0.0, -THIGH, 0.0));
    let spine_bind = hips_bind * Mat4::from_translation(Vec3::new(0.0, SPINE, 0.0));
    let inverse = |m: Mat4| m.inverse();
    let body_skin = SkinnedMesh {
        inverse_bindposes: bindposes.add(SkinnedMeshInverseBindposes::from(vec![
            inverse(hips_bind),
            inverse(spine_bind),
            inverse(thigh_bind(1.0)),
            inverse(knee_bind(1.0)),
            inverse(thigh_bind(-1.0)),
            inverse(knee_bind(-1.0)),
        ])),
        joints: vec![hips, spine, legs[0].0, legs[0].1, legs[1].0, legs[1].1],
    };
    let grey = materials.add(StandardMaterial {
        base_color: Color::srgb(0.62, 0.6, 0.58),
        perceptual_roughness: 0.7,
        ..default()
    });
    commands.spawn((
        Mesh3d(meshes.add(body_mesh())),
        MeshMaterial3d(grey.clone()),
        body_skin,
        Name::new("body"),
    ));
    commands.spawn((
        Mesh3d(meshes.add(Sphere::new(0.11))),
        MeshMaterial3d(grey),
        Transform::from_xyz(0.0, 0.43, 0.0),
        ChildOf(spine),
        Name::new("head"),
    ));
    // The skirt: a cloth of the skinned mesh, its skin the hips.
    commands.spawn((
        Mesh3d(meshes.add(skirt_mesh())),
        SkinnedMesh {
            inverse_bindposes: bindposes
                .add(SkinnedMeshInverseBindposes::from(vec![inverse(hips_bind)])),
            joints: vec![hips],
        },
        Cloth::from_mesh()
            .with_pins(ClothPins::None)
            .with_params(ClothParams {
                node_mass: 2e-4,
                ..ClothParams::seeds()
            }),
        // Never more than 2 cm into the body, however the hips turn.
        ClothBackStop::Uniform {
            distance: 0.02,
            radius: 0.3,
        },
        MeshMaterial3d(materials.add(fabric(Color::srgb(0.15, 0.35, 0.75), 0.85))),
        Name::new("skirt"),
    ));
    // The back, for the cape to lie against, and the cape hung from the spine joint by
    // its top row (each particle where it is in the spine's frame when first attached).
    commands.spawn((
        ClothCollider::capsule(0.16, 0.3),
        Transform::from_xyz(0.0, 0.08, 0.0),
        ChildOf(spine),
        Name::new("back collider"),
    ));
    let (width, height) = (14, 20);
    commands.spawn((
        Cloth::grid(width, height, 0.035)
            .with_pins(ClothPins::None)
            .with_params(ClothParams {
                node_mass: 2e-4,
                ..ClothParams::seeds()
            }),
        Transform::from_xyz(RADIUS, HIP + SPINE + 0.2, -0.19),
        ClothAttachments(vec![ClothAttachment::indices(spine, (0..width).collect())]),
        MeshMaterial3d(materials.add(fabric(Color::srgb(0.75, 0.12, 0.12), 0.8))),
        Name::new("cape"),
    ));
    common::spawn_stage(
        &mut commands,
        &mut meshes,
        &mut materials,
        Vec3::new(RADIUS, 0.9, 0.0),
        4.2,
        0.0,
    );
}

/// A cloth's material: seen from both sides.
fn fabric(base_color: Color, perceptual_roughness: f32) -> StandardMaterial {
    StandardMaterial {
        base_color,
        double_sided: true,
        cull_mode: None,
        perceptual_roughness,
        ..default()
    }
}

/// The walk at time `t` (s) of its `LAP`-long loop: the hips go round the circle facing
/// along it and bob; the thighs swing (±25°) in opposite phase, each knee bends as its
/// leg comes forward, and the spine turns against the hips. A joint's translation (only
/// the hips move theirs) and rotation.
fn walk(joint: Joint, t: f32) -> (Option<Vec3>, Quat) {
    let lap = TAU * t / LAP;
    let stride = TAU * t / STRIDE;
    match joint {
        Joint::Hips => {
            let along = Vec3::new(-lap.sin(), 0.0, lap.cos());
            let at = Vec3::new(
                RADIUS * lap.cos(),
                HIP + 0.015 * (2.0 * stride).cos(),
                RADIUS * lap.sin(),
            );
            let turn = Quat::from_rotation_y(along.x.atan2(along.z))
                * Quat::from_rotation_z(0.03 * stride.sin());
            (Some(at), turn)
        }
        Joint::Spine => (None, Quat::from_rotation_y(-0.12 * stride.sin())),
        Joint::Thigh(side) => (None, Quat::from_rotation_x(-0.45 * side * stride.sin())),
        Joint::Knee(side) => {
            let bend = (side * stride.cos()).max(0.0);
            (None, Quat::from_rotation_x(0.7 * bend))
        }
    }
}

/// The walk as an `AnimationClip` (what a game would load from its character's file):
/// each joint's translation and rotation sampled 30 times a second over the loop, the
/// joint named by its `AnimationTargetId`.
fn walk_clip(joints: &[(Joint, AnimationTargetId)]) -> AnimationClip {
    let keys = (LAP * 30.0) as usize;
    let domain = Interval::new(0.0, LAP).expect("the loop has a length");
    let times = move || (0..=keys).map(move |k| LAP * k as f32 / keys as f32);
    let mut clip = AnimationClip::default();
    for &(joint, target) in joints {
        let rotations = SampleAutoCurve::new(domain, times().map(|t| walk(joint, t).1));
        clip.add_curve_to_target(
            target,
            AnimatableCurve::new(
                animated_field!(Transform::rotation),
                rotations.expect("two keys or more"),
            ),
        );
        if walk(joint, 0.0).0.is_some() {
            let translations =
                SampleAutoCurve::new(domain, times().map(|t| walk(joint, t).0.unwrap()));
            clip.add_curve_to_target(
                target,
                AnimatableCurve::new(
                    animated_field!(Transform::translation),
                    translations.expect("two keys or more"),
                ),
            );
        }
    }
    clip
}

/// The camera's focus follows the hips (the orbit camera still turns and zooms round it).
fn follow(joints: Query<(&Joint, &Transform)>, mut cameras: Query<&mut PanOrbitCamera>) {
    let Some((_, hips)) = joints.iter().find(|(j, _)| matches!(j, Joint::Hips)) else {
        return;
    };
    for mut camera in &mut cameras {
        camera.target_focus = hips.translation;
    }
}
