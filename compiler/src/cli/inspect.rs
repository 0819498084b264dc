//! `reachc inspect`: the checked model, its Jacobians, atoms and bounds, as text or JSON.

use std::fmt::Write;

use reachc_runtime::interval::Interval;
use serde_json::{json, Value};

use crate::analysis::{bound_matrix, eval_box, split_atoms, time_range, AtomSplit, Derivatives};
use crate::ir::{ExprId, Names};
use crate::model::{Bounds, Model, UnsafeShape};

/// A matrix of expressions with its interval bounds, named as in the output.
struct Matrix {
    key: &'static str,
    title: &'static str,
    rows: Vec<Vec<ExprId>>,
    bounds: Vec<Vec<Interval>>,
    row_names: Vec<String>,
    col_names: Vec<String>,
}

/// Everything inspect shows, computed once.
struct Report {
    /// Diffusion, `D_x f`, `D_u f` and `D_x G` (rows `(state, noise)`), with bounds.
    matrices: Vec<Matrix>,
    /// The time range the bounds hold on.
    time: Interval,
}

fn names(model: &Model) -> (Vec<String>, Vec<String>, Vec<String>) {
    let n = |v: &[crate::model::Variable]| v.iter().map(|x| x.name.clone()).collect();
    (n(&model.states), n(&model.inputs), n(&model.noises))
}

fn report(model: &mut Model) -> Report {
    let d = Derivatives::of(model);
    let time = time_range(model);
    let (states, inputs, noises) = names(model);
    let jac_g_rows: Vec<Vec<ExprId>> = d.jac_g.iter().flatten().cloned().collect();
    let jac_g_names: Vec<String> = states
        .iter()
        .flat_map(|s| noises.iter().map(move |w| format!("G[{s}, {w}]")))
        .collect();
    let specs = [
        (
            "diffusion",
            "diffusion G (state x noise)",
            model.diffusion.clone(),
            states.clone(),
            noises.clone(),
        ),
        (
            "jacobian_x",
            "Jacobian D_x f (equation x state)",
            d.jac_x,
            states.clone(),
            states.clone(),
        ),
        (
            "jacobian_u",
            "Jacobian D_u f (equation x input)",
            d.jac_u,
            states.clone(),
            inputs,
        ),
        (
            "jacobian_g",
            "Jacobian D_x G (entry x state)",
            jac_g_rows,
            jac_g_names,
            states,
        ),
    ];
    let matrices = specs
        .into_iter()
        .map(|(key, title, rows, row_names, col_names)| Matrix {
            key,
            title,
            bounds: bound_matrix(model, &rows, time),
            rows,
            row_names,
            col_names,
        })
        .collect();
    Report { matrices, time }
}

fn sde(model: &Model, e: ExprId) -> String {
    let (states, inputs, noises) = names(model);
    let names = Names {
        states: &states,
        inputs: &inputs,
        noises: &noises,
        tables: &model.tables,
    };
    model.pool.to_sde(e, &names)
}

/// JSON numbers for interval ends; infinite ends become `null`.
fn ends(i: Interval) -> Value {
    json!([i.lo(), i.hi()])
}

fn bounds_json(b: Option<Bounds>) -> Value {
    b.map_or(Value::Null, |b| json!([b.lo, b.hi]))
}

fn atoms_json(model: &Model, split: &AtomSplit, time: Interval) -> Value {
    let exprs: Vec<ExprId> = split.atoms.iter().map(|a| a.expr).collect();
    let ranges = eval_box(model, &exprs, time);
    let atoms: Vec<Value> = split
        .atoms
        .iter()
        .zip(&ranges)
        .map(
            |(a, r)| json!({ "expr": sde(model, a.expr), "range": ends(*r), "entries": a.entries }),
        )
        .collect();
    json!({ "constant": split.constant, "atoms": atoms })
}

