//! `reachc run`: compute the spec's analyses with the compiled backend (a generated crate, built
//! with cargo and cached) or the IR interpreter (no cargo), print summaries, write JSON and CSV.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use clap::ValueEnum;

use super::plot::{self, RunPlotArgs};
use super::{load_reporting, EXIT_SPEC, EXIT_USAGE};
use reachc_compiler::backend::crate_writer::{
    compile_crate, shared_target_dir, write_crate, CrateOptions,
};
use reachc_compiler::backend::interp::Interpreter;
use reachc_compiler::backend::{mangle, prepare};
use reachc_compiler::diagnostics::render;
use reachc_compiler::driver::Loaded;
use reachc_runtime::app::DEFAULT_OUT_DIR;
use reachc_runtime::system::ModelInfo;

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
) -> Result<(), u8> {
    let color = std::io::stderr().is_terminal();
    let mut loaded = load_reporting(spec)?;
    plot::check_states(plot, &loaded)?;
    let out_dir = out.unwrap_or_else(|| PathBuf::from(DEFAULT_OUT_DIR));
    let mut args = vec!["-o".to_string(), out_dir.display().to_string()];
    if let Some(name) = &analysis {
        args.extend(["--analysis".to_string(), name.clone()]);
    }
    let before = plot::result_stamps(plot, &loaded, &out_dir);
    let (code, model) = match backend {
        Backend::Interp => {
            let (interp, info) = interpreter(loaded, color);
            let code = reachc_runtime::app::run_cli(
                &interp,
                &info,
                &args,
                &mut std::io::stdout().lock(),
                &mut std::io::stderr().lock(),
            );
            (code, Some((interp, info)))
        }
        Backend::Compiled => {
            let binary = compiled_binary(&mut loaded, color)?;
            let status = std::process::Command::new(&binary)
                .args(&args)
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

/// Writes the spec's crate into the shared cache and compiles it (release); the binary's path,
/// or the exit code after reporting the failure.
pub(super) fn compiled_binary(loaded: &mut Loaded, color: bool) -> Result<PathBuf, u8> {
    let crates = shared_target_dir()
        .and_then(|t| t.parent().map(|p| p.join("crates")))
        .unwrap_or_else(|| PathBuf::from("target/reachc-crates"));
    std::fs::create_dir_all(&crates).map_err(|e| {
        eprintln!("error: cannot create {}: {e}", crates.display());
        EXIT_USAGE
    })?;
    let dir = crates.join(mangle::crate_name(&loaded.model.name));
    let written = write_crate(loaded, &dir, &CrateOptions::default()).map_err(|e| {
        eprint!("{}", e.report(color));
        e.exit_code()
    })?;
    compile_crate(&written.dir, true).map_err(|e| {
        eprint!("{}", e.report(color));
        EXIT_USAGE
    })
}
