//! Compiling a generated crate with cargo, reporting progress as cargo goes.
//!
//! cargo runs with `--message-format=json-render-diagnostics`: its standard output is one JSON
//! message per line, read as they come (each `compiler-artifact` message is a compiled target,
//! reported as a [`Progress`] event), while its standard error (status lines and rendered
//! compiler diagnostics) is collected and shown only if the build fails.

use std::ffi::OsString;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use super::BuildError;

/// The cargo profile a crate is compiled with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Profile {
    /// `cargo build` (generated crates set `opt-level = 1`).
    Dev,
    /// `cargo build --release`.
    Release,
}

impl Profile {
    /// `Release` if `release`, else `Dev`.
    pub fn from_release(release: bool) -> Profile {
        if release {
            Profile::Release
        } else {
            Profile::Dev
        }
    }

    /// The profile's name as cargo spells it (`dev`, `release`).
    pub fn name(self) -> &'static str {
        match self {
            Profile::Dev => "dev",
            Profile::Release => "release",
        }
    }
}

/// What happens while cargo compiles a crate, in order: [`Progress::Started`], any number of
/// [`Progress::Compiled`], then [`Progress::Finished`] (also when cargo fails).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Progress {
    /// cargo is starting on the generated crate `package`.
    Started {
        /// The generated crate's package name.
        package: String,
    },
    /// cargo has finished a target of `package` (a library, a build script or a binary).
    Compiled {
        /// The package's name (e.g. `serde`, `reachc-runtime`).
        package: String,
        /// Whether it was already up to date (nothing was compiled).
        fresh: bool,
    },
    /// cargo has exited.
    Finished {
        /// Whether it succeeded.
        success: bool,
    },
}

/// How to run cargo.
#[derive(Clone, Debug)]
pub struct Cargo {
    /// The program: `$CARGO` when set (cargo sets it for the programs it runs), else `cargo`
    /// from `PATH`.
    pub program: OsString,
    /// The target directory (`CARGO_TARGET_DIR`).
    pub target_dir: PathBuf,
    /// The profile.
    pub profile: Profile,
}

impl Cargo {
    /// cargo from the environment (see [`Cargo::program`]) with this target directory and
    /// profile.
    pub fn new(target_dir: impl Into<PathBuf>, profile: Profile) -> Cargo {
        Cargo {
            program: std::env::var_os("CARGO")
                .filter(|p| !p.is_empty())
                .unwrap_or_else(|| "cargo".into()),
            target_dir: target_dir.into(),
            profile,
        }
    }

