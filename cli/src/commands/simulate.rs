//! `reachc simulate`: Monte Carlo check of the spec's delta-PRS analyses (Euler-Maruyama sample
//! paths, `reachc_runtime::simulate`), with the compiled backend (the generated binary's
//! `simulate` mode) or the interpreter. On a terminal, a progress bar follows the paths.

use std::io::{BufRead, BufReader, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use std::fmt::Write as FmtWrite;

use indicatif::{MultiProgress, ProgressBar, ProgressState, ProgressStyle};

use super::failures::Locator;
use super::run::{compiled_binary, exit_code, interpreter, Backend};
use super::{load_reporting, EXIT_SPEC, EXIT_USAGE};
use reachc_runtime::app::{SimulateOptions, DEFAULT_OUT_DIR};
use reachc_runtime::simulate::{self, InputMode, Shard};

/// `reachc simulate SPEC ...`, or `reachc simulate merge PART...`.
#[derive(clap::Args, Debug)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct SimulateCommand {
    /// Merge the parts of a sharded run instead.
    #[command(subcommand)]
    pub merge: Option<MergeCommand>,
    /// The .sde spec.
    #[arg(required = true)]
    pub spec: Option<PathBuf>,
    /// What to simulate and how.
    #[command(flatten)]
    pub sim: SimulateArgs,
    /// Generated and compiled code, or the IR interpreter (no cargo needed).
    #[arg(long, value_enum, default_value = "compiled")]
    pub backend: Backend,
    /// Directory for ANALYSIS.sim.json, or the parts with --shard (default: reachc-out).
    #[arg(short, long)]
    pub out: Option<PathBuf>,
}

/// The subcommand of `reachc simulate`.
#[derive(clap::Subcommand, Debug)]
pub enum MergeCommand {
    /// Merge the part files of a sharded run (`reachc simulate SPEC --shard I/K`, every I) into
    /// the ANALYSIS.sim.json an unsharded run writes, byte for byte. Exit code 1 when a coverage
    /// check fails, 2 when the parts do not belong together, one is missing, repeated,
    /// unreadable or not a part file (nothing is written then).
    Merge {
        /// The part files (ANALYSIS.shard-I-of-K.part), of one or more analyses.
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// Directory for ANALYSIS.sim.json (default: reachc-out).
        #[arg(short, long)]
        out: Option<PathBuf>,
        /// Do not print the summaries.
        #[arg(short, long)]
        quiet: bool,
    },
}

/// The options passed on to the simulation (the runtime's `simulate` command line).
#[derive(clap::Args, Debug)]
pub struct SimulateArgs {
    /// Check only this analysis (default: all).
    #[arg(long)]
    pub analysis: Option<String>,
    /// Number of sample paths (of all shards).
    #[arg(long, required = true)]
    pub paths: Option<u64>,
    /// Run only shard I of K (0-based): the paths [floor(I N / K), floor((I + 1) N / K)), the
    /// same as in an unsharded run; writes OUT/ANALYSIS.shard-I-of-K.part instead of reports.
    #[arg(long, value_name = "I/K", value_parser = Shard::parse)]
    pub shard: Option<Shard>,
    /// Random seed; the same seed gives the same results, whatever the number of threads.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Largest Euler-Maruyama step (default: chosen per report interval from the drift's
    /// Jacobian over the analysis' sets, h L <= 0.05, at most 100 steps per report interval).
    #[arg(long)]
    pub dt: Option<f64>,
    /// Recompute the PRS at this delta instead of the analysis' own.
    #[arg(long)]
    pub delta: Option<f64>,
    /// Inputs: uniform in the box, random corners (both piecewise constant), or the centre.
    #[arg(long, value_enum, default_value = "random")]
    pub inputs: Inputs,
    /// Hold time of piecewise-constant inputs (default: the analysis' step).
    #[arg(long)]
    pub hold: Option<f64>,
    /// Confidence level of the Clopper-Pearson bounds and of the coverage check.
    #[arg(long, default_value_t = 0.999)]
    pub confidence: f64,
    /// Worker threads (default: all cores); the results do not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Also certify each analysis' probability of safety on [0, T] (unsafe sets, uniform
    /// guarantee; about a dozen runs) and check it against the paths that entered no unsafe set.
    #[arg(long)]
    pub probability: bool,
    /// Do not print the summaries (nor cargo's progress).
    #[arg(short, long)]
    pub quiet: bool,
}

/// How the paths' inputs are drawn ([`InputMode`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Inputs {
    /// Uniform in the input box, piecewise constant.
    Random,
    /// A random corner of the input box, piecewise constant.
    Corners,
    /// The centre of the input box.
    #[value(alias = "center")]
    Centre,
}

