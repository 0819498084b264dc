//! The `reachc` binary; everything lives in the library (`reachc::cli`).

fn main() -> std::process::ExitCode {
    reachc::cli::main()
}
