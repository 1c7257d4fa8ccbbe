//! Headless App tests of drawing: the render mesh created and rewritten in place, hidden
//! cloths, interpolation between steps.

use bevy::mesh::Mesh3d;
use bevy::prelude::*;
use bevy_cloth::prelude::*;

use crate::common::*;

#[test]
fn mesh_is_created_and_rewritten_in_place() {
    let mut app = app();
    // Drawn where the last step ended (see a_hidden_cloth_steps_but_writes_its_mesh_only_when_shown).
    app.insert_resource(ClothInterpolation(false));
    let (e, handle) = spawn_small_cloth(&mut app);
    let read = |app: &App| mesh_positions(app, &handle);
    let before = read(&app);
    assert_eq!(before.len(), 20);
    for _ in 0..10 {
        app.update();
    }
    let after = read(&app);
    assert_eq!(
        app.world().get::<Mesh3d>(e).unwrap().0,
        handle,
        "a new mesh was made"
    );
    assert_ne!(before, after, "the mesh did not follow the cloth");
    // Positions are local to the entity: solver world position = transform · mesh position.
    let sim = app.world().get::<ClothSimulation>(e).unwrap();
    let world = sim.solver.positions()[19];
    let local = Vec3::from(after[19]);
    assert!(
        (local + Vec3::new(0.0, 2.0, 0.0) - world).length() < 1e-4,
        "local {local} world {world}"
    );
    // Pinned corners sit where the grid puts them in the entity's frame.
    assert!((Vec3::from(after[0]) - Vec3::new(-0.2, 0.0, 0.0)).length() < 1e-5);
}

#[test]
fn a_hidden_cloth_steps_but_writes_its_mesh_only_when_shown() {
    let mut app = app();
    // Drawn where the last step ended (with interpolation, at 16 ms updates and no time
    // over, a mesh shows where the step began: the_mesh_is_drawn_between_the_last_two_steps).
    app.insert_resource(ClothInterpolation(false));
    let (e, handle) = spawn_small_cloth(&mut app);
    let read = |app: &App| mesh_positions(app, &handle);
    app.world_mut().entity_mut(e).insert(Visibility::Hidden);
    app.update();
    let hidden = read(&app);
    let solver_at = |app: &App| {
        app.world()
            .get::<ClothSimulation>(e)
            .unwrap()
            .solver
            .positions()[19]
    };
    let before = solver_at(&app);
    for _ in 0..10 {
        app.update();
    }
    assert_ne!(solver_at(&app), before, "a hidden cloth still steps");
    assert_eq!(read(&app), hidden, "a hidden cloth's mesh is not rewritten");
    app.world_mut().entity_mut(e).insert(Visibility::Inherited);
    app.update();
    let shown = Vec3::from(read(&app)[19]);
    let world = solver_at(&app);
    assert!(
        (shown + Vec3::new(0.0, 2.0, 0.0) - world).length() < 1e-4,
        "written when shown"
    );
}

/// The mesh is drawn between the last two fixed steps: after an update that leaves half
/// a timestep over (8 of 16 ms), each vertex is midway between where the last step
/// began and where it ended; with interpolation off it is where the step ended.
#[test]
fn the_mesh_is_drawn_between_the_last_two_steps() {
    use bevy::time::TimeUpdateStrategy;
    use std::time::Duration;
    for on in [true, false] {
        let mut app = app();
        app.insert_resource(ClothInterpolation(on));
        let (e, handle) = spawn_small_cloth(&mut app);
        for _ in 0..5 {
            app.update();
        }
        let positions = |app: &App| {
            let sim = app.world().get::<ClothSimulation>(e).unwrap();
            sim.solver.positions().to_vec()
        };
        let before = positions(&app);
        app.update(); // one 16 ms step, nothing over
        let after = positions(&app);
        app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_millis(8)));
        app.update(); // no step: half a timestep over
        assert_eq!(positions(&app), after, "an 8 ms update stepped");
        let drawn = mesh_positions(&app, &handle);
        let mut moved = 0.0f32;
        for i in 0..after.len() {
            // The cloth's frame is a translation by 2 m up.
            let want = if on {
                before[i].lerp(after[i], 0.5)
            } else {
                after[i]
            };
            let got = Vec3::from(drawn[i]) + Vec3::new(0.0, 2.0, 0.0);
            assert!(
                got.distance(want) < 1e-5,
                "interpolation {on}: vertex {i} drawn at {got}, not {want}"
            );
            moved = moved.max(before[i].distance(after[i]));
        }
        assert!(moved > 1e-3, "the cloth moved in that step: {moved} m");
    }
}

