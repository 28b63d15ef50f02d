//! The solved speed profile on the path grid: `s_i`, `ṡ_i = √b_i` and the
//! time `t_i` at each grid point. On segment `i` the path acceleration is
//! constant, so `Δt_i = 2Δs_i/(ṡ_i + ṡ_{i+1})` and
//! `s(τ) = s_i + ṡ_i τ + s̈ τ²/2`.

use serde::Serialize;

use super::grid::PathGrid;

/// The solved profile on the grid: `s_i`, `ṡ_i = √b_i`, `t_i`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpeedProfile {
    /// Grid points, units of the path parameter (rad of joint-space chord).
    pub s: Vec<f64>,
    /// `ṡ` at each grid point, per second.
    pub s_dot: Vec<f64>,
    /// Time at each grid point, seconds.
    pub t: Vec<f64>,
}

impl SpeedProfile {
    /// From `b_i = ṡ²` at the grid points.
    pub fn new(grid: &PathGrid, b: &[f64]) -> Self {
        let s_dot: Vec<f64> = b.iter().map(|b| b.max(0.0).sqrt()).collect();
        let mut t = Vec::with_capacity(b.len());
        t.push(0.0);
        for i in 0..grid.segments() {
            let dt = 2.0 * grid.step(i) / (s_dot[i] + s_dot[i + 1]);
            t.push(t[i] + dt);
        }
        Self {
            s: grid.s.clone(),
            s_dot,
            t,
        }
    }

    /// Total duration, seconds.
    pub fn duration(&self) -> f64 {
        *self.t.last().unwrap_or(&0.0)
    }

    /// `(s, ṡ, s̈, segment)` at time `t` (clamped to the profile).
    pub fn state_at(&self, t: f64) -> (f64, f64, f64, usize) {
        let last = self.t.len() - 2;
        let i = (self.t.partition_point(|&ti| ti <= t).max(1) - 1).min(last);
        let dt = self.t[i + 1] - self.t[i];
        let tau = (t - self.t[i]).clamp(0.0, dt);
        let acc = (self.s_dot[i + 1] - self.s_dot[i]) / dt;
        let s = self.s[i] + self.s_dot[i] * tau + 0.5 * acc * tau * tau;
        (s.min(self.s[i + 1]), self.s_dot[i] + acc * tau, acc, i)
    }
}
