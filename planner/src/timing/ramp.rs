//! Ramped switches: the time-optimal speed profile with its peaks rounded
//! so that the path acceleration falls at a jerk-limited rate where it
//! switches from speeding up to slowing down, instead of jumping.
//!
//! The time-optimal profile `b(s) = ṡ²` switches its path acceleration
//! `a = b'/2` from `+A` to `−A` (a peak of `b`) or from `+A` to 0 (the start
//! of a cruise) in one grid step: the joints' accelerations `q̈ = q'' b + q' a`
//! jump by up to `2A_j`, and the moving-average filter of
//! [`jerk`](super::jerk) needs a width of `2A/J` to bound the jerk there.
//! A fall of `a` spread over time at rate `κ J` needs no filter: with
//! `dt = ds/ṡ`, joint `j` keeps `|q'_j| |da/dt| ≤ κ J_j` when
//!
//! ```text
//! b''(s) = 2 da/ds ≥ −c(s),    c(s) = 2κ min_j J_j / (ṡ(s) |q'_j(s)|)
//! ```
//!
//! The greatest profile below the time-optimal `b*` with that bound is
//! `g = conv(b* + φ) − φ`, where `φ'' = c` and `conv` is the greatest convex
//! minorant (`g + φ` convex ⇔ `g'' ≥ −c`; the largest convex function
//! below `b* + φ` is its lower convex hull). On the grid `φ` is summed with
//! the discrete second difference, the hull is Andrew's monotone chain,
//! `O(N)`. `ṡ` is taken from a given profile (`b*` in the first round, an
//! upper bound on every profile's, so `c` is the tighter one). The rises
//! of `a` (from rest, into the end's rest, into and out of a dip of the
//! speed limit) are left to the filter: the greatest
//! profile with `b'' ≤ c` does not exist (the bound is not lattice-closed),
//! so a rise needs a non-convex program. The profile is then timed again
//! with `b ≤ g` as one more row per grid point, which keeps every other
//! limit exactly ([`topp`](super::topp)).

use super::grid::PathGrid;
use super::spline::PiecewiseCubic;

/// Least speed, as a share of the profile's fastest, at which `c` is
/// evaluated (`c` grows without bound at rest, where `b*` is no peak).
const LEAST_SPEED: f64 = 0.05;

/// The rounded profile `g ≤ b*` on `grid`: `b_star[k] = b*(s_k)` (1/s²),
/// `speeds[k]` the `ṡ²` at which `c` is evaluated (1/s²), `jerk` the
/// joints' limits (rad/s³), `kappa ∈ (0, 1]` the share of them the path
/// acceleration's fall may use. `g[k] ∈ [0, b*_k]`, one per grid point.
pub fn rounded_peaks(
    spline: &PiecewiseCubic,
    grid: &PathGrid,
    b_star: &[f64],
    speeds: &[f64],
    jerk: &[f64],
    kappa: f64,
) -> Vec<f64> {
    let n = grid.segments();
    let fastest = speeds.iter().copied().fold(0.0, f64::max).sqrt();
    let (mut q, mut dq, mut ddq) = (
        vec![0.0; spline.dim()],
        vec![0.0; spline.dim()],
        vec![0.0; spline.dim()],
    );
    let curvature: Vec<f64> = (0..=n)
        .map(|k| {
            spline.eval(grid.s[k], &mut q, &mut dq, &mut ddq);
            let speed = speeds[k].max(0.0).sqrt().max(LEAST_SPEED * fastest);
            let rate = dq
                .iter()
                .zip(jerk)
                .map(|(d, j)| j / d.abs().max(f64::MIN_POSITIVE))
                .fold(f64::INFINITY, f64::min);
            2.0 * kappa * rate / speed
        })
        .collect();
    rounded_falls(grid, b_star, &curvature)
}

