//! The front end of generated binaries, and of `reachc run` / `reachc simulate` with the
//! interpreter: run a model's analyses (summaries, JSON and CSV results) or check them against
//! Monte Carlo sample paths (`simulate`).
//!
//! [`run`] and [`simulate()`] take typed options ([`RunOptions`], [`SimulateOptions`]); a
//! generated binary's command line is their textual form, parsed by [`Command::parse`] and
//! written by `to_args` (by hand, no clap, so the runtime stays light):
//! `[--analysis NAME] [-o DIR] [--quiet] [--deny-unsafe] [--probability] [--tighten]
//! [--error-lines]`, or
//! `simulate --paths N [options]` (see [`SIMULATE_USAGE`]).
//!
//! Exit codes (the CLI's too): [`EXIT_OK`], [`EXIT_FAILED`] (an analysis could not run, its
//! result is not finite, or a coverage check failed), [`EXIT_USAGE`] (a bad command line,
//! including an analysis name the model does not have, or a file that cannot be written),
//! [`EXIT_UNSAFE`] (`--deny-unsafe` and a verdict "not shown safe"). The files of one command
//! are written together, each whole ([`crate::output`]): when some analyses fail, the files of
//! the others are written and each failure is reported ([`Failure`]; with `--error-lines` as
//! the lines the CLI locates in the spec).

use crate::failure::Failure;
use crate::output::Files;
use crate::report;
use reachc_core::engine::RunError;
use reachc_core::model::ModelInfo;
use reachc_core::simulate::{self, InputMode, Shard, SimError, SimReport};
use reachc_core::{Model, Reach};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// Default output directory.
pub const DEFAULT_OUT_DIR: &str = "reachc-out";

const USAGE: &str =
    "usage: <model> [--analysis NAME] [-o DIR] [--quiet] [--deny-unsafe] [--probability]
               [--tighten] [--error-lines]
       <model> simulate --paths N [options]   (Monte Carlo check; simulate --help)
  --analysis NAME  run only this analysis (default: all)
  -o, --out DIR    output directory for <analysis>.json and <analysis>.csv (default: reachc-out)
  -q, --quiet      do not print the summaries
  --deny-unsafe    exit with status 3 when a verdict is \"not shown safe\"
  --probability    also bound the probability of safety on [0, T] (analyses with unsafe sets
                   and a uniform guarantee; about a dozen runs each)
  --tighten        also write <analysis>.tightening.csv: the unsafe sets inflated for a
                   nominal (noise-free) plan, per report interval (MPC set erosion)
  --error-lines    report failed analyses as `reachc-failure` lines (for reachc)
  -h, --help       print this help
  Exit status: 0 ok, 1 an analysis could not run (the others' results are written), 2 usage
  or I/O error, 3 not shown safe with --deny-unsafe (the results are written).";

/// Help of the `simulate` mode.
pub const SIMULATE_USAGE: &str =
    "usage: <model> simulate --paths N [--analysis NAME] [--seed S] [--dt H]
         [--delta D] [--inputs random|corners|centre] [--hold T] [--confidence C]
         [--threads T] [--shard I/K [--spec-hash H]] [--probability] [-o DIR] [--quiet]
         [--progress] [--error-lines]
  Euler-Maruyama sample paths checked against each analysis' delta-PRS; writes
  DIR/<analysis>.sim.json. Exit status 0 when every coverage check passes, 1 when one fails
  or an analysis cannot be simulated (the other reports are written), 2 on usage or I/O
  errors. With --shard, only shard I of K of the paths, and instead of the
  reports the exact statistics DIR/<analysis>.shard-I-of-K.part (exit status 0 when written),
  for `reachc simulate merge`.
  --paths N          number of sample paths (required)
  --analysis NAME    check only this analysis (default: all)
  --seed S           random seed (default 0); the same seed gives the same results
  --dt H             largest Euler-Maruyama step (default: per report interval, h L <= 0.05)
  --delta D          recompute the PRS at this delta instead of the analysis' own
  --inputs MODE      random: uniform in the input box (default); corners: a random corner;
                     centre: the box centre. random and corners are redrawn every hold time
  --hold T           hold time of the piecewise-constant inputs (default: the analysis' step)
  --confidence C     level of the Clopper-Pearson bounds and of the check (default 0.999)
  --threads T        worker threads (default: all cores); results do not depend on it
  --shard I/K        run only the paths [floor(I N / K), floor((I + 1) N / K)) (0-based I)
  --spec-hash H      the spec's identity recorded in the parts (reachc passes its SHA-256)
  --probability      also certify each analysis' probability of safety on [0, T] (unsafe sets,
                     uniform guarantee; about a dozen runs) and check it against the paths
                     that entered no unsafe set (Clopper-Pearson at --confidence)
  -o, --out DIR      output directory (default: reachc-out)
  -q, --quiet        do not print the summaries
  --progress         write `reachc-progress <analysis> <done> <total>` lines to stderr
  --error-lines      report failed analyses as `reachc-failure` lines (for reachc)";

/// Exit status of a successful run.
pub const EXIT_OK: u8 = 0;
/// Exit status when an analysis could not run or its result is not finite (the other analyses'
/// files are written), or, for `simulate`, a coverage check failed.
pub const EXIT_FAILED: u8 = 1;
/// Exit status of a usage error (an unknown analysis name too) or an I/O error (a file that
/// cannot be written: nothing is).
pub const EXIT_USAGE: u8 = 2;
/// Exit status of `run --deny-unsafe` when some verdict is "not shown safe" (the results are
/// written).
pub const EXIT_UNSAFE: u8 = 3;

/// What `run` does.
#[derive(Clone, Debug, PartialEq)]
pub struct RunOptions {
    /// Run only this analysis (all when `None`).
    pub analysis: Option<String>,
    /// Directory for `<analysis>.json` and `<analysis>.csv`.
    pub out_dir: PathBuf,
    /// Do not print the summaries.
    pub quiet: bool,
    /// Exit with [`EXIT_UNSAFE`] when a verdict is "not shown safe".
    pub deny_unsafe: bool,
    /// Also compute each analysis' probability of safety ([`Reach::safety_probability`]):
    /// printed, and in the JSON.
    pub probability: bool,
    /// Also write `<analysis>.tightening.csv` ([`Reach::tighten`], method.md 8.14) for the
    /// analyses of a model with unsafe sets, with a line in the summary.
    pub tighten: bool,
    /// `out_dir` is a staging directory that the caller moves into place (`reachc run --plot`):
    /// do not print where the files were written.
    pub stage: bool,
    /// Report failed analyses as [`Failure::to_line`] lines (the CLI locates them in the spec).
    pub error_lines: bool,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            analysis: None,
            out_dir: PathBuf::from(DEFAULT_OUT_DIR),
            quiet: false,
            deny_unsafe: false,
            probability: false,
            tighten: false,
            stage: false,
            error_lines: false,
        }
    }
}

