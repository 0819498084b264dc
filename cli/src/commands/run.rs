//! `reachc run`: compute the spec's analyses with the compiled backend (a generated crate, built
//! with cargo and cached) or the IR interpreter (no cargo), print summaries, write JSON and CSV.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use clap::ValueEnum;

use super::plot::{self, RunPlotArgs};
use super::progress::CompileDisplay;
use super::{load_reporting, EXIT_SPEC, EXIT_USAGE};
use reachc_compiler::backend::interp::Interpreter;
use reachc_compiler::backend::prepare;
use reachc_compiler::diagnostics::render;
use reachc_compiler::driver::Loaded;
use reachc_compiler::package::{Cache, Profile};
use reachc_runtime::app::{RunOptions, DEFAULT_OUT_DIR};
use reachc_runtime::model::ModelInfo;

/// Which backend computes the sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Backend {
    /// Generate a Rust crate, compile it (cached) and run its binary.
    Compiled,
    /// Evaluate the IR directly: no cargo, results at once.
    Interp,
}

/// Runs `reachc run` (and, with `--plot`, plots the results). Exit codes: 0 ok, 1 spec errors
/// or an analysis that cannot run, 2 usage, I/O or cargo failures.
pub fn run_spec(
    spec: &Path,
    analysis: Option<String>,
    backend: Backend,
    out: Option<PathBuf>,
    plot: &RunPlotArgs,
    quiet: bool,
) -> Result<(), u8> {
    let color = std::io::stderr().is_terminal();
    let mut loaded = load_reporting(spec)?;
    plot::check_states(plot, &loaded)?;
    let opts = RunOptions {
        analysis: analysis.clone(),
        out_dir: out.unwrap_or_else(|| PathBuf::from(DEFAULT_OUT_DIR)),
        quiet: false,
    };
    let out_dir = opts.out_dir.clone();
    let before = plot::result_stamps(plot, &loaded, &out_dir);
    let (code, model) = match backend {
        Backend::Interp => {
            let (interp, info) = interpreter(loaded, color);
            let code = reachc_runtime::app::run(
                &interp,
                &info,
                &opts,
                &mut std::io::stdout().lock(),
                &mut std::io::stderr().lock(),
            );
            (code, Some((interp, info)))
        }
        Backend::Compiled => {
            let binary = compiled_binary(&mut loaded, color, quiet)?;
            let status = std::process::Command::new(&binary)
                .args(opts.to_args())
                .status()
                .map_err(|e| {
                    eprintln!("error: cannot run {}: {e}", binary.display());
                    EXIT_USAGE
                })?;
            let code = status
                .code()
                .map_or(EXIT_USAGE, |c| u8::try_from(c).unwrap_or(EXIT_USAGE));
            // The plots simulate paths in-process: the interpreter computes the same numbers.
            (
                code,
                plot.plot.is_some().then(|| plot::interpreter_quiet(loaded)),
            )
        }
    };
    // A usage error (e.g. an unknown analysis) ran nothing worth plotting.
    let plotted = match model {
        Some((interp, info)) if code != EXIT_USAGE => plot::plot_after_run(
            plot,
            (&interp, &info),
            analysis.as_deref(),
            &out_dir,
            &before,
        ),
        _ => Ok(()),
    };
    match (code, plotted) {
        (0, p) => p,
        (1, Err(p)) => Err(p.max(EXIT_SPEC)),
        (1, Ok(())) => Err(EXIT_SPEC),
        (c, _) => Err(c),
    }
}

/// The interpreter backend of a loaded spec and its model info (warnings printed to stderr).
pub(super) fn interpreter(mut loaded: Loaded, color: bool) -> (Interpreter, ModelInfo) {
    let prepared = prepare(&mut loaded.model);
    if !prepared.warnings.is_empty() {
        let path = loaded.path.display().to_string();
        eprint!(
            "{}",
            render(&prepared.warnings, &path, &loaded.source, color)
        );
    }
    let interp = Interpreter::new(loaded.model, &prepared);
    (interp, prepared.info)
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
