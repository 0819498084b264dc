//! `kappa(n, delta)` against the 30-digit reference values (`core/tests/data/kappa.jsonl`,
//! recomputed by `scripts/reference/kappa.py`) and the structural properties of the rules.

use reachc_core::kappa::{kappa, kappa_amgf, kappa_paper, kappa_paper_optimal, log_phi_lower};
use reachc_core::model::RadiusRule;

struct Row {
    n: usize,
    delta: f64,
    amgf: f64,
    paper_1_16: f64,
    chi2: f64,
}

fn reference() -> Vec<Row> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/kappa.jsonl");
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read the kappa reference {path}: {e}"));
    let rows: Vec<Row> = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).expect("reference line is JSON");
            let f = |k: &str| v[k].as_f64().unwrap_or_else(|| panic!("field {k} in {l}"));
            Row {
                n: v["n"].as_u64().expect("field n") as usize,
                delta: f("delta"),
                amgf: f("kappa_amgf"),
                paper_1_16: f("kappa_paper_eps_1_16"),
                chi2: f("chi2_quantile"),
            }
        })
        .collect();
    assert!(rows.len() >= 30, "reference too short: {} rows", rows.len());
    rows
}

/// Relative tolerance of the match, and how far below the reference a value may be.
const MATCH_REL: f64 = 1e-9;
const BELOW_REL: f64 = 1e-12;

fn check(name: &str, n: usize, delta: f64, ours: f64, reference: f64) -> f64 {
    let rel = (ours - reference) / reference;
    assert!(
        rel.abs() <= MATCH_REL,
        "{name}(n = {n}, delta = {delta}): {ours} vs reference {reference} (rel {rel:e})"
    );
    assert!(
        rel >= -BELOW_REL,
        "{name}(n = {n}, delta = {delta}): {ours} below reference {reference} (rel {rel:e})"
    );
    rel
}

#[test]
fn amgf_matches_reference() {
    let (mut max_abs, mut min_rel) = (0.0f64, f64::INFINITY);
    for r in reference() {
        let k = kappa_amgf(r.n, r.delta);
        let rel = check("kappa_amgf", r.n, r.delta, k, r.amgf);
        assert_eq!(k, kappa(r.n, r.delta, RadiusRule::Amgf));
        max_abs = max_abs.max(rel.abs());
        min_rel = min_rel.min(rel);
    }
    println!("amgf: max |rel err| = {max_abs:e}, min (ours - ref)/ref = {min_rel:e}");
}

#[test]
fn paper_matches_reference() {
    let (mut max_abs, mut min_rel) = (0.0f64, f64::INFINITY);
    for r in reference() {
        let k = kappa_paper(r.n, r.delta, 1.0 / 16.0);
        let rel = check("kappa_paper", r.n, r.delta, k, r.paper_1_16);
        assert_eq!(k, kappa(r.n, r.delta, RadiusRule::Paper(1.0 / 16.0)));
        max_abs = max_abs.max(rel.abs());
        min_rel = min_rel.min(rel);
    }
    println!("paper(1/16): max |rel err| = {max_abs:e}, min (ours - ref)/ref = {min_rel:e}");
}

/// Beyond the shared grid (which stops at n = 10, delta = 1e-9): `(n, delta, kappa_amgf,
/// chi2_quantile)` computed independently with mpmath at 40 digits from the closed form
/// `Phi_n(z) = Gamma(n/2) (2/z)^(n/2-1) I_(n/2-1)(z)` (root of `2 (ln Phi - L) = z (ln Phi)'`
/// by `findroot`; chi-square upper quantile by bisection on `gammainc`).
const EXTRA: [(usize, f64, f64, f64); 8] = [
    (2, 1e-3, 18.545475452898486, 13.815510557964274),
    (1, 1e-15, 70.46384715094126, 64.43046352012365),
    (2, 1e-15, 75.22925624289512, 69.07755278982137),
    (20, 1e-6, 72.6835641613819, 65.42068103504783),
    (100, 1e-12, 244.05448552411397, 233.81056795920782),
    (300, 1e-3, 400.2210229823973, 381.4252485204115),
    (1000, 1e-15, 1418.7925639276584, 1397.571510083207),
    (1000, 0.1, 1098.9744657440795, 1057.723901381614),
];

#[test]
fn amgf_matches_extra_values() {
    let (mut max_abs, mut min_rel) = (0.0f64, f64::INFINITY);
    for (n, delta, reference, chi2) in EXTRA {
        let k = kappa_amgf(n, delta);
        let rel = check("kappa_amgf", n, delta, k, reference);
        assert!(
            k >= chi2,
            "n = {n}, delta = {delta}: {k} below the floor {chi2}"
        );
        max_abs = max_abs.max(rel.abs());
        min_rel = min_rel.min(rel);
    }
    println!("amgf (extra): max |rel err| = {max_abs:e}, min (ours - ref)/ref = {min_rel:e}");
}

