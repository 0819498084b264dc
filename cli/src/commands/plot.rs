//! `reachc plot RESULT.json` and `reachc run --plot DIR`: pictures of a result (see
//! [`crate::plot`]). Sample paths are simulated in-process with the IR interpreter (the same
//! numbers as generated code, no cargo).
//!
//! The radius figure's empirical quantile comes from the Monte Carlo report
//! `<analysis>.sim.json` beside the result when there is one for the same analysis, delta and
//! report times (written by `reachc simulate -o DIR`); otherwise `reachc run --plot` simulates
//! [`RUN_QUANTILE_PATHS`] paths itself, and `reachc plot` draws no quantile.

use std::path::{Path, PathBuf};

use reachc_runtime::app::commit;
use reachc_runtime::output::Files;
use reachc_runtime::simulate::{self, SimReport};
use reachc_runtime::{engine, Model as _};

use super::{load_reporting, EXIT_USAGE};
use crate::plot::input::{ResultFile, SimFile};
use crate::plot::{self, select, Choice, Model, Quantile, StateWidths};
use reachc_compiler::backend::interp::Interpreter;
use reachc_compiler::backend::prepare;
use reachc_compiler::driver::Loaded;

/// Paths `reachc run --plot` simulates for the quantile when no report is at hand.
pub const RUN_QUANTILE_PATHS: u64 = 2000;
/// Most state updates (paths x states x report times) of that simulation: about a second with
/// the interpreter; larger models (the 1000-state chain: 2 * 10^8) get no quantile.
const RUN_QUANTILE_WORK: f64 = 2e7;

/// `reachc plot`'s options.
#[derive(clap::Args, Debug)]
pub struct PlotArgs {
    /// The result of `reachc run` (DIR/ANALYSIS.json).
    pub result: PathBuf,
    /// The spec the result was computed from: adds sample paths and unsafe sets.
    #[arg(long)]
    pub spec: Option<PathBuf>,
    /// The two plotted states, e.g. `theta,omega` (default: the first two output states).
    #[arg(long, value_delimiter = ',')]
    pub states: Option<Vec<String>>,
    /// Times at which the sets are drawn, e.g. `0.5,1,4` (default: four, evenly spaced, ending
    /// at the horizon).
    #[arg(long, value_delimiter = ',')]
    pub times: Option<Vec<f64>>,
    /// Number of sample paths (with --spec).
    #[arg(long, default_value_t = plot::DEFAULT_PATHS)]
    pub paths: u64,
    /// Random seed of the paths (path p is path p of `reachc simulate --seed S`).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Monte Carlo report for the quantile (default: ANALYSIS.sim.json beside the result).
    #[arg(long)]
    pub sim: Option<PathBuf>,
    /// Also fill the union of the PRS over all report times (an envelope, as the paper's
    /// Fig. 7).
    #[arg(long)]
    pub envelope: bool,
    /// Directory for the pictures (default: the result's directory).
    #[arg(short, long)]
    pub out: Option<PathBuf>,
}

/// `reachc run`'s plot options.
#[derive(clap::Args, Debug, Default)]
pub struct RunPlotArgs {
    /// Also draw each analysis' sets and radii into DIR (ANALYSIS_sets.svg/.png,
    /// ANALYSIS_radius.svg/.png).
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// The two plotted states, e.g. `theta,omega` (default: the first two output states).
    #[arg(long, value_delimiter = ',', requires = "plot", value_name = "A,B")]
    pub plot_states: Option<Vec<String>>,
    /// Times at which the sets are drawn (default: four, evenly spaced, ending at the horizon).
    #[arg(
        long,
        value_delimiter = ',',
        requires = "plot",
        value_name = "T1,T2,..."
    )]
    pub plot_times: Option<Vec<f64>>,
    /// Number of sample paths drawn.
    #[arg(long, default_value_t = plot::DEFAULT_PATHS, requires = "plot", value_name = "N")]
    pub plot_paths: u64,
    /// Also fill the union of the PRS over all report times.
    #[arg(long, requires = "plot")]
    pub plot_envelope: bool,
}

