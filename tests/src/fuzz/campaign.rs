//! A campaign: mutants of the seed corpus through `reachc check` and `reachc run --backend
//! interp`, on a few threads, each input under its [`Budget`]; the outcome of every input.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Duration;

use proptest::strategy::{Strategy, ValueTree};
use proptest::test_runner::{Config as RunnerConfig, RngAlgorithm, TestRng, TestRunner};

use super::classify::{classify, Outcome};
use super::exec::{self, reachc_binary, Budget};
use super::mutate::{mutant, valid_mutant, Mutant};
/// A scratch folder per worker (`fuzz-...`), removed on drop.
pub use reachc_test_support::files::Scratch;

/// Seeds whose own `run` takes seconds: their mutants go through `check` only, so a timeout of
/// `run` means the mutation made it slow. (`vanderpol.sde` runs 2 x 64 pieces of its initial
/// box: about 9 s of CPU in the debug build, near the budget.)
const SLOW_TO_RUN: &[&str] = &[
    "chain1000.sde",
    "unicycle.sde",
    "unicycle_lookahead.sde",
    "vanderpol.sde",
];

/// The seed corpus: `tests/fuzz/corpus/`, the shipped specs, `tests/good/` and `tests/bad/`.
pub struct Corpus {
    /// Each seed's path relative to the workspace.
    pub names: Vec<String>,
    /// Each seed's text, with `csv("..")` paths made absolute so mutants load their tables
    /// from anywhere.
    pub texts: Vec<String>,
}

impl Corpus {
    /// Reads the corpus from the workspace.
    pub fn load() -> Corpus {
        let (mut names, mut texts) = (Vec::new(), Vec::new());
        for dir in ["tests/fuzz/corpus", "specs", "tests/good", "tests/bad"] {
            for path in crate::specs_in(dir) {
                // Invalid UTF-8 seeds (tests/bad/not_utf8.sde) are left to the byte mutations.
                let Ok(text) = std::fs::read_to_string(&path) else {
                    continue;
                };
                texts.push(absolute_tables(
                    &text,
                    path.parent().expect("a file in a folder"),
                ));
                names.push(crate::relative(&path));
            }
        }
        Corpus { names, texts }
    }

    /// Indices of the seeds whose mutants `command` runs. For `check`, the valid seeds count
    /// twice, so about half the mutants start from a spec that checks (two thirds of the
    /// files are bad specs).
    pub fn seeds_for(&self, command: Command) -> Vec<usize> {
        let bad = |i: usize| self.names[i].starts_with("tests/bad/");
        let valid = (0..self.names.len()).filter(|&i| !bad(i));
        match command {
            Command::Check => (0..self.names.len()).chain(valid).collect(),
            Command::Run => valid
                .filter(|&i| !SLOW_TO_RUN.iter().any(|s| self.names[i].ends_with(s)))
                .collect(),
        }
    }
}

/// `text` with every `csv("PATH")` relative to `dir` made absolute.
fn absolute_tables(text: &str, dir: &Path) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(i) = rest.find("csv(\"") {
        let (head, tail) = rest.split_at(i + 5);
        out.push_str(head);
        let end = tail.find('"').unwrap_or(tail.len());
        let path = dir.join(&tail[..end]);
        out.push_str(
            &path
                .to_string_lossy()
                .replace('\\', "\\\\")
                .replace('"', "\\\""),
        );
        rest = &tail[end..];
    }
    out + rest
}

/// The command a mutant goes through.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Command {
    /// `reachc check SPEC`.
    Check,
    /// `reachc run --backend interp SPEC -o OUT`.
    Run,
}

impl Command {
    /// The command's name.
    pub fn name(self) -> &'static str {
        match self {
            Command::Check => "check",
            Command::Run => "run",
        }
    }

    /// The arguments of `reachc` for `spec`, writing results under `out`.
    pub fn args(self, spec: &Path, out: &Path) -> Vec<std::ffi::OsString> {
        match self {
            Command::Check => vec!["check".into(), spec.into()],
            Command::Run => vec![
                "run".into(),
                "--backend".into(),
                "interp".into(),
                spec.into(),
                "-o".into(),
                out.into(),
            ],
        }
    }

    /// The budget of one input.
    pub fn budget(self) -> Budget {
        match self {
            Command::Check => Budget::CHECK,
            Command::Run => Budget::RUN,
        }
    }
}

/// Mutant `index` for `command` of the campaign with seed `seed`: drawn by proptest from a
/// generator seeded with all three, so any one mutant can be drawn again alone.
pub fn mutant_at(command: Command, seed: u64, index: u64) -> Mutant {
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    bytes[8..16].copy_from_slice(&index.to_le_bytes());
    bytes[16] = command as u8;
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &bytes);
    let mut runner = TestRunner::new_with_rng(RunnerConfig::default(), rng);
    let tree = match command {
        Command::Check => mutant().new_tree(&mut runner).map(|t| t.current()),
        Command::Run => valid_mutant().new_tree(&mut runner).map(|t| t.current()),
    };
    tree.expect("the mutant strategies never reject")
}