impl SimulateArgs {
    /// The runtime's options for these arguments, writing to `out`, for the spec whose source
    /// has the SHA-256 `spec_hash`.
    fn options(&self, out: Option<PathBuf>, spec_hash: String) -> SimulateOptions {
        let inputs = match self.inputs {
            Inputs::Random => InputMode::Random,
            Inputs::Corners => InputMode::Corners,
            Inputs::Centre => InputMode::Centre,
        };
        SimulateOptions {
            analysis: self.analysis.clone(),
            out_dir: out.unwrap_or_else(|| PathBuf::from(DEFAULT_OUT_DIR)),
            quiet: self.quiet,
            progress: false,
            delta: self.delta,
            shard: self.shard,
            spec_hash: self.shard.map(|_| spec_hash),
            // Set for the compiled backend (the interpreter's failures are typed).
            error_lines: false,
            probability: self.probability,
            sim: simulate::Options {
                // Required by clap unless merging.
                paths: self.paths.unwrap_or_default(),
                seed: self.seed,
                dt: self.dt,
                inputs,
                hold: self.hold,
                confidence: self.confidence,
                threads: self.threads,
                safety_bound: None,
                goal_bounds: Vec::new(),
            },
        }
    }
}

/// Paths per second, three significant digits with an SI prefix: `17.3 M paths/s` (indicatif's
/// own `{per_sec}` prints `17,297,925.3962/s`).
fn rate(per_sec: f64) -> String {
    let (v, prefix) = [(1e9, "G "), (1e6, "M "), (1e3, "k ")]
        .into_iter()
        .find(|&(scale, _)| per_sec >= scale)
        .map_or((per_sec, ""), |(scale, p)| (per_sec / scale, p));
    let decimals = if v >= 100.0 {
        0
    } else if v >= 10.0 {
        1
    } else {
        2
    };
    format!("{v:.decimals$} {prefix}paths/s")
}

/// One progress bar per analysis, under a [`MultiProgress`] that also prints other output.
struct Bars {
    multi: MultiProgress,
    current: Option<(String, ProgressBar)>,
    /// The shard simulated, if any (named in the bars' messages).
    shard: Option<Shard>,
}

impl Bars {
    fn new(shard: Option<Shard>) -> Self {
        Bars {
            multi: MultiProgress::new(),
            current: None,
            shard,
        }
    }

    /// `done` of `total` paths of `analysis`; the bar disappears when they are all done (so
    /// the summary that follows is not interleaved with it).
    fn update(&mut self, analysis: &str, done: u64, total: u64) {
        if self.current.as_ref().is_none_or(|(a, _)| a != analysis) {
            let bar = self.multi.add(ProgressBar::new(total));
            // A fixed template: cannot fail to parse.
            if let Ok(style) = ProgressStyle::with_template(
                "{msg} [{bar:40}] {pos}/{len} paths, {rate}, eta {eta}",
            ) {
                let style = style.with_key("rate", |s: &ProgressState, w: &mut dyn FmtWrite| {
                    let _ = w.write_str(&rate(s.per_sec()));
                });
                bar.set_style(style.progress_chars("=> "));
            }
            let shard = self
                .shard
                .map(|s| format!(", shard {s}"))
                .unwrap_or_default();
            bar.set_message(format!("simulating `{analysis}`{shard}"));
            self.current = Some((analysis.to_string(), bar));
        }
        if let Some((_, bar)) = &self.current {
            bar.set_position(done);
            if done >= total {
                bar.finish_and_clear();
                self.current = None;
            }
        }
    }
}

/// Runs `reachc simulate` or `reachc simulate merge`.
pub fn run_command(cmd: SimulateCommand) -> Result<(), u8> {
    match (cmd.merge, cmd.spec) {
        (Some(MergeCommand::Merge { parts, out, quiet }), _) => {
            let out = out.unwrap_or_else(|| PathBuf::from(DEFAULT_OUT_DIR));
            let code = reachc_runtime::merge::merge_files(
                &parts,
                &out,
                quiet,
                &mut std::io::stdout().lock(),
                &mut std::io::stderr().lock(),
            );
            spec_exit(code)
        }
        (None, Some(spec)) => run_simulate(&spec, &cmd.sim, cmd.backend, cmd.out),
        // clap requires the spec without a subcommand.
        (None, None) => Err(EXIT_USAGE),
    }
}

/// The CLI's result for a runtime exit code (1, a failed check, is the CLI's spec-error code).
fn spec_exit(code: u8) -> Result<(), u8> {
    match code {
        0 => Ok(()),
        1 => Err(EXIT_SPEC),
        c => Err(c),
    }
}