    /// Compiles the binaries of the crate at `dir` (`cargo build --bins`, `--release` for the
    /// release profile) and returns the path of its binary. `progress` sees what cargo reports.
    ///
    /// The crate's `Cargo.lock` is used as it is (a generated crate is written with one, see
    /// [`super::lock`]). Errors: cargo cannot be started, fails (its diagnostics in the error),
    /// or reports no binary.
    pub fn build(
        &self,
        dir: &Path,
        progress: &mut dyn FnMut(&Progress),
    ) -> Result<PathBuf, BuildError> {
        let manifest = dir.join("Cargo.toml");
        let mut cmd = Command::new(&self.program);
        cmd.arg("build")
            .arg("--manifest-path")
            .arg(&manifest)
            .arg("--bins")
            .arg("--message-format=json-render-diagnostics")
            .env("CARGO_TARGET_DIR", &self.target_dir)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        if self.profile == Profile::Release {
            cmd.arg("--release");
        }
        let program = Path::new(&self.program).display().to_string();
        let mut child = spawn(&mut cmd).map_err(|e| BuildError::Cargo {
            message: if e.kind() == std::io::ErrorKind::NotFound {
                format!(
                    "cannot run {program}: {e}; the compiled backend needs a Rust toolchain \
                     (https://rustup.rs), `--backend interp` does not"
                )
            } else {
                format!("cannot run {program}: {e}")
            },
            stderr: String::new(),
        })?;
        let package = read_package_name(&manifest);
        progress(&Progress::Started {
            package: package.clone(),
        });
        let (stdout, stderr) = (child.stdout.take(), child.stderr.take());
        let (binary, stderr) = std::thread::scope(|scope| {
            // Drained from its own thread: a full pipe would block cargo.
            let errors = scope.spawn(move || {
                let mut text = String::new();
                if let Some(mut s) = stderr {
                    let _ = s.read_to_string(&mut text);
                }
                text
            });
            let mut binary = None;
            for line in stdout.into_iter().flat_map(|s| BufReader::new(s).lines()) {
                let Ok(line) = line else { break };
                match parse_message(&line) {
                    Some(Message::Artifact {
                        package,
                        fresh,
                        executable,
                    }) => {
                        if executable.is_some() {
                            binary = executable;
                        }
                        progress(&Progress::Compiled { package, fresh });
                    }
                    Some(Message::Other) | None => {}
                }
            }
            (binary, errors.join().unwrap_or_default())
        });
        let status = child.wait().map_err(|e| BuildError::Cargo {
            message: format!("waiting for {program}: {e}"),
            stderr: stderr.clone(),
        });
        let success = status.as_ref().is_ok_and(|s| s.success());
        progress(&Progress::Finished { success });
        let status = status?;
        if !status.success() {
            return Err(BuildError::Cargo {
                message: format!("cargo build of {} failed ({status})", dir.display()),
                stderr,
            });
        }
        binary.ok_or_else(|| BuildError::Cargo {
            message: format!("cargo build of {} reported no binary", dir.display()),
            stderr,
        })
    }
}

/// Starts `cmd`, retrying briefly while the program is busy (`ETXTBSY`: a program written just
/// before, whose descriptor another thread's child process still holds open for writing).
fn spawn(cmd: &mut Command) -> std::io::Result<std::process::Child> {
    let mut attempt = 0;
    loop {
        match cmd.spawn() {
            Err(e) if e.kind() == std::io::ErrorKind::ExecutableFileBusy && attempt < 20 => {
                attempt += 1;
                std::thread::sleep(std::time::Duration::from_millis(10));
            }
            result => return result,
        }
    }
}

