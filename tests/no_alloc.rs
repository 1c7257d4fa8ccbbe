//! The hot step allocates nothing: counted with a wrapping global allocator. (The
//! `unsafe` lives in this test binary only; the library forbids it.)

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use bevy::math::{Affine3A, Vec3};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::Cloth as Solver;

struct Counting;

thread_local! {
    /// Allocations made by this thread (tests run in parallel threads; each counts its own).
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

// SAFETY: forwards every call unchanged to the system allocator.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn the_counter_sees_this_threads_allocations() {
    let before = allocations();
    let v: Vec<u64> = std::hint::black_box(Vec::with_capacity(16));
    assert!(
        allocations() > before,
        "the counting allocator counted nothing"
    );
    drop(v);
}

#[test]
fn steps_allocate_nothing() {
    let params = ClothParams {
        tear_ratio: Some(1.05),
        springs: SpringParams {
            damping: 0.001,
            ..SpringParams::default()
        },
        ..ClothParams::default()
    };
    let mut cloth = Solver::new(
        &ClothShape::Grid {
            width: 16,
            height: 16,
            spacing: 0.05,
        },
        &Pins::TopCorners,
        &params,
        Affine3A::IDENTITY,
    )
    .unwrap();
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
    let before = allocations();
    for _ in 0..100 {
        cloth.step(0.016, &env);
        cloth.normals_into(&mut normals);
        std::hint::black_box(cloth.energy(&env));
        std::hint::black_box(cloth.strain());
    }
    let after = allocations();
    assert!(cloth.substeps() > 1);
    assert!(
        cloth.torn_count() > 0,
        "tearing is part of the step under test"
    );
    assert_eq!(
        after - before,
        0,
        "{} allocations in 100 steps",
        after - before
    );
}

#[test]
fn patch_steps_allocate_nothing_even_with_a_state_dependent_pull() {
    let model = Model::Patches(PatchParams {
        exponent: 2.0,
        ..PatchParams::default()
    });
    let mut cloth = Solver::new(
        &ClothShape::Grid {
            width: 16,
            height: 16,
            spacing: 0.05,
        },
        &Pins::TopCorners,
        &ClothParams {
            model,
            ..ClothParams::default()
        },
        Affine3A::IDENTITY,
    )
    .unwrap();
    let env = Environment::default();
    cloth.step(0.016, &env); // warm-up: the patch lattice is built on the first step
    let before = allocations();
    for _ in 0..50 {
        cloth.step(0.016, &env);
    }
    let after = allocations();
    assert!(cloth.patches().is_some());
    assert_eq!(
        after - before,
        0,
        "{} allocations in 50 patch steps",
        after - before
    );
}
