//! Self-collision: a cloth dropped onto a ball folds onto itself on the ground without
//! passing through itself, and three cloths dropped on each other stay in layers (no two particles that are not rest neighbours closer than
//! half the distance kept, no edge through a triangle, checked exactly here, not by the
//! solver), and the same scene without it does cross; one thread and two give the same
//! bits. `cargo test --test self_collision`.

use bevy::math::{Vec3, Vec3A};
use bevy_cloth::headless::SceneRun;
use bevy_cloth::params::{Model, Substeps};
use bevy_cloth::scene::ClothScene;
use bevy_cloth::solver::ClothSolver;

mod common;
use common::{edges_through_triangles, segment_hits_triangle};

/// Seconds each scene runs: it has settled by then.
const SECONDS: f32 = 5.0;
/// Frames checked: every this many steps.
const EVERY: usize = 8;

/// A scene of `assets/scenes/` with self-collision on or off, as XPBD (the file's) or
/// mass-spring.
fn scene(name: &str, self_collision: bool, model: &str) -> ClothScene {
    let path = format!("assets/scenes/{name}.ron");
    let mut scene = ClothScene::load(&path).expect("the scene loads");
    for entry in &mut scene.cloths {
        let params = &mut entry.cloth.params;
        params.self_collision.enabled = self_collision;
        if model == "mass-spring" {
            params.model = Model::MassSpring;
            params.springs.structural.stiffness = 400.0;
            params.strain_limit = Some(0.1);
            params.substeps = Substeps::Auto { max: 512 };
        }
    }
    scene
}

/// What a run did, over the frames checked.
#[derive(Debug, Default)]
struct Crossings {
    /// The closest two particles that are not rest neighbours came, m.
    closest: f32,
    /// Frames with an edge through a triangle, and the most such edges in one.
    frames: usize,
    most: usize,
    /// The distance the solver kept.
    d: f32,
    checked: usize,
}

fn run(scene: &ClothScene) -> Crossings {
    let mut run = SceneRun::new(scene).expect("the scene builds");
    let steps = (SECONDS / run.timestep).round() as usize;
    let mut seen = Crossings {
        closest: f32::INFINITY,
        ..Default::default()
    };
    run.run(steps, |step, cloths| {
        if step % EVERY != 0 {
            return;
        }
        let cloths: Vec<&ClothSolver> = cloths.iter().map(|(_, c)| c).collect();
        for cloth in &cloths {
            assert!(cloth.is_stable(), "the cloth stays finite");
            seen.d = seen.d.max(cloth.self_collision_distance());
        }
        seen.closest = seen.closest.min(closest_non_neighbours(&cloths));
        let crossing = edges_through_triangles(&cloths);
        if crossing > 0 {
            seen.frames += 1;
            seen.most = seen.most.max(crossing);
        }
        seen.checked += 1;
    });
    seen
}

/// The closest two particles come that are not rest neighbours: of different cloths,
/// or of one grid cloth more than two rows or columns apart (within two along the grid
/// is the springs' reach).
fn closest_non_neighbours(cloths: &[&ClothSolver]) -> f32 {
    let mut closest = f32::INFINITY;
    for (a, ca) in cloths.iter().enumerate() {
        let (w, _) = ca.grid_size().expect("a grid");
        let x = ca.positions();
        for i in 0..x.len() {
            let (ci, ri) = (i as i64 % w as i64, i as i64 / w as i64);
            for (j, xj) in x.iter().enumerate().skip(i + 1) {
                let (cj, rj) = (j as i64 % w as i64, j as i64 / w as i64);
                if (ci - cj).abs() <= 2 && (ri - rj).abs() <= 2 {
                    continue;
                }
                closest = closest.min(x[i].distance(*xj));
            }
            for cb in &cloths[a + 1..] {
                for xj in cb.positions() {
                    closest = closest.min(x[i].distance(*xj));
                }
            }
        }
    }
    closest
}

#[test]
fn the_exact_crossing_test_finds_an_edge_through_a_triangle_and_no_other() {
    let (a, b, c) = (Vec3A::ZERO, Vec3A::X, Vec3A::Y);
    let through = |p: Vec3, q: Vec3| segment_hits_triangle(p.into(), q.into(), a, b, c);
    assert!(through(Vec3::new(0.2, 0.2, -1.0), Vec3::new(0.2, 0.2, 1.0)));
    assert!(!through(Vec3::new(0.2, 0.2, 0.1), Vec3::new(0.2, 0.2, 1.0)));
    assert!(!through(
        Vec3::new(0.8, 0.8, -1.0),
        Vec3::new(0.8, 0.8, 1.0)
    ));
    assert!(!through(
        Vec3::new(0.2, 0.2, -1.0),
        Vec3::new(0.2, 0.2, -0.5)
    ));
}

#[test]
fn a_cloth_folding_onto_itself_does_not_pass_through_itself() {
    stays_apart("fold");
}

#[test]
fn three_cloths_dropped_on_each_other_stay_in_layers() {
    stays_apart("stack");
}

