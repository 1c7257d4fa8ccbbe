//! Contact: the colliders ([`Collider`], each a solid of [`shapes`] with a thickness,
//! friction and motion) and the contact stage, which keeps the particles out of them with
//! Coulomb friction against the surface's own motion and sums the reaction each collider
//! takes.

use crate::solver::state::mark;
use bevy::math::{Quat, Vec3};

mod carry;
mod collider;
mod edges;
pub(super) mod self_contact;
pub mod shapes;

pub(crate) use collider::Bounds;
pub use collider::{Collider, ColliderImpulse, Motion};
pub(in crate::solver) use edges::EDGES;
use edges::axis;

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
    /// One particle's pushes by collider (scratch, kept for its storage).
    pub pushes: Vec<(usize, Vec3)>,
    /// The capsules and cylinders thinner than the cloth's longest edge, which the edge
    /// pass tests (set with the colliders: neither changes between steps).
    pub thin: Vec<usize>,
    /// The overlaps lifted out this substep, and the cloth carried out with them
    /// ([`Contact::carry`]).
    pub carry: carry::Carry,
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

    /// Keeps every free particle `thickness` outside every collider, order-independently,
    /// with Coulomb friction once per particle; velocities follow the corrected positions,
    /// `v = (x − x_prev)/h`. `tau` is the time left in the step after this substep.
    ///
    /// Per particle (`resolve_particle`): its path over the substep is swept against each
    /// collider it starts outside of, so a fast particle stops at the near face of a thin
    /// plate rather than crossing it; then, at most [`CONTACT_PASSES`] times, it is pushed
    /// out of the collider it is deepest in (the deepest, not the first listed: the same
    /// answer in any order). The part of a push deeper than the particle's own motion
    /// undoes an overlap it started in (spawned inside, a collider that jumped): its
    /// `previous` moves out with it (pre-stabilisation, Macklin et al. 2014 §5.2), so that
    /// part adds no velocity. That part is at most `depenetration` (m) a substep: a
    /// particle that started deep inside comes out over several (PhysX's maximum
    /// depenetration velocity), so the cloth's constraints are not yanked by a push of
    /// its whole depth and do not launch it. Deeper than that, it leaves along the
    /// cloth's own normal where that leads out (`normal(x, i)`: particle `i`'s normal,
    /// any length, at positions `x`), and keeps no motion back in.
    /// Each particle it moves is marked in `touched`.
    pub fn resolve(
        &mut self,
        p: &mut Particles,
        (tau, h, depenetration): (f32, f32, f32),
        normal: impl Fn(&[Vec3], usize) -> Vec3,
        touched: &mut [bool],
    ) {
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
        let world = World {
            colliders,
            bounds,
            turns: &self.turns_now,
            h,
            depenetration,
        };
        let pushes = &mut self.pushes;
        self.carry.begin(p.position.len());
        for i in 0..p.position.len() {
            let w = p.inv_mass[i];
            let left = self.carry.take_left(i);
            if w == 0.0 {
                continue;
            }
            let (x, previous) = (p.position[i], p.previous[i]);
            pushes.clear();
            let exit = || normal(&p.position, i).try_normalize();
            let Some(out) = world.resolve_particle(x, previous, exit, pushes) else {
                continue;
            };
            self.carry
                .note(i, left, (out.lifted, out.overlap), depenetration);
            give_reaction(&mut self.collider_impulses, pushes, out.x, w * h);
            p.position[i] = out.x;
            p.previous[i] = out.previous;
            p.velocity[i] = (out.x - out.previous) / h;
            mark(touched, i);
        }
    }
}

/// The reaction to one particle's contact, now at `x`, of inverse mass over the substep
/// `w_h` (`w h`): each collider takes the particle's momentum change it caused, the other
/// way (`m Δv`, `Δv = (push − previous's shift)/h`).
fn give_reaction(impulses: &mut [ColliderImpulse], pushes: &[(usize, Vec3)], x: Vec3, w_h: f32) {
    for &(k, push) in pushes {
        let impulse = push / w_h;
        impulses[k].linear -= impulse;
        impulses[k].angular -= x.cross(impulse);
    }
}

/// How many times a particle is pushed out of the collider it is deepest in (a crease of
/// two overlapping colliders takes a few; one collider takes one).
pub const CONTACT_PASSES: usize = 4;

/// A collider a particle is in: which, how deep, the outward normal, and whether its
/// path was swept into it.
struct Hit {
    k: usize,
    depth: f32,
    n: Vec3,
    swept: bool,
}