/// What `simulate` does.
#[derive(Clone, Debug, PartialEq)]
pub struct SimulateOptions {
    /// Check only this analysis (all when `None`).
    pub analysis: Option<String>,
    /// Directory for `<analysis>.sim.json`.
    pub out_dir: PathBuf,
    /// Do not print the summaries.
    pub quiet: bool,
    /// Report progress as `reachc-progress <analysis> <done> <total>` lines on stderr (when no
    /// progress callback is given).
    pub progress: bool,
    /// Recompute each PRS at this delta instead of the analysis' own.
    pub delta: Option<f64>,
    /// Run only this shard of the paths and write its part (`<analysis>.shard-I-of-K.part`)
    /// instead of the report.
    pub shard: Option<Shard>,
    /// The spec's identity written into parts (`reachc` passes the SHA-256 of the spec's
    /// source); parts merge only with parts of the same.
    pub spec_hash: Option<String>,
    /// Report failed analyses as [`Failure::to_line`] lines (the CLI locates them in the spec).
    pub error_lines: bool,
    /// Certify each analysis' probability of safety ([`Reach::safety_probability`]) and test it
    /// against the paths (`simulate::Options::safety_bound`).
    pub probability: bool,
    /// The simulation itself.
    pub sim: simulate::Options,
}

impl Default for SimulateOptions {
    fn default() -> Self {
        SimulateOptions {
            analysis: None,
            out_dir: PathBuf::from(DEFAULT_OUT_DIR),
            quiet: false,
            progress: false,
            delta: None,
            shard: None,
            spec_hash: None,
            error_lines: false,
            probability: false,
            sim: simulate::Options::default(),
        }
    }
}

