//! Parts into a report: [`Merger`] checks that parts belong together (the same run, every shard
//! once), sums their counts, keeps the `j` largest distances of their union, and builds the
//! [`SimReport`] (quantiles, Clopper-Pearson bounds, the verdict). An unsharded simulation is one
//! part merged alone, so a merged report is the unsharded one to the bit.

use super::binomial;
use super::error::{MergeError, RunDifference, RunOption};
use super::part::{Part, PartStats, RunInfo};
use super::part_file::run_bytes;
use super::report::{
    Coverage, GoalCheck, HorizonReport, InputsReport, SafetyCheck, SimReport, SimStep, StateSpread,
    TubeReport, UnsafeHits,
};
use super::run::QUANTILE_BYTES;
use super::shard::Shard;
use super::topk::TopK;
use super::InputMode;
use crate::model::Guarantee;
use std::collections::BTreeMap;

/// The parts of one run, added one at a time (memory: the largest `j` distances per report
/// time, twice at most, whatever the number of parts).
pub struct Merger {
    /// The first part's label and run, its bytes (what every other part must equal), shard
    /// count.
    first: Option<(String, RunInfo, Vec<u8>, u64)>,
    /// The shards seen, with their parts' labels.
    seen: BTreeMap<u64, String>,
    stats: Option<PartStats>,
    /// The metric's distances and the states' deviations.
    topk: Option<(TopK, TopK)>,
}

impl Default for Merger {
    fn default() -> Self {
        Merger::new()
    }
}

impl Merger {
    /// No parts yet.
    pub fn new() -> Merger {
        Merger {
            first: None,
            seen: BTreeMap::new(),
            stats: None,
            topk: None,
        }
    }

    /// Adds the part `label` (how errors name it): refused when malformed, from another run
    /// than the parts before it, or of a shard already added.
    pub fn add(&mut self, label: &str, part: Part) -> Result<(), MergeError> {
        let err = Err;
        if let Some(fault) = part.malformed() {
            return err(MergeError::Malformed {
                label: label.to_string(),
                fault,
            });
        }
        match &self.first {
            None => {
                let run = &part.run;
                let (steps, n) = (run.steps.len(), run.states.len());
                let buffers = steps as u64 * (1 + n as u64);
                if run.quantile_rank.saturating_mul(16 * buffers) > QUANTILE_BYTES {
                    return err(MergeError::QuantileMemory {
                        label: label.to_string(),
                        rank: run.quantile_rank,
                        steps,
                        n,
                        max_gib: QUANTILE_BYTES >> 30,
                    });
                }
                let j = usize::try_from(run.quantile_rank).unwrap_or(usize::MAX);
                self.topk = Some((TopK::new(steps, j), TopK::new(steps * n, j)));
                self.first = Some((
                    label.to_string(),
                    run.clone(),
                    run_bytes(run),
                    part.shard.count,
                ));
            }
            Some((first, run, bytes, count)) => {
                if let Some(difference) = difference(run, &part.run, bytes) {
                    return err(MergeError::OtherRun {
                        label: label.to_string(),
                        first: first.clone(),
                        difference,
                    });
                }
                if part.shard.count != *count {
                    return err(MergeError::ShardCount {
                        label: label.to_string(),
                        shard: part.shard,
                        first: first.clone(),
                        count: *count,
                    });
                }
            }
        }
        if let Some(other) = self.seen.get(&part.shard.index) {
            return err(MergeError::Repeated {
                label: label.to_string(),
                other: other.clone(),
                shard: part.shard,
            });
        }
        self.seen.insert(part.shard.index, label.to_string());
        match &mut self.stats {
            Some(s) => s.add(&part.stats),
            None => self.stats = Some(part.stats),
        }
        if let Some(topks) = &mut self.topk {
            for (topk, tops) in [(&mut topks.0, &part.top), (&mut topks.1, &part.state_top)] {
                for (k, top) in tops.iter().enumerate() {
                    top.iter().for_each(|&d| topk.push(k, d));
                }
                topk.tighten();
            }
        }
        Ok(())
    }

