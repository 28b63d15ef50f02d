//! Removing the wiggle from a dense IK joint path: each joint pulled taut
//! through a tube around its waypoint values.
//!
//! Path IK every centimetre of tool path leaves small back-and-forth steps
//! in the joints (a wrist turning 5–10 mrad one way and back while the
//! tool goes straight down), which a time-optimal timing follows faithfully:
//! joints reversing direction a dozen times in one pick and place. Here
//! each joint `j`, as a function of the path's chord length `x`, is
//! replaced by the **taut string** through the tube `[q_j(x_k) − ε_j,
//! q_j(x_k) + ε_j]` (the shortest graph inside it; the ends fixed): it
//! changes direction only where the tube forces it, so it has the fewest
//! direction changes of any path in the tube (Davies & Kovac, Ann. Stat.
//! 2001, for the same string on cumulative sums). Being within `ε_j` of
//! every waypoint and between the tube's bounds, it never leaves the range
//! the waypoints and `ε_j` span; the tube is clipped to the joint limits.
//!
//! `ε_j` is the tool budget over the joint's lever (how far the tool moves
//! per radian of that joint, measured by forward kinematics), at most
//! [`MAX_TUBE`]; where the smoothed waypoints' tools end farther than the
//! budget from the planned tool path, every tube is narrowed in proportion
//! and the string pulled again. The timing stage then checks every sample
//! against the planned tool path as before.

use super::deviation::{ToolFk, ToolPathCheck};

/// Widest tube, rad (m): bounds the tool's turn (orientation is not in the
/// tool-path check) to about half a degree.
pub const MAX_TUBE: f64 = 0.01;

/// Rounds of narrowing before the waypoints are kept as they are.
const ROUNDS: usize = 4;

/// The waypoints with every joint pulled taut, or `None` when the tubes
/// could not be made to keep the tool within `budget` metres of the
/// planned tool path (`planned`) at every waypoint. `points` has at least
/// two waypoints; `lower`/`upper` are the joint limits.
pub fn pull_taut(
    points: &[&[f64]],
    knots: &[f64],
    (lower, upper): (&[f64], &[f64]),
    fk: ToolFk,
    planned: &ToolPathCheck,
    budget: f64,
) -> Option<Vec<Vec<f64>>> {
    let dim = points[0].len();
    let levers = levers(points, fk);
    let mut scale = 1.0;
    for _ in 0..ROUNDS {
        let tube: Vec<f64> = levers
            .iter()
            .map(|l| (scale * budget / l.max(1e-6)).min(MAX_TUBE))
            .collect();
        let columns: Vec<Vec<f64>> = (0..dim)
            .map(|j| {
                let y: Vec<f64> = points.iter().map(|p| p[j]).collect();
                let last = y.len() - 1;
                let bound = |k: usize, sign: f64| match k {
                    0 => y[0],
                    k if k == last => y[last],
                    k => (y[k] + sign * tube[j]).clamp(lower[j], upper[j]),
                };
                let lo: Vec<f64> = (0..=last).map(|k| bound(k, -1.0)).collect();
                let hi: Vec<f64> = (0..=last).map(|k| bound(k, 1.0)).collect();
                taut_string(knots, &lo, &hi)
            })
            .collect();
        let smoothed: Vec<Vec<f64>> = (0..points.len())
            .map(|k| (0..dim).map(|j| columns[j][k]).collect())
            .collect();
        let last_segment = points.len() - 2;
        let worst = smoothed
            .iter()
            .enumerate()
            .map(|(k, q)| {
                let segments = (k.saturating_sub(1).min(last_segment), k.min(last_segment));
                planned.distance(fk(q), segments)
            })
            .fold(0.0, f64::max);
        if worst <= budget {
            return Some(smoothed);
        }
        scale *= 0.8 * budget / worst;
    }
    None
}

/// How far the tool moves per unit of each joint, metres per rad (m):
/// the largest of finite differences at the first, middle and last waypoint.
fn levers(points: &[&[f64]], fk: ToolFk) -> Vec<f64> {
    const STEP: f64 = 1e-4;
    let dim = points[0].len();
    let mut out = vec![0.0_f64; dim];
    for q in [
        points[0],
        points[points.len() / 2],
        points[points.len() - 1],
    ] {
        let at = fk(q);
        let mut moved = q.to_vec();
        for j in 0..dim {
            moved[j] = q[j] + STEP;
            let p = fk(&moved);
            moved[j] = q[j];
            let d = (0..3).map(|c| (p[c] - at[c]).powi(2)).sum::<f64>().sqrt() / STEP;
            out[j] = out[j].max(d);
        }
    }
    out
}