/// A parsed command line of a generated binary.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// Run the analyses.
    Run(RunOptions),
    /// Check them against Monte Carlo sample paths.
    Simulate(SimulateOptions),
    /// Print this help text.
    Help(&'static str),
}

/// A usage error: the message and the help to print after it.
#[derive(Clone, Debug, PartialEq)]
pub struct UsageError {
    /// What is wrong.
    pub message: String,
    /// The relevant help text.
    pub usage: &'static str,
}

impl Command {
    /// Parses the arguments (without the program name).
    pub fn parse(args: &[String]) -> Result<Command, UsageError> {
        match args.first().map(String::as_str) {
            Some("simulate") => parse_simulate(&args[1..]).map_err(|message| UsageError {
                message,
                usage: SIMULATE_USAGE,
            }),
            _ => parse_run(args).map_err(|message| UsageError {
                message,
                usage: USAGE,
            }),
        }
    }
}

/// Splits `--flag=value`; a flag's value is the inline one or the next argument.
struct Args<'a> {
    it: std::slice::Iter<'a, String>,
}

impl<'a> Args<'a> {
    /// The next flag and its inline value, if any.
    fn next_flag(&mut self) -> Option<(&'a str, Option<&'a str>)> {
        let a = self.it.next()?;
        Some(match a.split_once('=') {
            Some((f, v)) if f.starts_with("--") => (f, Some(v)),
            _ => (a.as_str(), None),
        })
    }

