//! Runs the stochastic cart under the model-predictive controller for 6 s and reports the time
//! per reachability call and the constraint violations: `cargo run --release -p mpc`.

use mpc::{closed_loop, Cart};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let s = closed_loop(&Cart, 60, 1)?;
    let mut times: Vec<f64> = s
        .reach_times
        .iter()
        .map(|d| d.as_secs_f64() * 1e3)
        .collect();
    times.sort_by(f64::total_cmp);
    let mean = times.iter().sum::<f64>() / times.len() as f64;
    println!(
        "{} periods of 0.1 s: Reach::from_box + tighten {mean:.2} ms mean, {:.2} ms median, {:.2} ms max",
        s.periods,
        times[times.len() / 2],
        times[times.len() - 1]
    );
    println!(
        "violations (wall or speed limit) in {} periods, no feasible candidate in {}",
        s.violations, s.infeasible
    );
    println!("    t      p   tightened wall (end of plan)");
    for (k, (p, w)) in s.positions.iter().zip(&s.walls).enumerate().step_by(5) {
        println!("{:>5.1} {p:>6.3} {w:>6.3}", (k + 1) as f64 * 0.1);
    }
    Ok(())
}
