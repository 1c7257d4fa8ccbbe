//! `cloth soak`: a scene's cloth driven for minutes, checked every step.

use std::path::PathBuf;

use clap::Args;

use crate::args::*;
use bevy_cloth::prelude::*;

#[derive(Args)]
pub(crate) struct SoakArgs {
    /// The scene file (RON).
    pub(crate) scene: PathBuf,
    /// Wall-clock minutes (at most 1,440).
    #[arg(long, default_value_t = 1.0, value_parser = minutes)]
    pub(crate) minutes: f32,
    /// Which of the scene's cloths (its index).
    #[arg(long, default_value_t = 0)]
    pub(crate) cloth: usize,
    /// Stops after this many steps if they come before the minutes are up (the same
    /// seed and steps, the same soak, on any machine).
    #[arg(long, value_parser = steps)]
    pub(crate) steps: Option<usize>,
    /// The random generator's seed (the same seed, the same soak).
    #[arg(long, default_value_t = 1)]
    pub(crate) seed: u64,
    /// Prints JSON instead of a table.
    #[arg(long)]
    pub(crate) json: bool,
}

/// `cloth soak`: the soak, a status line a minute on stderr, the summary on stdout; exit
/// code 1 when it found a bug (non-finite state, an invalid edit accepted, memory growth).
pub(crate) fn soak(args: SoakArgs) -> Result<(), String> {
    let scene = ClothScene::load(&args.scene).map_err(|e| e.to_string())?;
    let duration = std::time::Duration::from_secs_f32(args.minutes * 60.0);
    let mut next = 60.0;
    let length = (duration, args.steps.map(|n| n as u64));
    let summary = bevy_cloth_lab::soak::soak(&scene, args.cloth, length, args.seed, |s| {
        if s.seconds >= next {
            next += 60.0;
            eprintln!(
                "{:.0} s: {} steps, {} non-finite, {:.1} MB resident",
                s.seconds,
                s.steps,
                s.non_finite_steps,
                bevy_cloth_lab::soak::resident_mb()
            );
        }
    })?;
    if args.json {
        print_json(&summary)?;
    } else {
        let s = &summary;
        println!("| soak of {} | |", args.scene.display());
        println!("|---|---:|");
        for (what, value) in [
            ("wall-clock s", format!("{:.0}", s.seconds)),
            ("steps", s.steps.to_string()),
            ("simulated s", format!("{:.0}", s.simulated_seconds)),
            ("grabs", s.grabs.to_string()),
            (
                "cut strokes / springs cut",
                format!("{} / {}", s.cuts, s.springs_cut),
            ),
            ("springs torn by stretching", s.springs_torn.to_string()),
            (
                "valid edits / model switches",
                format!("{} / {}", s.edits, s.model_switches),
            ),
            (
                "invalid edits refused / accepted",
                format!("{} / {}", s.refused_edits, s.accepted_invalid_edits),
            ),
            ("resets", s.resets.to_string()),
            (
                "steps with non-finite state",
                s.non_finite_steps.to_string(),
            ),
            (
                "steps past 100% strain (reset)",
                s.unstable_steps.to_string(),
            ),
            (
                "resident MB settled / peak / end",
                format!(
                    "{:.1} / {:.1} / {:.1}",
                    s.rss_start_mb, s.rss_peak_mb, s.rss_end_mb
                ),
            ),
            (
                "step ms median / max",
                format!("{:.3} / {:.1}", s.median_step_ms, s.max_step_ms),
            ),
            ("passed", s.passed().to_string()),
        ] {
            println!("| {what} | {value} |");
        }
    }
    if summary.passed() {
        Ok(())
    } else {
        eprintln!("error: the soak found a problem (see the summary)");
        std::process::exit(1);
    }
}
