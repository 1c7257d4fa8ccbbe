//! Garments: pattern pieces placed in space and stitched by seams (Maslova §1.4: "the
//! parts are joined by extra springs between the particles along the seams").
//!
//! A garment file (RON) lists the pieces and the seams; everything about a garment is
//! data, so a user can stitch their own:
//! ```ron
//! (
//!     spacing: 0.034,            // m between neighbouring nodes at resolution 1
//!     pieces: [
//!         (name: "front", pattern: "tshirt_front.txt", translation: (0.0, 0.0, 0.17)),
//!         (name: "back", pattern: "tshirt_back.txt", translation: (0.0, 0.0, -0.17),
//! yaw_degrees: 180.0),     ],
//!     seams: [
//!         // nodes (column, row) from `from` to `to` on each piece, joined in order
//!         (name: "left side", a: (piece: "front", from: (6, 7), to: (6, 22)),
//!                             b: (piece: "back", from: (23, 7), to: (23, 22))),
//!     ],
//!     // optional: named runs of nodes a game attaches (`ClothAttachment::run`)
//!     runs: [
//!         (name: "collar", nodes: (piece: "back", from: (12, 0), to: (17, 0))),
//!     ],
//! )
//! ```
//! Pattern paths are relative to the garment file. A piece's node `(c, r)` starts at
//! `(c·s − (width−1)·s/2, −r·s, 0)` (centred, top row at y = 0), turned by `yaw_degrees`
//! about +y and moved by `translation`. A seam edge runs along a row, a column or a 45°
//! diagonal; both edges must hold the same number of present nodes.

use std::ops::Range;
use std::path::{Path, PathBuf};

use bevy::math::{Quat, Vec3};
use serde::{Deserialize, Serialize};

use crate::error::ClothError;

use crate::layout::pattern::{Pattern, PatternWarning};
use crate::solver::topology::{grid_spring_pairs, grid_triangles};
use crate::solver::{Layout, SpringKind};

mod asset;
pub use asset::{Garment, GarmentLoader};

pub use crate::limits::MAX_RESOLUTION;

/// A garment file as written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GarmentFile {
    /// Distance between neighbouring nodes at resolution 1, m.
    pub spacing: f32,
    /// The pattern pieces.
    pub pieces: Vec<PieceDesc>,
    /// The seams joining them.
    #[serde(default)]
    pub seams: Vec<SeamDesc>,
    /// Named runs of nodes, for a game to attach (a collar to a neck, a cape's top edge to
    /// the shoulders).
    #[serde(default)]
    pub runs: Vec<RunDesc>,
}

/// A named straight run of nodes on one piece.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunDesc {
    /// The name attachments refer to.
    pub name: String,
    /// The nodes, as a seam edge gives them.
    pub nodes: SeamEdge,
}

/// One pattern piece and where it starts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PieceDesc {
    /// The name seams refer to.
    pub name: String,
    /// The 0/1 pattern file, relative to the garment file.
    pub pattern: String,
    /// Where the middle of the piece's top row starts, m (garment frame).
    #[serde(default, with = "crate::params::vec3_serde")]
    pub translation: Vec3,
    /// Turn about +y, degrees (180 puts a back piece behind, facing away).
    #[serde(default)]
    pub yaw_degrees: f32,
}

/// A seam: the nodes of edge `a` are joined one by one to those of edge `b`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeamDesc {
    /// A name for messages.
    #[serde(default)]
    pub name: String,
    /// One side.
    pub a: SeamEdge,
    /// The other side, in the same order.
    pub b: SeamEdge,
}

/// A straight run of nodes on one piece, `from` and `to` included, as `(column, row)` at
/// resolution 1.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeamEdge {
    /// The piece's name.
    pub piece: String,
    /// First node `(column, row)`.
    pub from: (u32, u32),
    /// Last node `(column, row)`.
    pub to: (u32, u32),
}

