//! The `main` of generated crates' binaries: run the model's analyses, print summaries, write
//! JSON and CSV results; or (`simulate`) check them against Monte Carlo sample paths.
//!
//! Arguments are parsed by hand (no clap) so the runtime stays light:
//! `[--analysis NAME] [-o DIR] [--quiet]`, or `simulate --paths N [options]` (see
//! [`SIMULATE_USAGE`]).

use crate::engine::{self, RunError};
use crate::simulate::{self, InputMode, SimError};
use crate::system::{Analysis, ModelInfo, System};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// Default output directory.
pub const DEFAULT_OUT_DIR: &str = "reachc-out";

const USAGE: &str = "usage: <model> [--analysis NAME] [-o DIR] [--quiet]
       <model> simulate --paths N [options]   (Monte Carlo check; simulate --help)
  --analysis NAME  run only this analysis (default: all)
  -o, --out DIR    output directory for <analysis>.json and <analysis>.csv (default: reachc-out)
  -q, --quiet      do not print the summaries
  -h, --help       print this help";

/// Help of the `simulate` mode.
pub const SIMULATE_USAGE: &str =
    "usage: <model> simulate --paths N [--analysis NAME] [--seed S] [--dt H]
         [--delta D] [--inputs random|corners|centre] [--hold T] [--confidence C]
         [--threads T] [-o DIR] [--quiet] [--progress]
  Euler-Maruyama sample paths checked against each analysis' delta-PRS; writes
  DIR/<analysis>.sim.json. Exit status 0 when every coverage check passes, 1 when one fails.
  --paths N          number of sample paths (required)
  --analysis NAME    check only this analysis (default: all)
  --seed S           random seed (default 0); the same seed gives the same results
  --dt H             largest Euler-Maruyama step (default: the analysis' step)
  --delta D          recompute the PRS at this delta instead of the analysis' own
  --inputs MODE      random: uniform in the input box (default); corners: a random corner;
                     centre: the box centre. random and corners are redrawn every hold time
  --hold T           hold time of the piecewise-constant inputs (default: the analysis' step)
  --confidence C     level of the Clopper-Pearson bounds and of the check (default 0.999)
  --threads T        worker threads (default: all cores); results do not depend on it
  -o, --out DIR      output directory (default: reachc-out)
  -q, --quiet        do not print the summaries
  --progress         write `reachc-progress <analysis> <done> <total>` lines to stderr";

/// Exit status of a successful run.
pub const EXIT_OK: u8 = 0;
/// Exit status when an analysis could not run (or its results could not be written).
pub const EXIT_FAILED: u8 = 1;
/// Exit status of a usage error.
pub const EXIT_USAGE: u8 = 2;

/// The `main` of a generated binary: parses `std::env::args`, see [`run_cli`]. Generic so that
/// the simulation's hot loop calls the generated model directly (no virtual calls).
pub fn main_with<S: System + Sync>(sys: &S, info: &ModelInfo) -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let code = run_cli(
        sys,
        info,
        &args,
        &mut std::io::stdout().lock(),
        &mut std::io::stderr().lock(),
    );
    ExitCode::from(code)
}

/// Parsed command line.
struct Options {
    analysis: Option<String>,
    out_dir: PathBuf,
    quiet: bool,
}

/// Parses the arguments; `Err(None)` for `--help`, `Err(Some(msg))` for a usage error.
fn parse(args: &[String]) -> Result<Options, Option<String>> {
    let mut opts = Options {
        analysis: None,
        out_dir: PathBuf::from(DEFAULT_OUT_DIR),
        quiet: false,
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let (flag, inline) = match a.split_once('=') {
            Some((f, v)) if f.starts_with("--") => (f, Some(v.to_string())),
            _ => (a.as_str(), None),
        };
        let mut value = |name: &str| {
            inline
                .clone()
                .or_else(|| it.next().cloned())
                .ok_or_else(|| Some(format!("{name} needs a value")))
        };
        match flag {
            "--analysis" => opts.analysis = Some(value("--analysis")?),
            "-o" | "--out" => opts.out_dir = PathBuf::from(value(flag)?),
            "-q" | "--quiet" => opts.quiet = true,
            "-h" | "--help" => return Err(None),
            other => return Err(Some(format!("unexpected argument `{other}`"))),
        }
    }
    Ok(opts)
}

/// Runs the command line `args` (without the program name), writing to `out` / `err`; returns
/// the exit status: [`EXIT_OK`], [`EXIT_FAILED`] if some analysis could not run or its files
/// could not be written, [`EXIT_USAGE`] for a usage error (including an unknown analysis name).
/// Analyses with an unsupported method are reported as skipped, not as failures. A first
/// argument `simulate` runs [`simulate_cli`].
pub fn run_cli<S: System + Sync>(
    sys: &S,
    info: &ModelInfo,
    args: &[String],
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> u8 {
    if args.first().is_some_and(|a| a == "simulate") {
        return simulate_cli(sys, info, &args[1..], out, err, None);
    }
    let opts = match parse(args) {
        Ok(o) => o,
        Err(None) => {
            let _ = writeln!(out, "{USAGE}");
            return EXIT_OK;
        }
        Err(Some(msg)) => {
            let _ = writeln!(err, "error: {msg}\n{USAGE}");
            return EXIT_USAGE;
        }
    };
    let Some(selected) = select(info, opts.analysis.as_deref(), err) else {
        return EXIT_USAGE;
    };
    let mut status = EXIT_OK;
    for a in selected {
        match engine::run(sys, info, a) {
            Ok(res) => {
                if !opts.quiet {
                    let _ = writeln!(out, "{}", res.summary());
                }
                match write_files(&res, &opts.out_dir) {
                    Ok((json, csv)) => {
                        if !opts.quiet {
                            let _ = writeln!(out, "  wrote {} and {}\n", json, csv);
                        }
                    }
                    Err(e) => {
                        let _ = writeln!(
                            err,
                            "error: analysis `{}`: cannot write results to {}: {e}",
                            a.name,
                            opts.out_dir.display()
                        );
                        status = EXIT_FAILED;
                    }
                }
            }
            Err(RunError::Unsupported(why)) => {
                let _ = writeln!(err, "skipped analysis `{}`: {why}", a.name);
            }
            Err(e) => {
                let _ = writeln!(err, "error: analysis `{}` could not run: {e}", a.name);
                status = EXIT_FAILED;
            }
        }
    }
    status
}

/// Writes `DIR/<analysis>.json` and `DIR/<analysis>.csv`; returns their paths.
fn write_files(
    res: &engine::AnalysisResult,
    dir: &std::path::Path,
) -> std::io::Result<(String, String)> {
    std::fs::create_dir_all(dir)?;
    let json = dir.join(format!("{}.json", res.analysis));
    std::fs::write(&json, res.to_json() + "\n")?;
    let csv = dir.join(format!("{}.csv", res.analysis));
    let mut f = std::io::BufWriter::new(std::fs::File::create(&csv)?);
    res.write_csv(&mut f)?;
    f.flush()?;
    Ok((json.display().to_string(), csv.display().to_string()))
}

/// The analyses to run: all, or the one named (`None` after reporting an unknown name).
fn select<'a>(
    info: &'a ModelInfo,
    name: Option<&str>,
    err: &mut dyn Write,
) -> Option<Vec<&'a Analysis>> {
    let Some(name) = name else {
        return Some(info.analyses.iter().collect());
    };
    let found: Vec<_> = info.analyses.iter().filter(|a| a.name == name).collect();
    if found.is_empty() {
        let names: Vec<&str> = info.analyses.iter().map(|a| a.name.as_str()).collect();
        let _ = writeln!(
            err,
            "error: model `{}` has no analysis `{name}` (available: {})",
            info.name,
            names.join(", ")
        );
        return None;
    }
    Some(found)
}