    /// The value of `flag`.
    fn value(&mut self, flag: &str, inline: Option<&'a str>) -> Result<&'a str, String> {
        inline
            .or_else(|| self.it.next().map(String::as_str))
            .ok_or_else(|| format!("{flag} needs a value"))
    }
}

fn parse_run(args: &[String]) -> Result<Command, String> {
    let mut opts = RunOptions::default();
    let mut args = Args { it: args.iter() };
    while let Some((flag, inline)) = args.next_flag() {
        match flag {
            "--analysis" => opts.analysis = Some(args.value(flag, inline)?.to_string()),
            "-o" | "--out" => opts.out_dir = PathBuf::from(args.value(flag, inline)?),
            "-q" | "--quiet" => opts.quiet = true,
            "--deny-unsafe" => opts.deny_unsafe = true,
            "--probability" => opts.probability = true,
            "--tighten" => opts.tighten = true,
            "--stage" => opts.stage = true,
            "--error-lines" => opts.error_lines = true,
            "-h" | "--help" => return Ok(Command::Help(USAGE)),
            other => return Err(format!("unexpected argument `{other}`")),
        }
    }
    Ok(Command::Run(opts))
}

fn parse_simulate(args: &[String]) -> Result<Command, String> {
    let mut a = SimulateOptions::default();
    let mut paths = None;
    let mut args = Args { it: args.iter() };
    while let Some((flag, inline)) = args.next_flag() {
        let mut value = || args.value(flag, inline);
        match flag {
            "--analysis" => a.analysis = Some(value()?.to_string()),
            "-o" | "--out" => a.out_dir = PathBuf::from(value()?),
            "-q" | "--quiet" => a.quiet = true,
            "--progress" => a.progress = true,
            "--error-lines" => a.error_lines = true,
            "--probability" => a.probability = true,
            "--paths" => paths = Some(number::<u64>(flag, value()?)?),
            "--seed" => a.sim.seed = number(flag, value()?)?,
            "--dt" => a.sim.dt = Some(number(flag, value()?)?),
            "--hold" => a.sim.hold = Some(number(flag, value()?)?),
            "--confidence" => a.sim.confidence = number(flag, value()?)?,
            "--delta" => {
                let d: f64 = number(flag, value()?)?;
                if !(d > 0.0 && d < 1.0) {
                    return Err(format!("--delta {d} must lie in (0, 1)"));
                }
                a.delta = Some(d);
            }
            "--shard" => a.shard = Some(Shard::parse(value()?).map_err(|e| e.to_string())?),
            "--spec-hash" => a.spec_hash = Some(value()?.to_string()),
            "--threads" => {
                let t: usize = number(flag, value()?)?;
                if t == 0 {
                    return Err("--threads must be at least 1".into());
                }
                a.sim.threads = Some(t);
            }
            "--inputs" => {
                let v = value()?;
                a.sim.inputs = InputMode::parse(v)
                    .ok_or_else(|| format!("--inputs `{v}`: expected random, corners or centre"))?;
            }
            "-h" | "--help" => return Ok(Command::Help(SIMULATE_USAGE)),
            other => return Err(format!("unexpected argument `{other}`")),
        }
    }
    a.sim.paths = paths.ok_or_else(|| "--paths N is required".to_string())?;
    Ok(Command::Simulate(a))
}

/// Parses a number given to `flag`.
fn number<T: std::str::FromStr>(flag: &str, v: &str) -> Result<T, String> {
    v.trim()
        .parse()
        .map_err(|_| format!("{flag}: `{v}` is not a valid number"))
}

impl RunOptions {
    /// The command line that [`Command::parse`] reads back as these options.
    pub fn to_args(&self) -> Vec<String> {
        let mut args = vec!["-o".to_string(), self.out_dir.display().to_string()];
        if let Some(name) = &self.analysis {
            args.extend(["--analysis".to_string(), name.clone()]);
        }
        for (on, flag) in [
            (self.quiet, "--quiet"),
            (self.deny_unsafe, "--deny-unsafe"),
            (self.probability, "--probability"),
            (self.tighten, "--tighten"),
            (self.stage, "--stage"),
            (self.error_lines, "--error-lines"),
        ] {
            if on {
                args.push(flag.into());
            }
        }
        args
    }
}

impl SimulateOptions {
    /// The command line (starting with `simulate`) that [`Command::parse`] reads back as these
    /// options. Numbers are written in Rust's shortest round-trip form, so they parse back to
    /// the same bits.
    pub fn to_args(&self) -> Vec<String> {
        let s = &self.sim;
        let mut args = vec!["simulate".to_string()];
        let mut opt = |flag: &str, v: Option<String>| {
            if let Some(v) = v {
                args.extend([flag.to_string(), v]);
            }
        };
        opt("--paths", Some(s.paths.to_string()));
        opt("--analysis", self.analysis.clone());
        opt("--seed", Some(s.seed.to_string()));
        opt("--dt", s.dt.map(|v| v.to_string()));
        opt("--delta", self.delta.map(|v| v.to_string()));
        opt("--inputs", Some(s.inputs.name().to_string()));
        opt("--hold", s.hold.map(|v| v.to_string()));
        opt("--confidence", Some(s.confidence.to_string()));
        opt("--threads", s.threads.map(|v| v.to_string()));
        opt("--shard", self.shard.map(|v| v.to_string()));
        opt("--spec-hash", self.spec_hash.clone());
        opt("-o", Some(self.out_dir.display().to_string()));
        if self.quiet {
            args.push("--quiet".into());
        }
        if self.progress {
            args.push("--progress".into());
        }
        if self.error_lines {
            args.push("--error-lines".into());
        }
        if self.probability {
            args.push("--probability".into());
        }
        args
    }
}

/// The `main` of a generated binary: parses `std::env::args`, see [`run_cli`]. Generic so that
/// the simulation's hot loop calls the generated model directly (no virtual calls).
pub fn main_with<M: Model>(model: &M) -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let code = run_cli(
        model,
        &args,
        &mut std::io::stdout().lock(),
        &mut std::io::stderr().lock(),
    );
    ExitCode::from(code)
}

/// Runs the command line `args` (without the program name), writing to `out` / `err`: parses
/// it ([`Command::parse`]) and calls [`run`] or [`simulate()`]. A usage error exits with
/// [`EXIT_USAGE`] after the help text.
pub fn run_cli<M: Model>(
    model: &M,
    args: &[String],
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> u8 {
    match Command::parse(args) {
        Ok(Command::Run(opts)) => run(model, &opts, out, err),
        Ok(Command::Simulate(opts)) => simulate(model, &opts, out, err, None),
        Ok(Command::Help(usage)) => {
            let _ = writeln!(out, "{usage}");
            EXIT_OK
        }
        Err(e) => {
            let _ = writeln!(err, "error: {}\n{}", e.message, e.usage);
            EXIT_USAGE
        }
    }
}

/// Where failed analyses are reported: to a caller's list, or to `err` (in prose, or as
/// [`Failure::to_line`] lines with `lines`).
struct Failures<'a> {
    collect: Option<&'a mut Vec<Failure>>,
    lines: bool,
    count: usize,
}

impl<'a> Failures<'a> {
    fn new(collect: Option<&'a mut Vec<Failure>>, lines: bool) -> Self {
        Failures {
            collect,
            lines,
            count: 0,
        }
    }

