//! Plots of a result (`reachc plot`, `reachc run --plot`): SVG and PNG pictures of the sets in
//! a 2-D projection and of the radii against time.
//!
//! - [`input`]: the result JSON and the Monte Carlo report, read and checked;
//! - [`select`]: which states and times to draw;
//! - [`geometry`]: the exact projections of the sets (support functions, boundary polygons);
//! - [`regions`]: the unsafe sets in the plane;
//! - [`scene`]: what the figures show, in plot coordinates;
//! - [`figures`], [`font`], [`raster`], [`output`]: drawing with plotters, the bundled font,
//!   the PNG backend's text, SVG and PNG renderings in memory.
//!
//! This file ties them together: from a result (and, if given, the spec's model for sample
//! paths and unsafe sets) to the files, in memory; the caller writes them whole or not at all
//! ([`reachc_runtime::output::Files`]).

pub mod figures;
pub mod font;
pub mod geometry;
pub mod input;
pub mod output;
pub mod raster;
pub mod regions;
pub mod scene;
pub mod select;

use std::path::{Path, PathBuf};

use reachc_runtime::model::{Analysis, ModelInfo};
use reachc_runtime::output::Files;
use reachc_runtime::simulate::{self, Options};

use geometry::{Plane, Point};
use input::{MovingSet, ResultFile};
use output::Draw;
use reachc_compiler::ir::Table;
use regions::Region;

/// Sample paths drawn by default.
pub const DEFAULT_PATHS: u64 = 50;

/// What to draw.
#[derive(Clone, Debug, Default)]
pub struct Choice {
    /// The plotted states by name (default: the first two outputs).
    pub states: Option<Vec<String>>,
    /// The times at which sets are drawn (default: four, evenly spaced, ending at the horizon).
    pub times: Option<Vec<f64>>,
    /// Number of sample paths.
    pub paths: u64,
    /// Their random seed (path `p` is path `p` of `reachc simulate --seed S`).
    pub seed: u64,
    /// Also fill the union of the PRS over all report times (the paper's Fig. 7 "envelope").
    pub envelope: bool,
}

/// The spec's model, for sample paths, unsafe sets and reference trajectories.
pub struct Model<'a> {
    /// The system (the interpreter) with its sets and analyses.
    pub sys: &'a dyn reachc_runtime::Model,
    /// Its tables: one with columns named as both plotted states is drawn as a reference.
    pub tables: &'a [Table],
}

impl Model<'_> {
    /// Its sets and analyses.
    fn info(&self) -> &ModelInfo {
        self.sys.info()
    }
}

/// The first table with columns named as the two plotted states, as a path in the plane with
/// its legend label (e.g. a reference trajectory `ref.px`, `ref.py`).
fn reference(model: &Model<'_>, plane: [usize; 2]) -> Option<(String, Vec<Point>)> {
    let names = plane.map(|i| model.info().states()[i].as_str());
    model.tables.iter().find_map(|t| {
        let (a, b) = (t.column_index(names[0])?, t.column_index(names[1])?);
        let path = t.values[a]
            .iter()
            .zip(&t.values[b])
            .map(|(&x, &y)| [x, y])
            .collect();
        Some((
            format!("table `{}` ({}, {}): reference", t.name, names[0], names[1]),
            path,
        ))
    })
}

/// A Monte Carlo quantile for the radius figure, and the per-state spreads for the widths
/// figure.
#[derive(Clone, Debug)]
pub struct Quantile {
    /// Per report time of the result (`None` where not finite).
    pub values: Vec<Option<f64>>,
    /// Per state of the result, in its order (empty: the report has none).
    pub states: Vec<StateWidths>,
    /// Number of paths.
    pub paths: u64,
    /// Where it comes from, for the legend.
    pub source: String,
}

/// One state's half-widths about the nominal over the report times (`None` where not finite).
#[derive(Clone, Debug, PartialEq)]
pub struct StateWidths {
    /// The PRS's bounding box.
    pub prs: Vec<Option<f64>>,
    /// The interval holding `1 - delta` of the paths.
    pub quantile: Vec<Option<f64>>,
}

