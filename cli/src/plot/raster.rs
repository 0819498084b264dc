//! The bitmap backend of the PNGs: plotters' `BitMapBackend` with its own text rendering.
//!
//! plotters draws ab_glyph text glyph by glyph at rounded pen positions and without the
//! glyphs' left side bearings, which scrambles the letter spacing of small text ("qu an tile").
//! Here each line is laid out in fractional pixels (advances, kerning, bearings) with the
//! bundled font, and every glyph's coverage is blended into the bitmap; the text size reported
//! to plotters' layout is that of the same layout.

use ab_glyph::{point, Font, FontRef, PxScale, ScaleFont};
use plotters::backend::BitMapBackend;
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
};

use super::font;

/// A [`BitMapBackend`] whose text is rasterised with correct glyph placement.
pub struct Raster<'a> {
    inner: BitMapBackend<'a>,
    font: FontRef<'static>,
}

impl<'a> Raster<'a> {
    /// Draws into `buf` (8-bit RGB, `size.0 * size.1 * 3` bytes).
    pub fn with_buffer(buf: &'a mut [u8], size: (u32, u32)) -> Result<Self, String> {
        Ok(Raster {
            inner: BitMapBackend::with_buffer(buf, size),
            font: FontRef::try_from_slice(font::BYTES)
                .map_err(|_| "the bundled font cannot be read".to_string())?,
        })
    }

    /// Lays out one line of text at `size` pixels: the glyphs with their baseline origins, the
    /// width and the line height (ascent minus descent) in pixels, and the ascent.
    fn layout(&self, text: &str, size: f64) -> (Vec<ab_glyph::Glyph>, f32, f32, f32) {
        let scale = PxScale::from(size as f32);
        let scaled = self.font.as_scaled(scale);
        let (ascent, height) = (scaled.ascent(), scaled.ascent() - scaled.descent());
        let mut x = 0.0;
        let mut prev = None;
        let mut glyphs = Vec::with_capacity(text.len());
        for c in text.chars() {
            let id = scaled.glyph_id(c);
            if let Some(p) = prev {
                x += scaled.kern(p, id);
            }
            glyphs.push(id.with_scale_and_position(scale, point(x, ascent)));
            x += scaled.h_advance(id);
            prev = Some(id);
        }
        (glyphs, x, height, ascent)
    }
}

/// Cosine of the sharpest joined turn's inner angle: a mitre limit of 4 (SVG's default) is
/// an inner angle of 2 asin(1/4), about 29 degrees.
const MITRE_COS: f64 = 0.875;

type Error<'a> = DrawingErrorKind<<BitMapBackend<'a> as DrawingBackend>::ErrorType>;

impl<'a> DrawingBackend for Raster<'a> {
    type ErrorType = <BitMapBackend<'a> as DrawingBackend>::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), Error<'a>> {
        self.inner.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), Error<'a>> {
        self.inner.present()
    }

    fn draw_pixel(&mut self, point: BackendCoord, color: BackendColor) -> Result<(), Error<'a>> {
        self.inner.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), Error<'a>> {
        self.inner.draw_line(from, to, style)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), Error<'a>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }

    /// Wide lines are polygons with mitred joins, and plotters does not limit the mitre: at a
    /// sharp turn (sample paths zigzag) the join becomes a long spike. As SVG does (mitre
    /// limit 4), a turn sharper than about 29 degrees is not joined: the path is split there.
    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), Error<'a>> {
        if style.stroke_width() <= 1 {
            return self.inner.draw_path(path, style);
        }
        let mut points: Vec<BackendCoord> = path.into_iter().collect();
        points.dedup();
        let mut start = 0;
        for k in 1..points.len().saturating_sub(1) {
            let (a, b, c) = (points[k - 1], points[k], points[k + 1]);
            let u = (f64::from(a.0 - b.0), f64::from(a.1 - b.1));
            let v = (f64::from(c.0 - b.0), f64::from(c.1 - b.1));
            let cos = (u.0 * v.0 + u.1 * v.1) / (u.0.hypot(u.1) * v.0.hypot(v.1));
            if cos > MITRE_COS {
                self.inner.draw_path(points[start..=k].to_vec(), style)?;
                start = k;
            }
        }
        self.inner.draw_path(points[start..].to_vec(), style)
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), Error<'a>> {
        self.inner.draw_circle(center, radius, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), Error<'a>> {
        self.inner.fill_polygon(vert, style)
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        (w, h): (u32, u32),
        src: &[u8],
    ) -> Result<(), Error<'a>> {
        self.inner.blit_bitmap(pos, (w, h), src)
    }

    fn estimate_text_size<S: BackendTextStyle>(
        &self,
        text: &str,
        style: &S,
    ) -> Result<(u32, u32), Error<'a>> {
        let (_, width, height, _) = self.layout(text, style.size());
        Ok((width.ceil() as u32, height.ceil() as u32))
    }

    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<(), Error<'a>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let (glyphs, width, height, _) = self.layout(text, style.size());
        let anchor = style.anchor();
        let dx = match anchor.h_pos {
            HPos::Left => 0.0,
            HPos::Center => -width / 2.0,
            HPos::Right => -width,
        };
        let dy = match anchor.v_pos {
            VPos::Top => 0.0,
            VPos::Center => -height / 2.0,
            VPos::Bottom => -height,
        };
        let (dx, dy) = (dx.round() as i32, dy.round() as i32);
        let transform = style.transform();
        let (w, h) = self.get_size();
        let mut pixels = Vec::new();
        for g in glyphs {
            let Some(outline) = self.font.outline_glyph(g) else {
                continue;
            };
            let b = outline.px_bounds();
            outline.draw(|x, y, coverage| {
                let local = (
                    b.min.x as i32 + x as i32 + dx,
                    b.min.y as i32 + y as i32 + dy,
                );
                let (x, y) = transform.transform(local.0, local.1);
                pixels.push(((pos.0 + x, pos.1 + y), coverage));
            });
        }
        for ((x, y), coverage) in pixels {
            if coverage > 0.0 && x >= 0 && y >= 0 && x < w as i32 && y < h as i32 {
                let alpha = color.alpha * f64::from(coverage.min(1.0));
                self.inner
                    .draw_pixel((x, y), BackendColor { alpha, ..color })?;
            }
        }
        Ok(())
    }
}
