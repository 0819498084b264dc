//! The `reachc` binary; everything lives in the library (`reachc::commands`).

fn main() -> std::process::ExitCode {
    reachc::main()
}
