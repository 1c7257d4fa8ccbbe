//! Scene files: cloths, gravity, wind and timestep as data (RON, like Bevy's own scenes).
//!
//! ```ron
//! (
//!     timestep: 0.016,
//!     environment: (gravity: (0.0, -9.81, 0.0), wind: (direction: (0.0, 0.0, 1.0), strength: 0.001)),
//!     cloths: [
//!         (name: "curtain", translation: (0.0, 2.0, 0.0),
//!          cloth: (shape: Grid(width: 32, height: 32, spacing: 0.05), pins: TopCorners)),
//!     ],
//! )
//! ```

use std::path::{Path, PathBuf};

use bevy::math::Vec3;
use bevy::reflect::{GetPath, Reflect};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use bevy::ecs::entity::Entity;
use bevy::ecs::name::Name;
use bevy::ecs::system::Commands;

use crate::params::{Environment, WindZone};
use crate::{Cloth, ClothCollider, ClothEnvironment, ClothLod, ClothStats};

/// A scene: the cloths, their world and the timestep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClothScene {
    /// Fixed timestep in s (Sladović 2014 §5: 16 ms).
    #[serde(default = "default_timestep")]
    pub timestep: f32,
    /// Gravity and wind.
    #[serde(default)]
    pub environment: Environment,
    /// The cloths.
    pub cloths: Vec<SceneCloth>,
    /// Solids the cloths are kept out of (a mannequin, a ground).
    #[serde(default)]
    pub colliders: Vec<SceneCollider>,
    /// Regions of moving air ([`WindZone`]), blowing through the air model on every
    /// cloth they reach: `wind_zones: [(shape: Sphere(radius: 2.0), centre: (0, 1, 0),
    /// velocity: (6, 0, 0), falloff: 0.25)]`. Spawned as
    /// [`ClothWindZone`](crate::ClothWindZone) entities.
    #[serde(default)]
    pub wind_zones: Vec<WindZone>,
}

/// A collider in a scene, with where it is and whether it is drawn.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneCollider {
    /// A name for the entity.
    #[serde(default)]
    pub name: String,
    /// Where its origin is.
    #[serde(default, with = "crate::params::vec3_serde")]
    pub translation: Vec3,
    /// Rotation as Euler angles X, Y, Z in degrees (applied in that order).
    #[serde(default, with = "crate::params::vec3_serde")]
    pub rotation_degrees: Vec3,
    /// The solid, its thickness and friction.
    pub collider: ClothCollider,
    /// Colour to draw it in (linear RGB 0–1); not drawn when absent.
    #[serde(default)]
    pub color: Option<[f32; 3]>,
}

impl SceneCollider {
    /// The entity's transform.
    pub fn transform(&self) -> bevy::transform::components::Transform {
        let r = self.rotation_degrees * (std::f32::consts::PI / 180.0);
        bevy::transform::components::Transform::from_translation(self.translation).with_rotation(
            bevy::math::Quat::from_euler(bevy::math::EulerRot::XYZ, r.x, r.y, r.z),
        )
    }
}

fn default_timestep() -> f32 {
    0.016
}

/// One cloth in a scene, with where it is and how it looks.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneCloth {
    /// A name for the entity.
    #[serde(default)]
    pub name: String,
    /// Where the cloth's frame is (for a grid: the middle of its top edge).
    #[serde(default, with = "crate::params::vec3_serde")]
    pub translation: Vec3,
    /// Rotation of the frame about the vertical axis, in degrees.
    #[serde(default)]
    pub yaw_degrees: f32,
    /// Tilt of the frame about its x axis before the yaw, in degrees: 90 lays a grid
    /// level (its rows running away along −z).
    #[serde(default)]
    pub pitch_degrees: f32,
    /// Shape, pins and model parameters.
    pub cloth: Cloth,
    /// Base colour as linear RGB in 0–1.
    #[serde(default = "default_color")]
    pub color: [f32; 3],
    /// Colours of a garment's pieces in order (front, back, …); pieces past the list take
    /// `color`.
    #[serde(default)]
    pub piece_colors: Vec<[f32; 3]>,
    /// Level of detail (a grid cloth's model from its size on screen, see
    /// [`crate::ClothLod`]) with its default thresholds.
    #[serde(default)]
    pub lod: bool,
}