    fn report(&mut self, failure: Failure, err: &mut dyn Write) {
        self.count += 1;
        match &mut self.collect {
            Some(list) => list.push(failure),
            None if self.lines => {
                let _ = writeln!(err, "{}", failure.to_line());
            }
            None => {
                let _ = writeln!(err, "{failure}");
            }
        }
    }

    /// After the other analyses' files are written: whether any failed, printing how many
    /// (unless collected: the caller prints them, then [`Failure::summary`]).
    fn any(&self, of: usize, err: &mut dyn Write) -> bool {
        if self.count > 0 && self.collect.is_none() {
            let _ = writeln!(err, "{}", Failure::summary(self.count, of));
        }
        self.count > 0
    }
}

/// Runs the selected analyses, prints their summaries and writes `DIR/<analysis>.json` and
/// `.csv` for each that ran, all at the end (each file whole). Returns [`EXIT_OK`],
/// [`EXIT_FAILED`] if some analysis could not run or its result is not finite (reported on
/// `err`; the files of the others are written), [`EXIT_USAGE`] for an unknown analysis name or
/// files that cannot be written, [`EXIT_UNSAFE`] with `deny_unsafe` when a verdict is "not
/// shown safe" (and nothing failed). Analyses with an unsupported method are reported as
/// skipped, not as failures.
pub fn run<M: Model>(model: &M, opts: &RunOptions, out: &mut dyn Write, err: &mut dyn Write) -> u8 {
    run_analyses(model, opts, out, err, None)
}

/// [`run`], with the failed analyses added to `failures` instead of printed (the CLI's
/// interpreter backend locates them in the spec), [`Failure::summary`] included.
pub fn run_collecting<M: Model>(
    model: &M,
    opts: &RunOptions,
    out: &mut dyn Write,
    err: &mut dyn Write,
    failures: &mut Vec<Failure>,
) -> u8 {
    run_analyses(model, opts, out, err, Some(failures))
}

fn run_analyses<M: Model>(
    model: &M,
    opts: &RunOptions,
    out: &mut dyn Write,
    err: &mut dyn Write,
    collect: Option<&mut Vec<Failure>>,
) -> u8 {
    let info = model.info();
    let Some(selected) = select(info, opts.analysis.as_deref(), err) else {
        return EXIT_USAGE;
    };
    let mut failures = Failures::new(collect, opts.error_lines);
    let (mut files, mut not_safe) = (Files::new(), false);
    for &name in &selected {
        let ran = Reach::new(model, name).and_then(|r| r.run().map(|res| (r, res)));
        let (reach, res) = match ran {
            Ok(ran) => ran,
            Err(RunError::Unsupported(why)) => {
                let _ = writeln!(err, "skipped analysis `{name}`: {why}");
                continue;
            }
            Err(e) => {
                failures.report(Failure::run(name, &e), err);
                continue;
            }
        };
        // The probability of safety and of reaching each goal, where asked for and defined.
        let probability = (opts.probability && !info.unsafe_sets().is_empty())
            .then(|| reach.safety_probability());
        let goal_probabilities: Vec<_> = (0..info.goals().len())
            .filter(|_| opts.probability)
            .map(|g| reach.goal_probability(g))
            .collect();
        // The unsafe sets inflated for a nominal plan, where asked for.
        let tightening =
            (opts.tighten && !info.unsafe_sets().is_empty()).then(|| reach.tighten(&res, &[]));
        if !opts.quiet {
            let _ = write!(out, "{}", report::summary(&res));
            match &probability {
                Some(Ok(p)) => {
                    let _ = writeln!(
                        out,
                        "  {}",
                        report::probability::line(info.unsafe_sets(), p)
                    );
                }
                Some(Err(why)) => {
                    let _ = writeln!(out, "  {}", report::probability::not_computed(why));
                }
                None => {}
            }
            for (g, p) in goal_probabilities.iter().enumerate() {
                let _ = match p {
                    Ok(p) => writeln!(
                        out,
                        "  {}",
                        report::probability::goal_line(
                            info.goals(),
                            info.unsafe_sets(),
                            res.horizon(),
                            p
                        )
                    ),
                    Err(why) => writeln!(
                        out,
                        "  {}",
                        report::probability::goal_not_computed(&info.goals()[g], why)
                    ),
                };
            }
            match &tightening {
                Some(Ok(t)) => {
                    let _ = writeln!(out, "  {}", report::tightening::line(info.unsafe_sets(), t));
                }
                Some(Err(why)) => {
                    let _ = writeln!(out, "  {}", report::tightening::not_computed(why));
                }
                None => {}
            }
            let _ = writeln!(out);
        }
        let probability = probability.and_then(Result::ok);
        let goal_probabilities: Vec<_> = goal_probabilities.into_iter().flatten().collect();
        not_safe |= matches!(
            res.verdict(),
            reachc_core::prs::Verdict::NotShownSafe { .. }
        );
        let mut csv = Vec::new();
        // Writing into memory cannot fail.
        let _ = report::write_csv(&res, &mut csv);
        let dir = &opts.out_dir;
        files.add(
            dir.join(format!("{name}.json")),
            (report::to_json_with(
                &res,
                report::probability::Probabilities {
                    safety: probability.as_ref(),
                    goals: &goal_probabilities,
                },
            ) + "\n")
                .into(),
        );
        files.add(dir.join(format!("{name}.csv")), csv);
        if let Some(Ok(t)) = &tightening {
            let mut csv = Vec::new();
            let _ = report::tightening::write_csv(t, info.states(), &mut csv);
            files.add(dir.join(format!("{name}.tightening.csv")), csv);
        }
    }
    if let Err(code) = commit(files, !opts.quiet && !opts.stage, out, err) {
        return code;
    }
    if failures.any(selected.len(), err) {
        return EXIT_FAILED;
    }
    if opts.deny_unsafe && not_safe {
        let _ = writeln!(err, "error: not shown safe (--deny-unsafe)");
        return EXIT_UNSAFE;
    }
    EXIT_OK
}

