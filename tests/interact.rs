//! Grab and cut, headless: what the curtain's mouse tools do.

use bevy::math::{Affine3A, Vec3};
use bevy_cloth::params::{Environment, Model, XpbdParams};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::ClothSolver;

const DT: f32 = 0.016;

fn curtain() -> ClothSolver {
    curtain_of(Model::MassSpring)
}

fn curtain_of(model: Model) -> ClothSolver {
    let params = ClothParams {
        model,
        ..ClothParams::seeds()
    };
    ClothShape::Grid {
        width: 10,
        height: 8,
        spacing: 0.1,
    }
    .build_solver(&ClothPins::TopRow, &params, Affine3A::IDENTITY)
    .unwrap()
}

#[test]
fn picking_finds_the_particle_under_the_ray() {
    let cloth = curtain();
    // Particle (i=3, j=5) is at (3·0.1 − 0.45, −0.5, 0).
    let target = Vec3::new(-0.15, -0.5, 0.0);
    let origin = Vec3::new(0.0, 0.0, 3.0);
    let (i, along) = cloth
        .nearest_particle_to_ray(origin, target - origin, 0.05)
        .unwrap();
    assert_eq!(i, 5 * 10 + 3);
    assert!((along - (target - origin).length()).abs() < 1e-4);
    // A ray that misses the cloth picks nothing.
    assert!(
        cloth
            .nearest_particle_to_ray(origin, Vec3::new(1.0, 0.0, 0.0), 0.05)
            .is_none()
    );
}

#[test]
fn a_grabbed_particle_follows_the_target_and_pulls_the_cloth() {
    // Mass-spring, and XPBD (its constraints hold the grabbed particle as a pin).
    for model in [Model::MassSpring, Model::Xpbd(XpbdParams::default())] {
        grabbed_particle_follows_and_pulls(model);
    }
}

fn grabbed_particle_follows_and_pulls(model: Model) {
    let mut cloth = curtain_of(model);
    let env = Environment::default();
    for _ in 0..60 {
        cloth.step(DT, &env);
    }
    let corner = 7 * 10 + 9; // bottom right
    assert!(cloth.grab(corner));
    let start = cloth.positions()[corner as usize];
    let target = start + Vec3::new(0.0, 0.0, 0.4);
    let neighbour_before = cloth.positions()[corner as usize - 1];
    for n in 0..60 {
        // Drag smoothly toward the target over half a second, then hold.
        let t = ((n + 1) as f32 / 30.0).min(1.0);
        cloth.drag_grab(start.lerp(target, t));
        cloth.step(DT, &env);
        let expected = start.lerp(target, t);
        assert!(
            cloth.positions()[corner as usize].distance(expected) < 1e-5,
            "step {n}"
        );
    }
    let neighbour_after = cloth.positions()[corner as usize - 1];
    assert!(
        neighbour_after.z - neighbour_before.z > 0.2,
        "the cloth did not follow"
    );
    cloth.release_grab();
    cloth.step(DT, &env);
    assert!(
        cloth.positions()[corner as usize].distance(target) > 1e-5,
        "released, it moves freely"
    );
    assert!(!cloth.particles().is_pinned(corner as usize));
    // Reset undoes it.
    cloth.reset();
    assert!(cloth.grabbed().is_none());
}

#[test]
fn a_cut_tears_exactly_the_springs_it_crosses() {
    let mut cloth = curtain();
    // A stroke seen from z = 3 sweeping horizontally across the cloth at y = −0.35 (between
    // rows 3 and 4), from x = −0.22 to x = 0.22 (between columns 2 and 7 at x = ±0.25).
    let eye = Vec3::new(0.0, -0.35, 3.0);
    let far = |x: f32| eye + (Vec3::new(x, -0.35, 0.0) - eye) * 2.0;
    let torn = cloth.cut(eye, far(-0.22), far(0.22));
    // Expected: every spring with one end above y = −0.35 and one below, whose crossing
    // point lies within |x| < 0.22 — found independently from the rest positions.
    let x0 = cloth.positions().to_vec();
    let s = cloth.springs();
    let mut expected = 0;
    for k in 0..s.len() {
        let (p, q) = (x0[s.a[k] as usize], x0[s.b[k] as usize]);
        if (p.y + 0.35) * (q.y + 0.35) < 0.0 {
            let t = (-0.35 - p.y) / (q.y - p.y);
            let x = p.x + t * (q.x - p.x);
            if x.abs() < 0.22 {
                expected += 1;
                assert!(
                    !s.alive[k],
                    "spring {k} ({p} – {q}) crosses the cut but is whole"
                );
            }
        }
    }
    assert_eq!(torn, expected);
    assert_eq!(cloth.torn_count(), expected);
    assert_eq!(
        s.alive.iter().filter(|a| !**a).count(),
        expected,
        "only those springs tore"
    );
    assert!(cloth.triangle_visible().iter().any(|v| !*v));
    // Reset restores every spring.
    cloth.reset();
    assert_eq!(cloth.torn_count(), 0);
    assert!(cloth.springs().alive.iter().all(|a| *a));
}
