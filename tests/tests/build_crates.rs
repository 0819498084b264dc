//! Generated crates (`reachc build`): deterministic bytes for every shipped spec, no absolute
//! path in any of them; for small specs, the crate compiles clippy-clean with cargo (its
//! `Cargo.lock` as cargo would write it) and its binary runs; a vendored crate moved elsewhere
//! builds with plain cargo; the cache runs an unchanged spec's binary without cargo; and the
//! generated code computes what the IR interpreter computes.
//!
//! Every crate compiles in one shared target directory, `<workspace>/target/reachc-crates`,
//! against one shared copy of the runtime, `<workspace>/target/reachc-e2e-cache/runtime`, so the
//! runtime is compiled once (per profile) for all of them.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;

use reachc_compiler::backend::codegen;
use reachc_compiler::backend::interp::Interpreter;
use reachc_compiler::backend::prepare;
use reachc_compiler::driver::load;
use reachc_compiler::model::Model;
use reachc_compiler::package::{
    compile_crate_in, install_runtime, write_crate, BuildError, Cache, CrateOptions,
    InstalledRuntime, Profile, RuntimeDep, WrittenCrate,
};
use reachc_e2e::{discrete_specs, relative, shipped_specs, workspace};
use reachc_runtime::{Interval, System};
use reachc_test_support::files::{with_extension, Scratch};
use reachc_test_support::rng::Rng;

/// Held by each test that runs cargo: the tests share one target directory, and crates of the
/// same spec (the probe and the real binary of `pendulum`) would overwrite each other's binary.
static CARGO: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Takes the [`CARGO`] lock (a test that failed while holding it does not poison the others).
fn cargo_lock() -> std::sync::MutexGuard<'static, ()> {
    CARGO
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The shared target directory of the generated crates.
fn target_dir() -> PathBuf {
    workspace().join("target").join("reachc-crates")
}

/// The cache of the tests (its runtime is the one every test crate shares; its target
/// directory is [`target_dir`]).
fn cache() -> Cache {
    Cache::new(
        workspace().join("target").join("reachc-e2e-cache"),
        target_dir(),
    )
}

/// The runtime shared by the crates of the tests, installed once.
fn runtime() -> &'static InstalledRuntime {
    static RUNTIME: OnceLock<InstalledRuntime> = OnceLock::new();
    RUNTIME.get_or_init(|| install_runtime(&cache().runtime_parent(), true).unwrap())
}

/// Compiles the crate at `dir` (dev profile) in the shared target directory.
fn compile(dir: &Path) -> Result<PathBuf, BuildError> {
    compile_crate_in(dir, Profile::Dev, &target_dir(), &mut |_| {})
}

fn spec(name: &str) -> PathBuf {
    workspace().join("specs").join(name)
}

/// Loads `spec` and writes its crate to `out`.
fn write(spec: &Path, out: &Path) -> WrittenCrate {
    write_with(spec, out, codegen::Options::default())
}

/// Loads `spec` and writes its crate to `out`, generating code with `codegen`.
fn write_with(spec: &Path, out: &Path, codegen: codegen::Options) -> WrittenCrate {
    let mut loaded = load(spec).unwrap_or_else(|e| panic!("{}:\n{e}", relative(spec)));
    let options = CrateOptions {
        runtime: RuntimeDep::shared(runtime(), out).unwrap(),
        spec_label: Some(format!("`{}`", relative(spec))),
        codegen,
    };
    write_crate(&mut loaded, out, &options)
        .unwrap_or_else(|e| panic!("{}: writing the crate:\n{e}", relative(spec)))
}

