//! An analysis that could not run, as a value: what `run` and `simulate` report for it, and its
//! one-line wire form between a generated binary and the CLI.
//!
//! With `--error-lines`, a generated binary writes each failure to stderr as one line
//!
//! ```text
//! reachc-failure ANALYSIS CULPRIT MESSAGE
//! ```
//!
//! `ANALYSIS` is the analysis' name (an identifier), `CULPRIT` is `-` or a
//! [`Culprit`] token (`state:I`, `setting:KEY`), `MESSAGE` the rest of the line (line breaks
//! in it replaced by spaces). The CLI reads these lines back ([`Failure::parse_line`]) and
//! renders each as a diagnostic located in the spec; this is the only text parsed between them.

use reachc_core::engine::{Culprit, RunError};
use reachc_core::simulate::SimInvalid;
use std::fmt;

/// The prefix of a failure line.
const PREFIX: &str = "reachc-failure ";

/// Why one analysis produced no result (the others are still written).
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    /// The analysis' name.
    pub analysis: String,
    /// What happened, completing "analysis `NAME` ...": "could not run: ...", "cannot be
    /// simulated: ...".
    pub message: String,
    /// The state or setting to look at, when known.
    pub culprit: Option<Culprit>,
}

impl Failure {
    /// An analysis the engine could not run.
    pub fn run(analysis: &str, e: &RunError) -> Failure {
        Failure {
            analysis: analysis.to_string(),
            message: format!("could not run: {e}"),
            culprit: e.culprit(),
        }
    }

    /// An analysis whose result cannot be simulated.
    pub fn simulation(analysis: &str, why: &SimInvalid) -> Failure {
        Failure {
            analysis: analysis.to_string(),
            message: format!("cannot be simulated: {why}"),
            culprit: None,
        }
    }

    /// The last line after `failed` of `of` analyses failed (the others' files written).
    pub fn summary(failed: usize, of: usize) -> String {
        let count = if failed == 1 {
            "1 analysis".to_string()
        } else {
            format!("{failed} analyses")
        };
        if failed < of {
            format!("error: {count} of {of} failed (the others' files are written)")
        } else {
            format!("error: {count} of {of} failed")
        }
    }

    /// The wire form (see the module documentation), without a line break.
    pub fn to_line(&self) -> String {
        let culprit = self
            .culprit
            .map_or_else(|| "-".to_string(), |c| c.to_string());
        let message = self.message.replace(['\n', '\r'], " ");
        format!("{PREFIX}{} {culprit} {message}", self.analysis)
    }

    /// Reads a line written by [`Failure::to_line`]; `None` for any other line.
    pub fn parse_line(line: &str) -> Option<Failure> {
        let rest = line.strip_prefix(PREFIX)?;
        let (analysis, rest) = rest.split_once(' ')?;
        let (culprit, message) = rest.split_once(' ')?;
        let culprit = match culprit {
            "-" => None,
            token => Some(Culprit::parse(token)?),
        };
        Some(Failure {
            analysis: analysis.to_string(),
            message: message.to_string(),
            culprit,
        })
    }
}

/// The prose form: ``error: analysis `NAME` MESSAGE``.
impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "error: analysis `{}` {}", self.analysis, self.message)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use reachc_core::engine::{Detail, Problem, Setting};

    #[test]
    fn failures_round_trip_through_their_lines() {
        let e = RunError::NonFinite(
            Detail::from(Problem::EmpiricalPathNotFinite(0.0)).at_setting(Setting::Step),
        );
        let f = Failure::run("fast", &e);
        assert_eq!(
            f.to_line(),
            "reachc-failure fast setting:step could not run: numerical failure: a sample path of \
             the empirical rate estimate is not finite at t = 0"
        );
        assert_eq!(Failure::parse_line(&f.to_line()), Some(f));
        let simulation = Failure::simulation("a", &SimInvalid::NominalSize);
        assert_eq!(
            simulation.message,
            "cannot be simulated: a nominal state has the wrong dimension"
        );
        let plain = Failure {
            message: "cannot be simulated: two\nlines".into(),
            ..simulation
        };
        let back = Failure::parse_line(&plain.to_line()).unwrap();
        assert_eq!(back.culprit, None);
        assert_eq!(back.message, "cannot be simulated: two lines");
        for other in [
            "reachc-progress a 1 2",
            "reachc-failure a",
            "reachc-failure a setting:speed x",
            "error: analysis `a` could not run",
        ] {
            assert_eq!(Failure::parse_line(other), None, "{other}");
        }
    }
}