impl SceneCloth {
    /// The cloth's frame: its translation, tilted by `pitch_degrees` about +x, then
    /// turned by `yaw_degrees` about +y.
    pub fn transform(&self) -> bevy::transform::components::Transform {
        use bevy::math::Quat;
        let yaw = Quat::from_rotation_y(self.yaw_degrees.to_radians());
        let pitch = Quat::from_rotation_x(self.pitch_degrees.to_radians());
        bevy::transform::components::Transform::from_translation(self.translation)
            .with_rotation(yaw * pitch)
    }
}

fn default_color() -> [f32; 3] {
    [0.6, 0.1, 0.12]
}

/// What is wrong with a scene file.
#[derive(Debug, Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{file}: {source}")]
    Io {
        /// The file.
        file: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The file is not a valid scene (syntax, unknown or missing field, wrong type).
    #[error("{file}:{line}:{column}: {message}")]
    Parse {
        /// The file.
        file: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What the parser expected.
        message: String,
    },
    /// A `--set key=value` override that does not apply.
    #[error("--set {spec}: {message}")]
    Override {
        /// The override as given.
        spec: String,
        /// What is wrong.
        message: String,
    },
    /// A value is out of range.
    #[error("{file}:{line}: `{field}`: {message}")]
    Invalid {
        /// The file.
        file: PathBuf,
        /// 1-based line of the cloth (or of the field, when it can be found).
        line: usize,
        /// The field path, e.g. `cloths[0].cloth.params.node_mass`.
        field: String,
        /// What is wrong.
        message: String,
    },
}

/// The entities [`ClothScene::spawn`] made, in the scene's order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SpawnedScene {
    /// One per entry of `cloths`.
    pub cloths: Vec<Entity>,
    /// One per entry of `colliders`.
    pub colliders: Vec<Entity>,
}

impl ClothScene {
    /// Spawns the scene: each cloth (its [`Cloth`], `Name`, `Transform` and
    /// [`ClothStats`]) and each collider (its [`ClothCollider`], `Name`, `Transform`), and
    /// sets the environment. How they look (materials, collider meshes) is the app's to
    /// add to the returned entities, and so is the clock: the scene's `timestep` is what
    /// it was made for, and `Time<Fixed>` stays the game's (set it from the scene with
    /// [`ClothPlugin::with_timestep`](crate::ClothPlugin::with_timestep) or
    /// `Time::<Fixed>::from_seconds`, as the examples do).
    pub fn spawn(&self, commands: &mut Commands) -> SpawnedScene {
        let colliders = self
            .colliders
            .iter()
            .map(|entry| {
                commands
                    .spawn((
                        entry.collider.clone(),
                        entry.transform(),
                        Name::new(entry.name.clone()),
                    ))
                    .id()
            })
            .collect();
        commands.insert_resource(ClothEnvironment(self.environment));
        for zone in &self.wind_zones {
            commands.spawn((
                crate::ClothWindZone::from_world(zone),
                bevy::transform::components::Transform::from_translation(zone.centre)
                    .with_rotation(zone.rotation),
                Name::new("wind zone"),
            ));
        }
        let cloths = self
            .cloths
            .iter()
            .map(|entry| {
                let mut cloth = commands.spawn((
                    entry.cloth.clone(),
                    ClothStats::default(),
                    Name::new(entry.name.clone()),
                    entry.transform(),
                ));
                if entry.lod {
                    cloth.insert(ClothLod::default());
                }
                cloth.id()
            })
            .collect();
        SpawnedScene { cloths, colliders }
    }
}

