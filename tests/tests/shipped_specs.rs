//! Every shipped spec (and benchmark, `specs/arch/`) checks, its symbolic derivatives agree with
//! central finite differences at random points, and every expression `inspect` prints parses
//! back to the same function.

use std::collections::HashMap;

use reachc_compiler::analysis::Derivatives;
use reachc_compiler::driver::{check_source, load};
use reachc_compiler::ir::{ExprId, Names, VarValues};
use reachc_compiler::model::Model;
use reachc_e2e::{benchmark_specs, discrete_specs, relative, shipped_specs};
use reachc_test_support::rng::Rng;

/// A random point: states in the domain (or within 3 of the initial set where unbounded),
/// inputs in their box, time in [0, 5].
struct Point {
    states: Vec<f64>,
    inputs: Vec<f64>,
    time: f64,
}

fn random_point(model: &Model, rng: &mut Rng) -> Point {
    let states = model
        .states
        .iter()
        .zip(&model.domain)
        .zip(&model.initial.boxes)
        .map(|((_, d), b)| {
            let (lo, hi) = b.map_or((-2.0, 2.0), |b| (b.lo - 3.0, b.hi + 3.0));
            rng.range(lo.max(d.lo), hi.min(d.hi))
        })
        .collect();
    let inputs = model
        .input_box
        .iter()
        .map(|b| rng.range(b.lo, b.hi))
        .collect();
    Point {
        states,
        inputs,
        time: rng.range(0.0, 5.0),
    }
}

fn eval(model: &Model, roots: &[ExprId], p: &Point) -> Vec<f64> {
    let noises = vec![0.0; model.noises.len()];
    let vars = VarValues {
        states: &p.states,
        inputs: &p.inputs,
        noises: &noises,
        time: p.time,
    };
    model.pool.eval(roots, &vars, &model.tables)
}

/// Central differences with h ~ 1e-6 are good to about 1e-9 relative; 1e-6 leaves room.
fn close(sym: f64, fd: f64) -> bool {
    (sym - fd).abs() <= 1e-6 * (1.0 + sym.abs())
}

/// Central difference of `exprs` along coordinate `j` of states or inputs.
fn central(model: &Model, exprs: &[ExprId], p: &Point, j: usize, input: bool) -> Vec<f64> {
    let x = if input { p.inputs[j] } else { p.states[j] };
    let h = 1e-6 * x.abs().max(1.0);
    let at = |v: f64| {
        let mut q = Point {
            states: p.states.clone(),
            inputs: p.inputs.clone(),
            time: p.time,
        };
        if input {
            q.inputs[j] = v
        } else {
            q.states[j] = v
        }
        eval(model, exprs, &q)
    };
    let (plus, minus) = (at(x + h), at(x - h));
    plus.iter()
        .zip(&minus)
        .map(|(a, b)| (a - b) / (2.0 * h))
        .collect()
}

#[test]
fn derivatives_match_finite_differences() {
    let all = shipped_specs().into_iter().chain(benchmark_specs());
    for path in all.chain(discrete_specs()) {
        let mut model = load(&path)
            .unwrap_or_else(|e| panic!("{}:\n{e}", relative(&path)))
            .model;
        let d = Derivatives::of(&mut model);
        let zero = model.pool.num(0.0);
        let jac_g: HashMap<(usize, usize, usize), ExprId> = d
            .jac_g
            .iter()
            .map(|g| ((g.row, g.noise, g.state), g.expr))
            .collect();
        // The 1000-state chain has the same equations as the 12-state one: sample about 40 rows
        // and columns, and fewer points.
        let sample: Vec<usize> = (0..model.states.len())
            .step_by((model.states.len() / 40).max(1))
            .collect();
        let points = if model.states.len() > 100 { 3 } else { 20 };
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        for _ in 0..points {
            let p = random_point(&model, &mut rng);
            let f = model.drift.clone();
            for (what, jac, input) in [("D_x f", &d.jac_x, false), ("D_u f", &d.jac_u, true)] {
                let cols: Vec<usize> = if input {
                    (0..model.inputs.len()).collect()
                } else {
                    sample.clone()
                };
                for j in cols {
                    let fd = central(&model, &f, &p, j, input);
                    let col: Vec<ExprId> = jac.iter().map(|r| r[j]).collect();
                    let sym = eval(&model, &col, &p);
                    for &i in &sample {
                        assert!(
                            close(sym[i], fd[i]),
                            "{} {what}[{i}][{j}] = {} at {:?}: symbolic {} vs finite difference {}",
                            relative(&path),
                            model.states[i].name,
                            p.states,
                            sym[i],
                            fd[i]
                        );
                    }
                }
            }
            // G entries (i, k) for sampled rows and noise channels (G is n x m, a million
            // entries for the big chain).
            let noise_sample: Vec<usize> = (0..model.noises.len())
                .step_by((model.noises.len() / 40).max(1))
                .collect();
            let entries: Vec<(usize, usize)> = sample
                .iter()
                .flat_map(|&i| noise_sample.iter().map(move |&k| (i, k)))
                .collect();
            let g: Vec<ExprId> = entries
                .iter()
                .map(|&(i, k)| model.diffusion[i][k])
                .collect();
            for &j in &sample {
                let fd = central(&model, &g, &p, j, false);
                let col: Vec<ExprId> = entries
                    .iter()
                    .map(|&(i, k)| *jac_g.get(&(i, k, j)).unwrap_or(&zero))
                    .collect();
                let sym = eval(&model, &col, &p);
                for (k, (s, f)) in sym.iter().zip(&fd).enumerate() {
                    assert!(
                        close(*s, *f),
                        "{} D_x G entry {k}, state {j}: {s} vs {f}",
                        relative(&path)
                    );
                }
            }
        }
    }
}

