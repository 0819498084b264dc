//! The exit codes of generated binaries: their `main` is `reachc_runtime::app::run_cli` on the
//! generated model; here on the interpreter of the same spec (the numbers are the same), so no
//! crate is compiled. The CLI's codes are checked in cli/tests/outputs.rs.

use reachc_compiler::driver::load;
use reachc_e2e::{interpreter_of, workspace};
use reachc_runtime::app::{run_cli, EXIT_FAILED, EXIT_OK, EXIT_UNSAFE, EXIT_USAGE};
use std::path::PathBuf;

/// A decay through an unsafe half-space: not shown safe.
const THROUGH: &str = "not_shown_safe.sde";
/// `x' = 400 x` from 0 with a global rate: the radius of analysis `long` overflows.
const GROWING: &str = "radius_overflow.sde";

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("reachc-exit-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs the binary's command line `args` on `tests/good/SPEC`; its exit code and stderr.
fn binary(spec: &str, args: &[&str]) -> (u8, String) {
    let path = workspace().join("tests/good").join(spec);
    let (sys, _) = interpreter_of(load(&path).unwrap().model);
    let args: Vec<String> = args.iter().map(|a| a.to_string()).collect();
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = run_cli(&sys, &args, &mut out, &mut err);
    (code, String::from_utf8_lossy(&err).into_owned())
}

#[test]
fn generated_binaries_follow_the_exit_code_policy() {
    let dir = scratch("policy");
    let out = dir.join("out");
    let o = out.to_str().unwrap();
    // Not shown safe: 0, or 3 with --deny-unsafe (the results written).
    assert_eq!(binary(THROUGH, &["-o", o, "-q"]).0, EXIT_OK);
    std::fs::remove_dir_all(&out).unwrap();
    let (code, err) = binary(THROUGH, &["-o", o, "-q", "--deny-unsafe"]);
    assert_eq!(code, EXIT_UNSAFE, "{err}");
    assert_eq!(EXIT_UNSAFE, 3);
    assert!(out.join("contraction.json").is_file());
    // A file in place of the output folder: an I/O error, 2, the file untouched.
    let file = dir.join("file");
    std::fs::write(&file, "mine").unwrap();
    let (code, err) = binary(THROUGH, &["-o", file.to_str().unwrap()]);
    assert_eq!(code, EXIT_USAGE, "{err}");
    assert!(err.contains("(nothing written)"), "{err}");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "mine");
    // The same for simulate.
    let (code, err) = binary(
        THROUGH,
        &[
            "simulate",
            "--paths",
            "10",
            "-q",
            "-o",
            file.to_str().unwrap(),
        ],
    );
    assert_eq!(code, EXIT_USAGE, "{err}");
    // An unknown analysis: a usage error.
    let (code, err) = binary(THROUGH, &["--analysis", "nope", "-o", o]);
    assert_eq!(code, EXIT_USAGE, "{err}");
    // A result that is not finite: that analysis failed, the other one is written.
    let fresh = dir.join("fresh");
    let (code, err) = binary(GROWING, &["-q", "-o", fresh.to_str().unwrap()]);
    assert_eq!(code, EXIT_FAILED, "{err}");
    assert!(
        err.contains(
            "error: analysis `long` could not run: numerical failure: the PRS is not finite from \
             t = 1.8 on"
        ),
        "{err}"
    );
    assert!(fresh.join("short.json").is_file() && !fresh.join("long.json").exists());
    // With --error-lines, the failure is the line reachc locates: at the horizon.
    let (code, err) = binary(
        GROWING,
        &["-q", "--error-lines", "-o", fresh.to_str().unwrap()],
    );
    assert_eq!(code, EXIT_FAILED, "{err}");
    assert!(
        err.starts_with(
            "reachc-failure long setting:horizon could not run: numerical failure: the PRS is \
             not finite from t = 1.8 on"
        ),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