/// A garment ready to build a cloth from: particles, springs, triangles, pieces and seams.
#[derive(Clone, Debug, Default)]
pub struct GarmentLayout {
    /// Particle start positions in the garment's frame.
    pub positions: Vec<Vec3>,
    /// Springs within pieces and along seams.
    pub springs: Vec<(SpringKind, u32, u32)>,
    /// Triangles, counter-clockwise seen from each piece's outside.
    pub triangles: Vec<[u32; 3]>,
    /// `(name, particle range)` of each piece.
    pub pieces: Vec<(String, Range<u32>)>,
    /// `(name, particle pairs)` of each seam.
    pub seams: Vec<(String, Vec<[u32; 2]>)>,
    /// `(name, particles)` of each named run.
    pub runs: Vec<(String, Vec<u32>)>,
    /// Legal but odd things in the patterns (disconnected islands).
    pub warnings: Vec<PatternWarning>,
}

impl GarmentLayout {
    /// The solver's layout: positions, springs (seams included), triangles and pieces.
    pub fn into_layout(self) -> Layout {
        Layout {
            positions: self.positions,
            springs: self.springs,
            triangles: self.triangles,
            grid: None,
            pieces: self.pieces,
            runs: self.runs,
        }
    }
}

/// The `assets` folder: where Bevy's asset server looks (`BEVY_ASSET_ROOT`, the crate
/// under cargo, else beside the executable), or else `assets` in the working directory (a
/// binary run by hand from the project).
/// On the web there is no file system: it is `assets`, as Bevy's web reader has it.
pub fn asset_root() -> PathBuf {
    let local = PathBuf::from("assets");
    #[cfg(not(target_arch = "wasm32"))]
    {
        let bevy_root = bevy::asset::io::file::FileAssetReader::get_base_path().join("assets");
        if bevy_root.exists() || !local.exists() {
            return bevy_root;
        }
    }
    local
}

/// The path of an asset file under [`asset_root`]; absolute paths stay as they are.
pub fn asset_path(file: &str) -> PathBuf {
    asset_root().join(file)
}

impl GarmentLayout {
    /// Reads a garment file and its patterns, rescaled to `resolution` (1 = as drawn; n
    /// divides the spacing by n and keeps the outline, see [`Pattern::rescale`]).
    pub fn load(path: &Path, resolution: u32) -> Result<GarmentLayout, ClothError> {
        let name = crate::limits::shown_path(path);
        let text = crate::limits::read_text(path).map_err(|e| ClothError::Garment {
            file: name.clone(),
            line: 1,
            column: 1,
            message: format!("cannot read the garment: {e}"),
        })?;
        let dir = path.parent().unwrap_or(Path::new("."));
        Self::parse(&text, &name, resolution, |pattern| {
            Pattern::load(&dir.join(pattern))
        })
    }

    /// Parses garment text; `read_pattern` loads a piece's pattern by its path as written.
    pub fn parse(
        text: &str,
        file: &str,
        resolution: u32,
        mut read_pattern: impl FnMut(
            &str,
        ) -> Result<
            (Pattern, Vec<PatternWarning>),
            crate::layout::pattern::PatternError,
        >,
    ) -> Result<GarmentLayout, ClothError> {
        let error = |needle: &str, message: String| {
            let (line, column) = locate(text, needle);
            ClothError::Garment {
                file: file.to_string(),
                line,
                column,
                message,
            }
        };
        let desc: GarmentFile = ron::from_str(text).map_err(|e| ClothError::Garment {
            file: file.to_string(),
            line: e.span.start.line,
            column: e.span.start.col,
            message: e.code.to_string(),
        })?;
        check_header(&desc, resolution, &error)?;
        let mut layout = GarmentLayout::default();
        let grids = lay_pieces(&desc, resolution, &mut layout, &mut read_pattern, &error)?;
        for seam in &desc.seams {
            let pairs = seam_pairs(seam, &desc.pieces, &grids, resolution, &error)?;
            layout
                .springs
                .extend(pairs.iter().map(|p| (SpringKind::Seam, p[0], p[1])));
            layout.seams.push((seam.name.clone(), pairs));
        }
        layout.runs = runs(&desc, &grids, resolution, &error)?;
        Ok(layout)
    }
}

