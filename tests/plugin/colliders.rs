//! Headless App tests of collider entities: cloth kept out, carried, primitives
//! converted, planes, a torus, bad sizes refused.

use bevy::prelude::*;
use bevy_cloth::ColliderKind;
use bevy_cloth::prelude::*;

use crate::common::*;

#[test]
fn collider_entities_keep_cloth_out_and_follow_their_transform() {
    let mut app = app();
    let cloth = app
        .world_mut()
        .spawn((
            Cloth::grid(8, 8, 0.05).with_pins(ClothPins::None),
            Transform::from_xyz(0.0, 1.0, 0.0)
                .with_rotation(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2)),
        ))
        .id();
    let ball = app
        .world_mut()
        .spawn((
            ClothCollider::sphere(0.15).with_thickness(0.01),
            Transform::from_xyz(0.0, 0.6, 0.175),
        ))
        .id();
    app.world_mut().spawn(ClothCollider::plane());
    // The cloth falls onto the ball and drapes over it: never inside it (by more than its
    // thickness), never below the ground, and touching it.
    let centre = Vec3::new(0.0, 0.6, 0.175);
    let mut touched = false;
    for _ in 0..150 {
        app.update();
        let Some(sim) = app.world().get::<ClothSimulation>(cloth) else {
            continue;
        };
        let x = sim.solver.positions();
        let closest = x
            .iter()
            .map(|p| p.distance(centre))
            .fold(f32::MAX, f32::min);
        assert!(
            closest > 0.15 - 1e-4,
            "a particle is {closest} m from the centre"
        );
        touched |= closest < 0.15 + 0.01 + 1e-3;
        assert!(
            x.iter().all(|p| p.y >= -1e-4),
            "a particle went through the ground"
        );
    }
    assert!(touched, "the cloth never reached the ball");
    let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
    let colliders = sim.solver.colliders();
    assert_eq!(colliders.len(), 2);
    assert!(colliders.iter().any(|c| matches!(
        c.shape,
        bevy_cloth::solver::ColliderShape::Sphere(bevy_cloth::solver::shapes::Sphere { center, radius })
            if center.distance(centre) < 1e-6 && radius == 0.15
    )));
    // Moving the entity moves the collider.
    app.world_mut()
        .get_mut::<Transform>(ball)
        .unwrap()
        .translation = Vec3::new(1.0, 0.5, 0.0);
    app.update();
    app.update();
    let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
    assert!(sim.solver.colliders().iter().any(|c| matches!(
        c.shape,
        bevy_cloth::solver::ColliderShape::Sphere(bevy_cloth::solver::shapes::Sphere { center, .. })
            if center.distance(Vec3::new(1.0, 0.5, 0.0)) < 1e-6
    )));
}

#[test]
fn a_cloth_lying_on_a_moving_collider_entity_is_carried_along() {
    // A box entity moved by its Transform 8 mm each 16 ms frame (0.5 m/s along x), a
    // cloth lying on it (μ = 0.8): the plugin gives the box its motion from the change of
    // its transform, and friction carries the cloth with it (less the ~1.6 cm it slips
    // while getting up to speed, v²/2μg).
    let mut app = app();
    let platform = app
        .world_mut()
        .spawn((
            ClothCollider::cuboid(2.0, 0.2, 2.0).with_friction(0.8),
            Transform::default(),
        ))
        .id();
    let cloth = app
        .world_mut()
        .spawn(lying_cloth(Vec3::new(0.0, 0.106, 0.0)))
        .id();
    app.update();
    app.update();
    let start = entity_centroid(&app, cloth);
    for _ in 0..60 {
        app.world_mut()
            .get_mut::<Transform>(platform)
            .unwrap()
            .translation
            .x += 0.008;
        app.update();
    }
    let moved = entity_centroid(&app, cloth) - start;
    let platform_x = app
        .world()
        .get::<Transform>(platform)
        .unwrap()
        .translation
        .x;
    eprintln!("the cloth moved {moved}, the box {platform_x}");
    assert!(
        moved.x > platform_x - 0.03 && moved.x < platform_x,
        "the cloth moved {moved}, the box {platform_x}"
    );
    assert!(moved.y.abs() < 3e-3, "stays on top: {moved}");
}

/// Collider constructors take the sizes Bevy's primitives take, and the primitives
/// convert into the same colliders.
#[test]
fn colliders_take_the_sizes_of_bevys_primitives() {
    let cuboid = ClothCollider::cuboid(2.0, 0.2, 1.0);
    assert_eq!(
        cuboid.shape,
        ColliderKind::Cuboid {
            half_extents: Vec3::new(1.0, 0.1, 0.5)
        }
    );
    assert_eq!(ClothCollider::from(Cuboid::new(2.0, 0.2, 1.0)), cuboid);
    let capsule = ClothCollider::capsule(0.1, 0.6);
    assert_eq!(
        capsule.shape,
        ColliderKind::Capsule {
            radius: 0.1,
            half_length: 0.3
        }
    );
    assert_eq!(ClothCollider::from(Capsule3d::new(0.1, 0.6)), capsule);
    let cylinder = ClothCollider::cylinder(0.2, 1.0);
    assert_eq!(
        cylinder.shape,
        ColliderKind::Cylinder {
            radius: 0.2,
            half_height: 0.5
        }
    );
    assert_eq!(ClothCollider::from(Cylinder::new(0.2, 1.0)), cylinder);
    assert_eq!(
        ClothCollider::from(Sphere::new(0.3)),
        ClothCollider::sphere(0.3)
    );
}

