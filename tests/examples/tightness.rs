//! The tightness table of docs/paper-reproduction.md: for every shipped spec and analysis, under
//! both guarantees, the PRS's bounding-box half-widths at the horizon against the Monte Carlo
//! `1 - delta` quantiles of `|X_T,i - c_i|` (`c` the centre of that box), per coordinate.
//!
//! `cargo run -p reachc-e2e --example tightness [PATHS]` (default 20000 paths, uniform initial
//! states and inputs, Euler-Maruyama at a tenth of the analysis' step). Prints a markdown table:
//! per analysis and guarantee, the largest and the smallest ratio half-width / quantile over the
//! coordinates, and the first two coordinates' half-widths and quantiles.

use reachc_e2e::{interpreter_of, relative, shipped_specs};
use reachc_runtime::model::{Guarantee, Rate};
use reachc_runtime::simulate::{sample_paths, Options};
use reachc_runtime::Reach;

fn main() {
    let paths: u64 = std::env::args()
        .nth(1)
        .map_or(20_000, |s| s.parse().expect("PATHS is a number"));
    println!("| spec / analysis | guarantee | half-widths (first two) | quantiles | ratio max | ratio min |");
    println!("|---|---|---|---|---|---|");
    for spec in shipped_specs() {
        let model = reachc_compiler::driver::load(&spec).unwrap().model;
        let (sys, info) = interpreter_of(model);
        if info.states().len() > 100 {
            continue;
        }
        for analysis in info.analyses() {
            let mut row = Vec::new();
            for guarantee in [Guarantee::Pointwise, Guarantee::Uniform] {
                let mut info = info.clone();
                let a = info
                    .analyses_mut()
                    .iter_mut()
                    .find(|a| a.spec.name == analysis.spec.name)
                    .unwrap();
                a.spec.guarantee = guarantee;
                // Local rates need the tube; the pointwise default is the global rate.
                if guarantee == Guarantee::Pointwise && a.spec.rate == Rate::Local {
                    a.spec.rate = Rate::Global;
                }
                let spec_a = a.spec.clone();
                let Ok(prs) = Reach::paired(&sys, &info, &spec_a.name).and_then(|r| r.run()) else {
                    continue;
                };
                let Some(hull) = prs.hull(prs.horizon()) else {
                    continue;
                };
                let opts = Options {
                    paths,
                    seed: 3,
                    dt: Some(spec_a.step / 10.0),
                    ..Options::default()
                };
                let times = [0.0, prs.horizon()];
                let Ok(states) =
                    sample_paths(&sys, &info, &times, Some(prs.initial_center()), &opts)
                else {
                    continue;
                };
                let n = info.states().len();
                let level = 1.0 - spec_a.delta.max(1e-3);
                let mut half = Vec::new();
                let mut quant = Vec::new();
                for i in 0..n {
                    let c = 0.5 * (hull[i].lo + hull[i].hi);
                    let mut d: Vec<f64> = states.iter().map(|p| (p[n + i] - c).abs()).collect();
                    d.sort_by(f64::total_cmp);
                    let k = ((level * d.len() as f64).ceil() as usize).min(d.len() - 1);
                    half.push(0.5 * (hull[i].hi - hull[i].lo));
                    quant.push(d[k]);
                }
                let ratios: Vec<f64> = half.iter().zip(&quant).map(|(h, q)| h / q).collect();
                let fmt = |v: &[f64]| {
                    v.iter()
                        .take(2)
                        .map(|x| format!("{x:.4}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                row.push(format!(
                    "| {} / {} | {} | {} | {} | {:.3} | {:.3} |",
                    relative(&spec).trim_start_matches("specs/"),
                    spec_a.name,
                    match guarantee {
                        Guarantee::Pointwise => "pointwise",
                        Guarantee::Uniform => "uniform",
                    },
                    fmt(&half),
                    fmt(&quant),
                    ratios.iter().copied().fold(0.0, f64::max),
                    ratios.iter().copied().fold(f64::INFINITY, f64::min),
                ));
            }
            for r in row {
                println!("{r}");
            }
        }
    }
}
