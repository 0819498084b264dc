//! cargo's progress on stderr while a generated crate compiles: a spinner on a terminal (gone
//! when cargo is done), one plain line otherwise, nothing with `--quiet` or when cargo does not
//! run (a cached binary).

use std::collections::BTreeSet;
use std::io::IsTerminal;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use reachc_compiler::package::Progress;

/// How progress is shown.
enum Mode {
    /// Not at all.
    Quiet,
    /// One line when cargo starts (stderr is not a terminal: a log, a pipe).
    Plain,
    /// A spinner naming the last crate compiled and how many are done.
    Spinner,
}

/// Shows the [`Progress`] events of one cargo build.
pub(super) struct CompileDisplay {
    mode: Mode,
    spinner: Option<ProgressBar>,
    package: String,
    /// Packages with at least one target compiled (not fresh).
    compiled: BTreeSet<String>,
}

impl CompileDisplay {
    /// A display on stderr: a spinner on a terminal, a plain line otherwise, nothing if
    /// `quiet`.
    pub(super) fn new(quiet: bool) -> CompileDisplay {
        let mode = if quiet {
            Mode::Quiet
        } else if std::io::stderr().is_terminal() {
            Mode::Spinner
        } else {
            Mode::Plain
        };
        CompileDisplay {
            mode,
            spinner: None,
            package: String::new(),
            compiled: BTreeSet::new(),
        }
    }

    /// Shows one event.
    pub(super) fn event(&mut self, event: &Progress) {
        match (&self.mode, event) {
            (Mode::Quiet, _) => {}
            (Mode::Plain, Progress::Started { package }) => {
                eprintln!("{}", started_line(package));
            }
            (Mode::Plain, _) => {}
            (Mode::Spinner, Progress::Started { package }) => {
                self.package = package.clone();
                let spinner = ProgressBar::new_spinner();
                // A fixed template: cannot fail to parse.
                if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} [{elapsed}]") {
                    spinner.set_style(style);
                }
                spinner.set_message(started_line(package));
                spinner.enable_steady_tick(Duration::from_millis(120));
                self.spinner = Some(spinner);
            }
            (Mode::Spinner, Progress::Compiled { package, fresh }) => {
                if !fresh {
                    self.compiled.insert(package.clone());
                }
                if let Some(spinner) = &self.spinner {
                    spinner.set_message(compiled_line(&self.package, package, self.compiled.len()));
                }
            }
            (Mode::Spinner, Progress::Finished { .. }) => {
                if let Some(spinner) = self.spinner.take() {
                    spinner.finish_and_clear();
                }
            }
        }
    }
}

impl Drop for CompileDisplay {
    fn drop(&mut self) {
        if let Some(spinner) = self.spinner.take() {
            spinner.finish_and_clear();
        }
    }
}

/// The message when cargo starts on the generated crate `package`.
fn started_line(package: &str) -> String {
    format!(
        "compiling {package} with cargo (the first build also compiles the runtime: about a \
         minute)"
    )
}

/// The spinner's message once `last` is done, `count` crates compiled so far.
fn compiled_line(package: &str, last: &str, count: usize) -> String {
    let crates = if count == 1 { "crate" } else { "crates" };
    format!("compiling {package} with cargo: {last} done ({count} {crates})")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages() {
        assert_eq!(
            started_line("pendulum"),
            "compiling pendulum with cargo (the first build also compiles the runtime: about a \
             minute)"
        );
        assert_eq!(
            compiled_line("pendulum", "reachc-runtime", 12),
            "compiling pendulum with cargo: reachc-runtime done (12 crates)"
        );
        assert_eq!(
            compiled_line("pendulum", "serde", 1),
            "compiling pendulum with cargo: serde done (1 crate)"
        );
    }

    #[test]
    fn quiet_shows_nothing_and_a_spinner_goes_away() {
        let mut quiet = CompileDisplay::new(true);
        quiet.event(&Progress::Started {
            package: "x".into(),
        });
        assert!(quiet.spinner.is_none());
        let mut spinning = CompileDisplay {
            mode: Mode::Spinner,
            spinner: None,
            package: String::new(),
            compiled: BTreeSet::new(),
        };
        spinning.event(&Progress::Started {
            package: "x".into(),
        });
        for (package, fresh) in [("serde", false), ("serde", false), ("rayon", true)] {
            spinning.event(&Progress::Compiled {
                package: package.into(),
                fresh,
            });
        }
        assert_eq!(spinning.compiled.len(), 1);
        spinning.event(&Progress::Finished { success: true });
        assert!(spinning.spinner.is_none());
    }
}
