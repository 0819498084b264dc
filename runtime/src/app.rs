//! The `main` of generated crates' binaries: run the model's analyses, print summaries, write
//! JSON and CSV results.
//!
//! Arguments are parsed by hand (no clap) so the runtime stays light:
//! `[--analysis NAME] [-o DIR] [--quiet]`.

use crate::engine::{self, RunError};
use crate::system::{ModelInfo, System};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// Default output directory.
pub const DEFAULT_OUT_DIR: &str = "reachc-out";

const USAGE: &str = "usage: <model> [--analysis NAME] [-o DIR] [--quiet]
  --analysis NAME  run only this analysis (default: all)
  -o, --out DIR    output directory for <analysis>.json and <analysis>.csv (default: reachc-out)
  -q, --quiet      do not print the summaries
  -h, --help       print this help";

/// Exit status of a successful run.
pub const EXIT_OK: u8 = 0;
/// Exit status when an analysis could not run (or its results could not be written).
pub const EXIT_FAILED: u8 = 1;
/// Exit status of a usage error.
pub const EXIT_USAGE: u8 = 2;

/// The `main` of a generated binary: parses `std::env::args`, see [`run_cli`].
pub fn main_with(sys: &dyn System, info: &ModelInfo) -> ExitCode {
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
/// Analyses with an unsupported method are reported as skipped, not as failures.
pub fn run_cli(
    sys: &dyn System,
    info: &ModelInfo,
    args: &[String],
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> u8 {
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
    let selected: Vec<_> = match &opts.analysis {
        None => info.analyses.iter().collect(),
        Some(name) => {
            let found: Vec<_> = info.analyses.iter().filter(|a| &a.name == name).collect();
            if found.is_empty() {
                let names: Vec<&str> = info.analyses.iter().map(|a| a.name.as_str()).collect();
                let _ = writeln!(
                    err,
                    "error: model `{}` has no analysis `{name}` (available: {})",
                    info.name,
                    names.join(", ")
                );
                return EXIT_USAGE;
            }
            found
        }
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