/// Every file under `dir`, relative, sorted, with its bytes.
fn tree(dir: &Path) -> Vec<(String, Vec<u8>)> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<(String, Vec<u8>)>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(root, &path, out);
            } else {
                let rel = path
                    .strip_prefix(root)
                    .unwrap()
                    .to_string_lossy()
                    .into_owned();
                out.push((rel, std::fs::read(&path).unwrap()));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

#[test]
fn every_shipped_spec_generates_the_same_bytes_twice() {
    let scratch = Scratch::new("e2e-bytes");
    for spec in shipped_specs() {
        let name = spec.file_stem().unwrap().to_string_lossy().into_owned();
        let a = scratch.0.join(format!("{name}-a"));
        let b = scratch.0.join(format!("{name}-b"));
        let written = write(&spec, &a);
        write(&spec, &b);
        let (ta, tb) = (tree(&a), tree(&b));
        let names: Vec<&str> = ta.iter().map(|(p, _)| p.as_str()).collect();
        assert_eq!(
            names,
            [
                "Cargo.lock",
                "Cargo.toml",
                "README.md",
                "src/lib.rs",
                "src/main.rs"
            ],
            "{}",
            relative(&spec)
        );
        for ((pa, ba), (pb, bb)) in ta.iter().zip(&tb) {
            assert_eq!(pa, pb);
            assert!(
                ba == bb,
                "{}: {pa} differs between two runs",
                relative(&spec)
            );
        }
        // The manifest names the package, the binary and the shared runtime by relative path.
        let manifest = String::from_utf8(ta[1].1.clone()).unwrap();
        assert!(manifest.contains(&format!("name = \"{}\"", written.crate_name)));
        assert!(manifest.contains("[[bin]]") && manifest.contains("\n[workspace]\n"));
        let RuntimeDep::Shared(path) = RuntimeDep::shared(runtime(), &a).unwrap() else {
            unreachable!()
        };
        assert!(!Path::new(&path).is_absolute());
        assert!(
            manifest.contains(&format!("reachc-runtime = {{ path = \"{path}\" }}")),
            "{manifest}"
        );
        assert_eq!(
            a.join(&path).canonicalize().unwrap(),
            runtime().runtime_crate().canonicalize().unwrap()
        );
        // Writing again over the first crate replaces it in place.
        write(&spec, &a);
        assert_eq!(tree(&a), ta);
    }
}

/// Every file under `dir` whose bytes contain one of `needles`, with the needle.
fn files_containing(dir: &Path, needles: &[String]) -> Vec<(String, String)> {
    let mut found = Vec::new();
    for (rel, bytes) in tree(dir) {
        for needle in needles {
            if bytes.windows(needle.len()).any(|w| w == needle.as_bytes()) {
                found.push((rel.clone(), needle.clone()));
            }
        }
    }
    found
}

/// The paths no generated file may contain: the workspace, the temporary directory, the
/// scratch directory and the cache (as given and canonical).
fn absolute_paths(scratch: &Path) -> Vec<String> {
    let mut paths = vec![
        workspace(),
        std::env::temp_dir(),
        scratch.to_path_buf(),
        cache().root().to_path_buf(),
    ];
    paths.extend(paths.clone().iter().filter_map(|p| p.canonicalize().ok()));
    let mut out: Vec<String> = paths
        .iter()
        .map(|p| p.display().to_string())
        .filter(|p| p.len() > 1)
        .collect();
    out.sort();
    out.dedup();
    out
}

#[test]
fn no_generated_file_names_an_absolute_path() {
    let scratch = Scratch::new("e2e-absolute");
    let needles = absolute_paths(&scratch.0);
    // The spec by absolute path: the README names its file name only.
    let pendulum = spec("pendulum.sde");
    assert!(pendulum.is_absolute());
    let vendored = scratch.0.join("vendored");
    let mut loaded = load(&pendulum).unwrap();
    let written = write_crate(&mut loaded, &vendored, &CrateOptions::default()).unwrap();
    assert!(written.vendored && written.changed);
    assert!(vendored.join("vendor/reachc-runtime/src/lib.rs").is_file());
    assert!(vendored.join("vendor/reachc-core/Cargo.toml").is_file());
    // A crate of the cache, beside the runtime it shares.
    let shared = cache().crate_dir("no-absolute-paths");
    let _ = std::fs::remove_dir_all(&shared);
    std::fs::create_dir_all(shared.parent().unwrap()).unwrap();
    let options = CrateOptions {
        runtime: RuntimeDep::shared(runtime(), &shared).unwrap(),
        ..CrateOptions::default()
    };
    write_crate(&mut loaded, &shared, &options).unwrap();
    for dir in [&vendored, &shared, &runtime().dir().to_path_buf()] {
        let found = files_containing(dir, &needles);
        assert!(found.is_empty(), "{}: {found:?}", dir.display());
    }
    let readme = std::fs::read_to_string(vendored.join("README.md")).unwrap();
    assert!(readme.contains("from `pendulum.sde`"), "{readme}");
    std::fs::remove_dir_all(&shared).unwrap();
}

#[test]
fn a_vendored_crate_moves_and_builds_with_plain_cargo() {
    let _cargo = cargo_lock();
    let scratch = Scratch::new("e2e-vendored");
    let written_at = scratch.0.join("written").join("pendulum");
    std::fs::create_dir_all(written_at.parent().unwrap()).unwrap();
    let mut loaded = load(&spec("pendulum.sde")).unwrap();
    write_crate(&mut loaded, &written_at, &CrateOptions::default()).unwrap();
    // Moved elsewhere, the original gone: it still builds, offline, with its own lock.
    let moved = scratch.0.join("elsewhere").join("moved");
    std::fs::create_dir_all(moved.parent().unwrap()).unwrap();
    std::fs::rename(&written_at, &moved).unwrap();
    let build = cargo(
        "build",
        &moved.join("Cargo.toml"),
        &["--locked", "--offline", "--message-format=short"],
    );
    assert!(
        build.status.success(),
        "cargo build --locked --offline of a moved vendored crate:\n{}",
        String::from_utf8_lossy(&build.stderr)
    );
    let binary = target_dir()
        .join("debug")
        .join(format!("pendulum{}", std::env::consts::EXE_SUFFIX));
    let results = scratch.0.join("out");
    let run = Command::new(&binary)
        .args(["--quiet", "-o"])
        .arg(&results)
        .stdin(Stdio::null())
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(results.join("contraction.json").is_file());
}

/// Modification times of every file under `dir`, relative paths sorted.
fn mtimes(dir: &Path) -> Vec<(String, std::time::SystemTime)> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<(String, std::time::SystemTime)>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let meta = std::fs::metadata(&path).unwrap();
            if meta.is_dir() {
                walk(root, &path, out);
            } else {
                let rel = path.strip_prefix(root).unwrap().display().to_string();
                out.push((rel, meta.modified().unwrap()));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

#[test]
fn the_cache_runs_an_unchanged_spec_without_cargo() {
    let _cargo = cargo_lock();
    let scratch = Scratch::new("e2e-cache");
    // A model name of its own: its crate and binary are this test's alone.
    let text = std::fs::read_to_string(spec("pendulum.sde"))
        .unwrap()
        .replace("model pendulum", "model cache_probe");
    let spec_path = scratch.0.join("cache_probe.sde");
    std::fs::write(&spec_path, &text).unwrap();
    let cache = cache();
    let mut events = Vec::new();
    let first = cache
        .binary(&mut load(&spec_path).unwrap(), Profile::Dev, &mut |p| {
            events.push(p.clone())
        })
        .unwrap();
    assert!(first.compiled);
    assert!(first.crate_dir.join(".reachc-stamp").is_file());
    assert!(first.path.is_file());
    assert!(matches!(
        events.first(),
        Some(reachc_compiler::package::Progress::Started { package }) if package == "cache-probe"
    ));
    let crate_before = mtimes(&first.crate_dir);
    let runtime_before = mtimes(runtime().dir());
    let binary_before = std::fs::metadata(&first.path).unwrap().modified().unwrap();

    // Unchanged: no file written, no cargo (a program that cannot run), no progress.
    std::thread::sleep(std::time::Duration::from_millis(20));
    let no_cargo = cache.clone().with_cargo_program(scratch.0.join("no-cargo"));
    let mut events = Vec::new();
    let second = no_cargo
        .binary(&mut load(&spec_path).unwrap(), Profile::Dev, &mut |p| {
            events.push(p.clone())
        })
        .unwrap();
    assert!(!second.compiled);
    assert_eq!(second.path, first.path);
    assert!(events.is_empty(), "{events:?}");
    assert_eq!(mtimes(&first.crate_dir), crate_before);
    assert_eq!(mtimes(runtime().dir()), runtime_before);
    assert_eq!(
        std::fs::metadata(&first.path).unwrap().modified().unwrap(),
        binary_before
    );

    // A changed spec needs cargo (which cannot run here: an error, exit code 2) ...
    std::fs::write(&spec_path, text.replace("const K1 = -20", "const K1 = -21")).unwrap();
    let err = no_cargo
        .binary(&mut load(&spec_path).unwrap(), Profile::Dev, &mut |_| {})
        .unwrap_err();
    assert!(matches!(err, BuildError::Cargo { .. }), "{err:?}");
    assert_eq!(err.exit_code(), 2);
    // ... and builds with it.
    let third = cache
        .binary(&mut load(&spec_path).unwrap(), Profile::Dev, &mut |_| {})
        .unwrap();
    assert!(third.compiled);
    assert!(
        !cache
            .binary(&mut load(&spec_path).unwrap(), Profile::Dev, &mut |_| {})
            .unwrap()
            .compiled
    );
    // A binary replaced by someone else (another crate of the same name in the same target
    // directory) is not trusted: cargo runs again and puts this crate's binary back.
    std::fs::remove_file(&third.path).unwrap();
    std::fs::write(&third.path, b"replaced").unwrap();
    let fourth = cache
        .binary(&mut load(&spec_path).unwrap(), Profile::Dev, &mut |_| {})
        .unwrap();
    assert!(fourth.compiled);
    let run = Command::new(&fourth.path)
        .args(["--quiet", "-o"])
        .arg(scratch.0.join("out"))
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

/// Runs `cargo SUBCOMMAND --manifest-path MANIFEST ARGS` (the cargo running the tests) in the
/// shared target directory.
fn cargo(subcommand: &str, manifest: &Path, args: &[&str]) -> std::process::Output {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    Command::new(cargo)
        .arg(subcommand)
        .arg("--manifest-path")
        .arg(manifest)
        .arg("--quiet")
        .args(args)
        .env("CARGO_TARGET_DIR", target_dir())
        .stdin(Stdio::null())
        .output()
        .expect("cargo runs")
}

#[test]
fn small_crates_compile_clippy_clean_and_run() {
    let _cargo = cargo_lock();
    let scratch = Scratch::new("e2e-compile");
    // The pendulum also with its methods split into helper functions (clippy-clean too).
    let chunked = codegen::Options {
        split_above: 3,
        chunk_size: 3,
    };
    for (stem, name, options) in [
        ("pendulum", "pendulum", codegen::Options::default()),
        ("linear", "linear", codegen::Options::default()),
        ("pendulum", "pendulum-chunked", chunked),
    ] {
        let dir = scratch.0.join(name);
        let written = write_with(&spec(&format!("{stem}.sde")), &dir, options);
        let lib = std::fs::read_to_string(dir.join("src/lib.rs")).unwrap();
        assert_eq!(lib.contains("_part0("), options == chunked, "{name}");
        let lock = std::fs::read(dir.join("Cargo.lock")).unwrap();
        let binary = compile(&dir).unwrap_or_else(|e| panic!("{name}: cargo build:\n{e}"));
        assert!(binary.is_file(), "{}", binary.display());
        // The generated lock is the one cargo would write: it is left as it is.
        assert!(
            std::fs::read(dir.join("Cargo.lock")).unwrap() == lock,
            "{name}: cargo changed Cargo.lock"
        );
        assert!(binary
            .file_stem()
            .is_some_and(|s| s.to_string_lossy() == written.crate_name));

        let clippy = cargo(
            "clippy",
            &dir.join("Cargo.toml"),
            &["--all-targets", "--", "-D", "warnings"],
        );
        assert!(
            clippy.status.success(),
            "{name}: cargo clippy -- -D warnings:\n{}",
            String::from_utf8_lossy(&clippy.stderr)
        );

        let results = scratch.0.join(format!("{name}-out"));
        let run = Command::new(&binary)
            .arg("-o")
            .arg(&results)
            .arg("--quiet")
            .stdin(Stdio::null())
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{name}: {} exited with {}:\n{}",
            binary.display(),
            run.status,
            String::from_utf8_lossy(&run.stderr)
        );
        let json = with_extension(&results, "json");
        assert!(!json.is_empty(), "{name}: no JSON in {}", results.display());
        for file in json {
            let text = std::fs::read_to_string(&file).unwrap();
            serde_json::from_str::<serde_json::Value>(&text)
                .unwrap_or_else(|e| panic!("{}: not JSON: {e}", file.display()));
        }
    }
}

/// The program replacing a generated crate's `src/main.rs`: for each line of stdin (a point
/// `x, u, t` then a box `(lo, hi)` per state, input and time, then eight more states and inputs,
/// the lanes, one after the other, as f64 bit patterns in hex), it prints, for the model and
/// then each of its frames, drift, `D_x f`, `D_u f`, `G` at the point, then their interval
/// versions and the sparse `D_x f` on the box (`lo hi` per entry), then `drift_x8` and
/// `diffusion_x8` of the lanes at `t` (lane by lane for each entry), all as hex bit patterns on
/// one line.
fn probe_main(crate_ident: &str, type_name: &str) -> String {
    format!(
        r#"use std::io::{{BufRead, Write}};

use reachc_runtime::{{Interval, System, X8}};

fn parse(s: &str) -> f64 {{
    f64::from_bits(u64::from_str_radix(s, 16).expect("hex"))
}}

fn dump(
    sys: &dyn System,
    (x, u, t): (&[f64], &[f64], f64),
    (xi, ui, ti): (&[Interval], &[Interval], Interval),
    (lx, lu): (&[X8], &[X8]),
    sets: usize,
    words: &mut Vec<String>,
) {{
    let (n, p, m) = (sys.n(), sys.p(), sys.m());
    let mut f = vec![0.0; n];
    let mut jx = vec![0.0; n * n];
    let mut ju = vec![0.0; n * p];
    let mut g = vec![0.0; n * m];
    sys.drift(x, u, t, &mut f);
    sys.jac_x(x, u, t, &mut jx);
    sys.jac_u(x, u, t, &mut ju);
    sys.diffusion(x, t, &mut g);
    let mut fi = vec![Interval::ZERO; n];
    let mut jxi = vec![Interval::ZERO; n * n];
    let mut jui = vec![Interval::ZERO; n * p];
    let mut gi = vec![Interval::ZERO; n * m];
    let mut si = vec![Interval::ZERO; sys.jac_x_pattern().len()];
    let mut ni = vec![Interval::ZERO; sets];
    sys.drift_interval(xi, ui, ti, &mut fi);
    sys.jac_x_interval(xi, ui, ti, &mut jxi);
    sys.jac_u_interval(xi, ui, ti, &mut jui);
    sys.diffusion_interval(xi, ti, &mut gi);
    sys.jac_x_sparse_interval(xi, ui, ti, &mut si);
    sys.set_numbers(ti, &mut ni);
    for v in f.iter().chain(&jx).chain(&ju).chain(&g) {{
        words.push(format!("{{:016x}}", v.to_bits()));
    }}
    for v in fi.iter().chain(&jxi).chain(&jui).chain(&gi).chain(&si).chain(&ni) {{
        words.push(format!("{{:016x}}", v.lo().to_bits()));
        words.push(format!("{{:016x}}", v.hi().to_bits()));
    }}
    // NaN where nothing is written: a missing store shows.
    let mut f8 = vec![X8::splat(f64::NAN); n];
    let mut g8 = vec![X8::splat(f64::NAN); n * m];
    sys.drift_x8(lx, lu, t, &mut f8);
    sys.diffusion_x8(lx, t, &mut g8);
    for v in f8.iter().chain(&g8).flat_map(|v| v.0) {{
        words.push(format!("{{:016x}}", v.to_bits()));
    }}
}}

fn main() {{
    let sys = {crate_ident}::{type_name};
    let (n, p) = (sys.n(), sys.p());
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    for line in std::io::stdin().lock().lines() {{
        let v: Vec<f64> = line.expect("stdin").split_whitespace().map(parse).collect();
        let (x, u, t) = (&v[..n], &v[n..n + p], v[n + p]);
        let b = &v[n + p + 1..];
        let iv = |k: usize| Interval::new(b[2 * k], b[2 * k + 1]);
        let xi: Vec<Interval> = (0..n).map(iv).collect();
        let ui: Vec<Interval> = (n..n + p).map(iv).collect();
        let ti = iv(n + p);
        let l = &b[2 * (n + p + 1)..];
        let lane = |i: usize| X8(std::array::from_fn(|k| l[k * (n + p) + i]));
        let (lx, lu): (Vec<X8>, Vec<X8>) = ((0..n).map(lane).collect(), (n..n + p).map(lane).collect());
        let lanes = (&lx[..], &lu[..]);
        let mut words: Vec<String> = Vec::new();
        let numbers = reachc_runtime::Model::info(&sys).set_numbers();
        dump(&sys, (x, u, t), (&xi, &ui, ti), lanes, numbers, &mut words);
        let mut k = 0;
        while let Some(frame) = sys.frame(k) {{
            dump(frame, (x, u, t), (&xi, &ui, ti), lanes, 0, &mut words);
            k += 1;
        }}
        writeln!(out, "{{}}", words.join(" ")).expect("stdout");
    }}
}}
"#
    )
}

/// What the probe prints for one system at a sample, computed by the interpreter, each entry
/// with its name: the point values of drift, `D_x f`, `D_u f`, `G`, then the box values of the
/// same, of the sparse `D_x f` and of the `sets` moving set numbers (method.md 8.15) over the
/// sample's time box.
struct Values {
    points: Vec<(String, f64)>,
    boxes: Vec<(String, Interval)>,
}

fn evaluate(sys: &dyn System, s: &Sample, sets: usize) -> Values {
    let (n, p, m) = (sys.n(), sys.p(), sys.m());
    let sizes = [n, n * n, n * p, n * m, sys.jac_x_pattern().len(), sets];
    let mut points: Vec<Vec<f64>> = sizes[..4].iter().map(|&len| vec![0.0; len]).collect();
    sys.drift(&s.x, &s.u, s.t, &mut points[0]);
    sys.jac_x(&s.x, &s.u, s.t, &mut points[1]);
    sys.jac_u(&s.x, &s.u, s.t, &mut points[2]);
    sys.diffusion(&s.x, s.t, &mut points[3]);
    let mut boxes: Vec<Vec<Interval>> =
        sizes.iter().map(|&len| vec![Interval::ZERO; len]).collect();
    sys.drift_interval(&s.xi, &s.ui, s.ti, &mut boxes[0]);
    sys.jac_x_interval(&s.xi, &s.ui, s.ti, &mut boxes[1]);
    sys.jac_u_interval(&s.xi, &s.ui, s.ti, &mut boxes[2]);
    sys.diffusion_interval(&s.xi, s.ti, &mut boxes[3]);
    sys.jac_x_sparse_interval(&s.xi, &s.ui, s.ti, &mut boxes[4]);
    sys.set_numbers(s.ti, &mut boxes[5]);
    fn named<T: Copy>(parts: &[Vec<T>], names: &[&str]) -> Vec<(String, T)> {
        parts
            .iter()
            .zip(names)
            .flat_map(|(part, name)| {
                part.iter()
                    .enumerate()
                    .map(move |(e, &v)| (format!("{name}[{e}]"), v))
            })
            .collect()
    }
    let names = ["drift", "jac_x", "jac_u", "diffusion"];
    let interval_names = [
        "drift_interval",
        "jac_x_interval",
        "jac_u_interval",
        "diffusion_interval",
        "jac_x_sparse_interval",
        "set_numbers",
    ];
    Values {
        points: named(&points, &names),
        boxes: named(&boxes, &interval_names),
    }
}

/// A point and a box around it: states near their initial set, inputs in their box, time in
/// [0, 6] (past the end of the unicycle's table); and the eight states and inputs of
/// `drift_x8`'s lanes.
struct Sample {
    x: Vec<f64>,
    u: Vec<f64>,
    t: f64,
    xi: Vec<Interval>,
    ui: Vec<Interval>,
    ti: Interval,
    lanes: Vec<(Vec<f64>, Vec<f64>)>,
}

fn sample(model: &Model, rng: &mut Rng) -> Sample {
    // A box of width up to 1e-2 holding `v` (min/max: rounding cannot push `v` out).
    let around = |v: f64, rng: &mut Rng| {
        let r = rng.range(0.0, 1e-2);
        let lo = v - r * rng.uniform();
        Interval::new(lo.min(v), (lo + r).max(v))
    };
    let state = |rng: &mut Rng| -> Vec<f64> {
        model
            .initial
            .boxes
            .iter()
            .map(|b| {
                let (lo, hi) = b.map_or((-2.0, 2.0), |b| (b.lo - 2.0, b.hi + 2.0));
                rng.range(lo, hi)
            })
            .collect()
    };
    let x = state(rng);
    let input = |rng: &mut Rng| -> Vec<f64> {
        model
            .input_box
            .iter()
            .map(|b| rng.range(b.lo, b.hi))
            .collect()
    };
    let u = input(rng);
    let t = rng.range(0.0, 6.0);
    let n = model.states.len();
    // The sample's own state and input, signed zeros, a wide one and states near the initial
    // set with inputs in the box, so the lanes differ from each other.
    let p = model.inputs.len();
    let mut lanes = vec![
        (x.clone(), u.clone()),
        (vec![0.0; n], vec![0.0; p]),
        (vec![-0.0; n], vec![-0.0; p]),
        ((0..n).map(|_| rng.range(-1e3, 1e3)).collect(), input(rng)),
    ];
    lanes.extend((0..4).map(|_| (state(rng), input(rng))));
    Sample {
        xi: x.iter().map(|&v| around(v, rng)).collect(),
        ui: u.iter().map(|&v| around(v, rng)).collect(),
        ti: around(t, rng),
        x,
        u,
        t,
        lanes,
    }
}

fn hex(v: f64) -> String {
    format!("{:016x}", v.to_bits())
}

/// Bitwise equality (NaN equal to NaN).
fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

#[test]
fn generated_code_agrees_with_the_interpreter() {
    let _cargo = cargo_lock();
    let scratch = Scratch::new("e2e-interp");
    // Every shipped spec but chain1000 (chain10 has the same equations; the big crate alone
    // takes a minute to compile).
    // Plus a spec whose names are Rust keywords (`fn`, `type`, `impl`, `self`, ...).
    let shipped = [
        "chain10",
        "duffing",
        "linear",
        "linear_n",
        "lorenz",
        "msd",
        "overtake",
        "pendulum",
        "unicycle",
        "unicycle_lookahead",
        "vanderpol",
        "vanderpol_feedback",
        "discrete/building_automation",
        "discrete/integrator_chain",
    ];
    let keywords = workspace().join("tests/good/rust_keywords.sde");
    // Every shipped spec that gets `drift_x8` is probed.
    for path in shipped_specs().into_iter().chain(discrete_specs()) {
        let model = load(&path).unwrap().model;
        let stem = relative(&path);
        let stem = stem.trim_start_matches("specs/").trim_end_matches(".sde");
        let lanes = model.states.len() <= codegen::LANES_MAX_STATES;
        assert!(!lanes || shipped.contains(&stem), "{stem} is not probed");
    }
    // Specs with at most four states (generated with `drift_x8`) that the shipped ones do not
    // cover: every function of values in lanes and of `t` alone, entries of
    // `t` alone, constant, zero, and a state itself.
    let lanes_specs =
        ["lanes", "lanes_leaves"].map(|n| workspace().join(format!("tests/good/{n}.sde")));
    // Then specs whose methods (of more than 3 operands) are split into helper functions that
    // pass values through scratch arrays: chain10 (chain1000's equations, which are split at the
    // default size), the pendulum (a frame) and the unicycle (a table, inputs and time).
    let chunked = codegen::Options {
        split_above: 3,
        chunk_size: 3,
    };
    let default = codegen::Options::default();
    let cases = shipped
        .iter()
        .map(|n| (spec(&format!("{n}.sde")), default))
        .chain([(keywords, default)])
        .chain(lanes_specs.into_iter().map(|p| (p, default)))
        .chain(
            ["chain10", "pendulum", "unicycle"]
                .iter()
                .map(|n| (spec(&format!("{n}.sde")), chunked)),
        );
    for (path, options) in cases {
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        let name = if options == chunked {
            format!("{stem}-chunked")
        } else {
            stem
        };
        let name = name.as_str();
        let dir = scratch.0.join(name);
        let written = write_with(&path, &dir, options);
        let mut model = load(&path).unwrap().model;
        // `drift_x8` is generated (else the trait's default, per lane, is what the probe sees).
        let lanes = model.states.len() <= codegen::LANES_MAX_STATES && options == default;
        let lib = std::fs::read_to_string(dir.join("src/lib.rs")).unwrap();
        assert_eq!(lib.contains("fn drift_x8("), lanes, "{name}: drift_x8");
        let ident = written.crate_name.replace('-', "_");
        std::fs::write(
            dir.join("src/main.rs"),
            probe_main(&ident, &written.type_name),
        )
        .unwrap();
        let binary = compile(&dir).unwrap_or_else(|e| panic!("{name}: cargo build:\n{e}"));

        let prepared = prepare(&mut model);
        let interp = Interpreter::new(model.clone(), &prepared);

        let mut rng = Rng(0x9E37_79B9_7F4A_7C15 ^ name.len() as u64);
        let samples: Vec<Sample> = (0..50).map(|_| sample(&model, &mut rng)).collect();
        let mut input = String::new();
        for s in &samples {
            let mut words: Vec<String> = Vec::new();
            words.extend(s.x.iter().chain(&s.u).map(|&v| hex(v)));
            words.push(hex(s.t));
            for iv in s.xi.iter().chain(&s.ui).chain(std::iter::once(&s.ti)) {
                words.push(hex(iv.lo()));
                words.push(hex(iv.hi()));
            }
            for (x, u) in &s.lanes {
                words.extend(x.iter().chain(u).map(|&v| hex(v)));
            }
            input.push_str(&words.join(" "));
            input.push('\n');
        }
        let mut child = Command::new(&binary)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Written from another thread: the probe's output fills its pipe before it has read
        // all of the input.
        let mut stdin = child.stdin.take().unwrap();
        let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
        let output = child.wait_with_output().unwrap();
        writer.join().unwrap().unwrap();
        assert!(
            output.status.success(),
            "{name}: probe failed:\n{}",
            String::from_utf8_lossy(&output.stderr)
        );
        let stdout = String::from_utf8(output.stdout).unwrap();
        let lines: Vec<&str> = stdout.lines().collect();
        assert_eq!(lines.len(), samples.len());

        // The interpreter and its frames, in the probe's order.
        let mut systems: Vec<&dyn System> = vec![&interp];
        while let Some(frame) = interp.frame(systems.len() - 1) {
            systems.push(frame);
        }
        for (k, (s, line)) in samples.iter().zip(&lines).enumerate() {
            let words: Vec<f64> = line
                .split_whitespace()
                .map(|w| f64::from_bits(u64::from_str_radix(w, 16).unwrap()))
                .collect();
            let mut at = 0;
            for (j, sys) in systems.iter().enumerate() {
                let what = if j == 0 {
                    format!("{name}: sample {k}")
                } else {
                    format!("{name}: frame {}: sample {k}", j - 1)
                };
                let sets = if j == 0 { model.set_numbers.len() } else { 0 };
                let want = evaluate(*sys, s, sets);
                let (np, nb) = (want.points.len(), want.boxes.len());
                assert!(words.len() >= at + np + 2 * nb, "{what}: too few values");
                let points = &words[at..at + np];
                let boxes: Vec<Interval> = words[at + np..at + np + 2 * nb]
                    .chunks(2)
                    .map(|w| Interval::new(w[0], w[1]))
                    .collect();
                at += np + 2 * nb;
                // Same operations in the same order: bit for bit.
                for (&g, (entry, i)) in points.iter().zip(&want.points) {
                    assert!(
                        same(g, *i),
                        "{what}: {entry}: generated {g:e}, interpreter {i:e} (x = {:?}, u = {:?}, \
                         t = {:?})",
                        s.x,
                        s.u,
                        s.t
                    );
                }
                for (g, (entry, i)) in boxes.iter().zip(&want.boxes) {
                    assert!(
                        same(g.lo(), i.lo()) && same(g.hi(), i.hi()),
                        "{what}: {entry}: generated {g:?}, interpreter {i:?}"
                    );
                }
                // Enclosure: the point lies in the box, so the box results hold the point
                // results (the dense parts come first, in the same order).
                for (&v, (g, (entry, _))) in points.iter().zip(boxes.iter().zip(&want.boxes)) {
                    assert!(
                        v.is_nan() || g.contains(v),
                        "{what}: {entry} = {g:?} misses {v:e}"
                    );
                }
                // `drift_x8` and `diffusion_x8`: lane `l` of entry `i` is the drift (then
                // `G`) at the lane's state and input, bit for bit.
                let (n, m) = (sys.n(), sys.m());
                assert!(
                    words.len() >= at + 8 * n * (1 + m),
                    "{what}: too few lane values"
                );
                let (mut f, mut g) = (vec![0.0; n], vec![0.0; n * m]);
                for (l, (state, input)) in s.lanes.iter().enumerate() {
                    sys.drift(state, input, s.t, &mut f);
                    sys.diffusion(state, s.t, &mut g);
                    let named =
                        |name, v: &[f64]| v.iter().map(move |&v| (name, v)).collect::<Vec<_>>();
                    let want = [named("drift_x8", &f), named("diffusion_x8", &g)].concat();
                    for (i, &(method, want)) in want.iter().enumerate() {
                        let got = words[at + 8 * i + l];
                        assert!(
                            same(got, want),
                            "{what}: {method} entry {i} lane {l} at {state:?}, u = {input:?}, \
                             t = {}: generated {got:e}, interpreter {want:e}",
                            s.t
                        );
                    }
                }
                at += 8 * n * (1 + m);
            }
            assert_eq!(at, words.len(), "{name}: sample {k}: too many values");
        }
    }
}