/// A render mesh `k` times finer each way than the `w × h` grid whose rest positions are
/// `rest`: each cell cut into `k × k`, its vertices placed bilinearly, with normals, UVs
/// and tangents.
fn finer_grid(rest: &[Vec3], (w, h): (u32, u32), k: u32) -> Mesh {
    let (rw, rh) = ((w - 1) * k + 1, (h - 1) * k + 1);
    let mut positions = Vec::new();
    for j in 0..rh {
        for i in 0..rw {
            let (ci, cj) = ((i / k).min(w - 2), (j / k).min(h - 2));
            let (a, b) = (
                (i - ci * k) as f32 / k as f32,
                (j - cj * k) as f32 / k as f32,
            );
            let at = |di: u32, dj: u32| rest[((cj + dj) * w + ci + di) as usize];
            let top = at(0, 0).lerp(at(1, 0), a);
            let bottom = at(0, 1).lerp(at(1, 1), a);
            positions.push(top.lerp(bottom, b).to_array());
        }
    }
    let n = positions.len();
    let uvs: Vec<[f32; 2]> = (0..n as u32)
        .map(|v| {
            [
                (v % rw) as f32 / (rw - 1) as f32,
                (v / rw) as f32 / (rh - 1) as f32,
            ]
        })
        .collect();
    let mut indices = Vec::new();
    for j in 0..rh - 1 {
        for i in 0..rw - 1 {
            let v = j * rw + i;
            indices.extend([v, v + rw, v + 1, v + 1, v + rw, v + rw + 1]);
        }
    }
    Mesh::new(
        bevy::mesh::PrimitiveTopology::TriangleList,
        bevy::asset::RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, vec![[0.0f32, 0.0, 1.0]; n])
    .with_inserted_attribute(Mesh::ATTRIBUTE_UV_0, uvs)
    .with_inserted_attribute(Mesh::ATTRIBUTE_TANGENT, vec![[1.0f32, 0.0, 0.0, 1.0]; n])
    .with_inserted_indices(bevy::mesh::Indices::U32(indices))
}

/// A proxy 3 × 3 times finer than `cloth`, a built `w × h` grid ([`finer_grid`]): the
/// cloth's rest positions, the proxy's vertices, and the proxy's mesh added to the app.
fn finer_proxy(
    app: &mut App,
    cloth: Entity,
    (w, h): (u32, u32),
) -> (Vec<Vec3>, Vec<Vec3>, Handle<Mesh>) {
    let rest = {
        let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
        sim.solver.rest_positions().to_vec()
    };
    let render = finer_grid(&rest, (w, h), 3);
    let render_x: Vec<Vec3> = match render.attribute(Mesh::ATTRIBUTE_POSITION) {
        Some(bevy::mesh::VertexAttributeValues::Float32x3(p)) => {
            p.iter().map(|&p| Vec3::from(p)).collect()
        }
        _ => unreachable!(),
    };
    let handle = app.world_mut().resource_mut::<Assets<Mesh>>().add(render);
    (rest, render_x, handle)
}

/// A cloth drawn with a proxy 3 × 3 times finer (9 times the vertices): once bound, the
/// entity draws the proxy's mesh, and after 300 frames of sagging every render vertex is
/// within 1e-5 m of its bound point on its simulation triangle (bound anew here from the
/// rest shape), its normal a unit vector and its tangent at right angles to it; the drawn
/// vertices are those of the golden dump `proxy_drawn`.
#[test]
fn a_proxy_mesh_follows_its_simulation_triangles() {
    let mut app = app();
    app.insert_resource(ClothInterpolation(false));
    let (w, h) = (8u32, 6u32);
    let cloth = app
        .world_mut()
        .spawn((
            Cloth::grid(w, h, 0.1),
            Transform::from_xyz(0.5, 2.0, -0.3).with_rotation(Quat::from_rotation_y(0.4)),
        ))
        .id();
    while app.world().get::<ClothSimulation>(cloth).is_none() {
        app.update();
    }
    let (rest, render_x, handle) = finer_proxy(&mut app, cloth, (w, h));
    app.world_mut().entity_mut(cloth).insert(ClothProxy {
        mesh: handle.clone(),
    });
    for _ in 0..300 {
        app.update();
    }
    // The cloth draws its own copy of the proxy's mesh, which stays as it was.
    let own = app.world().get::<Mesh3d>(cloth).unwrap().0.clone();
    assert_ne!(own, handle);
    let template: Vec<Vec3> = mesh_positions(&app, &handle)
        .into_iter()
        .map(Vec3::from)
        .collect();
    assert_eq!(template, render_x);
    let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
    let binding =
        bevy_cloth::solver::ProxyBinding::bind(&rest, sim.solver.triangles(), &render_x, None)
            .unwrap();
    let drawn = mesh_positions(&app, &own);
    let (farthest, moved) = proxy_offsets(&sim.solver, &binding, &drawn, &render_x);
    eprintln!(
        "{} render vertices: farthest from its bound point {farthest:e} m; moved up to {moved:.3} m",
        drawn.len()
    );
    assert_eq!(drawn.len(), render_x.len());
    assert!(farthest < 1e-5, "{farthest} m");
    assert!(moved > 0.01, "the cloth sagged: {moved} m");
    // What a game draws, as it was: the proxy's vertices after the 300 frames.
    let drawn: Vec<Vec3> = drawn.into_iter().map(Vec3::from).collect();
    golden::assert_golden("proxy_drawn", &drawn);
    let meshes = app.world().resource::<Assets<Mesh>>();
    let mesh = meshes.get(&own).unwrap();
    let (
        Some(bevy::mesh::VertexAttributeValues::Float32x3(normals)),
        Some(bevy::mesh::VertexAttributeValues::Float32x4(tangents)),
    ) = (
        mesh.attribute(Mesh::ATTRIBUTE_NORMAL),
        mesh.attribute(Mesh::ATTRIBUTE_TANGENT),
    )
    else {
        panic!("normals and tangents kept");
    };
    for (n, t) in normals.iter().zip(tangents) {
        let (n, t) = (Vec3::from(*n), Vec3::new(t[0], t[1], t[2]));
        assert!((n.length() - 1.0).abs() < 1e-4);
        assert!(n.dot(t).abs() < 1e-4, "tangent {t} against normal {n}");
    }
}