/// The shortest graph through the windows `[lo_k, hi_k]` at `x_k` (strictly
/// increasing; `lo_0 = hi_0` and the last window a point fix the ends),
/// evaluated at every `x_k`. Funnel algorithm: from the current anchor the
/// slopes that pass every window so far form an interval; when a window
/// lies wholly above (below) it, the string bends at the window that set
/// the interval's upper (lower) end, on that window's upper (lower) bound.
pub fn taut_string(x: &[f64], lo: &[f64], hi: &[f64]) -> Vec<f64> {
    let n = x.len();
    let mut out = vec![lo[0]; n];
    let (mut anchor, mut value) = (0, lo[0]);
    while anchor + 1 < n {
        let (mut slope_lo, mut slope_hi) = (f64::NEG_INFINITY, f64::INFINITY);
        let (mut at_lo, mut at_hi) = (anchor + 1, anchor + 1);
        let mut bend = None;
        for k in anchor + 1..n {
            let dx = x[k] - x[anchor];
            let (low, high) = ((lo[k] - value) / dx, (hi[k] - value) / dx);
            if low > slope_hi {
                bend = Some((at_hi, hi[at_hi]));
                break;
            }
            if high < slope_lo {
                bend = Some((at_lo, lo[at_lo]));
                break;
            }
            if high < slope_hi {
                (slope_hi, at_hi) = (high, k);
            }
            if low > slope_lo {
                (slope_lo, at_lo) = (low, k);
            }
        }
        let (to, end) = bend.unwrap_or((n - 1, lo[n - 1]));
        let slope = (end - value) / (x[to] - x[anchor]);
        for k in anchor + 1..to {
            out[k] = value + slope * (x[k] - x[anchor]);
        }
        out[to] = end;
        (anchor, value) = (to, end);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rising ramp with a ±4 mrad zig-zag: pulled taut in a 5 mrad tube
    /// it rises without a single reversal and stays in the tube.
    #[test]
    fn a_zigzag_inside_the_tube_becomes_monotone() {
        let x: Vec<f64> = (0..40).map(|k| k as f64 * 0.01).collect();
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(k, x)| 0.1 * x + if k % 2 == 0 { 0.004 } else { -0.004 })
            .collect();
        let last = y.len() - 1;
        let (mut lo, mut hi): (Vec<f64>, Vec<f64>) =
            y.iter().map(|v| (v - 0.005, v + 0.005)).unzip();
        // The ends on the ramp, as a piece's end waypoints are.
        let end = 0.1 * x[last];
        (lo[0], hi[0], lo[last], hi[last]) = (0.0, 0.0, end, end);
        let taut = taut_string(&x, &lo, &hi);
        assert!(taut.windows(2).all(|w| w[1] >= w[0]), "{taut:?}");
        for k in 0..=last {
            assert!(lo[k] - 1e-12 <= taut[k] && taut[k] <= hi[k] + 1e-12);
        }
        assert_eq!((taut[0], taut[last]), (0.0, end));
    }

    /// A real turn (up 0.1, then down) is kept: one reversal, at the top.
    #[test]
    fn a_turn_wider_than_the_tube_is_kept() {
        let x: Vec<f64> = (0..21).map(|k| k as f64).collect();
        let y: Vec<f64> = x.iter().map(|x| 0.1 - 0.01 * (x - 10.0).abs()).collect();
        let (mut lo, mut hi): (Vec<f64>, Vec<f64>) =
            y.iter().map(|v| (v - 0.005, v + 0.005)).unzip();
        (lo[0], hi[0], lo[20], hi[20]) = (y[0], y[0], y[20], y[20]);
        let taut = taut_string(&x, &lo, &hi);
        let top = taut.iter().copied().fold(f64::MIN, f64::max);
        assert!((top - 0.095).abs() < 1e-12, "{taut:?}");
        let turns = taut
            .windows(3)
            .filter(|w| (w[1] - w[0]) * (w[2] - w[1]) < 0.0)
            .count();
        assert_eq!(turns, 1, "{taut:?}");
    }
}
