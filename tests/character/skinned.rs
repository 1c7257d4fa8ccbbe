//! A cloth built from a skinned mesh in the plugin: it follows its bones within its
//! painted distances, mesh vertex indices pin the welded particles, a capsule spans two
//! joints, a skirt walks without entering a leg.

use super::*;
use crate::motion::{deepest_in_back_stops, normals_at};

/// Columns and rows of the skinned panel's vertices, 4 cm apart.
pub(crate) const COLUMNS: u32 = 6;
pub(crate) const ROWS: u32 = 9;
pub(crate) const STEP: f32 = 0.04;

/// A hanging panel (a skirt's front, 20 × 32 cm) skinned to two joints: the hip (its
/// top rows) and the knee, 16 cm down (its lower rows, blending in over the middle).
/// Max distances painted 0 on the top row, growing 1.5 cm a row below.
fn skinned_panel() -> Mesh {
    let mut positions = Vec::new();
    let (mut joints, mut weights, mut distances) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..ROWS {
        for i in 0..COLUMNS {
            positions.push([(i as f32 - 2.5) * STEP, -(j as f32) * STEP, 0.1]);
            let knee = ((j as f32 - 2.0) / 4.0).clamp(0.0, 1.0);
            joints.push([0u16, 1, 0, 0]);
            weights.push([1.0 - knee, knee, 0.0, 0.0]);
            distances.push(0.015 * j as f32);
        }
    }
    let mut indices = Vec::new();
    for j in 0..ROWS - 1 {
        for i in 0..COLUMNS - 1 {
            let a = j * COLUMNS + i;
            indices.extend([a, a + COLUMNS, a + 1, a + 1, a + COLUMNS, a + COLUMNS + 1]);
        }
    }
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(
        Mesh::ATTRIBUTE_JOINT_INDEX,
        VertexAttributeValues::Uint16x4(joints),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_JOINT_WEIGHT, weights)
    .with_inserted_attribute(ATTRIBUTE_MAX_DISTANCE, distances)
    .with_inserted_indices(Indices::U32(indices))
}

/// Where Bevy's skinning puts mesh-space `v` (its shader's linear blend).
fn skinned(app: &App, skin: &SkinnedMesh, v: Vec3, joints: [u16; 4], weights: [f32; 4]) -> Vec3 {
    let inverse = app
        .world()
        .resource::<Assets<SkinnedMeshInverseBindposes>>()
        .get(&skin.inverse_bindposes)
        .unwrap();
    // The joints' global transforms, from their transforms (the headless app has no
    // transform propagation): the hip's, and the knee's as the hip's child.
    let local = |e: Entity| app.world().get::<Transform>(e).unwrap().compute_affine();
    let globals = [
        local(skin.joints[0]),
        local(skin.joints[0]) * local(skin.joints[1]),
    ];
    (0..4)
        .map(|k| {
            let global = globals[joints[k] as usize];
            (global * Affine3A::from_mat4(inverse[joints[k] as usize])).transform_point3(v)
                * weights[k]
        })
        .sum()
}

