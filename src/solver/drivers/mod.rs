//! Kinematic drivers: what moves particles by prescription rather than by force. Pins
//! follow the cloth's frame and a grabbed particle follows its tool, both over the
//! substeps of a step; seams shorten from their starting gap to their rest length over
//! the sewing time (Maslova §1.4); motion constraints keep particles within a distance
//! of targets that move (NvCloth's motion constraints, Unreal's painted max distance: a
//! skirt on a walking body), and off a sphere behind their targets (a back stop: Jolt's
//! skinned constraints, NvCloth's separation constraints).

pub(super) mod inertia;
pub(super) mod interact;
pub(super) mod teleport;

use bevy::math::{Affine3A, Vec3};

use super::{ClothSolver, Grab, ModelState, Particles, SpringKind};
use crate::error::ClothError;

/// What holds particles from outside: the pins (the layout's, then the attached ones),
/// the frame they follow, and a grab.
#[derive(Clone, Debug)]
pub(super) struct Drivers {
    /// Pinned particles: the layout's (the first `fixed_pins`), then the attached ones.
    pub pins: Vec<u32>,
    /// Each pin's world target when set from outside (an attachment), `None` for a pin
    /// that follows the frame.
    pub pin_goal: Vec<Option<Vec3>>,
    pub fixed_pins: usize,
    /// Where each pin was at the start of the step, and where it ends it.
    pub pin_from: Vec<Vec3>,
    pub pin_to: Vec<Vec3>,
    /// The frame (local → world) the pins follow.
    pub frame: Affine3A,
    pub grab: Option<Grab>,
    /// Motion constraints (empty: none).
    pub motion: MotionConstraints,
}

/// Motion constraints: each particle with a finite `radius` kept within it of its
/// target, which goes from `from` to `to` over the step as pins do. A radius of 0 makes
/// the particle an attached pin instead (exactly at its target); `f32::INFINITY`, free.
/// With back stops, each particle is also kept out of a sphere behind its target along
/// the targets' normal (`normal_from` to `normal_to` over the step).
#[derive(Clone, Debug, Default)]
pub(super) struct MotionConstraints {
    pub from: Vec<Vec3>,
    pub to: Vec<Vec3>,
    pub radius: Vec<f32>,
    /// The targets given for the next step.
    pub next: Vec<Vec3>,
    /// Each particle's place among the pins while the constraints are set (kept for its
    /// storage).
    pub slot: Vec<u32>,
    /// One per particle (empty: none).
    pub back_stop: Vec<BackStop>,
    /// The targets' unit normals at the step's start and end, and for the next step (from
    /// the cloth's triangles at the targets); empty without back stops.
    pub normal_from: Vec<Vec3>,
    pub normal_to: Vec<Vec3>,
    pub normal_next: Vec<Vec3>,
}

/// A back stop (Jolt's skinned constraint, NvCloth's separation constraint, Chaos's
/// backstop): the particle is kept outside a sphere of `radius` m whose surface lies
/// `distance` m behind its target, along the target's normal (the centre at
/// `target − normal · (distance + radius)`), so a skinned cloth cannot swing into the body
/// it lies on without a collider per bone. "Behind" is against the side the cloth's
/// triangles face (their counter-clockwise winding, the side a mesh's normals point to).
/// It acts only while `distance` is less than the particle's maximum distance (Jolt's
/// rule: otherwise the max distance already keeps the particle off it). A radius of 0
/// is no back stop.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BackStop {
    /// How far behind its target the particle may go, m (≥ 0).
    pub distance: f32,
    /// The sphere's radius, m (≥ 0; 0: none). A large radius makes the back stop a plane
    /// at `distance` behind the target; a small one lets the particle round it sideways.
    pub radius: f32,
}

impl BackStop {
    /// Moves `x` out of this back stop's sphere behind `target` along `normal` (the targets'
    /// normal, any length): out to its surface the nearest way, along the line from its
    /// centre. Whether it moved.
    #[inline(always)]
    fn keep_out(&self, x: &mut Vec3, target: Vec3, normal: Vec3) -> bool {
        // In front of its target a particle is outside the sphere, whose surface lies
        // `distance` ≥ 0 behind it: no normal to make unit.
        if (*x - target).dot(normal) > 0.0 {
            return false;
        }
        let n = normal.normalize_or_zero();
        let centre = target - n * (self.distance + self.radius);
        let off = *x - centre;
        let l2 = off.length_squared();
        let inside = l2 < self.radius * self.radius;
        if inside {
            let out = if l2 > 0.0 { off / l2.sqrt() } else { n };
            *x = centre + out * self.radius;
        }
        inside
    }
}

