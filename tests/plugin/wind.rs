//! Wind zones in the world: a `ClothWindZone` entity blows on the cloths it reaches.

use crate::common::*;
use bevy::prelude::*;
use bevy_cloth::prelude::*;

/// A 10 × 8 banner hung from its top row at `x`.
fn banner(app: &mut App, x: f32) -> Entity {
    app.world_mut()
        .spawn((
            Cloth::grid(10, 8, 0.05).with_pins(ClothPins::TopRow),
            Transform::from_xyz(x, 2.0, 0.0),
        ))
        .id()
}

/// A sphere zone about one banner, turned by its transform so that its local +x blows
/// along the world's +z, streams that banner out and leaves the other, 5 m away, where
/// a banner in a world without zones hangs.
#[test]
fn a_wind_zone_entity_blows_on_the_cloths_it_reaches() {
    let mut calm = app();
    let calm_far = banner(&mut calm, 5.0);
    let mut app = app();
    let near = banner(&mut app, 0.0);
    let far = banner(&mut app, 5.0);
    app.world_mut().spawn((
        ClothWindZone::sphere(1.0, Vec3::X * 8.0),
        Transform::from_xyz(0.25, 1.8, 0.0)
            .with_rotation(Quat::from_rotation_y(-std::f32::consts::FRAC_PI_2)),
    ));
    for _ in 0..60 {
        app.update();
        calm.update();
    }
    let sim = |app: &App, e| {
        app.world()
            .get::<ClothSimulation>(e)
            .unwrap()
            .solver
            .clone()
    };
    let blown = sim(&app, near);
    let downwind = blown.positions().iter().map(|x| x.z).fold(0.0, f32::max);
    eprintln!("the banner in the zone: {downwind:.3} m downwind");
    assert_eq!(blown.wind_zones().len(), 1);
    assert!(downwind > 0.2, "{downwind} m");
    let (far, calm_far) = (sim(&app, far), sim(&calm, calm_far));
    assert!(far.wind_zones().is_empty());
    assert_eq!(far.positions(), calm_far.positions());
}

/// The plugin drives the cloths side by side on two cores (the zones, the colliders, the
/// skins each cloth's own): six banners, two of them in a zone, one against a ball, end
/// on the bits they end on when every system takes one cloth after another.
#[test]
fn driving_side_by_side_is_driving_one_after_another() {
    let run = |parallel: bool| {
        bevy_cloth::solver::set_parallel(parallel);
        let mut app = app();
        let banners: Vec<Entity> = (0..6).map(|k| banner(&mut app, k as f32 * 0.8)).collect();
        app.world_mut().spawn((
            ClothWindZone::sphere(1.0, Vec3::Z * 6.0),
            Transform::from_xyz(0.6, 1.8, 0.0),
        ));
        app.world_mut().spawn((
            ClothCollider::sphere(0.1).with_thickness(0.01),
            Transform::from_xyz(3.4, 1.8, 0.05),
        ));
        for _ in 0..40 {
            app.update();
        }
        let world = app.world();
        let sim = |e| &world.get::<ClothSimulation>(e).unwrap().solver;
        let zones: Vec<usize> = banners.iter().map(|&e| sim(e).wind_zones().len()).collect();
        let x: Vec<Vec<Vec3>> = banners
            .iter()
            .map(|&e| sim(e).positions().to_vec())
            .collect();
        (zones, x)
    };
    let (one, two) = (run(false), run(true));
    bevy_cloth::solver::set_parallel(true);
    assert_eq!(one, two);
    // The zone blew on the first and not the last; the ball pushed the fifth off its
    // plane, where the last, calm, hangs in it.
    let (zones, x) = one;
    assert_eq!((zones[0], zones[5]), (1, 0));
    let off_plane = |k: usize| x[k].iter().map(|p| p.z.abs()).fold(0.0, f32::max);
    assert!(off_plane(0) > 0.05, "{}", off_plane(0));
    assert!(off_plane(4) > 1e-3, "{}", off_plane(4));
    assert_eq!(off_plane(5), 0.0);
}