#[test]
fn amgf_above_gaussian_floor() {
    for r in reference() {
        let k = kappa_amgf(r.n, r.delta);
        assert!(
            k >= r.chi2,
            "kappa_amgf(n = {}, delta = {}) = {k} below the chi-square floor {}",
            r.n,
            r.delta,
            r.chi2
        );
    }
}

/// Independent check of the reformulation `kappa = inf_z h(z)`: the returned `s` satisfies the
/// condition of method.md as stated, `inf_lambda [lambda^2/2 - ln Phi_n(lambda sqrt(s))] <= ln delta`
/// (with the certified lower bound of `ln Phi_n`, so an upper bound of the bracket), while
/// `s (1 - 1e-9)` does not (tightness; up to the lambda search, which is fine on this scale).
#[test]
fn amgf_satisfies_the_original_condition() {
    let inner = |n: usize, s: f64| {
        let f = |lam: f64| lam * lam / 2.0 - log_phi_lower(n, lam * s.sqrt());
        // Grid, then golden-section refinement around the best grid point.
        let (mut best, mut best_i) = (f64::INFINITY, 0);
        for i in 1..6000 {
            let v = f(i as f64 * 0.01);
            if v < best {
                best = v;
                best_i = i;
            }
        }
        let (mut a, mut b) = ((best_i - 1) as f64 * 0.01, (best_i + 1) as f64 * 0.01);
        for _ in 0..100 {
            let c = a + (b - a) * 0.381_966_011_250_105;
            let d = a + (b - a) * 0.618_033_988_749_895;
            if f(c) <= f(d) {
                b = d;
            } else {
                a = c;
            }
            best = best.min(f(c)).min(f(d));
        }
        best
    };
    for &n in &[1usize, 2, 3, 10, 100, 1000] {
        for &d in &[0.1, 1e-3, 1e-9, 1e-15] {
            let s = kappa_amgf(n, d);
            let ln_d = d.ln();
            assert!(
                inner(n, s) <= ln_d,
                "n = {n}, delta = {d}: condition fails at kappa = {s}"
            );
            assert!(
                inner(n, s * (1.0 - 1e-9)) > ln_d,
                "n = {n}, delta = {d}: kappa = {s} is not tight"
            );
        }
    }
}

#[test]
fn method_md_figures() {
    // method.md section 5: at n = 2, delta = 1e-3, paper 31.63, amgf 18.55, floor 13.82.
    let p = kappa_paper(2, 1e-3, 1.0 / 16.0);
    let a = kappa_amgf(2, 1e-3);
    assert!((p - 31.63).abs() < 0.005, "paper {p}");
    assert!((a - 18.55).abs() < 0.005, "amgf {a}");
    assert!(a > 13.81);
}

const NS: [usize; 12] = [1, 2, 3, 4, 5, 6, 10, 20, 50, 100, 300, 1000];
const DELTAS: [f64; 9] = [0.5, 0.1, 1e-2, 1e-3, 1e-5, 1e-7, 1e-9, 1e-12, 1e-15];

#[test]
fn paper_optimal_at_most_paper_1_16() {
    for &n in &NS {
        for &d in &DELTAS {
            let (k, eps) = kappa_paper_optimal(n, d);
            assert!(eps > 0.0 && eps < 1.0);
            assert_eq!(k, kappa_paper(n, d, eps));
            assert_eq!(k, kappa(n, d, RadiusRule::PaperOptimal));
            let k16 = kappa_paper(n, d, 1.0 / 16.0);
            assert!(k <= k16, "n = {n}, delta = {d}: optimal {k} > 1/16 {k16}");
            // Near-optimality: no grid eps does better.
            for i in 1..1000 {
                let e = i as f64 / 1000.0;
                let ke = kappa_paper(n, d, e);
                assert!(
                    k <= ke * (1.0 + 1e-12),
                    "n = {n}, delta = {d}: eps {e} gives {ke} < {k}"
                );
            }
        }
    }
}

