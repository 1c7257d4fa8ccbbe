//! A glTF character walking in its skirt, stepped after its animation.

use super::*;

/// A small skinned, animated character as an exporter writes it, in glTF 2.0 (a
/// `.gltf` and its `.bin`): an armature node (0.5 m along x) holding two joints, hips
/// (1 m up) and a knee (16 cm below), and a skirt panel (the skinned panel's grid, its
/// waist at the hips) skinned to them, with its maximum distance in the custom vertex
/// attribute `_MAX_DISTANCE` (what Blender writes for a float attribute named so). One
/// animation, "Walk", 2 s: the hips walk 1.2 m/s along x and bob 2 cm; the knee swings
/// ±40° at 1 Hz.
mod walk_gltf {
    use std::f32::consts::TAU;
    use std::path::Path;

    use bevy::math::{Mat4, Quat, Vec3};
    use serde_json::{Value, json};

    use crate::skinned::{COLUMNS, ROWS, STEP};

    /// The file's walk, loaded as an animation graph of one clip: the graph and its node.
    pub fn animation(
        app: &mut bevy::prelude::App,
    ) -> (
        bevy::prelude::Handle<bevy::prelude::AnimationGraph>,
        bevy::prelude::AnimationNodeIndex,
    ) {
        use bevy::gltf::GltfAssetLabel;
        use bevy::prelude::*;
        let server = app.world().resource::<AssetServer>().clone();
        let clip = server.load(GltfAssetLabel::Animation(0).from_asset("walk.gltf"));
        let (graph, walk) = AnimationGraph::from_clip(clip);
        let graph = app
            .world_mut()
            .resource_mut::<Assets<AnimationGraph>>()
            .add(graph);
        (graph, walk)
    }

    const ARMATURE: Vec3 = Vec3::new(0.5, 0.0, 0.0);
    const HIPS: Vec3 = Vec3::new(0.0, 1.0, 0.0);
    const KNEE: Vec3 = Vec3::new(0.0, -0.16, 0.0);
    /// The animation's length (s) and its keys a second.
    const LENGTH: f32 = 2.0;
    const KEYS: u32 = 30;

    /// The hips' translation and the knee's rotation at time `t` of the walk.
    fn hips_at(t: f32) -> Vec3 {
        HIPS + Vec3::new(1.2 * t, 0.02 * (2.0 * TAU * t).sin(), 0.0)
    }
    fn knee_at(t: f32) -> Quat {
        Quat::from_rotation_x(0.7 * (TAU * t).sin())
    }

    /// The joints' bind poses (global, the armature's offset included), inverted: hips,
    /// knee.
    pub fn inverse_bindposes() -> [Mat4; 2] {
        let hips_bind = Mat4::from_translation(ARMATURE + HIPS);
        let knee_bind = hips_bind * Mat4::from_translation(KNEE);
        [hips_bind.inverse(), knee_bind.inverse()]
    }

    /// The panel's vertices in the bind pose: position, joints' weights (hips, knee) and
    /// maximum distance (0 on the waist row, 1.5 cm more each row down).
    pub fn vertices() -> Vec<(Vec3, [f32; 2], f32)> {
        vertices_at(1)
    }

    /// The panel `finer` times as fine each way (1: the simulation's), its weights and
    /// distances the same functions of the place.
    pub fn vertices_at(finer: u32) -> Vec<(Vec3, [f32; 2], f32)> {
        let (columns, rows) = ((COLUMNS - 1) * finer + 1, (ROWS - 1) * finer + 1);
        let mut v = Vec::new();
        for j in 0..rows {
            for i in 0..columns {
                let (u, w) = (i as f32 / finer as f32, j as f32 / finer as f32);
                let knee = ((w - 2.0) / 4.0).clamp(0.0, 1.0);
                let p = ARMATURE + HIPS + Vec3::new((u - 2.5) * STEP, -w * STEP, 0.1);
                v.push((p, [1.0 - knee, knee], 0.015 * w));
            }
        }
        v
    }

    /// The binary buffer, one view per accessor (each 4-byte aligned).
    #[derive(Default)]
    struct Buffer {
        bytes: Vec<u8>,
        views: Vec<Value>,
        accessors: Vec<Value>,
    }