/// A particle kept out of the colliders by [`World::resolve_particle`].
struct Resolved {
    /// Its position and `previous` (while [`World::push_out`] works: the shift of
    /// `previous` so far).
    x: Vec3,
    previous: Vec3,
    /// How far it was moved out of an overlap it started in (pre-stabilised: `previous`
    /// moved with it).
    lifted: Vec3,
    /// How deep that overlap was, m (it comes out over several substeps when deeper than
    /// the cap).
    overlap: f32,
}

/// The colliders of one substep, placed, with their boxes and turns, and how far a
/// particle that started inside one is moved out in the substep at most.
struct World<'a> {
    colliders: &'a [Collider],
    bounds: &'a [Bounds],
    turns: &'a [Quat],
    h: f32,
    depenetration: f32,
}

impl World<'_> {
    /// Where a particle's point `x` was at the start of the substep, seen from collider
    /// `k` placed at its end: `previous` carried by the body's motion.
    fn start(&self, k: usize, previous: Vec3) -> Vec3 {
        let c = &self.colliders[k];
        if c.motion.is_still() {
            previous
        } else {
            let turn = self.turns.get(k).copied().unwrap_or_default();
            previous + c.motion.carry(turn, self.h, previous)
        }
    }

    /// A particle that moved from `previous` to `x` in the substep, kept outside every
    /// collider: where it ends ([`Resolved`]), and each collider's share of the
    /// correction (less the shift of `previous`) in `pushes`; `None` when no collider
    /// touched it.
    fn resolve_particle(
        &self,
        x: Vec3,
        previous: Vec3,
        exit: impl Fn() -> Option<Vec3>,
        pushes: &mut Vec<(usize, Vec3)>,
    ) -> Option<Resolved> {
        let start = x;
        let mut out = Resolved {
            x,
            previous: Vec3::ZERO, // the shift of `previous` until the end
            lifted: Vec3::ZERO,
            overlap: 0.0,
        };
        // The collider whose surface takes the friction (`friction`): the one that pushed
        // most.
        let mut most: Option<(usize, f32, Vec3)> = None;
        // Colliders the particle met in the first pass: with one, its push is final (a
        // particle pushed out of one collider into another it was not in needs a push
        // larger than the gap between them: a crease, where both meet it).
        let mut met = 0;
        for pass in 0..CONTACT_PASSES {
            if pass == 1 && met < 2 {
                break;
            }
            let Some(hit) = self.deepest(pass, previous, out.x, &mut met) else {
                break;
            };
            let k = hit.k;
            self.push_out(&mut out, hit, previous, &exit, pushes);
            keep_most(&mut most, pushes, k);
        }
        let (k, _, _) = most?;
        out.previous += previous;
        let friction = self.friction(k, out.x - start, out.x, out.previous);
        out.x += friction;
        add_push(pushes, k, friction);
        Some(out)
    }

    /// One push of a particle (from `previous`, on its way `out` so far, `out.previous`
    /// holding its `previous`'s shift) out of the collider of `hit`, its share added to
    /// `pushes`.
    fn push_out(
        &self,
        out: &mut Resolved,
        Hit { k, depth, n, swept }: Hit,
        previous: Vec3,
        exit: &impl Fn() -> Option<Vec3>,
        pushes: &mut Vec<(usize, Vec3)>,
    ) {
        let push = n * depth;
        out.x += push;
        // Pre-stabilisation: a push deeper than the particle's own motion over the
        // substep (relative to the body) undoes an overlap it started in; that part
        // moves `previous` too, so it adds no velocity. A push never sends a particle
        // off faster than it came in.
        // Its own motion into the surface (a particle moving out on its own has none:
        // taking the length instead counted an outward motion as an approach, and its
        // push then added that much velocity, doubling it a substep).
        let moved = out.x - push - self.start(k, previous + out.previous);
        let own = (-moved.dot(n)).max(0.0);
        let before = (depth - own).max(0.0);
        // Of that, no more than the cap this substep: the rest waits for the next.
        out.previous += n * before;
        out.lifted += n * before;
        out.overlap = out.overlap.max(before);
        if before > self.depenetration {
            let at = out.x;
            (out.x, out.previous) =
                self.capped_exit((k, n, before), out.x, previous, out.previous, exit, pushes);
            out.lifted += out.x - at;
        }
        add_push(pushes, k, push - n * before);
        // Stopped where its path met the surface, its motion into the surface ends
        // there (Müller 2007 §3.5: the collision's velocity update, no restitution).
        if swept {
            let into = (out.x - previous - out.previous).dot(n);
            if into < 0.0 {
                out.previous += n * into;
                add_push(pushes, k, -n * into);
            }
        }
    }

    /// A particle at `x` that was `before` deep in collider `k` (outward normal `n`) at
    /// the substep's start, more than the cap, its `previous` shifted by `shift`: instead
    /// of the whole way out along `n`, it moves out by the cap ([`Self::way_out`]), and
    /// keeps no motion back in (what the cloth's constraints pulled it in by is taken out
    /// of its velocity, or they would pump momentum into it every substep that moving
    /// `previous` with it hides, and launch its neighbours). Its new position and shift.
    fn capped_exit(
        &self,
        (k, n, before): (usize, Vec3, f32),
        x: Vec3,
        previous: Vec3,
        shift: Vec3,
        exit: &impl Fn() -> Option<Vec3>,
        pushes: &mut Vec<(usize, Vec3)>,
    ) -> (Vec3, Vec3) {
        let out = self.way_out(k, x - n * before, n, before, exit);
        let (x, mut shift) = (x - n * before + out, shift - n * before + out);
        let d = out.normalize_or_zero();
        let into = (x - self.start(k, previous + shift)).dot(d);
        if into < 0.0 {
            shift += d * into;
            add_push(pushes, k, -d * into);
        }
        (x, shift)
    }

    /// How a particle at `x`, `before` deep in collider `k` (outward normal `n`) since
    /// the start of the substep, more than the cap, moves out of it this substep: by the
    /// cap. It leaves along the cloth's own normal (`exit`), to the side that is out
    /// sooner, when that side leads out within [`EXIT_REACH`] times its depth. A cloth
    /// spawned through a ball and pushed toward the nearest surface would open a hole the
    /// ball's size, and its constraints would fight the push; along its normal it only
    /// bends, and every particle leaves to the same side. Otherwise (a cloth edge-on in
    /// the ground) toward the nearest surface.
    #[cold]
    #[inline(never)]
    fn way_out(
        &self,
        k: usize,
        x: Vec3,
        n: Vec3,
        before: f32,
        exit: impl Fn() -> Option<Vec3>,
    ) -> Vec3 {
        let cap = self.depenetration;
        let c = &self.colliders[k];
        let reach = EXIT_REACH * before;
        // How far along `d` the particle is out: swept back from the far point.
        let out_along = |d: Vec3| {
            let far = x + d * reach;
            if c.penetration(far).is_some() {
                return None;
            }
            c.sweep(far, x).map(|(t, _)| (reach * (1.0 - t), d))
        };
        let Some(m) = exit() else {
            return n * cap;
        };
        // Across the cloth already (a cloth pressed into the ground, wrapped on a body):
        // the nearest surface is the way out along its normal too, without the search.
        if m.dot(n).abs() > ALONG_NORMAL {
            return n * cap;
        }
        let sides = [m, -m];
        let nearest = sides
            .into_iter()
            .filter(|d| *d != Vec3::ZERO)
            .filter_map(out_along)
            .min_by(|a, b| a.0.total_cmp(&b.0));
        nearest.map_or(n, |(_, d)| d) * cap
    }

    /// The collider the particle at `x` (from `previous`) is deepest in, in pass `pass`;
    /// the first pass also sweeps its path, and counts in `met` the colliders it meets.
    #[inline(always)]
    fn deepest(&self, pass: usize, previous: Vec3, x: Vec3, met: &mut usize) -> Option<Hit> {
        let mut deepest: Option<Hit> = None;
        let path = Bounds::segment(previous, x);
        for (k, c) in self.colliders.iter().enumerate() {
            let hit = if pass == 0 {
                // The first pass sweeps the path (only a path that crossed the band can
                // differ from where it ends).
                if !self.bounds[k].overlaps(&path) {
                    continue;
                }
                match self.crossing(k, previous, x) {
                    Some((depth, n)) => Some((depth, n, true)),
                    None => self.bounds[k]
                        .contains(x)
                        .then(|| c.penetration(x))
                        .flatten()
                        .map(|(depth, n)| (depth, n, false)),
                }
            } else if self.bounds[k].contains(x) {
                c.penetration(x).map(|(depth, n)| (depth, n, false))
            } else {
                None
            };
            let Some((depth, n, swept)) = hit else {
                continue;
            };
            if pass == 0 {
                *met += 1;
            }
            // Equal depths (a symmetric crease) are told apart by their normals, not by
            // the colliders' order.
            let deeper =
                |d: &Hit| depth > d.depth || (depth == d.depth && n.to_array() > d.n.to_array());
            if deepest.as_ref().is_none_or(deeper) {
                deepest = Some(Hit { k, depth, n, swept });
            }
        }
        deepest
    }

    /// Coulomb friction once, from the whole normal `correction` of a particle now at `x`
    /// (from `previous`), against the motion of collider `k`'s surface: the tangential
    /// motion removed, up to `friction × |correction|`.
    fn friction(&self, k: usize, correction: Vec3, x: Vec3, previous: Vec3) -> Vec3 {
        let depth = correction.length();
        let n = correction / depth.max(f32::MIN_POSITIVE);
        let c = &self.colliders[k];
        let mut moved = x - previous;
        if !c.motion.is_still() {
            let turn = self.turns.get(k).copied().unwrap_or_default();
            moved -= c.motion.carry(turn, self.h, previous);
        }
        let tangential = moved - n * moved.dot(n);
        let slide = tangential.length();
        let grip = c.friction * depth;
        -if slide <= grip {
            tangential
        } else {
            tangential * (grip / slide)
        }
    }

    /// A path over the substep that the discrete test at its end gets wrong: it crossed
    /// collider `k` (a plate thinner than the step) or ends pushed out of the far side.
    /// Returns `(depth, normal)` of the correction that stops it where it met the band
    /// (swept from outside the band), or on the plane it started on (from inside the band,
    /// as a particle resting on the surface does), or `None` when the discrete test is
    /// right.
    fn crossing(&self, k: usize, previous: Vec3, x: Vec3) -> Option<(f32, Vec3)> {
        let c = &self.colliders[k];
        let start = self.start(k, previous);
        let path = x - start;
        // A path shorter than the band cannot cross the solid from outside it.
        if path.length_squared() <= c.thickness * c.thickness {
            return None;
        }
        if c.penetration(x).is_some_and(|(_, n)| n.dot(path) < 0.0) {
            return None; // ends in the band on the side it came from: the discrete push
        }
        let (d0, n0) = c.distance(start);
        let (t, n) = if d0 < 0.0 {
            return None; // started inside the solid: pushed out where it ends
        } else if d0 <= c.thickness {
            (0.0, n0)
        } else if path.length() < d0 - c.thickness {
            return None; // cannot reach the band
        } else {
            c.sweep(start, x)?
        };
        let past = (x - (start + path * t)).dot(n);
        (past < 0.0).then_some((-past, n))
    }
}

