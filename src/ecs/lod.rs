//! Level of detail: a cloth's model follows its size on screen.

use bevy::prelude::*;
use bevy::transform::helper::TransformHelper;

use crate::ecs::cloth::{Cloth, ClothSimulation};
use crate::params::{ClothParams, Model, PatchParams};

/// Level of detail: the cloth's model follows its size on screen. At level 0
/// the cloth runs its own model; below each threshold it switches to the patch model with
/// parts of 2×2, 4×4 and 8×8 particles (Sladović 2014 §3.4: cheaper the larger the parts),
/// which adopts the running state (no jump), and back as the cloth grows on screen. The
/// size is the cloth's bounding sphere projected by the active camera, as a fraction of
/// the view's height. Grid cloths only (the patch model needs a grid): on others it
/// stays at level 0. While not at level 0 the component owns `Cloth::params.model`
/// (the cloth's own model is kept and put back).
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[reflect(Component, Default)]
pub struct ClothLod {
    /// The fractions of the view's height below which the cloth goes to parts of 2×2,
    /// 4×4 and 8×8 (decreasing).
    pub thresholds: [f32; 3],
    /// A band of this fraction around each threshold: the cloth goes coarser below
    /// `t (1 − band)` and finer above `t (1 + band)`, so it does not flicker at one.
    pub band: f32,
    /// The current level, 0–3 (set by the plugin).
    pub level: usize,
    /// The size on screen last measured (set by the plugin).
    pub screen_fraction: f32,
    /// The cloth's own model, kept while the level is not 0.
    pub(crate) full: Option<crate::params::Model>,
}

impl Default for ClothLod {
    fn default() -> Self {
        Self {
            thresholds: [0.5, 0.25, 0.12],
            band: 0.1,
            level: 0,
            screen_fraction: 1.0,
            full: None,
        }
    }
}

impl ClothLod {
    /// The patch size of each level above 0.
    pub const PART_SIZES: [u32; 3] = [2, 4, 8];

    /// What level `level` runs, in words: `its own model` or `patches 2×2` (…).
    pub fn describe(level: usize) -> String {
        match level.checked_sub(1).and_then(|l| Self::PART_SIZES.get(l)) {
            Some(s) => format!("patches {s}×{s}"),
            None => "its own model".into(),
        }
    }

    /// The level a cloth at `fraction` of the view's height goes to from `level`: one
    /// level at a time, coarser below a threshold less the band, finer above one plus it.
    pub fn next_level(&self, level: usize, fraction: f32) -> usize {
        if level < 3 && fraction < self.thresholds[level] * (1.0 - self.band) {
            level + 1
        } else if level > 0 && fraction > self.thresholds[level - 1] * (1.0 + self.band) {
            level - 1
        } else {
            level
        }
    }
}

/// Sets each [`ClothLod`] cloth's level from its size on the active camera's view: the
/// bounding sphere of its particles, `radius / (distance · tan(fov/2))` for a perspective
/// camera (`radius / half height` for an orthographic one). A new level sets the cloth's
/// model (its own at 0, patches above), which `build_cloths` then applies.
fn choose_levels(
    transforms: TransformHelper,
    cameras: Query<(Entity, &Camera, &Projection)>,
    mut cloths: Query<(&mut Cloth, &mut ClothLod, &ClothSimulation)>,
) {
    let Some((camera, _, projection)) = cameras.iter().find(|(_, c, _)| c.is_active) else {
        return;
    };
    // Computed here rather than read from `GlobalTransform`, which a headless app
    // without transform propagation does not update.
    let Ok(eye) = transforms.compute_global_transform(camera) else {
        return;
    };
    for (mut cloth, mut lod, sim) in &mut cloths {
        if sim.solver.grid_size().is_none() {
            continue;
        }
        let (centre, radius) = sim.solver.bounding_sphere();
        let fraction = match projection {
            Projection::Perspective(p) => {
                let distance = eye.translation().distance(centre).max(f32::EPSILON);
                radius / (distance * (p.fov * 0.5).tan())
            }
            Projection::Orthographic(o) => radius / (o.area.height() * 0.5).max(f32::EPSILON),
            Projection::Custom(_) => continue,
        };
        let lod = lod.bypass_change_detection();
        lod.screen_fraction = fraction;
        let coarse = |level: usize| {
            Model::Patches(PatchParams {
                part_width: ClothLod::PART_SIZES[level - 1],
                part_height: ClothLod::PART_SIZES[level - 1],
                ..PatchParams::default()
            })
        };
        let mut level = lod.next_level(lod.level, fraction);
        // A cloth the patch model refuses (self-collision, a fabric in physical units)
        // keeps its own model at any distance: its own checks decide.
        let params = ClothParams {
            model: coarse(level.max(1)),
            ..cloth.params
        };
        if level > 0 && lod.level == 0 && params.validate().is_err() {
            level = 0;
        }
        if level == lod.level {
            continue;
        }
        if lod.level == 0 {
            lod.full = Some(cloth.params.model);
        }
        lod.level = level;
        cloth.params.model = match level {
            0 => lod.full.take().unwrap_or(cloth.params.model),
            l => coarse(l),
        };
    }
}

/// Level of detail ([`ClothLod`]): each cloth with one picks its model from its size on
/// screen before it is built and stepped.
pub struct ClothLodPlugin;

impl Plugin for ClothLodPlugin {
    fn build(&self, app: &mut App) {
        let schedule = crate::ecs::plugin::ClothSchedule::of(app);
        app.register_type::<ClothLod>().add_systems(
            schedule,
            choose_levels.in_set(crate::ecs::plugin::ClothPrepareSystems::Levels),
        );
    }
}
