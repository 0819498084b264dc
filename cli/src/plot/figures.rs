//! The figures, drawn with plotters on any backend (SVG or bitmap, see
//! [`super::output`]): the sets in a 2-D projection (deterministic sets dashed, PRS solid, as
//! in the paper's figures; sample paths, the nominal, unsafe sets), the radii against time and, for
//! time-varying rates, the contraction rate against time.
//! Each figure has a legend panel on its right, so nothing is drawn over the data.

use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::font::FAMILY;
use super::geometry::{clip, half_planes, Point};
use super::output::Draw;
use super::regions::Region;
use super::scene::{RadiusScene, RatesScene, SetsScene, WidthsScene};
use reachc_runtime::report::count;

/// Size of the sets figure.
pub const SETS_SIZE: (u32, u32) = (1100, 780);
/// Size of the radius figure.
pub const RADIUS_SIZE: (u32, u32) = (1100, 560);
/// Width of the legend panel.
const LEGEND_WIDTH: u32 = 320;
/// Characters per legend line (at the legend's font size, within the panel).
const LEGEND_CHARS: usize = 38;

/// Colours of the successive times (colour-blind-safe order of the usual tab10 palette, red
/// left out: it marks unsafe sets).
const PALETTE: [RGBColor; 7] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];
const UNSAFE: RGBColor = RGBColor(214, 39, 40);
/// Goal sets (olive: not one of the first eight report times' colours).
const GOAL: RGBColor = RGBColor(188, 189, 34);
const PATHS: RGBColor = RGBColor(100, 100, 100);
/// Fill of the union of the PRS over the horizon (opaque, so overlaps do not darken).
const ENVELOPE: RGBColor = RGBColor(178, 223, 138);
const GRID: RGBColor = RGBColor(232, 232, 232);
const NOTE: RGBColor = RGBColor(90, 90, 90);

/// How an entry of the legend is marked.
enum Mark {
    Line(RGBAColor, u32),
    Dashed(RGBAColor),
    Fill(RGBAColor),
    Dot(RGBAColor),
}

fn err(e: impl std::fmt::Display) -> String {
    format!("drawing failed: {e}")
}