#[test]
fn planes_and_half_spaces_convert_with_their_normals_and_offsets() {
    let identity = GlobalTransform::IDENTITY;
    let plane = |c: ClothCollider| match c.to_world(&identity).shape {
        bevy_cloth::solver::ColliderShape::Plane(bevy_cloth::solver::shapes::Plane {
            point,
            normal,
        }) => (point, normal),
        other => panic!("not a plane: {other:?}"),
    };
    // Bevy's infinite plane: the solid behind it, like avian's `Collider::half_space`.
    let tilted = Vec3::new(1.0, 1.0, 0.0).normalize();
    let (point, normal) = plane(InfinitePlane3d::new(tilted).into());
    assert!(point.length() < 1e-6 && (normal - tilted).length() < 1e-6);
    assert_eq!(
        plane(InfinitePlane3d::new(Vec3::Y).into()),
        plane(ClothCollider::plane())
    );
    // Bevy's half-space is the solid, its normal pointing in: y > 0.5 here, a ceiling.
    let ceiling = bevy::math::primitives::HalfSpace::new(Vec4::new(0.0, 1.0, 0.0, -0.5));
    let (point, normal) = plane(ceiling.into());
    assert!(
        (point - Vec3::new(0.0, 0.5, 0.0)).length() < 1e-6,
        "{point}"
    );
    assert!((normal - Vec3::NEG_Y).length() < 1e-6, "{normal}");
    // A zero normal is refused; thickness and friction take their defaults in a file.
    assert!(
        ClothCollider::half_space(Vec3::ZERO, 0.0)
            .validate()
            .is_err()
    );
    let from_file: ClothCollider = ron::from_str("(shape: Sphere(radius: 0.2))").unwrap();
    assert_eq!(from_file, ClothCollider::sphere(0.2));
    assert!(
        ron::from_str::<ClothCollider>("(thickness: 0.01)").is_err(),
        "no shape"
    );
}

/// A solver shape of its own file (the torus) is a component like the built-in kinds:
/// placed by its entity's transform, checked by its own sizes.
#[test]
fn a_torus_collider_is_placed_by_its_transform_and_checked() {
    use bevy_cloth::solver::shapes::Torus;
    let ring = Torus {
        center: Vec3::ZERO,
        axis: Vec3::Y,
        major_radius: 0.3,
        minor_radius: 0.02,
    };
    let transform = Transform::from_xyz(0.0, 1.0, 2.0)
        .with_rotation(Quat::from_rotation_x(std::f32::consts::FRAC_PI_2))
        .with_scale(Vec3::splat(2.0));
    let world = ClothCollider::from_shape(ring).to_world(&GlobalTransform::from(transform));
    let bevy_cloth::solver::ColliderShape::Torus(placed) = world.shape else {
        panic!("{:?}", world.shape)
    };
    assert!((placed.center - Vec3::new(0.0, 1.0, 2.0)).length() < 1e-6);
    assert!((placed.axis - Vec3::Z).length() < 1e-6, "{}", placed.axis);
    assert!((placed.major_radius - 0.6).abs() < 1e-6 && (placed.minor_radius - 0.04).abs() < 1e-6);
    let thin = Torus {
        minor_radius: -0.01,
        ..ring
    };
    let refused = ClothCollider::from_shape(thin).validate().unwrap_err();
    assert!(refused.to_string().contains("minor_radius"), "{refused}");
}

/// A collider with a negative radius is not clamped to 0 in silence: it gets
/// `ClothColliderInvalid` naming the radius, `ClothColliderBecameInvalid` fires once (and
/// it is logged), and it is left out of the cloths' steps; fixed, it is a collider again.
#[test]
fn a_collider_of_negative_size_is_refused_until_fixed() {
    let mut app = app();
    let events = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let seen = events.clone();
    let collider = app
        .world_mut()
        .spawn((ClothCollider::sphere(-1.0), Transform::default()))
        .observe(move |_: On<ClothColliderBecameInvalid>| {
            seen.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        })
        .id();
    for _ in 0..3 {
        app.update();
    }
    assert_eq!(events.load(std::sync::atomic::Ordering::Relaxed), 1);
    assert!(
        app.world().get::<ClothInvalid>(collider).is_none(),
        "not a cloth"
    );
    let invalid = app
        .world()
        .get::<ClothColliderInvalid>(collider)
        .expect("refused");
    assert!(
        matches!(
            invalid.0,
            ClothError::InvalidParameter {
                field: "radius",
                ..
            }
        ),
        "{:?}",
        invalid.0
    );
    *app.world_mut().get_mut::<ClothCollider>(collider).unwrap() = ClothCollider::sphere(0.2);
    for _ in 0..3 {
        app.update();
    }
    assert!(app.world().get::<ClothColliderInvalid>(collider).is_none());
}
