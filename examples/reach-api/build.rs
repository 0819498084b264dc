//! Compiles the shipped Duffing oscillator to `$OUT_DIR/duffing.rs` (included by `src/lib.rs`).

fn main() -> Result<(), Box<dyn std::error::Error>> {
    reachc_compiler::Config::new().compile(&["../../specs/duffing.sde"])?;
    Ok(())
}
