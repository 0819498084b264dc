//! The `.sde` front end: source text to syntax tree ([`ast`]), with syntax diagnostics.
//!
//! [`parse`] never panics and always returns a (possibly partial) [`ast::Spec`] together with
//! every syntax error it found; it recovers at the item level (and at the statement level inside
//! blocks) so that several errors are reported in one run.

pub mod ast;
mod lexer;
mod parser;

pub(crate) use parser::too_large;
pub use parser::{MAX_DEPTH, MAX_DIAGNOSTICS, MAX_HEIGHT, MAX_SOURCE_LEN};

/// Stack for the parsing thread: recursion is bounded by [`MAX_DEPTH`], but unoptimized builds
/// use several KiB per nesting level, more than a 2 MiB test thread offers.
const PARSE_STACK: usize = 32 << 20;

/// Parses a spec. Always returns a (possibly partial) Spec plus every syntax error found.
///
/// Diagnostics are sorted by the start of their primary span; every span lies within
/// `0..=src.len()` on char boundaries (end-of-file errors point at `src.len()`). Sources larger
/// than [`MAX_SOURCE_LEN`] bytes are rejected with a single diagnostic at `0..0`.
///
/// The work runs on a scoped thread with a large stack, so that the caller's stack size does not
/// matter (if the thread cannot be spawned, it runs on the caller's thread).
pub fn parse(src: &str) -> (ast::Spec, Vec<crate::diagnostics::Diagnostic>) {
    std::thread::scope(|scope| {
        let spawned = std::thread::Builder::new()
            .name("reachc-parse".to_string())
            .stack_size(PARSE_STACK)
            .spawn_scoped(scope, || parser::parse_spec(src));
        match spawned {
            Ok(handle) => handle
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic)),
            Err(_) => parser::parse_spec(src),
        }
    })
}
