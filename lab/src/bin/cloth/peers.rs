//! `cloth peers`: speed at equal accuracy beside other solvers, in one run.

use clap::Args;

use crate::args::*;
use crate::charts;
use bevy_cloth::solver;
use bevy_cloth_lab::peers::{self, Hang, PEER_SOLVERS, Peer, PeerRow};

#[derive(Args)]
pub(crate) struct PeersArgs {
    /// Particles across (and down) the square cloth, comma separated (2 to 512).
    #[arg(long, value_delimiter = ',', default_values_t = [16, 64, 256], value_parser = side)]
    pub(crate) sides: Vec<usize>,
    /// What holds it: its whole top row (`top-row`), its two top corners (`corners`), or
    /// its top row with the cloth starting level and swinging down (`swing`).
    #[arg(long, default_value = "top-row", value_parser = hang)]
    pub(crate) hang: Hang,
    /// Frames of 1/60 s per run (the first 5 are not timed).
    #[arg(long, default_value_t = 60, value_parser = steps)]
    pub(crate) frames: usize,
    /// The solvers, comma separated: ours (XPBD swept), tethers (swept + tethers), lines (lines + tethers, the default), self (lines + tethers + self-collision), rapier, sticks (all when absent).
    #[arg(long, value_delimiter = ',', value_parser = peer_solver)]
    pub(crate) solvers: Vec<&'static str>,
    /// Keeps our kernels on one thread (the peers always run on one).
    #[arg(long = "one-thread")]
    pub(crate) one_thread: bool,
    #[command(flatten)]
    pub(crate) output: Output,
}

/// `cloth peers`: every configuration of every solver on every side, in one run; the
/// table, then each solver's cheapest configuration within 1% and within 0.1% strain and
/// its cost against rapier-cloth-core's in the same run.
pub(crate) fn peers(args: PeersArgs) -> Result<(), String> {
    let solvers = or_all(args.solvers, &PEER_SOLVERS);
    if args.one_thread {
        solver::set_parallel(false);
    }
    let configs: Vec<Peer> = peers::default_peers()
        .into_iter()
        .filter(|p| solvers.contains(&p.key()))
        .collect();
    let rows = measure_all(&configs, &args.sides, args.hang, args.frames)?;
    if let Some(chart) = &args.output.chart {
        charts::peers(chart, &rows)?;
    }
    let best = peers::cheapest_within(&rows, &[0.01, 0.001]);
    if args.output.json {
        return print_json(&serde_json::json!({
            "threads": solver::threads(),
            "frames": args.frames,
            "warmup_frames": peers::WARMUP_FRAMES,
            "rows": rows,
            "cheapest": best,
        }));
    }
    println!(
        "{} frames of 1/60 s per run, the first {} not timed; ours on {} thread(s), the others on one.",
        args.frames,
        peers::WARMUP_FRAMES,
        solver::threads()
    );
    print_rows(&rows);
    print_best(&best);
    Ok(())
}

/// Every configuration on every side, a line on stderr per run.
fn measure_all(
    configs: &[Peer],
    sides: &[usize],
    hang: Hang,
    frames: usize,
) -> Result<Vec<PeerRow>, String> {
    let bar = progress(configs.len() * sides.len(), "runs");
    let mut rows: Vec<PeerRow> = Vec::new();
    for &side in sides {
        for &peer in configs {
            let row = peers::measure(side, hang, peer, frames)?;
            bar.suspend(|| {
                eprintln!(
                    "  {:>6} {:<26} {:<26} {}",
                    side * side,
                    row.solver,
                    row.label,
                    match (&row.failed, row.ms, row.strain) {
                        (Some(why), _, _) => format!("failed: {why}"),
                        (None, Some(ms), Some(strain)) =>
                            format!("{ms:.3} ms  strain {:.3}%", strain * 100.0),
                        _ => String::new(),
                    }
                )
            });
            bar.inc(1);
            rows.push(row);
        }
    }
    bar.finish_and_clear();
    Ok(rows)
}

/// Every run's cost, strain and sag.
fn print_rows(rows: &[PeerRow]) {
    println!();
    println!(
        "| particles | solver | configuration | ms per frame, median [p10–p90] | ns per projection | strain | sag |"
    );
    println!("|---:|---|---|---:|---:|---:|---:|");
    for r in rows {
        let (time, ns, strain, sag) = match (r.ms, r.ms_spread, r.strain, r.sag) {
            (Some(ms), Some((lo, hi)), Some(strain), Some(sag)) => (
                format!("{ms:.3} [{lo:.3}–{hi:.3}]"),
                r.ns_per_projection
                    .map_or("-".into(), |ns| format!("{ns:.2}")),
                format!("{:.3}%", strain * 100.0),
                format!("{:.3}%", sag * 100.0),
            ),
            _ => (
                "-".into(),
                "-".into(),
                format!("failed: {}", r.failed.as_deref().unwrap_or("")),
                "-".into(),
            ),
        };
        println!(
            "| {} | {} | {} | {time} | {ns} | {strain} | {sag} |",
            r.side * r.side,
            r.solver,
            r.label
        );
    }
}

/// Each solver's cheapest configuration within each strain, against rapier-cloth-core's.
fn print_best(best: &[peers::Cheapest]) {
    println!();
    println!(
        "The cheapest configuration of each solver within a strain, and rapier-cloth-core's cost over its:"
    );
    println!();
    println!(
        "| particles | strain within | solver | configuration | ms per frame | strain | rapier / it |"
    );
    println!("|---:|---:|---|---|---:|---:|---:|");
    for b in best {
        println!(
            "| {} | {}% | {} | {} | {:.3} | {:.3}% | {} |",
            b.side * b.side,
            b.within * 100.0,
            b.solver,
            b.label,
            b.ms,
            b.strain * 100.0,
            b.rapier_over.map_or("-".into(), |r| format!("{r:.2}x"))
        );
    }
}
