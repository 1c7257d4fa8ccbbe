//! Teleports: when the drivers jump (a character respawned, through a portal, a cut in a
//! cutscene), the cloth is carried with them rigidly rather than dragged across the gap
//! by its pins (Magica Cloth's and Chaos Cloth's teleport modes; NvCloth's `teleport`).
//! The jump is told from the drivers alone: the rigid motion that best maps where they
//! were onto where they are asked to be (Horn 1987's fit, its rotation by the iterative
//! extraction of Müller et al. 2016), past a distance or an angle.

use bevy::math::{Affine3A, Mat3, Quat, Vec3};

use super::super::models::shape_matching::{extract_rotation, outer};
use super::super::{ClothSolver, ModelState};
use crate::params::TeleportMode;

/// A rigid motion: `x ↦ to_centre + rotation (x − from_centre)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidMove {
    /// The point that goes to `to_centre` (the drivers' centre before).
    pub from_centre: Vec3,
    /// Where it goes.
    pub to_centre: Vec3,
    /// The turn about it.
    pub rotation: Quat,
}

impl RigidMove {
    /// The move that does nothing.
    pub const IDENTITY: RigidMove = RigidMove {
        from_centre: Vec3::ZERO,
        to_centre: Vec3::ZERO,
        rotation: Quat::IDENTITY,
    };

    /// `affine` as a rigid move (its rotation part; a scale or shear is dropped).
    pub fn from_affine(affine: Affine3A) -> Self {
        let (_, rotation, translation) = affine.to_scale_rotation_translation();
        RigidMove {
            from_centre: Vec3::ZERO,
            to_centre: translation,
            rotation,
        }
    }

    /// Where it takes `x`.
    #[inline]
    pub fn apply(&self, x: Vec3) -> Vec3 {
        self.to_centre + self.rotation * (x - self.from_centre)
    }

    /// How far the centre moves, m.
    pub fn distance(&self) -> f32 {
        self.from_centre.distance(self.to_centre)
    }

    /// How far it turns, radians in [0, π].
    pub fn angle(&self) -> f32 {
        2.0 * self.rotation.w.abs().min(1.0).acos()
    }

    /// What is left of this move (of points that `last` brought to `from_centre` in the
    /// step before) once `last` is continued one more step: the jump beyond the drivers'
    /// ordinary motion (their velocity and turn kept), which a teleport carries the cloth
    /// by, so that the step then sweeps the pins as it would have without the jump.
    pub fn beyond(&self, last: &RigidMove) -> RigidMove {
        RigidMove {
            from_centre: self.from_centre + (last.to_centre - last.from_centre),
            to_centre: self.to_centre,
            rotation: (self.rotation * last.rotation.inverse()).normalize(),
        }
    }

    /// The move back.
    pub fn inverse(&self) -> RigidMove {
        RigidMove {
            from_centre: self.to_centre,
            to_centre: self.from_centre,
            rotation: self.rotation.inverse(),
        }
    }

    /// The rigid move that best carries each `from` onto its `to` (least squares, equal
    /// weights): the centres' difference and the rotation part of `Σ (to − c_to)(from −
    /// c_from)ᵀ`, found from the identity, so points on a line or one point give the least
    /// turn that fits. `None` for no points.
    pub fn fit(pairs: impl Iterator<Item = (Vec3, Vec3)> + Clone) -> Option<Self> {
        let (mut count, mut from_sum, mut to_sum) = (0u32, Vec3::ZERO, Vec3::ZERO);
        for (from, to) in pairs.clone() {
            count += 1;
            from_sum += from;
            to_sum += to;
        }
        if count == 0 {
            return None;
        }
        let (from_centre, to_centre) = (from_sum / count as f32, to_sum / count as f32);
        let mut a = Mat3::ZERO;
        for (from, to) in pairs {
            a += outer(to - to_centre, from - from_centre);
        }
        Some(RigidMove {
            from_centre,
            to_centre,
            rotation: extract_rotation(&a, Quat::IDENTITY),
        })
    }
}

/// A teleport a step made: how far and how much its drivers jumped, and what the cloth
/// did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Teleported {
    /// What the cloth did.
    pub mode: TeleportMode,
    /// The move it was carried by.
    pub by: RigidMove,
    /// How far the drivers' centre moved, m.
    pub distance: f32,
    /// How far they turned, radians.
    pub angle: f32,
}

impl ClothSolver {
    /// Treats the next step's move of the drivers (pins, attachments, motion-constraint
    /// targets), however small, as a teleport done by `mode` ([`TeleportMode::Off`]:
    /// takes back a request). Call it when a game moves the body the cloth hangs on to a
    /// new place, with the body's new pose set as usual.
    pub fn teleport_next_step(&mut self, mode: TeleportMode) {
        self.teleport_request = (mode != TeleportMode::Off).then_some(mode);
        self.disturbed = true;
    }

    /// The rigid move of the cloth's drivers this step asks for: each pin from where its
    /// particle is to its goal (or where the frame puts it), each motion-constraint
    /// target from last step's to the next. `None` with no drivers.
    fn drivers_move(&self) -> Option<RigidMove> {
        let d = &self.drivers;
        let x = &self.particles.position;
        let rest = &self.structure.local_rest;
        let pins = d.pins.iter().zip(&d.pin_goal).map(|(&i, goal)| {
            let i = i as usize;
            let to = goal.unwrap_or_else(|| d.frame.transform_point3(rest[i]));
            (x[i], to)
        });
        let m = &d.motion;
        let targets = if m.to.len() == m.next.len() {
            &m.to[..]
        } else {
            &[]
        };
        let motion = targets.iter().copied().zip(m.next.iter().copied());
        RigidMove::fit(pins.chain(motion))
    }