/// Lays out every piece of `desc` in `layout` (its particles, springs and faces) in
/// order; per piece, its pattern at `resolution` and the particle index of each grid node.
fn lay_pieces(
    desc: &GarmentFile,
    resolution: u32,
    layout: &mut GarmentLayout,
    read_pattern: &mut impl FnMut(
        &str,
    ) -> Result<
        (Pattern, Vec<PatternWarning>),
        crate::layout::pattern::PatternError,
    >,
    error: &impl Fn(&str, String) -> ClothError,
) -> Result<Vec<(Pattern, Vec<u32>)>, ClothError> {
    let spacing = desc.spacing / resolution as f32;
    // Per piece: its pattern and the particle index of each grid node.
    let mut grids: Vec<(Pattern, Vec<u32>)> = Vec::new();
    for piece in &desc.pieces {
        if desc.pieces.iter().filter(|p| p.name == piece.name).count() > 1 {
            return Err(error(
                &format!("\"{}\"", piece.name),
                format!("two pieces are named `{}`", piece.name),
            ));
        }
        let (pattern, warnings) = read_pattern(&piece.pattern)?;
        layout.warnings.extend(warnings);
        check_nodes(&pattern, &piece.name, resolution, error)?;
        let pattern = pattern.rescale(resolution);
        let start = layout.positions.len() as u32;
        let index = add_piece(layout, &pattern, piece, spacing);
        if layout.positions.len() > crate::solver::MAX_PARTICLES {
            return Err(error(
                &format!("\"{}\"", piece.name),
                format!(
                    "{} particles up to piece `{}` is more than the limit of {} (limits::MAX_PARTICLES)",
                    layout.positions.len(),
                    piece.name,
                    crate::solver::MAX_PARTICLES
                ),
            ));
        }
        layout
            .pieces
            .push((piece.name.clone(), start..layout.positions.len() as u32));
        grids.push((pattern, index));
    }
    Ok(grids)
}

/// The refined grid of `pattern` at `resolution` within the limit, before it is
/// allocated.
fn check_nodes(
    pattern: &Pattern,
    piece: &str,
    resolution: u32,
    error: &dyn Fn(&str, String) -> ClothError,
) -> Result<(), ClothError> {
    let refined = |n: u32| (n as u64 - 1) * resolution as u64 + 1;
    let nodes = refined(pattern.width) * refined(pattern.height);
    if nodes > crate::limits::MAX_PATTERN_NODES as u64 {
        return Err(error(
            &format!("\"{piece}\""),
            format!(
                "piece `{piece}` at resolution {resolution} has {nodes} grid nodes, more than the limit of {} (limits.rs)",
                crate::limits::MAX_PATTERN_NODES
            ),
        ));
    }
    Ok(())
}

/// The garment's named runs: each its particles along its nodes (names unique).
fn runs(
    desc: &GarmentFile,
    grids: &[(Pattern, Vec<u32>)],
    resolution: u32,
    error: &dyn Fn(&str, String) -> ClothError,
) -> Result<Vec<(String, Vec<u32>)>, ClothError> {
    let mut runs = Vec::with_capacity(desc.runs.len());
    for run in &desc.runs {
        let needle = format!("\"{}\"", run.name);
        if desc.runs.iter().filter(|r| r.name == run.name).count() > 1 {
            return Err(error(&needle, format!("two runs are named `{}`", run.name)));
        }
        let label = format!("run `{}`", run.name);
        let particles = edge_particles(
            &run.nodes,
            (&label, &needle),
            &desc.pieces,
            grids,
            resolution,
            error,
        )?;
        runs.push((run.name.clone(), particles));
    }
    Ok(runs)
}

/// The garment file's own numbers: a positive spacing, a resolution in range, a piece.
fn check_header(
    desc: &GarmentFile,
    resolution: u32,
    error: &dyn Fn(&str, String) -> ClothError,
) -> Result<(), ClothError> {
    if !(desc.spacing > 0.0 && desc.spacing <= crate::limits::MAX_SPACING) {
        return Err(error(
            "spacing",
            format!(
                "`spacing` must be a distance from 0 (excluded) to 10 m (limits::MAX_SPACING), got {}",
                desc.spacing
            ),
        ));
    }
    if !(1..=MAX_RESOLUTION).contains(&resolution) {
        return Err(error(
            "spacing",
            format!("resolution {resolution} is outside 1–{MAX_RESOLUTION}"),
        ));
    }
    if desc.pieces.is_empty() {
        return Err(error("pieces", "a garment needs at least one piece".into()));
    }
    let limit = crate::limits::MAX_POSITION;
    for piece in &desc.pieces {
        let placed = piece.translation.is_finite()
            && piece.translation.length() <= limit
            && piece.yaw_degrees.is_finite()
            && piece.yaw_degrees.abs() <= limit;
        if !placed {
            return Err(error(
                &format!("\"{}\"", piece.name),
                format!(
                    "piece `{}`: translation and yaw_degrees must be finite and within {:e} (limits::MAX_POSITION)",
                    piece.name,
                    crate::limits::MAX_POSITION
                ),
            ));
        }
    }
    Ok(())
}