/// The `inspect --json` document (schema in docs/language.md).
pub fn json(model: &mut Model) -> String {
    let r = report(model);
    let model = &*model;
    let mut doc = json!({
        "model": model.name,
        "doc": model.doc,
        "constants": model.constants.iter().map(|(n, v)| json!({"name": n, "value": v})).collect::<Vec<_>>(),
        "states": model.states.iter().zip(&model.domain).map(|(s, d)| json!({
            "name": s.name, "initial": bounds_json(s.bounds), "domain": [d.lo, d.hi],
        })).collect::<Vec<_>>(),
        "inputs": model.inputs.iter().map(|u| json!({"name": u.name, "range": bounds_json(u.bounds)})).collect::<Vec<_>>(),
        "noise": model.noises.iter().map(|w| w.name.clone()).collect::<Vec<_>>(),
        "initial_balls": model.initial.balls.iter().map(|b| json!({
            "over": b.states.iter().map(|&i| model.states[i].name.clone()).collect::<Vec<_>>(),
            "center": b.center, "radius": b.radius, "metric": b.metric,
        })).collect::<Vec<_>>(),
        "domain_given": model.has_domain,
        "time_range": ends(r.time),
        "drift": model.drift.iter().map(|&e| sde(model, e)).collect::<Vec<_>>(),
        "unsafe": model.unsafe_sets.iter().map(|u| unsafe_json(model, u)).collect::<Vec<_>>(),
        "analyses": model.analyses.iter().map(|a| json!({
            "name": a.name, "method": format!("{:?}", a.method).to_lowercase(), "delta": a.delta,
            "horizon": a.horizon, "step": a.step,
        })).collect::<Vec<_>>(),
    });
    let mut bounds = serde_json::Map::new();
    let mut atoms = serde_json::Map::new();
    let mut unbounded = Vec::new();
    for m in &r.matrices {
        let exprs: Vec<Vec<String>> = m
            .rows
            .iter()
            .map(|row| row.iter().map(|&e| sde(model, e)).collect())
            .collect();
        doc[m.key] = json!(exprs);
        bounds.insert(
            m.key.into(),
            json!(m
                .bounds
                .iter()
                .map(|row| row.iter().map(|i| ends(*i)).collect::<Vec<_>>())
                .collect::<Vec<_>>()),
        );
        if m.key != "jacobian_g" {
            atoms.insert(
                m.key.into(),
                atoms_json(model, &split_atoms(&model.pool, &m.rows), r.time),
            );
        }
        for (i, row) in m.bounds.iter().enumerate() {
            for (j, b) in row.iter().enumerate().filter(|(_, b)| !b.is_bounded()) {
                unbounded.push(json!({
                    "matrix": m.key, "row": i, "column": j, "row_name": m.row_names[i],
                    "column_name": m.col_names[j], "expr": exprs[i][j], "range": ends(*b),
                }));
            }
        }
    }
    doc["jacobian_g"] = json!(doc["jacobian_g"].as_array().map(|rows| rows
        .chunks(model.noises.len().max(1))
        .map(|c| json!(c))
        .collect::<Vec<_>>()));
    doc["bounds"] = Value::Object(bounds);
    doc["atoms"] = Value::Object(atoms);
    doc["unbounded"] = json!(unbounded);
    let mut s = serde_json::to_string_pretty(&doc).expect("JSON values always serialise");
    s.push('\n');
    s
}

fn unsafe_json(model: &Model, u: &crate::model::UnsafeSet) -> Value {
    let name = |i: &usize| model.states[*i].name.clone();
    match &u.shape {
        UnsafeShape::Box(sides) => json!({"name": u.name, "kind": "box",
            "sides": sides.iter().map(|(i, b)| json!({"state": name(i), "range": [b.lo, b.hi]})).collect::<Vec<_>>()}),
        UnsafeShape::Ball {
            states,
            center,
            radius,
        } => json!({"name": u.name, "kind": "ball",
            "over": states.iter().map(name).collect::<Vec<_>>(), "center": center, "radius": radius}),
        UnsafeShape::HalfSpace { normal, offset } => {
            json!({"name": u.name, "kind": "halfspace", "normal": normal, "offset": offset})
        }
    }
}

fn fmt_bounds(b: Bounds) -> String {
    format!("[{}, {}]", b.lo, b.hi)
}