/// A number for a label: at most 6 decimals, without trailing zeros.
pub(super) fn num(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// An axis label for the value `v` on an axis spanning `span`: enough decimals for ticks a
/// tenth of the span apart, trailing zeros dropped; large magnitudes in scientific notation
/// (`2.5e6`), which keeps the labels short.
fn tick(v: f64, span: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if span.abs() >= 1e5 || v.abs() >= 1e6 || (v.abs() < 1e-4 && span == v.abs()) {
        let s = format!("{v:.3e}");
        return match s.split_once('e') {
            Some((m, e)) if m.contains('.') => {
                format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
            }
            _ => s,
        };
    }
    let decimals = if span > 0.0 {
        (-(span / 10.0).log10().floor()).clamp(0.0, 12.0) as usize
    } else {
        6
    };
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// Splits `text` into lines of at most `width` characters, at spaces.
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split_whitespace() {
        match lines.last_mut() {
            Some(l) if l.chars().count() + 1 + word.chars().count() <= width => {
                l.push(' ');
                l.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

/// Draws the legend panel: marked entries, then notes in smaller grey text.
fn legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    s: u32,
    entries: &[(Mark, String)],
    notes: &[String],
) -> Result<(), String> {
    let i = |v: i32| v * s as i32;
    let label = TextStyle::from((FAMILY, f64::from(15 * s)).into_font())
        .pos(Pos::new(HPos::Left, VPos::Center));
    let small = TextStyle::from((FAMILY, f64::from(13 * s)).into_font())
        .color(&NOTE)
        .pos(Pos::new(HPos::Left, VPos::Center));
    let mut y = i(60);
    for (mark, text) in entries {
        let (x0, x1) = (i(12), i(46));
        match mark {
            Mark::Line(c, w) => area.draw(&PathElement::new(
                vec![(x0, y), (x1, y)],
                c.stroke_width(w * s),
            )),
            Mark::Dashed(c) => area.draw(&DashedPathElement::new(
                vec![(x0, y), (x1, y)],
                i(7),
                i(4),
                c.stroke_width(2 * s),
            )),
            Mark::Fill(c) => area.draw(&Rectangle::new(
                [(x0, y - i(7)), (x1, y + i(7))],
                c.filled(),
            )),
            Mark::Dot(c) => area.draw(&Circle::new(((x0 + x1) / 2, y), 4 * s, c.filled())),
        }
        .map_err(err)?;
        for line in wrap(text, LEGEND_CHARS) {
            area.draw(&Text::new(line, (i(56), y), label.clone()))
                .map_err(err)?;
            y += i(19);
        }
        y += i(5);
    }
    y += i(12);
    for note in notes {
        for line in wrap(note, LEGEND_CHARS + 6) {
            area.draw(&Text::new(line, (i(12), y), small.clone()))
                .map_err(err)?;
            y += i(17);
        }
        y += i(6);
    }
    Ok(())
}

/// A chart on `area` in the figures' style (scale `s`): the caption `title`, the margin and
/// the label areas.
fn chart_builder<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    title: &str,
    s: u32,
) -> ChartBuilder<'a, 'static, DB> {
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(title, (FAMILY, f64::from(22 * s)))
        .margin(14 * s)
        .x_label_area_size(50 * s)
        .y_label_area_size(80 * s);
    builder
}

/// Draws a chart's axes in the figures' style (scale `s`): the descriptions `desc` and tick
/// labels by `fmt` (x, then y), a light grid at the labelled ticks only.
fn mesh<DB: DrawingBackend, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, Y>>,
    s: u32,
    desc: [&str; 2],
    fmt: [&dyn Fn(&f64) -> String; 2],
) -> Result<(), String>
where
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let f = |v: u32| f64::from(v * s);
    chart
        .configure_mesh()
        .x_desc(desc[0])
        .y_desc(desc[1])
        .x_label_formatter(fmt[0])
        .y_label_formatter(fmt[1])
        .label_style((FAMILY, f(14)))
        .axis_desc_style((FAMILY, f(17)))
        .max_light_lines(0)
        .bold_line_style(GRID.stroke_width(s))
        .axis_style(BLACK.stroke_width(s))
        .set_all_tick_mark_size(5 * s as i32)
        .draw()
        .map_err(err)
}

/// The smallest rectangle holding `points`, padded by 6% (and to a non-zero size).
fn view(points: impl Iterator<Item = Point>) -> ((f64, f64), (f64, f64)) {
    let (mut x, mut y) = (
        (f64::INFINITY, f64::NEG_INFINITY),
        (f64::INFINITY, f64::NEG_INFINITY),
    );
    for p in points.filter(|p| p[0].is_finite() && p[1].is_finite()) {
        x = (x.0.min(p[0]), x.1.max(p[0]));
        y = (y.0.min(p[1]), y.1.max(p[1]));
    }
    let pad = |(lo, hi): (f64, f64)| {
        // No finite point: any view.
        if lo > hi {
            return (-1.0, 1.0);
        }
        let w = (hi - lo)
            .max(1e-9 * lo.abs().max(hi.abs()))
            .max(f64::MIN_POSITIVE);
        let w = if hi > lo { w } else { 1e-3 * lo.abs().max(1.0) };
        (lo - 0.06 * w, hi + 0.06 * w)
    };
    (pad(x), pad(y))
}

/// A closed polygon's points (the first repeated at the end).
fn closed(poly: &[Point]) -> Vec<(f64, f64)> {
    poly.iter()
        .chain(poly.first())
        .map(|p| (p[0], p[1]))
        .collect()
}

impl Draw for SetsScene {
    fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        s: u32,
    ) -> Result<(), String> {
        let (i, f) = (|v: i32| v * s as i32, |v: u32| f64::from(v * s));
        let (plot_area, legend_area) = panels(area, s);
        // The view holds the sets, the paths and the bounded unsafe sets.
        let bounded = self
            .regions
            .iter()
            .map(|(_, r)| r)
            .chain(self.goals.iter().flat_map(|(_, parts)| parts))
            .filter_map(Region::bounds);
        let (vx, vy) = view(
            self.slices
                .iter()
                .flat_map(|sl| sl.prs.iter().chain(&sl.det).chain(&sl.samples).copied())
                .chain(self.envelope.iter().flatten().copied())
                .chain(self.reference.iter().flat_map(|(_, p)| p.iter().copied()))
                .chain(self.nominal.iter().copied())
                .chain(self.paths.iter().flatten().copied())
                .chain(bounded.flat_map(|(x, y)| [[x.0, y.0], [x.1, y.1]])),
        );
        let mut chart = chart_builder(&plot_area, &self.title, s)
            .build_cartesian_2d(vx.0..vx.1, vy.0..vy.1)
            .map_err(err)?;
        let x_fmt = |v: &f64| tick(*v, vx.1 - vx.0);
        let y_fmt = |v: &f64| tick(*v, vy.1 - vy.0);
        mesh(
            &mut chart,
            s,
            [&self.axes[0], &self.axes[1]],
            [&x_fmt, &y_fmt],
        )?;
        let mut entries = Vec::new();

        // Unsafe sets and goals (a goal as the intersection of its parts' projections) first:
        // everything else is drawn over them.
        let (unsafe_fill, goal_fill) = (UNSAFE.mix(0.22), GOAL.mix(0.12));
        let unsafe_sets = self
            .regions
            .iter()
            .map(|(name, r)| (false, name, r.polygon_in(vx, vy)));
        let goals = self.goals.iter().map(|(name, parts)| {
            let first = parts[0].polygon_in(vx, vy);
            let poly = parts[1..].iter().fold(first, |poly, r| {
                clip(&poly, &half_planes(&r.polygon_in(vx, vy)))
            });
            (true, name, poly)
        });
        let mut goals_drawn = Vec::new();
        for (goal, name, poly) in unsafe_sets.chain(goals) {
            if poly.len() < 3 {
                continue;
            }
            let (fill, line, label) = match goal {
                false => (unsafe_fill, UNSAFE.stroke_width(s), RGBColor(150, 20, 20)),
                true => (goal_fill, GOAL.stroke_width(2 * s), RGBColor(110, 110, 10)),
            };
            chart
                .draw_series(std::iter::once(Polygon::new(closed(&poly), fill.filled())))
                .map_err(err)?;
            chart
                .draw_series(LineSeries::new(closed(&poly), line))
                .map_err(err)?;
            let n = poly.len() as f64;
            let c = (
                poly.iter().map(|p| p[0]).sum::<f64>() / n,
                poly.iter().map(|p| p[1]).sum::<f64>() / n,
            );
            let style = TextStyle::from((FAMILY, f(14)).into_font())
                .color(&label)
                .pos(Pos::new(HPos::Center, VPos::Center));
            chart
                .draw_series(std::iter::once(Text::new(name.clone(), c, style)))
                .map_err(err)?;
            if goal {
                goals_drawn.push(name.as_str());
            }
        }
        if !self.regions.is_empty() {
            let names: Vec<&str> = self.regions.iter().map(|(n, _)| n.as_str()).collect();
            entries.push((
                Mark::Fill(unsafe_fill),
                format!("unsafe: {}", names.join(", ")),
            ));
        }
        if !goals_drawn.is_empty() {
            entries.push((
                Mark::Fill(goal_fill),
                format!("goal: {}", goals_drawn.join(", ")),
            ));
        }

        if !self.envelope.is_empty() {
            chart
                .draw_series(
                    self.envelope
                        .iter()
                        .map(|p| Polygon::new(closed(p), ENVELOPE.filled())),
                )
                .map_err(err)?;
            entries.push((
                Mark::Fill(ENVELOPE.to_rgba()),
                format!(
                    "union of the PRS over all {} report times",
                    self.envelope.len()
                ),
            ));
        }
        for (k, sl) in self.slices.iter().enumerate() {
            let c = PALETTE[k % PALETTE.len()];
            if sl.prs.len() >= 3 {
                chart
                    .draw_series(std::iter::once(Polygon::new(
                        closed(&sl.prs),
                        c.mix(0.07).filled(),
                    )))
                    .map_err(err)?;
            }
        }
        for p in &self.paths {
            // A diverged path stops where its state stops being finite.
            let finite = p
                .iter()
                .take_while(|z| z[0].is_finite() && z[1].is_finite());
            chart
                .draw_series(LineSeries::new(
                    finite.map(|z| (z[0], z[1])),
                    PATHS.mix(0.3).stroke_width(s),
                ))
                .map_err(err)?;
        }
        if !self.paths.is_empty() {
            entries.push((
                Mark::Line(PATHS.mix(0.6), 1),
                format!(
                    "{} ({})",
                    count(self.paths.len() as u64, "sample path"),
                    self.paths_by
                ),
            ));
        }
        let mut any_det = false;
        for (k, sl) in self.slices.iter().enumerate() {
            let c = PALETTE[k % PALETTE.len()];
            if sl.det.len() >= 2 {
                any_det = true;
                chart
                    .draw_series(DashedLineSeries::new(
                        closed(&sl.det),
                        i(7),
                        i(4),
                        c.stroke_width(2 * s),
                    ))
                    .map_err(err)?;
            }
            if sl.prs.len() >= 3 {
                chart
                    .draw_series(LineSeries::new(closed(&sl.prs), c.stroke_width(2 * s)))
                    .map_err(err)?;
            }
            for piece in &sl.pieces {
                chart
                    .draw_series(LineSeries::new(closed(piece), c.mix(0.6).stroke_width(s)))
                    .map_err(err)?;
            }
            chart
                .draw_series(
                    sl.samples
                        .iter()
                        .map(|z| Circle::new((z[0], z[1]), 2 * s, c.mix(0.85).filled())),
                )
                .map_err(err)?;
            let what = if sl.prs.is_empty() {
                "X_t of the paths"
            } else {
                "PRS"
            };
            let mark = if sl.prs.is_empty() {
                Mark::Dot(c.to_rgba())
            } else {
                Mark::Line(c.to_rgba(), 2)
            };
            entries.push((mark, format!("t = {}: {what}", num(sl.t))));
        }
        if any_det {
            entries.push((
                Mark::Dashed(BLACK.mix(0.7)),
                "deterministic set (dashed, same colour)".into(),
            ));
        }
        if !self.slices.iter().all(|sl| sl.samples.is_empty())
            && self.slices.iter().any(|sl| !sl.prs.is_empty())
        {
            entries.push((
                Mark::Dot(PATHS.to_rgba()),
                "dots: the paths' X_t at those times".into(),
            ));
        }
        if let Some((label, path)) = &self.reference {
            chart
                .draw_series(DashedLineSeries::new(
                    path.iter().map(|z| (z[0], z[1])),
                    i(9),
                    i(6),
                    BLACK.mix(0.8).stroke_width(2 * s),
                ))
                .map_err(err)?;
            entries.push((Mark::Dashed(BLACK.mix(0.8)), label.clone()));
        }
        if !self.nominal.is_empty() {
            chart
                .draw_series(LineSeries::new(
                    self.nominal.iter().map(|z| (z[0], z[1])),
                    BLACK.stroke_width(2 * s),
                ))
                .map_err(err)?;
            for (k, sl) in self.slices.iter().enumerate() {
                if let Some(z) = sl.nominal {
                    let c = PALETTE[k % PALETTE.len()];
                    chart
                        .draw_series([
                            Circle::new((z[0], z[1]), 5 * s, BLACK.filled()),
                            Circle::new((z[0], z[1]), 3 * s, c.filled()),
                        ])
                        .map_err(err)?;
                }
            }
            entries.push((Mark::Line(BLACK.to_rgba(), 2), self.nominal_label.clone()));
        }
        let mut notes = self.notes.clone();
        let (px, py) = view(self.paths.iter().flatten().copied());
        let ratio = ((vx.1 - vx.0) / (px.1 - px.0)).min((vy.1 - vy.0) / (py.1 - py.0));
        if !self.paths.is_empty() && ratio > 100.0 {
            notes.push(format!(
                "the sets are about {ratio:.0e} times wider than the spread of the sample \
                 paths: earlier times show both"
            ));
        }
        legend(&legend_area, s, &entries, &notes)
    }
}