/// Writes `files` whole or not at all, printing their names when `announce`; the exit code of
/// a failure ([`EXIT_USAGE`]: an I/O error).
pub fn commit(
    files: Files,
    announce: bool,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), u8> {
    match files.commit() {
        Ok(paths) => {
            if announce && !paths.is_empty() {
                let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
                let _ = writeln!(out, "wrote {}", names.join(", "));
            }
            Ok(())
        }
        Err(e) => {
            let _ = writeln!(err, "error: {e} (nothing written)");
            Err(EXIT_USAGE)
        }
    }
}

/// The names of the analyses to run: all, or the one named (`None` after reporting an unknown
/// name).
fn select<'a>(
    info: &'a ModelInfo,
    name: Option<&str>,
    err: &mut dyn Write,
) -> Option<Vec<&'a str>> {
    let names = info.analyses().iter().map(|a| a.spec.name.as_str());
    let Some(name) = name else {
        return Some(names.collect());
    };
    let found: Vec<&str> = names.clone().filter(|&a| a == name).collect();
    if found.is_empty() {
        let all: Vec<&str> = names.collect();
        let _ = writeln!(
            err,
            "error: model `{}` has no analysis `{name}` (available: {})",
            info.name(),
            all.join(", ")
        );
        return None;
    }
    Some(found)
}

/// What one analysis' simulation gave: the report, or a shard's part.
enum Simulated {
    Report(SimReport),
    Part(simulate::Part),
}

/// `time: ... s for ... path-steps (... path-steps/s, N threads)`.
fn timing(secs: f64, path_steps: f64, threads: usize) -> String {
    format!(
        "time: {secs:.3} s for {path_steps:.3e} path-steps ({:.3e} path-steps/s, {})",
        path_steps / secs,
        report::count(threads as u64, "thread")
    )
}

/// The file of a report: `DIR/<analysis>.sim.json` and its bytes (what `simulate` and
/// `reachc simulate merge` write).
pub fn report_file(dir: &std::path::Path, sim: &SimReport) -> (PathBuf, Vec<u8>) {
    (
        dir.join(format!("{}.sim.json", sim.analysis)),
        (report::simulation::to_json(sim) + "\n").into(),
    )
}

/// The name of a shard's part file: `<analysis>.shard-I-of-K.part`.
pub fn part_file_name(analysis: &str, shard: Shard) -> String {
    format!(
        "{analysis}.shard-{}-of-{}.part",
        shard.index(),
        shard.count()
    )
}

/// A progress callback: `(analysis, paths done, paths in all)`.
pub type Progress<'a> = dyn FnMut(&str, u64, u64) + 'a;

