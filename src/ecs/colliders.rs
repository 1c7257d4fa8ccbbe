//! Colliders: the [`ClothCollider`] component, and the system that gives every cloth the
//! colliders where their entities are now, each with its motion since the last step.

use bevy::prelude::*;
use bevy::transform::helper::TransformHelper;
use serde::{Deserialize, Serialize};

use crate::ecs::cloth::{ClothSimulation, Layers, Named};
use crate::ecs::events::ClothColliderBecameInvalid;
use crate::error::ClothError;
use crate::solver;
use crate::solver::shapes::check_size;

/// A solid the cloths are kept out of, placed by its entity's transform: spheres,
/// capsules and planes with a thickness and friction. Every cloth collides with every
/// collider, every substep.
///
/// ```
/// use bevy::prelude::*;
/// use bevy_cloth::prelude::*;
/// # let mut world = World::new();
/// world.spawn((ClothCollider::sphere(0.3), Transform::from_xyz(0.0, 1.0, 0.0)));
/// world.spawn(ClothCollider::plane().with_friction(0.8)); // the ground, y = 0
/// ```
#[derive(Component, Clone, Debug, PartialEq, Reflect, Serialize, Deserialize)]
#[reflect(Component, Debug, PartialEq)]
#[require(Transform)]
#[serde(deny_unknown_fields)]
pub struct ClothCollider {
    /// The solid, in the entity's local frame.
    pub shape: ColliderKind,
    /// How far outside the surface particles stay, m.
    #[serde(default = "ClothCollider::default_thickness")]
    pub thickness: f32,
    /// Coulomb friction coefficient (0 = ice; a particle sticks on a slope while
    /// tan θ ≤ friction).
    #[serde(default = "ClothCollider::default_friction")]
    pub friction: f32,
}

/// The solid of a [`ClothCollider`], in its entity's local frame (the same conventions as
/// Bevy's `Sphere`, `Capsule3d` and `Plane3d` meshes).
#[derive(Clone, Debug, PartialEq, Reflect, Serialize, Deserialize)]
pub enum ColliderKind {
    /// A ball about the origin.
    Sphere {
        /// Radius, m.
        radius: f32,
    },
    /// A capsule along local y: all points within `radius` of the segment from
    /// `(0, −half_length, 0)` to `(0, half_length, 0)`.
    Capsule {
        /// Radius, m.
        radius: f32,
        /// Half the length of the axis segment (without the caps), m.
        half_length: f32,
    },
    /// A box about the origin, `half_extents` along local x, y and z (scaled per axis by
    /// the transform).
    Cuboid {
        /// Half its size along local x, y, z, m.
        #[serde(with = "crate::params::vec3_serde")]
        half_extents: Vec3,
    },
    /// A cylinder along local y about the origin, `radius` from its axis and
    /// `half_height` up and down it (Bevy's `Cylinder`).
    Cylinder {
        /// Radius, m.
        radius: f32,
        /// Half its height, m.
        half_height: f32,
    },
    /// The half-space below the local xz plane (normal +y): a ground or a wall.
    Plane,
    /// The half-space `normal · x < distance` (local): behind the plane `distance` m
    /// from the origin along its outward `normal` (made unit when placed).
    HalfSpace {
        /// The plane's normal, pointing out of the solid.
        #[serde(with = "crate::params::vec3_serde")]
        normal: Vec3,
        /// The plane's distance from the origin along `normal`, m.
        distance: f32,
    },
    /// Any of the solver's [shapes](crate::solver::shapes) (a torus, a convex hull, one of
    /// your own), in the local frame; built in code only (a scene file names the kinds
    /// above).
    #[serde(skip)]
    Shape(solver::ColliderShape),
}

impl ColliderKind {
    /// The solid in the local frame, as a solver shape (negative sizes count as 0).
    pub fn local(&self) -> solver::ColliderShape {
        use solver::shapes::{Capsule, Cuboid, Cylinder, Plane, Sphere};
        match *self {
            ColliderKind::Sphere { radius } => Sphere {
                center: Vec3::ZERO,
                radius: radius.max(0.0),
            }
            .into(),
            ColliderKind::Capsule {
                radius,
                half_length,
            } => Capsule {
                a: Vec3::new(0.0, -half_length.max(0.0), 0.0),
                b: Vec3::new(0.0, half_length.max(0.0), 0.0),
                radius: radius.max(0.0),
            }
            .into(),
            ColliderKind::Cuboid { half_extents } => {
                Cuboid::new(Vec3::ZERO, Quat::IDENTITY, half_extents.max(Vec3::ZERO)).into()
            }
            ColliderKind::Cylinder {
                radius,
                half_height,
            } => Cylinder {
                center: Vec3::ZERO,
                axis: Vec3::Y,
                half_height: half_height.max(0.0),
                radius: radius.max(0.0),
            }
            .into(),
            ColliderKind::Plane => Plane {
                point: Vec3::ZERO,
                normal: Vec3::Y,
            }
            .into(),
            ColliderKind::HalfSpace { normal, distance } => {
                let normal = normal.normalize_or(Vec3::Y);
                Plane {
                    point: normal * distance,
                    normal,
                }
                .into()
            }
            ColliderKind::Shape(ref shape) => shape.clone(),
        }
    }