/// The plot and legend panels of a figure (the legend on the right, `s` the pixel scale).
fn panels<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    s: u32,
) -> (DrawingArea<DB, Shift>, DrawingArea<DB, Shift>) {
    let (w, _) = area.dim_in_pixel();
    area.split_horizontally(w.saturating_sub(LEGEND_WIDTH * s))
}

/// Radii spanning more than this ratio are drawn on a logarithmic axis.
const LOG_RATIO: f64 = 1e3;

/// A curve of a figure against time: values per report time (`None`: a gap), its colour,
/// whether it is dashed, its legend label.
struct Curve<'a> {
    values: Vec<Option<f64>>,
    colour: RGBColor,
    dashed: bool,
    label: &'a str,
}

/// Curves against the report `times` with the legend panel: a linear value axis, or a
/// logarithmic one when the values span more than [`LOG_RATIO`].
fn curves_figure<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    s: u32,
    (title, y_label): (&str, &str),
    times: &[f64],
    curves: &[Curve<'_>],
    notes: &[String],
) -> Result<(), String> {
    let (plot_area, legend_area) = panels(area, s);
    let t_last = times.last().copied().unwrap_or(1.0);
    let right = if t_last > 0.0 { t_last } else { 1.0 };
    let values: Vec<f64> = curves
        .iter()
        .flat_map(|c| c.values.iter().flatten())
        .copied()
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    let top = values.iter().copied().fold(0.0, f64::max);
    let low = values.iter().copied().fold(f64::INFINITY, f64::min);
    let mut builder = chart_builder(&plot_area, title, s);
    let mut notes = notes.to_vec();
    // Exploding radii (an analysis whose c is positive) would flatten everything else.
    if top > LOG_RATIO * low {
        let chart = builder
            .build_cartesian_2d(0.0..right, (low / 1.5..top * 1.5).log_scale())
            .map_err(err)?;
        notes.push(format!(
            "logarithmic scale: the values span {:.0} orders of magnitude",
            (top / low).log10()
        ));
        draw_curves(chart, s, true, (times, y_label), curves)?;
    } else {
        let top = if top > 0.0 { 1.08 * top } else { 1.0 };
        let chart = builder
            .build_cartesian_2d(0.0..right, 0.0..top)
            .map_err(err)?;
        draw_curves(chart, s, false, (times, y_label), curves)?;
    }
    let entries: Vec<(Mark, String)> = curves
        .iter()
        .map(|c| {
            let mark = if c.dashed {
                Mark::Dashed(c.colour.to_rgba())
            } else {
                Mark::Line(c.colour.to_rgba(), 2)
            };
            (mark, c.label.to_string())
        })
        .collect();
    legend(&legend_area, s, &entries, &notes)
}

