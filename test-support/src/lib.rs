//! The fixtures the workspace's tests share, each written once: deterministic random numbers
//! ([`rng`]), hand-written systems ([`systems`]) and their model data ([`models`]), hand-made
//! sets ([`sets`]), reference flows ([`flow`]), scratch folders and folder listings
//! ([`files`]). A dev-dependency of the crates whose tests use them; never published.
//!
//! reachc-core's own unit tests cannot use this crate (it depends on reachc-core: its types
//! would be another crate's there), so `core/src/test_support.rs` compiles `rng.rs`, `sets.rs`,
//! `systems.rs` and `models.rs` into them from this folder. Those files therefore take the
//! crate's names from their parent module (the `use`s below) and nothing else from outside.

use reachc_core::interval::Interval;
use reachc_core::model::{Bounds, Constants, InitialSet, ModelInfo, ModelParts};
use reachc_core::System;

pub mod files;
pub mod flow;
pub mod models;
pub mod rng;
pub mod sets;
pub mod systems;
