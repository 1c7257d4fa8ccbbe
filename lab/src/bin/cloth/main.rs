//! `cloth`: the headless command line (`cloth --help`, `cloth <verb> --help`).
//!
//! `run` prints a JSON summary on stdout and dumps positions on request; `bench` prints
//! Sladović's (2014) timing table (fig. 23) beside ours and, with `--app`, Maslova's frame
//! rates beside the full app's; `accuracy` and `stability` print their tables. `--chart`
//! draws the chart to a PNG and an SVG beside it. Bad input exits with code 2 and a
//! one-line message naming the file, line and field; nothing panics on user input.

/// `println!` that exits quietly when stdout is closed (`cloth run … | head -3`) instead
/// of panicking as std's does; defined before the modules so that they use it too.
macro_rules! println {
    () => {
        crate::out(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        crate::out(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// Writes to stdout; a closed pipe ends the program quietly (exit 0: the reader had what
/// it wanted), any other failure with exit code 2.
fn out(args: std::fmt::Arguments) {
    if let Err(e) = std::io::stdout().write_fmt(args) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("error: stdout: {e}");
        std::process::exit(2);
    }
}

/// `print!` through [`out`], as `println!` above.
macro_rules! print {
    ($($arg:tt)*) => {
        crate::out(format_args!($($arg)*))
    };
}

mod charts;

mod accuracy;
mod args;
mod bench;
mod cantilever;
mod choose;
mod crowd;
mod drape;
mod peers;
mod run;
mod soak;
mod stability;
mod storm;

use std::io::Write;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Headless runs and measurements of bevy_cloth.
#[derive(Parser)]
#[command(
    name = "cloth",
    about = "Headless runs and measurements of bevy_cloth (bad input: exit code 2, one line)"
)]
struct Cli {
    #[command(subcommand)]
    verb: Verb,
}

#[derive(Subcommand)]
enum Verb {
    /// Runs a scene headless: a JSON summary on stdout, positions dumped on request.
    Run(run::RunArgs),
    /// Sladović's (2014) timing table (fig. 23) beside ours; with --app, Maslova's frame rates.
    Bench(bench::BenchArgs),
    /// Speed against accuracy, against a converged reference.
    Accuracy(accuracy::AccuracyArgs),
    /// Where each method fails: the linear and the nonlinear stability maps.
    Stability(stability::StabilityArgs),
    /// The cheapest configuration of your scene's cloth within an error, or the most
    /// accurate within a cost per step (the accuracy study on that scene).
    Choose(choose::ChooseArgs),
    /// Drives a scene's cloth for minutes with gusty wind, grabs, cuts, tearing,
    /// parameter edits (and refused invalid ones), model switches and resets, checking
    /// every step for non-finite state and the memory for growth.
    Soak(soak::SoakArgs),
    /// Speed at equal accuracy beside other solvers, in one run: a cloth hung from its top
    /// row (or corners) with our XPBD without and with tethers, rapier-cloth-core and a
    /// Verlet + sticks baseline, each over a sweep of its cost setting.
    Peers(peers::PeersArgs),
    /// The cantilever test (ASTM D1388): a fabric strip 2.5 cm wide pushed over a ledge
    /// until its tip falls 41.5°; its bending length against `(B / (ρ_A g))^(1/3)`.
    Cantilever(cantilever::CantileverArgs),
    /// The crowd example's headless twin: characters walking loops in capes and skirts
    /// drawn through proxies, teleports, a wind zone; each part of a frame timed on one
    /// thread and on the pool.
    Crowd(crowd::CrowdArgs),
    /// The drape test (Cusick): a 30 cm circle of fabric clamped between 18 cm discs,
    /// its drape coefficient from its shadow, with a picture of the shadows side by side.
    Drape(drape::DrapeArgs),
    /// Where each method fails in the weather: the flag in air from calm to a gale,
    /// self-collision off and on, mass-spring, XPBD and XPBD inside the plugin's frame
    /// budget; each cell's cost, substeps, strain and whether it held together.
    Storm(storm::StormArgs),
}
fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help and --version
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            // One line naming the problem, as for every other bad input.
            let line = bevy_cloth::lab::one_line(&e.render().to_string());
            eprintln!("error: {line}");
            return ExitCode::from(2);
        }
    };
    let result = match cli.verb {
        Verb::Run(args) => run::run(args),
        Verb::Bench(args) => bench::bench(args),
        Verb::Accuracy(args) => accuracy::accuracy(args),
        Verb::Stability(args) => stability::stability(args),
        Verb::Choose(args) => choose::choose(args),
        Verb::Soak(args) => soak::soak(args),
        Verb::Peers(args) => peers::peers(args),
        Verb::Cantilever(args) => cantilever::cantilever(args),
        Verb::Drape(args) => drape::drape(args),
        Verb::Crowd(args) => crowd::crowd(args),
        Verb::Storm(args) => storm::storm(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
    }
}
