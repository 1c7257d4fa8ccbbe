//! Scene files: the shipped ones load; malformed ones name the file, line and field.

mod common;

use std::path::Path;

use common::app;

use bevy::prelude::{Fixed, GlobalTransform, Name, Time, Vec3};
use bevy_cloth::params::{
    Integrator, Model, ModelKind, PatchTargets, Substeps, WindField, XpbdParams,
};
use bevy_cloth::prelude::*;
use bevy_cloth::scene::SceneError;

#[test]
fn shipped_scenes_load() {
    for entry in std::fs::read_dir("assets/scenes").unwrap() {
        let path = entry.unwrap().path();
        let scene = ClothScene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(!scene.cloths.is_empty(), "{}", path.display());
    }
    let curtain = ClothScene::load("assets/scenes/curtain.ron").unwrap();
    assert_eq!(curtain.timestep, 0.016);
    assert_eq!(curtain.cloths[0].cloth.pins, ClothPins::TopCorners);
}

fn parse(text: &str) -> Result<ClothScene, SceneError> {
    ClothScene::parse(text, Path::new("bad.ron"))
}

#[test]
fn a_missing_file_names_it() {
    let e = ClothScene::load("assets/scenes/nope.ron").unwrap_err();
    assert!(e.to_string().contains("nope.ron"), "{e}");
}