impl ClothScene {
    /// Reads and checks a scene file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, SceneError> {
        let file = path.as_ref().to_path_buf();
        let text = crate::limits::read_text(&file).map_err(|source| SceneError::Io {
            file: file.clone(),
            source,
        })?;
        Self::parse(&text, &file)
    }

    /// Parses and checks scene text; `file` names it in errors.
    pub fn parse(text: &str, file: &Path) -> Result<Self, SceneError> {
        let scene: ClothScene = ron::from_str(text).map_err(|e| SceneError::Parse {
            file: file.to_path_buf(),
            line: e.span.start.line,
            column: e.span.start.col,
            message: e.code.to_string(),
        })?;
        scene.validate(text, file)?;
        Ok(scene)
    }

    /// Applies an override `key=value`, as the examples' and the command line's `--set`:
    /// `timestep=0.01`, `environment.wind.strength=0`, `environment.gravity=0,-1.6,0`,
    /// `cloth.params.node_mass=0.001` (every cloth), `cloths[1].pins=TopRow` (one cloth),
    /// `cloth.params.substeps=auto` or `=8`, `cloth.params.tear_ratio=none` or `=2.5`,
    /// `cloth.shape.width=64`. Keys are reflection paths into [`Environment`] and
    /// [`Cloth`]; the result is checked like a scene file.
    ///
    /// A refused override leaves the scene as it was.
    pub fn apply_override(&mut self, spec: &str) -> Result<(), SceneError> {
        let mut edited = self.clone();
        edited.apply_override_in_place(spec)?;
        *self = edited;
        Ok(())
    }

    /// [`ClothScene::apply_override`] without the copy: on an error the scene may hold the
    /// refused value.
    fn apply_override_in_place(&mut self, spec: &str) -> Result<(), SceneError> {
        let fail = |message: String| SceneError::Override {
            spec: spec.to_string(),
            message,
        };
        let (key, value) = spec
            .split_once('=')
            .ok_or_else(|| fail("expected key=value".into()))?;
        let (key, value) = (key.trim(), value.trim());
        if key == "timestep" {
            self.timestep = value
                .parse()
                .map_err(|_| fail(format!("`{value}` is not a number")))?;
        } else if let Some(path) = key.strip_prefix("environment.") {
            set_field(&mut self.environment, path, value).map_err(fail)?;
        } else if let Some(path) = key.strip_prefix("cloth.") {
            if self.cloths.is_empty() {
                return Err(fail("the scene has no cloth".into()));
            }
            for entry in &mut self.cloths {
                set_field(&mut entry.cloth, path, value).map_err(fail)?;
            }
        } else if let Some(rest) = key.strip_prefix("cloths[") {
            let (index, path) = rest
                .split_once("].")
                .ok_or_else(|| fail("expected cloths[N].field".into()))?;
            let count = self.cloths.len();
            let entry = index
                .parse::<usize>()
                .ok()
                .and_then(|i| self.cloths.get_mut(i))
                .ok_or_else(|| fail(format!("no cloth {index}: the scene has {count}")))?;
            set_field(&mut entry.cloth, path, value).map_err(fail)?;
        } else {
            return Err(fail(
                "keys start with timestep, environment., cloth. or cloths[N].".into(),
            ));
        }
        // Said once: what is wrong, and the field only when it is not the key's own (not
        // the override again as a file).
        self.validate("", Path::new(spec)).map_err(|e| match e {
            SceneError::Invalid { field, message, .. } => fail(refusal_of(key, &field, &message)),
            other => fail(other.to_string()),
        })
    }

    /// The first cloth or collider placed out of range (not finite, or farther than
    /// `limits::MAX_POSITION`): its field, the key to point at, the message and the
    /// section it is in.
    fn misplaced(&self) -> Option<(String, &'static str, String, &'static str)> {
        let placed = |p: Vec3| p.is_finite() && p.length() <= crate::limits::MAX_POSITION;
        let angle = |a: f32| a.is_finite() && a.abs() <= crate::limits::MAX_POSITION;
        for (i, entry) in self.cloths.iter().enumerate() {
            let checks = [
                ("translation", placed(entry.translation)),
                ("yaw_degrees", angle(entry.yaw_degrees)),
                ("pitch_degrees", angle(entry.pitch_degrees)),
            ];
            if let Some((key, _)) = checks.iter().find(|(_, ok)| !ok) {
                let message = format!(
                    "must be finite and within {max:e} (limits::MAX_POSITION)",
                    max = crate::limits::MAX_POSITION
                );
                return Some((format!("cloths[{i}].{key}"), key, message, "cloths"));
            }
        }
        for (i, entry) in self.colliders.iter().enumerate() {
            if !placed(entry.translation) || !placed(entry.rotation_degrees) {
                let message = format!(
                    "translation and rotation_degrees must be finite and within {max:e} (limits::MAX_POSITION)",
                    max = crate::limits::MAX_POSITION
                );
                let field = format!("colliders[{i}].translation");
                return Some((field, "translation", message, "colliders"));
            }
        }
        None
    }

    /// What is wrong with cloth entry `i`, if anything: the field's path, its key in the
    /// file and the message (its garment file first, then its shape, pins and params).
    fn cloth_error(i: usize, entry: &SceneCloth) -> Option<(String, &'static str, String)> {
        if let crate::layout::shape::ClothShape::Garment { file, resolution } = &entry.cloth.shape {
            let path = crate::layout::garment::asset_path(file);
            if let Err(e) = crate::layout::garment::GarmentLayout::load(&path, *resolution) {
                return Some((format!("cloths[{i}].cloth.shape"), "Garment", e.to_string()));
            }
        }
        let e = entry.cloth.validate().err()?;
        let field = error_field(&e);
        let path = if field.starts_with("shape") || field == "pins" {
            format!("cloths[{i}].cloth.{field}")
        } else {
            format!("cloths[{i}].cloth.params.{field}")
        };
        Some((path, leaf(field), e.to_string()))
    }

    /// More cloths or colliders than [`MAX_SCENE_ITEMS`](crate::limits::MAX_SCENE_ITEMS):
    /// which, and the message.
    fn too_many(&self) -> Option<(&'static str, String)> {
        let max = crate::limits::MAX_SCENE_ITEMS;
        [
            ("cloths", self.cloths.len()),
            ("colliders", self.colliders.len()),
            ("wind_zones", self.wind_zones.len()),
        ]
        .into_iter()
        .find(|&(_, count)| count > max)
        .map(|(key, count)| {
            (
                key,
                format!("{count} {key}: at most {max} (limits::MAX_SCENE_ITEMS)"),
            )
        })
    }

    fn validate(&self, text: &str, file: &Path) -> Result<(), SceneError> {
        let invalid = |field: String, key: &str, message: String, after: usize| {
            // Point at the line of the offending key, searching from the cloth's entry.
            let after = after.min(text.len());
            let offset = text
                .get(after..)
                .and_then(|rest| rest.find(&format!("{key}:")))
                .map_or(after, |o| after + o);
            SceneError::Invalid {
                file: file.to_path_buf(),
                line: text[..offset.min(text.len())].lines().count().max(1),
                field,
                message,
            }
        };
        if !(self.timestep > 0.0 && self.timestep <= 1.0) {
            return Err(invalid(
                "timestep".into(),
                "timestep",
                format!("must be in (0, 1] s, got {}", self.timestep),
                0,
            ));
        }
        if let Some((key, message)) = self.too_many() {
            return Err(invalid(key.into(), key, message, 0));
        }
        if let Err(e) = self.environment.validate() {
            let field = error_field(&e);
            return Err(invalid(
                format!("environment.{field}"),
                leaf(field),
                e.to_string(),
                0,
            ));
        }
        if let Some((field, key, message, section)) = self.misplaced() {
            let after = text.find(section).unwrap_or(0);
            return Err(invalid(field, key, message, after));
        }
        let mut search_from = text.find("cloths").unwrap_or(0);
        for (i, entry) in self.cloths.iter().enumerate() {
            let entry_start = text
                .get(search_from..)
                .and_then(|rest| rest.find("cloth:"))
                .map_or(search_from, |o| search_from + o);
            if let Some((path, key, message)) = Self::cloth_error(i, entry) {
                return Err(invalid(path, key, message, entry_start));
            }
            search_from = entry_start + 1;
        }
        if let Some((section, path, field, message)) = self.world_error() {
            let after = text.find(section).unwrap_or(0);
            return Err(invalid(path, leaf(field), message, after));
        }
        Ok(())
    }

    /// The first collider or wind zone that fails its check: its section, its path, its
    /// field and the message.
    fn world_error(&self) -> Option<(&'static str, String, &'static str, String)> {
        let mut bad = self.colliders.iter().enumerate();
        if let Some((i, e)) = bad.find_map(|(i, c)| c.collider.validate().err().map(|e| (i, e))) {
            let field = error_field(&e);
            let path = format!("colliders[{i}].collider.{field}");
            return Some(("colliders", path, field, e.to_string()));
        }
        let mut bad = self.wind_zones.iter().enumerate();
        let (i, e) = bad.find_map(|(i, z)| z.validate().err().map(|e| (i, e)))?;
        let field = error_field(&e).trim_start_matches("wind_zone.");
        let path = format!("wind_zones[{i}].{field}");
        Some(("wind_zones", path, field, e.to_string()))
    }
}