/// The curves of [`curves_figure`] on a linear or logarithmic value axis (`log`: values that
/// are not positive are left out).
fn draw_curves<DB: DrawingBackend, Y>(
    mut chart: ChartContext<'_, DB, Cartesian2d<RangedCoordf64, Y>>,
    s: u32,
    log: bool,
    (times, y_label): (&[f64], &str),
    curves: &[Curve<'_>],
) -> Result<(), String>
where
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let i = |v: i32| v * s as i32;
    let x_span = times.last().copied().unwrap_or(1.0);
    let y_span = if log { 0.0 } else { chart.y_range().end };
    let x_fmt = |v: &f64| tick(*v, x_span);
    let y_fmt = |v: &f64| {
        if log {
            tick(*v, v.abs())
        } else {
            tick(*v, y_span)
        }
    };
    mesh(&mut chart, s, ["t", y_label], [&x_fmt, &y_fmt])?;
    for c in curves {
        // Runs of drawable points: a curve is broken where a value is missing, not finite, or
        // (log scale) not positive.
        let mut runs = vec![Vec::new()];
        for (t, v) in times.iter().zip(&c.values) {
            match v {
                Some(v) if v.is_finite() && (!log || *v > 0.0) => {
                    if let Some(r) = runs.last_mut() {
                        r.push((*t, *v));
                    }
                }
                _ => runs.push(Vec::new()),
            }
        }
        let style = c.colour.stroke_width(2 * s);
        for run in runs {
            if c.dashed {
                chart
                    .draw_series(DashedLineSeries::new(run, i(9), i(5), style))
                    .map_err(err)?;
            } else {
                chart
                    .draw_series(LineSeries::new(run, style))
                    .map_err(err)?;
            }
        }
    }
    Ok(())
}

