//! Helpers for the workspace-level end-to-end tests: where the shipped specs and the bad-spec
//! corpus live, and a renderer that names files relative to the workspace (stable snapshots).

use reachc_compiler::backend::{interp::Interpreter, prepare};
use reachc_compiler::driver::{check_source, load};
use reachc_runtime::model::ModelInfo;
use reachc_runtime::prs::{Proved, Role};
use reachc_runtime::Prs;
use std::path::{Path, PathBuf};

pub mod fuzz;

/// The interpreter of a checked model, with its model data.
pub fn interpreter_of(mut model: reachc_compiler::model::Model) -> (Interpreter, ModelInfo) {
    let prepared = prepare(&mut model);
    let info = prepared.info.clone();
    (Interpreter::new(model, &prepared), info)
}

/// The interpreter of the shipped spec `specs/NAME`.
pub fn shipped(name: &str) -> (Interpreter, ModelInfo) {
    let model = load(&workspace().join("specs").join(name)).expect("a shipped spec loads");
    interpreter_of(model.model)
}

/// The interpreter of a spec given as source (paths in it relative to `specs/`); panics with
/// the diagnostics if it does not check.
pub fn inline(source: &str) -> (Interpreter, ModelInfo) {
    let (model, diags) = check_source(source, &workspace().join("specs"));
    interpreter_of(model.unwrap_or_else(|| panic!("{diags:?}")))
}

/// The linearised Gaussian member of a result (method.md 8.10) and its mixture bound's number
/// of epochs; panics without one.
pub fn linearised_member(prs: &Prs) -> (&Prs, usize) {
    let m = prs
        .also()
        .iter()
        .find(|m| m.role() == Role::Linearised)
        .expect("a linearised Gaussian member");
    let epochs = m
        .validation()
        .rigorous
        .iter()
        .find_map(|p| match p {
            Proved::LinearisedGaussian { epochs } => Some(*epochs),
            _ => None,
        })
        .expect("the member says how it is proved");
    (m, epochs)
}

/// `z^2` with `4 Q(z) = delta / (n K)`, `Q` the standard normal upper tail: the squared factor
/// of the linearised member's Gaussian box (method.md 8.10: the reflection principle per
/// coordinate and epoch, `n K` events sharing `delta`). Computed independently of the crate:
/// `Q` by its continued fraction, `z` by bisection.
pub fn reflection_factor(n: usize, epochs: usize, delta: f64) -> f64 {
    upper_quantile(delta / (4.0 * (n * epochs) as f64)).powi(2)
}

/// `z >= 1` with `Q(z) = q` (`Q` the standard normal upper tail, [`normal_tail`]), by
/// bisection (to the last bit).
pub fn upper_quantile(q: f64) -> f64 {
    let (mut lo, mut hi) = (1.0f64, 40.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if normal_tail(mid) > q {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// `Q(z) = P(N(0, 1) > z)` for `z >= 1`: `phi(z) / (z + 1/(z + 2/(z + 3/(z + ...))))`
/// (Laplace's continued fraction), evaluated backwards from 500 terms.
pub fn normal_tail(z: f64) -> f64 {
    let cf = (1..500).rev().fold(z, |acc, k| z + f64::from(k) / acc);
    (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt() / cf
}

/// The workspace root.
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the workspace")
        .to_path_buf()
}

/// Every shipped spec, sorted by name.
pub fn shipped_specs() -> Vec<PathBuf> {
    specs_in("specs")
}

/// The field's benchmarks, `specs/arch/` (their runs take minutes: only the checks that cost
/// little take them all, and their own tests the rest), sorted by name.
pub fn benchmark_specs() -> Vec<PathBuf> {
    specs_in("specs/arch")
}

/// The discrete-time specs, `specs/discrete/` (method.md 8.16), sorted by name.
pub fn discrete_specs() -> Vec<PathBuf> {
    specs_in("specs/discrete")
}

/// The `.sde` files of the workspace folder `dir`, sorted by name.
fn specs_in(dir: &str) -> Vec<PathBuf> {
    reachc_test_support::files::with_extension(&workspace().join(dir), "sde")
}

/// The path of `p` relative to the workspace, with `/` separators (for snapshot stability).
pub fn relative(p: &Path) -> String {
    p.strip_prefix(workspace())
        .unwrap_or(p)
        .to_string_lossy()
        .replace('\\', "/")
}

#[cfg(test)]
mod tests {
    use super::normal_tail;

    /// Reference values of the normal upper tail (Python's `erfc(z / sqrt 2) / 2`).
    #[test]
    fn the_normal_tail_matches_reference_values() {
        for (z, q) in [
            (1.0, 0.15865525393145707),
            (3.0, 0.0013498980316300957),
            (5.0, 2.866515718791946e-07),
        ] {
            assert!((normal_tail(z) / q - 1.0).abs() < 1e-12, "Q({z})");
        }
    }
}
