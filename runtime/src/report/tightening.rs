//! Renderings of a [`Tightening`] (method.md 8.14): the CSV of the tightened constraints and
//! inflated unsafe sets per report interval (`reachc run --tighten`, docs/results.md), and the
//! summary's line.

use super::{csv_field, num};
use reachc_core::engine::{Constraint, Tightening};
use reachc_core::model::{Bounds, UnsafeShape};
use std::fmt::Write as _;
use std::io::{self, Write};

/// The CSV: `t`, then per constraint `cJ.bound` (a half-space, `J` its place from 1) or
/// `cJ.STATE_lo,cJ.STATE_hi` (a box), then per unsafe set `NAME.offset` (a half-space
/// `normal . x >= offset`), `NAME.STATE_lo,NAME.STATE_hi` (a box) or `NAME.radius` (a ball):
/// the sets as the nominal must meet (constraints) or avoid (unsafe sets) them over the report
/// interval ending at `t`. `states` names the model's states.
pub fn write_csv(t: &Tightening, states: &[String], w: &mut dyn Write) -> io::Result<()> {
    let Some(first) = t.steps.first() else {
        return writeln!(w, "t");
    };
    let box_labels = |name: &str, coords: &[(usize, Bounds)], out: &mut String| {
        for (i, _) in coords {
            let state = states.get(*i).map_or("?", String::as_str);
            let _ = write!(
                out,
                ",{},{}",
                csv_field(&format!("{name}.{state}_lo")),
                csv_field(&format!("{name}.{state}_hi"))
            );
        }
    };
    let mut header = String::from("t");
    for (j, c) in first.constraints.iter().enumerate() {
        let name = format!("c{}", j + 1);
        match c {
            Constraint::HalfSpace { .. } => {
                let _ = write!(header, ",{name}.bound");
            }
            Constraint::Box(coords) => box_labels(&name, coords, &mut header),
        }
    }
    for u in &first.unsafe_sets {
        match &u.shape {
            UnsafeShape::HalfSpace { .. } => {
                let _ = write!(header, ",{}", csv_field(&format!("{}.offset", u.name)));
            }
            UnsafeShape::Box(coords) => box_labels(&u.name, coords, &mut header),
            UnsafeShape::Ball { .. } => {
                let _ = write!(header, ",{}", csv_field(&format!("{}.radius", u.name)));
            }
        }
    }
    writeln!(w, "{header}")?;
    let ranges = |coords: &[(usize, Bounds)], row: &mut String| {
        for (_, b) in coords {
            let _ = write!(row, ",{},{}", b.lo, b.hi);
        }
    };
    for st in &t.steps {
        let mut row = format!("{}", st.t);
        for c in &st.constraints {
            match c {
                Constraint::HalfSpace { bound, .. } => {
                    let _ = write!(row, ",{bound}");
                }
                Constraint::Box(coords) => ranges(coords, &mut row),
            }
        }
        for u in &st.unsafe_sets {
            match &u.shape {
                UnsafeShape::HalfSpace { offset, .. } => {
                    let _ = write!(row, ",{offset}");
                }
                UnsafeShape::Box(coords) => ranges(coords, &mut row),
                UnsafeShape::Ball { radius, .. } => {
                    let _ = write!(row, ",{radius}");
                }
            }
        }
        writeln!(w, "{row}")?;
    }
    Ok(())
}

/// The summary's line where the tightening could not be computed, and why.
pub fn not_computed(why: &dyn std::fmt::Display) -> String {
    format!("tightening: not computed: {why}")
}

/// The summary's line: per unsafe set of `original` (the model's), how far the tightening moves
/// it at most over the horizon (the largest distance a face, an offset or a radius moves).
pub fn line(original: &[reachc_core::model::UnsafeSet], t: &Tightening) -> String {
    let moved: Vec<String> = original
        .iter()
        .enumerate()
        .map(|(j, u)| {
            let most = t
                .steps
                .iter()
                .map(|st| moved_by(&u.shape, &st.unsafe_sets[j].shape))
                .fold(0.0f64, f64::max);
            format!("`{}` by up to {}", u.name, num(most))
        })
        .collect();
    format!(
        "tightened for a nominal plan (method.md 8.14): unsafe sets inflated, {}",
        moved.join(", ")
    )
}

/// The largest distance between the numbers of two versions of one shape (offsets, faces,
/// radii).
fn moved_by(a: &UnsafeShape, b: &UnsafeShape) -> f64 {
    match (a, b) {
        (UnsafeShape::HalfSpace { offset: x, .. }, UnsafeShape::HalfSpace { offset: y, .. }) => {
            (x - y).abs()
        }
        (UnsafeShape::Box(x), UnsafeShape::Box(y)) => {
            // (An infinite face does not move.)
            let gap = |p: f64, q: f64| if p.is_finite() { (p - q).abs() } else { 0.0 };
            x.iter()
                .zip(y)
                .map(|((_, p), (_, q))| gap(p.lo, q.lo).max(gap(p.hi, q.hi)))
                .fold(0.0, f64::max)
        }
        (UnsafeShape::Ball { radius: x, .. }, UnsafeShape::Ball { radius: y, .. }) => (x - y).abs(),
        _ => f64::NAN,
    }
}