/// Checks `--plot-states` against the spec's states before anything runs.
pub(super) fn check_states(args: &RunPlotArgs, loaded: &Loaded) -> Result<(), u8> {
    let Some(names) = &args.plot_states else {
        return Ok(());
    };
    let states: Vec<String> = loaded.model.states.iter().map(|s| s.name.clone()).collect();
    select::pick_states(&states, &[], Some(names))
        .map(|_| ())
        .map_err(|e| {
            eprintln!("error: --plot-states: {e}");
            EXIT_USAGE
        })
}

/// A fresh staging directory for `reachc run --plot`: the run writes its results there, the
/// plots are drawn from them, and both are then written together into their places.
pub(super) fn staging_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("reachc-run-{}", std::process::id()));
    // Left by an earlier process with the same id that was killed.
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn result_path(out_dir: &Path, analysis: &str) -> PathBuf {
    out_dir.join(format!("{analysis}.json"))
}

/// The interpreter of a loaded spec, without printing its warnings again.
pub(super) fn interpreter_quiet(mut loaded: Loaded) -> Interpreter {
    let prepared = prepare(&mut loaded.model);
    Interpreter::new(loaded.model, &prepared)
}

/// Writes `files` whole or not at all and prints their names; the exit code of a failure.
fn write(files: Files) -> Result<(), u8> {
    commit(
        files,
        true,
        &mut std::io::stdout().lock(),
        &mut std::io::stderr().lock(),
    )
}

/// The quantiles of a Monte Carlo report file (per state when it has them for every state of
/// the result).
fn quantile_of(sim: &SimFile, result: &ResultFile, source: String) -> Quantile {
    let n = result.states.len();
    let per_state = sim.states == result.states && sim.steps.iter().all(|s| s.states.len() == n);
    // A statistic that was not finite is written as `null`, read as NaN.
    let finite = |v: f64| Some(v).filter(|v| v.is_finite());
    Quantile {
        values: sim.steps.iter().map(|s| finite(s.quantile)).collect(),
        states: if per_state {
            StateWidths::per_state(&sim.steps, n, |s, i| {
                (finite(s.states[i].prs), finite(s.states[i].quantile))
            })
        } else {
            Vec::new()
        },
        paths: sim.paths,
        source,
    }
}

/// `<analysis>.sim.json` beside the result, if it is there and belongs to it (otherwise a
/// message on stderr says why it is not used).
fn sibling_report(result_path: &Path, result: &ResultFile) -> Option<Quantile> {
    let path = result_path.with_file_name(format!("{}.sim.json", result.analysis));
    if !path.is_file() {
        return None;
    }
    match SimFile::read(&path).map(|s| (s.mismatch(result), s)) {
        Ok((None, sim)) => Some(quantile_of(
            &sim,
            result,
            format!("report {}", path.display()),
        )),
        Ok((Some(why), _)) => {
            eprintln!("note: not using {}: {why}", path.display());
            None
        }
        Err(e) => {
            eprintln!("note: not using {e}");
            None
        }
    }
}

/// Runs `reachc plot`. Exit codes: 0 ok, 1 errors in the spec, 2 usage or I/O errors (a missing
/// or malformed result, an unknown state, a spec that does not match the result).
pub fn run_plot(args: &PlotArgs) -> Result<(), u8> {
    let usage = |e: String| {
        eprintln!("error: {e}");
        EXIT_USAGE
    };
    let result = ResultFile::read(&args.result).map_err(usage)?;
    let quantile = match &args.sim {
        Some(path) => {
            let sim = SimFile::read(path).map_err(usage)?;
            if let Some(why) = sim.mismatch(&result) {
                return Err(usage(format!(
                    "{} does not belong to the result: {why}",
                    path.display()
                )));
            }
            Some(quantile_of(
                &sim,
                &result,
                format!("report {}", path.display()),
            ))
        }
        None => sibling_report(&args.result, &result),
    };
    let model = match &args.spec {
        Some(spec) => Some(interpreter_quiet(load_reporting(spec)?)),
        None => None,
    };
    let choice = Choice {
        states: args.states.clone(),
        times: args.times.clone(),
        paths: args.paths,
        seed: args.seed,
        envelope: args.envelope,
    };
    let dir = match &args.out {
        Some(d) => d.clone(),
        None => args
            .result
            .parent()
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf),
    };
    let model = model.as_ref().map(|sys| Model {
        sys,
        tables: &sys.model().tables,
    });
    let files = plot::plot_result(&result, model.as_ref(), quantile.as_ref(), &choice, &dir)
        .map_err(usage)?;
    write(files)
}

