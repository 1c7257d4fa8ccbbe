//! avian3d bodies and cloth (the `avian` feature), in [`ClothAvianPlugin`], which a game
//! adds beside `ClothPlugin` and avian's `PhysicsPlugins`: the cloth steps after avian's
//! step in the same schedule, is kept out of avian colliders, pushes back on their
//! bodies, and falls under avian's `Gravity`.
//!
//! The cloth is kept out of avian colliders — balls, capsules, cuboids, cylinders, convex hulls and half-spaces — placed by their
//! entities' global transforms, with avian's `Friction` (its dynamic coefficient) when the
//! entity has one; a moving body sweeps through the step and carries the cloth by friction
//! (the plugin gives every collider its motion). An entity with a `ClothCollider` of its own
//! uses that instead. Other shapes (trimeshes, compounds, cones, …) are not collided with,
//! nor are sensors (`Sensor`), disabled colliders (`ColliderDisabled`) and colliders whose
//! `CollisionLayers` do not meet the cloth's (a cloth entity may have `CollisionLayers` of
//! its own; without, it has avian's default: the first layer, meeting every layer).

use std::sync::Arc;

use avian3d::prelude::{
    Collider, ColliderDisabled, ColliderOf, CollisionLayers, Friction, Gravity, PhysicsSystems,
    RigidBody, Sensor,
};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::transform::helper::TransformHelper;

use crate::ecs::cloth::{ClothEnvironment, ClothInvalid, ClothSimulation, Layers};
use crate::ecs::colliders::{ClothCollider, PlacedColliders, give_colliders, place_colliders};
use crate::ecs::plugin::{ClothSchedule, ClothSystems};
use crate::ecs::step::{StepProgress, finish_steps};
use crate::solver::shapes::{Capsule, Convex, Cuboid, Cylinder, Plane, Sphere};
use crate::solver::{self, ColliderShape, ConvexHull, Placement, Shape};

/// Cloth with avian3d bodies. Add it after `ClothPlugin` (and with avian's
/// `PhysicsPlugins`, in the schedule avian steps in, `FixedPostUpdate` by default):
///
/// ```no_run
/// use avian3d::prelude::*;
/// use bevy::prelude::*;
/// use bevy_cloth::prelude::*;
/// App::new().add_plugins((
///     DefaultPlugins,
///     PhysicsPlugins::default(),
///     ClothPlugin::default(),
///     ClothAvianPlugin::default(),
/// ));
/// ```
///
/// It orders the cloth's step after avian's (`ClothSystems::Prepare` after
/// `PhysicsSystems::Last`), so the cloth meets the bodies, and follows its attachments,
/// where avian's step put them, where they are drawn; it places avian colliders for the
/// cloths, gives their bodies the cloth's reaction, and copies avian's `Gravity` into
/// `ClothEnvironment` when it changes (unless `follow_gravity` is false).
pub struct ClothAvianPlugin {
    /// The cloth falls under avian's `Gravity` (default true); false leaves
    /// `ClothEnvironment`'s gravity to the game.
    pub follow_gravity: bool,
}

impl Default for ClothAvianPlugin {
    fn default() -> Self {
        Self {
            follow_gravity: true,
        }
    }
}

impl Plugin for ClothAvianPlugin {
    fn build(&self, app: &mut App) {
        let schedule = app
            .world()
            .get_resource::<ClothSchedule>()
            .expect("add ClothPlugin before ClothAvianPlugin")
            .0;
        app.configure_sets(schedule, ClothSystems::Prepare.after(PhysicsSystems::Last))
            .add_systems(
                schedule,
                (
                    (place_avian_colliders, cloth_layers)
                        .after(place_colliders)
                        .before(give_colliders)
                        .in_set(ClothSystems::Prepare),
                    push_back_bodies
                        .after(finish_steps)
                        .in_set(ClothSystems::Finish),
                ),
            );
        if self.follow_gravity {
            app.add_systems(
                schedule,
                follow_gravity
                    .before(place_colliders)
                    .in_set(ClothSystems::Prepare),
            );
        }
    }
}

