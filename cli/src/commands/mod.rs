//! The `reachc` command line. Exit codes: 0 ok, 1 spec errors or an analysis that cannot run
//! (or a failed coverage check), 2 usage, I/O or cargo errors, 3 "not shown safe" with
//! `run --deny-unsafe` ([`reachc_runtime::app`]).

mod build;
mod failures;
pub mod inspect;
mod plot;
mod progress;
mod run;
mod simulate;

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use reachc_compiler::diagnostics::render;
use reachc_compiler::driver::{load, LoadError, Loaded};
use reachc_runtime::report::count;

/// reachc: a compiler for stochastic reachability (delta-probabilistic reachable sets).
#[derive(Parser, Debug)]
#[command(name = "reachc", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Parse and check a spec; print diagnostics.
    Check {
        /// The .sde spec.
        spec: PathBuf,
    },
    /// Show the checked model: simplified drift and diffusion, Jacobians, atoms and bounds.
    Inspect {
        /// The .sde spec.
        spec: PathBuf,
        /// Print JSON (documented in docs/language.md) instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Generate a Rust crate for a spec and compile it with cargo.
    Build {
        /// The .sde spec.
        spec: PathBuf,
        /// The crate's directory (default: ./CRATE_NAME); replaced if it holds an older one.
        #[arg(short, long)]
        out: Option<PathBuf>,
        /// Only write the crate; do not run cargo.
        #[arg(long)]
        no_compile: bool,
        /// Compile with optimisations (cargo build --release).
        #[arg(long)]
        release: bool,
        /// Do not show cargo's progress.
        #[arg(short, long)]
        quiet: bool,
    },
    /// Compute the spec's delta-PRS analyses: print summaries, write JSON and CSV results.
    Run {
        /// The .sde spec.
        spec: PathBuf,
        /// Run only this analysis (default: all).
        #[arg(long)]
        analysis: Option<String>,
        /// Generated and compiled code, or the IR interpreter (no cargo needed).
        #[arg(long, value_enum, default_value = "compiled")]
        backend: run::Backend,
        /// Directory for ANALYSIS.json and ANALYSIS.csv (default: reachc-out).
        #[arg(short, long)]
        out: Option<PathBuf>,
        /// Pictures of the results.
        #[command(flatten)]
        plot: plot::RunPlotArgs,
        /// Exit with code 3 when a verdict is "not shown safe" (the results are written).
        #[arg(long)]
        deny_unsafe: bool,
        /// Also bound each analysis' probability of safety on [0, T], for every start and input
        /// (analyses with unsafe sets and a uniform guarantee; about a dozen runs each):
        /// printed, and `safety_probability` in the JSON.
        #[arg(long)]
        probability: bool,
        /// Also write ANALYSIS.tightening.csv: the unsafe sets inflated for a nominal
        /// (noise-free) plan per report interval, so that a plan avoiding them keeps the
        /// stochastic system out of the unsafe sets with probability 1 - delta (MPC set
        /// erosion, method.md 8.14).
        #[arg(long)]
        tighten: bool,
        /// Do not show cargo's progress (compiled backend).
        #[arg(short, long)]
        quiet: bool,
    },
    /// Monte Carlo check of the analyses: Euler-Maruyama sample paths against each delta-PRS;
    /// writes ANALYSIS.sim.json. Exit code 1 when a coverage check fails. With --shard I/K,
    /// only that shard's paths and a part file; `reachc simulate merge` makes the reports.
    Simulate(simulate::SimulateCommand),
    /// Draw a result of `reachc run` (ANALYSIS.json): its sets in a 2-D projection with sample
    /// paths and unsafe sets (given the spec), and its radii against time; SVG and PNG.
    Plot(plot::PlotArgs),
}

/// Exit code for spec errors: the runtime's code for an analysis that cannot run
/// ([`reachc_runtime::app::EXIT_FAILED`]), so one spec problem has one code at every stage.
pub const EXIT_SPEC: u8 = reachc_runtime::app::EXIT_FAILED;
/// Exit code for usage and I/O errors (the runtime's [`reachc_runtime::app::EXIT_USAGE`]).
pub const EXIT_USAGE: u8 = reachc_runtime::app::EXIT_USAGE;

/// Runs the CLI on the process arguments.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            // clap uses 0 for --help/--version and 2 for usage errors, as we do.
            return ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(EXIT_USAGE));
        }
    };
    match run(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(code) => ExitCode::from(code),
    }
}

fn run(command: Command) -> Result<(), u8> {
    match command {
        Command::Build {
            spec,
            out,
            no_compile,
            release,
            quiet,
        } => build::run_build(&spec, out, no_compile, release, quiet),
        Command::Run {
            spec,
            analysis,
            backend,
            out,
            plot,
            deny_unsafe,
            probability,
            tighten,
            quiet,
        } => run::run_spec(
            &spec,
            analysis,
            backend,
            out,
            &plot,
            run::Flags {
                deny_unsafe,
                probability,
                tighten,
                quiet,
            },
        ),
        Command::Simulate(cmd) => simulate::run_command(cmd),
        Command::Plot(args) => plot::run_plot(&args),
        Command::Check { spec } => {
            let loaded = load_reporting(&spec)?;
            let m = &loaded.model;
            let counts = [
                (m.states.len(), "state"),
                (m.inputs.len(), "input"),
                (m.noises.len(), "noise channel"),
            ]
            .map(|(n, noun)| count(n as u64, noun));
            println!(
                "ok: model `{}` ({}, {} {})",
                m.name,
                counts.join(", "),
                m.analyses.len(),
                if m.analyses.len() == 1 {
                    "analysis"
                } else {
                    "analyses"
                }
            );
            Ok(())
        }
        Command::Inspect { spec, json } => {
            let mut loaded = load_reporting(&spec)?;
            let mut out = std::io::BufWriter::new(std::io::stdout().lock());
            let written = if json {
                inspect::json(&mut loaded.model, &mut out)
            } else {
                inspect::text(&mut loaded.model, &mut out)
            };
            // A closed pipe (`| head`) is not worth a panic or an error message.
            match written.and_then(|()| out.flush()) {
                Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
                    eprintln!("error: writing the report: {e}");
                    Err(EXIT_USAGE)
                }
                _ => Ok(()),
            }
        }
    }
}

/// Loads a spec, printing diagnostics (warnings too) to stderr; the exit code on failure.
fn load_reporting(spec: &std::path::Path) -> Result<Loaded, u8> {
    let color = std::io::stderr().is_terminal();
    match load(spec) {
        Ok(loaded) => {
            if !loaded.warnings.is_empty() {
                let path = loaded.path.display().to_string();
                eprint!("{}", render(&loaded.warnings, &path, &loaded.source, color));
            }
            Ok(loaded)
        }
        Err(e) => {
            eprint!("{}", e.report(color));
            Err(match e {
                LoadError::Io(_) => EXIT_USAGE,
                LoadError::Spec { .. } => EXIT_SPEC,
            })
        }
    }
}