    /// Checks the sizes: radii and half-extents > 0, half-lengths ≥ 0, a half-space's
    /// normal non-zero, each within [`crate::limits::MAX_POSITION`]; a solver shape by its
    /// own [`Shape::validate`](solver::Shape::validate).
    pub fn validate(&self) -> Result<(), ClothError> {
        use solver::Shape;
        use solver::shapes::{Cuboid, Cylinder, Sphere};
        match *self {
            // The solver's shapes name the same fields.
            ColliderKind::Sphere { radius } => Sphere {
                center: Vec3::ZERO,
                radius,
            }
            .validate(),
            ColliderKind::Capsule {
                radius,
                half_length,
            } => {
                // Its radius as a ball's.
                let center = Vec3::ZERO;
                Sphere { center, radius }.validate()?;
                let expected = format!(
                    "a half-length from 0 to {max:e} m",
                    max = crate::limits::MAX_POSITION
                );
                check_size("half_length", half_length, true, expected)
            }
            ColliderKind::Cuboid { half_extents } => {
                Cuboid::new(Vec3::ZERO, Quat::IDENTITY, half_extents).validate()
            }
            ColliderKind::Cylinder {
                radius,
                half_height,
            } => Cylinder {
                center: Vec3::ZERO,
                axis: Vec3::Y,
                half_height,
                radius,
            }
            .validate(),
            ColliderKind::Plane => Ok(()),
            ColliderKind::Shape(ref shape) => shape.validate(),
            ColliderKind::HalfSpace { normal, distance } => {
                let length = normal.length();
                let ok = length.is_finite() && length > 1e-6;
                crate::params::check("normal", length, ok, "a finite, non-zero normal")?;
                let ok = distance.abs() <= crate::limits::MAX_POSITION;
                crate::params::check(
                    "distance",
                    distance,
                    ok,
                    format!(
                        "a distance within ±{max:e} m",
                        max = crate::limits::MAX_POSITION
                    ),
                )
            }
        }
    }
}

impl From<InfinitePlane3d> for ClothCollider {
    /// The solid behind the plane (its `normal` points out of it), like avian's
    /// `Collider::half_space`.
    fn from(p: InfinitePlane3d) -> Self {
        Self::half_space(*p.normal, 0.0)
    }
}

impl From<bevy::math::primitives::HalfSpace> for ClothCollider {
    /// Bevy's half-space is the solid, its normal pointing into it.
    fn from(h: bevy::math::primitives::HalfSpace) -> Self {
        Self::half_space(-Vec3::from(h.normal()), h.d())
    }
}

impl From<Sphere> for ClothCollider {
    fn from(s: Sphere) -> Self {
        Self::sphere(s.radius)
    }
}

impl From<Capsule3d> for ClothCollider {
    fn from(c: Capsule3d) -> Self {
        Self::capsule(c.radius, 2.0 * c.half_length)
    }
}

impl From<Cuboid> for ClothCollider {
    fn from(c: Cuboid) -> Self {
        Self::new(ColliderKind::Cuboid {
            half_extents: c.half_size,
        })
    }
}

impl From<Cylinder> for ClothCollider {
    fn from(c: Cylinder) -> Self {
        Self::new(ColliderKind::Cylinder {
            radius: c.radius,
            half_height: c.half_height,
        })
    }
}

impl ClothCollider {
    /// The thickness a collider has unless set, m (also avian colliders').
    pub const THICKNESS: f32 = 0.005;
    /// The friction coefficient a collider has unless set (also avian colliders' without
    /// a `Friction`).
    pub const FRICTION: f32 = 0.3;

    fn new(shape: ColliderKind) -> Self {
        Self {
            shape,
            thickness: Self::THICKNESS,
            friction: Self::FRICTION,
        }
    }

    /// A sphere of `radius` m.
    pub fn sphere(radius: f32) -> Self {
        Self::new(ColliderKind::Sphere { radius })
    }

