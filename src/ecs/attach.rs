//! Attachments: particles of a cloth held to other entities (a cape to a character's
//! shoulders, a flag to its pole), and the system that moves them every step.

use bevy::prelude::*;
use bevy::transform::helper::TransformHelper;

use crate::ecs::cloth::ClothSimulation;
use crate::solver;

/// Attaches particles of this cloth to other entities (a cape to a character's
/// shoulders, a flag to a mast): each attached particle follows its entity's global
/// transform every step, interpolated over the substeps as pins are, at the point it had
/// in that entity's frame when first attached (or at a point given, [`ClothAttachment::at`]).
#[derive(Component, Clone, Debug, Default, PartialEq, Reflect)]
#[reflect(Component, Debug, Default, PartialEq)]
pub struct ClothAttachments(pub Vec<ClothAttachment>);

/// One entity and the particles held to it (see [`ClothAttachments`]).
#[derive(Clone, Debug, PartialEq, Reflect)]
#[reflect(Debug, PartialEq)]
pub struct ClothAttachment {
    /// The entity followed.
    pub target: Entity,
    /// Which particles.
    pub particles: AttachParticles,
    /// Each particle and its point in the target's frame, chosen when first attached
    /// (`None` until then, and again after the cloth is rebuilt).
    pub(crate) held: Option<Vec<(u32, Vec3)>>,
}

/// Which particles an attachment holds.
#[derive(Clone, Debug, PartialEq, Reflect)]
#[reflect(Debug, PartialEq)]
pub enum AttachParticles {
    /// By index (`j·width + i` for a grid); indices past the cloth are skipped.
    Indices(Vec<u32>),
    /// The `count` particles nearest `point`, a point in the target's frame (a shoulder).
    Nearest {
        /// The point, in the target entity's frame.
        point: Vec3,
        /// How many particles.
        count: u32,
    },
    /// A garment's named run of nodes (its file's `runs`, e.g. a collar).
    Run(String),
    /// Particles at given points of the target's frame (local offsets): each is pulled
    /// there from wherever it is.
    At(Vec<(u32, Vec3)>),
}

impl ClothAttachment {
    /// The garment run `name` (its file's `runs`) held to `target`; a cloth without such a
    /// run logs an error and attaches nothing.
    pub fn run(target: Entity, name: impl Into<String>) -> Self {
        Self {
            target,
            particles: AttachParticles::Run(name.into()),
            held: None,
        }
    }

    /// Each particle held to `target` at its point in `target`'s frame (a local offset),
    /// wherever the particle starts; indices past the cloth are skipped.
    pub fn at(target: Entity, points: Vec<(u32, Vec3)>) -> Self {
        Self {
            target,
            particles: AttachParticles::At(points),
            held: None,
        }
    }

    /// Particles `indices` held to `target`.
    pub fn indices(target: Entity, indices: Vec<u32>) -> Self {
        Self {
            target,
            particles: AttachParticles::Indices(indices),
            held: None,
        }
    }

    /// The `count` particles nearest `point` (in `target`'s frame) held to `target`.
    pub fn nearest(target: Entity, point: Vec3, count: u32) -> Self {
        Self {
            target,
            particles: AttachParticles::Nearest { point, count },
            held: None,
        }
    }

    /// The particles held and their points in the target's frame (empty until the first
    /// step after the cloth is built).
    pub fn held(&self) -> &[(u32, Vec3)] {
        self.held.as_deref().unwrap_or(&[])
    }
}

/// Holds each [`ClothAttachments`] cloth's particles at their entities' global
/// transforms for this step (the solver reaches them over its substeps). The particles and
/// their points in the target's frame are chosen the first time (and again when the cloth
/// is rebuilt); a target without a transform (despawned) lets its particles go.
fn attach_cloths(
    transforms: TransformHelper,
    mut cloths: Query<(Entity, &mut ClothSimulation, &mut ClothAttachments)>,
) {
    for (entity, mut sim, mut attachments) in &mut cloths {
        let rebuilt = sim.is_added();
        let solver = &mut sim.solver;
        for attachment in &mut attachments.0 {
            if rebuilt {
                attachment.held = None;
            }
            let Ok(frame) = transforms.compute_global_transform(attachment.target) else {
                for &(i, _) in attachment.held() {
                    solver.detach(i);
                }
                continue;
            };
            let held = attachment
                .held
                .get_or_insert_with(|| choose_held(entity, &attachment.particles, solver, &frame));
            let attached = held
                .iter()
                .try_for_each(|&(i, local)| solver.attach(i, frame.transform_point(local)));
            if let Err(e) = attached {
                warn!("cloth attachment: {e}; choosing its particles again");
                attachment.held = None;
            }
        }
    }
}

/// The particles an attachment holds and each one's point in the target's frame (`frame`
/// where the target is now): given, or where the particle is now.
fn choose_held(
    cloth: Entity,
    particles: &AttachParticles,
    solver: &solver::ClothSolver,
    frame: &GlobalTransform,
) -> Vec<(u32, Vec3)> {
    let x = solver.positions();
    let to_local = frame.affine().inverse();
    let here = |i: u32| (i, to_local.transform_point3(x[i as usize]));
    let kept = |held: Vec<(u32, Vec3)>, given: usize| left_out(cloth, held, given, x.len());
    match particles {
        AttachParticles::At(points) => kept(
            points
                .iter()
                .copied()
                .filter(|&(i, local)| (i as usize) < x.len() && local.is_finite())
                .collect(),
            points.len(),
        ),
        AttachParticles::Indices(list) => kept(
            list.iter()
                .copied()
                .filter(|&i| (i as usize) < x.len())
                .map(here)
                .collect(),
            list.len(),
        ),
        AttachParticles::Nearest { point, count } => {
            let at = frame.transform_point(*point);
            let mut order: Vec<u32> = (0..x.len() as u32).collect();
            order.sort_by(|&a, &b| {
                x[a as usize]
                    .distance_squared(at)
                    .total_cmp(&x[b as usize].distance_squared(at))
            });
            order.truncate(*count as usize);
            order.into_iter().map(here).collect()
        }
        AttachParticles::Run(name) => match solver.run(name) {
            Some(run) => run.iter().copied().map(here).collect(),
            None => {
                error!("cloth {cloth}: no run named `{name}` to attach");
                Vec::new()
            }
        },
    }
}

/// `held`, the particles of `given` that the cloth (of `count` particles) has: the others
/// are left out, and said so (a cloth whose every attached index lay outside it fell
/// without a word).
fn left_out(cloth: Entity, held: Vec<(u32, Vec3)>, given: usize, count: usize) -> Vec<(u32, Vec3)> {
    if held.len() < given {
        let nothing = if held.is_empty() {
            "; it holds nothing"
        } else {
            ""
        };
        warn!(
            "cloth {cloth}: {} of the attachment's {given} particles are not among its {count} \
             (or their points are not finite) and are left out{nothing}",
            given - held.len(),
        );
    }
    held
}

/// Attachments ([`ClothAttachments`]): particles held at points of other entities,
/// following them every step.
pub struct ClothAttachPlugin;

impl Plugin for ClothAttachPlugin {
    fn build(&self, app: &mut App) {
        let schedule = crate::ecs::plugin::ClothSchedule::of(app);
        app.register_type::<ClothAttachments>()
            .register_type::<ClothAttachment>()
            .register_type::<AttachParticles>()
            .add_systems(
                schedule,
                attach_cloths.in_set(crate::ecs::plugin::ClothPrepareSystems::Attach),
            );
    }
}
