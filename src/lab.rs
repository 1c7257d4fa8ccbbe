//! Helpers the lab crate and the tests share with the library: not part of the API
//! (hidden from the docs; they may change in any release). They are here, rather than
//! copied into the lab, because the library uses each of them too, or because a test of
//! the library needs the very same one.

pub use crate::solver::{task_pool, unit_hash};
pub use crate::stats::median;

/// A multi-line message (a command-line parser's, with its usage block) folded onto one
/// line, without its leading `error: `: every bad input is reported in one line.
pub fn one_line(message: &str) -> String {
    let lines: Vec<&str> = message
        .lines()
        .map(str::trim)
        .take_while(|l| !l.is_empty() && !l.starts_with("Usage:"))
        .collect();
    lines.join(" ").trim_start_matches("error: ").to_string()
}