#[test]
fn monotone_in_delta_and_n() {
    for &n in &NS {
        let mut prev = 0.0;
        for &d in &DELTAS {
            let k = kappa_amgf(n, d);
            assert!(
                k.is_finite() && k > prev,
                "amgf not decreasing in delta: n = {n}, delta = {d}"
            );
            prev = k;
        }
    }
    for &d in &DELTAS {
        let mut prev = (0.0, 0.0, 0.0);
        for &n in &NS {
            let cur = (
                kappa_amgf(n, d),
                kappa_paper(n, d, 1.0 / 16.0),
                kappa_paper_optimal(n, d).0,
            );
            assert!(
                cur.0 > prev.0 && cur.1 > prev.1 && cur.2 > prev.2,
                "not increasing in n: n = {n}, delta = {d}"
            );
            prev = cur;
        }
    }
}

#[test]
fn amgf_below_paper_and_hoeffding() {
    for &n in &NS {
        for &d in &DELTAS {
            let a = kappa_amgf(n, d);
            let p = kappa_paper_optimal(n, d).0;
            assert!(a <= p, "n = {n}, delta = {d}: amgf {a} > paper optimal {p}");
            // Sub-Gaussianity of the sphere gives Phi_n(z) <= e^(z^2 / (2n)), hence kappa >= n.
            assert!(a >= n as f64, "n = {n}, delta = {d}: amgf {a} < n");
        }
    }
    // n = 1: cosh z >= e^z / 2 gives amgf <= 2 ln 2 + 2 ln(1/delta) (Hoeffding); the gap is
    // ln(1 + e^(-2z)), below the rounding margin for small delta, hence the slack.
    for &d in &DELTAS {
        let a = kappa_amgf(1, d);
        let hoeffding = 2.0 * std::f64::consts::LN_2 - 2.0 * d.ln();
        assert!(
            a <= hoeffding * (1.0 + 3e-13),
            "delta = {d}: {a} > {hoeffding}"
        );
    }
}

/// `ln cosh z`, `ln(sinh z / z)`, `ln(3 (z cosh z - sinh z) / z^3)` without overflow.
fn log_phi_closed(n: usize, z: f64) -> f64 {
    let e = (-2.0 * z).exp();
    match n {
        1 => z + (e).ln_1p() - std::f64::consts::LN_2,
        3 => z + (-e).ln_1p() - std::f64::consts::LN_2 - z.ln(),
        // 3 (z cosh z - sinh z) / z^3 = 3 e^z ((z - 1) + (z + 1) e^(-2z)) / (2 z^3)
        5 => z + (3.0 * ((z - 1.0) + (z + 1.0) * e) / (2.0 * z * z * z)).ln(),
        _ => unreachable!(),
    }
}

#[test]
fn log_phi_lower_against_closed_forms() {
    for &n in &[1usize, 3, 5] {
        for i in 0..400 {
            let z = 2.0 + i as f64 * 2.5; // 2 ..= 999.5
            let lo = log_phi_lower(n, z);
            let exact = log_phi_closed(n, z);
            let tol = 1e-13 * exact.abs().max(1.0);
            assert!(
                lo <= exact + 1e-15 * exact,
                "n = {n}, z = {z}: {lo} > {exact}"
            );
            assert!(exact - lo <= tol, "n = {n}, z = {z}: {lo} vs {exact}");
        }
    }
    assert_eq!(log_phi_lower(7, 0.0), 0.0);
}

/// Beyond the series' range (z > 1e4) one Stirling-bounded term is below the closed form and
/// within `2 ln z` (plus the rounding margin, 1e-9 relative) of it.
#[test]
fn log_phi_lower_for_huge_z_stays_below_and_close() {
    for &n in &[1usize, 3, 5] {
        for &z in &[1.0001e4, 3.7e5, 1e9, 2.5e15, 1e40] {
            let lo = log_phi_lower(n, z);
            let exact = log_phi_closed(n, z);
            assert!(
                lo <= exact * (1.0 - 1e-14),
                "n = {n}, z = {z}: {lo} > {exact}"
            );
            let tol = 2.0 * z.ln() + 1e-9 * exact;
            assert!(exact - lo <= tol, "n = {n}, z = {z}: {lo} vs {exact}");
        }
    }
}

#[test]
fn large_n_and_small_delta_are_finite() {
    for &n in &[500usize, 1000, 2000] {
        for &d in &[1e-15, 1e-30, 1e-100] {
            let k = kappa_amgf(n, d);
            assert!(k.is_finite() && k > n as f64, "n = {n}, delta = {d}: {k}");
        }
    }
}

#[test]
#[should_panic]
fn rejects_delta_one() {
    kappa_amgf(2, 1.0);
}

#[test]
#[should_panic]
fn rejects_n_zero() {
    kappa_amgf(0, 0.1);
}

#[test]
#[should_panic]
fn rejects_eps_out_of_range() {
    kappa_paper(2, 0.1, 1.0);
}