/// The particle pairs a seam joins: its two edges' nodes, in order, in their pieces'
/// particle indices (`grids`: each piece's pattern and node → particle map).
fn seam_pairs(
    seam: &SeamDesc,
    pieces: &[PieceDesc],
    grids: &[(Pattern, Vec<u32>)],
    resolution: u32,
    error: &dyn Fn(&str, String) -> ClothError,
) -> Result<Vec<[u32; 2]>, ClothError> {
    let label = if seam.name.is_empty() {
        "a seam".to_string()
    } else {
        format!("seam `{}`", seam.name)
    };
    let needle = if seam.name.is_empty() {
        "seams".to_string()
    } else {
        format!("\"{}\"", seam.name)
    };
    let mut sides = Vec::new();
    for edge in [&seam.a, &seam.b] {
        let where_ = (label.as_str(), needle.as_str());
        sides.push(edge_particles(
            edge, where_, pieces, grids, resolution, error,
        )?);
    }
    if sides[0].len() != sides[1].len() {
        return Err(error(
            &needle,
            format!(
                "{label}: edge a has {} nodes but edge b has {}",
                sides[0].len(),
                sides[1].len()
            ),
        ));
    }
    let pairs: Vec<[u32; 2]> = sides[0]
        .iter()
        .zip(&sides[1])
        .map(|(&a, &b)| [a, b])
        .collect();
    if let Some(p) = pairs.iter().find(|p| p[0] == p[1]) {
        return Err(error(
            &needle,
            format!("{label} joins particle {} to itself", p[0]),
        ));
    }
    Ok(pairs)
}

/// The particles of a seam edge or a run, in order; `(label, needle)`: what an error calls
/// it and the text it points at.
fn edge_particles(
    edge: &SeamEdge,
    (label, needle): (&str, &str),
    pieces: &[PieceDesc],
    grids: &[(Pattern, Vec<u32>)],
    resolution: u32,
    error: &dyn Fn(&str, String) -> ClothError,
) -> Result<Vec<u32>, ClothError> {
    let Some(p) = pieces.iter().position(|p| p.name == edge.piece) else {
        return Err(error(
            needle,
            format!("{label}: no piece is named `{}`", edge.piece),
        ));
    };
    let (pattern, index) = &grids[p];
    let nodes = edge_nodes(edge, resolution, pattern)
        .map_err(|m| error(needle, format!("{label}: {m}")))?;
    let mut particles = Vec::with_capacity(nodes.len());
    for (c, r) in nodes {
        if !pattern.has(c as i64, r as i64) {
            return Err(error(
                needle,
                format!(
                    "{label}: node ({}, {}) of `{}` is not in the pattern",
                    c as f32 / resolution as f32,
                    r as f32 / resolution as f32,
                    edge.piece
                ),
            ));
        }
        particles.push(index[(r * pattern.width + c) as usize]);
    }
    Ok(particles)
}

/// Adds one piece's particles, springs and triangles; returns the particle index of each
/// grid node (`u32::MAX` where the pattern has a 0).
fn add_piece(
    layout: &mut GarmentLayout,
    pattern: &Pattern,
    piece: &PieceDesc,
    spacing: f32,
) -> Vec<u32> {
    let (w, h) = (pattern.width, pattern.height);
    let turn = Quat::from_rotation_y(piece.yaw_degrees.to_radians());
    let half = (w - 1) as f32 * spacing * 0.5;
    let mut index = vec![u32::MAX; pattern.nodes.len()];
    for r in 0..h {
        for c in 0..w {
            let g = (r * w + c) as usize;
            if pattern.nodes[g] {
                index[g] = layout.positions.len() as u32;
                let local = Vec3::new(c as f32 * spacing - half, -(r as f32) * spacing, 0.0);
                layout.positions.push(turn * local + piece.translation);
            }
        }
    }
    // The grid's springs between present nodes (Sladović 2014 §3.2); a bend spring also needs
    // the node it bends over, so none bridges a notch.
    let present = |g: u32| index[g as usize] != u32::MAX;
    for (kind, a, b) in grid_spring_pairs(w, h) {
        let bends = matches!(kind, SpringKind::Bend | SpringKind::BendDiagonal);
        let middle = || {
            let (ca, ra, cb, rb) = (a % w, a / w, b % w, b / w);
            ((ra + rb) / 2) * w + (ca + cb) / 2
        };
        if present(a) && present(b) && (!bends || present(middle())) {
            layout
                .springs
                .push((kind, index[a as usize], index[b as usize]));
        }
    }
    add_piece_triangles(layout, w, h, &index);
    index
}

