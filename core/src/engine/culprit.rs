//! What in the spec a run-time failure points at: a state, or a setting of the analysis block.
//! The CLI turns a [`Culprit`] into a source span (the state's declaration, the setting's line)
//! and renders the failure like a compile-time diagnostic.

use super::problem::{Note, Problem};
use std::fmt;

/// A setting of an `analysis` block (docs/language.md, "Analyses"): the one to change.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Setting {
    /// `method = contraction | interval`.
    Method,
    /// `delta = ...`.
    Delta,
    /// `horizon = ...`.
    Horizon,
    /// `step = ...` (the report step).
    Step,
    /// `metric = ...`.
    Metric,
    /// `radius = ...`.
    Radius,
    /// `rate = ...`.
    Rate,
    /// `inclusion = ...` (interval method).
    Inclusion,
    /// `integrator = ...`.
    Integrator,
    /// `guarantee = ...`.
    Guarantee,
    /// `transform = ...` (interval method).
    Transform,
    /// `outputs = [...]`.
    Outputs,
    /// `first_order = on | off`.
    FirstOrder,
    /// `split = [..]`.
    Split,
}

impl Setting {
    /// Every setting, in the order docs/language.md lists them.
    pub const ALL: [Setting; 14] = [
        Setting::Method,
        Setting::Delta,
        Setting::Horizon,
        Setting::Step,
        Setting::Metric,
        Setting::Radius,
        Setting::Rate,
        Setting::Inclusion,
        Setting::Integrator,
        Setting::Guarantee,
        Setting::Transform,
        Setting::Outputs,
        Setting::FirstOrder,
        Setting::Split,
    ];

    /// The setting's key as a spec writes it: `horizon`, `step`, ...
    pub fn key(self) -> &'static str {
        match self {
            Setting::Method => "method",
            Setting::Delta => "delta",
            Setting::Horizon => "horizon",
            Setting::Step => "step",
            Setting::Metric => "metric",
            Setting::Radius => "radius",
            Setting::Rate => "rate",
            Setting::Inclusion => "inclusion",
            Setting::Integrator => "integrator",
            Setting::Guarantee => "guarantee",
            Setting::Transform => "transform",
            Setting::Outputs => "outputs",
            Setting::FirstOrder => "first_order",
            Setting::Split => "split",
        }
    }

    /// The setting whose key is `key`.
    pub fn from_key(key: &str) -> Option<Setting> {
        Setting::ALL.into_iter().find(|s| s.key() == key)
    }
}

/// What a run-time failure points at in the spec, when the engine knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Culprit {
    /// A state, by its index in the model (its declaration).
    State(usize),
    /// A setting of the failing analysis' block (its line, or the block when it is a default).
    Setting(Setting),
}

/// The token form, `state:I` or `setting:KEY` (one word: part of the failure lines of
/// generated binaries, `reachc_runtime::app::Failure`).
impl fmt::Display for Culprit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Culprit::State(i) => write!(f, "state:{i}"),
            Culprit::Setting(s) => write!(f, "setting:{}", s.key()),
        }
    }
}

impl Culprit {
    /// Reads the token form written by `Display` (`None` for anything else).
    pub fn parse(token: &str) -> Option<Culprit> {
        match token.split_once(':')? {
            ("state", i) => i.parse().ok().map(Culprit::State),
            ("setting", key) => Setting::from_key(key).map(Culprit::Setting),
            _ => None,
        }
    }
}

/// Why an analysis could not run: the problem, what in the spec it points at, and the
/// circumstances (the piece of a split box, ...). Its `Display` (the words) is in
/// `core/src/words.rs`.
#[derive(Clone, Debug, PartialEq)]
pub struct Detail {
    /// What went wrong, with what it is about (boxed: results stay small).
    pub problem: Box<Problem>,
    /// The state or setting to look at, when the engine knows it.
    pub culprit: Option<Culprit>,
    /// Circumstances, in the order they were added.
    pub notes: Vec<Note>,
}

impl Detail {
    /// The same problem pointing at `culprit`.
    pub fn at(self, culprit: Culprit) -> Detail {
        Detail {
            culprit: Some(culprit),
            ..self
        }
    }

    /// The same problem pointing at the setting `setting`.
    pub fn at_setting(self, setting: Setting) -> Detail {
        self.at(Culprit::Setting(setting))
    }
}

impl From<Problem> for Detail {
    fn from(problem: Problem) -> Detail {
        Detail {
            problem: Box::new(problem),
            culprit: None,
            notes: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn culprits_round_trip_through_their_tokens() {
        for c in Setting::ALL
            .map(Culprit::Setting)
            .into_iter()
            .chain([Culprit::State(0), Culprit::State(1999)])
        {
            assert_eq!(Culprit::parse(&c.to_string()), Some(c));
        }
        assert_eq!(
            Culprit::Setting(Setting::Horizon).to_string(),
            "setting:horizon"
        );
        for bad in ["state:x", "setting:speed", "horizon", "state:-1", ""] {
            assert_eq!(Culprit::parse(bad), None, "{bad}");
        }
    }
}