/// How much farther than its depth a particle that started deep in a collider may have to
/// go along its cloth's normal to leave that way rather than toward the nearest surface.
const EXIT_REACH: f32 = 8.0;

/// The cosine above which the nearest surface's normal counts as the cloth's (8°).
const ALONG_NORMAL: f32 = 0.99;

/// Adds `push` to collider `k`'s share.
/// Keeps in `most` the collider whose whole push on the particle so far (its entry of
/// `pushes`) is the largest, `k` having just pushed; ties go by the push's direction
/// rather than the colliders' order.
#[inline]
fn keep_most(most: &mut Option<(usize, f32, Vec3)>, pushes: &[(usize, Vec3)], k: usize) {
    let share = pushes
        .iter()
        .find(|(j, _)| *j == k)
        .map_or(Vec3::ZERO, |p| p.1);
    let total = share.length();
    let more = |&(_, m, p): &(usize, f32, Vec3)| {
        total > m || (total == m && share.to_array() > p.to_array())
    };
    if most.is_none_or(|m| more(&m)) {
        *most = Some((k, total, share));
    }
}

fn add_push(pushes: &mut Vec<(usize, Vec3)>, k: usize, push: Vec3) {
    match pushes.iter_mut().find(|(j, _)| *j == k) {
        Some((_, p)) => *p += push,
        None => pushes.push((k, push)),
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
        // Only a cloth not yet disturbed asks whether the change reaches it (a moving
        // character's cloth already is, by its pins or targets, and skips the box).
        if !self.disturbed {
            let cloth = Bounds::around(&self.particles.position);
            self.disturbed = self.contact.change_reaches(&cloth);
        }
        // The thin colliders, for the edge pass: thicker than the cloth's longest edge,
        // the particles catch a collider themselves.
        let longest = self.structure.longest_edge;
        let contact = &mut self.contact;
        contact.thin.clear();
        let thin = |c: &Collider| axis(c).is_some_and(|(_, _, reach)| 2.0 * reach < longest);
        contact
            .thin
            .extend((0..contact.colliders.len()).filter(|&k| thin(&contact.colliders[k])));
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
