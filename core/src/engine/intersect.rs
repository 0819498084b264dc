//! Several metrics at once (method.md section 8.6): the results of one analysis under `K`
//! metrics, each at `delta / K`, hold at once with probability `1 - delta` (union bound), so
//! the PRS is the intersection of their sets.

use super::assemble::verdicts;
use super::safety::Check;
use super::Run;
use crate::model::ModelInfo;
use crate::prs::{Prs, Validation};

/// The intersection of `first` and `others` (results of the same analysis and run, on the same
/// report times, each at `delta / K`) as one result at `delta`: a margin of the intersection is
/// at least the largest of the members' (the intersection lies in each), and the verdicts
/// follow from those margins. `checks` are `first`'s.
pub(crate) fn intersect(
    info: &ModelInfo,
    checks: &[Check],
    delta: f64,
    mut first: Prs,
    others: Vec<Prs>,
) -> Prs {
    // One level of members: a member's own members join the list (their margins are already
    // in the member's).
    let mut members = std::mem::take(&mut first.also);
    for mut other in others {
        let theirs = std::mem::take(&mut other.also);
        members.push(other);
        members.extend(theirs);
    }
    let others = members;
    for (k, step) in first.steps.iter_mut().enumerate() {
        for other in &others {
            let theirs = &other.steps[k];
            debug_assert_eq!(theirs.t, step.t, "members share the report times");
            for (m, &o) in step.margins.iter_mut().zip(&theirs.margins) {
                // NaN never counts as safe: keep it only if no member shows more.
                if o > *m || m.is_nan() {
                    *m = o;
                }
            }
        }
    }
    for other in &others {
        absorb(&mut first.validation, &other.validation);
    }
    let swept = first.unsafe_sets.iter().map(|v| v.swept.clone()).collect();
    let (unsafe_sets, verdict) = verdicts(info, checks, &first.steps, swept);
    first.unsafe_sets = unsafe_sets;
    first.verdict = verdict;
    first.delta = delta;
    first.also = others;
    first
}

/// What a result combined of `from` and others leaves unproved or conditional: `into`'s and
/// `from`'s (each unproved item once).
pub(super) fn absorb(into: &mut Validation, from: &Validation) {
    into.conditional_on_domain |= from.conditional_on_domain;
    for item in &from.not_validated {
        if !into.not_validated.contains(item) {
            into.not_validated.push(item.clone());
        }
    }
}

/// `main` intersected with those of `members` that cut it somewhere (results of the same run
/// with the same stochastic radii, so at the same delta: method.md 8.7, 8.8); `main` itself
/// when none does.
pub(crate) fn cut_by(run: &Run, main: Prs, mut members: Vec<Prs>) -> Prs {
    members.retain(|m| cuts(&main, m));
    if members.is_empty() {
        main
    } else {
        intersect(run.info, &run.setup.checks, run.spec.delta, main, members)
    }
}

/// Whether `boxes` makes `ball` smaller somewhere: a tighter bound of a coordinate at a report
/// time, or a larger safety margin.
fn cuts(ball: &Prs, boxes: &Prs) -> bool {
    ball.steps
        .iter()
        .zip(&boxes.steps)
        .enumerate()
        .any(|(k, (a, b))| {
            let tighter = match (ball.own_hull_at(k), boxes.own_hull_at(k)) {
                (Some(x), Some(y)) => x.iter().zip(&y).any(|(x, y)| y.lo > x.lo || y.hi < x.hi),
                _ => false,
            };
            tighter || a.margins.iter().zip(&b.margins).any(|(x, y)| y > x)
        })
}