    /// A capsule along local y of `radius` m whose axis segment (without the caps) is
    /// `length` m long: the sizes Bevy's `Capsule3d::new(radius, length)` and avian's
    /// `Collider::capsule` take.
    pub fn capsule(radius: f32, length: f32) -> Self {
        Self::new(ColliderKind::Capsule {
            radius,
            half_length: length / 2.0,
        })
    }

    /// A box `x_length × y_length × z_length` m about the origin: the sizes Bevy's
    /// `Cuboid::new` and avian's `Collider::cuboid` take.
    pub fn cuboid(x_length: f32, y_length: f32, z_length: f32) -> Self {
        let half_extents = Vec3::new(x_length, y_length, z_length) / 2.0;
        Self::new(ColliderKind::Cuboid { half_extents })
    }

    /// A cylinder along local y of `radius` m and `height` m: the sizes Bevy's
    /// `Cylinder::new` and avian's `Collider::cylinder` take.
    pub fn cylinder(radius: f32, height: f32) -> Self {
        Self::new(ColliderKind::Cylinder {
            radius,
            half_height: height / 2.0,
        })
    }

    /// A plane through the origin with normal +y (a ground): the solid is below it.
    pub fn plane() -> Self {
        Self::new(ColliderKind::Plane)
    }

    /// The solid `normal · x < distance`, behind the plane `distance` m from the origin
    /// along its outward `normal`.
    pub fn half_space(normal: Vec3, distance: f32) -> Self {
        Self::new(ColliderKind::HalfSpace { normal, distance })
    }

    /// Any of the solver's [shapes](crate::solver::shapes), in the entity's local frame
    /// (a torus, a convex hull, a shape of your own registered there).
    ///
    /// ```
    /// use bevy::prelude::*;
    /// use bevy_cloth::prelude::*;
    /// use bevy_cloth::solver::shapes::Torus;
    /// # let mut world = World::new();
    /// let ring = Torus { center: Vec3::ZERO, axis: Vec3::Y, major_radius: 0.3, minor_radius: 0.02 };
    /// world.spawn((ClothCollider::from_shape(ring), Transform::from_xyz(0.0, 1.0, 0.0)));
    /// ```
    pub fn from_shape(shape: impl Into<solver::ColliderShape>) -> Self {
        Self::new(ColliderKind::Shape(shape.into()))
    }

    fn default_thickness() -> f32 {
        Self::THICKNESS
    }

    fn default_friction() -> f32 {
        Self::FRICTION
    }

    /// Replaces the thickness (m).
    pub fn with_thickness(mut self, thickness: f32) -> Self {
        self.thickness = thickness;
        self
    }

    /// Replaces the friction coefficient.
    pub fn with_friction(mut self, friction: f32) -> Self {
        self.friction = friction;
        self
    }

    /// Checks sizes: radius > 0, half-length, thickness and friction ≥ 0, each within
    /// [`crate::limits::MAX_POSITION`].
    pub fn validate(&self) -> Result<(), ClothError> {
        self.shape.validate()?;
        check_size(
            "thickness",
            self.thickness,
            true,
            format!(
                "a thickness from 0 to {max:e} m",
                max = crate::limits::MAX_POSITION
            ),
        )?;
        let expected = format!(
            "a friction coefficient from 0 to {max:e}",
            max = crate::limits::MAX_POSITION
        );
        check_size("friction", self.friction, true, expected)
    }

    /// The collider in world space under `transform`: its [`ColliderKind::local`] shape
    /// placed by it ([`Shape::placed`](solver::Shape::placed): radii scale with the
    /// largest scale factor across their axis, lengths along theirs).
    pub fn to_world(&self, transform: &GlobalTransform) -> solver::Collider {
        use solver::Shape;
        let placement = solver::Placement::affine(transform.affine());
        solver::Collider {
            shape: self.shape.local().placed(&placement),
            thickness: self.thickness.max(0.0),
            friction: self.friction.max(0.0),
            motion: solver::Motion::NONE,
        }
    }
}

/// A collider entity moving faster than this (m/s), or turning more than a quarter turn in
/// a step, is taken to have jumped there (a respawn, a teleport): it gets no motion.
pub const TELEPORT_SPEED: f32 = 100.0;

/// Each collider entity's pose (rotation, translation) at the last step, from which the
/// next step takes its motion.
#[derive(Default)]
struct ColliderPoses {
    before: bevy::ecs::entity::EntityHashMap<(Quat, Vec3)>,
    now: bevy::ecs::entity::EntityHashMap<(Quat, Vec3)>,
}