/// Parsed `simulate` command line.
struct SimArgs {
    analysis: Option<String>,
    out_dir: PathBuf,
    quiet: bool,
    progress: bool,
    delta: Option<f64>,
    opts: simulate::Options,
}

/// Parses the `simulate` arguments; `Err(None)` for `--help`, `Err(Some(msg))` for a usage
/// error.
fn parse_simulate(args: &[String]) -> Result<SimArgs, Option<String>> {
    let mut a = SimArgs {
        analysis: None,
        out_dir: PathBuf::from(DEFAULT_OUT_DIR),
        quiet: false,
        progress: false,
        delta: None,
        opts: simulate::Options::default(),
    };
    let mut paths = None;
    let mut it = args.iter();
    while let Some(arg) = it.next() {
        let (flag, inline) = match arg.split_once('=') {
            Some((f, v)) if f.starts_with("--") => (f, Some(v.to_string())),
            _ => (arg.as_str(), None),
        };
        let mut value = || {
            inline
                .clone()
                .or_else(|| it.next().cloned())
                .ok_or_else(|| Some(format!("{flag} needs a value")))
        };
        match flag {
            "--analysis" => a.analysis = Some(value()?),
            "-o" | "--out" => a.out_dir = PathBuf::from(value()?),
            "-q" | "--quiet" => a.quiet = true,
            "--progress" => a.progress = true,
            "--paths" => paths = Some(number::<u64>(flag, &value()?)?),
            "--seed" => a.opts.seed = number(flag, &value()?)?,
            "--dt" => a.opts.dt = Some(number(flag, &value()?)?),
            "--hold" => a.opts.hold = Some(number(flag, &value()?)?),
            "--confidence" => a.opts.confidence = number(flag, &value()?)?,
            "--delta" => {
                let d: f64 = number(flag, &value()?)?;
                if !(d > 0.0 && d < 1.0) {
                    return Err(Some(format!("--delta {d} must lie in (0, 1)")));
                }
                a.delta = Some(d);
            }
            "--threads" => {
                let t: usize = number(flag, &value()?)?;
                if t == 0 {
                    return Err(Some("--threads must be at least 1".into()));
                }
                a.opts.threads = Some(t);
            }
            "--inputs" => {
                let v = value()?;
                a.opts.inputs = InputMode::parse(&v).ok_or_else(|| {
                    Some(format!(
                        "--inputs `{v}`: expected random, corners or centre"
                    ))
                })?;
            }
            "-h" | "--help" => return Err(None),
            other => return Err(Some(format!("unexpected argument `{other}`"))),
        }
    }
    a.opts.paths = paths.ok_or_else(|| Some("--paths N is required".to_string()))?;
    Ok(a)
}

