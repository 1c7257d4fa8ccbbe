//! Garments as assets: the plugin loads them and rebuilds them when a file changes.

use super::*;

/// Updates `app` (sleeping between updates, so the file watcher gets to run) until
/// `done` holds, for at most `seconds` of wall-clock time.
fn update_until(app: &mut App, seconds: f32, mut done: impl FnMut(&mut App) -> bool) -> bool {
    let start = std::time::Instant::now();
    while start.elapsed().as_secs_f32() < seconds {
        app.update();
        if done(app) {
            return true;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    false
}

/// The particle count of the one cloth, or its error.
fn built(app: &mut App) -> Option<Result<usize, String>> {
    let world = app.world_mut();
    let mut cloths =
        world.query_filtered::<(Option<&ClothSimulation>, Option<&ClothInvalid>), bevy::prelude::With<Cloth>>();
    let (sim, invalid) = cloths.single(world).expect("one cloth");
    match (sim, invalid) {
        (_, Some(e)) => Some(Err(e.0.to_string())),
        (Some(sim), None) => Some(Ok(sim.solver.particle_count())),
        (None, None) => None,
    }
}

#[test]
fn the_plugin_loads_garments_as_assets_and_rebuilds_them_when_a_file_changes() {
    let dir = std::env::temp_dir().join(format!("bevy_cloth_hot_reload_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let write = |file: &str, text: &str| std::fs::write(dir.join(file), text).unwrap();
    write(
        "g.ron",
        "(spacing: 0.1, pieces: [(name: \"a\", pattern: \"p.txt\")])",
    );
    // Broken from the start: the cloth is invalid, with the pattern's line and column.
    write("p.txt", "111\n1x1\n");
    let mut app = bevy_cloth::headless::headless_app_in(dir.to_string_lossy());
    app.world_mut().spawn(Cloth::garment("g.ron"));
    assert!(update_until(&mut app, 10.0, |app| built(app).is_some()));
    let error = built(&mut app).unwrap().unwrap_err();
    assert!(error.contains("p.txt:2:2"), "{error}");
    // Fixed on disk: the watcher reloads it and the cloth is built (3×3 = 9 particles).
    write("p.txt", "111\n111\n111\n");
    assert!(
        update_until(&mut app, 10.0, |app| built(app) == Some(Ok(9))),
        "{:?}",
        built(&mut app)
    );
    // Edited while running: rebuilt at the new size.
    write("p.txt", "1111\n1111\n1111\n1111\n");
    assert!(
        update_until(&mut app, 10.0, |app| built(app) == Some(Ok(16))),
        "{:?}",
        built(&mut app)
    );
    // A broken edit stops the cloth with the error; fixing the garment file rebuilds it.
    write(
        "g.ron",
        "(spacing: 0.1, pieces: [(name: \"a\", pattern: \"p.txt\")], oops: 1)",
    );
    assert!(update_until(&mut app, 10.0, |app| matches!(
        built(app),
        Some(Err(e)) if e.starts_with("g.ron:1:")
    )));
    write(
        "g.ron",
        "(spacing: 0.1, pieces: [(name: \"a\", pattern: \"p.txt\")])",
    );
    assert!(update_until(&mut app, 10.0, |app| built(app) == Some(Ok(16))));
    std::fs::remove_dir_all(&dir).ok();
}
