//! Input signals of the sample paths: piecewise constant on intervals `[i h, (i + 1) h)` of the
//! hold time `h`, drawn afresh per path and interval.

use super::rng::{uniform, PathRng};
use crate::lanes::X8;
use crate::model::Bounds;

/// How the inputs of a sample path are chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputMode {
    /// Uniform in the input box, redrawn every hold time (the default).
    Random,
    /// A uniformly random corner of the input box, redrawn every hold time ("bang-bang"; a hold
    /// time at least the horizon keeps one corner per path).
    Corners,
    /// The centre of the input box (the nominal's input).
    Centre,
}

impl InputMode {
    /// Its name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            InputMode::Random => "random",
            InputMode::Corners => "corners",
            InputMode::Centre => "centre",
        }
    }

    /// Parses a command-line name (`center` is accepted for `centre`).
    pub fn parse(s: &str) -> Option<InputMode> {
        match s {
            "random" => Some(InputMode::Random),
            "corners" => Some(InputMode::Corners),
            "centre" | "center" => Some(InputMode::Centre),
            _ => None,
        }
    }
}

/// The input box and how to draw from it.
#[derive(Clone, Debug)]
pub(crate) struct InputSchedule {
    lo: Vec<f64>,
    width: Vec<f64>,
    mode: InputMode,
    hold: f64,
}

impl InputSchedule {
    /// `hold > 0` is the hold time.
    pub(crate) fn new(input_box: &[Bounds], mode: InputMode, hold: f64) -> Self {
        InputSchedule {
            lo: input_box.iter().map(|r| r.lo).collect(),
            width: input_box.iter().map(|r| r.hi - r.lo).collect(),
            mode,
            hold,
        }
    }

    /// Sets `u` for the Euler step starting at `t` (models with inputs only). `interval` is the
    /// path's current hold interval (start a path with `None`); the input is redrawn when it
    /// changes.
    #[inline(always)] // keeps the path's stream in registers in the caller's loop
    pub(crate) fn update(
        &self,
        t: f64,
        interval: &mut Option<u64>,
        rng: &mut PathRng,
        u: &mut [f64],
    ) {
        if self.redraw(t, interval) {
            for (j, uj) in u.iter_mut().enumerate() {
                let bits = if self.draws() { rng.next_u64() } else { 0 };
                *uj = self.draw(j, bits);
            }
        }
    }

    /// [`update`](Self::update) for eight paths in lanes (lane `l` of `u[j]`: input `j` of path
    /// `l`), whose hold intervals are all `interval` (paths stepped in lockstep from the same
    /// start are), `next` giving each lane's next 64 random bits: the same draws and values,
    /// lane by lane.
    #[inline]
    pub(crate) fn update_x8(
        &self,
        t: f64,
        interval: &mut Option<u64>,
        mut next: impl FnMut() -> [u64; 8],
        u: &mut [X8],
    ) {
        if self.redraw(t, interval) {
            for (j, uj) in u.iter_mut().enumerate() {
                let bits = if self.draws() { next() } else { [0; 8] };
                *uj = X8(bits.map(|b| self.draw(j, b)));
            }
        }
    }

    /// Whether the input changes at the step starting at `t`, moving `interval` to that
    /// step's hold interval.
    #[inline(always)]
    fn redraw(&self, t: f64, interval: &mut Option<u64>) -> bool {
        // The relative slack puts t = i h (up to rounding) into interval i, not i - 1.
        let i = match self.mode {
            InputMode::Centre => 0,
            _ => (t / self.hold * (1.0 + 1e-12)) as u64,
        };
        let changed = *interval != Some(i);
        *interval = Some(i);
        changed
    }

    /// Whether an input value takes random bits (one draw of 64 per input).
    #[inline(always)]
    fn draws(&self) -> bool {
        self.mode != InputMode::Centre
    }

    /// Input `j`'s value from the random `bits` (ignored by [`InputMode::Centre`]).
    #[inline(always)]
    fn draw(&self, j: usize, bits: u64) -> f64 {
        match self.mode {
            InputMode::Random => self.lo[j] + self.width[j] * uniform(bits),
            InputMode::Corners => {
                if bits >> 63 == 1 {
                    self.lo[j] + self.width[j]
                } else {
                    self.lo[j]
                }
            }
            InputMode::Centre => self.lo[j] + 0.5 * self.width[j],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Bounds;

    #[test]
    fn inputs_change_only_at_hold_boundaries_and_stay_in_the_box() {
        let s = InputSchedule::new(
            &[Bounds::new(-1.0, 1.0), Bounds::new(2.0, 2.5)],
            InputMode::Random,
            0.1,
        );
        let mut rng = PathRng::new(0, 0);
        let (mut u, mut iv) = (vec![0.0; 2], None);
        let mut changes = 0;
        let mut prev = vec![f64::NAN; 2];
        for k in 0..100 {
            s.update(k as f64 * 0.01, &mut iv, &mut rng, &mut u);
            assert!((-1.0..=1.0).contains(&u[0]) && (2.0..=2.5).contains(&u[1]));
            if u != prev {
                changes += 1;
                // t = 0, 0.1, ..., 0.9 (k = 0, 10, 20, ...): exactly at the boundaries.
                assert_eq!(k % 10, 0, "changed at step {k}");
            }
            prev.clone_from(&u);
        }
        assert_eq!(changes, 10);
    }

    #[test]
    fn corners_and_centre() {
        let b = [Bounds::new(-1.0, 1.0)];
        let corners = InputSchedule::new(&b, InputMode::Corners, 1.0);
        let centre = InputSchedule::new(&b, InputMode::Centre, 1.0);
        let mut rng = PathRng::new(0, 0);
        let mut seen = [0; 2];
        for k in 0..200 {
            let (mut u, mut iv) = (vec![0.0], None);
            corners.update(k as f64, &mut iv, &mut rng, &mut u);
            assert!(u[0] == -1.0 || u[0] == 1.0);
            seen[usize::from(u[0] > 0.0)] += 1;
        }
        assert!(seen[0] > 70 && seen[1] > 70, "{seen:?}");
        let (mut u, mut iv) = (vec![9.0], None);
        centre.update(3.0, &mut iv, &mut rng, &mut u);
        assert_eq!(u[0], 0.0);
        assert_eq!(InputMode::parse("center"), Some(InputMode::Centre));
    }
}
