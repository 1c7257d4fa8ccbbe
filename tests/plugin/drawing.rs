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