impl StateWidths {
    /// Per state `i < n`, its widths over `steps`, `(prs, quantile)` of step `s` and state `i`
    /// from `widths(s, i)`.
    pub fn per_state<S>(
        steps: &[S],
        n: usize,
        widths: impl Fn(&S, usize) -> (Option<f64>, Option<f64>),
    ) -> Vec<StateWidths> {
        (0..n)
            .map(|i| {
                let (prs, quantile) = steps.iter().map(|s| widths(s, i)).unzip();
                StateWidths { prs, quantile }
            })
            .collect()
    }
}

impl Quantile {
    /// The quantiles of a Monte Carlo report, described by `source`.
    pub fn of(report: &simulate::SimReport, source: String) -> Quantile {
        let finite = |v: f64| Some(v).filter(|v| v.is_finite());
        Quantile {
            values: report.steps.iter().map(|s| finite(s.quantile)).collect(),
            states: StateWidths::per_state(&report.steps, report.states.len(), |s, i| {
                (finite(s.states[i].prs), finite(s.states[i].quantile))
            }),
            paths: report.paths,
            source,
        }
    }
}

/// Output file names: `DIR/<analysis>_sets.svg` and so on.
fn file(dir: &Path, analysis: &str, figure: &str, ext: &str) -> PathBuf {
    dir.join(format!("{analysis}_{figure}.{ext}"))
}

/// The label of a set of the spec: its name, and for a moving set (method.md 8.15, drawn from
/// the spec where the result does not give its positions) the time of its shape, `t = 0`.
fn spec_label(name: &str, moving: bool) -> String {
    if moving {
        format!("{name} at t = 0")
    } else {
        name.to_string()
    }
}

/// The unsafe sets of `info` in the plane, except those the result gives the positions of
/// (`from_result`, drawn by [`scene::moving_regions`]); those that do not constrain it are
/// listed in `notes`.
fn unsafe_regions(
    info: &ModelInfo,
    plane: [usize; 2],
    from_result: &[MovingSet],
    notes: &mut Vec<String>,
) -> Vec<(String, Region)> {
    let mut regions = Vec::new();
    let given = |name: &str| from_result.iter().any(|m| !m.goal && m.name == name);
    for u in info.unsafe_sets().iter().filter(|u| !given(&u.name)) {
        match Region::of(&u.shape, plane) {
            Some(r) => regions.push((spec_label(&u.name, !u.moving.is_empty()), r)),
            None => notes.push(scene::not_drawn("unsafe set", &u.name)),
        }
    }
    regions
}

/// The goal sets of `info` in the plane, each as its parts' projections (those that do not
/// constrain the plane are left out; a goal none of whose parts does is listed in `notes`),
/// except those the result gives the positions of (`from_result`).
fn goal_regions(
    info: &ModelInfo,
    plane: [usize; 2],
    from_result: &[MovingSet],
    notes: &mut Vec<String>,
) -> Vec<(String, Vec<Region>)> {
    let mut goals = Vec::new();
    let given = |name: &str| from_result.iter().any(|m| m.goal && m.name == name);
    for g in info.goals().iter().filter(|g| !given(&g.name)) {
        let parts: Vec<Region> = g
            .parts
            .iter()
            .filter_map(|p| Region::of(p, plane))
            .collect();
        if parts.is_empty() {
            notes.push(scene::not_drawn("goal", &g.name));
        } else {
            goals.push((spec_label(&g.name, !g.moving.is_empty()), parts));
        }
    }
    goals
}

/// Records `choice.paths` sample paths at `times` (with `simulate`'s defaults: random inputs,
/// Euler steps and input hold times of one report step).
fn sample(
    model: &Model<'_>,
    times: &[f64],
    center: Option<&[f64]>,
    choice: &Choice,
) -> Result<Vec<Vec<f64>>, String> {
    let opts = Options {
        paths: choice.paths,
        seed: choice.seed,
        ..Options::default()
    };
    simulate::sample_paths(model.sys, model.info(), times, center, &opts)
        .map_err(|e| format!("cannot simulate sample paths: {e}"))
}

