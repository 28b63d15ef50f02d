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
//! [`MAX_TUBE`]; at each waypoint whose smoothed tool ends farther than the
//! budget from the planned tool path, every joint's tube is narrowed there
//! in proportion and the string pulled again. Narrowing only where the
//! budget is exceeded suffices: a string stays inside its tube at every
//! waypoint, so a waypoint's tubes alone bound how far its tool moves.
//! (Narrowing every tube by the worst waypoint's excess, as before, left
//! the examples' tubes at a median 0.39 of their width over whole pieces.)
//! The timing stage then checks every sample against the planned tool path
//! as before.

use super::deviation::{ToolFk, ToolPathCheck};

/// Widest tube, rad (m): bounds the tool's turn (orientation is not in the
/// tool-path check) to about half a degree.
pub const MAX_TUBE: f64 = 0.01;

/// Rounds of narrowing before the waypoints are kept as they are.
const ROUNDS: usize = 12;

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
    let tube: Vec<f64> = levers
        .iter()
        .map(|l| (budget / l.max(1e-6)).min(MAX_TUBE))
        .collect();
    // Each waypoint's share of the tubes, narrowed where the tool strays.
    let mut scale = vec![1.0; points.len()];
    for _ in 0..ROUNDS {
        let columns: Vec<Vec<f64>> = (0..dim)
            .map(|j| {
                let y: Vec<f64> = points.iter().map(|p| p[j]).collect();
                let last = y.len() - 1;
                let bound = |k: usize, sign: f64| match k {
                    0 => y[0],
                    k if k == last => y[last],
                    k => (y[k] + sign * scale[k] * tube[j]).clamp(lower[j], upper[j]),
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
        let mut within = true;
        for (k, q) in smoothed.iter().enumerate() {
            let segments = (k.saturating_sub(1).min(last_segment), k.min(last_segment));
            let off = planned.distance(fk(q), segments);
            if off > budget {
                scale[k] *= 0.8 * budget / off;
                within = false;
            }
        }
        if within {
            return Some(smoothed);
        }
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

    /// Two joints zig-zagging together near the start move the tool off
    /// its path by more than the budget when both are pulled straight:
    /// the tubes narrow there only, and far from it the other joint's
    /// ±1 mrad zig-zag (inside its 1.5 mrad tube) still comes out without
    /// a single reversal. Narrowing every tube by the worst waypoint's
    /// excess (to 0.9 mrad) left it zig-zagging all along the piece.
    #[test]
    fn taut_narrows_the_tubes_only_where_the_tool_strays() {
        // Tool: x = joint 2 (the path's progress), y = joint 0 + joint 1;
        // every joint moves the tool 1 m per rad, so each tube is 1.5 mrad.
        let fk = |q: &[f64]| [q[2], q[0] + q[1], 0.0];
        let zig = |k: usize| if k.is_multiple_of(2) { 1e-3 } else { -1e-3 };
        let rows: Vec<Vec<f64>> = (0..41)
            .map(|k| {
                let together = if (3..=8).contains(&k) { zig(k) } else { 0.0 };
                vec![zig(k), together, 0.01 * k as f64]
            })
            .collect();
        let points: Vec<&[f64]> = rows.iter().map(Vec::as_slice).collect();
        let knots: Vec<f64> = (0..41).map(|k| 0.01 * k as f64).collect();
        let budget = 1.5e-3;
        let planned = ToolPathCheck::new(&points, &fk, 0.005);
        let (lower, upper) = (vec![-1.0; 3], vec![1.0; 3]);
        let taut = pull_taut(&points, &knots, (&lower, &upper), &fk, &planned, budget)
            .expect("a string within the budget");
        for (k, q) in taut.iter().enumerate() {
            let segments = (k.saturating_sub(1).min(39), k.min(39));
            assert!(planned.distance(fk(q), segments) <= budget, "waypoint {k}");
        }
        let far: Vec<f64> = taut[12..].iter().map(|q| q[0]).collect();
        let turns = far
            .windows(3)
            .filter(|w| (w[1] - w[0]) * (w[2] - w[1]) < -1e-18)
            .count();
        assert_eq!(turns, 0, "{far:?}");
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