/// The human-readable report.
pub fn text(model: &mut Model) -> String {
    let r = report(model);
    let model = &*model;
    let mut o = String::new();
    let _ = writeln!(
        o,
        "model {}: {} states, {} inputs, {} noise channels",
        model.name,
        model.states.len(),
        model.inputs.len(),
        model.noises.len()
    );
    if let Some(doc) = &model.doc {
        for line in doc.lines() {
            let _ = writeln!(o, "  /// {line}");
        }
    }
    let _ = writeln!(o, "\nstates (initial set; domain):");
    for (s, d) in model.states.iter().zip(&model.domain) {
        let init = s
            .bounds
            .map_or_else(|| "in an initial ball".to_string(), fmt_bounds);
        let _ = writeln!(o, "  {:<12} {:<30} domain {}", s.name, init, fmt_bounds(*d));
    }
    for b in &model.initial.balls {
        let over: Vec<&str> = b
            .states
            .iter()
            .map(|&i| model.states[i].name.as_str())
            .collect();
        let _ = writeln!(
            o,
            "  ball over [{}]: center {:?}, radius {}{}",
            over.join(", "),
            b.center,
            b.radius,
            if b.metric.is_some() {
                ", with metric"
            } else {
                ""
            }
        );
    }
    if !model.inputs.is_empty() {
        let _ = writeln!(o, "\ninputs:");
        for u in &model.inputs {
            let _ = writeln!(
                o,
                "  {:<12} {}",
                u.name,
                u.bounds.map_or_else(String::new, fmt_bounds)
            );
        }
    }
    if !model.noises.is_empty() {
        let names: Vec<&str> = model.noises.iter().map(|w| w.name.as_str()).collect();
        let _ = writeln!(o, "\nnoise: {}", names.join(", "));
    }
    let _ = writeln!(o, "\ndrift (simplified):");
    for (s, &f) in model.states.iter().zip(&model.drift) {
        let _ = writeln!(o, "  {}' = {}", s.name, sde(model, f));
    }
    let _ = writeln!(
        o,
        "\nbounds over the domain, inputs in their box, t in [{}, {}]",
        r.time.lo(),
        r.time.hi()
    );
    let mut unbounded = Vec::new();
    for m in &r.matrices {
        let _ = writeln!(o, "\n{} (non-zero entries):", m.title);
        let mut any = false;
        for (i, row) in m.rows.iter().enumerate() {
            for (j, &e) in row.iter().enumerate() {
                if model.pool.as_const(e) == Some(0.0) {
                    continue;
                }
                any = true;
                let b = m.bounds[i][j];
                let _ = writeln!(
                    o,
                    "  [{}, {}] = {}    in {}",
                    m.row_names[i],
                    m.col_names[j],
                    sde(model, e),
                    b
                );
                if !b.is_bounded() {
                    unbounded.push(format!(
                        "{} [{}, {}] = {}",
                        m.key,
                        m.row_names[i],
                        m.col_names[j],
                        sde(model, e)
                    ));
                }
            }
        }
        if !any {
            let _ = writeln!(o, "  (all zero)");
        }
        if m.key != "jacobian_g" && any {
            let split = split_atoms(&model.pool, &m.rows);
            let exprs: Vec<ExprId> = split.atoms.iter().map(|a| a.expr).collect();
            let ranges = eval_box(model, &exprs, r.time);
            let _ = writeln!(
                o,
                "  atoms: {} (constant part plus atom x coefficient matrix)",
                split.atoms.len()
            );
            for (k, (a, range)) in split.atoms.iter().zip(&ranges).enumerate() {
                let entries: Vec<String> = a
                    .entries
                    .iter()
                    .map(|(i, j, c)| format!("[{}, {}]*{c}", m.row_names[*i], m.col_names[*j]))
                    .collect();
                let _ = writeln!(
                    o,
                    "    a{} = {}    in {}    at {}",
                    k + 1,
                    sde(model, a.expr),
                    range,
                    entries.join(", ")
                );
            }
        }
    }
    let _ = writeln!(o);
    if unbounded.is_empty() {
        let _ = writeln!(o, "every entry is bounded over the domain");
    } else {
        let _ = writeln!(
            o,
            "unbounded over the domain ({} entries):",
            unbounded.len()
        );
        for u in &unbounded {
            let _ = writeln!(o, "  {u}");
        }
        let _ = writeln!(o, "help: add a `domain {{ x in [LO, HI] }}` block to bound the states these entries depend on");
    }
    o
}