/// Scene `name`, XPBD and mass-spring: with self-collision no edge through a triangle
/// and no two particles closer than `d/2`; without it, both (the detector sees them).
fn stays_apart(name: &str) {
    for model in ["xpbd", "mass-spring"] {
        let with = run(&scene(name, true, model));
        eprintln!("{name}, {model}, self-collision on: {with:?}");
        assert!(with.d > 0.0, "{name}, {model}: self-collision acts");
        assert_eq!(
            with.frames, 0,
            "{name}, {model}: an edge through a triangle: {with:?}"
        );
        assert!(
            with.closest >= 0.5 * with.d,
            "{name}, {model}: two particles closer than d/2 = {}: {with:?}",
            0.5 * with.d
        );
        let without = run(&scene(name, false, model));
        eprintln!("{name}, {model}, self-collision off: {without:?}");
        assert!(
            without.frames > 0 && without.closest < 0.5 * with.d,
            "{name}, {model}: without self-collision it should pass through: {without:?}"
        );
    }
}

#[test]
fn self_collision_is_refused_for_the_models_without_it() {
    let mut scene = scene("fold", true, "xpbd");
    let params = &mut scene.cloths[0].cloth.params;
    params.model = Model::ShapeMatching(Default::default());
    params.springs.structural.stiffness = 400.0;
    let err = SceneRun::new(&scene).err().expect("refused");
    assert!(err.to_string().contains("self-collision"), "{err}");
}

/// A 256 × 256 cloth folded over onto itself (the upper half laid 0.9 of the distance
/// kept above the lower, so every pair of layers is in contact from the first substep):
/// the same bits on one thread and on the pool.
#[test]
fn the_same_bits_on_one_thread_and_on_both_cores() {
    let folded = || {
        let mut scene = scene("fold", true, "xpbd");
        let cloth = &mut scene.cloths[0].cloth;
        cloth.shape = bevy_cloth::ClothShape::Grid {
            width: 256,
            height: 256,
            spacing: 0.004,
        };
        let mut run = SceneRun::new(&scene).expect("builds");
        let solver = &mut run.cloths[0].1;
        solver.step(run.timestep, &run.environment);
        let d = solver.self_collision_distance();
        assert!(d > 0.0);
        let p = solver.particles_mut();
        let half = 128 * 256;
        for i in half..2 * half {
            let mirror = (2 * half - 1 - i) / 256 * 256 + i % 256;
            p.position[i] = p.position[mirror] + Vec3::Y * (0.9 * d);
            p.previous[i] = p.position[i];
            p.velocity[i] = Vec3::ZERO;
        }
        run
    };
    let mut positions = Vec::new();
    for parallel in [false, true] {
        let mut run = folded();
        let mut pushes = 0;
        let mut steps = || {
            run.run(10, |step, cloths| {
                if step == 1 {
                    pushes = cloths[0].1.self_collision_pushes();
                }
            })
        };
        if parallel {
            steps();
        } else {
            bevy_cloth::solver::on_one_thread(steps);
        }
        assert!(pushes > 10_000, "the layers touch: {pushes} pushes");
        let solver = &run.cloths[0].1;
        positions.push(solver.positions().to_vec());
    }
    assert!(
        positions[0] == positions[1],
        "one thread and the pool differ"
    );
}

/// The T-shirt sewn on the mannequin (1.5 s), then the mannequin taken away: the shirt
/// falls to the ground and its front and back fold onto each other. With self-collision
/// no edge passes through a triangle; without, they do.
#[test]
fn a_sewn_t_shirt_dropped_off_its_mannequin_keeps_front_and_back_apart() {
    let run_shirt = |on: bool| {
        let mut scene = ClothScene::load("assets/scenes/tshirt.ron").expect("loads");
        scene.environment.wind.strength = 0.0;
        scene.cloths[0].cloth.params.self_collision.enabled = on;
        let mut run = SceneRun::new(&scene).expect("builds");
        run.run(94, |_, _| {});
        let ground: Vec<_> = scene
            .colliders
            .iter()
            .filter(|c| c.name == "ground")
            .map(|c| {
                let t = bevy::transform::components::GlobalTransform::from(c.transform());
                c.collider.to_world(&t)
            })
            .collect();
        run.cloths[0].1.set_colliders(ground);
        let mut frames = 0;
        let mut most = 0;
        run.run(188, |step, cloths| {
            if step % EVERY == 0 {
                let crossing = edges_through_triangles(&[&cloths[0].1]);
                frames += (crossing > 0) as usize;
                most = most.max(crossing);
            }
        });
        (frames, most)
    };
    let with = run_shirt(true);
    let without = run_shirt(false);
    eprintln!("T-shirt dropped: with self-collision {with:?}, without {without:?}");
    assert_eq!(with.0, 0, "no edge through a triangle: {with:?}");
    assert!(
        without.0 > 0,
        "without it the shirt passes through itself: {without:?}"
    );
}