/// Sets the field at a reflection `path` of `target` from text: numbers, booleans,
/// vectors `x,y,z`, `none` or a number for optional numbers, `auto` or a count for
/// substeps, and unit variant names for enums (`TopRow`, `Trigonometric`, `Verlet`).
/// What `--set` and [`ClothScene::apply_override`] use; on a component (a [`Cloth`], an
/// [`Environment`]) it edits as the inspector does, and the plugin checks the result.
/// Never panics: a path or value that does not fit is an error naming it.
pub fn set_field(target: &mut dyn Reflect, path: &str, value: &str) -> Result<(), String> {
    use bevy::reflect::ReflectMut;
    use bevy::reflect::enums::{DynamicEnum, DynamicVariant};

    let field = target
        .reflect_path_mut(path)
        .map_err(|e| format!("no field `{path}`: {e}"))?;
    // `inf` passes here (XPBD's inextensible springs); the parameters' validation
    // refuses it wherever a finite value is needed, naming the field.
    let number = || {
        value
            .parse::<f32>()
            .ok()
            .filter(|v| !v.is_nan() && *v != f32::NEG_INFINITY)
            .ok_or_else(|| format!("`{value}` is not a number (or inf)"))
    };
    if let Some(f) = field.try_downcast_mut::<f32>() {
        *f = number()?;
    } else if let Some(f) = field.try_downcast_mut::<u32>() {
        *f = value
            .parse()
            .map_err(|_| format!("`{value}` is not a whole number ≥ 0"))?;
    } else if let Some(f) = field.try_downcast_mut::<bool>() {
        *f = value
            .parse()
            .map_err(|_| format!("`{value}` is not true or false"))?;
    } else if let Some(f) = field.try_downcast_mut::<Vec3>() {
        let parts: Vec<f32> = value
            .split(',')
            .map(|p| p.trim().parse::<f32>())
            .collect::<Result<_, _>>()
            .map_err(|_| format!("`{value}` is not a vector x,y,z"))?;
        match parts[..] {
            [x, y, z] => *f = Vec3::new(x, y, z),
            _ => return Err(format!("`{value}` is not a vector x,y,z")),
        }
    } else if let Some(f) = field.try_downcast_mut::<Option<f32>>() {
        *f = if value.eq_ignore_ascii_case("none") {
            None
        } else {
            Some(number()?)
        };
    } else if let Some(done) = set_by_name(field, value) {
        done?;
    } else if let ReflectMut::Enum(e) = field.reflect_mut() {
        let unit = DynamicEnum::new(value, DynamicVariant::Unit);
        e.try_apply(&unit).map_err(|_| {
            let names = e
                .get_represented_enum_info()
                .map(|info| info.variant_names().join(", "))
                .unwrap_or_default();
            format!("`{value}` is not one of {names}")
        })?;
    } else {
        return Err(format!("`{path}` cannot be set from the command line"));
    }
    Ok(())
}

