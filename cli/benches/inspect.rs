//! `reachc inspect` on the 1000-state chain: load (parse, check, unroll), differentiate,
//! bound every Jacobian entry, and print the JSON. Run with `cargo bench -p reachc`.

use std::path::PathBuf;

fn chain1000() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../specs/chain1000.sde")
}

fn main() {
    divan::main();
}

/// Parse and check only.
#[divan::bench(sample_count = 20)]
fn load_chain1000() -> reachc_compiler::model::Model {
    reachc_compiler::driver::load(&chain1000()).unwrap().model
}

/// Everything `reachc inspect --json` does after reading the file.
#[divan::bench(sample_count = 20)]
fn inspect_json_chain1000() -> usize {
    let mut model = reachc_compiler::driver::load(&chain1000()).unwrap().model;
    let mut out = Vec::new();
    reachc::commands::inspect::json(&mut model, &mut out).unwrap();
    out.len()
}

/// The text report.
#[divan::bench(sample_count = 20)]
fn inspect_text_chain1000() -> usize {
    let mut model = reachc_compiler::driver::load(&chain1000()).unwrap().model;
    let mut out = Vec::new();
    reachc::commands::inspect::text(&mut model, &mut out).unwrap();
    out.len()
}
