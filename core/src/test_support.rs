//! The workspace's shared test fixtures (`test-support/`, crate reachc-test-support), compiled
//! into this crate's unit tests from their files: through the crate, a unit test here would see
//! a second reachc-core whose types are not this one's. The files take the crate's names from
//! this module.

#![allow(dead_code)] // each unit test uses some of the fixtures

use crate::interval::Interval;
use crate::model::{Bounds, Constants, InitialSet, ModelInfo, ModelParts};
use crate::system::System;

#[path = "../../test-support/src/models.rs"]
pub(crate) mod models;
#[path = "../../test-support/src/rng.rs"]
pub(crate) mod rng;
#[path = "../../test-support/src/sets.rs"]
pub(crate) mod sets;
#[path = "../../test-support/src/systems.rs"]
pub(crate) mod systems;
