//! Headless App tests of attachments: a cloth on a moving entity, a garment on a hanger
//! by its runs, local offsets.

use bevy::prelude::*;
use bevy_cloth::prelude::*;

use crate::common::*;

/// A "shoulder" entity 2 m up and an 8 × 6 cloth (5 cm, no pins, the seeds' springs: let
/// go, it falls as in a vacuum) beside it, held by the attachments `held` makes for the
/// shoulder: (shoulder, cloth).
fn cloth_on_a_shoulder(
    app: &mut App,
    held: impl FnOnce(Entity) -> Vec<ClothAttachment>,
) -> (Entity, Entity) {
    let place = Transform::from_xyz(0.0, 2.0, 0.0);
    let shoulder = app.world_mut().spawn(place).id();
    let cloth = app
        .world_mut()
        .spawn((
            Cloth::grid(8, 6, 0.05)
                .with_pins(ClothPins::None)
                .with_params(ClothParams::seeds()),
            place,
            ClothAttachments(held(shoulder)),
        ))
        .id();
    (shoulder, cloth)
}

#[test]
fn an_attached_cloth_follows_its_moving_entity_with_no_lag_beyond_a_step() {
    // A cape-like cloth hanging from a "shoulder" entity that walks along x and turns:
    // its two top corners, attached, are where the entity puts them at the end of every
    // step (the solver reaches the target over the step's substeps, as pins do).
    let mut app = app();
    let (shoulder, cloth) = cloth_on_a_shoulder(&mut app, |shoulder| {
        vec![
            ClothAttachment::indices(shoulder, vec![0]),
            ClothAttachment::nearest(shoulder, Vec3::new(0.175, 0.0, 0.0), 1),
        ]
    });
    // Built in the first frame (by command), attached from the second.
    app.update();
    app.update();
    let held: Vec<(u32, Vec3)> = app
        .world()
        .get::<ClothAttachments>(cloth)
        .unwrap()
        .0
        .iter()
        .flat_map(|a| a.held().to_vec())
        .collect();
    assert_eq!(held.iter().map(|h| h.0).collect::<Vec<_>>(), [0, 7]);
    for frame in 1..=60 {
        {
            let mut t = app.world_mut().get_mut::<Transform>(shoulder).unwrap();
            t.translation.x += 0.02;
            t.rotate_y(0.01);
        }
        app.update();
        let t = *app.world().get::<Transform>(shoulder).unwrap();
        let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
        for &(i, local) in &held {
            let want = t.transform_point(local);
            let got = sim.solver.positions()[i as usize];
            assert!(
                got.distance(want) < 1e-5,
                "frame {frame}: particle {i} at {got}, the shoulder puts it at {want}"
            );
        }
        // The rest of the cloth hangs below and follows (a sheet 0.25 m long).
        let lowest = sim
            .solver
            .positions()
            .iter()
            .map(|p| p.y)
            .fold(f32::MAX, f32::min);
        assert!(
            lowest < 2.0 && lowest > 1.6,
            "frame {frame}: lowest {lowest}"
        );
        assert!(sim.solver.is_stable());
    }
    // The entity gone: the cloth is let go and falls.
    app.world_mut().despawn(shoulder);
    for _ in 0..30 {
        app.update();
    }
    let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
    assert!(sim.solver.attached().is_empty());
    assert!(sim.solver.positions()[0].y < 1.0);
}

#[test]
fn a_garment_hangs_from_its_named_runs_on_a_moving_hanger() {
    // The T-shirt held by its file's two shoulder runs to a "hanger" entity that moves
    // and turns: every run particle is where the hanger puts it each frame, and the shirt
    // hangs below.
    let mut app = app();
    let hanger = app
        .world_mut()
        .spawn(Transform::from_xyz(0.0, 1.5, 0.0))
        .id();
    let shirt = app
        .world_mut()
        .spawn((
            Cloth::garment("patterns/tshirt.ron"),
            Transform::from_xyz(0.0, 1.5, 0.0),
            ClothAttachments(vec![
                ClothAttachment::run(hanger, "right shoulder"),
                ClothAttachment::run(hanger, "left shoulder"),
            ]),
        ))
        .id();
    // The garment loads through the asset server: a few frames until it is built and held.
    let mut held = Vec::new();
    for _ in 0..200 {
        app.update();
        held = app
            .world()
            .get::<ClothAttachments>(shirt)
            .map_or(Vec::new(), |a| {
                a.0.iter().flat_map(|a| a.held().to_vec()).collect()
            });
        if !held.is_empty() {
            break;
        }
    }
    assert_eq!(held.len(), 12, "two runs of 6 nodes");
    for frame in 1..=90 {
        {
            let mut t = app.world_mut().get_mut::<Transform>(hanger).unwrap();
            t.translation.x += 0.01;
            t.rotate_y(0.01);
        }
        app.update();
        let t = *app.world().get::<Transform>(hanger).unwrap();
        let sim = app.world().get::<ClothSimulation>(shirt).unwrap();
        for &(i, local) in &held {
            let got = sim.solver.positions()[i as usize];
            let want = t.transform_point(local);
            assert!(
                got.distance(want) < 1e-5,
                "frame {frame}: particle {i} at {got}, the hanger puts it at {want}"
            );
        }
        assert!(sim.solver.is_stable());
    }
    // After the sewing (1 s, no gravity) the shirt drops and hangs from the shoulders.
    let sim = app.world().get::<ClothSimulation>(shirt).unwrap();
    let lowest = sim
        .solver
        .positions()
        .iter()
        .map(|x| x.y)
        .fold(f32::MAX, f32::min);
    assert!(
        lowest < 1.5 - 0.6,
        "hangs below the hanger: lowest {lowest}"
    );
}

