//! Rendering a figure to SVG and PNG in memory (the files are written by
//! [`reachc_runtime::output::Files`]: whole or not at all).

use plotters::coord::Shift;
use plotters::prelude::*;

use super::raster::Raster;

/// Size of the pictures in pixels (the SVG's user units).
pub type Size = (u32, u32);

/// A drawing function: the same code draws on either backend.
pub trait Draw {
    /// Draws onto the area (already filled white), every length in pixels multiplied by
    /// `scale`.
    fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        scale: u32,
    ) -> Result<(), String>;
}

/// PNGs are drawn this many times larger, then reduced (each pixel the mean of a block):
/// plotters' bitmap lines have no anti-aliasing of their own.
const SUPERSAMPLE: u32 = 3;

/// The figure as an SVG document.
pub fn svg<F: Draw>(figure: &F, size: Size) -> Result<String, String> {
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        figure.draw(&root, 1)?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(text)
}

/// The figure as a PNG image (8-bit RGB).
pub fn png<F: Draw>(figure: &F, size: Size) -> Result<Vec<u8>, String> {
    let k = SUPERSAMPLE as usize;
    let (w, h) = (size.0 as usize, size.1 as usize);
    let mut big = vec![0u8; w * k * h * k * 3];
    {
        let root = Raster::with_buffer(&mut big, (size.0 * SUPERSAMPLE, size.1 * SUPERSAMPLE))?
            .into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        figure.draw(&root, SUPERSAMPLE)?;
        root.present().map_err(|e| e.to_string())?;
    }
    let mut rgb = vec![0u8; w * h * 3];
    for (p, out) in rgb.chunks_exact_mut(3).enumerate() {
        let (x, y) = (p % w, p / w);
        for (c, v) in out.iter_mut().enumerate() {
            let sum: usize = (0..k * k)
                .map(|q| usize::from(big[((y * k + q / k) * w * k + x * k + q % k) * 3 + c]))
                .sum();
            *v = ((sum + k * k / 2) / (k * k)) as u8;
        }
    }
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, size.0, size.1);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    writer.write_image_data(&rgb).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())?;
    Ok(out)
}