/// Adds every avian collider the cloths meet to the step's colliders (an entity with a
/// `ClothCollider` of its own uses that instead); the cloth's reaction goes to its body.
#[allow(clippy::type_complexity)]
fn place_avian_colliders(
    transforms: TransformHelper,
    colliders: Query<
        (
            Entity,
            &Collider,
            Option<&Friction>,
            Option<&CollisionLayers>,
            Option<&ColliderOf>,
        ),
        (
            Without<ClothCollider>,
            Without<Sensor>,
            Without<ColliderDisabled>,
        ),
    >,
    mut placed: ResMut<PlacedColliders>,
    mut hulls: Local<HullCache>,
) {
    for (entity, collider, friction, layers, of) in &colliders {
        let Ok(transform) = transforms.compute_global_transform(entity) else {
            continue;
        };
        if let Some(c) = to_solver_collider(collider, &transform, friction, &mut hulls) {
            let body = of.map_or(entity, |of| of.body);
            placed.add(
                entity,
                body,
                &transform,
                c,
                layers.map_or(Layers::DEFAULT, to_layers),
            );
        }
    }
    hulls.end_step();
}

fn to_layers(layers: &CollisionLayers) -> Layers {
    Layers {
        memberships: layers.memberships.0,
        filters: layers.filters.0,
    }
}

/// Each cloth meets the colliders its `CollisionLayers` meet (avian's default without).
fn cloth_layers(mut cloths: Query<(&mut ClothSimulation, Option<&CollisionLayers>)>) {
    for (mut sim, layers) in &mut cloths {
        sim.bypass_change_detection().layers = layers.map_or(Layers::DEFAULT, to_layers);
    }
}

/// The cloth falls under avian's gravity.
fn follow_gravity(gravity: Res<Gravity>, mut env: ResMut<ClothEnvironment>) {
    if gravity.is_changed() && env.gravity != gravity.0 {
        env.gravity = gravity.0;
    }
}

/// Hulls made from avian convex shapes, kept by the shape they came from so each is made
/// once (not every step); ones not used in a step are dropped at [`HullCache::end_step`].
#[derive(Default)]
pub struct HullCache {
    hulls: HashMap<usize, (Arc<ConvexHull>, bool)>,
}

impl HullCache {
    /// The hull made from `polyhedron`, the shape named `key`: the kept one, or made now
    /// and kept; `None` (with a warning, once) for a hull the cloth cannot use.
    fn get_or_make(
        &mut self,
        key: usize,
        polyhedron: &avian3d::parry::shape::ConvexPolyhedron,
    ) -> Option<Arc<ConvexHull>> {
        if let Some((hull, used)) = self.hulls.get_mut(&key) {
            *used = true;
            return Some(hull.clone());
        }
        let corners = polyhedron.vertices_adj_to_face();
        let faces = polyhedron
            .faces()
            .iter()
            .map(|f| {
                let first = f.first_vertex_or_edge as usize;
                let n = f.num_vertices_or_edges as usize;
                (f.normal, corners[first..first + n].to_vec())
            })
            .collect();
        let hull = match ConvexHull::new(polyhedron.points().to_vec(), faces) {
            Ok(hull) => Arc::new(hull),
            Err(e) => {
                warn_once!("an avian convex hull the cloth cannot use: {e}");
                return None;
            }
        };
        self.hulls.insert(key, (hull.clone(), true));
        Some(hull)
    }

    /// Drops the hulls no collider used since the last call.
    pub fn end_step(&mut self) {
        self.hulls.retain(|_, (_, used)| std::mem::take(used));
    }
}

/// How far outside an avian collider's surface the particles stay, m (a `ClothCollider`'s
/// default).
pub const THICKNESS: f32 = ClothCollider::THICKNESS;

