//! `reachc inspect`: the checked model, its Jacobians, atoms and bounds, as text or JSON.
//!
//! Both forms come from one `Report`. Expressions are printed once per distinct IR node (a
//! 1000-state chain has a million Jacobian entries but few distinct ones), large shared
//! sub-expressions once as `let`s (so the output stays linear in the size of the IR), and the
//! JSON is streamed from borrowed data rather than built as a tree.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::io::Write;

use reachc_runtime::interval::Interval;
use reachc_runtime::report::schema::ShapeJson;
use serde::Serialize;
use serde_json::{json, Value};

use reachc_compiler::analysis::{
    bound_matrix, eval_box, split_atoms, time_range, AtomSplit, Derivatives, GradEntry,
};
use reachc_compiler::ir::{ExprId, Names};
use reachc_compiler::model::{Bounds, Model, Moving, Slot, Time, UnsafeShape, Variable};

/// A dense matrix of expressions with its interval bounds.
struct Matrix {
    key: &'static str,
    title: &'static str,
    rows: Vec<Vec<ExprId>>,
    bounds: Vec<Vec<Interval>>,
    row_names: Vec<String>,
    col_names: Vec<String>,
    atoms: AtomSplit,
    atom_ranges: Vec<Interval>,
}

/// Everything inspect shows, computed once.
struct Report {
    /// Diffusion `G`, `D_x f` and `D_u f`.
    matrices: Vec<Matrix>,
    /// The non-zero entries of `D_x G` with their bounds.
    jac_g: Vec<(GradEntry, Interval)>,
    /// The time range the bounds hold on.
    time: Interval,
    /// Every expression shown, printed in `.sde` syntax.
    printed: HashMap<ExprId, String>,
    /// The shared sub-expressions the printed expressions use, `(name, expression)` in order.
    lets: Vec<(String, String)>,
}

fn names(v: &[Variable]) -> Vec<String> {
    v.iter().map(|x| x.name.clone()).collect()
}

fn report(model: &mut Model) -> Report {
    let d = Derivatives::of(model);
    let model = &*model;
    let time = time_range(model);
    let (states, inputs, noises) = (
        names(&model.states),
        names(&model.inputs),
        names(&model.noises),
    );
    let specs = [
        (
            "diffusion",
            "diffusion G (state x noise)",
            model.diffusion.clone(),
            &noises,
        ),
        (
            "jacobian_x",
            "Jacobian D_x f (equation x state)",
            d.jac_x,
            &states,
        ),
        (
            "jacobian_u",
            "Jacobian D_u f (equation x input)",
            d.jac_u,
            &inputs,
        ),
    ];
    let matrices: Vec<Matrix> = specs
        .into_iter()
        .map(|(key, title, rows, cols)| {
            let atoms = split_atoms(&model.pool, &rows);
            let atom_exprs: Vec<ExprId> = atoms.atoms.iter().map(|a| a.expr).collect();
            Matrix {
                key,
                title,
                bounds: bound_matrix(model, &rows, time),
                atom_ranges: eval_box(model, &atom_exprs, time),
                atoms,
                rows,
                row_names: states.clone(),
                col_names: cols.clone(),
            }
        })
        .collect();
    let g_exprs: Vec<ExprId> = d.jac_g.iter().map(|g| g.expr).collect();
    let jac_g = d
        .jac_g
        .iter()
        .copied()
        .zip(eval_box(model, &g_exprs, time))
        .collect();
    let mut all: Vec<ExprId> = model.drift.clone();
    for m in &matrices {
        all.extend(m.rows.iter().flatten());
        all.extend(m.atoms.atoms.iter().map(|a| a.expr));
    }
    all.extend(g_exprs);
    all.extend(&model.set_numbers);
    all.sort_unstable();
    all.dedup();
    let sde_names = Names {
        states: &states,
        inputs: &inputs,
        noises: &noises,
        tables: &model.tables,
    };
    let shared = model.pool.to_sde_shared(&all, &sde_names);
    Report {
        matrices,
        jac_g,
        time,
        printed: all.into_iter().zip(shared.exprs).collect(),
        lets: shared.lets,
    }
}

impl Report {
    fn sde(&self, e: ExprId) -> &str {
        &self.printed[&e]
    }
}

/// `[lo, hi]`; serde_json writes infinite ends as `null`.
fn ends(i: Interval) -> [f64; 2] {
    [i.lo(), i.hi()]
}

