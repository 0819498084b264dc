//! Generated crates (`reachc build`): deterministic bytes for every shipped spec; for small
//! specs, the crate compiles clippy-clean with cargo and its binary runs; and the generated
//! code computes what the IR interpreter computes.
//!
//! Every crate compiles in one shared target directory, `<workspace>/target/reachc-crates`, so
//! the runtime is compiled once (per profile) for all of them.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use reachc_compiler::backend::codegen;
use reachc_compiler::backend::crate_writer::{
    compile_crate_in, write_crate, CrateOptions, WrittenCrate,
};
use reachc_compiler::backend::interp::Interpreter;
use reachc_compiler::backend::prepare;
use reachc_compiler::driver::load;
use reachc_compiler::model::Model;
use reachc_e2e::{relative, shipped_specs, workspace, Rng};
use reachc_runtime::{Interval, System};

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

/// A fresh scratch directory for one test (removed by [`Scratch`]'s drop).
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("reachc-e2e-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
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
        spec_label: Some(format!("`{}`", relative(spec))),
        codegen,
        ..CrateOptions::default()
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
    let scratch = Scratch::new("bytes");
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
            ["Cargo.toml", "README.md", "src/lib.rs", "src/main.rs"],
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
        // The manifest names the package, the binary and the runtime by absolute path.
        let manifest = String::from_utf8(ta[0].1.clone()).unwrap();
        assert!(manifest.contains(&format!("name = \"{}\"", written.crate_name)));
        assert!(manifest.contains("[[bin]]") && manifest.contains("\n[workspace]\n"));
        let runtime = workspace().join("runtime").canonicalize().unwrap();
        assert!(
            manifest.contains(&format!("path = \"{}\"", runtime.display())),
            "{manifest}"
        );
        // Writing again over the first crate replaces it in place.
        write(&spec, &a);
        assert_eq!(tree(&a), ta);
    }
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
    let scratch = Scratch::new("compile");
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
        let binary = compile_crate_in(&dir, false, &target_dir())
            .unwrap_or_else(|e| panic!("{name}: cargo build:\n{e}"));
        assert!(binary.is_file(), "{}", binary.display());
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
        let mut json: Vec<PathBuf> = std::fs::read_dir(&results)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "json"))
            .collect();
        json.sort();
        assert!(!json.is_empty(), "{name}: no JSON in {}", results.display());
        for file in json {
            let text = std::fs::read_to_string(&file).unwrap();
            serde_json::from_str::<serde_json::Value>(&text)
                .unwrap_or_else(|e| panic!("{}: not JSON: {e}", file.display()));
        }
    }
}