impl ColliderPoses {
    /// The motion of `entity` from its last pose to `transform` over `dt` (none the first
    /// time it is seen, or after a jump); remembers `transform` for the next step.
    fn motion(&mut self, entity: Entity, transform: &GlobalTransform, dt: f32) -> solver::Motion {
        let (_, rotation, translation) = transform.to_scale_rotation_translation();
        self.now.insert(entity, (rotation, translation));
        let Some(&before) = self.before.get(&entity) else {
            return solver::Motion::NONE;
        };
        let motion = solver::Motion::between(before, (rotation, translation), dt);
        let jumped = motion.linear.length() > TELEPORT_SPEED
            || motion.angular.length() * dt > std::f32::consts::FRAC_PI_2;
        if jumped { solver::Motion::NONE } else { motion }
    }

    /// Ends a step: its poses are the next step's `before`.
    fn end_step(&mut self) {
        std::mem::swap(&mut self.before, &mut self.now);
        self.now.clear();
    }
}

/// The colliders the cloths meet this step, in world space, in the order they were placed:
/// each one's entity (whose motion is tracked), the body its reaction goes to and its
/// layers. Filled by `place_colliders` (and the avian plugin), given to the cloths by
/// `give_colliders`.
#[derive(Resource, Default)]
pub(crate) struct PlacedColliders {
    colliders: Vec<solver::Collider>,
    /// Per collider, the entity that gets the cloth's reaction (an avian collider's body).
    pub(crate) bodies: Vec<Entity>,
    layers: Vec<Layers>,
    poses: ColliderPoses,
    dt: f32,
}

impl PlacedColliders {
    /// Places `collider` (in world space), the collider of `entity` now at `transform`,
    /// with its motion since the last step; its reaction goes to `body`.
    pub(crate) fn add(
        &mut self,
        entity: Entity,
        body: Entity,
        transform: &GlobalTransform,
        collider: solver::Collider,
        layers: Layers,
    ) {
        let motion = self.poses.motion(entity, transform, self.dt);
        self.colliders.push(solver::Collider { motion, ..collider });
        self.bodies.push(body);
        self.layers.push(layers);
    }
}

/// Makes a capsule [`ClothCollider`] span two entities, a bone: each step its axis runs
/// from `from`'s origin to `to`'s (a hip joint to a knee joint, as the animation has
/// put them), whatever its own entity's transform; its radius is the collider's. Its
/// motion since the last step (for friction and sweeping) is that of the segment's
/// middle and direction. On a collider of another shape it does nothing.
///
/// ```
/// use bevy::prelude::*;
/// use bevy_cloth::prelude::*;
/// # let mut world = World::new();
/// let hip = world.spawn(Transform::from_xyz(0.1, 0.9, 0.0)).id();
/// let knee = world.spawn(Transform::from_xyz(0.1, 0.5, 0.0)).id();
/// world.spawn((ClothCollider::capsule(0.07, 0.0), ClothColliderSpan { from: hip, to: knee }));
/// ```
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component, Debug, PartialEq)]
pub struct ClothColliderSpan {
    /// The entity at one end of the axis.
    pub from: Entity,
    /// The entity at the other.
    pub to: Entity,
}

impl ClothColliderSpan {
    /// A transform whose y axis runs from `from` to `to` (its origin midway, its y scale
    /// the length); `None` when an end has no transform.
    fn transform(&self, transforms: &TransformHelper) -> Option<GlobalTransform> {
        let a = transforms
            .compute_global_transform(self.from)
            .ok()?
            .translation();
        let b = transforms
            .compute_global_transform(self.to)
            .ok()?
            .translation();
        let axis = b - a;
        let rotation = Quat::from_rotation_arc(Vec3::Y, axis.normalize_or(Vec3::Y));
        let transform = Transform::from_translation(0.5 * (a + b))
            .with_rotation(rotation)
            .with_scale(Vec3::new(1.0, axis.length(), 1.0));
        Some(GlobalTransform::from(transform))
    }
}

/// Starts the step's colliders with every [`ClothCollider`] where its entity is now (each
/// placed once per step, then copied to every cloth).
pub(crate) fn place_colliders(
    time: Res<Time>,
    transforms: TransformHelper,
    colliders: Query<
        (Entity, &ClothCollider, Option<&ClothColliderSpan>),
        Without<ClothColliderInvalid>,
    >,
    mut placed: ResMut<PlacedColliders>,
) {
    let placed = &mut *placed;
    placed.dt = time.delta_secs();
    placed.colliders.clear();
    placed.bodies.clear();
    placed.layers.clear();
    for (entity, collider, span) in &colliders {
        let transform = match span {
            Some(span) => span.transform(&transforms),
            None => transforms.compute_global_transform(entity).ok(),
        };
        let Some(transform) = transform else {
            continue;
        };
        let mut collider = collider.clone();
        if let (Some(_), ColliderKind::Capsule { half_length, .. }) = (span, &mut collider.shape) {
            *half_length = 0.5 * transform.scale().y;
        }
        let transform = match span {
            Some(_) => GlobalTransform::from(transform.compute_transform().with_scale(Vec3::ONE)),
            None => transform,
        };
        let world = collider.to_world(&transform);
        placed.add(entity, entity, &transform, world, Layers::DEFAULT);
    }
}