/// A piece's triangles, by the particle index of each grid node of its `w × h` grid
/// (`u32::MAX` where the pattern has a 0).
fn add_piece_triangles(layout: &mut GarmentLayout, w: u32, h: u32, index: &[u32]) {
    let present = |g: u32| index[g as usize] != u32::MAX;
    // Full cells keep the grid's two triangles; a cell with three nodes (a diagonal edge
    // of the outline) gets the one triangle they make, wound the same way.
    let full = grid_triangles(w, h);
    for r in 0..h - 1 {
        for c in 0..w - 1 {
            let corners = [
                r * w + c,
                r * w + c + 1,
                (r + 1) * w + c,
                (r + 1) * w + c + 1,
            ];
            let [tl, tr, bl, br] = corners.map(present);
            let cell = (r * (w - 1) + c) as usize * 2;
            let map = |t: [u32; 3]| t.map(|g| index[g as usize]);
            let [a, b, c2, d] = corners;
            match (tl, tr, bl, br) {
                (true, true, true, true) => {
                    layout.triangles.push(map(full[cell]));
                    layout.triangles.push(map(full[cell + 1]));
                }
                (false, true, true, true) => layout.triangles.push(map([b, c2, d])),
                (true, false, true, true) => layout.triangles.push(map([a, c2, d])),
                (true, true, false, true) => layout.triangles.push(map([a, d, b])),
                (true, true, true, false) => layout.triangles.push(map([a, c2, b])),
                _ => {}
            }
        }
    }
}

/// The grid nodes of a seam edge at `resolution`, from `from` to `to` inclusive: a row, a
/// column or a 45° diagonal, both ends inside the (refined) `pattern`'s grid — checked
/// before the run is listed, so a run cannot be longer than the piece.
fn edge_nodes(
    edge: &SeamEdge,
    resolution: u32,
    pattern: &Pattern,
) -> Result<Vec<(u32, u32)>, String> {
    let f = resolution as i64;
    let (c0, r0) = (edge.from.0 as i64 * f, edge.from.1 as i64 * f);
    let (c1, r1) = (edge.to.0 as i64 * f, edge.to.1 as i64 * f);
    let (dc, dr) = (c1 - c0, r1 - r0);
    if dc != 0 && dr != 0 && dc.abs() != dr.abs() {
        return Err(format!(
            "edge {:?}→{:?} on `{}` is not along a row, a column or a 45° diagonal",
            edge.from, edge.to, edge.piece
        ));
    }
    let inside = |c: i64, r: i64| c < pattern.width as i64 && r < pattern.height as i64;
    for (end, (c, r), at) in [("from", (c0, r0), edge.from), ("to", (c1, r1), edge.to)] {
        if !inside(c, r) {
            return Err(format!(
                "`{end}` {at:?} is outside piece `{}` ({}×{} nodes at resolution 1)",
                edge.piece,
                (pattern.width as i64 - 1) / f + 1,
                (pattern.height as i64 - 1) / f + 1
            ));
        }
    }
    let n = dc.abs().max(dr.abs());
    Ok((0..=n)
        .map(|k| ((c0 + dc.signum() * k) as u32, (r0 + dr.signum() * k) as u32))
        .collect())
}

/// 1-based line and column of the first occurrence of `needle` in `text` (1:1 if absent).
fn locate(text: &str, needle: &str) -> (usize, usize) {
    text.find(needle).map_or((1, 1), |at| {
        let before = &text[..at];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        (line, column)
    })
}