#[test]
fn syntax_and_unknown_fields_give_line_and_column() {
    let text = "(\n  cloths: [\n    (cloth: (shape: Grid(width: 4, height: 4, spacing: 0.1), pinz: TopRow)),\n  ],\n)";
    match parse(text).unwrap_err() {
        SceneError::Parse {
            file,
            line,
            message,
            ..
        } => {
            assert_eq!(file, Path::new("bad.ron"));
            assert_eq!(line, 3);
            assert!(message.contains("pinz"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    let broken = "(\n  cloths: [\n    (cloth: (shape: Grid(width: 4, height: 4, spacing: 0.1)),\n";
    assert!(matches!(parse(broken), Err(SceneError::Parse { .. })));
}

#[test]
fn bad_values_name_the_field_and_line() {
    let text = "(\n  cloths: [\n    (cloth: (\n      shape: Grid(width: 4, height: 4, spacing: 0.1),\n      params: (\n        node_mass: -2.0,\n      ),\n    )),\n  ],\n)";
    match parse(text).unwrap_err() {
        SceneError::Invalid { field, line, .. } => {
            assert_eq!(field, "cloths[0].cloth.params.node_mass");
            assert_eq!(line, 6);
        }
        other => panic!("{other:?}"),
    }
    let tiny = "(cloths: [(cloth: (shape: Grid(width: 1, height: 4, spacing: 0.1)))])";
    let e = parse(tiny).unwrap_err();
    assert!(e.to_string().contains("2×2"), "{e}");
    let dt = "(timestep: 0.0, cloths: [])";
    assert!(matches!(parse(dt), Err(SceneError::Invalid { .. })));
    // More colliders than limits::MAX_SCENE_ITEMS: refused by count, before anything is
    // placed.
    let ground = "(collider: (shape: Plane)),";
    let many = format!(
        "(cloths: [], colliders: [{}])",
        ground.repeat(bevy_cloth::limits::MAX_SCENE_ITEMS + 1)
    );
    match parse(&many).unwrap_err() {
        SceneError::Invalid { field, message, .. } => {
            assert_eq!(field, "colliders");
            assert!(message.contains("MAX_SCENE_ITEMS"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    let enough = format!("(cloths: [], colliders: [{}])", ground.repeat(3));
    assert!(parse(&enough).is_ok());
}

#[test]
fn overrides_set_fields_by_path_and_refuse_bad_ones() {
    let mut scene = ClothScene::load("assets/scenes/curtain.ron").unwrap();
    scene.apply_override("environment.wind.strength=0").unwrap();
    scene
        .apply_override("environment.gravity=0, -1.62, 0")
        .unwrap();
    scene
        .apply_override("environment.wind.field=Constant")
        .unwrap();
    scene
        .apply_override("cloth.params.node_mass=0.001")
        .unwrap();
    scene
        .apply_override("cloth.params.springs.shear.enabled=false")
        .unwrap();
    scene.apply_override("cloth.params.substeps=12").unwrap();
    scene.apply_override("cloth.params.tear_ratio=2.5").unwrap();
    scene
        .apply_override("cloth.params.integrator=SemiImplicitEuler")
        .unwrap();
    scene.apply_override("cloths[0].pins=TopRow").unwrap();
    scene.apply_override("cloth.shape.width=12").unwrap();
    scene.apply_override("timestep=0.01").unwrap();
    let env = scene.environment;
    assert_eq!(env.wind.strength, 0.0);
    assert_eq!(env.gravity.y, -1.62);
    assert_eq!(env.wind.field, WindField::Constant);
    let cloth = &scene.cloths[0].cloth;
    assert_eq!(cloth.params.node_mass, 0.001);
    assert!(!cloth.params.springs.shear.enabled);
    assert_eq!(cloth.params.substeps, Substeps::Fixed(12));
    assert_eq!(cloth.params.tear_ratio, Some(2.5));
    assert_eq!(cloth.params.integrator, Integrator::SemiImplicitEuler);
    assert_eq!(cloth.pins, ClothPins::TopRow);
    assert!(matches!(cloth.shape, ClothShape::Grid { width: 12, .. }));
    assert_eq!(scene.timestep, 0.01);

    for bad in [
        "wind=0",
        "environment.wind.speed=3",
        "cloth.params.node_mass=-1",
        "cloth.params.node_mass=heavy",
        "cloth.pins=Middle",
        "cloths[4].pins=TopRow",
        "cloth.shape.width=1",
        "environment.gravity=1,2",
        "timestep=0",
    ] {
        let e = scene.clone().apply_override(bad).unwrap_err();
        assert!(matches!(e, SceneError::Override { .. }), "{bad}: {e}");
    }
}

#[test]
fn overrides_on_a_scene_of_several_cloths() {
    let mut scene = ClothScene::load("assets/scenes/card.ron").unwrap();
    assert_eq!(scene.cloths.len(), 2);
    scene.apply_override("environment.wind.strength=0").unwrap();
    scene
        .apply_override("cloths[1].params.node_mass=0.0001")
        .unwrap();
    assert_eq!(scene.cloths[1].cloth.params.node_mass, 1e-4);
    assert_eq!(scene.cloths[0].cloth.params.node_mass, 2e-5);
    let e = scene
        .apply_override("cloths[1].params.drag=-1")
        .unwrap_err();
    assert!(e.to_string().contains("cloths[1]"), "{e}");
}

#[test]
fn scenes_name_a_missing_garment_and_a_bad_collider() {
    let garment =
        r#"(cloths: [(cloth: (shape: Garment(file: "patterns/nope.ron", resolution: 1)))])"#;
    let e = ClothScene::parse(garment, Path::new("g.ron"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("g.ron:1: `cloths[0].cloth.shape`") && e.contains("nope.ron"),
        "{e}"
    );
    let collider = "(cloths: [],\n colliders: [(collider: (shape: Sphere(radius: -1.0)))])";
    let e = ClothScene::parse(collider, Path::new("c.ron"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("c.ron:2: `colliders[0].collider.radius`"),
        "{e}"
    );
    // The shipped T-shirt scene loads, with its mannequin.
    let scene = ClothScene::load("assets/scenes/tshirt.ron").unwrap();
    assert_eq!(scene.colliders.len(), 12);
}

#[test]
fn the_per_part_targets_still_read_under_their_old_name() {
    let old: PatchTargets = ron::from_str("Seed").unwrap();
    let new: PatchTargets = ron::from_str("PerPart").unwrap();
    assert_eq!(old, PatchTargets::PerPart);
    assert_eq!(new, PatchTargets::PerPart);
}

#[test]
fn one_model_identifier_reads_back_what_it_writes() {
    for kind in ModelKind::ALL {
        assert_eq!(kind.name().parse::<ModelKind>(), Ok(kind));
        assert_eq!(kind.to_string(), kind.name());
        assert_eq!(kind.default_model().kind(), kind);
    }
    assert!(matches!(
        "springs".parse::<ModelKind>(),
        Err(ClothError::UnknownModel { .. })
    ));
}

#[test]
fn xpbd_reads_from_scene_files_and_overrides_and_only_it_takes_an_infinite_stiffness() {
    let text = "(cloths: [(cloth: (shape: Grid(width: 4, height: 4, spacing: 0.1), params: (\n  model: Xpbd((max_stretch_error: 0.005)),\n  springs: (structural: (enabled: true, stiffness: inf)),\n)))])";
    let scene = parse(text).unwrap();
    let params = scene.cloths[0].cloth.params;
    assert_eq!(
        params.model,
        Model::Xpbd(XpbdParams {
            max_stretch_error: 0.005,
            ..XpbdParams::default()
        })
    );
    assert_eq!(params.springs.structural.stiffness, f32::INFINITY);
    // The explicit models refuse it, naming the field and line.
    let explicit = text.replace(
        "model: Xpbd((max_stretch_error: 0.005)),",
        "model: MassSpring,",
    );
    match parse(&explicit).unwrap_err() {
        SceneError::Invalid { field, line, .. } => {
            assert_eq!(field, "cloths[0].cloth.params.springs.structural.stiffness");
            assert_eq!(line, 3);
        }
        other => panic!("{other:?}"),
    }
    let mut curtain = ClothScene::load("assets/scenes/curtain.ron").unwrap();
    curtain.apply_override("cloth.params.model=Xpbd").unwrap();
    curtain
        .apply_override("cloth.params.springs.structural.stiffness=inf")
        .unwrap();
    assert!(matches!(
        curtain.cloths[0].cloth.params.model,
        Model::Xpbd(_)
    ));
    let mut explicit = ClothScene::load("assets/scenes/curtain.ron").unwrap();
    let e = explicit
        .apply_override("cloth.params.springs.structural.stiffness=inf")
        .unwrap_err();
    assert!(matches!(e, SceneError::Override { .. }), "{e}");
    // The refusal names the override once, then what is wrong; the field only when it is
    // another than the key's.
    let e = explicit
        .apply_override("cloth.params.drag=-1")
        .unwrap_err()
        .to_string();
    assert_eq!(e.matches("drag=-1").count(), 1, "{e}");
    assert!(!e.contains("params.drag`"), "{e}");
    let mut fabric = ClothScene::load("assets/scenes/denim_curtain.ron").unwrap();
    let e = fabric
        .apply_override("cloth.params.model=Patches")
        .unwrap_err()
        .to_string();
    assert!(e.contains("`cloths[0].cloth.params.fabric`: "), "{e}");
}

#[test]
fn a_box_collider_reads_from_a_scene_and_scales_with_its_transform() {
    let text = "(cloths: [(cloth: (shape: Grid(width: 4, height: 4, spacing: 0.1)))],
        colliders: [(translation: (1.0, 0.0, 0.0),
                     collider: (shape: Cuboid(half_extents: (0.1, 0.2, 0.3)), thickness: 0.01, friction: 0.3))])";
    let scene = ClothScene::parse(text, std::path::Path::new("box.ron")).unwrap();
    let collider = &scene.colliders[0];
    let transform = collider.transform().with_scale(Vec3::new(2.0, 1.0, 1.0));
    match collider
        .collider
        .to_world(&GlobalTransform::from(transform))
        .shape
    {
        bevy_cloth::solver::ColliderShape::Cuboid(bevy_cloth::solver::shapes::Cuboid {
            center,
            half_extents,
            ..
        }) => {
            assert_eq!(center, Vec3::new(1.0, 0.0, 0.0));
            assert_eq!(half_extents, Vec3::new(0.2, 0.2, 0.3));
        }
        other => panic!("{other:?}"),
    }
    // A flat box is refused, naming the field.
    let flat = text.replace("(0.1, 0.2, 0.3)", "(0.1, 0.0, 0.3)");
    let e = ClothScene::parse(&flat, std::path::Path::new("box.ron")).unwrap_err();
    assert!(e.to_string().contains("half_extents.y"), "{e}");
    // A cylinder in a scene file: scaled along y for its height, x/z for its radius; a
    // flat one is refused the same way.
    let cylinder = text.replace(
        "Cuboid(half_extents: (0.1, 0.2, 0.3))",
        "Cylinder(radius: 0.1, half_height: 0.4)",
    );
    let scene = ClothScene::parse(&cylinder, std::path::Path::new("c.ron")).unwrap();
    let transform = scene.colliders[0]
        .transform()
        .with_scale(Vec3::new(2.0, 0.5, 1.0));
    match scene.colliders[0]
        .collider
        .to_world(&GlobalTransform::from(transform))
        .shape
    {
        bevy_cloth::solver::ColliderShape::Cylinder(bevy_cloth::solver::shapes::Cylinder {
            half_height,
            radius,
            axis,
            ..
        }) => {
            assert_eq!((half_height, radius, axis), (0.2, 0.2, Vec3::Y));
        }
        other => panic!("{other:?}"),
    }
    let flat = cylinder.replace("half_height: 0.4", "half_height: 0.0");
    let e = ClothScene::parse(&flat, std::path::Path::new("c.ron")).unwrap_err();
    assert!(e.to_string().contains("half_height"), "{e}");
}

/// The first ```rust block of `text` from byte `from` on.
fn rust_block(text: &str, from: usize) -> &str {
    let start = from + text[from..].find("```rust\n").expect("a Rust block") + "```rust\n".len();
    &text[start..start + text[start..].find("```").expect("a closed block")]
}

/// The README's quick start is `examples/quickstart.rs` (which `cargo test` compiles),
/// without the example's doc comment.
#[test]
fn the_readme_quick_start_is_the_quickstart_example() {
    let root = env!("CARGO_MANIFEST_DIR");
    let example = std::fs::read_to_string(format!("{root}/examples/quickstart.rs")).unwrap();
    let code: String = example
        .lines()
        .filter(|l| !l.starts_with("//!"))
        .map(|l| format!("{l}\n"))
        .collect();
    let readme = std::fs::read_to_string(format!("{root}/README.md")).unwrap();
    assert_eq!(
        rust_block(&readme, 0),
        code.trim_start(),
        "README.md's quick start differs from the example"
    );
}

/// The recipes in `docs/recipes.md` are the examples' code: every block marked
/// `<!-- file: PATH -->` is that whole file, so what the page shows compiles and runs.
#[test]
fn every_recipe_block_is_its_example_file() {
    let root = env!("CARGO_MANIFEST_DIR");
    let page = std::fs::read_to_string(format!("{root}/docs/recipes.md")).unwrap();
    let marks: Vec<usize> = page.match_indices("<!-- file: ").map(|(i, _)| i).collect();
    assert!(!marks.is_empty(), "no recipe block is marked with its file");
    // Every recipe example is on the page.
    for entry in std::fs::read_dir(format!("{root}/examples")).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().to_string();
        if name.starts_with("recipe_") {
            let mark = format!("<!-- file: examples/{name} -->");
            assert!(
                page.contains(&mark),
                "docs/recipes.md has no block for {name}"
            );
        }
    }
    for at in marks {
        let path = page[at + "<!-- file: ".len()..]
            .split(" -->")
            .next()
            .unwrap();
        let file = std::fs::read_to_string(format!("{root}/{path}"))
            .unwrap_or_else(|e| panic!("{path}: {e}"));
        assert_eq!(
            rust_block(&page, at),
            file,
            "docs/recipes.md's block for {path}"
        );
    }
}

#[test]
fn a_scene_spawns_its_cloths_colliders_and_world() {
    let mut scene = ClothScene::load("assets/scenes/tshirt.ron").unwrap();
    // Made for another timestep than the app's 16 ms.
    scene.timestep = 0.01;
    let mut app = app();
    let spawned = scene.spawn(&mut app.world_mut().commands());
    app.world_mut().flush();
    assert_eq!(spawned.cloths.len(), scene.cloths.len());
    assert_eq!(spawned.colliders.len(), scene.colliders.len());
    // The garment loads through the asset server, in the background.
    let start = std::time::Instant::now();
    while start.elapsed().as_secs() < 10
        && !spawned
            .cloths
            .iter()
            .all(|&e| app.world().get::<ClothSimulation>(e).is_some())
    {
        app.update();
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    for (entry, &entity) in scene.cloths.iter().zip(&spawned.cloths) {
        let sim = app.world().get::<ClothSimulation>(entity).expect("built");
        assert!(sim.solver.particle_count() > 0);
        assert_eq!(
            app.world().get::<Name>(entity).map(|n| n.as_str()),
            Some(entry.name.as_str())
        );
    }
    for (entry, &entity) in scene.colliders.iter().zip(&spawned.colliders) {
        assert_eq!(
            app.world().get::<ClothCollider>(entity),
            Some(&entry.collider)
        );
    }
    assert_eq!(
        app.world().resource::<ClothEnvironment>().0,
        scene.environment
    );
    // Spawning a scene leaves the game's clock alone (a scene made for another timestep
    // once overwrote it).
    let fixed = app.world().resource::<Time<Fixed>>().timestep();
    assert_eq!(fixed, std::time::Duration::from_millis(16));
}

/// Two banners, one in a sphere of wind and one 10 m off; `zones` is the scene's
/// `wind_zones` entry.
fn banners(zones: &str) -> String {
    let banner = |x: f32| {
        format!(
            "(name: \"at {x}\", translation: ({x}, 2.0, 0.0), cloth: (shape: Grid(width: 10, \
             height: 8, spacing: 0.05), pins: TopRow)),"
        )
    };
    format!(
        "(cloths: [{}{}], wind_zones: [{zones}])",
        banner(0.0),
        banner(10.0)
    )
}

#[test]
fn a_scene_places_wind_zones_that_blow_in_the_runner_and_spawn_as_entities() {
    use bevy_cloth::headless::SceneRun;
    let zone = "(shape: Sphere(radius: 1.5), centre: (0, 1.8, 0), rotation: (0, 0.3826834, 0, \
                0.9238795), velocity: (0, 0, 6), falloff: 0.25, turbulence: (gust: 0.3, seed: 7))";
    let windy = parse(&banners(zone)).unwrap();
    let calm = parse(&banners("")).unwrap();
    assert_eq!(windy.wind_zones.len(), 1);
    let run = |scene: &ClothScene| {
        let mut run = SceneRun::new(scene).unwrap();
        run.run(120, |_, _| {});
        run.cloths
            .iter()
            .map(|(_, c)| c.positions().to_vec())
            .collect::<Vec<_>>()
    };
    let (windy_x, calm_x) = (run(&windy), run(&calm));
    let mean_z = |x: &[Vec3]| x.iter().map(|p| p.z).sum::<f32>() / x.len() as f32;
    let blown = mean_z(&windy_x[0]) - mean_z(&calm_x[0]);
    eprintln!("the banner in the zone: {blown:.3} m downwind");
    assert!(blown > 0.05, "moved {blown} m downwind");
    // The one the zone does not reach moves as in calm air, to the bit.
    assert_eq!(windy_x[1], calm_x[1]);

    // Spawned, the zone is an entity that places back to the scene's zone.
    let mut app = app();
    windy.spawn(&mut app.world_mut().commands());
    app.world_mut().flush();
    let mut zones = app
        .world_mut()
        .query::<(&ClothWindZone, &bevy::prelude::Transform)>();
    let (component, transform) = zones.single(app.world()).unwrap();
    let placed = component.placed(&GlobalTransform::from(*transform));
    let want = windy.wind_zones[0];
    assert!(placed.centre.distance(want.centre) < 1e-6);
    assert!(placed.velocity.distance(want.velocity) < 1e-5, "{placed:?}");
    assert_eq!(
        (placed.shape, placed.turbulence),
        (want.shape, want.turbulence)
    );

    // A bad zone names its field; a misspelt key is refused.
    let bad = banners("(shape: Sphere(radius: 1.0), falloff: 2.0)");
    match parse(&bad).unwrap_err() {
        SceneError::Invalid { field, .. } => assert_eq!(field, "wind_zones[0].falloff"),
        other => panic!("{other:?}"),
    }
    assert!(parse(&banners("(shape: Global, velocty: (1, 0, 0))")).is_err());
}