/// The rendered figures, or the first rendering's error.
fn rendered(files: Vec<(PathBuf, Result<Vec<u8>, String>)>) -> Result<Files, String> {
    let mut out = Files::new();
    for (path, bytes) in files {
        out.add(path, bytes?);
    }
    Ok(out)
}

/// Both renderings of a figure.
fn renderings<F: Draw>(
    figure: &F,
    size: output::Size,
    dir: &Path,
    analysis: &str,
    name: &str,
) -> Vec<(PathBuf, Result<Vec<u8>, String>)> {
    vec![
        (
            file(dir, analysis, name, "svg"),
            output::svg(figure, size).map(String::into_bytes),
        ),
        (file(dir, analysis, name, "png"), output::png(figure, size)),
    ]
}

/// Plots a result: `DIR/<analysis>_sets.svg/.png` (the sets at the chosen times, sample paths
/// and unsafe sets when the model is given, moving sets where the result says they are), `DIR/<analysis>_radius.svg/.png`, with a Monte
/// Carlo report's per-state spreads `DIR/<analysis>_widths.svg/.png` (the plotted states'
/// bounding-box half-widths against the paths') and, when the rates vary in time (local or
/// empirical), `DIR/<analysis>_rates.svg/.png` (`c_t`). Returns the
/// files, rendered but not written; the error is a message.
pub fn plot_result(
    result: &ResultFile,
    model: Option<&Model<'_>>,
    quantile: Option<&Quantile>,
    choice: &Choice,
    dir: &Path,
) -> Result<Files, String> {
    font::register()?;
    if let Some(m) = model {
        if m.info().name() != result.model || m.info().states() != result.states {
            return Err(format!(
                "the spec's model `{}` ({} states) is not the result's model `{}` ({} states)",
                m.info().name(),
                m.info().states().len(),
                result.model,
                result.states.len()
            ));
        }
    }
    let states = select::pick_states(&result.states, &result.outputs, choice.states.as_deref())?;
    let picked = select::pick_times(&result.times(), choice.times.as_deref())?;
    let plane = Plane::new(states, &result.constants.metric)
        .ok_or("the result's metric is not positive definite")?;
    let mut notes = Vec::new();
    let moving = result.moving_sets()?;
    let mut goals = model.map_or_else(Vec::new, |m| {
        goal_regions(m.info(), states, &moving, &mut notes)
    });
    let (mut regions, paths) = match model {
        Some(m) => (
            unsafe_regions(m.info(), states, &moving, &mut notes),
            sample(m, &result.times(), Some(&result.initial_center), choice)?,
        ),
        None => {
            let sets = match moving.is_empty() {
                true => "unsafe sets",
                false => "fixed unsafe sets and goals",
            };
            notes.push(format!(
                "no sample paths or {sets}: they need the spec (--spec)"
            ));
            (Vec::new(), Vec::new())
        }
    };
    // Moving sets where they are: at the chosen times, or at the first and last report time.
    let mut at = match choice.times {
        Some(_) => picked.clone(),
        None => vec![0, result.steps.len().saturating_sub(1)],
    };
    at.dedup();
    let drawn = scene::moving_regions(result, &moving, states, &at, &mut notes);
    regions.extend(drawn.unsafe_sets);
    goals.extend(drawn.goals);
    let mut sets = scene::sets_scene(result, &plane, &picked, &paths, regions);
    sets.goals = goals;
    if choice.envelope {
        sets.envelope = scene::envelope(result, &plane);
    }
    sets.reference = model.and_then(|m| reference(m, states));
    sets.notes.extend(notes);
    let radius = scene::radius_scene(
        result,
        quantile.map(|q| (q.values.clone(), q.paths, q.source.as_str())),
    );
    let mut files = renderings(&sets, figures::SETS_SIZE, dir, &result.analysis, "sets");
    files.extend(renderings(
        &radius,
        figures::RADIUS_SIZE,
        dir,
        &result.analysis,
        "radius",
    ));
    if let Some(widths) = quantile.and_then(|q| scene::widths_scene(result, states, q)) {
        files.extend(renderings(
            &widths,
            figures::RADIUS_SIZE,
            dir,
            &result.analysis,
            "widths",
        ));
    }
    if let Some(rates) = scene::rates_scene(result) {
        files.extend(renderings(
            &rates,
            figures::RADIUS_SIZE,
            dir,
            &result.analysis,
            "rates",
        ));
    }
    rendered(files)
}

