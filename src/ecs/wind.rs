//! Wind zones in the world: [`ClothWindZone`] entities, placed by their transforms, blow
//! on every cloth they reach through the air model.

use bevy::platform::collections::HashSet;
use bevy::prelude::*;
use bevy::transform::helper::TransformHelper;

use crate::ecs::cloth::ClothSimulation;
use crate::ecs::plugin::{ClothPrepareSystems, ClothSchedule};
use crate::params::{Turbulence, WindZone, ZoneShape};

/// A region of moving air: everywhere (`ZoneShape::Global`), a sphere or a box about
/// the entity, turned and scaled by its transform, fading over the outer `falloff` share
/// of its size, with gusts and turbulence. Its velocity is in the entity's own frame, so
/// turning the entity turns the wind. Every cloth it reaches feels it on its triangles
/// through the air model (`ClothEnvironment`'s air, or still air's coefficients when there
/// is none), each zone's velocity added to the air's; a global zone is the same as the
/// environment's air velocity, placed as an entity. A zone that fails its check is
/// skipped, with a warning once.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component)]
#[require(Transform)]
pub struct ClothWindZone {
    /// Where it blows, in the entity's frame.
    pub shape: ZoneShape,
    /// The air's velocity at full strength in the entity's frame, m/s.
    pub velocity: Vec3,
    /// The outer share of its size over which it fades to nothing, 0 to 1.
    pub falloff: f32,
    /// Gusts in time and turbulence in space.
    pub turbulence: Turbulence,
}

impl ClothWindZone {
    /// `zone` as a component, for an entity at its centre turned by its rotation
    /// (its velocity taken into that frame, so that [`placed`](Self::placed) gives
    /// `zone` back).
    pub fn from_world(zone: &WindZone) -> Self {
        ClothWindZone {
            shape: zone.shape,
            velocity: zone.rotation.inverse() * zone.velocity,
            falloff: zone.falloff,
            turbulence: zone.turbulence,
        }
    }

    /// Air moving at `velocity` everywhere.
    pub fn global(velocity: Vec3) -> Self {
        Self::new(ZoneShape::Global, velocity)
    }

    /// Air moving at `velocity` within `radius` of the entity, fading over its outer
    /// quarter.
    pub fn sphere(radius: f32, velocity: Vec3) -> Self {
        Self::new(ZoneShape::Sphere { radius }, velocity).with_falloff(0.25)
    }

    /// Air moving at `velocity` in a box of `half_extents` about the entity, fading over
    /// the outer quarter of each.
    pub fn cuboid(half_extents: Vec3, velocity: Vec3) -> Self {
        Self::new(ZoneShape::Box { half_extents }, velocity).with_falloff(0.25)
    }

    fn new(shape: ZoneShape, velocity: Vec3) -> Self {
        ClothWindZone {
            shape,
            velocity,
            falloff: 0.0,
            turbulence: Turbulence::default(),
        }
    }

    /// With this falloff.
    pub fn with_falloff(mut self, falloff: f32) -> Self {
        self.falloff = falloff;
        self
    }

    /// With these gusts and turbulence.
    pub fn with_turbulence(mut self, turbulence: Turbulence) -> Self {
        self.turbulence = turbulence;
        self
    }

    /// The zone placed by `transform` (its scale scales the shape: a sphere by its
    /// largest factor).
    pub fn placed(&self, transform: &GlobalTransform) -> WindZone {
        let (scale, rotation, centre) = transform.to_scale_rotation_translation();
        let shape = match self.shape {
            ZoneShape::Global => ZoneShape::Global,
            ZoneShape::Sphere { radius } => ZoneShape::Sphere {
                radius: radius * scale.abs().max_element(),
            },
            ZoneShape::Box { half_extents } => ZoneShape::Box {
                half_extents: half_extents * scale.abs(),
            },
        };
        WindZone {
            shape,
            centre,
            rotation,
            velocity: rotation * self.velocity,
            falloff: self.falloff,
            turbulence: self.turbulence,
        }
    }
}

/// Wind zones: [`ClothWindZone`] entities blow on the cloths they reach. In
/// [`ClothPlugin`](crate::ClothPlugin).
pub struct ClothWindPlugin;

impl Plugin for ClothWindPlugin {
    fn build(&self, app: &mut App) {
        let schedule = ClothSchedule::of(app);
        app.register_type::<ClothWindZone>()
            .register_type::<ZoneShape>()
            .register_type::<Turbulence>()
            .add_systems(schedule, blow.in_set(ClothPrepareSystems::Colliders));
    }
}

/// Hands every cloth the zones that reach it, on the world's clock (so that every cloth
/// in a zone gusts together). A zone that fails its check is skipped and named once.
fn blow(
    time: Res<Time>,
    transforms: TransformHelper,
    zones: Query<(Entity, &ClothWindZone)>,
    mut cloths: Query<&mut ClothSimulation>,
    mut warned: Local<HashSet<Entity>>,
    mut placed: Local<Vec<WindZone>>,
) {
    placed.clear();
    for (entity, zone) in &zones {
        // Where it is now (the fixed step runs before this frame's transforms are
        // propagated), as the colliders are placed.
        let Ok(transform) = transforms.compute_global_transform(entity) else {
            continue;
        };
        let zone = zone.placed(&transform);
        match zone.validate() {
            Ok(()) => placed.push(zone),
            Err(e) => {
                if warned.insert(entity) {
                    warn!("ClothWindZone on {entity}: {e}; it does not blow");
                }
            }
        }
    }
    let now = time.elapsed_secs();
    let placed = &*placed;
    // Side by side, as the cloths step: each one's zones are its own.
    let blown = cloths
        .iter_mut()
        .filter(|sim| !placed.is_empty() || !sim.solver.wind_zones().is_empty())
        .map(|sim| (sim.solver.particle_count() as u64, sim));
    crate::solver::share_items(blown, |mut sim| {
        sim.solver
            .set_wind_zones(placed, now)
            .expect("every zone checked");
    });
}
