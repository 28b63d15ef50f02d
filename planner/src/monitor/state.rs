//! The state of an execution along one sub-goal's planned trajectory:
//! where the robot is ([`Cursor`]: the plan sample, its plan time, the
//! speed override `σ`, the last executed samples) and the change of speed
//! under way ([`Ramp`]: `σ` and `σ̇` at the plan samples it covers).

/// Where execution is along one sub-goal's planned trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct Cursor {
    /// The plan sample the robot is at.
    pub index: usize,
    /// Its plan time, seconds from the start of the sub-goal's trajectory.
    pub s: f64,
    /// Speed override `σ = ṡ`, 0 (at rest) to 1 (as planned).
    pub sigma: f64,
    /// Mean joint velocities over the last executed interval and its
    /// duration (for the acceleration recomputed from positions).
    pub(super) last: Option<(Vec<f64>, f64)>,
    /// The last executed samples, this one last (at most three): plan
    /// index and time on [`Self::clock`]. Missing ones were at rest.
    pub(super) past: Vec<(usize, f64)>,
    /// Execution time since the cursor was placed, s.
    pub(super) clock: f64,
    /// The speed change under way, if any.
    pub(super) ramp: Option<Ramp>,
}

impl Cursor {
    pub const START: Cursor = Cursor {
        index: 0,
        s: 0.0,
        sigma: 1.0,
        last: None,
        past: Vec::new(),
        clock: 0.0,
        ramp: None,
    };

    /// At plan sample `index` (time `s`), at rest or resting.
    pub fn at(index: usize, s: f64, sigma: f64) -> Self {
        Self {
            index,
            s,
            sigma,
            ..Self::START
        }
    }

    /// The last three executed samples (plan index, time), oldest first;
    /// samples before the first known one at rest a period `dt` apart.
    pub(super) fn history(&self, dt: f64) -> [(usize, f64); 3] {
        let known = match self.past.len() {
            0 => vec![(self.index, self.clock)],
            n => self.past[n.saturating_sub(3)..].to_vec(),
        };
        let first = known[0];
        let mut out = [first; 3];
        let pad = 3 - known.len();
        for (i, slot) in out.iter_mut().enumerate() {
            *slot = match i < pad {
                true => (first.0, first.1 - dt * (pad - i) as f64),
                false => known[i - pad],
            };
        }
        out
    }

    pub(super) fn last(&self) -> Option<&(Vec<f64>, f64)> {
        self.last.as_ref()
    }

    pub(super) fn ramp(&self) -> Option<&Ramp> {
        self.ramp.as_ref()
    }

    /// The cursor after one executed sample at plan index `index`.
    pub(super) fn moved(&self, index: usize, s: f64, sigma: f64, last: (Vec<f64>, f64)) -> Cursor {
        let clock = self.clock + last.1;
        let mut past = self.past.clone();
        past.push((index, clock));
        if past.len() > 3 {
            past.remove(0);
        }
        let ramp = self
            .ramp
            .clone()
            .filter(|r| !(r.ended(index) && sigma == r.target));
        Cursor {
            index,
            s,
            sigma,
            last: Some(last),
            past,
            clock,
            ramp,
        }
    }
}

/// A change of speed: `σ` at plan samples `first..`, then `target`.
#[derive(Debug, Clone, PartialEq)]
pub struct Ramp {
    pub target: f64,
    pub(super) first: usize,
    pub(super) sigmas: Vec<f64>,
    /// `σ̇` at the same samples, 1/s.
    pub(super) rates: Vec<f64>,
}

impl Ramp {
    /// `σ` at plan sample `index` (at or after the ramp's first).
    pub fn sigma(&self, index: usize) -> f64 {
        self.at(&self.sigmas, index).unwrap_or(self.target)
    }

    pub(super) fn rate(&self, index: usize) -> f64 {
        self.at(&self.rates, index).unwrap_or(0.0)
    }

    fn at(&self, values: &[f64], index: usize) -> Option<f64> {
        index
            .checked_sub(self.first)
            .and_then(|i| values.get(i))
            .copied()
    }

    /// True once `index` is the ramp's last sample or past it.
    pub fn ended(&self, index: usize) -> bool {
        index + 1 >= self.first + self.sigmas.len()
    }
}