/// The program replacing a generated crate's `src/main.rs`: for each line of stdin (a point
/// `x, u, t` then a box `(lo, hi)` per state, input and time, and for a model without inputs
/// eight more states, the lanes, one after the other, as f64 bit patterns in hex), it prints,
/// for the model and then each of its frames, drift, `D_x f`, `D_u f`, `G` at the point, then
/// their interval versions and the sparse `D_x f` on the box (`lo hi` per entry), then (no
/// inputs) `drift_x8` of the lanes at `t` (lane by lane for each entry), all as hex bit patterns
/// on one line.
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
    lanes: Option<&[X8]>,
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
    sys.drift_interval(xi, ui, ti, &mut fi);
    sys.jac_x_interval(xi, ui, ti, &mut jxi);
    sys.jac_u_interval(xi, ui, ti, &mut jui);
    sys.diffusion_interval(xi, ti, &mut gi);
    sys.jac_x_sparse_interval(xi, ui, ti, &mut si);
    for v in f.iter().chain(&jx).chain(&ju).chain(&g) {{
        words.push(format!("{{:016x}}", v.to_bits()));
    }}
    for v in fi.iter().chain(&jxi).chain(&jui).chain(&gi).chain(&si) {{
        words.push(format!("{{:016x}}", v.lo().to_bits()));
        words.push(format!("{{:016x}}", v.hi().to_bits()));
    }}
    if let Some(lanes) = lanes {{
        // NaN where nothing is written: a missing store shows.
        let mut f8 = vec![X8::splat(f64::NAN); n];
        sys.drift_x8(lanes, t, &mut f8);
        for v in f8.iter().flat_map(|v| v.0) {{
            words.push(format!("{{:016x}}", v.to_bits()));
        }}
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
        let lanes: Option<Vec<X8>> = (p == 0)
            .then(|| (0..n).map(|i| X8(std::array::from_fn(|k| l[k * n + i]))).collect());
        let lanes = lanes.as_deref();
        let mut words: Vec<String> = Vec::new();
        dump(&sys, (x, u, t), (&xi, &ui, ti), lanes, &mut words);
        let mut k = 0;
        while let Some(frame) = sys.frame(k) {{
            dump(frame, (x, u, t), (&xi, &ui, ti), lanes, &mut words);
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
/// same and of the sparse `D_x f`.
struct Values {
    points: Vec<(String, f64)>,
    boxes: Vec<(String, Interval)>,
}

fn evaluate(sys: &dyn System, s: &Sample) -> Values {
    let (n, p, m) = (sys.n(), sys.p(), sys.m());
    let sizes = [n, n * n, n * p, n * m, sys.jac_x_pattern().len()];
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
    ];
    Values {
        points: named(&points, &names),
        boxes: named(&boxes, &interval_names),
    }
}

/// A point and a box around it: states near their initial set, inputs in their box, time in
/// [0, 6] (past the end of the unicycle's table); for a model without inputs, the eight states
/// of `drift_x8`'s lanes.
struct Sample {
    x: Vec<f64>,
    u: Vec<f64>,
    t: f64,
    xi: Vec<Interval>,
    ui: Vec<Interval>,
    ti: Interval,
    lanes: Vec<Vec<f64>>,
}

fn sample(model: &Model, rng: &mut Rng) -> Sample {
    // A box of width up to 1e-2 holding `v` (min/max: rounding cannot push `v` out).
    let around = |v: f64, rng: &mut Rng| {
        let r = rng.uniform(0.0, 1e-2);
        let lo = v - r * rng.next();
        Interval::new(lo.min(v), (lo + r).max(v))
    };
    let state = |rng: &mut Rng| -> Vec<f64> {
        model
            .states
            .iter()
            .map(|s| {
                let (lo, hi) = s.bounds.map_or((-2.0, 2.0), |b| (b.lo - 2.0, b.hi + 2.0));
                rng.uniform(lo, hi)
            })
            .collect()
    };
    let x = state(rng);
    let u: Vec<f64> = model
        .inputs
        .iter()
        .map(|i| i.bounds.map_or(0.0, |b| rng.uniform(b.lo, b.hi)))
        .collect();
    let t = rng.uniform(0.0, 6.0);
    let n = model.states.len();
    // The sample's own state, signed zeros, a wide one and states near the initial set, so
    // the lanes differ from each other.
    let lanes = if model.inputs.is_empty() {
        let mut lanes = vec![x.clone(), vec![0.0; n], vec![-0.0; n]];
        lanes.push((0..n).map(|_| rng.uniform(-1e3, 1e3)).collect());
        lanes.extend((0..4).map(|_| state(rng)));
        lanes
    } else {
        Vec::new()
    };
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
    let scratch = Scratch::new("interp");
    // Every shipped spec but chain1000 (chain10 has the same equations; the big crate alone
    // takes a minute to compile).
    // Plus a spec whose names are Rust keywords (`fn`, `type`, `impl`, `self`, ...).
    let shipped = [
        "chain10",
        "duffing",
        "linear",
        "linear_n",
        "pendulum",
        "unicycle",
        "unicycle_lookahead",
        "vanderpol",
    ];
    let keywords = workspace().join("tests/good/rust_keywords.sde");
    // Every shipped spec that gets `drift_x8` is probed.
    for path in shipped_specs() {
        let model = load(&path).unwrap().model;
        let stem = path.file_stem().unwrap().to_string_lossy();
        let lanes = model.inputs.is_empty() && model.states.len() <= codegen::LANES_MAX_STATES;
        assert!(!lanes || shipped.contains(&&*stem), "{stem} is not probed");
    }
    // Specs without inputs and with at most four states (generated with `drift_x8`) that the
    // shipped ones do not cover: every function of values in lanes and of `t` alone, entries of
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
        let lanes = model.inputs.is_empty()
            && model.states.len() <= codegen::LANES_MAX_STATES
            && options == default;
        let lib = std::fs::read_to_string(dir.join("src/lib.rs")).unwrap();
        assert_eq!(lib.contains("fn drift_x8("), lanes, "{name}: drift_x8");
        let ident = written.crate_name.replace('-', "_");
        std::fs::write(
            dir.join("src/main.rs"),
            probe_main(&ident, &written.type_name),
        )
        .unwrap();
        let binary = compile_crate_in(&dir, false, &target_dir())
            .unwrap_or_else(|e| panic!("{name}: cargo build:\n{e}"));

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
            words.extend(s.lanes.iter().flatten().map(|&v| hex(v)));
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
                let want = evaluate(*sys, s);
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
                        "{what}: {entry}: generated {g:e}, interpreter {i:e}"
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
                // `drift_x8`: lane `l` of entry `i` is the drift at the lane's state, bit for
                // bit.
                if !s.lanes.is_empty() {
                    let n = sys.n();
                    assert!(words.len() >= at + 8 * n, "{what}: too few lane values");
                    let mut f = vec![0.0; n];
                    for (l, state) in s.lanes.iter().enumerate() {
                        sys.drift(state, &[], s.t, &mut f);
                        for (i, &want) in f.iter().enumerate() {
                            let got = words[at + 8 * i + l];
                            assert!(
                                same(got, want),
                                "{what}: drift_x8[{i}] lane {l} at {state:?}, t = {}: \
                                 generated {got:e}, interpreter {want:e}",
                                s.t
                            );
                        }
                    }
                    at += 8 * n;
                }
            }
            assert_eq!(at, words.len(), "{name}: sample {k}: too many values");
        }
    }
}
