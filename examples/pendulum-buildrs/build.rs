//! Compiles the shipped pendulum spec to `$OUT_DIR/pendulum.rs` (included by `src/lib.rs`).

fn main() -> Result<(), Box<dyn std::error::Error>> {
    reachc_compiler::Config::new().compile(&["../../specs/pendulum.sde"])?;
    Ok(())
}