/// Gives every cloth the colliders placed this step, each with its motion since the last
/// step (so the solver sweeps it through the step and friction carries the cloth along):
/// all of them, or the ones its layers meet.
pub(crate) fn give_colliders(
    mut placed: ResMut<PlacedColliders>,
    mut cloths: Query<&mut ClothSimulation>,
) {
    placed.poses.end_step();
    let placed = &*placed;
    // Side by side, as the cloths step: each one's colliders are its own.
    let cloths = cloths
        .iter_mut()
        .map(|sim| (sim.solver.particle_count() as u64, sim));
    solver::share_items(cloths, |mut sim| give(placed, &mut sim));
}

/// Gives `sim` the colliders of `placed` its layers meet.
fn give(placed: &PlacedColliders, sim: &mut ClothSimulation) {
    if placed.colliders.is_empty() && sim.solver.colliders().is_empty() {
        return;
    }
    sim.colliders_from.clear();
    let layers = sim.layers;
    if placed.layers.iter().all(|&l| l.meet(layers)) {
        sim.colliders_from.extend(0..placed.colliders.len() as u32);
        sim.solver.set_colliders(placed.colliders.iter().cloned());
    } else {
        let met = (0..placed.colliders.len()).filter(|&i| placed.layers[i].meet(layers));
        sim.colliders_from.extend(met.map(|i| i as u32));
        let from = &sim.colliders_from;
        let colliders = from.iter().map(|&i| placed.colliders[i as usize].clone());
        sim.solver.set_colliders(colliders);
    }
}

/// Why a [`ClothCollider`] is left out of every cloth's step (a size out of range, such as
/// a negative radius): the plugin puts this on the collider's entity, triggers
/// [`ClothColliderBecameInvalid`] on it and logs it once, and removes it once the collider
/// is fixed.
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[reflect(Component, Debug, PartialEq)]
pub struct ClothColliderInvalid(pub ClothError);

/// Checks each collider added or changed ([`ClothCollider::validate`]): one with a size
/// out of range is marked [`ClothColliderInvalid`] and left out of every cloth's step
/// until it is fixed (sizes were clamped to 0 in silence).
#[allow(clippy::type_complexity)]
fn check_colliders(
    mut commands: Commands,
    colliders: Query<(Entity, &ClothCollider, Has<ClothColliderInvalid>), Changed<ClothCollider>>,
) {
    for (entity, collider, invalid) in &colliders {
        match collider.validate() {
            Ok(()) if invalid => {
                commands.entity(entity).remove::<ClothColliderInvalid>();
            }
            Ok(()) => {}
            Err(error) => {
                commands
                    .entity(entity)
                    .insert(ClothColliderInvalid(error.clone()));
                commands.trigger(ClothColliderBecameInvalid { entity, error });
            }
        }
    }
}

/// Logs why a collider is left out, naming it by its `Name` when it has one.
fn log_invalid_collider(invalid: On<ClothColliderBecameInvalid>, names: Query<&Name>) {
    let who = Named(invalid.entity, names.get(invalid.entity).ok());
    error!("collider {who} is left out: {}", invalid.error);
}

/// Colliders ([`ClothCollider`]): checked when added or changed, placed from their
/// transforms every step and given to the cloths within reach.
pub struct ClothCollidersPlugin;

impl Plugin for ClothCollidersPlugin {
    fn build(&self, app: &mut App) {
        let schedule = crate::ecs::plugin::ClothSchedule::of(app);
        app.register_type::<ClothCollider>()
            .register_type::<ColliderKind>()
            .register_type::<ClothColliderSpan>()
            .register_type::<ClothColliderInvalid>()
            .register_type::<ClothColliderBecameInvalid>()
            .init_resource::<PlacedColliders>()
            .add_observer(log_invalid_collider)
            .add_systems(
                schedule,
                (check_colliders, place_colliders, give_colliders)
                    .chain()
                    .in_set(crate::ecs::plugin::ClothPrepareSystems::Colliders),
            );
    }
}
