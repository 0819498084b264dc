//! Compiles the cart of `cart.sde` to `$OUT_DIR/cart.rs` (included by `src/lib.rs`).

fn main() -> Result<(), Box<dyn std::error::Error>> {
    reachc_compiler::Config::new().compile(&["cart.sde"])?;
    Ok(())
}