/// Two cloths drawn through one proxy mesh (as a crowd's capes are) each draw their own
/// copy of it on their own triangles: one hangs from its corners and the other falls, and
/// after 60 frames each drawn mesh is within 1e-5 m of its own cloth's bound points, the
/// two far apart, and the proxy's mesh as it was.
#[test]
fn cloths_drawn_through_one_proxy_mesh_each_draw_their_own() {
    let mut app = app();
    app.insert_resource(ClothInterpolation(false));
    let (w, h) = (8u32, 6u32);
    let hanging = app
        .world_mut()
        .spawn((Cloth::grid(w, h, 0.1), Transform::from_xyz(0.0, 2.0, 0.0)))
        .id();
    let falling = app
        .world_mut()
        .spawn((
            Cloth::grid(w, h, 0.1).with_pins(ClothPins::None),
            Transform::from_xyz(3.0, 2.0, 0.0),
        ))
        .id();
    while app.world().get::<ClothSimulation>(falling).is_none() {
        app.update();
    }
    let (rest, render_x, handle) = finer_proxy(&mut app, hanging, (w, h));
    for cloth in [hanging, falling] {
        app.world_mut().entity_mut(cloth).insert(ClothProxy {
            mesh: handle.clone(),
        });
    }
    for _ in 0..60 {
        app.update();
    }
    let world = app.world();
    let drawn = [hanging, falling].map(|cloth| world.get::<Mesh3d>(cloth).unwrap().0.clone());
    assert_ne!(drawn[0], drawn[1]);
    assert!(!drawn.contains(&handle));
    let template: Vec<Vec3> = mesh_positions(&app, &handle)
        .into_iter()
        .map(Vec3::from)
        .collect();
    assert_eq!(template, render_x, "the proxy's mesh is as it was");
    let positions = drawn.each_ref().map(|mesh| mesh_positions(&app, mesh));
    for (cloth, positions) in [hanging, falling].iter().zip(&positions) {
        let sim = world.get::<ClothSimulation>(*cloth).unwrap();
        let binding =
            bevy_cloth::solver::ProxyBinding::bind(&rest, sim.solver.triangles(), &render_x, None)
                .unwrap();
        let (farthest, _) = proxy_offsets(&sim.solver, &binding, positions, &render_x);
        assert!(farthest < 1e-5, "{cloth}: {farthest} m");
    }
    let apart = positions[0]
        .iter()
        .zip(&positions[1])
        .map(|(a, b)| Vec3::from(*a).distance(Vec3::from(*b)))
        .fold(0.0, f32::max);
    assert!(apart > 0.1, "the two drawn meshes differ: {apart} m");
}

/// A proxy mesh without positions is refused: the cloth is paused and says why.
#[test]
fn a_proxy_mesh_without_positions_is_refused() {
    let mut app = app();
    let cloth = app.world_mut().spawn(Cloth::grid(4, 4, 0.1)).id();
    while app.world().get::<ClothSimulation>(cloth).is_none() {
        app.update();
    }
    let empty = Mesh::new(
        bevy::mesh::PrimitiveTopology::TriangleList,
        bevy::asset::RenderAssetUsages::default(),
    );
    let handle = app.world_mut().resource_mut::<Assets<Mesh>>().add(empty);
    app.world_mut()
        .entity_mut(cloth)
        .insert(ClothProxy { mesh: handle });
    app.update();
    let invalid = app.world().get::<ClothInvalid>(cloth).expect("refused");
    assert!(
        matches!(&invalid.0, ClothError::BadMesh { reason } if reason.contains("proxy")),
        "{:?}",
        invalid.0
    );
}
