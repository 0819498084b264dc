//! Every limit the front end enforces, in one place (docs/language.md, section "Limits", lists
//! them with their diagnostics). They bound the work and memory of every later stage on hostile
//! input; each was chosen so that a spec at the limit still goes through `inspect`, `run` and
//! `build` (the figures measured are in the docs).

/// Largest accepted spec file, in bytes (read no further: a special file stops here).
pub const MAX_SOURCE_LEN: usize = 8 * 1024 * 1024;

/// Largest accepted CSV table file, in bytes (read no further, as for specs).
pub const MAX_TABLE_LEN: usize = 8 * 1024 * 1024;

/// Deepest accepted nesting of parentheses, brackets, calls, indices, unary minus, `^` and blocks.
pub const MAX_DEPTH: usize = 200;

/// Most operators on one path of an expression tree (a chain `a + b + c + ...` counts each).
pub const MAX_HEIGHT: usize = 1000;

/// Most statements (and loop iterations) that unrolling `for` loops may produce in one spec,
/// counted while unrolling so the error comes at once.
pub const MAX_UNROLLED: usize = 100_000;

/// Most states of a model (families unrolled).
pub const MAX_STATES: usize = 2_000;

/// Most inputs of a model (families unrolled).
pub const MAX_INPUTS: usize = 2_000;

/// Most noise channels of a model (families unrolled).
pub const MAX_NOISES: usize = 2_000;

/// Most report steps (`horizon / step`) of one analysis.
pub const MAX_REPORT_STEPS: f64 = 1e5;

/// Shortest report step of one analysis (the engines' own limit: shorter steps would be
/// subdivided into subnormal numbers, where no step makes progress).
pub use reachc_core::engine::MIN_REPORT_STEP;