/// Runs `reachc simulate`. Exit codes: 0 every coverage check passed (or, with a shard, its
/// part was written), 1 one failed (or spec errors, or an analysis that could not run: each
/// located in the spec, the others' reports written), 2 usage, I/O or cargo failures.
pub fn run_simulate(
    spec: &Path,
    sim: &SimulateArgs,
    backend: Backend,
    out: Option<PathBuf>,
) -> Result<(), u8> {
    let color = std::io::stderr().is_terminal();
    let show_bar = std::io::stderr().is_terminal();
    let mut loaded = load_reporting(spec)?;
    let locator = Locator::new(&loaded, color);
    let mut opts = sim.options(out, loaded.source_hash());
    let code = match backend {
        Backend::Interp => {
            let interp = interpreter(loaded, color);
            let mut bars = Bars::new(opts.shard);
            let mut progress = |a: &str, done: u64, total: u64| bars.update(a, done, total);
            let mut failures = Vec::new();
            let code = reachc_runtime::app::simulate_collecting(
                &interp,
                &opts,
                (&mut std::io::stdout().lock(), &mut std::io::stderr().lock()),
                show_bar.then_some(&mut progress as &mut dyn FnMut(&str, u64, u64)),
                &mut failures,
            );
            locator.print_collected(&failures, opts.analysis.as_deref());
            code
        }
        Backend::Compiled => {
            let binary = compiled_binary(&mut loaded, color, sim.quiet)?;
            // With a bar, the binary's `reachc-progress` lines drive it; its failures come as
            // `reachc-failure` lines, located here.
            opts.progress = show_bar;
            opts.error_lines = true;
            run_binary(&binary, &opts.to_args(), (show_bar, opts.shard), &locator)?
        }
    };
    spec_exit(code)
}

/// Runs the generated binary's `simulate` mode (of `shard`, if any); its failure lines are
/// located by `locator`; with a bar, its `reachc-progress` lines drive the bar and its other
/// output is printed around it.
fn run_binary(
    binary: &Path,
    args: &[String],
    (show_bar, shard): (bool, Option<Shard>),
    locator: &Locator,
) -> Result<u8, u8> {
    let cannot_run = |e: std::io::Error| {
        eprintln!("error: cannot run {}: {e}", binary.display());
        EXIT_USAGE
    };
    let mut cmd = Command::new(binary);
    cmd.args(args);
    if !show_bar {
        let mut child = cmd.stderr(Stdio::piped()).spawn().map_err(cannot_run)?;
        if let Some(stderr) = child.stderr.take() {
            locator.forward(stderr);
        }
        let status = child.wait().map_err(cannot_run)?;
        return Ok(exit_code(status));
    }
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(cannot_run)?;
    let mut bars = Bars::new(shard);
    let (stdout, stderr) = (child.stdout.take(), child.stderr.take());
    std::thread::scope(|scope| {
        // The summaries go to stdout: print them above the bar, from their own thread so that
        // neither pipe can fill up and block the child.
        let multi = bars.multi.clone();
        scope.spawn(move || {
            for line in stdout.into_iter().flat_map(|s| BufReader::new(s).lines()) {
                let Ok(line) = line else { break };
                multi.suspend(|| {
                    let _ = writeln!(std::io::stdout().lock(), "{line}");
                });
            }
        });
        for line in stderr.into_iter().flat_map(|s| BufReader::new(s).lines()) {
            let Ok(line) = line else { break };
            match parse_progress(&line) {
                Some((analysis, done, total)) => bars.update(analysis, done, total),
                None => bars.multi.suspend(|| eprint!("{}", locator.line(&line))),
            }
        }
    });
    let status = child.wait().map_err(cannot_run)?;
    Ok(exit_code(status))
}

/// `reachc-progress ANALYSIS DONE TOTAL` (analysis names are identifiers: no spaces).
fn parse_progress(line: &str) -> Option<(&str, u64, u64)> {
    let mut words = line.strip_prefix("reachc-progress ")?.split(' ');
    let (a, d, t) = (words.next()?, words.next()?, words.next()?);
    Some((a, d.parse().ok()?, t.parse().ok()?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_print_three_significant_digits() {
        assert_eq!(rate(17_297_925.396_2), "17.3 M paths/s");
        assert_eq!(rate(1_234.5), "1.23 k paths/s");
        assert_eq!(rate(999.0), "999 paths/s");
        assert_eq!(rate(2.5e9), "2.50 G paths/s");
    }

    #[test]
    fn progress_lines_parse() {
        assert_eq!(
            parse_progress("reachc-progress amgf_rule 65536 100000"),
            Some(("amgf_rule", 65536, 100000))
        );
        assert_eq!(parse_progress("skipped analysis `x`"), None);
        assert_eq!(parse_progress("reachc-progress a b c"), None);
    }
}