/// A skirt panel on a hip that walks (1.2 m/s) and a knee that swings (±40° at 1 Hz):
/// every frame each particle of distance 0 is where Bevy's skinning puts its vertex to
/// 1e-5 m, and none is farther than its painted distance (+1e-5 m); the skin is taken off
/// the entity (drawn as simulated) and the lower rows move within their distances.
#[test]
fn a_cloth_made_of_a_skinned_mesh_follows_its_bones_within_its_painted_distances() {
    let mut app = bevy_cloth::headless::headless_app();
    let hip_rest = Transform::from_xyz(0.0, 1.0, 0.0);
    let knee_rest = Transform::from_xyz(0.0, -0.16, 0.0);
    let hip = app.world_mut().spawn(hip_rest).id();
    let knee = app.world_mut().spawn((knee_rest, ChildOf(hip))).id();
    // Bind pose: the joints' global transforms as the mesh was made.
    let inverse = vec![
        hip_rest.to_matrix().inverse(),
        (hip_rest.to_matrix() * knee_rest.to_matrix()).inverse(),
    ];
    let bindposes = app
        .world_mut()
        .resource_mut::<Assets<SkinnedMeshInverseBindposes>>()
        .add(SkinnedMeshInverseBindposes::from(inverse));
    let mesh = skinned_panel();
    let rest: Vec<Vec3> = match mesh.attribute(Mesh::ATTRIBUTE_POSITION) {
        Some(VertexAttributeValues::Float32x3(p)) => p.iter().map(|&p| Vec3::from(p)).collect(),
        _ => unreachable!(),
    };
    let handle = app.world_mut().resource_mut::<Assets<Mesh>>().add(mesh);
    let skin = SkinnedMesh {
        inverse_bindposes: bindposes,
        joints: vec![hip, knee],
    };
    let cloth = app
        .world_mut()
        .spawn((
            Mesh3d(handle),
            skin.clone(),
            Cloth::from_mesh().with_pins(ClothPins::None),
        ))
        .id();
    let (mut pinned_off, mut over, mut swing) = (0.0f32, f32::MIN, 0.0f32);
    for frame in 0..150 {
        let t = frame as f32 / 60.0;
        let mut hip_now = hip_rest;
        hip_now.translation.x += 1.2 * t;
        *app.world_mut().get_mut::<Transform>(hip).unwrap() = hip_now;
        let mut knee_now = knee_rest;
        knee_now.rotation = Quat::from_rotation_x(0.7 * (std::f32::consts::TAU * t).sin());
        *app.world_mut().get_mut::<Transform>(knee).unwrap() = knee_now;
        app.update();
        let Some(sim) = app.world().get::<ClothSimulation>(cloth) else {
            continue;
        };
        assert!(
            app.world().get::<SkinnedMesh>(cloth).is_none(),
            "the skin comes off"
        );
        let x = sim.solver.positions();
        assert_eq!(x.len(), rest.len());
        for (k, &v) in rest.iter().enumerate() {
            let j = k as u32 / COLUMNS;
            let knee_weight = ((j as f32 - 2.0) / 4.0).clamp(0.0, 1.0);
            let target = skinned(
                &app,
                &skin,
                v,
                [0, 1, 0, 0],
                [1.0 - knee_weight, knee_weight, 0.0, 0.0],
            );
            let off = x[k].distance(target);
            let distance = 0.015 * j as f32;
            if j == 0 {
                pinned_off = pinned_off.max(off);
            } else {
                over = over.max(off - distance);
                swing = swing.max(off / distance);
            }
        }
    }
    eprintln!("distance 0: {pinned_off} m off; others: {over} m over, {swing} of their distance");
    assert!(
        pinned_off <= 1e-5,
        "the waist is {pinned_off} m off its skin"
    );
    assert!(over <= 1e-5, "a particle went {over} m past its distance");
    assert!(
        swing > 0.3,
        "the lower rows move within their distances: {swing}"
    );
}