impl Draw for RadiusScene {
    fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        s: u32,
    ) -> Result<(), String> {
        let some = |v: &[f64]| v.iter().map(|v| Some(*v)).collect();
        let mut curves = vec![
            Curve {
                values: some(&self.prs_radius),
                colour: PALETTE[1],
                dashed: false,
                label: &self.prs_label,
            },
            // Dashed over the PRS radius: the two are equal for a point initial set and no
            // inputs.
            Curve {
                values: some(&self.r_t),
                colour: PALETTE[0],
                dashed: true,
                label: "stochastic radius r_t",
            },
        ];
        if let Some((q, label)) = &self.quantile {
            curves.push(Curve {
                values: q.clone(),
                colour: PALETTE[2],
                dashed: false,
                label,
            });
        }
        let labels = (self.title.as_str(), "radius (P-norm)");
        curves_figure(area, s, labels, &self.times, &curves, &self.notes)
    }
}

impl Draw for WidthsScene {
    fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        s: u32,
    ) -> Result<(), String> {
        let curves: Vec<Curve<'_>> = self
            .states
            .iter()
            .enumerate()
            .flat_map(|(k, w)| {
                let colour = PALETTE[k % PALETTE.len()];
                [
                    Curve {
                        values: w.prs.clone(),
                        colour,
                        dashed: false,
                        label: &w.prs_label,
                    },
                    Curve {
                        values: w.paths.clone(),
                        colour,
                        dashed: true,
                        label: &w.paths_label,
                    },
                ]
            })
            .collect();
        let labels = (self.title.as_str(), "half-width about x*_t");
        curves_figure(area, s, labels, &self.times, &curves, &self.notes)
    }
}

