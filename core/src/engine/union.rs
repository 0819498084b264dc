//! Splitting the initial set (method.md 8.11): the initial box cut into pieces, each run at the
//! full delta, and the union of their sets as one result. Every path starts in exactly one
//! piece, and on that piece's event (probability at least `1 - delta`) it lies in that piece's
//! PRS, so it lies in the union with probability at least `1 - delta`: no union bound over the
//! pieces.

use super::assemble::verdicts;
use super::intersect::absorb;
use super::radius::BoxRadius;
use super::safety::Check;
use crate::interval::Interval;
use crate::model::{Bounds, InitialSet, ModelInfo, Split};
use crate::prs::{DetSet, Prs, Span, Step};

/// The pieces of the box `b` cut into `counts[i]` equal parts along state `i`, in the order of
/// the last state varying fastest. Neighbouring pieces share their cut (the same floating-point
/// number ends one and starts the next), so the pieces cover the box with no gap.
pub(crate) fn pieces(b: &[Bounds], counts: &[usize]) -> Vec<Vec<Bounds>> {
    // The cut `j` of `k` along `[lo, hi]`: `lo + (hi - lo) j / k`, the ends exact.
    let cut = |x: &Bounds, j: usize, k: usize| -> f64 {
        if j == 0 {
            x.lo
        } else if j == k {
            x.hi
        } else {
            (x.lo + (x.hi - x.lo) * (j as f64 / k as f64)).clamp(x.lo, x.hi)
        }
    };
    let mut out = vec![Vec::with_capacity(b.len())];
    for (x, &k) in b.iter().zip(counts) {
        out = out
            .into_iter()
            .flat_map(|piece| {
                (0..k).map(move |j| {
                    let mut p = piece.clone();
                    p.push(Bounds::new(cut(x, j, k), cut(x, j + 1, k)));
                    p
                })
            })
            .collect();
    }
    out
}

/// The union of `pieces` (the results of one analysis from the pieces of `initial`, each at
/// the analysis' delta, on the same report times) as one result: per report time its bounding
/// box, the box of its spans, the smallest margin of any piece per unsafe set (the union misses
/// an unsafe set only where every piece does) and the verdicts those margins give; the pieces
/// themselves in [`Prs::pieces`], which [`Prs::contains`] and [`Prs::span_contains`] ask.
pub(crate) fn union(
    info: &ModelInfo,
    checks: &[Check],
    initial: &InitialSet,
    split: Split,
    pieces: Vec<Prs>,
) -> Prs {
    let mut u = pieces[0].clone();
    let n = u.n();
    u.also = Vec::new();
    u.regions = Vec::new();
    u.initial = initial.clone();
    if let Ok(b) = initial.bounding_box() {
        u.initial_center = b.iter().map(|x| Interval::new(x.lo, x.hi).mid()).collect();
    }
    let norm = BoxRadius::new(&u.constants.metric, n);
    let hull = |a: Option<Vec<Bounds>>, b: Vec<Bounds>| -> Vec<Bounds> {
        match a {
            None => b,
            Some(a) => a
                .iter()
                .zip(&b)
                .map(|(a, b)| Bounds::new(a.lo.min(b.lo), a.hi.max(b.hi)))
                .collect(),
        }
    };
    let everything = || vec![Bounds::new(f64::NEG_INFINITY, f64::INFINITY); n];
    let steps: Vec<Step> = (0..u.steps.len())
        .map(|k| {
            let (mut set, mut span) = (None, None);
            let mut margins = vec![f64::INFINITY; checks.len()];
            let mut worst = pieces[0].steps[k].clone();
            for p in &pieces {
                let st = &p.steps[k];
                set = Some(hull(set, p.hull_at(k).unwrap_or_else(everything)));
                // The piece's span: its own, cut by its members' (an intersection).
                let own = p.own_span_hull_at(k).unwrap_or_else(everything);
                let cut = p.also.iter().fold(own, |b, m| {
                    let w = m.own_span_hull_at(k).unwrap_or_else(everything);
                    b.iter()
                        .zip(&w)
                        .map(|(a, o)| {
                            let (lo, hi) = (a.lo.max(o.lo), a.hi.min(o.hi));
                            Bounds::new(lo, hi.max(lo))
                        })
                        .collect()
                });
                span = Some(hull(span, cut));
                for (m, &o) in margins.iter_mut().zip(&st.margins) {
                    // NaN never counts as safe.
                    if o < *m || o.is_nan() {
                        *m = o;
                    }
                }
                worst.r_pointwise = worst.r_pointwise.max(st.r_pointwise);
                worst.psi = worst.psi.max(st.psi);
                worst.c = worst.c.max(st.c);
                worst.sigma = worst.sigma.max(st.sigma);
            }
            let (set, span) = (
                set.unwrap_or_else(everything),
                span.unwrap_or_else(everything),
            );
            let (lo, hi): (Vec<f64>, Vec<f64>) = set.iter().map(|b| (b.lo, b.hi)).unzip();
            // The box about its midpoint (`rad`: a half-width holding it).
            let (center, half): (Vec<f64>, Vec<f64>) = set
                .iter()
                .map(|b| {
                    let x = Interval::new(b.lo, b.hi);
                    (x.mid(), x.rad())
                })
                .unzip();
            let radius = norm.bound(&half);
            Step {
                t: worst.t,
                det: DetSet::Box {
                    lo,
                    hi,
                    center,
                    radius,
                },
                r_t: 0.0,
                r_span: 0.0,
                prs_radius: radius,
                span: Span {
                    lo: span.iter().map(|b| b.lo).collect(),
                    hi: span.iter().map(|b| b.hi).collect(),
                    radius: 0.0,
                },
                margins,
                ..worst
            }
        })
        .collect();
    let swept = u.unsafe_sets.iter().map(|v| v.swept.clone()).collect();
    let (unsafe_sets, verdict) = verdicts(info, checks, &steps, swept);
    u.steps = steps;
    u.unsafe_sets = unsafe_sets;
    u.verdict = verdict;
    u.internal_steps = pieces.iter().map(|p| p.internal_steps).sum();
    u.r1 = pieces.iter().map(|p| p.r1).fold(0.0, f64::max);
    u.rate.max_c = pieces
        .iter()
        .map(|p| p.rate.max_c)
        .fold(f64::NEG_INFINITY, f64::max);
    u.rate.min_c = pieces
        .iter()
        .map(|p| p.rate.min_c)
        .fold(f64::INFINITY, f64::min);
    u.rate.global_from = pieces
        .iter()
        .filter_map(|p| p.rate.global_from)
        .reduce(f64::min);
    u.kappa = pieces.iter().map(|p| p.kappa).fold(0.0, f64::max);
    u.hints = Vec::new();
    for p in &pieces {
        absorb(&mut u.validation, &p.validation);
        // One hint of each kind (the first piece's): the advice is about the model.
        for h in &p.hints {
            let kind = std::mem::discriminant(h);
            if !u.hints.iter().any(|o| std::mem::discriminant(o) == kind) {
                u.hints.push(h.clone());
            }
        }
    }
    u.split = split;
    u.pieces = pieces;
    u
}
