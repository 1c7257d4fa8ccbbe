//! The contact stage: particles kept out of the colliders (shapes and distances in
//! `collide.rs`), with Coulomb friction against the surface's own motion, and the
//! reaction each collider takes.

use bevy::math::{Quat, Vec3};

use super::collide::{Bounds, Collider, ColliderImpulse};
use super::{ClothSolver, Particles};

/// The colliders a cloth meets and the scratch of its contact stage.
#[derive(Clone, Debug, Default)]
pub(super) struct Contact {
    /// Colliders in world space the particles are kept out of.
    pub colliders: Vec<Collider>,
    /// The colliders before the last `set_colliders` (kept to tell a change, and for
    /// their storage).
    pub colliders_spare: Vec<Collider>,
    /// Each collider's bounding box grown by its thickness (the broad phase).
    pub collider_bounds: Vec<Bounds>,
    /// Whether any collider moves (then each substep places them in `colliders_now`).
    pub colliders_move: bool,
    /// The moving colliders where they are at the current substep, and their boxes.
    pub colliders_now: Vec<Collider>,
    pub bounds_now: Vec<Bounds>,
    /// Each moving collider's turn over the current substep.
    pub turns_now: Vec<Quat>,
    /// What the cloth gave each collider over the step.
    pub collider_impulses: Vec<ColliderImpulse>,
}

impl Contact {
    /// Takes `colliders` in place of the last ones (both keep their storage: no
    /// allocation once grown). Returns false when they are the same (the plugin sets them
    /// every step): then everything derived from them holds.
    pub fn replace(&mut self, colliders: impl IntoIterator<Item = Collider>) -> bool {
        std::mem::swap(&mut self.colliders, &mut self.colliders_spare);
        self.colliders.clear();
        self.colliders.extend(colliders);
        // One impulse sum per collider (zeroed by each step).
        self.collider_impulses
            .resize(self.colliders.len(), ColliderImpulse::default());
        if self.colliders_spare == self.colliders {
            return false;
        }
        self.collider_bounds.clear();
        self.collider_bounds
            .extend(self.colliders.iter().map(Collider::bounds));
        self.colliders_move = self.colliders.iter().any(|c| !c.motion.is_still());
        true
    }

    /// Whether a collider that the last [`Contact::replace`] changed or removed reaches
    /// the box `cloth`: only such a change can move the cloth.
    /// Colliders are compared place by place, in linear time (the plugin places them in
    /// the same order every step; a reordered list counts as changed, which only wakes).
    pub fn change_reaches(&self, cloth: &Bounds) -> bool {
        let (now, before) = (&self.colliders, &self.colliders_spare);
        let near = |c: &Collider| c.bounds().overlaps(cloth);
        let mut changed = now.iter().zip(before).filter(|(n, b)| n != b);
        let changed = changed.any(|(n, b)| near(n) || near(b));
        let added_or_gone = now
            .iter()
            .skip(before.len())
            .chain(before.iter().skip(now.len()));
        changed || added_or_gone.into_iter().any(near)
    }

    /// Places the moving colliders where they are at the end of the current substep:
    /// swept back by the time `tau` left in the step (the step's colliders are where it
    /// ends), with their turn over a substep of `h`.
    fn place_moving(&mut self, tau: f32, h: f32) {
        self.colliders_now.clear();
        self.colliders_now.extend(self.colliders.iter().map(|c| {
            if c.motion.is_still() {
                c.clone()
            } else {
                c.swept_back(tau)
            }
        }));
        self.bounds_now.clear();
        self.bounds_now
            .extend(self.colliders_now.iter().map(Collider::bounds));
        self.turns_now.clear();
        self.turns_now.extend(
            self.colliders_now
                .iter()
                .map(|c| Quat::from_scaled_axis(c.motion.angular * h)),
        );
    }

    /// Pushes every free particle out of every collider to `thickness` outside its
    /// surface, then removes tangential motion of this substep up to `friction × push`
    /// (Coulomb). Velocities follow the corrected positions: `v = (x − x_prev)/h`. `tau`
    /// is the time left in the step after this substep.
    pub fn resolve(&mut self, p: &mut Particles, tau: f32, h: f32) {
        if self.colliders.is_empty() {
            return;
        }
        if self.colliders_move {
            self.place_moving(tau, h);
        }
        let (colliders, bounds) = if self.colliders_move {
            (&self.colliders_now, &self.bounds_now)
        } else {
            (&self.colliders, &self.collider_bounds)
        };
        for i in 0..p.position.len() {
            if p.inv_mass[i] == 0.0 {
                continue;
            }
            let mut x = p.position[i];
            let mut touched = false;
            for (k, (c, bounds)) in colliders.iter().zip(bounds).enumerate() {
                if !bounds.contains(x) {
                    continue; // farther than the thickness: the distance would say so
                }
                let Some((depth, n)) = c.penetration(x) else {
                    continue;
                };
                let before = x;
                let turn = self.turns_now.get(k).copied().unwrap_or_default();
                x = push_out(c, x, depth, n, p.previous[i], turn, h);
                touched = true;
                // The reaction: the particle's momentum change, the other way.
                let push = (x - before) / (p.inv_mass[i] * h);
                self.collider_impulses[k].linear -= push;
                self.collider_impulses[k].angular -= x.cross(push);
            }
            if touched {
                p.position[i] = x;
                p.velocity[i] = (x - p.previous[i]) / h;
            }
        }
    }
}

/// `x` pushed out of `c` by `depth` along `n`, then its tangential motion since
/// `previous` removed up to `friction × depth`. Friction acts on the motion relative to
/// the surface under the particle: a particle that sticks moves with the body's point
/// where it was (`turn`: the body's turn over the substep).
fn push_out(
    c: &Collider,
    x: Vec3,
    depth: f32,
    n: Vec3,
    previous: Vec3,
    turn: Quat,
    h: f32,
) -> Vec3 {
    let x = x + n * depth;
    let mut moved = x - previous;
    if !c.motion.is_still() {
        moved -= c.motion.carry(turn, h, previous);
    }
    let tangential = moved - n * moved.dot(n);
    let slide = tangential.length();
    let grip = c.friction * depth;
    x - if slide <= grip {
        tangential
    } else {
        tangential * (grip / slide)
    }
}

impl ClothSolver {
    /// What the cloth gave each collider (in [`ClothSolver::colliders`]' order) over the
    /// last step: the reaction a physics engine applies to a dynamic body, so a cloth
    /// pushed by a ball pushes back.
    pub fn collider_impulses(&self) -> &[ColliderImpulse] {
        &self.contact.collider_impulses
    }

    /// Replaces the colliders the particles are kept out of (world space); reuses its
    /// storage, so calling it every step allocates nothing once it has grown.
    pub fn set_colliders(&mut self, colliders: impl IntoIterator<Item = Collider>) {
        if !self.contact.replace(colliders) {
            return;
        }
        let cloth = Bounds::around(&self.particles.position);
        self.disturbed |= self.contact.change_reaches(&cloth);
        // The part centres meet the colliders too: otherwise the targets sink into a
        // collider and pull the particles in after it.
        if let Some(patches) = self.model.patches_mut() {
            patches
                .parts
                .set_colliders(self.contact.colliders.iter().cloned());
        }
    }

    /// The colliders in use.
    pub fn colliders(&self) -> &[Collider] {
        &self.contact.colliders
    }
}