#[derive(Serialize)]
struct AtomDoc<'a> {
    expr: &'a str,
    range: [f64; 2],
    entries: &'a [(usize, usize, f64)],
}

#[derive(Serialize)]
struct SplitDoc<'a> {
    constant: &'a [Vec<f64>],
    atoms: Vec<AtomDoc<'a>>,
}

#[derive(Serialize)]
struct GradDoc<'a> {
    row: usize,
    noise: usize,
    column: usize,
    expr: &'a str,
    range: [f64; 2],
}

#[derive(Serialize)]
struct UnboundedDoc<'a> {
    matrix: &'a str,
    row: usize,
    column: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    noise: Option<usize>,
    expr: &'a str,
    range: [f64; 2],
}

#[derive(Serialize)]
struct LetDoc<'a> {
    name: &'a str,
    expr: &'a str,
}

#[derive(Serialize)]
struct Doc<'a> {
    model: &'a str,
    doc: Option<&'a str>,
    constants: Vec<Value>,
    states: Vec<Value>,
    inputs: Vec<Value>,
    noise: Vec<&'a str>,
    initial_balls: Vec<Value>,
    domain_given: bool,
    time: Value,
    time_range: [f64; 2],
    lets: Vec<LetDoc<'a>>,
    drift: Vec<&'a str>,
    diffusion: Vec<Vec<&'a str>>,
    jacobian_x: Vec<Vec<&'a str>>,
    jacobian_u: Vec<Vec<&'a str>>,
    jacobian_g: Vec<GradDoc<'a>>,
    bounds: HashMap<&'a str, Vec<Vec<[f64; 2]>>>,
    atoms: HashMap<&'a str, SplitDoc<'a>>,
    unbounded: Vec<UnboundedDoc<'a>>,
    #[serde(rename = "unsafe")]
    unsafe_sets: Vec<Value>,
    goals: Vec<Value>,
    analyses: Vec<Value>,
}

fn bounds_json(b: Option<Bounds>) -> Value {
    b.map_or(Value::Null, |b| json!([b.lo, b.hi]))
}