    /// The report of the parts added, when they are every shard of one run.
    pub fn finish(self) -> Result<SimReport, MergeError> {
        let (Some((_, run, _, count)), Some(stats), Some((mut topk, mut state_topk))) =
            (self.first, self.stats, self.topk)
        else {
            return Err(MergeError::NoParts);
        };
        let missing: Vec<Shard> = (0..count)
            .filter(|i| !self.seen.contains_key(i))
            .take(10)
            .map(|i| Shard { index: i, count })
            .collect();
        if !missing.is_empty() {
            let more = count - self.seen.len() as u64 - missing.len() as u64;
            return Err(MergeError::Missing {
                missing,
                more,
                have: self.seen.len(),
                count,
            });
        }
        Ok(report(&run, &stats, &mut topk, &mut state_topk))
    }
}

/// Merges labelled parts (see [`Merger`]).
pub fn merge(parts: impl IntoIterator<Item = (String, Part)>) -> Result<SimReport, MergeError> {
    let mut m = Merger::new();
    for (label, part) in parts {
        m.add(&label, part)?;
    }
    m.finish()
}

/// What differs between two runs, `a` of bytes `a_bytes` (as a part file holds them): the first
/// option that does, by name, or the analysis' result; `None` if they are the same to the bit.
fn difference(a: &RunInfo, b: &RunInfo, a_bytes: &[u8]) -> Option<RunDifference> {
    let named = [
        (RunOption::Version, a.version.clone(), b.version.clone()),
        (RunOption::Spec, a.spec_hash.clone(), b.spec_hash.clone()),
        (RunOption::Model, a.model.clone(), b.model.clone()),
        (RunOption::Analysis, a.analysis.clone(), b.analysis.clone()),
        (RunOption::Paths, a.paths.to_string(), b.paths.to_string()),
        (RunOption::Seed, a.seed.to_string(), b.seed.to_string()),
        (
            RunOption::Delta,
            format!("{:?}", a.delta),
            format!("{:?}", b.delta),
        ),
        (
            RunOption::Dt,
            format!("{:?}", a.dt_option),
            format!("{:?}", b.dt_option),
        ),
        (
            RunOption::Inputs,
            a.inputs.name().into(),
            b.inputs.name().into(),
        ),
        (
            RunOption::Hold,
            format!("{:?}", a.hold_option),
            format!("{:?}", b.hold_option),
        ),
        (
            RunOption::Confidence,
            format!("{:?}", a.confidence),
            format!("{:?}", b.confidence),
        ),
        (
            RunOption::ProbabilityBound,
            format!("{:?}", a.safety_bound),
            format!("{:?}", b.safety_bound),
        ),
        (
            RunOption::GoalBounds,
            format!("{:?}", a.goals),
            format!("{:?}", b.goals),
        ),
    ];
    if let Some((option, x, y)) = named.into_iter().find(|(_, x, y)| x != y) {
        return Some(RunDifference::Option {
            option,
            there: y,
            first: x,
        });
    }
    (run_bytes(b) != a_bytes).then_some(RunDifference::Results)
}