/// Pins given as a mesh's own vertex indices pin the particles those vertices were welded
/// into: a 3 × 3 quad mesh split along its middle column (a UV seam: the column's three
/// vertices twice, 12 vertices for 9 particles), pinned by two of the seam's second
/// copies (vertices 9 and 11), holds the welded top-middle and bottom-middle particles.
#[test]
fn mesh_vertex_indices_pin_the_welded_particles() {
    // Left half: columns 0 and 1 (vertices 0..6, row-major 2 a row); right half: columns
    // 1 and 2 (vertices 6..12), column 1 again.
    let mut positions = Vec::new();
    for half in 0..2 {
        for row in 0..3 {
            for c in 0..2 {
                positions.push([(half + c) as f32 * 0.1, -(row as f32) * 0.1, 0.0]);
            }
        }
    }
    let mut indices = Vec::new();
    for half in 0..2u32 {
        let base = half * 6;
        for row in 0..2u32 {
            let a = base + row * 2;
            indices.extend([a, a + 2, a + 1, a + 1, a + 2, a + 3]);
        }
    }
    let mesh = Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions.clone())
    .with_inserted_indices(Indices::U32(indices));
    let mut app = bevy_cloth::headless::headless_app();
    let handle = app.world_mut().resource_mut::<Assets<Mesh>>().add(mesh);
    // Vertex 6 is the right half's top-left (the seam's top), 10 its bottom-left.
    let cloth = app
        .world_mut()
        .spawn((
            Mesh3d(handle.clone()),
            Cloth::from_mesh().with_pins(ClothPins::Indices(vec![6, 10])),
        ))
        .id();
    for _ in 0..30 {
        app.update();
    }
    let sim = app.world().get::<ClothSimulation>(cloth).expect("built");
    let x = sim.solver.positions();
    assert_eq!(x.len(), 9, "the seam is welded");
    let pinned: Vec<Vec3> = sim.solver.pins().iter().map(|&i| x[i as usize]).collect();
    assert_eq!(pinned.len(), 2);
    for (want, got) in [positions[6], positions[10]].iter().zip(&pinned) {
        assert!(
            got.distance(Vec3::from(*want)) < 1e-5,
            "pinned {got}, not at {want:?}"
        );
    }
    // A vertex index past the mesh's 12 vertices is refused, naming the index.
    let bad = app
        .world_mut()
        .spawn((
            Mesh3d(handle),
            Cloth::from_mesh().with_pins(ClothPins::Indices(vec![12])),
        ))
        .id();
    app.update();
    let invalid = app.world().get::<ClothInvalid>(bad).expect("refused");
    assert!(invalid.0.to_string().contains("12"), "{}", invalid.0);
}

