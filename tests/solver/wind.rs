//! Wind zones: a banner inside a sphere zone moves, one outside does not, and the zone's
//! gusts and turbulence give the same bits on one thread and on the pool.

use bevy::math::{Affine3A, Vec3};
use bevy_cloth::params::{Environment, Turbulence, WindZone, ZoneShape};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::ClothSolver;

/// A 16 × 12 banner 5 cm apart hung from its top row, its top-left corner at `at`.
fn banner(at: Vec3) -> ClothSolver {
    let shape = ClothShape::Grid {
        width: 16,
        height: 12,
        spacing: 0.05,
    };
    shape
        .build_solver(
            &ClothPins::TopRow,
            &ClothParams::seeds(),
            Affine3A::from_translation(at),
        )
        .unwrap()
}

/// A gusty, turbulent sphere of air 1 m across about the first banner, blowing through
/// its face at 8 m/s.
fn zone() -> WindZone {
    WindZone {
        shape: ZoneShape::Sphere { radius: 1.0 },
        centre: Vec3::new(0.4, 1.7, 0.0),
        velocity: Vec3::Z * 8.0,
        falloff: 0.25,
        turbulence: Turbulence {
            gust: 0.4,
            gust_period: 0.5,
            noise: 0.5,
            scale: 0.3,
            seed: 7,
        },
        ..WindZone::default()
    }
}

/// Steps the banners side by side (as the plugin and the headless runner do), the
/// zones handed to each every step, and returns their positions.
fn blown(zones: &[WindZone], steps: u32) -> Vec<Vec<Vec3>> {
    let mut cloths = [
        banner(Vec3::new(0.0, 2.0, 0.0)),
        banner(Vec3::new(10.0, 2.0, 0.0)),
    ];
    let (env, dt) = (Environment::default(), 1.0 / 60.0);
    for step in 0..steps {
        for cloth in &mut cloths {
            cloth.set_wind_zones(zones, step as f32 * dt).unwrap();
        }
        let [a, b] = &mut cloths;
        bevy_cloth::solver::begin_cloths(&mut [(a, true), (b, true)], dt);
        bevy_cloth::solver::run_cloths(&mut [a, b], &env);
        for cloth in &mut cloths {
            cloth.end_step();
        }
    }
    cloths.iter().map(|c| c.positions().to_vec()).collect()
}

fn farthest(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f32::max)
}

/// The banner in the zone streams out along the wind; the one 10 m away is not reached
/// and moves exactly as in still air; the same bits on one thread and two.
#[test]
fn a_banner_in_a_wind_zone_moves_and_one_outside_does_not() {
    let zones = [zone()];
    let calm = blown(&[], 90);
    let runs = [
        bevy_cloth::solver::on_one_thread(|| blown(&zones, 90)),
        blown(&zones, 90),
    ];
    let [inside, outside] = [&runs[1][0], &runs[1][1]];
    let streamed = inside.iter().map(|x| x.z).fold(0.0, f32::max);
    let moved = farthest(inside, &calm[0]);
    eprintln!(
        "in the zone: {moved:.3} m from the calm banner, hem {streamed:.3} m downwind; \
         outside: {:e} m",
        farthest(outside, &calm[1])
    );
    assert!(
        streamed > 0.2,
        "the banner in the zone streams: {streamed} m"
    );
    assert_eq!(
        outside, &calm[1],
        "the banner outside moves as in still air"
    );
    assert!(runs[0] == runs[1], "one thread and the pool differ");
    let mut cloth = banner(Vec3::new(10.0, 2.0, 0.0));
    assert_eq!(
        cloth.set_wind_zones(&zones, 0.0).unwrap(),
        0,
        "out of reach"
    );
}

/// The zone's gusts and turbulence swell and stir the force: the banner's hem swings
/// over a wider range than in a steady zone (where a banner flutters too). A flutter's
/// range over 2 s is chaotic (the air's rounding alone moved the steady one from 0.104
/// to 0.127 m), so each is the median of five zones, 8 m/s ± 2%, with five seeds of
/// turbulence.
#[test]
fn gusts_keep_a_banner_moving() {
    let spread = |zone: WindZone| {
        let mut cloth = banner(Vec3::new(0.0, 2.0, 0.0));
        let (env, dt) = (Environment::default(), 1.0 / 60.0);
        let hem = cloth.positions().len() - 8;
        let (mut low, mut high) = (f32::MAX, f32::MIN);
        for step in 0..240 {
            cloth.set_wind_zones(&[zone], step as f32 * dt).unwrap();
            cloth.step(dt, &env);
            if step >= 120 {
                let z = cloth.positions()[hem].z;
                (low, high) = (low.min(z), high.max(z));
            }
        }
        high - low
    };
    let median = |gusty: bool| {
        let mut spreads: Vec<f32> = (0..5)
            .map(|k| {
                let mut zone = zone();
                zone.velocity *= 0.98 + 0.01 * k as f32;
                zone.turbulence.seed += k;
                if !gusty {
                    zone.turbulence = Turbulence::default();
                }
                spread(zone)
            })
            .collect();
        eprintln!("{spreads:.3?}");
        spreads.sort_by(f32::total_cmp);
        spreads[2]
    };
    let (steady, gusty) = (median(false), median(true));
    eprintln!(
        "the hem's swing over the last 2 s, median of five: steady {steady:.3} m, gusty \
         {gusty:.3} m"
    );
    assert!(gusty > 1.5 * steady && gusty > 0.05);
}

/// A zone that fails its check is refused with the field named, and none are taken.
#[test]
fn bad_wind_zones_are_refused() {
    let mut cloth = banner(Vec3::ZERO);
    for (bad, field) in [
        (
            WindZone {
                shape: ZoneShape::Sphere { radius: 0.0 },
                ..zone()
            },
            "wind_zone.radius",
        ),
        (
            WindZone {
                velocity: Vec3::NAN,
                ..zone()
            },
            "wind_zone.velocity",
        ),
        (
            WindZone {
                falloff: 2.0,
                ..zone()
            },
            "wind_zone.falloff",
        ),
        (
            WindZone {
                turbulence: Turbulence {
                    scale: 0.0,
                    ..Turbulence::default()
                },
                ..zone()
            },
            "wind_zone.turbulence.scale",
        ),
    ] {
        match cloth.set_wind_zones(&[zone(), bad], 0.0) {
            Err(ClothError::InvalidParameter { field: f, .. }) => assert_eq!(f, field),
            other => panic!("{bad:?}: {other:?}"),
        }
        assert!(cloth.wind_zones().is_empty());
    }
}