/// The quantile for `reachc run --plot`: the report beside the result, or a simulation of
/// [`RUN_QUANTILE_PATHS`] paths of the analysis (computed again in-process: the interpreter
/// gives the result's numbers).
fn run_quantile(model: &Model<'_>, json: &Path, result: &ResultFile) -> Option<Quantile> {
    if let Some(q) = sibling_report(json, result) {
        return Some(q);
    }
    let work = RUN_QUANTILE_PATHS as f64 * (result.states.len() * result.steps.len()) as f64;
    if work > RUN_QUANTILE_WORK {
        eprintln!(
            "note: no quantile for `{}`: {RUN_QUANTILE_PATHS} paths of {} states are too many \
             for a plot (`reachc simulate -o` writes a report that is used)",
            result.analysis,
            result.states.len()
        );
        return None;
    }
    let computed = engine::run(model.sys, &result.analysis).ok()?;
    let opts = simulate::Options {
        paths: RUN_QUANTILE_PATHS,
        ..simulate::Options::default()
    };
    let report: SimReport = match simulate::simulate(model.sys, &computed, &opts, &mut |_, _| {}) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("note: no quantile for `{}`: {e}", result.analysis);
            return None;
        }
    };
    Some(Quantile::of(
        &report,
        format!(
            "{} paths simulated for this plot (seed 0; `reachc simulate -o` writes a report \
             that is used instead)",
            report.paths
        ),
    ))
}

/// After `reachc run` wrote its results into `staging` (see [`staging_dir`]): plots each
/// selected analysis into `args.plot`, then writes the results into `out_dir` and the plots
/// together, whole or not at all (nothing when a plot fails). `interp` is the spec's
/// interpreter and model info. Analyses without a PRS get sample paths and unsafe sets only;
/// those without a result (skipped) are not plotted. Returns the exit code of a failure.
pub(super) fn plot_after_run(
    args: &RunPlotArgs,
    sys: &Interpreter,
    analysis: Option<&str>,
    staging: &Path,
    out_dir: &Path,
) -> Result<(), u8> {
    let Some(dir) = &args.plot else {
        return Ok(());
    };
    // No staging directory: every analysis was skipped, nothing was written.
    let mut files = if staging.is_dir() {
        Files::read_dir(staging, out_dir).map_err(|e| {
            eprintln!("error: reading the results in {}: {e}", staging.display());
            EXIT_USAGE
        })?
    } else {
        Files::new()
    };
    let model = Model {
        sys,
        tables: &sys.model().tables,
    };
    let choice = Choice {
        states: args.plot_states.clone(),
        times: args.plot_times.clone(),
        paths: args.plot_paths,
        seed: 0,
        envelope: args.plot_envelope,
    };
    for a in sys
        .info()
        .analyses()
        .iter()
        .filter(|a| analysis.is_none_or(|name| a.spec.name == name))
    {
        let plotted = if a.constants.is_err() {
            eprintln!(
                "note: analysis `{}` has no PRS: plotting its sample paths and unsafe sets only",
                a.spec.name
            );
            plot::plot_without_result(&model, a, &choice, dir)
        } else {
            let staged = result_path(staging, &a.spec.name);
            if !staged.is_file() {
                eprintln!(
                    "note: no result for analysis `{}` from this run: not plotted",
                    a.spec.name
                );
                continue;
            }
            ResultFile::read(&staged).and_then(|result| {
                // A Monte Carlo report beside the final result is used for the quantile.
                let json = result_path(out_dir, &a.spec.name);
                let quantile = run_quantile(&model, &json, &result);
                plot::plot_result(&result, Some(&model), quantile.as_ref(), &choice, dir)
            })
        };
        match plotted {
            Ok(f) => files.extend(f),
            Err(e) => {
                eprintln!(
                    "error: plotting analysis `{}`: {e} (nothing written)",
                    a.spec.name
                );
                return Err(EXIT_USAGE);
            }
        }
    }
    write(files)
}
