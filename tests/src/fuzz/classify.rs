//! The outcome classes of one input. Exit 0, 1 or 2 without a panic message is fine (1 with a
//! located diagnostic when the error comes from the spec); a panic, a signal, an abort, a
//! timeout, memory exhaustion or any other exit code is a failure.

use super::exec::Exit;

/// What became of one input.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Outcome {
    /// Exit 0.
    Accepted,
    /// Exit 1 with a diagnostic that has a location.
    Rejected,
    /// Exit 1 from `run` on a spec that `check` accepts: an analysis that cannot run.
    AnalysisError,
    /// Exit 2: usage or I/O error.
    Usage,
    /// Failure: exit 1 for a spec error, but no diagnostic with a location.
    NoLocation,
    /// Failure: a Rust panic (the message, or exit code 101).
    Panic,
    /// Failure: out of CPU time (`SIGXCPU`, or `SIGKILL` at the hard limit) or of wall-clock
    /// time.
    Timeout,
    /// Failure: an allocation failed under the address-space limit.
    OutOfMemory,
    /// Failure: the main thread or a worker overflowed its stack.
    StackOverflow,
    /// Failure: a file (a result, or stderr) grew past the file-size limit.
    OutputTooLarge,
    /// Failure: aborted (SIGABRT, or exit code 134).
    Abort,
    /// Failure: ended by another signal.
    Signal(i32),
    /// Failure: an exit code outside 0, 1, 2.
    ExitCode(i32),
}

impl Outcome {
    /// Whether this outcome is a defect.
    pub fn is_failure(&self) -> bool {
        !matches!(
            self,
            Outcome::Accepted | Outcome::Rejected | Outcome::AnalysisError | Outcome::Usage
        )
    }

    /// A short name, for tables and file names.
    pub fn name(&self) -> String {
        match self {
            Outcome::Accepted => "accepted".into(),
            Outcome::Rejected => "rejected".into(),
            Outcome::AnalysisError => "analysis-error".into(),
            Outcome::Usage => "usage-or-io".into(),
            Outcome::NoLocation => "no-location".into(),
            Outcome::Panic => "panic".into(),
            Outcome::Timeout => "timeout".into(),
            Outcome::OutOfMemory => "out-of-memory".into(),
            Outcome::StackOverflow => "stack-overflow".into(),
            Outcome::OutputTooLarge => "output-too-large".into(),
            Outcome::Abort => "abort".into(),
            Outcome::Signal(s) => format!("signal-{s}"),
            Outcome::ExitCode(c) => format!("exit-{c}"),
        }
    }
}

/// The outcome of `exit`; `spec_error` says whether an exit 1 is an error of the spec (and so
/// needs a located diagnostic) or of an analysis the spec asked for.
pub fn classify(exit: &Exit, spec_error: bool) -> Outcome {
    let err = &exit.stderr;
    if exit.timed_out {
        return Outcome::Timeout;
    }
    if err.contains("panicked") {
        return Outcome::Panic;
    }
    if err.contains("memory allocation of") || err.contains("capacity overflow") {
        return Outcome::OutOfMemory;
    }
    if err.contains("has overflowed its stack") {
        return Outcome::StackOverflow;
    }
    match (exit.code, exit.signal) {
        (_, Some(libc::SIGXCPU | libc::SIGKILL)) => Outcome::Timeout,
        (_, Some(libc::SIGXFSZ)) => Outcome::OutputTooLarge,
        (_, Some(libc::SIGABRT)) | (Some(134), _) => Outcome::Abort,
        (_, Some(signal)) => Outcome::Signal(signal),
        (Some(0), _) => Outcome::Accepted,
        (Some(1), _) if !spec_error => Outcome::AnalysisError,
        (Some(1), _) if has_location(err) => Outcome::Rejected,
        (Some(1), _) => Outcome::NoLocation,
        (Some(2), _) => Outcome::Usage,
        (Some(101), _) => Outcome::Panic,
        (Some(code), _) => Outcome::ExitCode(code),
        (None, None) => Outcome::Signal(0),
    }
}

/// Whether `stderr` holds a rendered diagnostic with a location: a `╭─[ FILE:LINE:COLUMN ]`
/// header.
pub fn has_location(stderr: &str) -> bool {
    stderr.lines().any(|line| {
        let Some((_, rest)) = line.split_once("─[") else {
            return false;
        };
        let inner = rest.trim_end().trim_end_matches(']').trim_end();
        let mut parts = inner.rsplitn(3, ':');
        let numeric = |p: Option<&str>| {
            p.is_some_and(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()))
        };
        numeric(parts.next()) && numeric(parts.next()) && parts.next().is_some()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn exit(code: Option<i32>, signal: Option<i32>, stderr: &str) -> Exit {
        Exit {
            code,
            signal,
            timed_out: false,
            stderr: stderr.into(),
            elapsed: Duration::ZERO,
        }
    }

    #[test]
    fn exit_codes_and_messages_map_to_classes() {
        let located = "Error: undefined name `x`\n   ╭─[ m.sde:6:12 ]\n";
        assert_eq!(
            classify(&exit(Some(1), None, located), true),
            Outcome::Rejected
        );
        assert_eq!(
            classify(&exit(Some(1), None, "error: bad"), true),
            Outcome::NoLocation
        );
        assert_eq!(
            classify(&exit(Some(1), None, "error: bad"), false),
            Outcome::AnalysisError
        );
        assert_eq!(classify(&exit(Some(0), None, ""), true), Outcome::Accepted);
        assert_eq!(
            classify(&exit(Some(2), None, "not UTF-8"), true),
            Outcome::Usage
        );
        let oom = "memory allocation of 8000000000 bytes failed\n";
        assert_eq!(
            classify(&exit(None, Some(libc::SIGABRT), oom), true),
            Outcome::OutOfMemory
        );
        assert_eq!(
            classify(&exit(None, Some(libc::SIGABRT), ""), true),
            Outcome::Abort
        );
        assert_eq!(classify(&exit(Some(134), None, ""), true), Outcome::Abort);
        assert_eq!(
            classify(&exit(None, Some(libc::SIGSEGV), ""), true),
            Outcome::Signal(11)
        );
        assert_eq!(
            classify(&exit(None, Some(libc::SIGXFSZ), ""), true),
            Outcome::OutputTooLarge
        );
        let panic = "thread 'main' panicked at src/x.rs:1:1:\nboom\n";
        assert_eq!(classify(&exit(Some(0), None, panic), true), Outcome::Panic);
        assert_eq!(classify(&exit(Some(101), None, ""), true), Outcome::Panic);
        assert_eq!(
            classify(&exit(Some(3), None, ""), true),
            Outcome::ExitCode(3)
        );
        assert!(!has_location("   ╭─[ m.sde ]"));
    }
}
