//! The hot step allocates nothing: counted with a wrapping global allocator, per thread
//! and over every thread (the compute pool's too). (The `unsafe` lives in this test binary
//! only; the library forbids it.)

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use bevy::math::{Affine3A, Quat, Vec3};
use bevy_cloth::params::{
    Environment, Inertia, Model, PatchParams, SelfCollision, SpringParams, Wind, WindField,
    WindZone, ZoneShape,
};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::shapes::Capsule;
use bevy_cloth::solver::{BackStop, ClothSolver, Collider, ColliderShape, Motion, ProxyBinding};

struct Counting;

thread_local! {
    /// Allocations made by this thread (tests run in parallel threads; each counts its own).
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

/// Allocations made by every thread of the process.
static ALL_ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

/// Held by each test while it counts: the count over every thread is then this test's
/// (the others wait), bar the harness's own bookkeeping.
static COUNTING: Mutex<()> = Mutex::new(());

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

// SAFETY: forwards every call unchanged to the system allocator.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        ALL_ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        ALL_ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// A 16×16 cloth of 5 cm, pinned at its top corners.
fn grid_cloth(params: &ClothParams) -> ClothSolver {
    let shape = ClothShape::Grid {
        width: 16,
        height: 16,
        spacing: 0.05,
    };
    shape
        .build_solver(&ClothPins::TopCorners, params, Affine3A::IDENTITY)
        .unwrap()
}

/// Allocations this thread makes while running `f`.
fn allocations_during(f: impl FnOnce()) -> usize {
    let before = allocations();
    f();
    allocations() - before
}

#[test]
fn the_counter_sees_this_threads_allocations() {
    let _alone = COUNTING.lock().unwrap_or_else(|e| e.into_inner());
    let counted = allocations_during(|| {
        std::hint::black_box(Vec::<u64>::with_capacity(16));
    });
    assert!(counted > 0, "the counting allocator counted nothing");
}

#[test]
fn steps_allocate_nothing() {
    let _alone = COUNTING.lock().unwrap_or_else(|e| e.into_inner());
    let params = ClothParams {
        tear_ratio: Some(1.05),
        springs: SpringParams {
            damping: 0.001,
            ..SpringParams::default()
        },
        ..ClothParams::seeds()
    };
    let mut cloth = grid_cloth(&params);
    let env = Environment {
        wind: Wind {
            direction: Vec3::Z,
            strength: 0.01,
            field: WindField::Trigonometric,
        },
        ..Environment::default()
    };
    let mut normals = vec![Vec3::ZERO; cloth.particle_count()];
    cloth.step(0.016, &env); // warm-up: automatic substeps are computed and cached
    let allocated = allocations_during(|| {
        for _ in 0..100 {
            cloth.step(0.016, &env);
            cloth.normals_into(&mut normals);
            std::hint::black_box(cloth.energy(&env));
            std::hint::black_box(cloth.strain());
        }
    });
    assert!(cloth.substeps() > 1);
    assert!(
        cloth.torn_count() > 0,
        "tearing is part of the step under test"
    );
    assert_eq!(allocated, 0, "{allocated} allocations in 100 steps");
}

#[test]
fn patch_steps_allocate_nothing_even_with_a_state_dependent_pull() {
    let _alone = COUNTING.lock().unwrap_or_else(|e| e.into_inner());
    let model = Model::Patches(PatchParams {
        exponent: 2.0,
        ..PatchParams::default()
    });
    let mut cloth = grid_cloth(&ClothParams {
        model,
        ..ClothParams::seeds()
    });
    let env = Environment::default();
    cloth.step(0.016, &env); // warm-up: the patch lattice is built on the first step
    let allocated = allocations_during(|| {
        for _ in 0..50 {
            cloth.step(0.016, &env);
        }
    });
    assert!(cloth.patches().is_some());
    assert_eq!(allocated, 0, "{allocated} allocations in 50 patch steps");
}

/// Self-collision's listing (the grid, the rest neighbours' marks, the pieces' pair
/// lists) keeps its storage: a cloth swinging down from level relists every step and,
/// once its scratch has grown over the first second, allocates nothing.
#[test]
fn self_collision_steps_allocate_nothing() {
    let _alone = COUNTING.lock().unwrap_or_else(|e| e.into_inner());
    let params = ClothParams {
        self_collision: SelfCollision::on(),
        ..ClothParams::seeds()
    };
    let shape = ClothShape::Grid {
        width: 16,
        height: 16,
        spacing: 0.05,
    };
    let level = Affine3A::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let mut cloth = shape
        .build_solver(&ClothPins::TopRow, &params, level)
        .unwrap();
    let env = Environment::default();
    for _ in 0..60 {
        cloth.step(0.016, &env);
    }
    let listed = cloth.self_collision_listings();
    let allocated = allocations_during(|| {
        for _ in 0..60 {
            cloth.step(0.016, &env);
        }
    });
    let relisted = cloth.self_collision_listings() - listed;
    assert!(cloth.self_collision_distance() > 0.0);
    assert!(
        relisted > 10,
        "the cloth relists its pairs: {relisted} of 60 steps"
    );
    assert_eq!(
        allocated, 0,
        "{allocated} allocations in 60 self-collision steps"
    );
}

/// A cloth above the parallel threshold (128 × 128 = 16,384 particles) steps on the
/// compute pool: its kernels allocate nothing on the pool's threads. The calling thread's
/// allocations are the pool's scope's (Bevy's `TaskPool::scope` boxes each piece it hands
/// the executor: about 850 a step here, printed), not the kernels'.
#[test]
fn a_large_cloth_on_the_pool_allocates_nothing_on_its_threads() {
    let _alone = COUNTING.lock().unwrap_or_else(|e| e.into_inner());
    let params = ClothParams {
        substeps: bevy_cloth::params::Substeps::Fixed(4),
        ..ClothParams::seeds()
    };
    let shape = ClothShape::Grid {
        width: 128,
        height: 128,
        spacing: 0.02,
    };
    let mut cloth = shape
        .build_solver(&ClothPins::TopRow, &params, Affine3A::IDENTITY)
        .unwrap();
    let env = Environment::default();
    assert!(
        bevy_cloth::solver::threads() > 1
            || std::thread::available_parallelism().map_or(1, usize::from) == 1
    );
    for _ in 0..3 {
        cloth.step(0.016, &env);
    }
    let (all_before, own_before) = (ALL_ALLOCATIONS.load(Ordering::SeqCst), allocations());
    let steps = 10;
    for _ in 0..steps {
        cloth.step(0.016, &env);
    }
    let own = allocations() - own_before;
    let others = ALL_ALLOCATIONS.load(Ordering::SeqCst) - all_before - own;
    println!(
        "{steps} steps of 16,384 particles: {own} allocations on the calling thread, {others} on the others"
    );
    assert_eq!(
        others, 0,
        "the pool's threads allocated {others} times in {steps} steps"
    );
}

/// What a game runs: the default cloth (XPBD along lines in twill, meeting the air on its
/// triangles) in gusty air and a wind zone, against a capsule that moves every step,
/// its colliders and zones handed over every step as the plugin hands them over.
#[test]
fn a_games_cloth_in_air_zones_and_contact_allocates_nothing_a_step() {
    let _alone = COUNTING.lock().unwrap_or_else(|e| e.into_inner());
    let mut cloth = grid_cloth(&ClothParams::default());
    let env = Environment {
        air: Some(Air {
            velocity: Vec3::new(2.0, 0.0, 1.0),
            field: WindField::Trigonometric,
            ..Air::default()
        }),
        ..Environment::default()
    };
    let zones = [WindZone {
        shape: ZoneShape::Sphere { radius: 2.0 },
        velocity: Vec3::Z * 4.0,
        ..WindZone::default()
    }];
    // A capsule across the cloth's middle, 2 cm in front of it, swaying into it.
    let capsule = |t: f32| {
        let at = Vec3::new(0.0, -0.4, 0.02 - 0.1 * t.sin());
        Collider {
            shape: ColliderShape::from(Capsule {
                a: at - Vec3::X * 0.5,
                b: at + Vec3::X * 0.5,
                radius: 0.05,
            }),
            thickness: 0.01,
            friction: 0.3,
            motion: Motion::NONE,
        }
    };
    let dt = 0.016;
    let step = |cloth: &mut ClothSolver, k: usize| {
        let t = k as f32 * dt;
        cloth.set_colliders([capsule(t)]);
        cloth.set_wind_zones(&zones, t).unwrap();
        cloth.step(dt, &env);
    };
    for k in 0..3 {
        step(&mut cloth, k); // warm-up: the substeps and the contact sets sized
    }
    let allocated = allocations_during(|| {
        for k in 3..63 {
            step(&mut cloth, k);
        }
    });
    assert!(cloth.is_stable());
    assert!(!cloth.wind_zones().is_empty(), "the zone reaches the cloth");
    assert_eq!(allocated, 0, "{allocated} allocations in 60 steps");
}

/// What a character's cape runs: the default cloth held by motion constraints to a
/// walking, turning body (a skinned cloth: the top row at its target, each row below 2 cm
/// freer), back stops behind its targets, half the body's inertia, and a proxy mesh (each
/// triangle's corners and middle) placed on it after each step, as the plugin draws it.
#[test]
fn a_skinned_cape_with_back_stops_inertia_and_a_proxy_allocates_nothing_a_step() {
    let _alone = COUNTING.lock().unwrap_or_else(|e| e.into_inner());
    let params = ClothParams {
        inertia: Inertia::scaled(0.5),
        ..ClothParams::default()
    };
    let mut cloth = grid_cloth(&params);
    let rest = cloth.positions().to_vec();
    let n = rest.len();
    let radius: Vec<f32> = (0..n).map(|k| 0.02 * (k / 16) as f32).collect();
    let stop = BackStop {
        distance: 0.01,
        radius: 0.3,
    };
    cloth.set_back_stops(&vec![stop; n]).unwrap();
    let render: Vec<Vec3> = cloth
        .triangles()
        .iter()
        .flat_map(|t| {
            let [a, b, c] = t.map(|i| rest[i as usize]);
            [a, b, c, (a + b + c) / 3.0]
        })
        .collect();
    let mut binding = ProxyBinding::bind(&rest, cloth.triangles(), &render, None).unwrap();
    let (mut drawn, mut drawn_normals) =
        (vec![[0.0; 3]; render.len()], vec![[0.0; 3]; render.len()]);
    let mut normals = vec![Vec3::ZERO; n];
    let mut targets = vec![Vec3::ZERO; n];
    let env = Environment::default();
    let dt = 0.016;
    let mut step = |cloth: &mut ClothSolver, k: usize| {
        let t = k as f32 * dt;
        let body = Affine3A::from_rotation_translation(
            Quat::from_rotation_y(0.6 * (6.0 * t).sin()),
            Vec3::new(0.0, 0.05 * (12.0 * t).sin(), 1.2 * t),
        );
        for (target, &x) in targets.iter_mut().zip(&rest) {
            *target = body.transform_point3(x);
        }
        cloth.set_frame(body);
        cloth.set_motion_constraints(&targets, &radius).unwrap();
        cloth.step(dt, &env);
        cloth.normals_into(&mut normals);
        binding.place(
            cloth.positions(),
            &normals,
            &mut drawn,
            &mut drawn_normals,
            None,
        );
    };
    for k in 0..3 {
        step(&mut cloth, k); // warm-up: the substeps and the scratch sized
    }
    let allocated = allocations_during(|| {
        for k in 3..63 {
            step(&mut cloth, k);
        }
    });
    assert!(cloth.is_stable());
    assert_eq!(allocated, 0, "{allocated} allocations in 60 steps");
}

/// The plugin's step in a headless app, on one thread (the multi-threaded executor
/// allocates a task for each system it runs, and more of them run with a cloth, their
/// run conditions met; so does the compute pool's scope for each share of several
/// cloths): Bevy's own scheduling, counted apart in the same app without a cloth,
/// allocates nothing an update. The cloth stage makes a few small lists a step of the
/// cloths that step (Bevy's borrows of the cloths live for one system's run, so such a
/// list cannot be kept from one step to the next): five with one cloth, whatever its
/// size, and six with several (one more in sharing their substeps); nothing per particle
/// or substep.
#[test]
fn the_plugins_step_allocates_a_few_lists_a_step_whatever_its_cloths_size() {
    let _alone = COUNTING.lock().unwrap_or_else(|e| e.into_inner());
    let over_60_updates = |cloths: &[u32]| -> usize {
        let mut app = bevy_cloth::headless::headless_app();
        app.finish();
        app.cleanup();
        for (_, schedule) in app
            .world_mut()
            .resource_mut::<bevy::ecs::schedule::Schedules>()
            .iter_mut()
        {
            schedule.set_executor(bevy::ecs::schedule::SingleThreadedExecutor::new());
        }
        for (k, &size) in cloths.iter().enumerate() {
            app.world_mut().spawn((
                Cloth::grid(size, size, 0.05),
                bevy::prelude::Transform::from_xyz(3.0 * k as f32, 3.0, 0.0),
            ));
        }
        for _ in 0..30 {
            app.update(); // built, drawn, the substeps settled
        }
        // Everything runs on this thread: its own count (other tests' threads starting
        // while this one counts are not its).
        allocations_during(|| {
            bevy_cloth::solver::on_one_thread(|| {
                for _ in 0..60 {
                    app.update();
                }
            });
        })
    };
    let bevy = over_60_updates(&[]);
    let small = over_60_updates(&[16]);
    let large = over_60_updates(&[48]);
    let three = over_60_updates(&[32, 32, 32]);
    eprintln!(
        "60 updates: Bevy's own {bevy} allocations; with one cloth of 16 x 16 {small}, of \
         48 x 48 {large}; with three of 32 x 32 {three}"
    );
    assert_eq!(bevy, 0, "Bevy's own scheduling allocated");
    assert_eq!(small, 5 * 60, "one small cloth");
    assert_eq!(large, 5 * 60, "one large cloth");
    assert_eq!(three, 6 * 60, "three cloths");
}
