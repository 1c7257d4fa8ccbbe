//! Headless App tests of building cloths: edits and rebuilds, invalid cloths refused and
//! logged, meshes as cloths, pins on the transform, tearing messages, observers, every
//! public type reflected.

use bevy::ecs::message::Messages;
use bevy::mesh::{Mesh, Mesh3d};
use bevy::prelude::*;
use bevy_cloth::prelude::*;

use crate::common::*;

#[test]
fn edits_take_effect_and_grid_changes_rebuild() {
    let mut app = app();
    let e = app
        .world_mut()
        .spawn(Cloth::grid(4, 4, 0.1).with_params(quiet_params()))
        .id();
    app.update();
    app.update();
    app.world_mut()
        .get_mut::<Cloth>(e)
        .unwrap()
        .params
        .springs
        .structural
        .stiffness = 321.0;
    app.update();
    let sim = app.world().get::<ClothSimulation>(e).unwrap();
    assert_eq!(sim.solver.params().springs.structural.stiffness, 321.0);
    assert_eq!(sim.solver.particle_count(), 16);
    app.world_mut().get_mut::<Cloth>(e).unwrap().shape = ClothShape::Grid {
        width: 6,
        height: 3,
        spacing: 0.1,
    };
    app.update();
    app.update();
    assert_eq!(
        app.world()
            .get::<ClothSimulation>(e)
            .unwrap()
            .solver
            .particle_count(),
        18
    );
}

#[test]
fn pinned_cloth_follows_its_transform() {
    let mut app = app();
    let e = app
        .world_mut()
        .spawn((Cloth::grid(4, 4, 0.1), Transform::from_xyz(0.0, 1.0, 0.0)))
        .id();
    for _ in 0..3 {
        app.update();
    }
    app.world_mut().get_mut::<Transform>(e).unwrap().translation = Vec3::new(1.0, 1.5, 0.0);
    for _ in 0..3 {
        app.update();
    }
    let sim = app.world().get::<ClothSimulation>(e).unwrap();
    let corner = sim.solver.positions()[0];
    assert!(
        (corner - Vec3::new(1.0 - 0.15, 1.5, 0.0)).length() < 1e-4,
        "corner at {corner}"
    );
}

/// A small cloth hung by its top row that tears under [`TEARING_GRAVITY`].
fn tearing_cloth() -> Cloth {
    let params = ClothParams {
        tear_ratio: Some(1.3),
        strain_limit: None,
        ..ClothParams::seeds()
    };
    Cloth::grid(5, 5, 0.1)
        .with_pins(ClothPins::TopRow)
        .with_params(params)
}

/// Gravity far past what [`tearing_cloth`]'s springs hold.
const TEARING_GRAVITY: Vec3 = Vec3::new(0.0, -30_000.0, 0.0);

#[test]
fn torn_springs_send_messages() {
    let mut app = app();
    let e = app.world_mut().spawn(tearing_cloth()).id();
    app.world_mut().resource_mut::<ClothEnvironment>().gravity = TEARING_GRAVITY;
    let mut cursor = app.world().resource::<Messages<ClothTorn>>().get_cursor();
    let mut seen = Vec::new();
    for _ in 0..30 {
        app.update();
        let messages = app.world().resource::<Messages<ClothTorn>>();
        seen.extend(cursor.read(messages).copied());
    }
    let sim = app.world().get::<ClothSimulation>(e).unwrap();
    assert!(
        !seen.is_empty(),
        "strain {:?} torn {}",
        sim.solver.strain(),
        sim.solver.torn_count()
    );
    assert_eq!(seen.len(), sim.solver.torn_count());
    assert!(
        seen.iter()
            .all(|m| m.cloth == e && !sim.solver.springs().alive[m.spring as usize])
    );
}