impl Draw for RatesScene {
    fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        s: u32,
    ) -> Result<(), String> {
        let (plot_area, legend_area) = panels(area, s);
        let right = self
            .times
            .last()
            .copied()
            .filter(|t| *t > 0.0)
            .unwrap_or(1.0);
        let values = self.c.iter().flatten().copied();
        let (lo, hi) = values.fold((0.0f64, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
        let pad = 0.08 * (hi - lo).max(1e-9);
        let mut chart = chart_builder(&plot_area, &self.title, s)
            .build_cartesian_2d(0.0..right, lo - pad..hi + pad)
            .map_err(err)?;
        let y_span = hi - lo;
        let x_fmt = |v: &f64| tick(*v, right);
        let y_fmt = |v: &f64| tick(*v, y_span.max(v.abs()));
        mesh(&mut chart, s, ["t", self.label], [&x_fmt, &y_fmt])?;
        // Zero: contraction below, growth above.
        chart
            .draw_series(LineSeries::new(
                [(0.0, 0.0), (right, 0.0)],
                BLACK.mix(0.4).stroke_width(s),
            ))
            .map_err(err)?;
        // Each rate holds on its report interval: a step curve.
        let mut run = Vec::new();
        let mut t0 = 0.0;
        let colour = PALETTE[3];
        for (t, c) in self.times.iter().zip(&self.c) {
            match c {
                Some(c) => run.extend([(t0, *c), (*t, *c)]),
                None => {
                    chart
                        .draw_series(LineSeries::new(
                            std::mem::take(&mut run),
                            colour.stroke_width(2 * s),
                        ))
                        .map_err(err)?;
                }
            }
            t0 = *t;
        }
        chart
            .draw_series(LineSeries::new(run, colour.stroke_width(2 * s)))
            .map_err(err)?;
        let entries = [(Mark::Line(colour.to_rgba(), 2), self.label.to_string())];
        legend(&legend_area, s, &entries, &self.notes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_and_wrapping() {
        assert_eq!(num(3.0000000000000004), "3");
        assert_eq!(num(0.25), "0.25");
        assert_eq!(num(-0.0), "0");
        assert_eq!(tick(0.30000000000000004, 0.8), "0.3");
        assert_eq!(tick(-2.0, 5.0), "-2");
        assert_eq!(tick(1.5e7, 4e7), "1.5e7");
        assert_eq!(tick(1.00005, 1e-4), "1.00005");
        assert_eq!(tick(2e-6, 2e-6), "2e-6");
        assert_eq!(
            wrap("a bb ccc dddd", 6),
            vec!["a bb".to_string(), "ccc".into(), "dddd".into()]
        );
    }
}