/// The three cloths of the stack come to rest on one another: over the half second after
/// 8 s, the fastest particle of a typical step (the median over the steps) moves under
/// 2 cm/s, and of any step under 20 cm/s. (Each cloth keeping apart from where the others
/// were when the step began, not where they are in each substep, they jittered by up to
/// 1 m/s for as long as they lay there; solved along lines at each cloth's own substep
/// count, at 0.28 m/s.) A resting stack still has a rare one-step pop, and when it comes
/// is chaos: gravity changed in its seventh digit moves the worst step of a run between
/// 0.6 cm/s and 40 cm/s, and the typical step between 0.2 and 4 cm/s. So it is run five times
/// so changed and the median run is held to the bounds: one run says which bits the
/// build rounds to, not whether the stack rests.
#[test]
fn a_stack_of_cloths_comes_to_rest() {
    let runs = 5;
    let (mut typical, mut worst) = (Vec::new(), Vec::new());
    for k in 0..runs {
        let mut scene = scene("stack", true, "xpbd");
        scene.environment.gravity *= 1.0 + 1e-6 * k as f32;
        let (t, w) = stack_at_rest(&scene);
        typical.push(t);
        worst.push(w);
    }
    eprintln!(
        "fastest particle over the last half second, in {runs} runs: {typical:?} m/s \
         typically, {worst:?} at worst"
    );
    let median = |v: &mut Vec<f32>| {
        v.sort_by(f32::total_cmp);
        v[v.len() / 2]
    };
    let (typical, worst) = (median(&mut typical), median(&mut worst));
    assert!(
        typical < 0.02,
        "the stack still moves: {typical} m/s in a typical step of the median run"
    );
    assert!(
        worst < 0.2,
        "the stack jitters: {worst} m/s in the median run"
    );
}

/// The fastest particle over the half second after 8 s of `scene`: in a typical step
/// (the median over the steps) and in the fastest, m/s.
fn stack_at_rest(scene: &ClothScene) -> (f32, f32) {
    let mut run = SceneRun::new(scene).expect("builds");
    let dt = run.timestep;
    run.run((8.0 / dt).round() as usize, |_, _| {});
    let mut before: Vec<Vec<Vec3>> = run
        .cloths
        .iter()
        .map(|(_, c)| c.positions().to_vec())
        .collect();
    let mut fastest = Vec::new();
    run.run((0.5 / dt).round() as usize, |_, cloths| {
        let mut step = 0.0f32;
        for ((_, c), was) in cloths.iter().zip(&mut before) {
            for (x, w) in c.positions().iter().zip(was.iter_mut()) {
                step = step.max(x.distance(*w) / dt);
                *w = *x;
            }
        }
        fastest.push(step);
    });
    fastest.sort_by(f32::total_cmp);
    (fastest[fastest.len() / 2], fastest[fastest.len() - 1])
}

/// A self-collision distance below 0.1 mm is refused at the door, naming its field (1e-30
/// m was accepted and overflowed the contact grid's cell count in the first step).
#[test]
fn a_vanishing_self_collision_distance_is_refused() {
    let mut scene = scene("fold", true, "xpbd");
    for d in [1e-30, 1e-9, 5e-5] {
        scene.cloths[0].cloth.params.self_collision.distance = Some(d);
        let error = SceneRun::new(&scene).err().expect("refused").to_string();
        assert!(error.contains("self_collision.distance"), "{error}");
    }
    scene.cloths[0].cloth.params.self_collision.distance = Some(1e-3);
    let mut run = SceneRun::new(&scene).expect("1 mm is a distance");
    run.run(3, |_, _| {});
}

#[allow(dead_code)]
#[path = "../examples/doorway.rs"]
mod doorway;

#[test]
fn the_doorways_strips_stay_whole_in_a_gale_with_self_collision() {
    // The doorway example headless (six denim strips 2 cm apart, 10 m/s gusts through the
    // door, self-collision on, accuracy first) for its first 3 s, when the strips first
    // fold against each other. With the fabric's hinges projected once for several
    // substeps under self-collision, a strip passed 50% at 2.0 s (75.5%); projected
    // every substep, the strips stayed below 25% for 20 s. Self-contact pushes the
    // folds apart after the constraints: with the strain limit solved along the lines
    // once more after it, at the step's end, the strips stay at their 10% limit (19.9%
    // without).
    use bevy_cloth::prelude::*;
    let setup = doorway::Doorway {
        wind: 10.0,
        self_collision: true,
        gap: 0.02,
    };
    let mut app = doorway::headless(setup, ClothBudget::UNLIMITED);
    let mut sims = app.world_mut().query::<&ClothSimulation>();
    let (mut worst, mut strips) = (0.0f32, 0);
    for _ in 0..190 {
        app.update();
        strips = 0;
        for sim in sims.iter(app.world()) {
            strips += 1;
            worst = worst.max(sim.solver.strain().max);
        }
    }
    eprintln!("the strips' largest strain in 3 s: {:.1}%", worst * 100.0);
    assert_eq!(strips, doorway::STRIPS);
    assert!(worst < 0.105, "a strip stretched {:.1}%", worst * 100.0);
}