    impl Buffer {
        /// Appends `data` (little-endian) as a view and an accessor of `kind` whose
        /// components are `component` (a glTF component type); returns its index.
        fn add(
            &mut self,
            data: &[u8],
            component: u32,
            kind: &str,
            count: usize,
            extra: Value,
        ) -> usize {
            let offset = self.bytes.len();
            self.bytes.extend_from_slice(data);
            while !self.bytes.len().is_multiple_of(4) {
                self.bytes.push(0);
            }
            self.views
                .push(json!({"buffer": 0, "byteOffset": offset, "byteLength": data.len()}));
            let mut accessor = json!({
                "bufferView": self.views.len() - 1,
                "componentType": component,
                "type": kind,
                "count": count,
            });
            if let (Value::Object(a), Value::Object(e)) = (&mut accessor, extra) {
                a.extend(e);
            }
            self.accessors.push(accessor);
            self.accessors.len() - 1
        }

        fn floats(&mut self, values: &[f32], kind: &str, per: usize, extra: Value) -> usize {
            let data: Vec<u8> = values.iter().flat_map(|x| x.to_le_bytes()).collect();
            self.add(&data, 5126, kind, values.len() / per, extra)
        }
    }

    /// The panel `finer` times as fine as the simulation's, skinned, as a glTF primitive
    /// whose accessors are added to `buffer`.
    fn primitive(buffer: &mut Buffer, finer: u32) -> Value {
        let vertices = vertices_at(finer);
        let positions: Vec<f32> = vertices.iter().flat_map(|v| v.0.to_array()).collect();
        let (lo, hi) = vertices.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), v| {
            (lo.min(v.0), hi.max(v.0))
        });
        let position = buffer.floats(
            &positions,
            "VEC3",
            3,
            json!({"min": lo.to_array(), "max": hi.to_array()}),
        );
        let normals: Vec<f32> = vertices.iter().flat_map(|_| [0.0, 0.0, 1.0]).collect();
        let normal = buffer.floats(&normals, "VEC3", 3, json!({}));
        let joints: Vec<u8> = vertices
            .iter()
            .flat_map(|_| [0u16, 1, 0, 0])
            .flat_map(|j| j.to_le_bytes())
            .collect();
        let joint = buffer.add(&joints, 5123, "VEC4", vertices.len(), json!({}));
        let weights: Vec<f32> = vertices
            .iter()
            .flat_map(|v| [v.1[0], v.1[1], 0.0, 0.0])
            .collect();
        let weight = buffer.floats(&weights, "VEC4", 4, json!({}));
        let distances: Vec<f32> = vertices.iter().map(|v| v.2).collect();
        let distance = buffer.floats(&distances, "SCALAR", 1, json!({}));
        let (columns, rows) = ((COLUMNS - 1) * finer + 1, (ROWS - 1) * finer + 1);
        let mut indices = Vec::new();
        for j in 0..rows - 1 {
            for i in 0..columns - 1 {
                let a = j * columns + i;
                indices.extend([a, a + columns, a + 1, a + 1, a + columns, a + columns + 1]);
            }
        }
        let index_bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let index = buffer.add(&index_bytes, 5125, "SCALAR", indices.len(), json!({}));
        json!({
            "attributes": {
                "POSITION": position,
                "NORMAL": normal,
                "JOINTS_0": joint,
                "WEIGHTS_0": weight,
                "_MAX_DISTANCE": distance,
            },
            "indices": index,
        })
    }

    /// Writes `walk.gltf` and `walk.bin` into `dir`: the character and its skirt, and with
    /// `render` a second mesh of the skirt that many times finer, `Skirt.render`, skinned
    /// to the same joints (the simulation and render meshes of one file).
    pub fn write(dir: &Path, render: Option<u32>) {
        let mut buffer = Buffer::default();
        let mut meshes = vec![json!({"name": "Skirt", "primitives": [primitive(&mut buffer, 1)]})];
        let mut nodes = vec![
            json!({"name": "Armature", "translation": ARMATURE.to_array(), "children": [1, 3]}),
            json!({"name": "Hips", "translation": HIPS.to_array(), "children": [2]}),
            json!({"name": "Knee", "translation": KNEE.to_array()}),
            json!({"name": "Skirt", "mesh": 0, "skin": 0}),
        ];
        if let Some(finer) = render {
            let primitive = primitive(&mut buffer, finer);
            meshes.push(json!({"name": "Skirt.render", "primitives": [primitive]}));
            nodes.push(json!({"name": "Skirt.render", "mesh": 1, "skin": 0}));
            nodes[0]["children"] = json!([1, 3, 4]);
        }
        let inverse: Vec<f32> = inverse_bindposes()
            .iter()
            .flat_map(|m| m.to_cols_array())
            .collect();
        let bindposes = buffer.floats(&inverse, "MAT4", 16, json!({}));
        // The walk's keys.
        let times: Vec<f32> = (0..=(LENGTH as u32 * KEYS))
            .map(|k| k as f32 / KEYS as f32)
            .collect();
        let time = buffer.floats(&times, "SCALAR", 1, json!({"min": [0.0], "max": [LENGTH]}));
        let translations: Vec<f32> = times.iter().flat_map(|&t| hips_at(t).to_array()).collect();
        let translation = buffer.floats(&translations, "VEC3", 3, json!({}));
        let rotations: Vec<f32> = times.iter().flat_map(|&t| knee_at(t).to_array()).collect();
        let rotation = buffer.floats(&rotations, "VEC4", 4, json!({}));
        let gltf = json!({
            "asset": {"version": "2.0", "generator": "bevy_cloth tests"},
            "scene": 0,
            "scenes": [{"name": "Character", "nodes": [0]}],
            "nodes": nodes,
            "skins": [{"joints": [1, 2], "inverseBindMatrices": bindposes}],
            "meshes": meshes,
            "animations": [{
                "name": "Walk",
                "channels": [
                    {"sampler": 0, "target": {"node": 1, "path": "translation"}},
                    {"sampler": 1, "target": {"node": 2, "path": "rotation"}},
                ],
                "samplers": [
                    {"input": time, "output": translation, "interpolation": "LINEAR"},
                    {"input": time, "output": rotation, "interpolation": "LINEAR"},
                ],
            }],
            "buffers": [{"uri": "walk.bin", "byteLength": buffer.bytes.len()}],
            "bufferViews": buffer.views,
            "accessors": buffer.accessors,
        });
        std::fs::create_dir_all(dir).unwrap();
        std::fs::write(dir.join("walk.bin"), &buffer.bytes).unwrap();
        std::fs::write(
            dir.join("walk.gltf"),
            serde_json::to_string_pretty(&gltf).unwrap(),
        )
        .unwrap();
    }
}