/// For each selected analysis: compute its PRS (at `opts.delta` if given), simulate the paths,
/// print the summary; at the end, write every `DIR/<analysis>.sim.json` (each whole).
/// Returns [`EXIT_OK`] when every coverage check passes, [`EXIT_FAILED`] when one fails (the
/// reports are written) or an analysis cannot run or be simulated (reported on `err`; the
/// other analyses' reports are written),
/// [`EXIT_USAGE`] for a usage error or files that cannot be written. Analyses without a PRS (no constants, unsupported
/// transform) are skipped with a message. `progress(analysis, done, total)` is called after each
/// batch of paths; without it, `opts.progress` writes `reachc-progress` lines to `err` instead.
/// With `opts.shard`, only that shard's paths run and `DIR/<analysis>.shard-I-of-K.part` is
/// written instead of each report ([`part_file_name`]; no verdict: [`EXIT_OK`] when written),
/// for [`crate::merge::merge_files`].
pub fn simulate<M: Model>(
    model: &M,
    opts: &SimulateOptions,
    out: &mut dyn Write,
    err: &mut dyn Write,
    progress: Option<&mut Progress<'_>>,
) -> u8 {
    simulate_analyses(model, opts, (out, err), progress, None)
}

/// [`simulate()`], with the failed analyses added to `failures` instead of printed (the CLI's
/// interpreter backend locates them in the spec), [`Failure::summary`] included.
pub fn simulate_collecting<M: Model>(
    model: &M,
    opts: &SimulateOptions,
    (out, err): (&mut dyn Write, &mut dyn Write),
    progress: Option<&mut Progress<'_>>,
    failures: &mut Vec<Failure>,
) -> u8 {
    simulate_analyses(model, opts, (out, err), progress, Some(failures))
}

