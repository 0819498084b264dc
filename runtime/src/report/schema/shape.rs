//! The JSON form of an unsafe set's or a goal part's shape, one for every document that writes
//! shapes: `reachc inspect --json` (`unsafe`, `goals[].parts`; docs/language.md) and the result
//! file's `swept` positions of moving sets (docs/results.md).

use super::nullable;
use reachc_core::model::UnsafeShape;
use serde::{Deserialize, Serialize};

/// A shape: `{"kind": "box", "sides": [{"state", "range"}]}`,
/// `{"kind": "ball", "over", "center", "radius"}` or `{"kind": "halfspace", "normal", "offset"}`
/// (the set `normal . x >= offset`). States by name; an infinite end of a range is `null`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ShapeJson {
    /// A box: the ranges of the states it constrains.
    Box {
        /// One range per constrained state.
        sides: Vec<SideJson>,
    },
    /// A ball over some states (a moving ball's numbers may be `null`: not finite).
    Ball {
        /// The states it is over, in the order of `center`.
        over: Vec<String>,
        /// Its centre.
        #[serde(deserialize_with = "nullable::numbers")]
        center: Vec<f64>,
        /// Its radius.
        #[serde(deserialize_with = "nullable::number")]
        radius: f64,
    },
    /// A half-space `normal . x >= offset` (a moving offset may be `null`: not finite).
    #[serde(rename = "halfspace")]
    HalfSpace {
        /// One coefficient per state.
        normal: Vec<f64>,
        /// The offset.
        #[serde(deserialize_with = "nullable::number")]
        offset: f64,
    },
}

/// One side of a box: a state and its range `[lo, hi]` (`null`: unbounded on that side).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SideJson {
    /// The state's name.
    pub state: String,
    /// Its range.
    #[serde(deserialize_with = "nullable::range")]
    pub range: [f64; 2],
}

impl ShapeJson {
    /// `shape`, its states named by `states` (`?` for an index out of range).
    pub fn of(states: &[String], shape: &UnsafeShape) -> ShapeJson {
        let name = |i: &usize| states.get(*i).map_or("?", String::as_str).to_string();
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
                center: center.clone(),
                radius: *radius,
            },
            UnsafeShape::HalfSpace { normal, offset } => ShapeJson::HalfSpace {
                normal: normal.clone(),
                offset: *offset,
            },
        }
    }
}