/// The greatest profile below `b` with `b'' ≥ −c` (`curvature[k]`):
/// `conv(b + φ) − φ` (see the module docs).
fn rounded_falls(grid: &PathGrid, b: &[f64], curvature: &[f64]) -> Vec<f64> {
    let n = grid.segments();
    // φ with φ_0 = 0, φ'_0 = 0 and discrete second difference c_k at each
    // inner grid point: (φ_{k+1} − φ_k)/Δs_k − (φ_k − φ_{k−1})/Δs_{k−1} = c_k (Δs_{k−1} + Δs_k)/2.
    let mut phi = vec![0.0; n + 1];
    let mut slope = 0.0;
    for k in 0..n {
        if k > 0 {
            slope += curvature[k] * 0.5 * (grid.step(k - 1) + grid.step(k));
        }
        phi[k + 1] = phi[k] + slope * grid.step(k);
    }
    let lifted: Vec<f64> = b.iter().zip(&phi).map(|(b, p)| b + p).collect();
    let hull = lower_hull(&grid.s, &lifted);
    let mut rounded = vec![0.0; n + 1];
    for pair in hull.windows(2) {
        let (i, m) = (pair[0], pair[1]);
        for k in i..=m {
            let t = (grid.s[k] - grid.s[i]) / (grid.s[m] - grid.s[i]);
            let chord = lifted[i] + t * (lifted[m] - lifted[i]);
            rounded[k] = (chord - phi[k]).clamp(0.0, b[k]);
        }
    }
    rounded
}

/// Indices of the lower convex hull of the points `(x_k, y_k)`, `x`
/// increasing, from the first to the last (Andrew's monotone chain).
fn lower_hull(x: &[f64], y: &[f64]) -> Vec<usize> {
    let mut hull: Vec<usize> = Vec::with_capacity(x.len());
    for k in 0..x.len() {
        while let [.., a, b] = hull[..] {
            // Drop `b` unless it lies strictly below the chord from `a` to `k`.
            let cross = (x[b] - x[a]) * (y[k] - y[a]) - (y[b] - y[a]) * (x[k] - x[a]);
            if cross <= 0.0 {
                hull.pop();
            } else {
                break;
            }
        }
        hull.push(k);
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sharp peak (`b` rising and falling linearly, `a` jumping from +2
    /// to −2) is rounded into a fall of `a` of at most `c Δs / 2` a grid
    /// point, stays below `b`, and is left as it is away from the peak.
    #[test]
    fn rounded_falls_bound_the_fall_of_the_path_acceleration() {
        let n = 100;
        let grid = PathGrid {
            s: (0..=n).map(|k| k as f64 / n as f64).collect(),
            piece: vec![0; n],
        };
        let b: Vec<f64> = grid.s.iter().map(|s| 4.0 * s.min(1.0 - s)).collect();
        let c = 40.0;
        let rounded = rounded_falls(&grid, &b, &vec![c; n + 1]);
        let step = 1.0 / n as f64;
        for k in 1..n {
            assert!(rounded[k] <= b[k] + 1e-12);
            let fall = (rounded[k + 1] - 2.0 * rounded[k] + rounded[k - 1]) / (2.0 * step);
            assert!(fall >= -0.5 * c * step - 1e-9, "a falls by {fall} at {k}");
        }
        assert!(rounded[n / 2] < b[n / 2] - 1e-3, "the peak is not rounded");
        for k in (0..=n).filter(|k| k.abs_diff(n / 2) > 10) {
            assert!((rounded[k] - b[k]).abs() < 1e-12, "changed at {k}");
        }
    }

    #[test]
    fn lower_hull_skips_points_above_the_chords() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0];
        let y = [0.0, 2.0, 1.0, 3.0, 0.0];
        assert_eq!(lower_hull(&x, &y), vec![0, 4]);
        let y = [3.0, 1.0, 0.5, 1.0, 3.0];
        assert_eq!(lower_hull(&x, &y), vec![0, 1, 2, 3, 4]);
    }
}