/// What a run of the glTF character measured, frame by frame once its cloth is built.
struct GltfWalk {
    frames: usize,
    /// The largest distance of a waist particle (distance 0) from where the skin puts it
    /// in the pose the step read, and in the pose drawn in the same frame.
    waist_off_read: f32,
    waist_off_drawn: f32,
    /// How far past its painted distance any other particle went (from the pose read).
    over: f32,
    /// The largest fraction of its distance a lower particle used.
    swing: f32,
    /// How far the drawn mesh (its vertices through the entity's transform) is from the
    /// simulated particles.
    drawn_off: f32,
    /// How far the hips walked.
    walked: f32,
}

/// A headless app that loads glTF files from `dir` and plays their animations, its
/// cloths stepping in `schedule` every 16 ms update.
fn gltf_app(dir: &std::path::Path, schedule: impl bevy::ecs::schedule::ScheduleLabel) -> App {
    use bevy::animation::AnimationPlugin;
    use bevy::gltf::{GltfMeshName, GltfPlugin};
    use bevy::time::TimeUpdateStrategy;
    use bevy::world_serialization::WorldSerializationPlugin;

    let step = std::time::Duration::from_millis(16);
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        bevy::asset::AssetPlugin {
            file_path: dir.to_string_lossy().into(),
            ..default()
        },
        TransformPlugin,
        AnimationPlugin,
        WorldSerializationPlugin,
        // glTF's `_MAX_DISTANCE` arrives as the semantic `MAX_DISTANCE` (the glTF crate
        // takes the underscore off).
        GltfPlugin::default().add_custom_vertex_attribute("MAX_DISTANCE", ATTRIBUTE_MAX_DISTANCE),
        ClothPlugin::new(schedule).with_timestep(step),
    ))
    .init_asset::<Mesh>()
    .init_asset::<SkinnedMeshInverseBindposes>()
    .insert_resource(TimeUpdateStrategy::ManualDuration(step));
    // A glTF scene is spawned by reflection: the types of its components are registered
    // (Bevy's `reflect_auto_register` feature, on by default, would do it).
    app.register_type::<Transform>()
        .register_type::<GlobalTransform>()
        .register_type::<bevy::transform::components::TransformTreeChanged>()
        .register_type::<Name>()
        .register_type::<ChildOf>()
        .register_type::<Children>()
        .register_type::<Mesh3d>()
        .register_type::<SkinnedMesh>()
        .register_type::<Visibility>()
        .register_type::<InheritedVisibility>()
        .register_type::<ViewVisibility>()
        .register_type::<bevy::camera::primitives::Aabb>()
        .register_type::<GltfMeshName>()
        .register_type::<bevy::gltf::GltfSceneName>()
        .register_type::<bevy::camera::visibility::DynamicSkinnedMeshBounds>()
        .register_type::<AnimationPlayer>()
        .register_type::<bevy::animation::AnimationTargetId>()
        .register_type::<bevy::animation::AnimatedBy>();
    // The glTF loader is registered when the plugins finish (`App::run` would do it).
    app.finish();
    app.cleanup();
    app
}

