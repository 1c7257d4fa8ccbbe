//! Cloth on animated characters: motion constraints (a painted maximum distance from
//! where the body's skinning puts each vertex), a cloth built from a skinned mesh
//! following its bones, mesh vertex indices through the welding.
//! `cargo test --test character`.

use bevy::math::{Affine3A, Quat, Vec3};
use bevy_cloth::params::Environment;
use bevy_cloth::prelude::*;

/// Where a 12 × 12 grid's rest particle `local` is at time `t` on a body that walks
/// (1.5 m/s along x), bobs (3 cm at 2 Hz) and sways (±20° about y at 1 Hz).
fn animated(local: Vec3, t: f32) -> Vec3 {
    let sway = Quat::from_rotation_y(0.35 * (std::f32::consts::TAU * t).sin());
    let bob = Vec3::new(
        1.5 * t,
        1.0 + 0.03 * (2.0 * std::f32::consts::TAU * t).sin(),
        0.0,
    );
    sway * local + bob
}

/// A grid whose top row has distance 0 and whose rows below may swing 2 cm farther each:
/// every frame of the animation the top row is at its target to 1e-5 m, and no particle
/// is farther than its distance (+1e-5 m), though gravity and the motion pull them.
#[test]
fn particles_stay_within_their_distance_of_animated_targets() {
    let (w, h) = (12u32, 12u32);
    let shape = ClothShape::Grid {
        width: w,
        height: h,
        spacing: 0.05,
    };
    let mut cloth = shape
        .build_solver(
            &ClothPins::None,
            &ClothParams::default(),
            Affine3A::IDENTITY,
        )
        .unwrap();
    let rest: Vec<Vec3> = cloth.positions().to_vec();
    let radius: Vec<f32> = (0..w * h).map(|k| 0.02 * (k / w) as f32).collect();
    let env = Environment::default();
    let dt = 1.0 / 60.0;
    let (mut worst_pinned, mut worst_over, mut swing) = (0.0f32, f32::MIN, 0.0f32);
    for frame in 1..=180 {
        let t = frame as f32 * dt;
        let targets: Vec<Vec3> = rest.iter().map(|&x| animated(x, t)).collect();
        cloth.set_motion_constraints(&targets, &radius).unwrap();
        cloth.step(dt, &env);
        assert!(cloth.is_stable());
        for (i, (&x, &target)) in cloth.positions().iter().zip(&targets).enumerate() {
            let off = x.distance(target);
            if radius[i] == 0.0 {
                worst_pinned = worst_pinned.max(off);
            } else {
                worst_over = worst_over.max(off - radius[i]);
                swing = swing.max(off / radius[i]);
            }
        }
    }
    eprintln!("distance 0: {worst_pinned} m off; the rest: {worst_over} m over, {swing} of theirs");
    assert!(
        worst_pinned <= 1e-5,
        "a particle of distance 0 was {worst_pinned} m off"
    );
    assert!(
        worst_over <= 1e-5,
        "a particle went {worst_over} m past its distance"
    );
    assert!(
        swing > 0.5,
        "the free rows swing within their distances: {swing}"
    );
}

/// Motion constraints can be dropped: the particles they attached are let go and fall.
#[test]
fn motion_constraints_cleared_let_the_cloth_go() {
    let shape = ClothShape::Grid {
        width: 4,
        height: 4,
        spacing: 0.05,
    };
    let mut cloth = shape
        .build_solver(
            &ClothPins::None,
            &ClothParams::default(),
            Affine3A::IDENTITY,
        )
        .unwrap();
    let rest = cloth.positions().to_vec();
    cloth.set_motion_constraints(&rest, &[0.0; 16]).unwrap();
    let env = Environment::default();
    for _ in 0..30 {
        cloth.step(1.0 / 60.0, &env);
    }
    assert!(cloth.positions()[15].distance(rest[15]) < 1e-5, "held");
    cloth.clear_motion_constraints();
    for _ in 0..30 {
        cloth.step(1.0 / 60.0, &env);
    }
    assert!(
        cloth.positions()[15].y < rest[15].y - 0.1,
        "falls once let go"
    );
    assert!(cloth.attached().is_empty());
    assert!(
        cloth.set_motion_constraints(&rest, &[0.1; 3]).is_err(),
        "one distance a particle"
    );
    assert!(
        cloth.set_motion_constraints(&rest, &[-1.0; 16]).is_err(),
        "no negative distance"
    );
}
