//! A result as CSV: one row per report time.

use super::{box_columns, shown_states, zonotopes};
use crate::report::csv_field;
use reachc_core::model::Method;
use reachc_core::prs::Prs;
use std::fmt::Write as _;
use std::io::{self, Write};

/// CSV with header `t,<output state names...>,det_radius,r_t,psi,c,sigma,prs_radius` and one
/// row per report time (the nominal state in the state columns). For the interval method (box
/// sets) the header is `t,<state>_lo,<state>_hi,...,r_t,psi` instead; with a coordinate
/// transform, `t,y1_lo,y1_hi,...,yn_lo,yn_hi,<state>_lo,<state>_hi,...,r_t,psi` (the box in
/// `y = T x`, then the parallelotope's interval hull in the output states). For first-order
/// zonotopes, `t,<state>_lo,<state>_hi,...,remainder,r_t,psi`: the zonotope's interval hull and
/// the P-radius of the ball added to it (the PRS is `Z (+) B_P(remainder + r_t)`).
pub fn write_csv(prs: &Prs, w: &mut dyn Write) -> io::Result<()> {
    let shown = shown_states(prs);
    let zonotopes = zonotopes(prs);
    if prs.method() == Method::Interval || zonotopes {
        let mut header = String::from("t");
        if let Some(first) = prs.steps().first() {
            for (label, _, _) in box_columns(prs, first) {
                let _ = write!(
                    header,
                    ",{},{}",
                    csv_field(&format!("{label}_lo")),
                    csv_field(&format!("{label}_hi"))
                );
            }
        }
        if zonotopes {
            header.push_str(",remainder");
        }
        header.push_str(",r_t,psi");
        writeln!(w, "{header}")?;
        for s in prs.steps() {
            let mut row = format!("{}", s.t);
            for (_, a, b) in box_columns(prs, s) {
                let _ = write!(row, ",{a},{b}");
            }
            if zonotopes {
                let _ = write!(row, ",{}", s.det.ball_added());
            }
            let _ = write!(row, ",{},{}", s.r_t, s.psi);
            writeln!(w, "{row}")?;
        }
        return Ok(());
    }
    let mut header = String::from("t");
    for &i in &shown {
        header.push(',');
        header.push_str(&csv_field(&prs.states()[i]));
    }
    header.push_str(",det_radius,r_t,psi,c,sigma,prs_radius");
    // Several metrics: the radii are the first metric's; the PRS is the intersection, whose
    // bounding box follows.
    let boxes = !prs.also().is_empty();
    if boxes {
        for &i in &shown {
            let name = &prs.states()[i];
            let _ = write!(
                header,
                ",{},{}",
                csv_field(&format!("prs_{name}_lo")),
                csv_field(&format!("prs_{name}_hi"))
            );
        }
    }
    writeln!(w, "{header}")?;
    for (k, s) in prs.steps().iter().enumerate() {
        let mut row = format!("{}", s.t);
        for &i in &shown {
            let _ = write!(row, ",{}", s.nominal()[i]);
        }
        let _ = write!(
            row,
            ",{},{},{},{},{},{}",
            s.det.radius(),
            s.r_t,
            s.psi,
            s.c,
            s.sigma,
            s.prs_radius
        );
        if let (true, Some(hull)) = (boxes, prs.hull_at(k)) {
            for &i in &shown {
                let _ = write!(row, ",{},{}", hull[i].lo, hull[i].hi);
            }
        }
        writeln!(w, "{row}")?;
    }
    Ok(())
}
