//! The `reachc` command line: `check`, `inspect`, `build`, `run`, `simulate` and `plot` on `.sde`
//! specs. The compiler itself is the library `reachc-compiler`; the sets are computed by
//! `reachc-runtime` (the interpreter backend in this process, the compiled backend in a generated
//! binary), through the same typed API downstream code uses.

pub mod commands;
pub mod plot;

pub use commands::main;