/// Writes the `inspect --json` document (schema in docs/language.md).
pub fn json(model: &mut Model, out: &mut dyn Write) -> std::io::Result<()> {
    let r = report(model);
    let model = &*model;
    let grid = |rows: &[Vec<ExprId>]| -> Vec<Vec<&str>> {
        rows.iter()
            .map(|row| row.iter().map(|&e| r.sde(e)).collect())
            .collect()
    };
    let states = names(&model.states);
    let mut unbounded = Vec::new();
    for m in &r.matrices {
        for (i, row) in m.bounds.iter().enumerate() {
            for (j, b) in row.iter().enumerate().filter(|(_, b)| !b.is_bounded()) {
                unbounded.push(UnboundedDoc {
                    matrix: m.key,
                    row: i,
                    column: j,
                    noise: None,
                    expr: r.sde(m.rows[i][j]),
                    range: ends(*b),
                });
            }
        }
    }
    for (g, b) in r.jac_g.iter().filter(|(_, b)| !b.is_bounded()) {
        unbounded.push(UnboundedDoc {
            matrix: "jacobian_g",
            row: g.row,
            column: g.state,
            noise: Some(g.noise),
            expr: r.sde(g.expr),
            range: ends(*b),
        });
    }
    let doc = Doc {
        model: &model.name,
        doc: model.doc.as_deref(),
        constants: model.constants.iter().map(|(n, v)| json!({"name": n, "value": v})).collect(),
        states: model
            .states
            .iter()
            .zip(&model.domain)
            .zip(&model.initial.boxes)
            .map(|((s, d), b)| json!({"name": s.name, "initial": bounds_json(*b), "domain": [d.lo, d.hi]}))
            .collect(),
        inputs: model
            .inputs
            .iter()
            .zip(&model.input_box)
            .map(|(u, b)| json!({"name": u.name, "range": bounds_json(Some(*b))}))
            .collect(),
        noise: model.noises.iter().map(|w| w.name.as_str()).collect(),
        initial_balls: model
            .initial
            .balls
            .iter()
            .map(|b| {
                let over: Vec<&str> = b.states.iter().map(|&i| model.states[i].name.as_str()).collect();
                let metric: Option<Vec<&[f64]>> = b.metric.as_ref().map(|m| m.chunks(b.states.len()).collect());
                json!({"over": over, "center": b.center, "radius": b.radius, "metric": metric})
            })
            .collect(),
        domain_given: model.has_domain,
        time: match model.time {
            Time::Continuous => json!("continuous"),
            Time::Discrete { period } => json!({"discrete": {"period": period}}),
        },
        time_range: ends(r.time),
        lets: r.lets.iter().map(|(name, expr)| LetDoc { name, expr }).collect(),
        drift: model.drift.iter().map(|&e| r.sde(e)).collect(),
        diffusion: grid(&r.matrices[0].rows),
        jacobian_x: grid(&r.matrices[1].rows),
        jacobian_u: grid(&r.matrices[2].rows),
        jacobian_g: r
            .jac_g
            .iter()
            .map(|(g, b)| GradDoc { row: g.row, noise: g.noise, column: g.state, expr: r.sde(g.expr), range: ends(*b) })
            .collect(),
        bounds: r
            .matrices
            .iter()
            .map(|m| (m.key, m.bounds.iter().map(|row| row.iter().map(|b| ends(*b)).collect()).collect()))
            .collect(),
        atoms: r
            .matrices
            .iter()
            .map(|m| {
                let atoms = m
                    .atoms
                    .atoms
                    .iter()
                    .zip(&m.atom_ranges)
                    .map(|(a, range)| AtomDoc { expr: r.sde(a.expr), range: ends(*range), entries: &a.entries })
                    .collect();
                (m.key, SplitDoc { constant: &m.atoms.constant, atoms })
            })
            .collect(),
        unbounded,
        unsafe_sets: model
            .unsafe_sets
            .iter()
            .map(|u| moving_json(model, &r, shape_json(&states, &u.name, &u.shape), &u.moving))
            .collect(),
        goals: model
            .goals
            .iter()
            .map(|g| {
                let parts: Vec<Value> = g
                    .parts
                    .iter()
                    .enumerate()
                    .map(|(j, p)| {
                        let moving: Vec<Moving> =
                            g.moving.iter().filter(|m| m.part == j).copied().collect();
                        moving_json(model, &r, shape_json(&states, &g.name, p), &moving)
                    })
                    .collect();
                json!({"name": g.name, "parts": parts,
                       "window": g.window.map(|w| [w.lo, w.hi]), "stay": g.stay})
            })
            .collect(),
        analyses: model
            .analyses
            .iter()
            .map(|a| {
                let a = &a.spec;
                json!({"name": a.name, "method": a.method.name(),
                       "delta": a.delta, "horizon": a.horizon, "step": a.step})
            })
            .collect(),
    };
    // Compact: dense Jacobians of large models are millions of entries (pipe through `jq` to read).
    serde_json::to_writer(&mut *out, &doc)?;
    writeln!(out)
}

/// An unsafe set, or a part of goal `set`, in the `inspect --json` document: the shape's one
/// JSON form ([`ShapeJson`]) with the set's name, in the states named `states`.
fn shape_json(states: &[String], set: &str, shape: &UnsafeShape) -> Value {
    // Plain data with string keys: converting cannot fail.
    let mut v = serde_json::to_value(ShapeJson::of(states, shape)).expect("a shape serialises");
    v["name"] = json!(set);
    v
}

/// `shape` (from [`shape_json`]) with, for a moving set (method.md 8.15), `"moving"`: each
/// moving number's place (`"offset"`, `"lo"`/`"hi"` with the side's state, `"center"` with its
/// entry, `"radius"`) and its expression of `t` and tables. The shape's own numbers are the
/// values at `t = 0`.
fn moving_json(model: &Model, r: &Report, mut shape: Value, moving: &[Moving]) -> Value {
    if moving.is_empty() {
        return shape;
    }
    let entries: Vec<Value> = moving
        .iter()
        .map(|m| {
            let expression = r.sde(model.set_numbers[m.number]);
            match m.slot {
                Slot::Offset => json!({"number": "offset", "expression": expression}),
                Slot::Lo(k) | Slot::Hi(k) => {
                    let end = if matches!(m.slot, Slot::Lo(_)) {
                        "lo"
                    } else {
                        "hi"
                    };
                    json!({"number": end, "side": k, "expression": expression})
                }
                Slot::Center(k) => {
                    json!({"number": "center", "entry": k, "expression": expression})
                }
                Slot::Radius => json!({"number": "radius", "expression": expression}),
            }
        })
        .collect();
    shape["moving"] = Value::Array(entries);
    shape
}

