//! The Bevy layer, one file per feature: the cloth components, `ClothPlugin` with its
//! system sets and systems, the render mesh written in place. It owns each solver inside a component and knows nothing of how a layout is
//! made. Its public items are re-exported at the crate's root.

pub(crate) mod attach;
#[cfg(feature = "avian")]
pub mod avian;
pub(crate) mod budget;
pub(crate) mod build;
pub(crate) mod cloth;
pub(crate) mod colliders;
pub(crate) mod culling;
pub(crate) mod events;
pub(crate) mod lod;
pub(crate) mod mesh;
pub(crate) mod plugin;
pub(crate) mod proxy;
pub(crate) mod skin;
pub(crate) mod sleep;
pub(crate) mod stats;
pub(crate) mod step;
pub(crate) mod wind;

pub use attach::{AttachParticles, ClothAttachPlugin, ClothAttachment, ClothAttachments};
pub use budget::{
    ClothBudget, ClothBudgetPlugin, ClothOverBudget, ClothPriority, ClothStageStats,
    ClothWithinBudget,
};
pub use build::ClothGarmentPlugin;
pub use cloth::{
    Cloth, ClothEnvironment, ClothInterpolation, ClothInvalid, ClothPause, ClothSimulation,
};
pub use colliders::{
    ClothCollider, ClothColliderInvalid, ClothColliderSpan, ClothCollidersPlugin, ColliderKind,
    TELEPORT_SPEED,
};
pub use culling::{ClothCulling, ClothCullingPlugin};
pub use events::{
    ClothAwoke, ClothBecameInvalid, ClothBuilt, ClothColliderBecameInvalid, ClothFellAsleep,
    ClothTeleport, ClothTeleported, ClothTorn,
};
pub use lod::{ClothLod, ClothLodPlugin};
pub use mesh::ClothMeshPlugin;
pub use plugin::{ClothCorePlugin, ClothPlugin, ClothPrepareSystems, ClothSystems};
pub use proxy::{ClothProxy, ClothProxyEntity, ClothProxyPlugin};
pub use skin::{
    ATTRIBUTE_BACK_STOP, ATTRIBUTE_MAX_DISTANCE, ClothBackStop, ClothMaxDistance, ClothSkinPlugin,
};
pub use sleep::{ClothSleep, ClothSleepPlugin, ClothWake};
pub use stats::{ClothStats, StatSample};
pub use step::{ClothSubstep, ClothSubstepPlan, ClothSubstepSystems};
pub use wind::{ClothWindPlugin, ClothWindZone};
