//! Motion constraints: particles kept within a painted distance of animated targets, and
//! back stops that keep a lagging cloth out of a sphere behind its targets.

use super::*;

/// A grid whose top row has distance 0 and whose rows below may swing 2 cm farther each:
/// every frame of the animation the top row is at its target to 1e-5 m, and no particle
/// is farther than its distance (+1e-5 m), though gravity and the motion pull them.
#[test]
fn particles_stay_within_their_distance_of_animated_targets() {
    let (w, h) = (12u32, 12u32);
    let mut cloth = free_grid(w, h);
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
    let mut cloth = free_grid(4, 4);
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

/// Each particle's unit normal at positions `x`: the sum of its triangles' area vectors
/// (counter-clockwise winding), as a renderer's smooth normals.
pub(crate) fn normals_at(triangles: &[[u32; 3]], x: &[Vec3]) -> Vec<Vec3> {
    let mut n = vec![Vec3::ZERO; x.len()];
    for t in triangles {
        let [a, b, c] = t.map(|v| v as usize);
        let area = (x[b] - x[a]).cross(x[c] - x[a]);
        for v in [a, b, c] {
            n[v] += area;
        }
    }
    n.iter().map(|n| n.normalize_or_zero()).collect()
}

/// How deep particle positions `x` are in their back-stop spheres (Jolt's definition:
/// centred `distance + radius` behind each target along its normal), the deepest; ≤ 0
/// when none is inside.
pub(crate) fn deepest_in_back_stops(
    x: &[Vec3],
    targets: &[Vec3],
    normals: &[Vec3],
    stop: BackStop,
) -> f32 {
    x.iter()
        .zip(targets.iter().zip(normals))
        .map(|(&x, (&target, &n))| {
            let centre = target - n * (stop.distance + stop.radius);
            stop.radius - x.distance(centre)
        })
        .fold(f32::MIN, f32::max)
}

/// A back stop keeps a cloth off the body it lags behind: a 12 × 12 grid held by its top
/// row, its targets (the body) swinging ±0.3 m at 1 Hz along the grid's own normal, so
/// the free rows trail behind the body each half swing. Back stops 1 cm behind the
/// targets, radius 0.5 m: no particle is ever inside its sphere (1e-5 m). Without them
/// the same motion puts the cloth more than 2 cm into the spheres, and with them it
/// still moves freely in front of its targets (more than 2 cm out).
#[test]
fn a_back_stop_keeps_a_lagging_cloth_out_of_its_sphere() {
    let (w, h) = (12u32, 12u32);
    let stop = BackStop {
        distance: 0.01,
        radius: 0.5,
    };
    let run = |stopped: bool| -> (f32, f32) {
        let mut cloth = free_grid(w, h);
        let rest: Vec<Vec3> = cloth.positions().to_vec();
        let normals = normals_at(cloth.triangles(), &rest);
        let n = normals[(w * h / 2) as usize];
        let radius: Vec<f32> = (0..w * h)
            .map(|k| if k < w { 0.0 } else { f32::INFINITY })
            .collect();
        if stopped {
            cloth.set_back_stops(&vec![stop; (w * h) as usize]).unwrap();
        }
        let env = Environment::default();
        let dt = 1.0 / 60.0;
        let (mut deepest, mut ahead) = (f32::MIN, 0.0f32);
        for frame in 1..=180 {
            let swing = 0.3 * (std::f32::consts::TAU * frame as f32 * dt).sin();
            let targets: Vec<Vec3> = rest.iter().map(|&x| x + n * swing).collect();
            cloth.set_motion_constraints(&targets, &radius).unwrap();
            cloth.step(dt, &env);
            let x = cloth.positions();
            deepest = deepest.max(deepest_in_back_stops(x, &targets, &normals, stop));
            for (&x, &target) in x.iter().zip(&targets) {
                ahead = ahead.max((x - target).dot(n));
            }
        }
        (deepest, ahead)
    };
    let (deepest, ahead) = run(true);
    let (free, _) = run(false);
    eprintln!(
        "deepest into a back stop: {deepest} m (without back stops {free} m); in front: {ahead} m"
    );
    assert!(
        deepest <= 1e-5,
        "a particle went {deepest} m into its back stop"
    );
    assert!(
        free > 0.02,
        "without back stops the cloth lags into them: {free} m"
    );
    assert!(
        ahead > 0.02,
        "in front of the body the cloth is free: {ahead} m"
    );
    let mut cloth = free_grid(4, 4);
    assert!(cloth.set_back_stops(&[stop; 3]).is_err(), "one a particle");
    let bad = BackStop {
        distance: f32::NAN,
        radius: 0.1,
    };
    assert!(cloth.set_back_stops(&[bad; 16]).is_err(), "no NaN distance");
}

/// Distances painted anew: a 6 × 6 grid lying flat with a layout pin at a corner of its
/// first row (particle 5), held by its first row (distance 0), then by its last row
/// with the first row given 5 cm, then by both rows. Each time exactly the particles of
/// distance 0 are attached, each at its own moving target; the far corner let go falls
/// within its 5 cm; the layout's pin, held to a target while its distance is 0, goes
/// back to its pinned place when it is not.
#[test]
fn distances_painted_anew_attach_and_let_go_the_right_particles() {
    let shape = ClothShape::Grid {
        width: 6,
        height: 6,
        spacing: 0.05,
    };
    let mut cloth = shape
        .build_solver(
            &ClothPins::Indices(vec![5]),
            &ClothParams::seeds(),
            // Lying flat, so that a particle let go falls.
            Affine3A::from_rotation_x(-std::f32::consts::FRAC_PI_2),
        )
        .unwrap();
    let rest = cloth.positions().to_vec();
    let env = Environment::default();
    let first: Vec<u32> = (0..6).collect();
    let last: Vec<u32> = (30..36).collect();
    let both: Vec<u32> = first.iter().chain(&last).copied().collect();
    let paint = |zero: &[u32], other: f32| -> Vec<f32> {
        (0..36u32)
            .map(|i| if zero.contains(&i) { 0.0 } else { other })
            .collect()
    };
    for (held, distances) in [
        (&first, paint(&first, f32::INFINITY)),
        (&last, paint(&last, 0.05)),
        (&both, paint(&both, f32::INFINITY)),
    ] {
        let mut targets = rest.clone();
        for frame in 0..40 {
            let shift = Vec3::new(0.005 * frame as f32, 0.0, 0.0);
            targets = rest.iter().map(|&x| x + shift).collect();
            cloth.set_motion_constraints(&targets, &distances).unwrap();
            cloth.step(1.0 / 60.0, &env);
            let x = cloth.positions();
            for &i in held {
                let off = x[i as usize].distance(targets[i as usize]);
                assert!(off < 1e-5, "particle {i} is {off} m off its target");
            }
        }
        // Attached: those of distance 0 but the layout's pin (a pin already).
        let mut attached = cloth.attached().to_vec();
        attached.sort();
        let expected: Vec<u32> = held.iter().copied().filter(|&i| i != 5).collect();
        assert_eq!(
            attached, expected,
            "exactly the particles of distance 0 are attached"
        );
        let x = cloth.positions();
        if !held.contains(&0) {
            let fell = rest[0].y - x[0].y;
            let off = x[0].distance(targets[0]);
            eprintln!("the far corner let go fell {fell} m, {off} m from its target");
            assert!(fell > 0.01, "the far corner, let go, falls: {fell} m");
            assert!(off <= 0.05 + 1e-5, "within its distance: {off} m");
        }
        if !held.contains(&5) {
            let off = x[5].distance(rest[5]);
            assert!(
                off < 1e-5,
                "the layout's pin is back at its place: {off} m off"
            );
        }
    }
}
