//! `reachc build`: a spec to a standalone Rust crate, compiled with cargo.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::{load_reporting, EXIT_USAGE};
use reachc_compiler::backend::crate_writer::{compile_crate, write_crate, CrateOptions};
use reachc_compiler::backend::mangle;
use reachc_compiler::diagnostics::render;

/// Runs `reachc build SPEC [-o OUT] [--no-compile] [--release]`: writes the crate (default
/// `./<crate name>`), compiles it unless `no_compile`, and prints what was written and the
/// binary's path. Errors: 1 for spec errors, 2 for I/O or cargo failures.
pub fn run_build(
    spec: &Path,
    out: Option<PathBuf>,
    no_compile: bool,
    release: bool,
) -> Result<(), u8> {
    let color = std::io::stderr().is_terminal();
    let start = Instant::now();
    let mut loaded = load_reporting(spec)?;
    let out = out.unwrap_or_else(|| PathBuf::from(mangle::crate_name(&loaded.model.name)));
    let written = write_crate(&mut loaded, &out, &CrateOptions::default()).map_err(|e| {
        eprint!("{}", e.report(color));
        e.exit_code()
    })?;
    if !written.warnings.is_empty() {
        let path = loaded.path.display().to_string();
        eprint!(
            "{}",
            render(&written.warnings, &path, &loaded.source, color)
        );
    }
    println!(
        "wrote crate `{}` to {} ({}) in {:.2?}",
        written.crate_name,
        written.dir.display(),
        written
            .files
            .iter()
            .map(|f| f.to_string_lossy().replace('\\', "/"))
            .collect::<Vec<_>>()
            .join(", "),
        start.elapsed()
    );
    if no_compile {
        return Ok(());
    }
    let compiling = Instant::now();
    eprintln!(
        "compiling {} with cargo{} ...",
        written.dir.display(),
        if release { " --release" } else { "" }
    );
    match compile_crate(&written.dir, release) {
        Ok(binary) => {
            println!(
                "binary: {} (cargo took {:.1?})",
                binary.display(),
                compiling.elapsed()
            );
            Ok(())
        }
        Err(e) => {
            eprint!("{}", e.report(color));
            Err(EXIT_USAGE)
        }
    }
}
