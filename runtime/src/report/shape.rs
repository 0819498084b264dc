//! The JSON form of an unsafe set's or a goal part's shape, one for every document that writes
//! shapes: `reachc inspect --json` (`unsafe`, `goals[].parts`; docs/language.md) and the result
//! file's `swept` positions of moving sets (docs/results.md).

use reachc_core::model::UnsafeShape;
use serde::Serialize;

/// A shape: `{"kind": "box", "sides": [{"state", "range"}]}`,
/// `{"kind": "ball", "over", "center", "radius"}` or `{"kind": "halfspace", "normal", "offset"}`
/// (the set `normal . x >= offset`). States by name; an infinite end of a range is `null`.
#[derive(Debug, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ShapeJson<'a> {
    /// A box: the ranges of the states it constrains.
    Box {
        /// One range per constrained state.
        sides: Vec<SideJson<'a>>,
    },
    /// A ball over some states.
    Ball {
        /// The states it is over, in the order of `center`.
        over: Vec<&'a str>,
        /// Its centre.
        center: &'a [f64],
        /// Its radius.
        radius: f64,
    },
    /// A half-space `normal . x >= offset`.
    #[serde(rename = "halfspace")]
    HalfSpace {
        /// One coefficient per state.
        normal: &'a [f64],
        /// The offset.
        offset: f64,
    },
}

/// One side of a box: a state and its range `[lo, hi]`.
#[derive(Debug, Serialize)]
pub struct SideJson<'a> {
    /// The state's name.
    pub state: &'a str,
    /// Its range.
    pub range: [f64; 2],
}

impl<'a> ShapeJson<'a> {
    /// `shape`, its states named by `states`.
    pub fn of(states: &'a [String], shape: &'a UnsafeShape) -> ShapeJson<'a> {
        let name = |i: &usize| states.get(*i).map_or("?", String::as_str);
        match shape {
            UnsafeShape::Box(sides) => ShapeJson::Box {
                sides: sides
                    .iter()
                    .map(|(i, b)| SideJson {
                        state: name(i),
                        range: [b.lo, b.hi],
                    })
                    .collect(),
            },
            UnsafeShape::Ball {
                states: over,
                center,
                radius,
            } => ShapeJson::Ball {
                over: over.iter().map(name).collect(),
                center,
                radius: *radius,
            },
            UnsafeShape::HalfSpace { normal, offset } => ShapeJson::HalfSpace {
                normal,
                offset: *offset,
            },
        }
    }
}