#[test]
fn invalid_cloths_are_logged_and_skipped_not_panicked() {
    let mut app = app();
    let bad_mass = app
        .world_mut()
        .spawn(Cloth::grid(4, 4, 0.1).with_params(ClothParams {
            node_mass: -1.0,
            ..ClothParams::seeds()
        }))
        .id();
    let bad_pin = app
        .world_mut()
        .spawn(Cloth::grid(4, 4, 0.1).with_pins(ClothPins::Indices(vec![99])))
        .id();
    let tiny = app.world_mut().spawn(Cloth::grid(1, 4, 0.1)).id();
    let good = app.world_mut().spawn(Cloth::grid(4, 4, 0.1)).id();
    for _ in 0..3 {
        app.update();
    }
    for e in [bad_mass, bad_pin, tiny] {
        assert!(app.world().get::<ClothInvalid>(e).is_some());
        assert!(app.world().get::<ClothSimulation>(e).is_none());
    }
    assert!(app.world().get::<ClothSimulation>(good).is_some());
    // Fixing the description builds it.
    app.world_mut()
        .get_mut::<Cloth>(bad_mass)
        .unwrap()
        .params
        .node_mass = 1e-3;
    app.update();
    app.update();
    assert!(app.world().get::<ClothInvalid>(bad_mass).is_none());
    assert!(app.world().get::<ClothSimulation>(bad_mass).is_some());
    // A running cloth given a bad value pauses with the error, and resumes when fixed.
    app.world_mut().get_mut::<Cloth>(good).unwrap().params.drag = f32::NAN;
    app.update();
    let t = sim_time(&app, good);
    app.update();
    assert!(app.world().get::<ClothInvalid>(good).is_some());
    assert_eq!(sim_time(&app, good), t);
    app.world_mut().get_mut::<Cloth>(good).unwrap().params.drag = 0.0;
    app.update();
    app.update();
    assert!(app.world().get::<ClothInvalid>(good).is_none());
    assert!(sim_time(&app, good) > t);
}

#[test]
fn a_mesh_becomes_a_cloth() {
    let mut app = app();
    let plane = Plane3d::new(Vec3::Z, Vec2::splat(0.5))
        .mesh()
        .subdivisions(3)
        .build();
    let vertices = plane.count_vertices();
    let handle = app.world_mut().resource_mut::<Assets<Mesh>>().add(plane);
    let e = app
        .world_mut()
        .spawn((Cloth::from_mesh(), Mesh3d(handle.clone())))
        .id();
    for _ in 0..3 {
        app.update();
    }
    let sim = app
        .world()
        .get::<ClothSimulation>(e)
        .expect("built from the mesh");
    assert_eq!(sim.solver.particle_count(), vertices);
    assert_eq!(
        sim.solver.pins().len(),
        5,
        "the top row of a 5×5 vertex plane"
    );
    assert!(sim.solver.spring_count() > vertices);
    assert_ne!(
        app.world().get::<Mesh3d>(e).unwrap().0,
        handle,
        "the source mesh is left alone"
    );
}

/// `value` is registered (with `ReflectComponent` when `component`) and comes back equal
/// from its reflected copy.
fn round_trips<T>(app: &App, value: T, component: bool)
where
    T: Reflect + FromReflect + TypePath + PartialEq + std::fmt::Debug,
{
    let registry = app.world().resource::<AppTypeRegistry>().read();
    let name = T::type_path();
    let registration = registry
        .get(std::any::TypeId::of::<T>())
        .unwrap_or_else(|| panic!("{name} is not registered"));
    if component {
        assert!(
            registration.data::<ReflectComponent>().is_some(),
            "{name} has no ReflectComponent"
        );
    }
    let copy = T::from_reflect(value.to_dynamic().as_partial_reflect())
        .unwrap_or_else(|| panic!("{name} does not come back from reflection"));
    assert_eq!(copy, value, "{name}");
}

