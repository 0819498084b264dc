//! Anything but a regular file as the spec (a FIFO with no writer, a device, a directory) is
//! refused at once with exit code 2 and a message naming the path, never waited on or read.
#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn temp_dir(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("reachc-cli-special-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `reachc check path`, failing the test (and killing reachc) if it takes 10 s; the exit
/// code and stderr.
fn check_promptly(path: &Path) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_reachc"))
        .arg("check")
        .arg(path)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the reachc binary runs");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(10) {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("reachc check {} still waiting after 10 s", path.display());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn assert_refused(path: &Path, kind: &str) {
    let (code, stderr) = check_promptly(path);
    assert_eq!(code, Some(2), "{stderr}");
    assert_eq!(
        stderr,
        format!(
            "error: cannot read {}: not a regular file ({kind}); give the path of a .sde file\n",
            path.display()
        )
    );
}

#[test]
fn a_fifo_is_refused_without_waiting_for_a_writer() {
    let fifo = temp_dir("fifo").join("spec.sde");
    let _ = std::fs::remove_file(&fifo);
    let made = Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    assert_refused(&fifo, "a FIFO");
}

#[test]
fn a_device_is_refused_without_reading_it() {
    assert_refused(Path::new("/dev/zero"), "a character device");
}

#[test]
fn a_directory_is_refused() {
    assert_refused(&temp_dir("dir"), "a directory");
}