/// The solver collider of an avian `collider` placed by `transform` (its scale is the
/// collider's own, `shape_scaled`), or `None` for a shape the cloth does not collide with.
pub fn to_solver_collider(
    collider: &Collider,
    transform: &GlobalTransform,
    friction: Option<&Friction>,
    hulls: &mut HullCache,
) -> Option<solver::Collider> {
    let shape = local_shape(collider, hulls)?;
    let (_, rotation, translation) = transform.to_scale_rotation_translation();
    let shape = shape.placed(&Placement::about(Vec3::ZERO, rotation, translation));
    Some(solver::Collider {
        shape,
        thickness: THICKNESS,
        friction: friction.map_or(ClothCollider::FRICTION, |f| f.dynamic_coefficient.max(0.0)),
        motion: solver::Motion::NONE,
    })
}
/// An avian collider's solid in its own frame, scaled: `None` for a shape the cloth does
/// not collide with.
fn local_shape(collider: &Collider, hulls: &mut HullCache) -> Option<ColliderShape> {
    let shape = collider.shape_scaled();
    let local = if let Some(ball) = shape.as_ball() {
        Sphere {
            center: Vec3::ZERO,
            radius: ball.radius,
        }
        .into()
    } else if let Some(capsule) = shape.as_capsule() {
        Capsule {
            a: capsule.segment.a,
            b: capsule.segment.b,
            radius: capsule.radius,
        }
        .into()
    } else if let Some(cuboid) = shape.as_cuboid() {
        Cuboid::new(Vec3::ZERO, Quat::IDENTITY, cuboid.half_extents).into()
    } else if let Some(cylinder) = shape.as_cylinder() {
        Cylinder {
            center: Vec3::ZERO,
            axis: Vec3::Y,
            half_height: cylinder.half_height,
            radius: cylinder.radius,
        }
        .into()
    } else if let Some(polyhedron) = shape.as_convex_polyhedron() {
        // The shape's own allocation names it (avian keeps a scaled shape until the scale
        // changes).
        let key = Arc::as_ptr(&shape.0) as *const () as usize;
        let hull = hulls.get_or_make(key, polyhedron)?;
        Convex {
            center: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            hull,
        }
        .into()
    } else if let Some(half_space) = shape.as_halfspace() {
        Plane {
            point: Vec3::ZERO,
            normal: half_space.normal,
        }
        .into()
    } else {
        return None;
    };
    Some(local)
}

/// The cloth pushes back: every cloth that stepped gives each avian
/// dynamic body among its colliders the impulse of its particles' contacts with it
/// ([`solver::ClothSolver::collider_impulses`]), so a ball dropped on a hammock is held.
fn push_back_bodies(
    placed: Res<PlacedColliders>,
    cloths: Query<(&ClothSimulation, &StepProgress), Without<ClothInvalid>>,
    mut bodies: Query<(&RigidBody, avian3d::prelude::Forces)>,
    mut totals: Local<Vec<solver::ColliderImpulse>>,
) {
    use avian3d::prelude::WriteRigidBodyForces;
    totals.clear();
    totals.resize(placed.bodies.len(), solver::ColliderImpulse::default());
    for (sim, progress) in &cloths {
        if progress.substeps == 0 {
            continue;
        }
        // The solver's colliders are the placed ones its layers meet, in order.
        for (&i, impulse) in sim
            .colliders_from
            .iter()
            .zip(sim.solver.collider_impulses())
        {
            let total = &mut totals[i as usize];
            total.linear += impulse.linear;
            total.angular += impulse.angular;
        }
    }
    // A collider's reaction goes to its body (itself, or the body it is a child of).
    for (&entity, total) in placed.bodies.iter().zip(totals.iter()) {
        if *total == solver::ColliderImpulse::default() {
            continue;
        }
        let Ok((body, mut forces)) = bodies.get_mut(entity) else {
            continue;
        };
        if body.is_dynamic() {
            // The linear impulse at the origin and the angular one about it: about the
            // centre of mass c that is `angular − c × linear`, as the impulse needs.
            forces.apply_linear_impulse_at_point(total.linear, Vec3::ZERO);
            forces.apply_angular_impulse(total.angular);
        }
    }
}