#[test]
fn every_public_component_resource_message_and_event_is_reflected_and_registered() {
    let app = app();
    let e = Entity::from_raw_u32(7).unwrap();
    round_trips(&app, Cloth::grid(4, 3, 0.1), true);
    round_trips(
        &app,
        ClothCollider::capsule(0.1, 0.5).with_friction(0.7),
        true,
    );
    round_trips(&app, ClothSleep::never(), true);
    round_trips(&app, ClothLod::default(), true);
    round_trips(
        &app,
        ClothAttachments(vec![
            ClothAttachment::nearest(e, Vec3::Y, 3),
            ClothAttachment::run(e, "collar"),
        ]),
        true,
    );
    round_trips(
        &app,
        ClothInvalid(bevy_cloth::ClothError::EmptyGarment),
        true,
    );
    round_trips(&app, ClothEnvironment::default(), false);
    round_trips(&app, ClothPause::default(), false);
    round_trips(&app, ClothInterpolation(false), false);
    round_trips(
        &app,
        ClothMaxDistance::VertexColor {
            channel: 0,
            scale: 0.2,
        },
        true,
    );
    round_trips(
        &app,
        ClothBackStop::PerVertex(vec![[0.01, 0.3], [0.0, 0.1]]),
        true,
    );
    round_trips(&app, bevy_cloth::StatSample::default(), false);
    round_trips(&app, ClothWake(e), false);
    round_trips(
        &app,
        ClothTorn {
            cloth: e,
            spring: 3,
            particles: [1, 2],
        },
        false,
    );
    round_trips(&app, ClothAwoke { entity: e }, false);
    round_trips(&app, ClothFellAsleep { entity: e }, false);
    round_trips(&app, ClothBuilt { entity: e }, false);
    round_trips(
        &app,
        ClothBecameInvalid {
            entity: e,
            error: bevy_cloth::ClothError::EmptyGarment,
        },
        false,
    );
    // Reflected without their solver state (not reflectable), for inspectors.
    let registry = app.world().resource::<AppTypeRegistry>().read();
    for (name, id) in [
        ("ClothSimulation", std::any::TypeId::of::<ClothSimulation>()),
        ("ClothStats", std::any::TypeId::of::<ClothStats>()),
    ] {
        let registration = registry.get(id).unwrap_or_else(|| panic!("{name}"));
        assert!(registration.data::<ReflectComponent>().is_some(), "{name}");
    }
}

/// What the observers on one cloth saw.
#[derive(Resource, Default, Debug)]
struct Seen {
    built: usize,
    torn: Vec<u32>,
    asleep: usize,
    awoke: usize,
    invalid: Vec<bevy_cloth::ClothError>,
}

#[test]
fn observers_on_a_cloth_see_it_built_torn_asleep_woken_and_invalid() {
    let mut app = app();
    app.init_resource::<Seen>();
    let e = app
        .world_mut()
        .spawn(tearing_cloth())
        .observe(|_: On<ClothBuilt>, mut seen: ResMut<Seen>| seen.built += 1)
        .observe(|torn: On<ClothTorn>, mut seen: ResMut<Seen>| seen.torn.push(torn.spring))
        .observe(|_: On<ClothFellAsleep>, mut seen: ResMut<Seen>| seen.asleep += 1)
        .observe(|_: On<ClothAwoke>, mut seen: ResMut<Seen>| seen.awoke += 1)
        .observe(|bad: On<ClothBecameInvalid>, mut seen: ResMut<Seen>| {
            seen.invalid.push(bad.error.clone())
        })
        .id();
    app.world_mut().resource_mut::<ClothEnvironment>().gravity = TEARING_GRAVITY;
    for _ in 0..30 {
        app.update();
    }
    let torn = app
        .world()
        .get::<ClothSimulation>(e)
        .unwrap()
        .solver
        .torn_count();
    let seen = app.world().resource::<Seen>();
    assert_eq!(seen.built, 1, "{seen:?}");
    assert!(
        !seen.torn.is_empty() && seen.torn.len() == torn,
        "{seen:?}, {torn} torn"
    );
    // Asleep: no gravity, the pieces come to rest within a few seconds and sleep.
    app.world_mut()
        .resource_mut::<ClothEnvironment>()
        .gravity_enabled = false;
    app.world_mut()
        .get_mut::<ClothSimulation>(e)
        .unwrap()
        .reset();
    for _ in 0..400 {
        app.update();
        if app.world().resource::<Seen>().asleep > 0 {
            break;
        }
    }
    assert_eq!(app.world().resource::<Seen>().asleep, 1);
    // Woken by the game's message.
    app.world_mut().write_message(ClothWake(e));
    app.update();
    assert_eq!(app.world().resource::<Seen>().awoke, 1);
    // Invalid: a negative mass.
    app.world_mut()
        .get_mut::<Cloth>(e)
        .unwrap()
        .params
        .node_mass = -1.0;
    app.update();
    let seen = app.world().resource::<Seen>();
    assert_eq!(seen.invalid.len(), 1, "{seen:?}");
    assert!(app.world().get::<ClothInvalid>(e).is_some());
}
