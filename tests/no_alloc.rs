//! The hot step allocates nothing: counted with a wrapping global allocator. (The
//! `unsafe` lives in this test binary only; the library forbids it.)

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use bevy::math::{Affine3A, Vec3};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::Cloth as Solver;

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards every call unchanged to the system allocator.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

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
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    for _ in 0..100 {
        cloth.step(0.016, &env);
        cloth.normals_into(&mut normals);
        std::hint::black_box(cloth.energy(&env));
        std::hint::black_box(cloth.strain());
    }
    let after = ALLOCATIONS.load(Ordering::Relaxed);
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