fn fmt_bounds(b: Bounds) -> String {
    format!("[{}, {}]", b.lo, b.hi)
}

/// Writes the human-readable report.
pub fn text(model: &mut Model, out: &mut dyn Write) -> std::io::Result<()> {
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
    for line in model.doc.iter().flat_map(|d| d.lines()) {
        let _ = writeln!(o, "  /// {line}");
    }
    if let Time::Discrete { period } = model.time {
        let _ = writeln!(
            o,
            "  discrete time: one step every period {period} (t = k * {period})"
        );
    }
    let _ = writeln!(o, "\nstates (initial set; domain):");
    for ((s, d), b) in model
        .states
        .iter()
        .zip(&model.domain)
        .zip(&model.initial.boxes)
    {
        let init = b.map_or_else(|| "in an initial ball".to_string(), fmt_bounds);
        let _ = writeln!(o, "  {:<12} {:<30} domain {}", s.name, init, fmt_bounds(*d));
    }
    for b in &model.initial.balls {
        let over: Vec<&str> = b
            .states
            .iter()
            .map(|&i| model.states[i].name.as_str())
            .collect();
        let metric = if b.metric.is_some() {
            ", with metric"
        } else {
            ""
        };
        let _ = writeln!(
            o,
            "  ball over [{}]: center {:?}, radius {}{metric}",
            over.join(", "),
            b.center,
            b.radius
        );
    }
    if !model.inputs.is_empty() {
        let _ = writeln!(o, "\ninputs:");
        for (u, b) in model.inputs.iter().zip(&model.input_box) {
            let _ = writeln!(o, "  {:<12} {}", u.name, fmt_bounds(*b));
        }
    }
    if !model.noises.is_empty() {
        let ws: Vec<&str> = model.noises.iter().map(|w| w.name.as_str()).collect();
        let _ = writeln!(o, "\nnoise: {}", ws.join(", "));
    }
    if !r.lets.is_empty() {
        let _ = writeln!(o, "\nshared sub-expressions:");
        for (name, e) in &r.lets {
            let _ = writeln!(o, "  let {name} = {e}");
        }
    }
    let (block, prime) = match model.time {
        Time::Continuous => ("drift", "'"),
        Time::Discrete { .. } => ("update", ""),
    };
    let _ = writeln!(o, "\n{block} (simplified):");
    for (s, &f) in model.states.iter().zip(&model.drift) {
        let _ = writeln!(o, "  {}{prime} = {}", s.name, r.sde(f));
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
            for (j, &e) in row
                .iter()
                .enumerate()
                .filter(|(_, &e)| model.pool.as_const(e) != Some(0.0))
            {
                any = true;
                let b = m.bounds[i][j];
                let entry = format!("[{}, {}] = {}", m.row_names[i], m.col_names[j], r.sde(e));
                let _ = writeln!(o, "  {entry}    in {b}");
                if !b.is_bounded() {
                    unbounded.push(format!("{} {entry}", m.key));
                }
            }
        }
        if !any {
            let _ = writeln!(o, "  (all zero)");
            continue;
        }
        let _ = writeln!(
            o,
            "  atoms: {} (matrix = constant part + sum of atom * coefficient)",
            m.atoms.atoms.len()
        );
        for (k, (a, range)) in m.atoms.atoms.iter().zip(&m.atom_ranges).enumerate() {
            let at: Vec<String> = a
                .entries
                .iter()
                .map(|(i, j, c)| format!("[{}, {}]*{c}", m.row_names[*i], m.col_names[*j]))
                .collect();
            let _ = writeln!(
                o,
                "    a{} = {}    in {}    at {}",
                k + 1,
                r.sde(a.expr),
                range,
                at.join(", ")
            );
        }
    }
    let _ = writeln!(
        o,
        "\nJacobian D_x G (non-zero entries d G[state, noise] / d state):"
    );
    if r.jac_g.is_empty() {
        let _ = writeln!(o, "  (all zero: additive noise)");
    }
    for (g, b) in &r.jac_g {
        let entry = format!(
            "d G[{}, {}] / d {} = {}",
            model.states[g.row].name,
            model.noises[g.noise].name,
            model.states[g.state].name,
            r.sde(g.expr)
        );
        let _ = writeln!(o, "  {entry}    in {b}");
        if !b.is_bounded() {
            unbounded.push(format!("jacobian_g {entry}"));
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
    out.write_all(o.as_bytes())
}
