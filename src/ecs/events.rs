//! What happens to a cloth, as events on its entity: observe one cloth with
//! `commands.entity(cape).observe(|torn: On<ClothTorn>| …)`, or every cloth with
//! `app.add_observer(…)`. Tearing is also a buffered [`Message`] (read it with a
//! `MessageReader<ClothTorn>`), for systems that take many at once.
//!
//! ```
//! use bevy::prelude::*;
//! use bevy_cloth::prelude::*;
//! # let mut world = World::new();
//! world
//!     .spawn(Cloth::grid(16, 16, 0.05))
//!     .observe(|torn: On<ClothTorn>| info!("spring {} of {} tore", torn.spring, torn.cloth))
//!     .observe(|asleep: On<ClothFellAsleep>| info!("{} is still", asleep.entity));
//! ```

use bevy::ecs::message::Message;
use bevy::prelude::*;

use crate::error::ClothError;
use crate::params::TeleportMode;

/// A spring tore (over-stretched past its tear strain, or cut): triggered on the cloth
/// entity and sent as a message, once per spring, at the end of the step that tore it.
#[derive(Message, EntityEvent, Clone, Copy, Debug, PartialEq, Eq, Reflect)]
#[reflect(Debug, PartialEq)]
pub struct ClothTorn {
    /// The cloth entity.
    #[event_target]
    pub cloth: Entity,
    /// The torn spring's index in `solver.springs()`.
    pub spring: u32,
    /// The two particles it joined.
    pub particles: [u32; 2],
}

/// The cloth fell asleep at the end of a step (see [`ClothSleep`](crate::ClothSleep)):
/// its steps are skipped until something can move it.
#[derive(EntityEvent, Clone, Copy, Debug, PartialEq, Eq, Reflect)]
#[reflect(Debug, PartialEq)]
pub struct ClothFellAsleep {
    /// The cloth entity.
    pub entity: Entity,
}

/// A sleeping cloth woke (something can move it: an edit, a collider near it, a grab, a
/// change of gravity or wind, a [`ClothWake`](crate::ClothWake) message).
#[derive(EntityEvent, Clone, Copy, Debug, PartialEq, Eq, Reflect)]
#[reflect(Debug, PartialEq)]
pub struct ClothAwoke {
    /// The cloth entity.
    pub entity: Entity,
}

/// The cloth stopped being simulated: its description is invalid, its garment failed to
/// load, or a step went non-finite (it then keeps its last good state). The entity has
/// [`ClothInvalid`](crate::ClothInvalid) with the same error until it is fixed.
#[derive(EntityEvent, Clone, Debug, PartialEq, Reflect)]
#[reflect(Debug, PartialEq)]
pub struct ClothBecameInvalid {
    /// The cloth entity.
    pub entity: Entity,
    /// Why.
    pub error: ClothError,
}

/// A [`ClothCollider`](crate::ClothCollider) was refused (a size out of range): it is left
/// out of every cloth's step, and its entity has
/// [`ClothColliderInvalid`](crate::ClothColliderInvalid) with the same error until it is
/// fixed.
#[derive(EntityEvent, Clone, Debug, PartialEq, Reflect)]
#[reflect(Debug, PartialEq)]
pub struct ClothColliderBecameInvalid {
    /// The collider's entity.
    pub entity: Entity,
    /// Why.
    pub error: ClothError,
}

/// Asks for a teleport of a cloth at its next step (a game moving the body it hangs on to
/// a new place): the move of its drivers (pins, attachments, skinned targets) that step,
/// however small, carries the whole cloth, by `mode` (see
/// [`Teleport`](crate::params::Teleport); jumps past its thresholds need no message).
/// A sleeping cloth wakes for it.
#[derive(Message, Clone, Copy, Debug, PartialEq, Eq, Reflect)]
#[reflect(Debug, PartialEq)]
pub struct ClothTeleport {
    /// The cloth entity.
    pub cloth: Entity,
    /// What the cloth does: keep its motion, or start at rest on its skinned pose.
    pub mode: TeleportMode,
}

/// The cloth was teleported at the start of the step that just ended: its drivers jumped
/// past the [`Teleport`](crate::params::Teleport) thresholds, or a [`ClothTeleport`]
/// asked for it. Triggered on the cloth entity.
#[derive(EntityEvent, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Debug, PartialEq)]
pub struct ClothTeleported {
    /// The cloth entity.
    pub entity: Entity,
    /// What it did.
    pub mode: TeleportMode,
    /// How far its drivers' centre jumped, m.
    pub distance: f32,
    /// How far they turned, radians.
    pub angle: f32,
}

/// The cloth's solver and mesh were built: the first time, and again after a change of
/// its shape or pins, or a reload of its garment file (its particles are new).
#[derive(EntityEvent, Clone, Copy, Debug, PartialEq, Eq, Reflect)]
#[reflect(Debug, PartialEq)]
pub struct ClothBuilt {
    /// The cloth entity.
    pub entity: Entity,
}