/// The report times `0, step, 2 step, ..., horizon` of an analysis (the last step may be
/// shorter; a ratio that is an integer up to rounding adds no sliver step).
fn report_times(analysis: &Analysis) -> Vec<f64> {
    let (h, s) = (analysis.spec.horizon, analysis.spec.step);
    let steps = (h / s * (1.0 - 1e-12)).ceil().max(1.0) as usize;
    let mut times: Vec<f64> = (0..steps).map(|k| k as f64 * s).collect();
    times.push(h);
    times
}

/// Plots an analysis that has no PRS (its constants could not be bounded): sample paths and
/// unsafe sets only, `DIR/<analysis>_sets.svg/.png` (rendered, not written).
pub fn plot_without_result(
    model: &Model<'_>,
    analysis: &Analysis,
    choice: &Choice,
    dir: &Path,
) -> Result<Files, String> {
    font::register()?;
    let info = model.info();
    let a = &analysis.spec;
    if !(a.step > 0.0 && a.horizon > 0.0 && a.horizon / a.step <= 1e7) {
        return Err(format!(
            "analysis `{}`: horizon {} and step {} give no report times to plot",
            a.name, a.horizon, a.step
        ));
    }
    let states = select::pick_states(info.states(), &a.outputs, choice.states.as_deref())?;
    let times = report_times(analysis);
    let picked = select::pick_times(&times, choice.times.as_deref())?;
    let plane = Plane::of_states(states);
    let mut notes = Vec::new();
    let regions = unsafe_regions(info, states, &[], &mut notes);
    let paths = sample(model, &times, None, choice)?;
    let mut sets = scene::paths_scene(info, analysis, &plane, (&times, &picked), &paths, regions);
    sets.goals = goal_regions(info, states, &[], &mut sets.notes);
    sets.reference = reference(model, states);
    sets.notes.extend(notes);
    rendered(renderings(&sets, figures::SETS_SIZE, dir, &a.name, "sets"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use reachc_runtime::model::{
        Bounds, GoalSet, ModelParts, Moving, Slot, UnsafeSet, UnsafeShape,
    };
    use reachc_test_support::models::model;

    /// The spec's sets: fixed ones by name, a moving one the result does not give at its
    /// shape of `t = 0`, labelled so; those the result gives are left to it.
    #[test]
    fn spec_sets_that_move_are_labelled_or_left_to_the_result() {
        let bar = |lo: f64| UnsafeShape::Box(vec![(0, Bounds::new(lo, lo + 1.0))]);
        let moves = vec![Moving {
            part: 0,
            slot: Slot::Lo(0),
            number: 0,
        }];
        let set = |name: &str, moving: &Vec<Moving>| UnsafeSet {
            name: name.into(),
            shape: bar(1.0),
            moving: moving.clone(),
        };
        let info = ModelInfo::from_parts(ModelParts {
            unsafe_sets: vec![
                set("fixed", &vec![]),
                set("slides", &moves),
                set("given", &moves),
            ],
            goals: vec![GoalSet {
                name: "dock".into(),
                parts: vec![bar(3.0)],
                moving: moves,
                window: None,
                stay: false,
            }],
            ..model("m", &["x", "y"], &[], &[(0.0, 0.0); 2]).into_parts()
        });
        let from_result = [MovingSet {
            name: "given".into(),
            goal: false,
            at: vec![vec![bar(2.0)]],
        }];
        let mut notes = Vec::new();
        let labels: Vec<String> = unsafe_regions(&info, [0, 1], &from_result, &mut notes)
            .into_iter()
            .map(|(label, _)| label)
            .collect();
        assert_eq!(labels, ["fixed", "slides at t = 0"]);
        let goals = goal_regions(&info, [0, 1], &from_result, &mut notes);
        assert_eq!(goals[0].0, "dock at t = 0");
        assert!(notes.is_empty());
    }
}