fn simulate_analyses<M: Model>(
    model: &M,
    opts: &SimulateOptions,
    (out, err): (&mut dyn Write, &mut dyn Write),
    mut progress: Option<&mut Progress<'_>>,
    collect: Option<&mut Vec<Failure>>,
) -> u8 {
    let info = model.info();
    let Some(selected) = select(info, opts.analysis.as_deref(), err) else {
        return EXIT_USAGE;
    };
    let mut failures = Failures::new(collect, opts.error_lines);
    let (mut files, mut coverage_failed) = (Files::new(), false);
    for &name in &selected {
        let reach = Reach::new(model, name).and_then(|r| match opts.delta {
            Some(d) => r.with_delta(d),
            None => Ok(r),
        });
        // The certified probability of safety to test, where asked for and defined.
        let mut sim_opts = opts.sim.clone();
        let wanted = opts.probability && !info.unsafe_sets().is_empty();
        if let Some(reach) = reach.as_ref().ok().filter(|_| wanted) {
            match reach.safety_probability() {
                Ok(p) => sim_opts.safety_bound = p.lower_bound(),
                Err(e) => {
                    let _ = writeln!(
                        err,
                        "note: analysis `{name}`: no probability of safety: {e}"
                    );
                }
            }
        }
        // And of reaching each goal.
        if let Some(reach) = reach.as_ref().ok().filter(|_| opts.probability) {
            sim_opts.goal_bounds = (0..info.goals().len())
                .map(|g| match reach.goal_probability(g) {
                    Ok(p) => p.lower_bound(),
                    Err(e) => {
                        let _ = writeln!(
                            err,
                            "note: analysis `{name}`: no probability of reaching `{}`: {e}",
                            info.goals()[g].name
                        );
                        None
                    }
                })
                .collect();
        }
        let result = match reach.and_then(|r| r.run()) {
            Ok(r) => r,
            Err(e @ (RunError::Unsupported(_) | RunError::NoConstants(_))) => {
                let _ = writeln!(err, "skipped analysis `{name}`: no PRS to check ({e})");
                continue;
            }
            Err(e) => {
                failures.report(Failure::run(name, &e), err);
                continue;
            }
        };
        let started = std::time::Instant::now();
        let simulated = {
            let mut report_progress = |done: u64, total: u64| match progress.as_mut() {
                Some(f) => f(name, done, total),
                None if opts.progress => {
                    let _ = writeln!(err, "reachc-progress {name} {done} {total}");
                }
                None => {}
            };
            match opts.shard {
                Some(shard) => {
                    simulate::run_part(model, &result, &sim_opts, shard, &mut report_progress)
                        .map(Simulated::Part)
                }
                None => simulate::simulate(model, &result, &sim_opts, &mut report_progress)
                    .map(Simulated::Report),
            }
        };
        let simulated = match simulated {
            Ok(r) => r,
            Err(SimError::Usage(m)) => {
                let _ = writeln!(err, "error: {m}");
                return EXIT_USAGE;
            }
            Err(SimError::Invalid(m)) => {
                failures.report(Failure::simulation(name, &m), err);
                continue;
            }
        };
        let secs = started.elapsed().as_secs_f64();
        let threads = simulate::thread_count(opts.sim.threads);
        let dt = match &simulated {
            Simulated::Report(sim) => sim.dt,
            Simulated::Part(part) => part.run.dt,
        };
        if let Some(w) = report::simulation::dt_warning(&dt) {
            let _ = writeln!(err, "warning: analysis `{name}`: {w}");
        }
        match simulated {
            Simulated::Report(sim) => {
                if !opts.quiet {
                    let _ = write!(out, "{}", report::simulation::summary(&sim));
                    let path_steps = sim.paths as f64 * sim.steps_per_path as f64;
                    let _ = writeln!(out, "  {}\n", timing(secs, path_steps, threads));
                }
                coverage_failed |= !sim.passed();
                let (path, bytes) = report_file(&opts.out_dir, &sim);
                files.add(path, bytes);
            }
            Simulated::Part(mut part) => {
                part.run.spec_hash = opts.spec_hash.clone().unwrap_or_default();
                let paths = part.shard.paths(part.run.paths);
                if !opts.quiet {
                    let path_steps =
                        (paths.end - paths.start) as f64 * part.run.steps_per_path as f64;
                    let _ = writeln!(
                        out,
                        "simulated `{name}`, shard {}: paths {}..{} of {}\n  {}",
                        part.shard,
                        paths.start,
                        paths.end,
                        part.run.paths,
                        timing(secs, path_steps, threads)
                    );
                }
                files.add(
                    opts.out_dir.join(part_file_name(name, part.shard)),
                    part.to_bytes(),
                );
            }
        }
    }
    if let Err(code) = commit(files, !opts.quiet, out, err) {
        return code;
    }
    if failures.any(selected.len(), err) || coverage_failed {
        EXIT_FAILED
    } else {
        EXIT_OK
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strings(args: &[&str]) -> Vec<String> {
        args.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn options_round_trip_through_the_command_line() {
        let run = RunOptions {
            analysis: Some("contraction".into()),
            out_dir: PathBuf::from("some dir/out"),
            quiet: true,
            deny_unsafe: true,
            probability: true,
            tighten: true,
            stage: true,
            error_lines: true,
        };
        assert_eq!(Command::parse(&run.to_args()), Ok(Command::Run(run)));
        let sim = SimulateOptions {
            analysis: Some("a".into()),
            out_dir: PathBuf::from("o"),
            quiet: false,
            progress: true,
            delta: Some(0.1 + 0.2),
            shard: Some(Shard::new(3, 8).unwrap()),
            spec_hash: Some("0a1b".into()),
            error_lines: true,
            probability: true,
            sim: simulate::Options {
                paths: 12345,
                seed: u64::MAX,
                dt: Some(1e-3 / 3.0),
                inputs: InputMode::Corners,
                hold: Some(0.7),
                confidence: 0.99,
                threads: Some(3),
                safety_bound: None,
                goal_bounds: Vec::new(),
            },
        };
        assert_eq!(Command::parse(&sim.to_args()), Ok(Command::Simulate(sim)));
    }

    #[test]
    fn usage_errors_name_the_problem() {
        let e = Command::parse(&strings(&["simulate", "--seed", "1"])).unwrap_err();
        assert_eq!(e.message, "--paths N is required");
        let e = Command::parse(&strings(&["simulate", "--paths", "9", "--shard", "4/4"]));
        assert_eq!(
            e.unwrap_err().message,
            "shard 4/4: the index must be below the number of shards (0-based)"
        );
        let e = Command::parse(&strings(&["--out"])).unwrap_err();
        assert_eq!(e.message, "--out needs a value");
        assert_eq!(
            Command::parse(&strings(&["--help"])),
            Ok(Command::Help(USAGE))
        );
    }
}
