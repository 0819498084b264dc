//! `reachc run`: compute the spec's analyses with the compiled backend (a generated crate, built
//! with cargo and cached) or the IR interpreter (no cargo), print summaries, write JSON and CSV.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use clap::ValueEnum;

use super::failures::Locator;
use super::plot::{self, RunPlotArgs};
use super::progress::CompileDisplay;
use super::{load_reporting, EXIT_USAGE};
use reachc_compiler::backend::interp::Interpreter;
use reachc_compiler::backend::prepare;
use reachc_compiler::diagnostics::render;
use reachc_compiler::driver::Loaded;
use reachc_compiler::package::{Cache, Profile};
use reachc_runtime::app::{RunOptions, DEFAULT_OUT_DIR, EXIT_OK};

/// Which backend computes the sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Backend {
    /// Generate a Rust crate, compile it (cached) and run its binary.
    Compiled,
    /// Evaluate the IR directly: no cargo, results at once.
    Interp,
}

/// The switches of `reachc run`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Flags {
    /// `--deny-unsafe`: exit with 3 when a verdict is "not shown safe".
    pub deny_unsafe: bool,
    /// `--probability`: also bound each analysis' probability of safety.
    pub probability: bool,
    /// `--tighten`: also write each analysis' tightening for a nominal plan.
    pub tighten: bool,
    /// `--quiet`: no cargo progress.
    pub quiet: bool,
}

/// Runs `reachc run` (and, with `--plot`, plots the results). Exit codes as the runtime's
/// [`reachc_runtime::app::run`]: 0 ok, 1 spec errors or an analysis that cannot run (each
/// failure located in the spec; the other analyses' results are written), 2 usage, I/O or
/// cargo failures (nothing written), 3 "not shown safe" with `--deny-unsafe` (everything
/// written).
pub fn run_spec(
    spec: &Path,
    analysis: Option<String>,
    backend: Backend,
    out: Option<PathBuf>,
    plot: &RunPlotArgs,
    Flags {
        deny_unsafe,
        probability,
        tighten,
        quiet,
    }: Flags,
) -> Result<(), u8> {
    let color = std::io::stderr().is_terminal();
    let mut loaded = load_reporting(spec)?;
    plot::check_states(plot, &loaded)?;
    let locator = Locator::new(&loaded, color);
    let out_dir = out.unwrap_or_else(|| PathBuf::from(DEFAULT_OUT_DIR));
    // With --plot, the results are staged and written together with the pictures.
    let staging = plot.plot.as_ref().map(|_| plot::staging_dir());
    let opts = RunOptions {
        analysis: analysis.clone(),
        out_dir: staging.clone().unwrap_or_else(|| out_dir.clone()),
        quiet: false,
        deny_unsafe,
        probability,
        tighten,
        stage: staging.is_some(),
        error_lines: backend == Backend::Compiled,
    };
    let (code, model) = match backend {
        Backend::Interp => {
            let interp = interpreter(loaded, color);
            let mut failures = Vec::new();
            let code = reachc_runtime::app::run_collecting(
                &interp,
                &opts,
                &mut std::io::stdout().lock(),
                &mut std::io::stderr().lock(),
                &mut failures,
            );
            locator.print_collected(&failures, analysis.as_deref());
            (code, interp)
        }
        Backend::Compiled => {
            let binary = compiled_binary(&mut loaded, color, quiet)?;
            let cannot_run = |e: std::io::Error| {
                eprintln!("error: cannot run {}: {e}", binary.display());
                EXIT_USAGE
            };
            // Its failures come as `reachc-failure` lines on stderr, located here.
            let mut child = std::process::Command::new(&binary)
                .args(opts.to_args())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .map_err(cannot_run)?;
            if let Some(stderr) = child.stderr.take() {
                locator.forward(stderr);
            }
            let status = child.wait().map_err(cannot_run)?;
            // The plots simulate paths in-process: the interpreter computes the same numbers.
            (exit_code(status), plot::interpreter_quiet(loaded))
        }
    };
    if let Some(staging) = staging {
        // A usage error ran nothing. A failed run staged no results: only the analyses without
        // a PRS get their picture (sample paths and unsafe sets, to see why).
        let plotted = if code != EXIT_USAGE {
            plot::plot_after_run(plot, &model, analysis.as_deref(), &staging, &out_dir)
        } else {
            Ok(())
        };
        let _ = std::fs::remove_dir_all(&staging);
        plotted?;
    }
    match code {
        EXIT_OK => Ok(()),
        c => Err(c),
    }
}

/// A child's exit status as ours (killed by a signal: a usage/I/O-class failure).
pub(super) fn exit_code(status: std::process::ExitStatus) -> u8 {
    status
        .code()
        .map_or(EXIT_USAGE, |c| u8::try_from(c).unwrap_or(EXIT_USAGE))
}

/// The interpreter backend of a loaded spec and its model info (warnings printed to stderr).
pub(super) fn interpreter(mut loaded: Loaded, color: bool) -> Interpreter {
    let prepared = prepare(&mut loaded.model);
    if !prepared.warnings.is_empty() {
        let path = loaded.path.display().to_string();
        eprint!(
            "{}",
            render(&prepared.warnings, &path, &loaded.source, color)
        );
    }
    Interpreter::new(loaded.model, &prepared)
}

/// The binary of the spec's crate in reachc's cache (release profile): generated, and compiled
/// when the cached binary is not current (cargo's progress on stderr unless `quiet`; nothing
/// when nothing is compiled). Warnings from preparing the model go to stderr. The exit code
/// after reporting a failure: 1 for spec errors, 2 for the cache or cargo.
pub(super) fn compiled_binary(
    loaded: &mut Loaded,
    color: bool,
    quiet: bool,
) -> Result<PathBuf, u8> {
    let report = |e: reachc_compiler::package::BuildError| {
        eprint!("{}", e.report(color));
        e.exit_code()
    };
    let cache = Cache::from_env().map_err(report)?;
    let mut display = CompileDisplay::new(quiet);
    let binary = cache
        .binary(loaded, Profile::Release, &mut |p| display.event(p))
        .map_err(report)?;
    if !binary.warnings.is_empty() {
        let path = loaded.path.display().to_string();
        eprint!("{}", render(&binary.warnings, &path, &loaded.source, color));
    }
    Ok(binary.path)
}