/// Parses a number given to `flag`.
fn number<T: std::str::FromStr>(flag: &str, v: &str) -> Result<T, Option<String>> {
    v.trim()
        .parse()
        .map_err(|_| Some(format!("{flag}: `{v}` is not a valid number")))
}

/// A progress callback: `(analysis, paths done, paths in all)`.
pub type Progress<'a> = dyn FnMut(&str, u64, u64) + 'a;

/// `simulate` mode: for each selected analysis, run the engine (at `--delta` if given), simulate
/// the paths, print the summary and write `DIR/<analysis>.sim.json`. Returns [`EXIT_OK`] when
/// every coverage check passes, [`EXIT_FAILED`] when one fails or an analysis or its files
/// fail, [`EXIT_USAGE`] for a usage error. Analyses without a PRS (no constants, unsupported
/// transform) are skipped with a message. `progress(analysis, done, total)` is called after each
/// batch of paths; without it, `--progress` writes `reachc-progress` lines to `err` instead.
pub fn simulate_cli<S: System + Sync>(
    sys: &S,
    info: &ModelInfo,
    args: &[String],
    out: &mut dyn Write,
    err: &mut dyn Write,
    mut progress: Option<&mut Progress<'_>>,
) -> u8 {
    let a = match parse_simulate(args) {
        Ok(a) => a,
        Err(None) => {
            let _ = writeln!(out, "{SIMULATE_USAGE}");
            return EXIT_OK;
        }
        Err(Some(msg)) => {
            let _ = writeln!(err, "error: {msg}\n{SIMULATE_USAGE}");
            return EXIT_USAGE;
        }
    };
    let Some(selected) = select(info, a.analysis.as_deref(), err) else {
        return EXIT_USAGE;
    };
    let mut status = EXIT_OK;
    for analysis in selected {
        let mut analysis = analysis.clone();
        if let Some(d) = a.delta {
            analysis.delta = d;
        }
        let result = match engine::run(sys, info, &analysis) {
            Ok(r) => r,
            Err(e @ (RunError::Unsupported(_) | RunError::NoConstants(_))) => {
                let _ = writeln!(
                    err,
                    "skipped analysis `{}`: no PRS to check ({e})",
                    analysis.name
                );
                continue;
            }
            Err(e) => {
                let _ = writeln!(
                    err,
                    "error: analysis `{}` could not run: {e}",
                    analysis.name
                );
                status = EXIT_FAILED;
                continue;
            }
        };
        let started = std::time::Instant::now();
        let simulated = {
            let name = analysis.name.as_str();
            let mut report_progress = |done: u64, total: u64| match progress.as_mut() {
                Some(f) => f(name, done, total),
                None if a.progress => {
                    let _ = writeln!(err, "reachc-progress {name} {done} {total}");
                }
                None => {}
            };
            simulate::simulate(sys, info, &result, &a.opts, &mut report_progress)
        };
        let report = match simulated {
            Ok(r) => r,
            Err(SimError::Usage(m)) => {
                let _ = writeln!(err, "error: {m}");
                return EXIT_USAGE;
            }
            Err(SimError::Invalid(m)) => {
                let _ = writeln!(
                    err,
                    "error: analysis `{}` cannot be simulated: {m}",
                    analysis.name
                );
                status = EXIT_FAILED;
                continue;
            }
        };
        let secs = started.elapsed().as_secs_f64();
        if !a.quiet {
            let path_steps = report.paths as f64 * report.steps_per_path as f64;
            let _ = write!(out, "{}", report.summary());
            let _ = writeln!(
                out,
                "  time: {secs:.3} s for {path_steps:.3e} path-steps ({:.3e} path-steps/s, {} \
                 threads)",
                path_steps / secs,
                simulate::thread_count(a.opts.threads)
            );
        }
        let file = a.out_dir.join(format!("{}.sim.json", report.analysis));
        let written = std::fs::create_dir_all(&a.out_dir)
            .and_then(|()| std::fs::write(&file, report.to_json() + "\n"));
        match written {
            Ok(()) if !a.quiet => {
                let _ = writeln!(out, "  wrote {}\n", file.display());
            }
            Ok(()) => {}
            Err(e) => {
                let _ = writeln!(err, "error: cannot write {}: {e}", file.display());
                status = EXIT_FAILED;
            }
        }
        if !report.passed() {
            status = EXIT_FAILED;
        }
    }
    status
}
