//! Attachments: particles of a cloth held to other entities (a cape to a character's
//! shoulders, a flag to its pole), and the system that moves them every step.

use bevy::prelude::*;
use bevy::transform::helper::TransformHelper;

use crate::ecs::cloth::{ClothInvalid, ClothSimulation, Named, pause_invalid};
use crate::error::ClothError;
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
    /// By index (`j·width + i` for a grid); indices past the cloth are left out (with a
    /// warning); if none is inside it, the cloth is not simulated ([`ClothError::AttachmentHoldsNothing`]).
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
    /// run is not simulated ([`ClothError::AttachmentHoldsNothing`]).
    pub fn run(target: Entity, name: impl Into<String>) -> Self {
        Self {
            target,
            particles: AttachParticles::Run(name.into()),
            held: None,
        }
    }

    /// Each particle held to `target` at its point in `target`'s frame (a local offset),
    /// wherever the particle starts; indices past the cloth are left out as for
    /// [`AttachParticles::Indices`].
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
/// is rebuilt); a target without a transform (despawned) lets its particles go. An
/// attachment that holds none of the cloth's particles stops the cloth
/// ([`ClothError::AttachmentHoldsNothing`]) until its attachments change.
#[allow(clippy::type_complexity)]
fn attach_cloths(
    mut commands: Commands,
    transforms: TransformHelper,
    mut cloths: Query<
        (
            Entity,
            &mut ClothSimulation,
            &mut ClothAttachments,
            Option<&Name>,
        ),
        Without<ClothInvalid>,
    >,
) {
    for (entity, mut sim, mut attachments, name) in &mut cloths {
        let rebuilt = sim.is_added();
        let solver = &mut sim.solver;
        let who = Named(entity, name);
        // The chosen particles are the plugin's bookkeeping, not a change of the user's
        // attachments (which lifts a refusal, `retry_attachments`).
        let attachments = attachments.bypass_change_detection();
        for (k, attachment) in attachments.0.iter_mut().enumerate() {
            if rebuilt {
                attachment.held = None;
            }
            let Ok(frame) = transforms.compute_global_transform(attachment.target) else {
                for &(i, _) in attachment.held() {
                    solver.detach(i);
                }
                continue;
            };
            if attachment.held.is_none() {
                match choose_held(who, &attachment.particles, solver, &frame) {
                    Ok(held) => attachment.held = Some(held),
                    Err(reason) => {
                        let error = ClothError::AttachmentHoldsNothing {
                            attachment: k,
                            reason,
                        };
                        pause_invalid(&mut commands, entity, error);
                        break;
                    }
                }
            }
            let attached = attachment
                .held()
                .iter()
                .try_for_each(|&(i, local)| solver.attach(i, frame.transform_point(local)));
            if let Err(e) = attached {
                warn!("cloth {who}: attachment {k}: {e}; choosing its particles again");
                attachment.held = None;
            }
        }
    }
}

/// A cloth stopped by an attachment that held nothing runs again once its attachments
/// change (they are chosen afresh on the next step).
fn retry_attachments(
    mut commands: Commands,
    cloths: Query<(Entity, &ClothInvalid), Changed<ClothAttachments>>,
) {
    for (entity, invalid) in &cloths {
        if matches!(invalid.0, ClothError::AttachmentHoldsNothing { .. }) {
            commands.entity(entity).remove::<ClothInvalid>();
        }
    }
}

/// The particles an attachment holds and each one's point in the target's frame (`frame`
/// where the target is now): given, or where the particle is now; or why it holds none.
fn choose_held(
    who: Named,
    particles: &AttachParticles,
    solver: &solver::ClothSolver,
    frame: &GlobalTransform,
) -> Result<Vec<(u32, Vec3)>, String> {
    let x = solver.positions();
    let to_local = frame.affine().inverse();
    let here = |i: u32| (i, to_local.transform_point3(x[i as usize]));
    let kept = |held: Vec<(u32, Vec3)>, given: usize| left_out(who, held, given, x.len());
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
            if *count == 0 {
                return Err("it asks for the 0 particles nearest a point".into());
            }
            let at = frame.transform_point(*point);
            let mut order: Vec<u32> = (0..x.len() as u32).collect();
            order.sort_by(|&a, &b| {
                x[a as usize]
                    .distance_squared(at)
                    .total_cmp(&x[b as usize].distance_squared(at))
            });
            order.truncate(*count as usize);
            Ok(order.into_iter().map(here).collect())
        }
        AttachParticles::Run(name) => match solver.run(name) {
            Some(run) if !run.is_empty() => Ok(run.iter().copied().map(here).collect()),
            _ => Err(format!("the cloth has no garment run named `{name}`")),
        },
    }
}

/// `held`, the particles of `given` that the cloth (of `count` particles) has: the others
/// are left out with a warning; none held at all is an error (a cloth whose every
/// attached index lay outside it fell without a word).
fn left_out(
    who: Named,
    held: Vec<(u32, Vec3)>,
    given: usize,
    count: usize,
) -> Result<Vec<(u32, Vec3)>, String> {
    if held.is_empty() {
        return Err(format!(
            "none of its {given} particles is among the cloth's {count} (indices 0 to {}) \
             with a finite point",
            count.saturating_sub(1)
        ));
    }
    if held.len() < given {
        warn!(
            "cloth {who}: {} of the attachment's {given} particles are not among its {count} \
             (or their points are not finite) and are left out",
            given - held.len(),
        );
    }
    Ok(held)
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
                (retry_attachments, attach_cloths)
                    .chain()
                    .in_set(crate::ecs::plugin::ClothPrepareSystems::Attach),
            );
    }
}