/// Quantiles, Clopper-Pearson bounds and the verdict from the merged statistics (`topk`: the
/// largest `run.quantile_rank` squared distances of all paths at each report time;
/// `state_topk`: the largest deviations of each state, entry `k n + i`).
fn report(run: &RunInfo, total: &PartStats, topk: &mut TopK, state_topk: &mut TopK) -> SimReport {
    let n = run.states.len();
    let n_paths = run.paths;
    let frac = |k: u64| k as f64 / n_paths as f64;
    let alpha = 1.0 - run.confidence;
    let alpha_step = alpha / run.steps.len() as f64;
    // Many steps share a count (often 0): compute each bound once.
    let mut upper_cache = BTreeMap::new();
    let mut upper = |k: u64| {
        *upper_cache
            .entry(k)
            .or_insert_with(|| binomial::upper_bound(k, n_paths, alpha))
    };
    let steps: Vec<SimStep> = run
        .steps
        .iter()
        .enumerate()
        .map(|(k, st)| {
            // The buffers hold squared distances (sqrt is monotone: same order statistics).
            let (q2, max2) = topk.result(k).unwrap_or((f64::NAN, f64::NAN));
            let (quantile, max) = (q2.sqrt(), max2.sqrt());
            let outside = total.outside[k];
            let states = st
                .hull
                .iter()
                .enumerate()
                .map(|(i, &prs)| {
                    let (quantile, max) =
                        state_topk.result(k * n + i).unwrap_or((f64::NAN, f64::NAN));
                    StateSpread { quantile, max, prs }
                })
                .collect();
            SimStep {
                t: st.t,
                r_t: st.r_t,
                prs_radius: st.prs_radius,
                quantile,
                max,
                outside,
                fraction: frac(outside),
                cp_upper: upper(outside),
                left_tube: run.tube.then_some(total.left_tube[k]),
                states,
            }
        })
        .collect();
    // The lower bound grows with the count: the step with the most violations decides, and the
    // failing steps are those above the smallest failing count.
    let worst_step = (0..steps.len())
        .max_by(|&a, &b| steps[a].outside.cmp(&steps[b].outside).then(b.cmp(&a)))
        .unwrap_or(0);
    let (worst_t, worst_outside) = (steps[worst_step].t, steps[worst_step].outside);
    let worst_cp_lower = binomial::lower_bound(worst_outside, n_paths, alpha_step);
    let mut lower_cache = BTreeMap::new();
    let failing_steps = steps
        .iter()
        .filter(|s| {
            *lower_cache.entry(s.outside).or_insert_with(|| {
                binomial::lower_bound(s.outside, n_paths, alpha_step) > run.delta
            })
        })
        .count();
    let pointwise_passed = failing_steps == 0;
    let tube = run.tube.then(|| {
        let outside = total.outside_tube;
        TubeReport {
            outside,
            fraction: frac(outside),
            cp_upper: binomial::upper_bound(outside, n_paths, alpha),
            cp_lower: binomial::lower_bound(outside, n_paths, alpha),
            checks_per_path: run.steps_per_path + 1,
        }
    });
    let (passed, decided_by) = match &tube {
        Some(t) => (t.cp_lower <= run.delta, Guarantee::Uniform),
        None => (pointwise_passed, Guarantee::Pointwise),
    };
    let hold = (run.has_inputs && run.inputs != InputMode::Centre)
        .then(|| run.hold_option.unwrap_or(run.step));
    SimReport {
        model: run.model.clone(),
        analysis: run.analysis.clone(),
        states: run.states.clone(),
        method: run.method,
        delta: run.delta,
        guarantee: run.guarantee,
        paths: n_paths,
        seed: run.seed,
        dt: run.dt,
        steps_per_path: run.steps_per_path,
        initial_states: run.initial_states,
        inputs: InputsReport {
            mode: run.inputs,
            hold,
            any: run.has_inputs,
            hold_shown: hold.unwrap_or(run.step),
        },
        noise: run.noise,
        quantile_rank: run.quantile_rank,
        steps,
        confidence: run.confidence,
        horizon: HorizonReport {
            outside_any: total.outside_any,
            fraction: frac(total.outside_any),
            cp_upper: binomial::upper_bound(total.outside_any, n_paths, alpha),
        },
        tube,
        unsafe_sets: run
            .unsafe_sets
            .iter()
            .enumerate()
            .map(|(i, (name, kind))| UnsafeHits {
                name: name.clone(),
                kind: *kind,
                hits: total.unsafe_hits[i],
                fraction: frac(total.unsafe_hits[i]),
                first_hit_t: Some(total.first_hit[i]).filter(|t| t.is_finite()),
            })
            .collect(),
        safety: (!run.unsafe_sets.is_empty()).then(|| {
            let safe = n_paths - total.unsafe_any;
            let cp_upper = 1.0 - binomial::lower_bound(total.unsafe_any, n_paths, alpha);
            SafetyCheck {
                safe,
                fraction: frac(safe),
                cp_upper,
                certified: run.safety_bound,
                passed: run.safety_bound.is_none_or(|b| b <= cp_upper),
            }
        }),
        goals: run
            .goals
            .iter()
            .zip(&total.goal_reached)
            .map(|((name, bound), &reached)| {
                let cp_upper = binomial::upper_bound(reached, n_paths, alpha);
                GoalCheck {
                    name: name.clone(),
                    reached,
                    fraction: frac(reached),
                    cp_upper,
                    certified: *bound,
                    passed: bound.is_none_or(|b| b <= cp_upper),
                }
            })
            .collect(),
        left_domain: run.has_domain.then_some(total.left_domain),
        diverged: total.diverged,
        verdict: Coverage {
            passed,
            decided_by,
            pointwise_passed,
            alpha,
            alpha_per_step: alpha_step,
            failing_steps,
            worst_step,
            worst_t,
            worst_outside,
            worst_cp_lower,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::super::part_file::FORMAT_VERSION;
    use super::super::tests::{info, narrow, sys};
    use super::super::{run_part, simulate, Options};
    use super::*;
    use crate::engine;
    use crate::prs::Prs;
    use crate::system::Paired;
    use crate::test_support::systems::Linear;

    /// The parts of `r` for `shards` shards, each through its file's bytes.
    fn parts(sys: &Linear, r: &Prs, opts: &Options, shards: u64) -> Vec<(String, Part)> {
        let info = info(sys.b);
        (0..shards)
            .map(|i| {
                let shard = Shard::new(i, shards).unwrap();
                let part =
                    run_part(&Paired::new(sys, &info), r, opts, shard, &mut |_, _| {}).unwrap();
                let bytes = part.to_bytes();
                let read = Part::from_bytes(&bytes).unwrap();
                assert_eq!(read, part);
                assert_eq!(read.to_bytes(), bytes);
                (format!("part{i}"), read)
            })
            .collect()
    }

    /// Shards merged, in any order, give the unsharded report to the bit: with inputs and an
    /// unsafe set, for a uniform result (a narrowed tube: many paths leave it) and a pointwise
    /// one; for 1 shard, shards dividing the paths and not, and shards of fewer paths than the
    /// quantile's rank (j = 51 here).
    #[test]
    fn sharded_runs_merge_into_the_unsharded_report() {
        for b in [0.0, 1.0] {
            let (sys, info) = (sys(b), info(b));
            let r = engine::run_paired(&sys, &info, &info.analyses[0]).unwrap();
            let mut pointwise = narrow(&r, 0.5);
            pointwise.guarantee = Guarantee::Pointwise;
            for r in [narrow(&r, 0.5), pointwise] {
                let opts = Options {
                    paths: 1_000,
                    seed: 7,
                    dt: Some(0.005),
                    ..Options::default()
                };
                let whole = simulate(&Paired::new(&sys, &info), &r, &opts, &mut |_, _| {}).unwrap();
                assert_eq!(whole.quantile_rank, 51);
                if r.guarantee == Guarantee::Uniform {
                    assert!(whole.tube.as_ref().unwrap().outside > 30);
                }
                for k in [1, 2, 3, 7, 40] {
                    let mut p = parts(&sys, &r, &opts, k);
                    p.reverse();
                    p.rotate_left(k as usize / 2);
                    assert_eq!(merge(p).unwrap(), whole, "b = {b}, {k} shards");
                }
            }
        }
    }

    fn merge_error(parts: Vec<(String, Part)>) -> String {
        merge(parts).unwrap_err().to_string()
    }

    /// Missing and repeated shards, parts of other runs (seed, paths, shard count, analysis
    /// result) are refused, naming the parts.
    #[test]
    fn merge_refuses_parts_that_do_not_belong_together() {
        let (sys, info) = (sys(0.0), info(0.0));
        let r = engine::run_paired(&sys, &info, &info.analyses[0]).unwrap();
        let opts = Options {
            paths: 200,
            ..Options::default()
        };
        let three = parts(&sys, &r, &opts, 3);
        assert_eq!(
            merge_error(vec![three[0].clone(), three[2].clone()]),
            "missing shard 1/3 (have 2 of 3)"
        );
        assert_eq!(
            merge_error(vec![three[0].clone()]),
            "missing shards 1/3, 2/3 (have 1 of 3)"
        );
        let mut again = three[1].clone();
        again.0 = "copy".into();
        assert_eq!(
            merge_error(vec![three[1].clone(), again]),
            "`copy` and `part1` are both shard 1/3"
        );
        let other = |opts: &Options, r: &Prs, k: u64| parts(&sys, r, opts, k).remove(1);
        let seed = other(
            &Options {
                seed: 1,
                ..opts.clone()
            },
            &r,
            3,
        );
        assert_eq!(
            merge_error(vec![three[0].clone(), seed]),
            "`part1` and `part0` are not parts of the same simulation: seed 1 there, 0 in the \
             first part"
        );
        let paths = other(
            &Options {
                paths: 300,
                ..opts.clone()
            },
            &r,
            3,
        );
        assert!(merge_error(vec![three[0].clone(), paths])
            .ends_with("paths 300 there, 200 in the first part"));
        assert_eq!(
            merge_error(vec![three[0].clone(), other(&opts, &r, 4)]),
            "`part1` is shard 1/4 but `part0` is one of 3 shards"
        );
        assert!(
            merge_error(vec![three[0].clone(), other(&opts, &narrow(&r, 0.5), 3)])
                .ends_with("the analysis' results or the sampling differ (same options)")
        );
        let mut spec = three[1].clone();
        spec.1.run.spec_hash = "abc".into();
        assert!(merge_error(vec![three[0].clone(), spec])
            .ends_with("spec (SHA-256) abc there,  in the first part"));
        assert_eq!(merge_error(vec![]), "no parts to merge");
    }

    /// Parts that are not well formed are refused, not trusted: counts above the paths,
    /// distances out of order or too few.
    #[test]
    fn malformed_parts_are_refused() {
        let (sys, info) = (sys(0.0), info(0.0));
        let r = engine::run_paired(&sys, &info, &info.analyses[0]).unwrap();
        let opts = Options {
            paths: 100,
            ..Options::default()
        };
        let (_, part) = parts(&sys, &r, &opts, 2).remove(0);
        for (what, change) in [
            (
                "counts",
                &(|p: &mut Part| p.stats.diverged = 51) as &dyn Fn(&mut Part),
            ),
            ("counts", &|p| p.stats.outside_tube += 1),
            ("not sorted", &|p| p.top[3].swap(0, 1)),
            ("expected 6", &|p| {
                p.top[2].pop();
            }),
            ("statistics", &|p| {
                p.stats.outside.pop();
            }),
        ] {
            let mut bad = part.clone();
            change(&mut bad);
            let e = merge_error(vec![("bad.part".into(), bad)]);
            assert!(
                e.starts_with("`bad.part` is not a valid part: ") && e.contains(what),
                "{e}"
            );
        }
    }

    /// Bytes that are not a part file, truncated or corrupt ones, another format version: each
    /// a message, never a panic.
    #[test]
    fn bad_part_files_are_refused() {
        let (sys, info) = (sys(0.0), info(0.0));
        let r = engine::run_paired(&sys, &info, &info.analyses[0]).unwrap();
        let opts = Options {
            paths: 50,
            ..Options::default()
        };
        let mut part = parts(&sys, &r, &opts, 1).remove(0).1;
        let bytes = part.to_bytes();
        let read = |b: &[u8]| Part::from_bytes(b).unwrap_err().to_string();
        // A shard that cannot be (index 5 of 3), with a good checksum: refused as it is read.
        part.shard = Shard { index: 5, count: 3 };
        assert_eq!(
            read(&part.to_bytes()),
            "shard 5/3: the index must be below the number of shards (0-based)"
        );
        assert!(read(b"{\"model\": 1}").starts_with("not a reachc simulate part file"));
        assert!(read(&[]).starts_with("not a reachc simulate part file"));
        for cut in [
            MAGIC_LEN,
            MAGIC_LEN + 4,
            MAGIC_LEN + 9,
            bytes.len() / 2,
            bytes.len() - 1,
        ] {
            let e = read(&bytes[..cut]);
            assert!(e.contains("truncated"), "{cut}: {e}");
        }
        let mut corrupt = bytes.clone();
        corrupt[bytes.len() / 2] ^= 1;
        assert_eq!(
            read(&corrupt),
            "corrupt or truncated: the checksum does not match"
        );
        let mut version = bytes.clone();
        version[MAGIC_LEN] = 9;
        assert_eq!(
            read(&version),
            format!("part file format version 9; this reachc reads version {FORMAT_VERSION}")
        );
        let mut longer = bytes.clone();
        longer.extend_from_slice(&[0; 8]);
        assert!(read(&longer).contains("checksum"), "{}", read(&longer));
        // Every cut and every flipped byte: an error, never a panic.
        for i in 0..bytes.len() {
            assert!(Part::from_bytes(&bytes[..i]).is_err());
            let mut b = bytes.clone();
            b[i] ^= 0x80;
            assert!(Part::from_bytes(&b).is_err(), "byte {i}");
        }
    }

    const MAGIC_LEN: usize = crate::simulate::MAGIC.len();
}
