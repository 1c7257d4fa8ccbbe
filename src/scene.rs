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
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::components::Cloth;
use crate::params::Environment;

/// A scene: the cloths, their world and the timestep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClothScene {
    /// Fixed timestep in s (seed 000 §5: 16 ms).
    #[serde(default = "default_timestep")]
    pub timestep: f32,
    /// Gravity and wind.
    #[serde(default)]
    pub environment: Environment,
    /// The cloths.
    pub cloths: Vec<SceneCloth>,
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
    /// Shape, pins and model parameters.
    pub cloth: Cloth,
    /// Base colour as linear RGB in 0–1.
    #[serde(default = "default_color")]
    pub color: [f32; 3],
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

impl ClothScene {
    /// Reads and checks a scene file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, SceneError> {
        let file = path.as_ref().to_path_buf();
        let text = std::fs::read_to_string(&file).map_err(|source| SceneError::Io {
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

    fn validate(&self, text: &str, file: &Path) -> Result<(), SceneError> {
        let invalid = |field: String, key: &str, message: String, after: usize| {
            // Point at the line of the offending key, searching from the cloth's entry.
            let offset = text[after.min(text.len())..]
                .find(&format!("{key}:"))
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
        if let Err(e) = self.environment.validate() {
            let field = error_field(&e);
            return Err(invalid(
                format!("environment.{field}"),
                leaf(field),
                e.to_string(),
                0,
            ));
        }
        let mut search_from = text.find("cloths").unwrap_or(0);
        for (i, entry) in self.cloths.iter().enumerate() {
            let entry_start = text[search_from..]
                .find("cloth:")
                .map_or(search_from, |o| search_from + o);
            if let Err(e) = entry.cloth.validate() {
                let field = error_field(&e);
                let path = if field.starts_with("shape") || field == "pins" {
                    format!("cloths[{i}].cloth.{field}")
                } else {
                    format!("cloths[{i}].cloth.params.{field}")
                };
                return Err(invalid(path, leaf(field), e.to_string(), entry_start));
            }
            search_from = entry_start + 1;
        }
        Ok(())
    }
}

fn error_field(e: &crate::error::ClothError) -> &'static str {
    use crate::error::ClothError::*;
    match e {
        InvalidParameter { field, .. } => field,
        GridTooSmall { .. } | GridTooLarge { .. } => "shape",
        PinOutOfRange { .. } => "pins",
        BadMesh { .. } => "shape",
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
