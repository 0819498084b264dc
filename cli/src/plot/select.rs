//! Which two states and which report times a figure shows: the command-line choices resolved
//! against a result (or an analysis), with messages naming what exists.

/// Default number of times drawn.
const DEFAULT_TIMES: usize = 4;

/// The plotted states `(horizontal, vertical)` by name (`requested`, exactly two) or, by
/// default, the first two output states (the first two states when there are fewer outputs).
pub fn pick_states(
    states: &[String],
    outputs: &[usize],
    requested: Option<&[String]>,
) -> Result<[usize; 2], String> {
    let Some(names) = requested else {
        let mut chosen: Vec<usize> = outputs.to_vec();
        chosen.extend(0..states.len());
        chosen.dedup();
        let mut it = chosen.iter().copied().filter(|&i| i < states.len());
        let first = it.next();
        let second = it.find(|&i| Some(i) != first);
        return match (first, second) {
            (Some(a), Some(b)) => Ok([a, b]),
            _ => Err(format!(
                "a 2-D plot needs two states; the model has {}",
                states.len()
            )),
        };
    };
    let [a, b] = names else {
        return Err(format!(
            "give exactly two states to plot (A,B), not {}",
            names.len()
        ));
    };
    let index = |name: &str| {
        states
            .iter()
            .position(|s| s == name)
            .ok_or_else(|| format!("no state `{name}` (the states are: {})", states.join(", ")))
    };
    let (ia, ib) = (index(a)?, index(b)?);
    if ia == ib {
        return Err(format!("plot two different states, not `{a}` twice"));
    }
    Ok([ia, ib])
}

/// The indices of the report times to draw: the nearest report time to each requested time
/// (which must lie within the report times), or about four evenly spaced times ending with the
/// last. Sorted, without repeats.
pub fn pick_times(times: &[f64], requested: Option<&[f64]>) -> Result<Vec<usize>, String> {
    let (first, last) = match (times.first(), times.last()) {
        (Some(&f), Some(&l)) => (f, l),
        _ => return Err("the result has no report times".into()),
    };
    let nearest = |t: f64| {
        (0..times.len())
            .min_by(|&i, &j| (times[i] - t).abs().total_cmp(&(times[j] - t).abs()))
            .unwrap_or(0)
    };
    let mut picked: Vec<usize> = match requested {
        Some(ts) => {
            let slack = 1e-9 * last.abs().max(1.0);
            if let Some(t) = ts
                .iter()
                .find(|&&t| !(t >= first - slack && t <= last + slack))
            {
                return Err(format!(
                    "time {t} is outside the report times [{first}, {last}]"
                ));
            }
            ts.iter().map(|&t| nearest(t)).collect()
        }
        None => (1..=DEFAULT_TIMES)
            .map(|k| nearest(first + (last - first) * k as f64 / DEFAULT_TIMES as f64))
            .collect(),
    };
    picked.sort_unstable();
    picked.dedup();
    Ok(picked)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn states_by_name_or_from_the_outputs() {
        let states = names(&["px", "py", "theta"]);
        assert_eq!(pick_states(&states, &[0, 1], None), Ok([0, 1]));
        assert_eq!(pick_states(&states, &[2], None), Ok([2, 0]));
        assert_eq!(
            pick_states(&states, &[], Some(&names(&["theta", "px"]))),
            Ok([2, 0])
        );
        let err = pick_states(&states, &[], Some(&names(&["px", "vx"]))).unwrap_err();
        assert!(
            err.contains("no state `vx`") && err.contains("px, py, theta"),
            "{err}"
        );
        assert!(pick_states(&states, &[], Some(&names(&["px"]))).is_err());
        assert!(pick_states(&states, &[], Some(&names(&["px", "px"]))).is_err());
        assert!(pick_states(&names(&["x"]), &[0], None).is_err());
    }

    #[test]
    fn times_snap_to_report_times() {
        let times: Vec<f64> = (0..=400).map(|k| f64::from(k) * 0.01).collect();
        assert_eq!(pick_times(&times, None), Ok(vec![100, 200, 300, 400]));
        assert_eq!(
            pick_times(&times, Some(&[0.5, 0.0, 0.501])),
            Ok(vec![0, 50])
        );
        assert!(pick_times(&times, Some(&[4.5]))
            .unwrap_err()
            .contains("outside"));
        // Fewer report times than the default count: each at most once.
        assert_eq!(pick_times(&[0.0, 1.0], None), Ok(vec![0, 1]));
    }
}