impl MotionConstraints {
    /// Starts a step: the targets (and their normals) go from where the last step's ended
    /// to those given.
    fn begin_step(&mut self) {
        if self.next.len() != self.to.len() {
            self.to.clone_from(&self.next);
        }
        std::mem::swap(&mut self.from, &mut self.to);
        self.to.clone_from(&self.next);
        if self.normal_next.len() != self.normal_to.len() {
            self.normal_to.clone_from(&self.normal_next);
        }
        std::mem::swap(&mut self.normal_from, &mut self.normal_to);
        self.normal_to.clone_from(&self.normal_next);
    }

    /// Pulls each constrained free particle back within its radius of where its target
    /// is a fraction `t` through the step, then out of its back stop, with the velocity
    /// that leaves it there. The back stop acts last, as the one a body cannot do without
    /// (Jolt applies it first; the order matters only where the two spheres' surfaces
    /// cross, and there this one keeps the particle out of the body).
    pub fn hold(&self, p: &mut Particles, t: f32, h: f32) {
        let n = self.radius.len();
        // Every array sliced to the constraints' length once, so that the loop indexes
        // without a bounds check a particle (this runs every substep on every particle
        // of a skinned cloth).
        let (from, to, radius) = (&self.from[..n], &self.to[..n], &self.radius[..n]);
        let (x, velocity) = (&mut p.position[..n], &mut p.velocity[..n]);
        let (previous, w) = (&p.previous[..n], &p.inv_mass[..n]);
        let stops = self.stops(n);
        for i in 0..n {
            if w[i] == 0.0 {
                continue;
            }
            let (target, r) = (from[i].lerp(to[i], t), radius[i]);
            let mut moved = false;
            if r.is_finite() {
                let off = x[i] - target;
                let l2 = off.length_squared();
                if l2 > r * r {
                    x[i] = target + off * (r / l2.sqrt());
                    moved = true;
                }
            }
            if let Some((stop, normal_from, normal_to)) = stops
                && stop[i].radius > 0.0
                && stop[i].distance < r
            {
                let normal = normal_from[i].lerp(normal_to[i], t);
                moved |= stop[i].keep_out(&mut x[i], target, normal);
            }
            if moved {
                velocity[i] = (x[i] - previous[i]) / h;
            }
        }
    }

    /// The back stops and their targets' normals at the step's start and end, each of
    /// `n`; `None` when there are none (or no normals yet).
    fn stops(&self, n: usize) -> Option<(&[BackStop], &[Vec3], &[Vec3])> {
        Some((
            self.back_stop.get(..n)?,
            self.normal_from.get(..n)?,
            self.normal_to.get(..n)?,
        ))
    }

    /// The targets' normals for the next step, from the cloth's triangles at the targets
    /// (what the back stops push along).
    fn aim_normals(&mut self, structure: &super::structure::Structure) {
        self.normal_next.clear();
        if self.back_stop.is_empty() || self.next.len() != self.back_stop.len() {
            return;
        }
        self.normal_next.resize(self.next.len(), Vec3::ZERO);
        structure.normal_sums_into(&self.next, &mut self.normal_next);
        super::unit::normalize_each_or(&mut self.normal_next, Vec3::ZERO);
    }
}

impl Drivers {
    /// The layout's `pins`, following `frame`.
    pub fn new(pins: &[u32], frame: Affine3A) -> Self {
        Drivers {
            pin_from: Vec::with_capacity(pins.len()),
            pin_to: Vec::with_capacity(pins.len()),
            pin_goal: vec![None; pins.len()],
            fixed_pins: pins.len(),
            pins: pins.to_vec(),
            frame,
            grab: None,
            motion: MotionConstraints::default(),
        }
    }

    /// Drops the attachments and the grab; the pins hold their particles where they are.
    pub fn reset(&mut self, p: &mut Particles) {
        self.grab = None;
        self.pins.truncate(self.fixed_pins);
        self.pin_goal.clear();
        self.pin_goal.resize(self.fixed_pins, None);
        for &i in &self.pins {
            p.inv_mass[i as usize] = 0.0;
        }
        self.pin_to.clear();
        self.pin_to
            .extend(self.pins.iter().map(|&i| p.position[i as usize]));
        self.pin_from.clone_from(&self.pin_to);
    }

    /// Starts a step: pins go from where they are to where the frame (or their goal) puts
    /// them, over the substeps; a grab from where its particle is.
    pub fn begin_step(&mut self, x: &[Vec3], local_rest: &[Vec3]) {
        std::mem::swap(&mut self.pin_from, &mut self.pin_to);
        for (k, &i) in self.pins.iter().enumerate() {
            self.pin_to[k] = self.pin_goal[k]
                .unwrap_or_else(|| self.frame.transform_point3(local_rest[i as usize]));
            self.pin_from[k] = x[i as usize];
        }
        if let Some(g) = &mut self.grab {
            g.from = x[g.particle as usize];
        }
        if !self.motion.radius.is_empty() {
            self.motion.begin_step();
        }
    }

