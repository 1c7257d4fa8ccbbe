//! How a cloth follows the bodies that hold it (its pins, attachments and skinned
//! targets) when they jump.

use bevy::reflect::Reflect;
use serde::{Deserialize, Serialize};

use super::check;
use crate::error::ClothError;

/// What a cloth does when the bodies holding it are teleported (Magica Cloth's and Chaos
/// Cloth's teleport modes, NvCloth's "teleport" call): the rigid motion that best carries
/// its drivers (pins, attachments, motion-constraint targets) from where they were to
/// where they are asked to be is applied to the whole cloth at once, instead of the pins
/// dragging the cloth across the gap over one step (which stretches it to tearing and
/// leaves it swinging, or through a wall between).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Reflect, Serialize, Deserialize)]
pub enum TeleportMode {
    /// Never: the pins drag the cloth however far they go.
    Off,
    /// The cloth's shape and motion carried rigidly with the bodies (its velocity turned
    /// with them): a cape on a character who walks through a portal keeps swinging.
    #[default]
    Keep,
    /// The shape carried rigidly and left at rest on the bodies (moving with them, without
    /// a swing of its own), each skinned particle (one with a motion constraint) placed
    /// on its target: a character respawned somewhere else.
    Reset,
}

/// When a cloth's drivers count as teleported, and what it does then
/// ([`TeleportMode`]). A step whose best rigid fit of the drivers' motion moves them
/// farther than `distance`, or turns them more than `angle_degrees`, is a teleport; a
/// game can also ask for one outright (`ClothSolver::teleport_next_step`, the plugin's
/// `ClothTeleport` message). A cloth with no pins, attachments or motion constraints has
/// no drivers to follow and never teleports by itself.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Teleport {
    /// What a teleport does (`Off`: the automatic one never happens; one asked for uses
    /// the mode it is asked with).
    pub mode: TeleportMode,
    /// The farthest the drivers' centre may move in one step before it is a teleport, m.
    /// The default 1 m is 62 m/s at the 16 ms step: faster than a game's characters run,
    /// slower than any respawn.
    pub distance: f32,
    /// The most the drivers may turn in one step before it is a teleport, degrees. The
    /// default 90° is 15 turns a second at the 16 ms step.
    pub angle_degrees: f32,
}

impl Default for Teleport {
    fn default() -> Self {
        Self {
            mode: TeleportMode::Keep,
            distance: 1.0,
            angle_degrees: 90.0,
        }
    }
}

impl Teleport {
    /// Checks the thresholds; the error names the field.
    pub(crate) fn validate(&self) -> Result<(), ClothError> {
        let max = crate::limits::MAX_POSITION;
        check(
            "teleport.distance",
            self.distance,
            self.distance > 0.0 && self.distance <= max,
            format!("a distance > 0 and at most {max:e} m (limits::MAX_POSITION)"),
        )?;
        check(
            "teleport.angle_degrees",
            self.angle_degrees,
            self.angle_degrees > 0.0 && self.angle_degrees <= 180.0,
            "an angle > 0 and at most 180 degrees",
        )
    }
}

/// How much of its drivers' motion a cloth feels as motion through the air (NvCloth's
/// local-space inertia, Magica Cloth's inertia and its movement and rotation speed
/// limits). The drivers (pins, attachments, motion-constraint targets) define a moving
/// frame, their best rigid fit step to step; a cloth feels the share `linear` of that
/// frame's change of velocity and the share `angular` of its change of turn: 1 is world
/// space (a cape whipped by every turn of its character as in the air), 0 is fully local
/// (the cloth carried along as if the frame stood still: a spinning character's cape
/// hangs as at rest). Frame motion faster than `max_speed` or `max_turn_speed` is not
/// felt at all: the excess carries the cloth rigidly.
#[derive(Clone, Copy, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Inertia {
    /// The share of the frame's linear acceleration the cloth feels, 0 to 1.
    pub linear: f32,
    /// The share of the frame's angular acceleration (and of the centrifugal and
    /// Coriolis pull of its turn) the cloth feels, 0 to 1.
    pub angular: f32,
    /// The fastest frame motion the cloth feels, m/s (`inf`: all of it); a body moving
    /// faster carries the cloth by the rest.
    pub max_speed: f32,
    /// The fastest frame turn the cloth feels, degrees a second (`inf`: all of it).
    pub max_turn_speed: f32,
}

impl Default for Inertia {
    fn default() -> Self {
        Self::WORLD
    }
}

impl Inertia {
    /// World space: the cloth feels all of its drivers' motion (the default).
    pub const WORLD: Inertia = Inertia {
        linear: 1.0,
        angular: 1.0,
        max_speed: f32::INFINITY,
        max_turn_speed: f32::INFINITY,
    };

    /// Feels `share` of both the frame's linear and angular acceleration, with no caps.
    pub fn scaled(share: f32) -> Self {
        Inertia {
            linear: share,
            angular: share,
            ..Self::WORLD
        }
    }

    /// Whether the cloth feels all of its drivers' motion (nothing to do).
    pub fn is_world(&self) -> bool {
        self.linear == 1.0
            && self.angular == 1.0
            && self.max_speed == f32::INFINITY
            && self.max_turn_speed == f32::INFINITY
    }

    /// Checks the shares and caps; the error names the field.
    pub(crate) fn validate(&self) -> Result<(), ClothError> {
        for (field, share) in [
            ("inertia.linear", self.linear),
            ("inertia.angular", self.angular),
        ] {
            check(
                field,
                share,
                (0.0..=1.0).contains(&share),
                "a share from 0 to 1",
            )?;
        }
        for (field, cap) in [
            ("inertia.max_speed", self.max_speed),
            ("inertia.max_turn_speed", self.max_turn_speed),
        ] {
            check(
                field,
                cap.min(crate::limits::MAX_POSITION),
                cap >= 0.0,
                "a speed ≥ 0 (`inf`: no cap)",
            )?;
        }
        Ok(())
    }
}
