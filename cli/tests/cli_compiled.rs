//! The compiled backend of `reachc run` / `reachc simulate` and `reachc build`, as a user runs
//! them, with a stand-in for cargo (a shell script that records its calls and "builds" a binary
//! that prints its arguments): an unchanged spec runs its cached binary without writing a file
//! or starting cargo, a changed one is built again; progress on stderr only while cargo runs
//! (none with `-q`); no absolute path in anything reachc writes; clear errors (exit code 2)
//! for an unusable cache, a missing or failing cargo. Real cargo builds are tested in
//! `tests/tests/build_crates.rs` and `tests/relocation.sh`.
#![cfg(unix)]

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::SystemTime;

use common::spec;
use reachc_test_support::files::Scratch;

/// The stand-in for cargo: appends its arguments to `$FAKE_CARGO_LOG`, writes
/// `$CARGO_TARGET_DIR/release/<package>` (a script printing `fake binary ARGS`) and reports it
/// the way cargo does.
const FAKE_CARGO: &str = r#"#!/bin/sh
echo "$*" >> "$FAKE_CARGO_LOG"
manifest=""
while [ $# -gt 0 ]; do
    if [ "$1" = "--manifest-path" ]; then manifest="$2"; fi
    shift
done
name=$(sed -n 's/^name = "\(.*\)"$/\1/p' "$manifest" | head -n 1)
mkdir -p "$CARGO_TARGET_DIR/release"
bin="$CARGO_TARGET_DIR/release/$name"
rm -f "$bin"
printf '#!/bin/sh\necho "fake binary $*"\n' > "$bin"
chmod +x "$bin"
echo "   Compiling $name" >&2
echo '{"reason":"compiler-artifact","package_id":"registry+https://x#serde@1.0.0","target":{"name":"serde"},"fresh":false,"executable":null}'
echo "{\"reason\":\"compiler-artifact\",\"package_id\":\"path+file:///x/$name#0.1.0\",\"target\":{\"name\":\"$name\"},\"fresh\":false,\"executable\":\"$bin\"}"
echo '{"reason":"build-finished","success":true}'
"#;

/// A test's world: a spec outside the repository, a cache, the fake cargo and its log.
struct World {
    scratch: Scratch,
}

impl World {
    fn new(name: &str) -> World {
        let scratch = Scratch::new(&format!("cli-{name}"));
        std::fs::copy(spec("pendulum.sde"), scratch.0.join("pendulum.sde")).unwrap();
        let cargo = scratch.0.join("fake-cargo");
        std::fs::write(&cargo, FAKE_CARGO).unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&cargo, std::fs::Permissions::from_mode(0o755)).unwrap();
        World { scratch }
    }

    fn path(&self, rel: &str) -> PathBuf {
        self.scratch.0.join(rel)
    }

    fn spec(&self) -> String {
        self.path("pendulum.sde").display().to_string()
    }

    /// The cache's root (its target directory is `<root>/target`).
    fn cache(&self) -> PathBuf {
        self.path("cache")
    }

    /// Runs reachc with the cache and `cargo` (the fake one unless given).
    fn reachc(&self, args: &[&str], cargo: Option<&Path>) -> Output {
        let fake = self.path("fake-cargo");
        Command::new(env!("CARGO_BIN_EXE_reachc"))
            .args(args)
            .current_dir(&self.scratch.0)
            .env("REACHC_TARGET_DIR", self.cache().join("target"))
            .env("CARGO", cargo.unwrap_or(&fake))
            .env("FAKE_CARGO_LOG", self.path("cargo.log"))
            .output()
            .expect("reachc runs")
    }

    /// The calls of the fake cargo so far.
    fn cargo_calls(&self) -> Vec<String> {
        std::fs::read_to_string(self.path("cargo.log"))
            .unwrap_or_default()
            .lines()
            .map(str::to_string)
            .collect()
    }
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Every file under `dir` with its modification time, sorted.
fn files(dir: &Path) -> Vec<(PathBuf, SystemTime)> {
    fn walk(dir: &Path, out: &mut Vec<(PathBuf, SystemTime)>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let meta = std::fs::metadata(&path).unwrap();
            if meta.is_dir() {
                walk(&path, out);
            } else {
                out.push((path, meta.modified().unwrap()));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, &mut out);
    out.sort();
    out
}

/// The absolute paths no file reachc writes may contain: the scratch directory, the temporary
/// directory, the workspace (as given and canonical).
fn forbidden(scratch: &Path) -> Vec<String> {
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut out = Vec::new();
    for p in [scratch.to_path_buf(), std::env::temp_dir(), workspace] {
        if let Ok(c) = p.canonicalize() {
            out.push(c.display().to_string());
        }
        out.push(p.display().to_string());
    }
    out.retain(|p| p.len() > 1);
    out
}

/// Asserts that no file under `dir` contains one of `needles`.
fn assert_no_paths(dir: &Path, needles: &[String]) {
    for (path, _) in files(dir) {
        let bytes = std::fs::read(&path).unwrap();
        for needle in needles {
            assert!(
                !bytes.windows(needle.len()).any(|w| w == needle.as_bytes()),
                "{} contains {needle}",
                path.display()
            );
        }
    }
}

#[test]
fn an_unchanged_spec_runs_its_cached_binary_without_cargo() {
    let world = World::new("cached");
    let spec = world.spec();
    let out = world.path("out").display().to_string();

    // First run: cargo builds, one plain progress line (stderr is not a terminal).
    let first = world.reachc(&["run", &spec, "-o", &out], None);
    assert_eq!(first.status.code(), Some(0), "{}", text(&first.stderr));
    assert_eq!(
        text(&first.stdout),
        format!("fake binary -o {out} --error-lines\n"),
        "the binary ran with the arguments"
    );
    let stderr = text(&first.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("compiling pendulum with cargo (the first build"),
        "{stderr}"
    );
    let calls = world.cargo_calls();
    assert_eq!(calls.len(), 1);
    assert!(
        calls[0].starts_with("build --manifest-path ") && calls[0].contains("--release"),
        "{calls:?}"
    );
    let cache = world.cache();
    let crate_dir = cache.join("crates").join("pendulum");
    let manifest = std::fs::read_to_string(crate_dir.join("Cargo.toml")).unwrap();
    assert!(
        manifest.contains("reachc-runtime = { path = \"../../runtime/"),
        "{manifest}"
    );
    assert!(crate_dir.join(".reachc-stamp").is_file());
    assert!(cache.join("runtime").read_dir().unwrap().count() == 1);
    assert_no_paths(&crate_dir, &forbidden(&world.scratch.0));
    assert_no_paths(&cache.join("runtime"), &forbidden(&world.scratch.0));
    let before = files(&cache);

    // Second run, cargo unusable: the cached binary runs; nothing written, nothing printed.
    std::thread::sleep(std::time::Duration::from_millis(20));
    let second = world.reachc(&["run", &spec, "-o", &out], Some(Path::new("/bin/false")));
    assert_eq!(second.status.code(), Some(0), "{}", text(&second.stderr));
    assert_eq!(
        text(&second.stdout),
        format!("fake binary -o {out} --error-lines\n")
    );
    assert_eq!(text(&second.stderr), "");
    assert_eq!(files(&cache), before);
    // simulate uses the same binary.
    let sim = world.reachc(
        &["simulate", &spec, "--paths", "10"],
        Some(Path::new("/bin/false")),
    );
    assert_eq!(sim.status.code(), Some(0), "{}", text(&sim.stderr));
    assert!(
        text(&sim.stdout).starts_with("fake binary simulate --paths 10"),
        "{}",
        text(&sim.stdout)
    );
    assert_eq!(text(&sim.stderr), "");
    assert_eq!(files(&cache), before);
    assert_eq!(world.cargo_calls().len(), 1);

    // A changed spec is built again; -q: no progress.
    let changed = std::fs::read_to_string(&spec)
        .unwrap()
        .replace("const K1 = -20", "const K1 = -21");
    std::fs::write(&spec, changed).unwrap();
    let failing = world.reachc(&["run", &spec, "-o", &out], Some(Path::new("/bin/false")));
    assert_eq!(failing.status.code(), Some(2), "cargo is needed again");
    let third = world.reachc(&["run", "-q", &spec, "-o", &out], None);
    assert_eq!(third.status.code(), Some(0), "{}", text(&third.stderr));
    assert_eq!(text(&third.stderr), "");
    assert_eq!(world.cargo_calls().len(), 2);
    let fourth = world.reachc(&["run", &spec, "-o", &out], Some(Path::new("/bin/false")));
    assert_eq!(fourth.status.code(), Some(0), "{}", text(&fourth.stderr));
    assert_eq!(text(&fourth.stderr), "");
}

#[test]
fn build_vendors_the_runtime_and_reports_progress() {
    let world = World::new("build");
    let spec = world.spec();
    let dir = world.path("crate");
    let d = dir.display().to_string();
    let written = world.reachc(&["build", &spec, "-o", &d, "--no-compile"], None);
    assert_eq!(written.status.code(), Some(0), "{}", text(&written.stderr));
    assert!(text(&written.stdout).starts_with("wrote crate `pendulum`"));
    assert_eq!(text(&written.stderr), "");
    for file in [
        "Cargo.toml",
        "Cargo.lock",
        "src/lib.rs",
        "vendor/reachc-runtime/Cargo.toml",
        "vendor/reachc-runtime/src/lib.rs",
        "vendor/reachc-core/src/lib.rs",
    ] {
        assert!(dir.join(file).is_file(), "{file}");
    }
    let manifest = std::fs::read_to_string(dir.join("Cargo.toml")).unwrap();
    assert!(manifest.contains("reachc-runtime = { path = \"vendor/reachc-runtime\" }"));
    assert_no_paths(&dir, &forbidden(&world.scratch.0));
    assert!(world.cargo_calls().is_empty());

    // Again: nothing written.
    let before = files(&dir);
    let again = world.reachc(&["build", &spec, "-o", &d, "--no-compile"], None);
    assert!(
        text(&again.stdout).starts_with("up to date"),
        "{}",
        text(&again.stdout)
    );
    assert_eq!(files(&dir), before);

    // Compiling: one progress line, or none with -q.
    let compiled = world.reachc(&["build", &spec, "-o", &d, "--release"], None);
    assert_eq!(
        compiled.status.code(),
        Some(0),
        "{}",
        text(&compiled.stderr)
    );
    assert!(text(&compiled.stderr).starts_with("compiling pendulum with cargo"));
    assert!(text(&compiled.stdout).contains("binary: "));
    let quiet = world.reachc(&["build", "-q", &spec, "-o", &d, "--release"], None);
    assert_eq!(quiet.status.code(), Some(0), "{}", text(&quiet.stderr));
    assert_eq!(text(&quiet.stderr), "");
    assert_eq!(world.cargo_calls().len(), 2);
}

#[test]
fn cache_and_cargo_failures_are_clear_errors() {
    let world = World::new("errors");
    let spec = world.spec();
    let run = |envs: &[(&str, Option<&str>)]| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_reachc"));
        cmd.args(["run", &spec, "-o"])
            .arg(world.path("out"))
            .current_dir(&world.scratch.0);
        for (k, v) in envs {
            match v {
                Some(v) => cmd.env(k, v),
                None => cmd.env_remove(k),
            };
        }
        let out = cmd.output().unwrap();
        (out.status.code(), text(&out.stderr))
    };
    // The cache under a file: cannot be created.
    std::fs::write(world.path("file"), "x").unwrap();
    let under_file = world.path("file/cache/target").display().to_string();
    let (code, err) = run(&[("REACHC_TARGET_DIR", Some(&under_file))]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("error: creating reachc's cache directory"),
        "{err}"
    );
    // No cache at all.
    let (code, err) = run(&[
        ("REACHC_TARGET_DIR", None),
        ("XDG_CACHE_HOME", None),
        ("HOME", None),
    ]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("no directory for reachc's cache"), "{err}");
    // cargo missing, cargo failing.
    let cache = world.cache().join("target").display().to_string();
    let (code, err) = run(&[
        ("REACHC_TARGET_DIR", Some(&cache)),
        ("CARGO", Some("/nonexistent/cargo")),
    ]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("cannot run /nonexistent/cargo") && err.contains("--backend interp"),
        "{err}"
    );
    let (code, err) = run(&[
        ("REACHC_TARGET_DIR", Some(&cache)),
        ("CARGO", Some("/bin/false")),
    ]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("cargo build of") && err.contains("failed"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}
