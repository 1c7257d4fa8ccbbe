//! Garment pieces as 0/1 pattern files (Maslova §1.4): "the shape of a piece is given by a
//! matrix in which 1 means a mass is present and 0 that it is absent".
//!
//! ```text
//! # a 4×3 piece with a notch; blank lines and `#` comments are allowed,
//! # digits may be separated by spaces
//! 1111
//! 1001
//! 1 1 1 1
//! ```
//! Row `r`, column `c` of the file is grid node `(c, r)`. [`Pattern::parse`] checks the
//! text and names the file, line and column of any problem; [`Pattern::rescale`] keeps
//! the outline on a finer grid.

use std::path::Path;

use thiserror::Error;

pub use crate::limits::MAX_PATTERN_NODES;

/// A garment piece: which nodes of a `width × height` grid carry a mass.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pattern {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `nodes[r·width + c]` is true where the pattern has a `1`.
    pub nodes: Vec<bool>,
}

/// What is wrong with a pattern file, and where.
#[derive(Clone, Debug, Error, PartialEq)]
#[error("{file}:{line}:{column}: {kind}")]
pub struct PatternError {
    /// The file (as given).
    pub file: String,
    /// 1-based line.
    pub line: usize,
    /// 1-based column (in characters).
    pub column: usize,
    /// What is wrong.
    pub kind: PatternErrorKind,
}

/// The kinds of pattern errors.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum PatternErrorKind {
    /// The file could not be read.
    #[error("cannot read the pattern: {0}")]
    Io(String),
    /// Bytes that are not UTF-8 text.
    #[error("the pattern is not UTF-8 text")]
    NotUtf8,
    /// A character other than `0`, `1`, space or `#` (which starts a comment).
    #[error(
        "unexpected character {0:?}: a pattern row holds only 0 and 1 (spaces and `#` comments allowed)"
    )]
    BadCharacter(char),
    /// A row with a different number of nodes than the first.
    #[error("this row has {found} nodes but the first row has {expected}")]
    Ragged {
        /// Nodes in the first row.
        expected: usize,
        /// Nodes in this row.
        found: usize,
    },
    /// No row at all, or no `1`.
    #[error("the pattern is empty: it needs at least one row with a 1")]
    Empty,
    /// More grid nodes than [`MAX_PATTERN_NODES`].
    #[error("the pattern has at least {nodes} grid nodes, more than the limit of {limit}")]
    TooLarge {
        /// Nodes counted so far.
        nodes: usize,
        /// The limit.
        limit: usize,
    },
}

/// Something legal but probably unintended in a pattern.
#[derive(Clone, Debug, PartialEq)]
pub struct PatternWarning {
    /// The file (as given).
    pub file: String,
    /// 1-based line of a node of the piece warned about.
    pub line: usize,
    /// 1-based column of that node.
    pub column: usize,
    /// What is odd.
    pub message: String,
}

impl std::fmt::Display for PatternWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}:{}:{}: {}",
            self.file, self.line, self.column, self.message
        )
    }
}

/// Reads one line's nodes onto `nodes` (and their places, on line `line_number`), checked
/// against the first row's `width` (0 before it): how many it had, or the column and kind
/// of the first error.
fn read_row(
    line: &str,
    width: usize,
    nodes: &mut Vec<bool>,
    places: &mut Vec<(u32, u32)>,
    line_number: u32,
) -> Result<usize, (usize, PatternErrorKind)> {
    let mut row = 0usize;
    for (c, ch) in line.chars().enumerate() {
        match ch {
            '0' | '1' => {
                nodes.push(ch == '1');
                places.push((line_number, c as u32 + 1));
                row += 1;
                if nodes.len() > MAX_PATTERN_NODES {
                    let kind = PatternErrorKind::TooLarge {
                        nodes: nodes.len(),
                        limit: MAX_PATTERN_NODES,
                    };
                    return Err((c + 1, kind));
                }
                if width > 0 && row > width {
                    let kind = PatternErrorKind::Ragged {
                        expected: width,
                        found: line.chars().filter(|c| matches!(c, '0' | '1')).count(),
                    };
                    return Err((c + 1, kind));
                }
            }
            ' ' | '\t' | '\r' => {}
            '#' => break,
            other => {
                return Err((c + 1, PatternErrorKind::BadCharacter(other)));
            }
        }
    }
    Ok(row)
}

impl Pattern {
    /// Reads and parses a pattern file.
    pub fn load(path: &Path) -> Result<(Pattern, Vec<PatternWarning>), PatternError> {
        let file = crate::limits::shown_path(path);
        let bytes = crate::limits::read_file(path).map_err(|e| PatternError {
            file: file.clone(),
            line: 1,
            column: 1,
            kind: PatternErrorKind::Io(e.to_string()),
        })?;
        Self::parse(&bytes, &file)
    }

    /// Parses pattern text; `file` names it in errors and warnings. Warns once per
    /// disconnected island after the first (nodes joined by no chain of springs).
    pub fn parse(bytes: &[u8], file: &str) -> Result<(Pattern, Vec<PatternWarning>), PatternError> {
        let error = |line: usize, column: usize, kind| PatternError {
            file: file.to_string(),
            line,
            column,
            kind,
        };
        let text = utf8(bytes, file)?;
        let mut width = 0usize;
        let mut nodes = Vec::new();
        // (line, column) of every node, for warnings.
        let mut places: Vec<(u32, u32)> = Vec::new();
        let mut first_row_line = 0;
        for (l, line) in text.lines().enumerate() {
            let row = read_row(line, width, &mut nodes, &mut places, l as u32 + 1)
                .map_err(|(column, kind)| error(l + 1, column, kind))?;
            if row == 0 {
                continue;
            }
            if width == 0 {
                width = row;
                first_row_line = l + 1;
            } else if row != width {
                let kind = PatternErrorKind::Ragged {
                    expected: width,
                    found: row,
                };
                return Err(error(l + 1, line.chars().count() + 1, kind));
            }
        }
        if !nodes.contains(&true) {
            return Err(error(first_row_line.max(1), 1, PatternErrorKind::Empty));
        }
        let pattern = Pattern {
            width: width as u32,
            height: (nodes.len() / width) as u32,
            nodes,
        };
        let warnings = island_warnings(&pattern, &places, file);
        Ok((pattern, warnings))
    }