/// One input of a campaign and what became of it.
#[derive(Clone, Debug)]
pub struct Record {
    /// The command.
    pub command: Command,
    /// The mutant's index (see [`mutant_at`]).
    pub index: u64,
    /// The seed it was made from (relative path).
    pub seed: String,
    /// Its bytes.
    pub bytes: Vec<u8>,
    /// Its outcome.
    pub outcome: Outcome,
    /// The first lines of its standard error.
    pub stderr_head: String,
    /// Wall-clock time.
    pub elapsed: Duration,
}

/// What a campaign runs.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The campaign's seed.
    pub seed: u64,
    /// How many mutants go through `check`.
    pub check: u64,
    /// How many mutants go through `run --backend interp`.
    pub run: u64,
    /// Worker threads.
    pub threads: usize,
}

/// Runs `bytes` as a spec through `command` in `dir` (for `run`, `check` first: an exit 1 of
/// `run` needs a located diagnostic only when the spec does not check). Returns the outcome,
/// the first lines of stderr and the time taken.
pub fn run_one(command: Command, bytes: &[u8], dir: &Path) -> (Outcome, String, Duration) {
    let spec = dir.join("mutant.sde");
    let out = dir.join("out");
    let _ = std::fs::remove_dir_all(&out);
    std::fs::write(&spec, bytes).expect("the scratch folder is writable");
    // A run's exit 1 is the spec's fault only when check rejects the spec too.
    let spec_error = match command {
        Command::Check => true,
        Command::Run => execute(Command::Check, &spec, &out, dir).1 != Outcome::Accepted,
    };
    let (exit, outcome) = execute(command, &spec, &out, dir);
    let outcome = match (outcome, spec_error) {
        (Outcome::AnalysisError, true) => classify(&exit, true),
        (o, _) => o,
    };
    let head: String = exit.stderr.lines().take(12).collect::<Vec<_>>().join("\n");
    (outcome, head, exit.elapsed)
}

/// Runs `command` on `spec` once; its exit, classified as if exit 1 were an analysis error.
fn execute(command: Command, spec: &Path, out: &Path, dir: &Path) -> (exec::Exit, Outcome) {
    let mut cmd = std::process::Command::new(reachc_binary());
    cmd.args(command.args(spec, out))
        .current_dir(dir)
        // The campaign's threads already use the cores.
        .env("RAYON_NUM_THREADS", "1");
    let exit =
        exec::run(cmd, &command.budget(), &dir.join("stderr.txt")).expect("reachc can be started");
    let outcome = match command {
        Command::Check => classify(&exit, true),
        Command::Run => classify(&exit, false),
    };
    (exit, outcome)
}

/// Runs the campaign `plan` over `corpus`; `progress` is called after each input with the
/// number done and the total. Records come back in job order (check mutants, then run).
pub fn run_campaign(
    plan: &Plan,
    corpus: &Corpus,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Vec<Record> {
    let jobs: Vec<(Command, u64)> = (0..plan.check)
        .map(|i| (Command::Check, i))
        .chain((0..plan.run).map(|i| (Command::Run, i)))
        .collect();
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let records = Mutex::new(Vec::with_capacity(jobs.len()));
    let seeds = [Command::Check, Command::Run].map(|c| corpus.seeds_for(c));
    std::thread::scope(|s| {
        for worker in 0..plan.threads.max(1) {
            let (jobs, next, done, records, seeds) = (&jobs, &next, &done, &records, &seeds);
            s.spawn(move || {
                let scratch = Scratch::new(&format!("fuzz-w{worker}"));
                while let Some(&(command, index)) = jobs.get(next.fetch_add(1, Ordering::Relaxed)) {
                    let m = mutant_at(command, plan.seed, index);
                    let candidates = &seeds[usize::from(command == Command::Run)];
                    let seed = candidates[m.seed.of(candidates.len())];
                    let bytes = m.apply(seed, &corpus.texts);
                    let (outcome, stderr_head, elapsed) = run_one(command, &bytes, &scratch.0);
                    let record = Record {
                        command,
                        index,
                        seed: corpus.names[seed].clone(),
                        bytes,
                        outcome,
                        stderr_head,
                        elapsed,
                    };
                    records.lock().expect("no worker panics").push(record);
                    progress(done.fetch_add(1, Ordering::Relaxed) + 1, jobs.len());
                }
            });
        }
    });
    let mut records = records.into_inner().expect("no worker panicked");
    records.sort_by_key(|r| (r.command, r.index));
    records
}

/// Outcome counts per command.
pub fn counts(records: &[Record]) -> BTreeMap<(Command, Outcome), usize> {
    let mut counts = BTreeMap::new();
    for r in records {
        *counts.entry((r.command, r.outcome.clone())).or_insert(0) += 1;
    }
    counts
}