    /// Where pin `k` is a fraction `t` through the step.
    pub fn pin_at(&self, k: usize, t: f32) -> Vec3 {
        self.pin_from[k].lerp(self.pin_to[k], t)
    }

    /// Moves the pinned and grabbed particles to where their drivers put them a fraction
    /// `t` through the step, with the velocity that takes them there this substep of `h`.
    pub fn drive(&self, p: &mut Particles, t: f32, h: f32) {
        for (k, &i) in self.pins.iter().enumerate() {
            p.move_to(i as usize, self.pin_at(k, t), h);
        }
        if let Some(g) = self.grab {
            p.move_to(g.particle as usize, g.from.lerp(g.target, t), h);
        }
    }
}

impl ClothSolver {
    /// Holds particle `i` at the world point `target`: an attachment to an outside body
    /// (a character's shoulder, a mast) that the caller moves every step. Like a pin the
    /// particle is kinematic and goes from where it is to `target` over the next step's
    /// substeps, so a body moving each step is followed with no lag beyond that step.
    /// Calling it again for an attached particle (or a pin) moves its target. It lasts
    /// until [`ClothSolver::detach`] or a reset; the patch model's parts are rebuilt to
    /// hang from it.
    pub fn attach(&mut self, i: u32, target: Vec3) -> Result<(), ClothError> {
        let slot = self.drivers.pins.iter().position(|&p| p == i);
        self.attach_in(i, target, slot)
    }

    /// [`ClothSolver::attach`] with the particle's place among the pins known (`None`:
    /// not held yet).
    fn attach_in(&mut self, i: u32, target: Vec3, slot: Option<usize>) -> Result<(), ClothError> {
        let count = self.particles.len();
        if i as usize >= count {
            return Err(ClothError::PinOutOfRange { index: i, count });
        }
        if !(target.is_finite() && target.length() <= crate::limits::MAX_POSITION) {
            return Err(ClothError::InvalidParameter {
                field: "attachment target",
                value: target.length(),
                expected: format!(
                    "a finite point within {:e} m (limits::MAX_POSITION)",
                    crate::limits::MAX_POSITION
                )
                .into(),
            });
        }
        if let Some(k) = slot {
            self.disturbed |= self.drivers.pin_goal[k] != Some(target);
            self.drivers.pin_goal[k] = Some(target);
            return Ok(());
        }
        let x = self.particles.position[i as usize];
        self.drivers.pins.push(i);
        self.drivers.pin_goal.push(Some(target));
        self.drivers.pin_from.push(x);
        self.drivers.pin_to.push(x);
        self.particles.inv_mass[i as usize] = 0.0;
        self.held_changed();
        Ok(())
    }

    /// Lets an attached particle go (a pin of the layout goes back to following the
    /// frame). False when it was neither.
    pub fn detach(&mut self, i: u32) -> bool {
        let Some(k) = self.drivers.pins.iter().position(|&p| p == i) else {
            return false;
        };
        if k < self.drivers.fixed_pins {
            self.drivers.pin_goal[k] = None;
        } else {
            self.drivers.pins.remove(k);
            self.drivers.pin_goal.remove(k);
            self.drivers.pin_from.remove(k);
            self.drivers.pin_to.remove(k);
            let p = &mut self.particles;
            p.inv_mass[i as usize] = 1.0 / p.mass[i as usize];
            self.held_changed();
        }
        self.disturbed = true;
        true
    }