    /// Whether node `(c, r)` is inside the grid and present.
    pub fn has(&self, c: i64, r: i64) -> bool {
        c >= 0
            && r >= 0
            && c < self.width as i64
            && r < self.height as i64
            && self.nodes[(r * self.width as i64 + c) as usize]
    }

    /// Number of present nodes.
    pub fn count(&self) -> usize {
        self.nodes.iter().filter(|&&n| n).count()
    }

    /// The connected groups of present nodes (joined through structural or shear springs,
    /// that is through any of the 8 neighbours), largest first; each lists grid indices
    /// in scan order.
    pub fn islands(&self) -> Vec<Vec<u32>> {
        let (w, h) = (self.width as i64, self.height as i64);
        let mut island = vec![u32::MAX; self.nodes.len()];
        let mut islands: Vec<Vec<u32>> = Vec::new();
        let mut stack = Vec::new();
        for start in 0..self.nodes.len() {
            if !self.nodes[start] || island[start] != u32::MAX {
                continue;
            }
            let id = islands.len() as u32;
            let mut members = Vec::new();
            island[start] = id;
            stack.push(start);
            while let Some(n) = stack.pop() {
                members.push(n as u32);
                let (c, r) = (n as i64 % w, n as i64 / w);
                for (dc, dr) in [
                    (-1, -1),
                    (0, -1),
                    (1, -1),
                    (-1, 0),
                    (1, 0),
                    (-1, 1),
                    (0, 1),
                    (1, 1),
                ] {
                    let (nc, nr) = (c + dc, r + dr);
                    if nc >= 0 && nr >= 0 && nc < w && nr < h {
                        let m = (nr * w + nc) as usize;
                        if self.nodes[m] && island[m] == u32::MAX {
                            island[m] = id;
                            stack.push(m);
                        }
                    }
                }
            }
            members.sort_unstable();
            islands.push(members);
        }
        islands.sort_by_key(|m| std::cmp::Reverse(m.len()));
        islands
    }

    /// The same outline on a grid `factor` times finer: node `(c, r)` of the result sits at
    /// `(c/factor, r/factor)` of this grid and is present when it lies on the piece: on a
    /// present node, on an edge between two present nodes, inside a cell whose four nodes
    /// are present, or inside the triangle of a cell with three (a diagonal outline). The
    /// piece keeps its size when the spacing is divided by `factor`.
    pub fn rescale(&self, factor: u32) -> Pattern {
        let f = factor.max(1) as i64;
        if f == 1 {
            return self.clone();
        }
        let (w, h) = (
            (self.width as i64 - 1) * f + 1,
            (self.height as i64 - 1) * f + 1,
        );
        let mut nodes = Vec::with_capacity((w * h) as usize);
        for r in 0..h {
            for c in 0..w {
                let (c0, r0, u, v) = (c / f, r / f, c % f, r % f);
                let present = match (u, v) {
                    (0, 0) => self.has(c0, r0),
                    (0, _) => self.has(c0, r0) && self.has(c0, r0 + 1),
                    (_, 0) => self.has(c0, r0) && self.has(c0 + 1, r0),
                    _ => {
                        let corners = [
                            self.has(c0, r0),
                            self.has(c0 + 1, r0),
                            self.has(c0, r0 + 1),
                            self.has(c0 + 1, r0 + 1),
                        ];
                        // (u, v) in units of 1/f inside the cell; the triangle of three
                        // corners is the half-cell on their side of the diagonal.
                        match corners {
                            [true, true, true, true] => true,
                            [false, true, true, true] => u + v >= f,
                            [true, true, true, false] => u + v <= f,
                            [true, false, true, true] => v >= u,
                            [true, true, false, true] => v <= u,
                            _ => false,
                        }
                    }
                };
                nodes.push(present);
            }
        }
        Pattern {
            width: w as u32,
            height: h as u32,
            nodes,
        }
    }
}

/// The file's text, or where its first byte that is not UTF-8 is.
fn utf8<'a>(bytes: &'a [u8], file: &str) -> Result<&'a str, PatternError> {
    std::str::from_utf8(bytes).map_err(|e| {
        let before = &bytes[..e.valid_up_to()];
        let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
        let line_start = before
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |p| p + 1);
        let column = String::from_utf8_lossy(&before[line_start..])
            .chars()
            .count()
            + 1;
        PatternError {
            file: file.to_string(),
            line,
            column,
            kind: PatternErrorKind::NotUtf8,
        }
    })
}

/// A warning for every island of nodes but the largest, at its first node's place
/// (`places`: the line and column of each node).
fn island_warnings(pattern: &Pattern, places: &[(u32, u32)], file: &str) -> Vec<PatternWarning> {
    pattern
        .islands()
        .iter()
        .skip(1)
        .map(|island| {
            let (line, column) = places[island[0] as usize];
            PatternWarning {
                file: file.to_string(),
                line: line as usize,
                column: column as usize,
                message: format!(
                    "{} node(s) here are not joined to the rest of the piece: they will fall on their own",
                    island.len()
                ),
            }
        })
        .collect()
}