/// The distance from `x` to the segment `a–b`.
fn from_segment(x: Vec3, a: Vec3, b: Vec3) -> f32 {
    let t = ((x - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
    x.distance(a + (b - a) * t)
}

/// A thigh collider spanning a hip and a knee joint follows them as the hip swings the
/// leg forward (±35° at 1 Hz) into a curtain hanging in front of it: the solver's capsule
/// runs from the hip to the knee every step, and no particle ever gets inside it.
#[test]
fn a_capsule_spanning_two_joints_follows_them_and_keeps_the_cloth_out() {
    let mut app = bevy_cloth::headless::headless_app();
    let hip_rest = Transform::from_xyz(0.0, 1.0, 0.0);
    let hip = app.world_mut().spawn(hip_rest).id();
    let knee = app
        .world_mut()
        .spawn((Transform::from_xyz(0.0, -0.45, 0.0), ChildOf(hip)))
        .id();
    let radius = 0.08;
    app.world_mut().spawn((
        ClothCollider::capsule(radius, 0.0),
        ClothColliderSpan {
            from: hip,
            to: knee,
        },
    ));
    // 20 × 14 particles 2.5 cm apart, hung by their top row 12 cm in front of the hip.
    let cloth = app
        .world_mut()
        .spawn((
            Cloth::grid(20, 14, 0.025).with_pins(ClothPins::TopRow),
            Transform::from_xyz(0.0, 1.05, 0.12),
        ))
        .id();
    let (mut closest, mut worst_end) = (f32::INFINITY, 0.0f32);
    for frame in 0..120 {
        let t = frame as f32 / 60.0;
        let swing = -0.6 * (std::f32::consts::TAU * t).sin();
        *app.world_mut().get_mut::<Transform>(hip).unwrap() =
            hip_rest.with_rotation(Quat::from_rotation_x(swing));
        app.update();
        let Some(sim) = app.world().get::<ClothSimulation>(cloth) else {
            continue;
        };
        let Some(collider) = sim.solver.colliders().first() else {
            continue;
        };
        let bevy_cloth::solver::ColliderShape::Capsule(bevy_cloth::solver::shapes::Capsule {
            a,
            b,
            radius: r,
        }) = collider.shape
        else {
            panic!("a capsule: {:?}", collider.shape);
        };
        // The joints where this step put them.
        let hip_at = hip_rest.with_rotation(Quat::from_rotation_x(swing));
        let knee_at = hip_at.transform_point(Vec3::new(0.0, -0.45, 0.0));
        worst_end = worst_end
            .max(a.distance(hip_at.translation))
            .max(b.distance(knee_at));
        assert!((r - radius).abs() < 1e-6);
        for &x in sim.solver.positions() {
            closest = closest.min(from_segment(x, a, b));
        }
    }
    eprintln!(
        "ends off by {worst_end} m; closest particle {closest} m from the axis (radius {radius})"
    );
    assert!(
        worst_end < 1e-5,
        "the capsule's ends are {worst_end} m off the joints"
    );
    assert!(
        closest >= radius - 1e-4,
        "a particle went {} m into the thigh",
        radius - closest
    );
    assert!(
        closest < radius + 0.02,
        "the thigh reached the cloth: {closest} m"
    );
}

/// An A-line skirt: a cone of 12 rings × 32 (radius 19 cm at the waist, 0.96 m up, to 31
/// cm at the hem, 40 cm down), wound to face out, skinned wholly to joint 0, its maximum
/// distance 0 at the waist growing to 0.2 m at the hem.
fn skirt_cone() -> Mesh {
    skirt_cone_wound(false)
}

/// [`skirt_cone`], or (`inward`) wound to face in and given normals that point out, as
/// hand-made meshes can be.
fn skirt_cone_wound(inward: bool) -> Mesh {
    let (rows, around) = (12u32, 32u32);
    let (mut positions, mut indices, mut distances) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..rows {
        let down = j as f32 / (rows - 1) as f32;
        for i in 0..around {
            let a = std::f32::consts::TAU * i as f32 / around as f32;
            let r = 0.19 + 0.12 * down;
            positions.push([r * a.sin(), 0.96 - 0.4 * down, r * a.cos()]);
            distances.push(0.2 * down * down);
        }
    }
    for j in 0..rows - 1 {
        for i in 0..around {
            let (a, b) = (j * around + i, j * around + (i + 1) % around);
            indices.extend([a, a + around, b, b, a + around, b + around]);
        }
    }
    let n = positions.len();
    let mut mesh = Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(
        Mesh::ATTRIBUTE_JOINT_INDEX,
        VertexAttributeValues::Uint16x4(vec![[0; 4]; n]),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_JOINT_WEIGHT, vec![[1.0, 0.0, 0.0, 0.0]; n])
    .with_inserted_attribute(ATTRIBUTE_MAX_DISTANCE, distances);
    if inward {
        let out: Vec<[f32; 3]> = positions_of(&mesh)
            .iter()
            .map(|p| {
                let radial = Vec3::new(p.x, 0.0, p.z).normalize();
                // The cone's slant: 12 cm out over 40 cm down.
                (radial * 0.4 + Vec3::Y * 0.12).normalize().to_array()
            })
            .collect();
        for t in indices.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
        mesh.insert_attribute(Mesh::ATTRIBUTE_NORMAL, out);
    }
    mesh.with_inserted_indices(Indices::U32(indices))
}

/// A mesh's vertex positions.
fn positions_of(mesh: &Mesh) -> Vec<Vec3> {
    match mesh.attribute(Mesh::ATTRIBUTE_POSITION) {
        Some(VertexAttributeValues::Float32x3(p)) => p.iter().map(|&p| Vec3::from(p)).collect(),
        _ => panic!("the mesh has no positions"),
    }
}

/// A mesh's triangles.
fn triangles_of(mesh: &Mesh) -> Vec<[u32; 3]> {
    let flat: Vec<u32> = mesh.indices().unwrap().iter().map(|i| i as u32).collect();
    flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
}

/// A skirt on a walking character: an A-line cone of 12 rings × 32, skinned to the hips,
/// its distance 0 at the waist growing to 0.2 m at the hem; two legs whose thighs swing
/// ±26° at 1 Hz in opposite phase while the hips walk at 1 m/s, each thigh a capsule
/// spanning its hip and knee joints. Over 3 s no skirt particle is ever inside a thigh,
/// and the thighs do push the skirt (some particle comes within 2 cm of their surface).
#[test]
fn a_skirt_on_a_walking_character_never_has_a_particle_inside_a_leg() {
    let mesh = skirt_cone();
    let mut app = bevy_cloth::headless::headless_app();
    let hip_rest = Transform::from_xyz(0.0, 0.92, 0.0);
    let hips = app.world_mut().spawn(hip_rest).id();
    let radius = 0.08;
    let mut thighs = Vec::new();
    for side in [1.0f32, -1.0] {
        let thigh = app
            .world_mut()
            .spawn((Transform::from_xyz(0.09 * side, -0.02, 0.0), ChildOf(hips)))
            .id();
        let knee = app
            .world_mut()
            .spawn((Transform::from_xyz(0.0, -0.42, 0.0), ChildOf(thigh)))
            .id();
        app.world_mut().spawn((
            ClothCollider::capsule(radius, 0.0),
            ClothColliderSpan {
                from: thigh,
                to: knee,
            },
        ));
        thighs.push((thigh, side));
    }
    let bindposes = app
        .world_mut()
        .resource_mut::<Assets<SkinnedMeshInverseBindposes>>()
        .add(SkinnedMeshInverseBindposes::from(vec![
            hip_rest.to_matrix().inverse(),
        ]));
    let handle = app.world_mut().resource_mut::<Assets<Mesh>>().add(mesh);
    let skirt = app
        .world_mut()
        .spawn((
            Mesh3d(handle),
            SkinnedMesh {
                inverse_bindposes: bindposes,
                joints: vec![hips],
            },
            Cloth::from_mesh().with_pins(ClothPins::None),
        ))
        .id();
    let (mut inside, mut closest) = (0.0f32, f32::INFINITY);
    for frame in 0..180 {
        let t = frame as f32 / 60.0;
        let stride = std::f32::consts::TAU * t;
        app.world_mut()
            .get_mut::<Transform>(hips)
            .unwrap()
            .translation
            .z = t;
        for &(thigh, side) in &thighs {
            app.world_mut()
                .get_mut::<Transform>(thigh)
                .unwrap()
                .rotation = Quat::from_rotation_x(-0.45 * side * stride.sin());
        }
        app.update();
        let Some(sim) = app.world().get::<ClothSimulation>(skirt) else {
            continue;
        };
        assert!(sim.solver.is_stable(), "frame {frame}");
        for collider in sim.solver.colliders() {
            let bevy_cloth::solver::ColliderShape::Capsule(bevy_cloth::solver::shapes::Capsule {
                a,
                b,
                ..
            }) = collider.shape
            else {
                continue;
            };
            for &x in sim.solver.positions() {
                let d = from_segment(x, a, b);
                inside = inside.max(radius - d);
                closest = closest.min(d - radius);
            }
        }
    }
    eprintln!("deepest into a thigh: {inside} m; closest to a thigh's surface: {closest} m");
    assert!(
        inside <= 1e-4,
        "a skirt particle went {inside} m into a thigh"
    );
    assert!(closest < 0.02, "the thighs reach the skirt: {closest} m");
}

/// A back stop keeps a skirt off the body with no collider: the skirt cone on hips that
/// walk for 6 s at 1 m/s, surging ±0.25 m/s at 1.5 Hz and turning ±35° at 1 Hz, so that
/// the hem swings back into where the legs would be. With `ClothBackStop::Uniform`
/// (1 cm behind, radius 0.3 m) no particle is ever inside its sphere at a frame's end
/// (1e-4 m), its centre found here from the skinned positions and the cone's outward
/// normals; so too for the cone wound inward with outward normals (the normals say which
/// side is out). Without it the same walk takes the skirt more than 2 cm into them.
#[test]
fn a_back_stop_keeps_a_walking_skirt_off_the_body_without_colliders() {
    let stop = BackStop {
        distance: 0.01,
        radius: 0.3,
    };
    let out = triangles_of(&skirt_cone());
    // The deepest any particle went into its back stop, and the frames measured (the
    // frames after the skirt's simulation was built).
    let walk = |stopped: bool, inward: bool| -> (f32, usize, Vec<Vec3>) {
        let mut app = bevy_cloth::headless::headless_app();
        let hip_rest = Transform::from_xyz(0.0, 0.92, 0.0);
        let hips = app.world_mut().spawn(hip_rest).id();
        let bindposes = app
            .world_mut()
            .resource_mut::<Assets<SkinnedMeshInverseBindposes>>()
            .add(SkinnedMeshInverseBindposes::from(vec![
                hip_rest.to_matrix().inverse(),
            ]));
        let mesh = skirt_cone_wound(inward);
        let rest = positions_of(&mesh);
        let handle = app.world_mut().resource_mut::<Assets<Mesh>>().add(mesh);
        let mut skirt = app.world_mut().spawn((
            Mesh3d(handle),
            SkinnedMesh {
                inverse_bindposes: bindposes,
                joints: vec![hips],
            },
            Cloth::from_mesh().with_pins(ClothPins::None),
        ));
        if stopped {
            skirt.insert(ClothBackStop::Uniform {
                distance: stop.distance,
                radius: stop.radius,
            });
        }
        let skirt = skirt.id();
        let (mut deepest, mut measured, mut end) = (f32::MIN, 0, Vec::new());
        for frame in 0..360 {
            let t = frame as f32 / 60.0;
            let tau = std::f32::consts::TAU;
            let place =
                Transform::from_xyz(0.0, 0.92, t - 0.25 / (1.5 * tau) * (1.5 * tau * t).cos())
                    .with_rotation(Quat::from_rotation_y(0.6 * (tau * t).sin()));
            *app.world_mut().get_mut::<Transform>(hips).unwrap() = place;
            app.update();
            let Some(sim) = app.world().get::<ClothSimulation>(skirt) else {
                continue;
            };
            assert!(sim.solver.is_stable(), "frame {frame}");
            // The skin: the hips now, from their rest (the particles are the mesh's
            // vertices, in order: it has no seam to weld).
            let skin = place.to_matrix() * hip_rest.to_matrix().inverse();
            let targets: Vec<Vec3> = rest.iter().map(|&v| skin.transform_point3(v)).collect();
            let normals = normals_at(&out, &targets);
            deepest = deepest.max(deepest_in_back_stops(
                sim.solver.positions(),
                &targets,
                &normals,
                stop,
            ));
            measured += 1;
            end = sim.solver.positions().to_vec();
        }
        (deepest, measured, end)
    };
    let runs = [walk(true, false), walk(true, true), walk(false, false)];
    let measured = runs.each_ref().map(|r| r.1);
    let [(deepest, _, stopped), (inward, _, _), (free, _, _)] = runs;
    eprintln!(
        "deepest into a back stop over 6 s: {deepest} m, wound inward with normals out \
         {inward} m (without back stops {free} m); frames measured {:?}",
        measured
    );
    // Each skirt built on its first frame, and measured on every one after.
    for measured in measured {
        assert!(
            measured >= 359,
            "the skirt was measured in {measured} of 360 frames"
        );
    }
    assert!(
        deepest <= 1e-4,
        "a skirt particle went {deepest} m into its back stop"
    );
    assert!(
        inward <= 1e-4,
        "wound inward: {inward} m into its back stop"
    );
    assert!(
        free > 0.02,
        "without back stops the walk takes the skirt into them: {free} m"
    );
    common::golden::assert_golden("back_stopped_skirt", &stopped);
}

/// Bad back stops are refused at the door, each with the error that names it, and a
/// fixed one builds: on a grid (it paints a mesh's vertices), one of the wrong count for
/// the mesh, a NaN distance.
#[test]
fn bad_back_stops_are_refused_with_what_is_wrong() {
    let mut app = bevy_cloth::headless::headless_app();
    let grid = app
        .world_mut()
        .spawn((
            Cloth::grid(4, 4, 0.1),
            ClothBackStop::Uniform {
                distance: 0.0,
                radius: 0.1,
            },
        ))
        .id();
    let mut skirt = |back: ClothBackStop| {
        let handle = app
            .world_mut()
            .resource_mut::<Assets<Mesh>>()
            .add(skirt_cone());
        app.world_mut()
            .spawn((
                Mesh3d(handle),
                Cloth::from_mesh().with_pins(ClothPins::None),
                back,
            ))
            .id()
    };
    let short = skirt(ClothBackStop::PerVertex(vec![[0.0, 0.1]; 3]));
    let nan = skirt(ClothBackStop::Uniform {
        distance: f32::NAN,
        radius: 0.1,
    });
    for _ in 0..3 {
        app.update();
    }
    let error = |app: &App, e: Entity| {
        let invalid = app.world().get::<ClothInvalid>(e).expect("refused");
        assert!(app.world().get::<ClothSimulation>(e).is_none());
        invalid.0.to_string()
    };
    let (grid_error, short_error, nan_error) =
        (error(&app, grid), error(&app, short), error(&app, nan));
    eprintln!("{grid_error}\n{short_error}\n{nan_error}");
    assert!(grid_error.contains("ClothBackStop"), "{grid_error}");
    assert!(short_error.contains("3 back stops"), "{short_error}");
    assert!(nan_error.contains("back stop distance"), "{nan_error}");
    *app.world_mut().get_mut::<ClothBackStop>(nan).unwrap() = ClothBackStop::Uniform {
        distance: 0.0,
        radius: 0.1,
    };
    app.update();
    app.update();
    assert!(
        app.world().get::<ClothInvalid>(nan).is_none(),
        "fixed, it builds"
    );
    assert!(app.world().get::<ClothSimulation>(nan).is_some());
}

/// A plain (unskinned) mesh with painted distances: its targets are its rest shape in the
/// entity's frame. The entity moves 1 m/s along x and turns; the top row (distance 0,
/// given per vertex in code) stays on its target to 1e-5 m and the rest within 3 cm.
#[test]
fn a_plain_mesh_keeps_within_its_painted_distances_of_its_frame() {
    let side = 5u32;
    let mut positions = Vec::new();
    for j in 0..side {
        for i in 0..side {
            positions.push([i as f32 * 0.05, -(j as f32) * 0.05, 0.0]);
        }
    }
    let mut indices = Vec::new();
    for j in 0..side - 1 {
        for i in 0..side - 1 {
            let a = j * side + i;
            indices.extend([a, a + side, a + 1, a + 1, a + side, a + side + 1]);
        }
    }
    let rest: Vec<Vec3> = positions.iter().map(|&p| Vec3::from(p)).collect();
    let distance: Vec<f32> = (0..side * side)
        .map(|k| if k < side { 0.0 } else { 0.03 })
        .collect();
    let mesh = Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_indices(Indices::U32(indices));
    let mut app = bevy_cloth::headless::headless_app();
    let handle = app.world_mut().resource_mut::<Assets<Mesh>>().add(mesh);
    let cloth = app
        .world_mut()
        .spawn((
            Mesh3d(handle),
            Cloth::from_mesh().with_pins(ClothPins::None),
            ClothMaxDistance::PerVertex(distance.clone()),
            Transform::from_xyz(0.0, 1.0, 0.0),
        ))
        .id();
    let (mut pinned_off, mut over, mut measured) = (0.0f32, f32::MIN, 0);
    for frame in 0..120 {
        let t = frame as f32 / 60.0;
        let place = Transform::from_xyz(t, 1.0, 0.0).with_rotation(Quat::from_rotation_y(t));
        *app.world_mut().get_mut::<Transform>(cloth).unwrap() = place;
        app.update();
        let Some(sim) = app.world().get::<ClothSimulation>(cloth) else {
            continue;
        };
        for (k, &x) in sim.solver.positions().iter().enumerate() {
            let off = x.distance(place.transform_point(rest[k]));
            if distance[k] == 0.0 {
                pinned_off = pinned_off.max(off);
            } else {
                over = over.max(off - distance[k]);
            }
        }
        measured += 1;
    }
    eprintln!("distance 0: {pinned_off} m off; the rest: {over} m over; {measured} frames");
    assert!(
        measured >= 119,
        "the cloth was measured in {measured} of 120 frames"
    );
    assert!(
        pinned_off <= 1e-5,
        "the top row is {pinned_off} m off its frame"
    );
    assert!(over <= 1e-5, "a particle went {over} m past its distance");
}
