//! Culling: cloths no camera sees, or too far from every one, do not step.

use bevy::camera::primitives::{Frustum, Sphere};
use bevy::prelude::*;
use bevy::transform::helper::TransformHelper;

use crate::ecs::cloth::ClothSimulation;
use crate::ecs::stats::ClothStats;
use crate::params::TeleportMode;

/// Culls a cloth: while its particles' bounding sphere is outside every active camera's
/// view (with `off_screen`), or farther than `max_distance` from every one, it takes no
/// steps (its pins and targets are still followed, so nothing is lost), as Magica
/// Cloth's culling stops its cloths. When it is seen again it is set on its body at
/// rest (a [`TeleportMode::Reset`] of its drivers' motion meanwhile), rather than swung
/// across the gap its body walked while it slept. Cameras without a [`Frustum`] (none
/// rendered yet) see everything. [`ClothStats::culled`] counts it.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component, Default)]
pub struct ClothCulling {
    /// Stop while outside every camera's view.
    pub off_screen: bool,
    /// Stop while farther than this from every camera, m (`inf`: never for distance).
    pub max_distance: f32,
    /// Whether it is culled now (set by the plugin).
    pub culled: bool,
}

impl Default for ClothCulling {
    /// Off screen, at any distance.
    fn default() -> Self {
        ClothCulling {
            off_screen: true,
            max_distance: f32::INFINITY,
            culled: false,
        }
    }
}

/// Culling ([`ClothCulling`], on the cloths that have one). In
/// [`ClothPlugin`](crate::ClothPlugin).
pub struct ClothCullingPlugin;

impl Plugin for ClothCullingPlugin {
    fn build(&self, app: &mut App) {
        let schedule = crate::ecs::plugin::ClothSchedule::of(app);
        app.register_type::<ClothCulling>().add_systems(
            schedule,
            cull.in_set(crate::ecs::plugin::ClothPrepareSystems::Levels),
        );
    }
}

/// Whether any of `cameras` (their place, and their view if rendered) sees a sphere at
/// `centre` of `radius` within `max_distance`.
fn seen(
    cameras: &[(Vec3, Option<Frustum>)],
    centre: Vec3,
    radius: f32,
    culling: &ClothCulling,
) -> bool {
    let sphere = Sphere {
        center: centre.into(),
        radius,
    };
    cameras.iter().any(|(eye, frustum)| {
        let near = eye.distance(centre) - radius <= culling.max_distance;
        let in_view =
            !culling.off_screen || frustum.is_none_or(|f| f.intersects_sphere(&sphere, true));
        near && in_view
    })
}

/// Marks each [`ClothCulling`] cloth culled or not from the active cameras; one seen
/// again is put back on its body at rest.
fn cull(
    transforms: TransformHelper,
    cameras: Query<(Entity, &Camera, Option<&Frustum>)>,
    mut cloths: Query<(
        &mut ClothCulling,
        &mut ClothSimulation,
        Option<&mut ClothStats>,
    )>,
) {
    let eyes: Vec<(Vec3, Option<Frustum>)> = cameras
        .iter()
        .filter(|(_, camera, _)| camera.is_active)
        .filter_map(|(entity, _, frustum)| {
            let eye = transforms.compute_global_transform(entity).ok()?;
            Some((eye.translation(), frustum.copied()))
        })
        .collect();
    if eyes.is_empty() {
        return;
    }
    for (mut culling, mut sim, stats) in &mut cloths {
        let (centre, radius) = sim.solver.bounding_sphere();
        let culled = !seen(&eyes, centre, radius, &culling);
        if culled != culling.culled {
            culling.culled = culled;
            if !culled {
                sim.solver.teleport_next_step(TeleportMode::Reset);
            }
        }
        if let Some(mut stats) = stats {
            stats.culled = culled;
        }
    }
}
