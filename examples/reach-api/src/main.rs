//! Sweeps initial boxes of the Duffing oscillator and follows a known forcing:
//! `cargo run -p reach-api`.

use reach_api::{analysis, forced, sweep, Duffing};
use reachc_runtime::Reach;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Checks the analysis and its certified constants once; every run below reuses them.
    let reach = Reach::new(&Duffing, analysis::CONTRACTION)?;
    let centres = [-1.5, -0.5, 0.5, 1.5];
    println!(
        "initial box x0 +- 0.1, v in [-0.1, 0.1]; PRS at t = 5 (delta = {})",
        reach.analysis().delta
    );
    println!(
        "{:>6}  {:>12}  {:>26}",
        "x0", "PRS radius", "x range (bounding box)"
    );
    for (x0, prs) in centres.iter().zip(sweep(&reach, &centres)?) {
        let st = prs.at(5.0).ok_or("t = 5 is a report time")?;
        let hull = prs.hull(5.0).ok_or("t = 5 is a report time")?;
        println!(
            "{x0:>6}  {:>12.6}  [{:>11.6}, {:>11.6}]",
            st.prs_radius, hull[0].lo, hull[0].hi
        );
    }
    let prs = forced(&reach, 1.0)?;
    let st = prs.at(5.0).ok_or("t = 5 is a report time")?;
    println!(
        "forced (+0.05 until t = 2, then -0.05) from x0 = 1: nominal x = {:.6}, PRS radius {:.6}",
        st.nominal()[0],
        st.prs_radius
    );
    let origin_in = prs.contains(&[0.0, 0.0], 5.0) == Some(true);
    println!(
        "the origin is {}in the PRS at t = 5",
        if origin_in { "" } else { "not " }
    );
    Ok(())
}
