//! Golden dumps: what a run ends at, stored as text and compared byte for byte, so the
//! physics does not change under a refactoring. Positions are printed as the shortest
//! text that reads back to the same `f32` (Rust's `Display`), so equal text is equal bits.
//!
//! After a change that is *meant* to change the physics, `BLESS=1` rewrites the stored
//! files, printing how far each file's positions moved (how many, the largest and the
//! median); a bless that moves any position farther than [`BLESS_BOUND_M`] is refused,
//! so a change that moves the cloth a long way has to raise the bound, with its reason,
//! in the same commit. The main crate's tests and the command line's
//! (`lab/tests/cli.rs`) share this file.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use bevy::math::Vec3;

/// The farthest a bless may move any stored position, m. 5 mm: a change of summation
/// order moves a settled cloth by float rounding (µm), a curtain in gusts by a few mm by
/// step 120, and the flag flapping on its pole, the most chaotic case, by tens of cm (36
/// cm); a move past the bound is a change of behaviour, or of rounding in the flag,
/// which the commit that makes it must own by raising this with its reason.
pub const BLESS_BOUND_M: f32 = 0.005;

/// The main crate's stored dumps.
pub fn main_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/golden")
}

/// `positions` as a dump: a header, then `particle,x,y,z` a line.
pub fn positions_csv(positions: &[Vec3]) -> String {
    let mut out = String::from("particle,x,y,z\n");
    for (i, p) in positions.iter().enumerate() {
        out.push_str(&format!("{i},{},{},{}\n", p.x, p.y, p.z));
    }
    out
}

/// How far the positions (each line's last three fields) moved from `old` to `new`,
/// lines matched in order (the header and lines without three numbers skipped), or
/// `None` when the two do not have the same lines.
pub fn moves(old: &str, new: &str) -> Option<Moves> {
    let position = |line: &str| -> Option<Vec3> {
        let f: Vec<f32> = line
            .rsplitn(4, ',')
            .take(3)
            .map(|s| s.trim().parse().ok())
            .collect::<Option<_>>()?;
        (f.len() == 3).then(|| Vec3::new(f[2], f[1], f[0]))
    };
    let (a, b): (Vec<&str>, Vec<&str>) = (old.lines().collect(), new.lines().collect());
    if a.len() != b.len() {
        return None;
    }
    let (mut moved, mut positions) = (Vec::new(), 0);
    for (x, y) in a.iter().zip(&b) {
        match (position(x), position(y)) {
            (Some(p), Some(q)) => {
                positions += 1;
                if p != q {
                    moved.push(p.distance(q));
                }
            }
            (None, None) => {}
            _ => return None,
        }
    }
    moved.sort_by(f32::total_cmp);
    Some(Moves {
        largest: moved.last().copied().unwrap_or(0.0),
        median: moved.get(moved.len() / 2).copied().unwrap_or(0.0),
        moved: moved.len(),
        positions,
    })
}

/// What a change did to a dump's positions ([`moves`]).
pub struct Moves {
    /// The largest move, m.
    pub largest: f32,
    /// The median move of those that moved, m.
    pub median: f32,
    /// How many moved, of `positions`.
    pub moved: usize,
    pub positions: usize,
}

impl std::fmt::Display for Moves {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} of {} positions moved, the largest {:e} m, the median of those {:e} m",
            self.moved, self.positions, self.largest, self.median
        )
    }
}

/// Checks `got` against the stored `dir/name.csv`: `Err` says where it differs. Under
/// `BLESS=1` writes it instead, printing the moves, and refuses (`Err`) a bless past
/// [`BLESS_BOUND_M`] or one that changes the lines (a new file is written as it is).
pub fn check(dir: &Path, name: &str, got: &str) -> Result<(), String> {
    let stored = dir.join(format!("{name}.csv"));
    let want = std::fs::read_to_string(&stored);
    if std::env::var_os("BLESS").is_some() {
        if let Ok(want) = &want {
            let Some(moves) = moves(want, got) else {
                return Err(format!("{name}: the bless changes the dump's lines"));
            };
            eprintln!("bless {name}: {moves}");
            if moves.largest > BLESS_BOUND_M {
                return Err(format!(
                    "{name}: the bless moves a position {} m, past the bound of \
                     {BLESS_BOUND_M} m (golden.rs: raise it, with the reason, to bless this)",
                    moves.largest
                ));
            }
        }
        std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
        return std::fs::write(&stored, got).map_err(|e| e.to_string());
    }
    let want = want.map_err(|e| format!("{}: {e} (BLESS=1 writes it)", stored.display()))?;
    if got == want {
        return Ok(());
    }
    let line = got
        .lines()
        .zip(want.lines())
        .position(|(a, b)| a != b)
        .map_or("the line count".to_string(), |i| format!("line {}", i + 1));
    let moved = moves(&want, got).map_or(String::new(), |m| format!(" ({m})"));
    Err(format!("{name}: differs at {line}{moved}"))
}

/// [`check`] of `positions` in the main crate's stored dumps, failing the test on a
/// difference.
pub fn assert_golden(name: &str, positions: &[Vec3]) {
    if let Err(e) = check(&main_dir(), name, &positions_csv(positions)) {
        panic!("golden dump {e}");
    }
}
