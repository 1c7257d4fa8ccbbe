//! Garment files as Bevy assets. The plugin loads a garment cloth's file through the
//! asset server, with its patterns as loader dependencies, so with Bevy's `file_watcher`
//! feature editing the garment or any of its pattern files while the app runs rebuilds
//! the cloth. Headless runs read the same files directly ([`GarmentLayout::load`]).

use std::collections::HashMap;

use bevy::asset::io::Reader;
use bevy::asset::{Asset, AssetLoader, LoadContext};
use bevy::reflect::TypePath;

use super::{GarmentFile, GarmentLayout};
use crate::error::ClothError;
use crate::layout::pattern::{Pattern, PatternError, PatternErrorKind, PatternWarning};

type PatternRead = Result<(Pattern, Vec<PatternWarning>), PatternError>;

/// A garment file with its pattern files read: lays out a [`GarmentLayout`] at any
/// resolution. Loaded by [`GarmentLoader`] (`.ron`).
#[derive(Asset, TypePath, Clone, Debug)]
pub struct Garment {
    /// The garment file's asset path, for messages.
    pub file: String,
    /// The garment file's text (errors found at a resolution point into it).
    text: String,
    /// Each piece's pattern (or why it cannot be read), by its path as written in the
    /// garment file.
    patterns: HashMap<String, PatternRead>,
}

impl Garment {
    /// The garment laid out at `resolution` (see [`GarmentLayout::load`]).
    pub fn layout(&self, resolution: u32) -> Result<GarmentLayout, ClothError> {
        GarmentLayout::parse(&self.text, &self.file, resolution, |path| {
            self.patterns.get(path).cloned().unwrap_or_else(|| {
                Err(PatternError {
                    file: path.to_string(),
                    line: 1,
                    column: 1,
                    kind: PatternErrorKind::Io("not read with the garment".into()),
                })
            })
        })
    }
}

/// Loads [`Garment`]s. Only an unreadable garment file fails the load: a malformed
/// garment or pattern loads (so Bevy watches every file it read) and the cloth built from
/// it is [`crate::ClothInvalid`] with the file, line and column at fault,
/// until an edit fixes it.
#[derive(TypePath, Default)]
pub struct GarmentLoader;

impl AssetLoader for GarmentLoader {
    type Asset = Garment;
    type Settings = ();
    type Error = ClothError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        load_context: &mut LoadContext<'_>,
    ) -> Result<Garment, ClothError> {
        let file = load_context.path().to_string();
        let cannot_read = |message: String| ClothError::Garment {
            file: file.clone(),
            line: 1,
            column: 1,
            message,
        };
        let mut bytes = Vec::new();
        reader
            .read_to_end(&mut bytes)
            .await
            .map_err(|e| cannot_read(format!("cannot read the garment: {e}")))?;
        let text = String::from_utf8(bytes)
            .map_err(|_| cannot_read("the garment is not UTF-8 text".into()))?;
        // The pieces' pattern paths; a garment RON cannot parse is reported by `layout`.
        let desc: Option<GarmentFile> = ron::from_str(&text).ok();
        let mut patterns = HashMap::new();
        for piece in desc.iter().flat_map(|d| &d.pieces) {
            if patterns.contains_key(&piece.pattern) {
                continue;
            }
            let path = load_context.path().resolve_embed_str(&piece.pattern);
            let read = match path {
                Ok(path) => load_context
                    .read_asset_bytes(path.clone())
                    .await
                    .map(|bytes| (path.to_string(), bytes))
                    .map_err(|e| e.to_string()),
                Err(e) => Err(e.to_string()),
            };
            let pattern = match read {
                Ok((name, bytes)) => Pattern::parse(&bytes, &name),
                Err(e) => Err(PatternError {
                    file: piece.pattern.clone(),
                    line: 1,
                    column: 1,
                    kind: PatternErrorKind::Io(e),
                }),
            };
            patterns.insert(piece.pattern.clone(), pattern);
        }
        Ok(Garment {
            file,
            text,
            patterns,
        })
    }

    fn extensions(&self) -> &[&str] {
        &["ron"]
    }
}