    /// Motion constraints for the next step and on (NvCloth's motion constraints, a
    /// painted "max distance"): particle `i` is kept within `max_distance[i]` m of
    /// `targets[i]` (world points, such as where the character's skinning puts the
    /// vertex), the targets moving from the last step's to these over the step's
    /// substeps. A distance of 0 attaches the particle to its target
    /// ([`ClothSolver::attach`]: exactly there at the step's end); `f32::INFINITY` leaves
    /// it free. Each substep they act after self-collision and before contact, so a
    /// collider between a particle and its target wins (a leg pushes a skirt out farther
    /// than its distance rather than through the leg). Call it before each step with the
    /// targets for that step's end; both slices have one entry per particle.
    pub fn set_motion_constraints(
        &mut self,
        targets: &[Vec3],
        max_distance: &[f32],
    ) -> Result<(), ClothError> {
        let n = self.particles.len();
        if targets.len() != n || max_distance.len() != n {
            return Err(ClothError::InvalidParameter {
                field: "motion constraints",
                value: targets.len().max(max_distance.len()) as f32,
                expected: "one target and one distance per particle".into(),
            });
        }
        if let Some(&r) = max_distance.iter().find(|r| r.is_nan() || **r < 0.0) {
            return Err(ClothError::InvalidParameter {
                field: "motion constraint distance",
                value: r,
                expected: "a distance ≥ 0 m (f32::INFINITY: free)".into(),
            });
        }
        let was = std::mem::take(&mut self.drivers.motion.radius);
        // Each particle's place among the pins (`u32::MAX`: none), so that holding a
        // body's thousands of particles of distance 0 is a lookup each, not a search of
        // the pins. Attaching only appends pins, which keeps the places; the particles
        // let go (rare: their distance was painted anew) are detached after.
        let mut slot = std::mem::take(&mut self.drivers.motion.slot);
        slot.clear();
        slot.resize(n, u32::MAX);
        for (k, &p) in self.drivers.pins.iter().enumerate() {
            slot[p as usize] = k as u32;
        }
        for (i, (&r, &target)) in max_distance.iter().zip(targets).enumerate() {
            if r == 0.0 {
                let held = (slot[i] != u32::MAX).then_some(slot[i] as usize);
                self.attach_in(i as u32, target, held)?;
            }
        }
        for (i, &r) in max_distance.iter().enumerate() {
            if r != 0.0 && was.get(i) == Some(&0.0) {
                self.detach(i as u32);
            }
        }
        let motion = &mut self.drivers.motion;
        motion.slot = slot;
        motion.radius = was;
        motion.radius.clear();
        motion.radius.extend_from_slice(max_distance);
        motion.next.clear();
        motion.next.extend_from_slice(targets);
        motion.aim_normals(&self.structure);
        self.disturbed = true;
        Ok(())
    }

    /// Back stops for the motion constraints, one per particle ([`BackStop`]: each
    /// particle kept out of a sphere behind its target, along the targets' normal, as
    /// Jolt's skinned constraints do). They act with the motion constraints
    /// ([`ClothSolver::set_motion_constraints`]), from the next step on, until
    /// [`ClothSolver::clear_motion_constraints`] or an empty slice.
    pub fn set_back_stops(&mut self, stops: &[BackStop]) -> Result<(), ClothError> {
        let n = self.particles.len();
        if !stops.is_empty() && stops.len() != n {
            return Err(ClothError::InvalidParameter {
                field: "back stops",
                value: stops.len() as f32,
                expected: format!("one back stop per particle ({n}), or none").into(),
            });
        }
        let limit = crate::limits::MAX_POSITION;
        let bad = |d: f32| !(0.0..=limit).contains(&d);
        if let Some(s) = stops.iter().find(|s| bad(s.distance) || bad(s.radius)) {
            let (field, value) = if bad(s.distance) {
                ("back stop distance", s.distance)
            } else {
                ("back stop radius", s.radius)
            };
            return Err(ClothError::InvalidParameter {
                field,
                value,
                expected: format!("a distance from 0 to {limit:e} m (limits::MAX_POSITION)").into(),
            });
        }
        let motion = &mut self.drivers.motion;
        motion.back_stop.clear();
        motion.back_stop.extend_from_slice(stops);
        motion.aim_normals(&self.structure);
        self.disturbed = true;
        Ok(())
    }

    /// Drops the motion constraints; the particles they attached are let go.
    pub fn clear_motion_constraints(&mut self) {
        let radius = std::mem::take(&mut self.drivers.motion.radius);
        for (i, &r) in radius.iter().enumerate() {
            if r == 0.0 {
                self.detach(i as u32);
            }
        }
        self.drivers.motion = MotionConstraints::default();
    }

    /// The particles held from outside ([`ClothSolver::attach`]), in order.
    pub fn attached(&self) -> &[u32] {
        &self.drivers.pins[self.drivers.fixed_pins..]
    }

    /// The set of held particles changed: the patch model's part lattice is rebuilt (its
    /// parts hang from the pins) by the next step.
    fn held_changed(&mut self) {
        if matches!(self.model, ModelState::Patches(_)) {
            self.model = ModelState::None;
        }
        self.disturbed = true;
    }

    /// Seam springs shrink from their starting gap to `seam_rest_length` over `sew_time`
    /// seconds of simulated time (a tailor sewing the pieces together).
    pub(super) fn sew(&mut self) {
        let s = &self.params.springs;
        let progress = if s.sew_time > 0.0 {
            (self.clock.time / s.sew_time).min(1.0)
        } else {
            1.0
        };
        let seams = self.structure.springs.ranges[SpringKind::Seam as usize].clone();
        for (rest, &start) in self.structure.springs.rest_length[seams]
            .iter_mut()
            .zip(&self.structure.seam_start)
        {
            *rest = start + (s.seam_rest_length - start) * progress;
        }
    }

    /// True while the seams of a garment are still being sewn (see `sew_time`).
    pub fn sewing(&self) -> bool {
        !self.structure.seam_start.is_empty()
            && self.clock.time < self.params.springs.sew_time
            && self.params.springs.seam.effective() > 0.0
    }
}