#[test]
fn particles_attached_at_local_offsets_go_there_and_follow() {
    // Two corners of a cloth held at points given in a bar entity's frame (not where they
    // start): they are pulled there in the first step and then follow the bar.
    let mut app = app();
    let bar = app
        .world_mut()
        .spawn(Transform::from_xyz(0.5, 2.0, 0.0))
        .id();
    let offsets = vec![
        (0, Vec3::new(-0.3, 0.0, 0.1)),
        (7, Vec3::new(0.3, 0.0, 0.1)),
    ];
    let cloth = app
        .world_mut()
        .spawn((
            Cloth::grid(8, 6, 0.05).with_pins(ClothPins::None),
            Transform::from_xyz(0.0, 1.8, 0.0),
            ClothAttachments(vec![ClothAttachment::at(bar, offsets.clone())]),
        ))
        .id();
    app.update();
    for frame in 0..40 {
        {
            let mut t = app.world_mut().get_mut::<Transform>(bar).unwrap();
            t.translation.z -= 0.01;
            t.rotate_y(0.02);
        }
        app.update();
        if frame == 0 {
            continue; // the first step after the cloth is built attaches them
        }
        let t = *app.world().get::<Transform>(bar).unwrap();
        let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
        for &(i, local) in &offsets {
            let (got, want) = (sim.solver.positions()[i as usize], t.transform_point(local));
            assert!(
                got.distance(want) < 1e-5,
                "frame {frame}: particle {i} at {got}, wanted {want}"
            );
        }
    }
}

/// An attachment that holds none of its cloth's particles (every index past the cloth, or
/// a garment run the cloth lacks) is not skipped in silence while the cloth falls: the
/// cloth gets `ClothInvalid` naming the attachment, `ClothBecameInvalid` fires, and it does
/// not move until its attachments change; fixed, it runs and holds.
#[test]
fn an_attachment_that_holds_nothing_stops_its_cloth_until_fixed() {
    let mut app = app();
    let body = app
        .world_mut()
        .spawn(Transform::from_xyz(0.0, 2.0, 0.0))
        .id();
    let refused = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let seen = refused.clone();
    let cape = app
        .world_mut()
        .spawn((
            Name::new("cape"),
            Cloth::grid(4, 4, 0.1).with_pins(ClothPins::None),
            ClothAttachments(vec![
                ClothAttachment::indices(body, vec![0, 3]),
                ClothAttachment::indices(body, vec![16, 400]),
            ]),
        ))
        .observe(move |e: On<ClothBecameInvalid>| seen.lock().unwrap().push(e.error.clone()))
        .id();
    for _ in 0..10 {
        app.update();
    }
    let invalid = app.world().get::<ClothInvalid>(cape).expect("refused");
    assert!(
        matches!(
            invalid.0,
            ClothError::AttachmentHoldsNothing { attachment: 1, .. }
        ),
        "{:?}",
        invalid.0
    );
    let message = invalid.0.to_string();
    assert!(
        message.contains("ClothAttachments[1]") && message.contains("16"),
        "{message}"
    );
    assert_eq!(
        refused.lock().unwrap().len(),
        1,
        "one event, not one a step"
    );
    let sim = app.world().get::<ClothSimulation>(cape).unwrap();
    assert_eq!(sim.solver.time(), 0.0, "a refused cloth does not step");
    // Fixed: the second attachment holds the other top corner.
    app.world_mut().get_mut::<ClothAttachments>(cape).unwrap().0[1] =
        ClothAttachment::indices(body, vec![15]);
    for _ in 0..10 {
        app.update();
    }
    assert!(app.world().get::<ClothInvalid>(cape).is_none());
    let sim = app.world().get::<ClothSimulation>(cape).unwrap();
    assert!(sim.solver.time() > 0.0);
    let attachments = app.world().get::<ClothAttachments>(cape).unwrap();
    assert_eq!(
        attachments.0[0].held().len() + attachments.0[1].held().len(),
        3
    );
    // A garment run the cloth lacks is refused the same way.
    app.world_mut().get_mut::<ClothAttachments>(cape).unwrap().0[0] =
        ClothAttachment::run(body, "collar");
    for _ in 0..3 {
        app.update();
    }
    let invalid = app.world().get::<ClothInvalid>(cape).expect("refused");
    assert!(invalid.0.to_string().contains("collar"), "{}", invalid.0);
}

