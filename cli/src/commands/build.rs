//! `reachc build`: a spec to a standalone Rust crate (the runtime vendored under `vendor/`),
//! compiled with cargo.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::load_reporting;
use super::progress::CompileDisplay;
use reachc_compiler::backend::mangle;
use reachc_compiler::diagnostics::render;
use reachc_compiler::package::{write_crate, Cache, CrateOptions, Profile};

/// Runs `reachc build SPEC [-o OUT] [--no-compile] [--release] [-q]`: writes the crate (default
/// `./<crate name>`; files already there with the same bytes are left alone), compiles it
/// unless `no_compile` (in the shared target directory of reachc's cache; cargo's progress on
/// stderr unless `quiet`), and prints what was written and the binary's path. Errors: 1 for
/// spec errors, 2 for I/O or cargo failures.
pub fn run_build(
    spec: &Path,
    out: Option<PathBuf>,
    no_compile: bool,
    release: bool,
    quiet: bool,
) -> Result<(), u8> {
    let color = std::io::stderr().is_terminal();
    let report = |e: reachc_compiler::package::BuildError| {
        eprint!("{}", e.report(color));
        e.exit_code()
    };
    let start = Instant::now();
    let mut loaded = load_reporting(spec)?;
    let out = out.unwrap_or_else(|| PathBuf::from(mangle::crate_name(&loaded.model.name)));
    let written = write_crate(&mut loaded, &out, &CrateOptions::default()).map_err(report)?;
    if !written.warnings.is_empty() {
        let path = loaded.path.display().to_string();
        eprint!(
            "{}",
            render(&written.warnings, &path, &loaded.source, color)
        );
    }
    let mut files: Vec<String> = written
        .files
        .iter()
        .map(|f| f.to_string_lossy().replace('\\', "/"))
        .collect();
    if written.vendored {
        files.push("vendor/".to_string());
    }
    let state = if written.changed {
        "wrote"
    } else {
        "up to date (nothing written):"
    };
    println!(
        "{state} crate `{}` at {} ({}) in {:.2?}",
        written.crate_name,
        written.dir.display(),
        files.join(", "),
        start.elapsed()
    );
    if no_compile {
        return Ok(());
    }
    let compiling = Instant::now();
    let cache = Cache::from_env().map_err(report)?;
    let mut display = CompileDisplay::new(quiet);
    let binary = cache
        .cargo(Profile::from_release(release))
        .build(&written.dir, &mut |p| display.event(p))
        .map_err(report)?;
    println!(
        "binary: {} (cargo took {:.1?})",
        binary.display(),
        compiling.elapsed()
    );
    Ok(())
}
