//! The bundled font: a subset of DejaVu Sans (assets/fonts/, with its licence), registered
//! with plotters under the family name the figures use. Text is laid out (and, in PNGs,
//! rasterised) with it, so the pictures look the same everywhere and no system font library
//! is needed; SVGs name the family, and viewers render it with their own sans-serif font.

use std::sync::OnceLock;

use plotters::style::FontStyle;

/// The family name the figures use (also written into the SVGs).
pub const FAMILY: &str = "sans-serif";

/// The font file.
pub static BYTES: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans-subset.ttf");

/// Registers the font once per process.
pub fn register() -> Result<(), String> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        plotters::style::register_font(FAMILY, FontStyle::Normal, BYTES)
            .map_err(|_| "the bundled font cannot be read".to_string())
    })
    .clone()
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_bundled_font_registers() {
        assert_eq!(super::register(), Ok(()));
    }
}
