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
