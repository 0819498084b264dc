//! What a result shows about the model's unsafe sets and goals.

use crate::model::{Bounds, UnsafeShape};

/// The kind of an unsafe set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnsafeKind {
    /// `{x : a.x >= b}`; margins are Euclidean distances.
    HalfSpace,
    /// A box; margins are the largest per-coordinate gap between the PRS's bounding box and it.
    Box,
    /// A Euclidean ball; margins are Euclidean distances.
    Ball,
}

impl UnsafeKind {
    /// The kind of an unsafe set's shape.
    pub fn of(shape: &UnsafeShape) -> UnsafeKind {
        match shape {
            UnsafeShape::HalfSpace { .. } => UnsafeKind::HalfSpace,
            UnsafeShape::Box(_) => UnsafeKind::Box,
            UnsafeShape::Ball { .. } => UnsafeKind::Ball,
        }
    }
}

/// One unsafe set's verdict over the horizon.
#[derive(Clone, Debug, PartialEq)]
pub struct UnsafeVerdict {
    /// Its name.
    pub name: String,
    /// Its kind (what the margins measure).
    pub kind: UnsafeKind,
    /// Shown safe at every report time.
    pub safe: bool,
    /// Smallest margin over the report times.
    pub min_margin: f64,
    /// Time of the smallest margin.
    pub min_margin_t: f64,
    /// First report time at which safety was not shown.
    pub first_not_safe_t: Option<f64>,
    /// A moving set (method.md 8.15): per report time, the fixed set that held all its
    /// positions over the report interval ending there (the time itself at `t = 0`), which the
    /// margins were computed against. Empty for a fixed set.
    pub swept: Vec<crate::model::UnsafeShape>,
}

/// The overall verdict. A PRS touching an unsafe set does not prove a violation, hence "not
/// shown safe" rather than "unsafe".
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    /// Every PRS is disjoint from every unsafe set.
    Safe,
    /// The spec has no unsafe sets.
    NoUnsafeSets,
    /// The first report time and set for which safety was not shown.
    NotShownSafe {
        /// Time.
        t: f64,
        /// Step index.
        step: usize,
        /// Index of the unsafe set in [`Prs::unsafe_sets`](super::Prs::unsafe_sets).
        set: usize,
    },
}

/// What a result shows about one goal set of the model (method.md 8.13).
#[derive(Clone, Debug, PartialEq)]
pub struct GoalVerdict {
    /// The goal's name.
    pub name: String,
    /// The times at which entering counts: the goal's window, or `[0, T]`.
    pub window: Bounds,
    /// Reach and stay (the state must remain in the goal until the horizon).
    pub stay: bool,
    /// Per report time, how far the PRS lies inside the goal: the smallest Euclidean gap
    /// between its bounding box and the goal's boundary (for a half-space or a ball part), or
    /// per coordinate (for a box part), rounded down; not positive where it is not shown
    /// inside. For reaching alone in a model without unsafe sets, the box is the pointwise one
    /// ([`Prs::pointwise_hull_at`](super::Prs::pointwise_hull_at)).
    pub margins: Vec<f64>,
    /// A moving goal (method.md 8.15): per report time, its parts held still inside all their
    /// positions at that time (the margins' goal). Empty for a fixed goal.
    pub swept: Vec<Vec<crate::model::UnsafeShape>>,
    /// What is shown.
    pub outcome: GoalOutcome,
}

/// The outcome of a [`GoalVerdict`].
#[derive(Clone, Debug, PartialEq)]
pub enum GoalOutcome {
    /// With probability at least `1 - delta`, for every start and input: the state is in the
    /// goal at report time `t` (in the window), having avoided every unsafe set on `[0, t]`;
    /// with `stay`, it also remains in the goal, and away from the unsafe sets, until the
    /// horizon.
    Reached {
        /// The first report time at which this is shown.
        t: f64,
        /// The smallest containment margin involved (at `t`, and with `stay` over the report
        /// intervals to the horizon).
        margin: f64,
    },
    /// Not shown (this does not prove that the goal is missed).
    NotShown(GoalMiss),
    /// A pointwise result bounds each time separately, not the path: no verdict (except for
    /// reaching alone without unsafe sets, a question about one time).
    NeedsUniform,
}

/// Why a goal is not shown reached.
#[derive(Clone, Debug, PartialEq)]
pub enum GoalMiss {
    /// No report time lies in the window.
    NoReportTime,
    /// The tube may meet unsafe set `set` (index into [`Prs::unsafe_sets`](super::Prs::unsafe_sets)) over the report
    /// interval ending at `t`, before the goal is shown reached (with `stay`: before the
    /// horizon).
    Unsafe {
        /// Report time.
        t: f64,
        /// Unsafe set index.
        set: usize,
    },
    /// At no report time in the window is the PRS shown inside the goal: the largest margin,
    /// and when.
    NotInside {
        /// Report time of the largest margin.
        t: f64,
        /// That margin (not positive).
        margin: f64,
    },
    /// The PRS is inside the goal at some report time in the window, but (the last such
    /// time tried) the tube over the report interval ending at `t` is not shown inside.
    Leaves {
        /// Report time.
        t: f64,
    },
}

impl GoalVerdict {
    /// Whether the goal is shown reached.
    pub fn reached(&self) -> bool {
        matches!(self.outcome, GoalOutcome::Reached { .. })
    }
}