/// The fields [`set_field`] takes by name: a model (with its defaults), a fabric preset
/// (or `none`), substeps (`auto` or a count). `None` when `field` is none of those.
fn set_by_name(
    field: &mut dyn bevy::reflect::PartialReflect,
    value: &str,
) -> Option<Result<(), String>> {
    use crate::fabric::Fabric;
    use crate::params::{Model, PatchParams, ShapeMatchingParams, Substeps, XpbdParams};
    if let Some(f) = field.try_downcast_mut::<Option<Fabric>>() {
        // A preset by name (`--set cloth.params.fabric=denim`), or `none`.
        *f = if value.eq_ignore_ascii_case("none") {
            None
        } else {
            match Fabric::named(value) {
                Ok(fabric) => Some(fabric),
                Err(e) => return Some(Err(e.to_string())),
            }
        };
    } else if let Some(f) = field.try_downcast_mut::<Model>() {
        *f = match value {
            "MassSpring" => Model::MassSpring,
            "ShapeMatching" => Model::ShapeMatching(ShapeMatchingParams::default()),
            "Patches" => Model::Patches(PatchParams::default()),
            "Xpbd" => Model::Xpbd(XpbdParams::default()),
            _ => {
                return Some(Err(format!(
                    "`{value}` is not MassSpring, ShapeMatching, Patches or Xpbd"
                )));
            }
        };
    } else if let Some(f) = field.try_downcast_mut::<Substeps>() {
        *f = if value.eq_ignore_ascii_case("auto") {
            Substeps::default()
        } else {
            match value.parse() {
                Ok(n) => Substeps::Fixed(n),
                Err(_) => return Some(Err(format!("`{value}` is not `auto` or a substep count"))),
            }
        };
    } else {
        return None;
    }
    Some(Ok(()))
}