/// Prints every drift, diffusion and Jacobian entry, appends them to the spec as equations of
/// probe states, reloads, and compares values at random points.
#[test]
fn printed_expressions_parse_back_to_the_same_function() {
    for path in shipped_specs()
        .into_iter()
        .chain(benchmark_specs())
        .filter(|p| !p.ends_with("chain1000.sde"))
    {
        let loaded = load(&path).unwrap();
        let mut model = loaded.model;
        let d = Derivatives::of(&mut model);
        let mut exprs: Vec<ExprId> = model.drift.clone();
        exprs.extend(model.diffusion.iter().flatten());
        exprs.extend(d.jac_x.iter().flatten());
        exprs.extend(d.jac_u.iter().flatten());
        exprs.extend(d.jac_g.iter().map(|g| g.expr));
        let names_of = |v: &[reachc_compiler::model::Variable]| {
            v.iter().map(|x| x.name.clone()).collect::<Vec<_>>()
        };
        let (s, u, w) = (
            names_of(&model.states),
            names_of(&model.inputs),
            names_of(&model.noises),
        );
        let names = Names {
            states: &s,
            inputs: &u,
            noises: &w,
            tables: &model.tables,
        };
        // Analyses carry n x n matrices that the extra probe states would invalidate.
        let mut src = without_analyses(&loaded.source);
        src.push_str("\ndrift {\n");
        let mut decls = String::new();
        for (k, &e) in exprs.iter().enumerate() {
            decls.push_str(&format!("state probe_{k} = 0\n"));
            src.push_str(&format!("probe_{k}' = {}\n", model.pool.to_sde(e, &names)));
        }
        src.push_str("}\n");
        src.push_str(&decls);
        let dir = path.parent().unwrap();
        let (again, diags) = check_source(&src, dir);
        let again = again.unwrap_or_else(|| {
            panic!(
                "{}: printed expressions do not check: {diags:#?}",
                relative(&path)
            )
        });
        let n = model.states.len();
        let mut rng = Rng(7);
        for _ in 0..10 {
            let p = random_point(&model, &mut rng);
            let original = eval(&model, &exprs, &p);
            let mut q = Point {
                states: p.states.clone(),
                inputs: p.inputs.clone(),
                time: p.time,
            };
            q.states.resize(again.states.len(), 0.0);
            let reparsed = eval(&again, &again.drift[n..], &q);
            for (k, (a, b)) in original.iter().zip(&reparsed).enumerate() {
                assert!(
                    (a - b).abs() <= 1e-12 * (1.0 + a.abs()) || (a.is_nan() && b.is_nan()),
                    "{}: expression {k} `{}`: {a} before printing, {b} after",
                    relative(&path),
                    model.pool.to_sde(exprs[k], &names)
                );
            }
        }
    }
}

/// The spec text with its `analysis` items cut out (located with the parser).
fn without_analyses(source: &str) -> String {
    let (spec, diags) = reachc_compiler::syntax::parse(source);
    assert!(diags.is_empty(), "{diags:?}");
    let mut out = source.to_string();
    let mut spans: Vec<_> = spec
        .items
        .iter()
        .filter_map(|item| match item {
            reachc_compiler::syntax::ast::Item::Analysis { span, .. } => Some(span.clone()),
            _ => None,
        })
        .collect();
    spans.sort_by_key(|s| std::cmp::Reverse(s.start));
    for span in spans {
        out.replace_range(span, "");
    }
    out
}
