//! The long fuzz campaign (docs/fuzzing.md): mutants of the seed corpus through `reachc
//! check`, then through `reachc run --backend interp`, each under its time and memory budget;
//! prints the outcome counts and rates, and saves one minimised reproducer per failure class.
//!
//! `cargo run --release -p reachc-e2e --example fuzz -- [--check N] [--run N] [--threads N]
//! [--seed N] [--findings DIR] [--minimise N] [--failures DIR]` (defaults: 10000, 1000, 2, 15,
//! tests/fuzz/findings, 150 runs per reproducer; with `--failures`, every failing mutant is
//! also written there, unminimised, as COMMAND-INDEX-CLASS.sde, for triage, and the
//! reproducers go there too unless `--findings` says otherwise: a triage run leaves the
//! repository's findings as they are).

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use reachc_e2e::fuzz::campaign::{
    counts, run_campaign, run_one, Command, Corpus, Plan, Record, Scratch,
};
use reachc_e2e::fuzz::minimise::minimise;

fn main() {
    let mut opts: BTreeMap<String, String> = BTreeMap::new();
    let args: Vec<String> = std::env::args().skip(1).collect();
    for pair in args.chunks(2) {
        let [key, value] = pair else {
            panic!(
                "options come in pairs: --check N --run N --threads N --seed N --findings DIR .."
            );
        };
        opts.insert(key.trim_start_matches("--").to_string(), value.clone());
    }
    let num = |key: &str, default: u64| {
        opts.get(key)
            .map_or(default, |v| v.parse().expect("a number"))
    };
    let findings = match (opts.get("findings"), opts.get("failures")) {
        (Some(dir), _) | (None, Some(dir)) => PathBuf::from(dir),
        (None, None) => reachc_e2e::workspace().join("tests/fuzz/findings"),
    };
    let corpus = Corpus::load();
    let mut records = Vec::new();
    println!("| command | mutants | wall s | mutants/s |");
    println!("|---|---|---|---|");
    for (command, n) in [
        (Command::Check, num("check", 10_000)),
        (Command::Run, num("run", 1000)),
    ] {
        let plan = Plan {
            seed: num("seed", 15),
            check: if command == Command::Check { n } else { 0 },
            run: if command == Command::Run { n } else { 0 },
            threads: num("threads", 2) as usize,
        };
        let start = Instant::now();
        let progress = |done: usize, total: usize| {
            if done.is_multiple_of(500) || done == total {
                eprintln!(
                    "{}: {done}/{total} ({:.0} s)",
                    command.name(),
                    start.elapsed().as_secs_f64()
                );
            }
        };
        let batch = run_campaign(&plan, &corpus, &progress);
        let wall = start.elapsed().as_secs_f64();
        println!(
            "| {} | {n} | {wall:.1} | {:.1} |",
            command.name(),
            n as f64 / wall
        );
        records.extend(batch);
    }
    println!("\n| command | outcome | count |\n|---|---|---|");
    for ((command, outcome), n) in counts(&records) {
        println!("| {} | {} | {n} |", command.name(), outcome.name());
    }
    if let Some(dir) = opts.get("failures") {
        std::fs::create_dir_all(dir).expect("the failures folder can be created");
        for r in records.iter().filter(|r| r.outcome.is_failure()) {
            let name = format!("{}-{}-{}.sde", r.command.name(), r.index, r.outcome.name());
            std::fs::write(PathBuf::from(dir).join(name), &r.bytes).expect("writable");
        }
    }
    save_findings(&records, &findings, num("minimise", 150) as usize);
}

/// Minimises the first failure of each (command, class) and writes it to `dir`; prints a
/// README line for each.
fn save_findings(records: &[Record], dir: &std::path::Path, runs: usize) {
    let mut seen = std::collections::BTreeSet::new();
    let scratch = Scratch::new("fuzz-minimise");
    std::fs::create_dir_all(dir).expect("the findings folder can be created");
    println!("\n| reproducer | command | outcome | from |\n|---|---|---|---|");
    for r in records.iter().filter(|r| r.outcome.is_failure()) {
        if !seen.insert((r.command, r.outcome.clone())) {
            continue;
        }
        let mut fails = |bytes: &[u8]| run_one(r.command, bytes, &scratch.0).0 == r.outcome;
        let small = minimise(&r.bytes, runs, &mut fails);
        let file = format!("{}-{}.sde", r.command.name(), r.outcome.name());
        std::fs::write(dir.join(&file), &small).expect("the findings folder is writable");
        let args = match r.command {
            Command::Check => "check",
            Command::Run => "run --backend interp",
        };
        println!(
            "| {file} | `reachc {args} {file}` | {} | {} mutant {} |",
            r.outcome.name(),
            r.seed,
            r.index
        );
    }
}