/// The refusal of an override of `key` by `field`'s check: its `message` without the
/// field it starts with, and the field only when it is another than the key's.
fn refusal_of(key: &str, field: &str, message: &str) -> String {
    let path = key
        .strip_prefix("cloth.")
        .or_else(|| key.split_once("].").map(|(_, path)| path))
        .unwrap_or(key);
    // `self_collision.distance` must be …: the field named again, inside backticks.
    let message = message
        .strip_prefix('`')
        .and_then(|rest| rest.split_once("` "))
        .filter(|(named, _)| field.ends_with(named))
        .map_or(message, |(_, rest)| rest);
    if field.ends_with(path) {
        message.to_string()
    } else {
        format!("`{field}`: {message}")
    }
}

fn error_field(e: &crate::error::ClothError) -> &'static str {
    use crate::error::ClothError::*;
    match e {
        InvalidParameter { field, .. } | TooMuchWork { field, .. } => field,
        GridTooSmall { .. } | GridTooLarge { .. } => "shape",
        PinOutOfRange { .. } => "pins",
        BadMesh { .. }
        | BadLayout { .. }
        | ModelNeedsGrid { .. }
        | ShapeNeedsSource { .. }
        | PaintNeedsMesh { .. }
        | EmptyGarment
        | Pattern(_)
        | Garment { .. } => "shape",
        UnknownModel { .. } => "model",
        ModelLacks { feature, .. } if feature.starts_with("fabric") => "fabric",
        ModelLacks { .. } => "self_collision",
        UnknownFabric { .. } | FabricNeedsSurface => "fabric",
        NotMeasurable { .. } | NonFinite { .. } | AttachmentHoldsNothing { .. } => "cloths",
    }
}

fn leaf(field: &str) -> &str {
    // `springs.shear.stiffness`: the family's name (`shear`) finds the line, not `stiffness`.
    let mut parts = field.rsplit('.');
    match (parts.next(), parts.next()) {
        (Some("stiffness"), Some(family)) => family,
        (Some(last), _) => last,
        _ => field,
    }
}