/// Loads `walk.gltf` (written by [`walk_gltf::write`]) as a user's character: the scene
/// spawned, the skirt's mesh entity (found by its glTF mesh name) made a cloth, the walk
/// played by the scene's animation player; the cloths step in `schedule`. Measures 110
/// frames of 16 ms (within the 2 s clip) once the cloth is built.
fn walk_a_gltf_character(
    schedule: impl bevy::ecs::schedule::ScheduleLabel,
    name: &str,
) -> GltfWalk {
    use bevy::animation::graph::AnimationGraphHandle;
    use bevy::gltf::{GltfAssetLabel, GltfMeshName};
    use bevy::world_serialization::{WorldAssetRoot, WorldInstanceReady};
    use std::time::Duration;

    let dir = std::env::temp_dir().join(format!("bevy_cloth_gltf_{}_{name}", std::process::id()));
    walk_gltf::write(&dir, None);
    let mut app = gltf_app(&dir, schedule);
    // The plugin draws between steps exactly when they are fixed ones.
    let fixed = app.world().resource::<ClothInterpolation>().0;
    let server = app.world().resource::<AssetServer>().clone();
    let scene = server.load(GltfAssetLabel::Scene(0).from_asset("walk.gltf"));
    let (graph, walk) = walk_gltf::animation(&mut app);
    app.world_mut()
        .spawn(WorldAssetRoot(scene.clone()))
        .observe(
            move |ready: On<WorldInstanceReady>,
                  children: Query<&Children>,
                  meshes: Query<&GltfMeshName>,
                  mut players: Query<&mut AnimationPlayer>,
                  mut commands: Commands| {
                for entity in children.iter_descendants(ready.entity) {
                    if meshes.get(entity).is_ok_and(|m| m.0 == "Skirt") {
                        commands
                            .entity(entity)
                            .insert(Cloth::from_mesh().with_pins(ClothPins::None));
                    }
                    if let Ok(mut player) = players.get_mut(entity) {
                        player.play(walk);
                        commands
                            .entity(entity)
                            .insert(AnimationGraphHandle(graph.clone()));
                    }
                }
            },
        );
    let vertices = walk_gltf::vertices();
    let inverse = walk_gltf::inverse_bindposes();
    let joint = |app: &App, name: &str| -> GlobalTransform {
        let world = app.world();
        let mut q = world.try_query::<(&Name, &GlobalTransform)>().unwrap();
        *q.iter(world).find(|(n, _)| n.as_str() == name).unwrap().1
    };
    // Where the skin puts each vertex with the joints at `pose`.
    let skin = |pose: [GlobalTransform; 2]| -> Vec<Vec3> {
        vertices
            .iter()
            .map(|(v, w, _)| {
                (0..2)
                    .map(|b| (pose[b].to_matrix() * inverse[b]).transform_point3(*v) * w[b])
                    .sum()
            })
            .collect()
    };
    let mut walk = GltfWalk {
        frames: 0,
        waist_off_read: 0.0,
        waist_off_drawn: 0.0,
        over: f32::MIN,
        swing: 0.0,
        drawn_off: 0.0,
        walked: 0.0,
    };
    let mut start = None;
    let mut read_pose = None;
    for _ in 0..600 {
        if walk.frames == 110 {
            break;
        }
        // The pose now is what a step in the fixed schedule reads in the next update.
        let before = read_pose.take();
        app.update();
        let world = app.world_mut();
        let mut cloths = world.query::<(&ClothSimulation, &Mesh3d, &GlobalTransform)>();
        let Some((sim, mesh, frame)) = cloths.iter(world).next() else {
            std::thread::sleep(Duration::from_millis(5)); // the glTF loads meanwhile
            continue;
        };
        let x = sim.solver.positions().to_vec();
        let (mesh, frame) = (mesh.0.clone(), *frame);
        let drawn_pose = [joint(&app, "Hips"), joint(&app, "Knee")];
        read_pose = Some(drawn_pose);
        let hips = drawn_pose[0].translation();
        let start = *start.get_or_insert(hips);
        walk.walked = walk.walked.max(hips.distance(start));
        let positions = match app
            .world()
            .resource::<Assets<Mesh>>()
            .get(&mesh)
            .unwrap()
            .attribute(Mesh::ATTRIBUTE_POSITION)
        {
            Some(VertexAttributeValues::Float32x3(p)) => p.clone(),
            _ => panic!("the cloth's mesh has positions"),
        };
        assert_eq!(x.len(), vertices.len(), "one particle a vertex");
        for (k, p) in positions.iter().enumerate() {
            let drawn = frame.transform_point(Vec3::from(*p));
            walk.drawn_off = walk.drawn_off.max(drawn.distance(x[k]));
        }
        let drawn = skin(drawn_pose);
        // In the fixed schedule the step read the pose the last update left; after the
        // animation (`PostUpdate`), the one drawn now.
        let read = match (fixed, before) {
            (true, Some(before)) => skin(before),
            (true, None) => continue, // the first frame: no pose before it was measured
            (false, _) => drawn.clone(),
        };
        walk.frames += 1;
        for (k, (_, _, distance)) in vertices.iter().enumerate() {
            let off = x[k].distance(read[k]);
            if *distance == 0.0 {
                walk.waist_off_read = walk.waist_off_read.max(off);
                walk.waist_off_drawn = walk.waist_off_drawn.max(x[k].distance(drawn[k]));
            } else {
                walk.over = walk.over.max(off - distance);
                walk.swing = walk.swing.max(off / distance);
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(
        walk.frames,
        110,
        "the glTF loaded ({:?}) and its cloth was built",
        server.get_load_state(&scene)
    );
    eprintln!(
        "{name}: waist {} m off the pose read, {} m off the pose drawn; others {} m past \
         their distance, {} of it used; mesh {} m off the particles; hips walked {} m",
        walk.waist_off_read,
        walk.waist_off_drawn,
        walk.over,
        walk.swing,
        walk.drawn_off,
        walk.walked
    );
    // On either clock: the walk played, the waist is on the pose its step read, and no
    // particle went past its distance though the lower rows swing.
    assert!(
        walk.walked > 1.0,
        "the animation walked the hips {} m",
        walk.walked
    );
    assert!(
        walk.waist_off_read <= 1e-5,
        "the waist is {} m off the pose read",
        walk.waist_off_read
    );
    assert!(
        walk.over <= 1e-5,
        "a particle went {} m past its distance",
        walk.over
    );
    assert!(
        walk.swing > 0.3,
        "the lower rows move within their distances: {}",
        walk.swing
    );
    walk
}

/// A character exported to glTF (a skirt skinned to two joints, its maximum distances in a
/// custom vertex attribute, a walk animation) loads and walks with its skirt a cloth:
/// stepped after the animation (`ClothPlugin::new(PostUpdate)`), every frame the waist is
/// where the skin puts it in the pose drawn that frame (1e-5 m), no particle is past its
/// painted distance (+1e-5 m) though the lower rows swing, and the mesh drawn is the
/// particles.
#[test]
fn a_gltf_character_walks_in_its_skirt_stepped_after_its_animation() {
    let walk = walk_a_gltf_character(PostUpdate, "after_animation");
    assert!(
        walk.waist_off_drawn <= 1e-5,
        "the waist is {} m off the body drawn",
        walk.waist_off_drawn
    );
    assert!(
        walk.drawn_off <= 1e-5,
        "the mesh is drawn {} m off the particles",
        walk.drawn_off
    );
}

/// The same character with the cloths on the fixed clock (the default): each step reads
/// the pose the animation left in the frame before, so the waist is on that pose (1e-5 m)
/// and a frame's motion behind the body drawn (the hips walk 1.2 m/s: ≈ 2 cm at 16 ms).
#[test]
fn on_the_fixed_clock_a_gltf_character_is_read_a_frame_late() {
    let walk = walk_a_gltf_character(FixedPostUpdate, "fixed");
    assert!(
        walk.waist_off_drawn > 0.01,
        "the waist lags the body drawn by a frame's motion: {} m",
        walk.waist_off_drawn
    );
}

/// A glTF file with the skirt's simulation mesh and a render mesh of it 3 × 3 times finer
/// (`Skirt` and `Skirt.render`, both skinned): the simulation mesh made the cloth and
/// drawn with the render mesh through `ClothProxyEntity`. The render entity is hidden, the
/// cloth draws its mesh, and after 110 frames of the walk every render vertex is on its
/// bound point of its simulation triangle (1e-5 m) though the skirt swung.
#[test]
fn a_gltf_skirt_is_drawn_with_the_finer_render_mesh_of_its_file() {
    use bevy::animation::graph::AnimationGraphHandle;
    use bevy::gltf::{GltfAssetLabel, GltfMeshName};
    use bevy::world_serialization::{WorldAssetRoot, WorldInstanceReady};
    use bevy_cloth::solver::ProxyBinding;

    let dir = std::env::temp_dir().join(format!("bevy_cloth_gltf_{}_proxy", std::process::id()));
    walk_gltf::write(&dir, Some(3));
    let mut app = gltf_app(&dir, PostUpdate);
    let server = app.world().resource::<AssetServer>().clone();
    let scene = server.load(GltfAssetLabel::Scene(0).from_asset("walk.gltf"));
    let (graph, walk) = walk_gltf::animation(&mut app);
    app.world_mut()
        .spawn(WorldAssetRoot(scene.clone()))
        .observe(
            move |ready: On<WorldInstanceReady>,
                  children: Query<&Children>,
                  meshes: Query<&GltfMeshName>,
                  mut players: Query<&mut AnimationPlayer>,
                  mut commands: Commands| {
                let named = |name: &str| {
                    children
                        .iter_descendants(ready.entity)
                        .find(|&e| meshes.get(e).is_ok_and(|m| m.0 == name))
                };
                let (Some(simulated), Some(render)) = (named("Skirt"), named("Skirt.render"))
                else {
                    panic!("the file has both meshes");
                };
                commands.entity(simulated).insert((
                    Cloth::from_mesh().with_pins(ClothPins::None),
                    ClothProxyEntity(render),
                ));
                for entity in children.iter_descendants(ready.entity) {
                    if let Ok(mut player) = players.get_mut(entity) {
                        player.play(walk);
                        commands
                            .entity(entity)
                            .insert(AnimationGraphHandle(graph.clone()));
                    }
                }
            },
        );
    // Until the cloth is built and draws the render entity's mesh.
    let (cloth, render) = (0..600)
        .find_map(|_| {
            app.update();
            std::thread::sleep(std::time::Duration::from_millis(2)); // the glTF loads
            let world = app.world_mut();
            let mut cloths = world.query::<(Entity, &ClothProxyEntity, &Mesh3d)>();
            let (cloth, render, drawn) = cloths.iter(world).next()?;
            let (render, drawn) = (render.0, drawn.0.clone());
            // Bound: the cloth draws its own copy of the render entity's mesh.
            let render_mesh = world.get::<Mesh3d>(render)?.0.clone();
            let meshes = world.resource::<Assets<Mesh>>();
            let vertices = |mesh: &Handle<Mesh>| meshes.get(mesh).map(Mesh::count_vertices);
            let bound = drawn != render_mesh
                && vertices(&drawn).is_some()
                && vertices(&drawn) == vertices(&render_mesh);
            bound.then_some((cloth, render))
        })
        .expect("the glTF loaded and its cloth was bound to its render mesh");
    for _ in 0..110 {
        app.update();
    }
    let world = app.world();
    assert_eq!(
        world.get::<Visibility>(render),
        Some(&Visibility::Hidden),
        "the render entity is hidden: the cloth draws it"
    );
    let sim = world.get::<ClothSimulation>(cloth).unwrap();
    let handle = &world.get::<Mesh3d>(cloth).unwrap().0;
    let fine: Vec<Vec3> = walk_gltf::vertices_at(3).iter().map(|v| v.0).collect();
    let binding = ProxyBinding::bind(
        sim.solver.rest_positions(),
        sim.solver.triangles(),
        &fine,
        None,
    )
    .unwrap();
    let drawn = common::mesh_positions(&app, handle);
    let (farthest, moved) = common::proxy_offsets(&sim.solver, &binding, &drawn, &fine);
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!(
        "{} render vertices for {} particles: farthest from its bound point {farthest:e} m; \
         moved up to {moved:.3} m",
        drawn.len(),
        sim.solver.particle_count()
    );
    assert_eq!(drawn.len(), fine.len(), "the render mesh is drawn");
    assert!(farthest < 1e-5, "{farthest} m");
    assert!(moved > 0.5, "the skirt walked: {moved} m");
}