/// The `name` of a manifest's `[package]` (the directory's name if it cannot be read).
fn read_package_name(manifest: &Path) -> String {
    let text = std::fs::read_to_string(manifest).unwrap_or_default();
    let mut in_package = false;
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with('[') {
            in_package = t == "[package]";
        } else if in_package {
            if let Some(v) = t
                .strip_prefix("name")
                .and_then(|r| r.trim_start().strip_prefix('='))
                .map(|r| r.trim().trim_matches('"'))
            {
                return v.to_string();
            }
        }
    }
    manifest
        .parent()
        .and_then(|d| d.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// A message of cargo's JSON output, as far as it matters here.
#[derive(Debug, PartialEq)]
enum Message {
    /// `compiler-artifact`: a target was compiled (or found fresh).
    Artifact {
        package: String,
        fresh: bool,
        executable: Option<PathBuf>,
    },
    /// Any other message.
    Other,
}

/// Parses one line of cargo's JSON output (`None`: not JSON).
fn parse_message(line: &str) -> Option<Message> {
    let msg: serde_json::Value = serde_json::from_str(line).ok()?;
    if msg["reason"] != "compiler-artifact" {
        return Some(Message::Other);
    }
    let package = msg["package_id"]
        .as_str()
        .and_then(package_name)
        .or_else(|| msg["target"]["name"].as_str().map(str::to_string))
        .unwrap_or_default();
    Some(Message::Artifact {
        package,
        fresh: msg["fresh"].as_bool().unwrap_or(false),
        executable: msg["executable"].as_str().map(PathBuf::from),
    })
}

/// The package name in a cargo package id: `registry+https://...#serde@1.0.228`,
/// `path+file:///x/pendulum#0.1.0` (the name is the URL's last segment when it matches), or the
/// older `serde 1.0.228 (registry+...)`.
fn package_name(id: &str) -> Option<String> {
    if let Some((url, fragment)) = id.rsplit_once('#') {
        return Some(match fragment.split_once('@') {
            Some((name, _)) => name.to_string(),
            None => url
                .trim_end_matches('/')
                .rsplit('/')
                .next()
                .unwrap_or(url)
                .to_string(),
        });
    }
    id.split_whitespace().next().map(str::to_string)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn artifacts_are_read_from_cargo_messages() {
        let lib = r#"{"reason":"compiler-artifact","package_id":"registry+https://github.com/rust-lang/crates.io-index#serde@1.0.228","target":{"name":"serde"},"fresh":false,"executable":null}"#;
        assert_eq!(
            parse_message(lib),
            Some(Message::Artifact {
                package: "serde".into(),
                fresh: false,
                executable: None
            })
        );
        let bin = r#"{"reason":"compiler-artifact","package_id":"path+file:///t/crates/pendulum#0.1.0","target":{"name":"pendulum"},"fresh":true,"executable":"/t/release/pendulum"}"#;
        assert_eq!(
            parse_message(bin),
            Some(Message::Artifact {
                package: "pendulum".into(),
                fresh: true,
                executable: Some(PathBuf::from("/t/release/pendulum"))
            })
        );
        assert_eq!(
            parse_message(r#"{"reason":"build-finished","success":true}"#),
            Some(Message::Other)
        );
        assert_eq!(parse_message("   Compiling serde"), None);
    }

    #[test]
    fn package_names_in_ids() {
        assert_eq!(
            package_name("path+file:///c/runtime/0.1.0-ab/reachc-runtime#0.1.0").as_deref(),
            Some("reachc-runtime")
        );
        assert_eq!(
            package_name("path+file:///c/crates/pend#pendulum@0.1.0").as_deref(),
            Some("pendulum")
        );
        assert_eq!(
            package_name("serde 1.0.0 (registry+https://x)").as_deref(),
            Some("serde")
        );
    }

    #[test]
    fn a_missing_cargo_is_a_clear_error() {
        let cargo = Cargo {
            program: "/nonexistent/cargo".into(),
            target_dir: std::env::temp_dir(),
            profile: Profile::Dev,
        };
        let mut events = Vec::new();
        let err = cargo
            .build(Path::new("/nonexistent/crate"), &mut |p| {
                events.push(p.clone())
            })
            .unwrap_err();
        assert!(matches!(err, BuildError::Cargo { .. }), "{err:?}");
        assert_eq!(err.exit_code(), 2);
        let text = err.to_string();
        assert!(text.contains("cannot run /nonexistent/cargo"), "{text}");
        assert!(text.contains("--backend interp"), "{text}");
        assert!(events.is_empty());
    }

    #[cfg(unix)]
    #[test]
    fn a_failing_cargo_reports_its_output() {
        let dir = std::env::temp_dir().join(format!("reachc-cargo-fail-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let script = dir.join("cargo");
        std::fs::write(
            &script,
            "#!/bin/sh\necho '{\"reason\":\"compiler-artifact\",\"package_id\":\"x#serde@1.0.0\",\"fresh\":false}'\necho 'error[E0001]: boom' >&2\nexit 101\n",
        )
        .unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&script, std::fs::Permissions::from_mode(0o755)).unwrap();
        let cargo = Cargo {
            program: script.into_os_string(),
            target_dir: dir.join("target"),
            profile: Profile::Release,
        };
        let mut events = Vec::new();
        let err = cargo
            .build(&dir.join("demo"), &mut |p| events.push(p.clone()))
            .unwrap_err();
        let text = err.report(false);
        assert!(text.contains("error[E0001]: boom"), "{text}");
        assert!(
            text.contains("cargo build of") && text.contains("failed"),
            "{text}"
        );
        assert_eq!(err.exit_code(), 2);
        assert_eq!(
            events,
            [
                Progress::Started {
                    package: "demo".into()
                },
                Progress::Compiled {
                    package: "serde".into(),
                    fresh: false
                },
                Progress::Finished { success: false }
            ]
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
