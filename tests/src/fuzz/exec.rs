//! Runs `reachc` as a subprocess under a budget: a CPU-time limit (`RLIMIT_CPU`: the measure
//! of a hang that does not depend on how loaded the shared machine is), a wall-clock timeout
//! at three times that (the child is killed; catches a child that blocks), an address-space
//! limit (`RLIMIT_AS`, so a huge allocation fails inside the child instead of
//! exhausting the machine), a limit on the size of any file it writes (`RLIMIT_FSIZE`) and no
//! core dumps.

use std::fs::File;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// What one input may spend.
#[derive(Clone, Copy, Debug)]
pub struct Budget {
    /// CPU time of the child (whole seconds, at least one); the wall clock allows three times
    /// as much.
    pub cpu: Duration,
    /// Address space of the child, in bytes.
    pub memory: u64,
    /// Largest file the child may write (its stderr included), in bytes.
    pub file: u64,
}

impl Budget {
    /// The budget of a `check`: 2 s of CPU, 1 GiB, 16 MiB files.
    pub const CHECK: Budget = Budget {
        cpu: Duration::from_secs(2),
        memory: 1 << 30,
        file: 16 << 20,
    };
    /// The budget of a `run --backend interp`: 10 s of CPU, 2 GiB, 64 MiB files.
    pub const RUN: Budget = Budget {
        cpu: Duration::from_secs(10),
        memory: 2 << 30,
        file: 64 << 20,
    };
}

/// How a child ended.
#[derive(Clone, Debug)]
pub struct Exit {
    /// Its exit code, if it exited.
    pub code: Option<i32>,
    /// The signal that ended it, if one did (not counting our kill on timeout).
    pub signal: Option<i32>,
    /// Whether it was killed at the end of its wall-clock time.
    pub timed_out: bool,
    /// Its standard error (lossy UTF-8).
    pub stderr: String,
    /// Wall-clock time it took.
    pub elapsed: Duration,
}

/// Runs `cmd` under `budget` with its standard output discarded and its standard error written
/// to `stderr_file` (a file, not a pipe: nothing to drain while waiting).
pub fn run(mut cmd: Command, budget: &Budget, stderr_file: &Path) -> std::io::Result<Exit> {
    let err = File::create(stderr_file)?;
    let limits = *budget;
    cmd.stdin(Stdio::null()).stdout(Stdio::null()).stderr(err);
    // SAFETY: the closure runs in the forked child before exec and only calls setrlimit, which
    // is async-signal-safe; it allocates nothing.
    unsafe {
        cmd.pre_exec(move || {
            // The resource type differs between C libraries: let the array infer it.
            let cpu = limits.cpu.as_secs().max(1);
            let limits = [
                (libc::RLIMIT_AS, limits.memory, limits.memory),
                // SIGXCPU at the soft limit, SIGKILL a second later if it is ignored.
                (libc::RLIMIT_CPU, cpu, cpu + 1),
                (libc::RLIMIT_FSIZE, limits.file, limits.file),
                (libc::RLIMIT_CORE, 0, 0),
            ];
            for (resource, soft, hard) in limits {
                let rl = libc::rlimit {
                    rlim_cur: soft,
                    rlim_max: hard,
                };
                if libc::setrlimit(resource, &rl) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
            }
            Ok(())
        });
    }
    let start = Instant::now();
    let mut child = cmd.spawn()?;
    let mut pause = Duration::from_millis(1);
    let (status, timed_out) = loop {
        if let Some(status) = child.try_wait()? {
            break (status, false);
        }
        if start.elapsed() >= budget.cpu.max(Duration::from_secs(1)) * 3 {
            // Already exited between try_wait and kill is fine: wait reaps it either way.
            let _ = child.kill();
            break (child.wait()?, true);
        }
        std::thread::sleep(pause);
        pause = (pause * 2).min(Duration::from_millis(20));
    };
    let elapsed = start.elapsed();
    let stderr = String::from_utf8_lossy(&std::fs::read(stderr_file)?).into_owned();
    Ok(Exit {
        code: status.code(),
        signal: if timed_out { None } else { status.signal() },
        timed_out,
        stderr,
        elapsed,
    })
}

/// The `reachc` binary the fuzz campaign drives: `$REACHC_BIN` if set, otherwise built once
/// by cargo with the profile and target directory of the running test or example (an e2e
/// test cannot name another package's binary through `CARGO_BIN_EXE_*`).
pub fn reachc_binary() -> &'static Path {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| {
        if let Some(bin) = std::env::var_os("REACHC_BIN") {
            return PathBuf::from(bin);
        }
        // target/<profile>/deps/fuzz-HASH or target/<profile>/examples/fuzz.
        let exe = std::env::current_exe().expect("the running executable has a path");
        let profile_dir = exe
            .parent()
            .and_then(Path::parent)
            .expect("tests and examples run from target/<profile>/<kind>/");
        let target = profile_dir.parent().expect("target/<profile>");
        let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let mut build = Command::new(cargo);
        build
            .current_dir(crate::workspace())
            .args([
                "build",
                "--quiet",
                "-p",
                "reachc",
                "--bin",
                "reachc",
                "--target-dir",
            ])
            .arg(target);
        if profile_dir.file_name().is_some_and(|n| n == "release") {
            build.arg("--release");
        }
        let status = build.status().expect("cargo runs");
        assert!(status.success(), "cargo build -p reachc failed");
        profile_dir.join("reachc")
    })
}
