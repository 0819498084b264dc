//! `reachc simulate merge`: the part files of a sharded simulation (`simulate --shard I/K`)
//! into the reports an unsharded run writes, byte for byte (`DIR/<analysis>.sim.json`).
//!
//! Parts are read one at a time and grouped by analysis; each group must be every shard of one
//! run ([`Merger`]); all parts must come from the same spec. Any problem (a file that cannot be
//! read, is not a part, is truncated or corrupt, a part of another run, a shard missing or
//! repeated) is an input error ([`EXIT_USAGE`]) naming the files, and nothing is written.

use crate::app::{commit, report_file, EXIT_FAILED, EXIT_OK, EXIT_USAGE};
use crate::output::Files;
use crate::report;
use reachc_core::simulate::{Merger, Part, SimReport};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Merges the part files `parts` into `out_dir/<analysis>.sim.json` (whole or not at all),
/// printing each report's summary unless `quiet`. Returns [`EXIT_OK`], [`EXIT_FAILED`] when a
/// coverage check fails (the reports are written), [`EXIT_USAGE`] for bad parts or files that
/// cannot be read or written.
pub fn merge_files(
    parts: &[PathBuf],
    out_dir: &Path,
    quiet: bool,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> u8 {
    match merge_reports(parts) {
        Ok(reports) => {
            let mut files = Files::new();
            let mut coverage_failed = false;
            for sim in &reports {
                if !quiet {
                    let _ = writeln!(out, "{}", report::simulation::summary(sim));
                }
                coverage_failed |= !sim.passed();
                let (path, bytes) = report_file(out_dir, sim);
                files.add(path, bytes);
            }
            if let Err(code) = commit(files, !quiet, out, err) {
                return code;
            }
            if coverage_failed {
                EXIT_FAILED
            } else {
                EXIT_OK
            }
        }
        Err(m) => {
            let _ = writeln!(err, "error: {m} (nothing written)");
            EXIT_USAGE
        }
    }
}

/// The reports of the parts, one per analysis (in name order), or what is wrong.
fn merge_reports(parts: &[PathBuf]) -> Result<Vec<SimReport>, String> {
    if parts.is_empty() {
        return Err("no part files given".into());
    }
    let mut groups: BTreeMap<String, Merger> = BTreeMap::new();
    let mut spec: Option<(String, String)> = None;
    for path in parts {
        let label = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| format!("cannot read {label}: {e}"))?;
        let part = Part::from_bytes(&bytes).map_err(|e| format!("{label}: {e}"))?;
        match &spec {
            Some((first, hash)) if *hash != part.run.spec_hash => {
                return Err(format!(
                    "`{label}` and `{first}` are parts of different specs (SHA-256 {} and {hash})",
                    part.run.spec_hash
                ));
            }
            Some(_) => {}
            None => spec = Some((label.clone(), part.run.spec_hash.clone())),
        }
        groups
            .entry(part.run.analysis.clone())
            .or_default()
            .add(&label, part)
            .map_err(|e| e.to_string())?;
    }
    groups
        .into_iter()
        .map(|(analysis, m)| {
            m.finish()
                .map_err(|e| format!("analysis `{analysis}`: {e}"))
        })
        .collect()
}
