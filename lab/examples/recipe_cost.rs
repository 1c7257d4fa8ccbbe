//! What each recipe's cloth costs: every `examples/recipe_*.rs` of the crate, run headless
//! as it is (its own `recipe` plugin function, so the numbers are those of the code the
//! recipes page shows), for 5 s of 16 ms fixed steps. After 1 s to settle, the cost of a
//! step (median and p10–p90 of the cloth's own step time, wall clock) with its
//! particles, its substeps and its largest strain, on the pool's threads and on one.
//!
//! `cargo run -p bevy_cloth_lab --example recipe_cost`
use bevy::prelude::*;
use bevy_cloth::headless::headless_base_in;
use bevy_cloth::layout::garment::asset_root;
use bevy_cloth::prelude::*;

#[allow(dead_code)]
#[path = "../../examples/recipe_cape.rs"]
mod cape;
#[allow(dead_code)]
#[path = "../../examples/recipe_flag.rs"]
mod flag;
#[allow(dead_code)]
#[path = "../../examples/recipe_skirt.rs"]
mod skirt;
#[allow(dead_code)]
#[path = "../../examples/recipe_tablecloth.rs"]
mod tablecloth;

/// A recipe: what its example adds to its app.
type Recipe = fn(&mut App);

const SETTLE: usize = 63;
const MEASURED: usize = 250;

/// A recipe's app without a window: the crate's headless base (assets, meshes, skins,
/// one 16 ms step an update) with what `DefaultPlugins` gives a recipe besides
/// (transforms, materials).
fn app(recipe: Recipe) -> App {
    let mut app = headless_base_in(asset_root().to_string_lossy());
    app.add_plugins(TransformPlugin)
        .init_asset::<StandardMaterial>();
    recipe(&mut app);
    app
}

struct Measured {
    particles: usize,
    ms: Vec<f32>,
    substeps: Vec<u32>,
    max_strain: f32,
}

fn measure(recipe: Recipe) -> Measured {
    let mut app = app(recipe);
    let mut m = Measured {
        particles: 0,
        ms: Vec::new(),
        substeps: Vec::new(),
        max_strain: 0.0,
    };
    let mut cloths = app.world_mut().query::<&ClothSimulation>();
    // Built in the first frames (by command, a skinned mesh once its skin is ready).
    for _ in 0..100 {
        app.update();
        if cloths.iter(app.world()).next().is_some() {
            break;
        }
    }
    for step in 0..SETTLE + MEASURED {
        app.update();
        let sims: Vec<_> = cloths.iter(app.world()).collect();
        assert_eq!(sims.len(), 1, "one cloth a recipe");
        let sim = sims[0];
        assert!(sim.solver.is_stable(), "the recipe's cloth went unstable");
        if step >= SETTLE {
            m.particles = sim.solver.particle_count();
            m.ms.push(sim.last_step_ms);
            m.substeps.push(sim.solver.substeps());
            m.max_strain = m.max_strain.max(sim.solver.strain().max);
        }
    }
    m
}

fn quantile(sorted: &[f32], q: f32) -> f32 {
    sorted[((sorted.len() - 1) as f32 * q).round() as usize]
}

fn main() {
    let recipes: [(&str, Recipe); 4] = [
        ("cape (running)", cape::recipe),
        ("flag (3 m/s air)", flag::recipe),
        ("skirt (skinned)", skirt::recipe),
        ("tablecloth", tablecloth::recipe),
    ];
    println!(
        "| recipe | particles | substeps | threads | ms a step, median (p10–p90) | largest strain |"
    );
    println!("|---|---:|---:|---:|---|---:|");
    for (name, recipe) in recipes {
        for one_thread in [false, true] {
            bevy_cloth::solver::set_parallel(!one_thread);
            let mut m = measure(recipe);
            m.ms.sort_by(f32::total_cmp);
            m.substeps.sort_unstable();
            println!(
                "| {name} | {} | {} | {} | {:.2} ({:.2}–{:.2}) | {:.1}% |",
                m.particles,
                m.substeps[m.substeps.len() / 2],
                if one_thread {
                    1
                } else {
                    bevy_cloth::solver::threads()
                },
                quantile(&m.ms, 0.5),
                quantile(&m.ms, 0.1),
                quantile(&m.ms, 0.9),
                100.0 * m.max_strain,
            );
        }
    }
}
