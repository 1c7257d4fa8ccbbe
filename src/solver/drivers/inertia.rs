//! Inertia scaling: how much of its drivers' motion a cloth feels as motion through the
//! air (NvCloth's local-space simulation with its linear and angular inertia; Magica
//! Cloth 2's inertia with movement and rotation speed limits). The drivers' best rigid
//! fit step to step (the one teleports are told by) is the moving frame.

use bevy::math::{Quat, Vec3};

use super::super::ClothSolver;
use super::teleport::RigidMove;
use crate::params::Integrator;

impl RigidMove {
    /// Splits this move into `(excess, felt)` with `felt ∘ excess = self`: `felt` moves
    /// the centre at most `max_distance` and turns at most `max_angle` (radians), and
    /// `excess`, the rest, turns about the drivers' centre and shifts.
    pub fn capped(&self, max_distance: f32, max_angle: f32) -> (RigidMove, RigidMove) {
        let shift = self.to_centre - self.from_centre;
        let length = shift.length();
        let excess_shift = if length > max_distance {
            shift * (1.0 - max_distance / length)
        } else {
            Vec3::ZERO
        };
        let angle = self.angle();
        let excess_turn = if angle > max_angle {
            Quat::IDENTITY
                .slerp(self.rotation, 1.0 - max_angle / angle)
                .normalize()
        } else {
            Quat::IDENTITY
        };
        let excess = RigidMove {
            from_centre: self.from_centre,
            to_centre: self.from_centre + excess_shift,
            rotation: excess_turn,
        };
        let felt = RigidMove {
            from_centre: self.from_centre + excess_shift,
            to_centre: self.to_centre,
            rotation: (self.rotation * excess_turn.inverse()).normalize(),
        };
        (excess, felt)
    }
}

/// What inertia scaling keeps from one step to the next: the drivers' move the cloth
/// felt, the share of it that carried the cloth, and where each particle started.
#[derive(Clone, Debug, Default)]
pub(in crate::solver) struct Felt {
    by: Option<RigidMove>,
    carried: Option<RigidMove>,
    from: Vec<Vec3>,
    /// The buffer `from` is copied into next (the last one's, kept for its storage).
    spare: Vec<Vec3>,
}

impl Felt {
    /// Forgets the last step (after a teleport, or with inertia off).
    pub(in crate::solver) fn clear(&mut self) {
        (self.by, self.carried) = (None, None);
        self.from.clear();
    }
}

impl ClothSolver {
    /// The cloth feels its drivers' move `jump` this step as its
    /// [`Inertia`](crate::params::Inertia) says: the part past its speed caps carries it
    /// rigidly, and of the rest (`felt`, against the last step's) it feels the share
    /// `linear` of the change in the frame's velocity and `angular` of the change in its
    /// turn; the remainder it takes as in the frame (fully local: moved as the frame moves
    /// it, its motion relative to the frame over the last step carried on).
    pub(in crate::solver) fn feel(&mut self, jump: RigidMove, dt: f32) {
        let inertia = self.params.inertia;
        let (excess, felt) = jump.capped(
            inertia.max_speed * dt,
            inertia.max_turn_speed.to_radians() * dt,
        );
        if excess.to_centre != excess.from_centre || excess.rotation != Quat::IDENTITY {
            self.move_rigidly(excess, true);
        }
        let shares = (1.0 - inertia.linear, 1.0 - inertia.angular);
        let last = self.felt.by.replace(felt);
        let last_carried = self.felt.carried.take();
        let n = self.particles.len();
        // Where each particle starts this step, for the next; the last step's starts,
        // which become each particle's target here (no allocation once warm).
        let mut from = std::mem::take(&mut self.felt.from);
        let mut now = std::mem::take(&mut self.felt.spare);
        now.clone_from(&self.particles.position);
        self.felt.from = now;
        if let Some(last) = last.filter(|_| from.len() == n && shares != (0.0, 0.0)) {
            let carried = felt.share(shares);
            self.aim_in_the_frame(&mut from, felt, last, last_carried, shares, dt);
            self.move_rigidly(carried, true);
            // Each free particle moves from where it was carried to its blended target.
            let h = self.clock.h;
            let p = &mut self.particles;
            for (i, &target) in from.iter().enumerate() {
                if p.inv_mass[i] != 0.0 {
                    p.velocity[i] = (target - p.position[i]) / dt;
                    p.previous[i] = p.position[i] - p.velocity[i] * h;
                }
            }
            self.felt.carried = Some(carried);
        }
        self.felt.spare = from;
    }

    /// Replaces where each particle started the last step (`from`) with where it would
    /// be a step from now: as in world space (its velocity carried on, with what last
    /// step's share `last_carried` carried it by), moved the shares `(linear, angular)`
    /// of the way to where the frame (moving by `last`, then `felt`) takes it, its motion
    /// relative to the frame carried on.
    fn aim_in_the_frame(
        &self,
        from: &mut [Vec3],
        felt: RigidMove,
        last: RigidMove,
        last_carried: Option<RigidMove>,
        (linear, angular): (f32, f32),
        dt: f32,
    ) {
        // The change in the frame's displacement: the whole of its linear part.
        let accelerated = (felt.to_centre - felt.from_centre) - (last.to_centre - last.from_centre);
        let carried = last_carried.unwrap_or(RigidMove::IDENTITY);
        let h = self.clock.h;
        let verlet = self.params.integrator == Integrator::Verlet;
        let p = &self.particles;
        for (i, start) in from.iter_mut().enumerate() {
            let x = p.position[i];
            // Verlet's velocity is its last displacement (the constraints' share in it),
            // which the carry last step is not part of.
            let v = if verlet {
                (x - p.previous[i]) / h
            } else {
                p.velocity[i]
            };
            let world = carried.apply(x) + v * dt;
            let local = felt.apply(2.0 * x - last.apply(*start));
            let turned = local - world - accelerated;
            *start = world + linear * accelerated + angular * turned;
        }
    }
}

impl RigidMove {
    /// The shares `(linear, angular)` of this move: its centre moved that share of the
    /// way, turned that share of its angle.
    fn share(&self, (linear, angular): (f32, f32)) -> RigidMove {
        RigidMove {
            from_centre: self.from_centre,
            to_centre: self.from_centre.lerp(self.to_centre, linear),
            rotation: Quat::IDENTITY.slerp(self.rotation, angular).normalize(),
        }
    }
}
