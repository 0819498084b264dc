//! The fuzz campaign of `reachc check` and `reachc run --backend interp` (docs/fuzzing.md):
//! mutants of a seed corpus ([`mutate`], drawn by proptest strategies), each run as a
//! subprocess under a time and memory budget ([`exec`]), its outcome classified
//! ([`classify`]); failing inputs are minimised ([`minimise`]) for the findings.

pub mod campaign;
pub mod classify;
pub mod exec;
pub mod lex;
pub mod minimise;
pub mod mutate;
