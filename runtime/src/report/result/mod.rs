//! Renderings of a [`Prs`]: JSON (documented in docs/results.md; `json.rs`, through the result
//! file's types in [`schema`](super::schema)), CSV (`csv.rs`) and a text summary (`text.rs`),
//! with the sentences the JSON and the text share (`words.rs`).

mod csv;
mod json;
mod text;
mod words;

pub use csv::write_csv;
pub use json::{to_json, to_json_with, to_json_within, MEMBERS_BUDGET};
pub use text::summary;
pub(crate) use words::unsafe_kind;

use reachc_core::prs::{DetSet, Prs, Role, Step};

/// State indices the CSV and the summary show: the outputs, or all states if there are none.
pub(super) fn shown_states(prs: &Prs) -> Vec<usize> {
    if prs.outputs().is_empty() {
        (0..prs.states().len()).collect()
    } else {
        prs.outputs().to_vec()
    }
}

/// Whether a result's own sets are first-order zonotopes (a member of role
/// [`Role::FirstOrder`] or [`Role::Linearised`]; its set at `t = 0` is the initial box).
pub(super) fn zonotopes(prs: &Prs) -> bool {
    matches!(prs.role(), Role::FirstOrder | Role::Linearised)
}

/// The ranges shown for a box step, `(label, lo, hi)`: the box over the shown states, or with a
/// transform the box in `y` (`y1`, `y2`, ...) and then the parallelotope's interval hull over
/// the shown states.
pub(super) fn box_columns(prs: &Prs, st: &Step) -> Vec<(String, f64, f64)> {
    let at = |v: &[f64], i: usize| v.get(i).copied().unwrap_or(f64::NAN);
    let shown = shown_states(prs).into_iter();
    match &st.det {
        DetSet::Parallelotope {
            lo,
            hi,
            hull_lo,
            hull_hi,
            ..
        } => {
            let ys = (0..prs.states().len()).map(|i| (format!("y{}", i + 1), at(lo, i), at(hi, i)));
            ys.chain(shown.map(|i| (prs.states()[i].clone(), at(hull_lo, i), at(hull_hi, i))))
                .collect()
        }
        DetSet::Box { lo, hi, .. }
        | DetSet::Zonotope {
            hull_lo: lo,
            hull_hi: hi,
            ..
        } => shown
            .map(|i| (prs.states()[i].clone(), at(lo, i), at(hi, i)))
            .collect(),
        DetSet::Ball { .. } => Vec::new(),
    }
}