/// A grid's default pins (`ClothPins::Auto`) hold its top corners only when nothing
/// attaches it: a cape attached to a body is not also nailed to the world, an attachment
/// added later lets go of the world, and pins given explicitly stay.
#[test]
fn an_attached_cloth_has_no_default_world_pins() {
    let mut app = app();
    let body = app
        .world_mut()
        .spawn(Transform::from_xyz(0.0, 2.0, 0.0))
        .id();
    let attached = |i: u32| ClothAttachments(vec![ClothAttachment::indices(body, vec![i])]);
    let cape = app
        .world_mut()
        .spawn((Cloth::grid(4, 4, 0.1), attached(1)))
        .id();
    let nailed = app
        .world_mut()
        .spawn((
            Cloth::grid(4, 4, 0.1).with_pins(ClothPins::TopCorners),
            attached(1),
        ))
        .id();
    let hung = app.world_mut().spawn(Cloth::grid(4, 4, 0.1)).id();
    for _ in 0..3 {
        app.update();
    }
    // The world's pins: the held particles less the attached ones.
    let pins = |app: &App, e: Entity| {
        let solver = &app.world().get::<ClothSimulation>(e).unwrap().solver;
        let world = solver.pins().len() - solver.attached().len();
        solver.pins()[..world].to_vec()
    };
    assert_eq!(pins(&app, cape), Vec::<u32>::new());
    assert_eq!(pins(&app, nailed), vec![0, 3]);
    assert_eq!(pins(&app, hung), vec![0, 3]);
    app.world_mut().entity_mut(hung).insert(attached(2));
    for _ in 0..3 {
        app.update();
    }
    assert_eq!(pins(&app, hung), Vec::<u32>::new(), "attached later");
    let held = app.world().get::<ClothAttachments>(hung).unwrap().0[0]
        .held()
        .to_vec();
    assert_eq!(held.len(), 1);
}

/// A shoulder that jumps 10 m takes its attached cloth along at once (a teleport by the
/// default thresholds), and a small move the game calls a teleport (`ClothTeleport`)
/// carries it too: each triggers one `ClothTeleported` with the mode and the distance.
#[test]
fn a_jumping_body_teleports_its_cloth_and_says_so() {
    let mut app = app();
    let (shoulder, cloth) = cloth_on_a_shoulder(&mut app, |shoulder| {
        vec![ClothAttachment::indices(shoulder, vec![0, 7])]
    });
    let seen = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let record = seen.clone();
    app.world_mut()
        .entity_mut(cloth)
        .observe(move |jump: On<ClothTeleported>| {
            record.lock().unwrap().push((jump.mode, jump.distance));
        });
    for _ in 0..30 {
        app.update();
    }
    assert!(
        seen.lock().unwrap().is_empty(),
        "hanging still is no teleport"
    );
    let lowest = |app: &App| {
        let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
        sim.solver
            .positions()
            .iter()
            .map(|x| x.y)
            .fold(f32::MAX, f32::min)
    };
    let hang = lowest(&app);
    app.world_mut()
        .get_mut::<Transform>(shoulder)
        .unwrap()
        .translation += Vec3::new(10.0, 0.0, 0.0);
    app.update();
    let sim = app.world().get::<ClothSimulation>(cloth).unwrap();
    let farthest_back = sim
        .solver
        .positions()
        .iter()
        .map(|x| x.x)
        .fold(f32::MAX, f32::min);
    assert!(
        farthest_back > 9.8,
        "a particle left at x = {farthest_back}"
    );
    assert!(
        (lowest(&app) - hang).abs() < 0.01,
        "the same hang after the jump"
    );
    app.world_mut()
        .get_mut::<Transform>(shoulder)
        .unwrap()
        .translation += Vec3::new(0.0, 0.0, 0.1);
    app.world_mut().write_message(ClothTeleport {
        cloth,
        mode: TeleportMode::Reset,
    });
    app.update();
    let seen = seen.lock().unwrap().clone();
    assert_eq!(seen.len(), 2, "{seen:?}");
    assert_eq!(seen[0].0, TeleportMode::Keep);
    assert!((seen[0].1 - 10.0).abs() < 0.05, "{seen:?}");
    assert_eq!(seen[1].0, TeleportMode::Reset);
    assert!((seen[1].1 - 0.1).abs() < 0.01, "{seen:?}");
}
