//! Failed analyses located in the spec: a [`Failure`] (typed from the interpreter, or read
//! from a generated binary's `reachc-failure` line) becomes a diagnostic on the analysis
//! block, and on the state or the setting it names, rendered like compile-time diagnostics.

use std::io::{BufRead, BufReader, Read};

use reachc_compiler::diagnostics::{render, Diagnostic};
use reachc_compiler::driver::Loaded;
use reachc_compiler::model::{Analysis, Variable};
use reachc_runtime::engine::Culprit;
use reachc_runtime::failure::Failure;

/// What it takes to locate failures in a spec: its text and the spans of its analyses and
/// states (kept when the model itself goes to a backend).
pub(super) struct Locator {
    path: String,
    source: String,
    analyses: Vec<Analysis>,
    states: Vec<Variable>,
    color: bool,
}

impl Locator {
    /// The locator of a loaded spec; `color` for rendering.
    pub(super) fn new(loaded: &Loaded, color: bool) -> Locator {
        Locator {
            path: loaded.path.display().to_string(),
            source: loaded.source.clone(),
            analyses: loaded.model.analyses.clone(),
            states: loaded.model.states.clone(),
            color,
        }
    }

    /// The failure as a diagnostic: on the setting's field (or, for a default, on the
    /// analysis' name), or on the state's declaration, with the analysis' name as the second
    /// label; on the analysis' name when nothing more is known. `None` for an analysis the
    /// spec does not have.
    pub(super) fn diagnostic(&self, f: &Failure) -> Option<Diagnostic> {
        let analysis = self.analyses.iter().find(|a| a.spec.name == f.analysis)?;
        let title = format!("analysis `{}` {}", f.analysis, f.message);
        let this = format!("in analysis `{}`", f.analysis);
        Some(match f.culprit {
            None => Diagnostic::error(title, analysis.name_span.clone(), "this analysis failed"),
            Some(Culprit::State(i)) => match self.states.get(i) {
                Some(state) => {
                    Diagnostic::error(title, state.span.clone(), format!("state `{}`", state.name))
                        .with_label(analysis.name_span.clone(), this)
                }
                None => {
                    Diagnostic::error(title, analysis.name_span.clone(), "this analysis failed")
                }
            },
            Some(Culprit::Setting(s)) => match analysis.settings.iter().find(|(k, _)| *k == s) {
                Some((_, span)) => Diagnostic::error(title, span.clone(), "the setting to change")
                    .with_label(analysis.name_span.clone(), this),
                None => Diagnostic::error(
                    title,
                    analysis.name_span.clone(),
                    format!("this analysis, with the default `{}`", s.key()),
                )
                .with_help(format!(
                    "set `{} = ...` in the block (the setting to change)",
                    s.key()
                )),
            },
        })
    }

    /// The failure rendered for stderr (as the runtime prints it when the spec has no such
    /// analysis).
    pub(super) fn render(&self, f: &Failure) -> String {
        match self.diagnostic(f) {
            Some(d) => render(&[d], &self.path, &self.source, self.color),
            None => format!("{f}\n"),
        }
    }

    /// Prints the failures collected from the interpreter, located, then
    /// [`Failure::summary`] (`of`: the analyses selected, all of them without `analysis`).
    pub(super) fn print_collected(&self, failures: &[Failure], analysis: Option<&str>) {
        for f in failures {
            eprint!("{}", self.render(f));
        }
        if !failures.is_empty() {
            let of = analysis.map_or(self.analyses.len(), |_| 1);
            eprintln!("{}", Failure::summary(failures.len(), of));
        }
    }

    /// A generated binary's stderr line as we print it: a failure line rendered, any other
    /// line as it is (with its line break).
    pub(super) fn line(&self, line: &str) -> String {
        match Failure::parse_line(line) {
            Some(f) => self.render(&f),
            None => format!("{line}\n"),
        }
    }

    /// Copies a generated binary's stderr to ours line by line ([`Locator::line`]).
    pub(super) fn forward(&self, stderr: impl Read) {
        for line in BufReader::new(stderr).lines() {
            let Ok(line) = line else { break };
            eprint!("{}", self.line(&line));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use reachc_compiler::driver::load;

    fn locator() -> Locator {
        let spec = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/run_errors/box_blows_up.sde");
        Locator::new(&load(&spec).unwrap(), false)
    }

    #[test]
    fn a_binary_s_failure_line_is_rendered_at_its_setting() {
        let l = locator();
        let shown = l.line("reachc-failure blows_up setting:step could not run: it blew up");
        assert!(
            shown.starts_with("Error: analysis `blows_up` could not run: it blew up"),
            "{shown}"
        );
        assert!(shown.contains("box_blows_up.sde:18:5 ]"), "{shown}");
        assert!(shown.contains("in analysis `blows_up`"), "{shown}");
        // A state, by index: its declaration.
        let shown = l.line("reachc-failure good state:0 could not run: left the domain");
        assert!(shown.contains("box_blows_up.sde:5:1 ]"), "{shown}");
        assert!(shown.contains("state `x`"), "{shown}");
        // Other lines pass through; an analysis the spec does not have is printed as prose.
        assert_eq!(
            l.line("skipped analysis `a`: why"),
            "skipped analysis `a`: why\n"
        );
        assert_eq!(
            l.line("reachc-failure other - could not run: x"),
            "error: analysis `other` could not run: x\n"
        );
    }
}