    /// At a step's start, the cloth follows its drivers: when they jump past the
    /// thresholds of [`Teleport`](crate::params::Teleport) (or a teleport was asked for),
    /// it is carried with them ([`ClothSolver::carry`]); otherwise it feels the share of
    /// their motion its [`Inertia`](crate::params::Inertia) sets.
    pub(in crate::solver) fn follow_drivers(&mut self, dt: f32) {
        let request = self.teleport_request.take();
        let (settings, inertia) = (self.params.teleport, self.params.inertia);
        let last = self.drivers_motion.take();
        let watch = settings.mode != TeleportMode::Off;
        if inertia.is_world() {
            self.felt.clear();
            if request.is_none() && !watch {
                return;
            }
        }
        let Some(jump) = self.drivers_move() else {
            return;
        };
        let past = watch
            && (jump.distance() > settings.distance
                || jump.angle() > settings.angle_degrees.to_radians());
        if let Some(mode) = request.or(past.then_some(settings.mode)) {
            self.drivers_motion = last;
            self.felt.clear();
            self.teleport(jump, last, mode, dt);
        } else {
            self.drivers_motion = Some(jump);
            if !inertia.is_world() {
                self.feel(jump, dt);
            }
        }
    }

    /// Carries the cloth by the jump `jump` (beyond `last`, the drivers' ordinary step)
    /// as `mode` says, and reports it.
    fn teleport(&mut self, jump: RigidMove, last: Option<RigidMove>, mode: TeleportMode, dt: f32) {
        // Carried by the jump beyond the drivers' ordinary step (the last one's motion
        // continued), which the step then sweeps them through as it would have anyway.
        let by = last.map_or(jump, |last| jump.beyond(&last));
        self.carry(by, mode);
        if let (TeleportMode::Reset, Some(last)) = (mode, last) {
            // At rest on the bodies: each particle moving as their ordinary step (the last
            // one's, continued from where the jump left them) carries the point it is at.
            let ordinary = RigidMove {
                from_centre: jump.from_centre,
                to_centre: jump.from_centre + (last.to_centre - last.from_centre),
                rotation: last.rotation,
            };
            self.move_with(|x| by.apply(ordinary.apply(by.inverse().apply(x))), dt);
        }
        self.report.teleported = Some(Teleported {
            mode,
            by,
            distance: jump.distance(),
            angle: jump.angle(),
        });
    }

    /// Gives each free particle the velocity that takes it to `step(x)` over `dt`.
    fn move_with(&mut self, step: impl Fn(Vec3) -> Vec3, dt: f32) {
        let h = self.clock.h;
        let p = &mut self.particles;
        for i in 0..p.len() {
            if p.inv_mass[i] != 0.0 {
                let x = p.position[i];
                p.velocity[i] = (step(x) - x) / dt;
                p.previous[i] = x - p.velocity[i] * h;
            }
        }
    }

    /// Carries the whole cloth by the rigid move `by` at once: every particle (the pinned
    /// ones too), its previous position and its velocity (turned with it) for
    /// [`TeleportMode::Keep`]; for [`TeleportMode::Reset`] left at rest, and each particle
    /// with a motion constraint placed on its target (where the step starts it). The
    /// drivers' last targets are carried too (the step sweeps them from there to where they
    /// are asked to be), and the state a failed step returns to is the carried one. `Off`
    /// does nothing.
    pub fn carry(&mut self, by: RigidMove, mode: TeleportMode) {
        if mode == TeleportMode::Off {
            return;
        }
        let keep = mode == TeleportMode::Keep;
        self.move_rigidly(by, keep);
        let (p, m) = (&mut self.particles, &self.drivers.motion);
        if !keep {
            // On the pose the step starts from (the next one before any step has run).
            let pose = if m.to.len() == p.len() {
                &m.to
            } else {
                &m.next
            };
            if pose.len() == p.len() {
                for (i, (&r, &target)) in m.radius.iter().zip(pose).enumerate() {
                    if r.is_finite() {
                        p.position[i] = target;
                    }
                }
            }
            p.previous.clone_from(&p.position);
        }
        match &mut self.model {
            ModelState::ShapeMatching(_) if keep => {}
            ModelState::ShapeMatching(s) => s.reset(),
            // The part lattice is rebuilt where the particles now are.
            ModelState::Patches(_) => self.model = ModelState::None,
            _ => {}
        }
        self.switch = None;
        self.save_checkpoint();
        self.disturbed = true;
    }

    /// Moves every particle (the pinned ones too) by `by`, with its previous position
    /// and velocity turned with it when `keep` (at rest otherwise), the drivers' last
    /// targets with them (the step sweeps them from there to where they are asked to be)
    /// and shape matching's warm-start rotations.
    pub(in crate::solver) fn move_rigidly(&mut self, by: RigidMove, keep: bool) {
        let p = &mut self.particles;
        for i in 0..p.len() {
            p.position[i] = by.apply(p.position[i]);
            if keep {
                p.previous[i] = by.apply(p.previous[i]);
                p.velocity[i] = by.rotation * p.velocity[i];
                p.residue[i] = by.rotation * p.residue[i];
            } else {
                p.velocity[i] = Vec3::ZERO;
                p.residue[i] = Vec3::ZERO;
            }
        }
        let m = &mut self.drivers.motion;
        for x in &mut m.to {
            *x = by.apply(*x);
        }
        for n in &mut m.normal_to {
            *n = by.rotation * *n;
        }
        if let ModelState::ShapeMatching(s) = &mut self.model {
            s.turn(by.rotation);
        }
    }
}
