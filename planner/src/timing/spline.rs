//! The path through the joint waypoints: the joint-space polyline (the path
//! the collision stage checked, linear between waypoints) with each interior
//! corner replaced by a quadratic Bézier blend — a shape-preserving, C1
//! piecewise polynomial in the path parameter `s`.
//!
//! For waypoints `P_0 … P_{W−1}` the knots are the chord lengths
//! `S_0 = 0`, `S_{k+1} = S_k + h_k`, `h_k = ‖P_{k+1} − P_k‖₂` (rad for a joint
//! path), so `‖q'(s)‖ = 1` on the straight parts and `≤ 1` in a blend. The
//! corner at `P_k` with radius `r_k ≤ min(h_{k−1}, h_k)/2` becomes, on
//! `s ∈ [S_k − r_k, S_k + r_k]`, the quadratic Bézier with control points
//!
//! ```text
//! A = P_k − (r_k/h_{k−1}) (P_k − P_{k−1}),   P_k,   C = P_k + (r_k/h_k) (P_{k+1} − P_k)
//! ```
//!
//! which is tangent to both segments where it meets them (C1). Two
//! properties follow from Bézier curves lying in the convex hull of their
//! control points, all three on the polyline:
//! - **no overshoot**: every joint stays between the smallest and largest of
//!   its values at `P_{k−1}, P_k, P_{k+1}`, so a path whose waypoints respect
//!   the joint limits respects them everywhere (a natural cubic spline does
//!   not: it swings past a limit, or far off a long segment beside short ones);
//! - **bounded deviation**: the blend is farthest from the polyline at its
//!   middle, `‖(A − 2P_k + C)/4‖ ≤ r_k/2`; elsewhere the path *is* the polyline.
//!
//! `q''` is constant on a blend and zero on a straight part (it jumps at the
//! knots, as the acceleration of any C1 path may); the timing program bounds
//! each piece separately, so every sample stays within the limits.
//! The same construction on the same knots and radii maps any per-waypoint
//! quantity (the tool positions) onto the path.

/// A C1 piecewise polynomial of degree ≤ 3 in `s`, one polynomial per piece
/// and dimension: `q(s_p + u) = c0 + c1 u + c2 u² + c3 u³`, `u ∈ [0, s_{p+1} − s_p]`.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseCubic {
    dim: usize,
    /// Knots `s_p`, strictly increasing, `knots[0] = 0`.
    knots: Vec<f64>,
    /// `coeffs[piece * dim + j] = [c0, c1, c2, c3]` of dimension `j`.
    coeffs: Vec<[f64; 4]>,
    /// Waypoint segments `k` (from `P_k` to `P_{k+1}`) each piece follows:
    /// `(k, k)` on a straight part, `(k − 1, k)` on the blend at `P_k`.
    segments: Vec<(usize, usize)>,
}

impl PiecewiseCubic {
    /// The blended polyline through `points` at the chord knots `knots`
    /// (see [`chord_knots`]) with corner radii `radii` (one per point, the
    /// end ones ignored, each clamped to `[0, min(h_{k−1}, h_k)/2]`).
    /// Callers guarantee `points.len() == knots.len() == radii.len() ≥ 2`,
    /// strictly increasing knots and equal dimensions.
    pub fn blended(points: &[&[f64]], knots: &[f64], radii: &[f64]) -> Self {
        let dim = points[0].len();
        let last = points.len() - 1;
        let h: Vec<f64> = knots.windows(2).map(|w| w[1] - w[0]).collect();
        let radius = |k: usize| match k {
            0 => 0.0,
            k if k == last => 0.0,
            k => radii[k].clamp(0.0, 0.5 * h[k - 1].min(h[k])),
        };
        let mut path = Self {
            dim,
            knots: vec![0.0],
            coeffs: Vec::with_capacity(2 * last * dim),
            segments: Vec::with_capacity(2 * last),
        };
        for k in 0..last {
            let (p, next) = (points[k], points[k + 1]);
            // Straight part of segment k, between the blends at its ends.
            let (from, to) = (radius(k), h[k] - radius(k + 1));
            if to - from > 1e-9 * h[k] {
                let coeffs = (0..dim).map(|j| {
                    let slope = (next[j] - p[j]) / h[k];
                    [p[j] + from * slope, slope, 0.0, 0.0]
                });
                path.push(knots[k] + to, coeffs, (k, k));
            }
            let r = radius(k + 1);
            if k + 1 < last && r > 0.0 {
                let after = points[k + 2];
                let coeffs = (0..dim).map(|j| {
                    let a = next[j] - r / h[k] * (next[j] - p[j]);
                    let c = next[j] + r / h[k + 1] * (after[j] - next[j]);
                    [
                        a,
                        (next[j] - a) / r,
                        (a - 2.0 * next[j] + c) / (4.0 * r * r),
                        0.0,
                    ]
                });
                path.push(knots[k + 1] + r, coeffs, (k, k + 1));
            }
        }
        // The end is the last waypoint exactly, whatever rounding did.
        *path.knots.last_mut().expect("at least one piece") = knots[last];
        path
    }

    fn push(&mut self, end: f64, coeffs: impl Iterator<Item = [f64; 4]>, segments: (usize, usize)) {
        self.knots.push(end);
        self.coeffs.extend(coeffs);
        self.segments.push(segments);
    }

    /// Number of dimensions (joints, or 3 for a tool path).
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Knots `s_p`.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// Total length `S_{W−1}`.
    pub fn length(&self) -> f64 {
        *self.knots.last().expect("a path has knots")
    }

    /// Number of polynomial pieces.
    pub fn pieces(&self) -> usize {
        self.knots.len() - 1
    }

    /// Coefficients `[c0, c1, c2, c3]` of dimension `j` on `piece`.
    pub fn piece(&self, piece: usize, j: usize) -> [f64; 4] {
        self.coeffs[piece * self.dim + j]
    }

    /// The waypoint segments `(first, last)` that `piece` follows.
    pub fn segments_of(&self, piece: usize) -> (usize, usize) {
        self.segments[piece]
    }

    /// The piece holding `s` (clamped to the path) and the local offset `u`.
    pub fn locate(&self, s: f64) -> (usize, f64) {
        let s = s.clamp(0.0, self.length());
        let piece = self
            .knots
            .partition_point(|&k| k <= s)
            .clamp(1, self.pieces())
            - 1;
        (piece, s - self.knots[piece])
    }

    /// Position, first and second derivative in `s` of every dimension.
    pub fn eval(&self, s: f64, q: &mut [f64], dq: &mut [f64], ddq: &mut [f64]) {
        let (piece, u) = self.locate(s);
        for j in 0..self.dim {
            let [c0, c1, c2, c3] = self.piece(piece, j);
            q[j] = c0 + u * (c1 + u * (c2 + u * c3));
            dq[j] = c1 + u * (2.0 * c2 + 3.0 * u * c3);
            ddq[j] = 2.0 * c2 + 6.0 * c3 * u;
        }
    }
}

/// Chord-length knots of `points`: `s_0 = 0`, `s_{k+1} = s_k + ‖p_{k+1} − p_k‖`.
pub fn chord_knots(points: &[&[f64]]) -> Vec<f64> {
    let mut knots = Vec::with_capacity(points.len());
    let mut s = 0.0;
    knots.push(s);
    for w in points.windows(2) {
        s += distance(w[0], w[1]);
        knots.push(s);
    }
    knots
}

/// The widest corner radii, `min(h_{k−1}, h_k)/2` (0 at the ends): the
/// blends then meet at the middle of every segment.
pub fn widest_radii(knots: &[f64]) -> Vec<f64> {
    let last = knots.len() - 1;
    (0..=last)
        .map(|k| match k {
            0 => 0.0,
            k if k == last => 0.0,
            k => 0.5 * (knots[k] - knots[k - 1]).min(knots[k + 1] - knots[k]),
        })
        .collect()
}

/// The blend's largest distance from its corner `P_k`, per unit radius:
/// `‖A − 2P_k + C‖ / (4 r_k)` (0 at the ends).
pub fn apex_offset(points: &[&[f64]], knots: &[f64], k: usize) -> Vec<f64> {
    if k == 0 || k + 1 >= points.len() {
        return vec![0.0; points[0].len()];
    }
    let (h0, h1) = (knots[k] - knots[k - 1], knots[k + 1] - knots[k]);
    (0..points[0].len())
        .map(|j| {
            let back = (points[k][j] - points[k - 1][j]) / h0;
            let ahead = (points[k + 1][j] - points[k][j]) / h1;
            0.25 * (ahead - back)
        })
        .collect()
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (y - x) * (y - x))
        .sum::<f64>()
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn path(points: &[Vec<f64>]) -> (PiecewiseCubic, Vec<f64>) {
        let refs: Vec<&[f64]> = points.iter().map(|p| p.as_slice()).collect();
        let knots = chord_knots(&refs);
        let radii = widest_radii(&knots);
        (PiecewiseCubic::blended(&refs, &knots, &radii), knots)
    }

    #[test]
    fn ends_on_the_waypoints_and_is_c1() {
        let pts = vec![
            vec![0.0, 1.0],
            vec![1.0, 0.5],
            vec![1.5, 2.0],
            vec![3.0, 2.5],
        ];
        let (p, knots) = path(&pts);
        let (mut q, mut dq, mut ddq) = ([0.0; 2], [0.0; 2], [0.0; 2]);
        p.eval(0.0, &mut q, &mut dq, &mut ddq);
        assert_eq!(q, [0.0, 1.0]);
        p.eval(*knots.last().unwrap(), &mut q, &mut dq, &mut ddq);
        assert!((q[0] - 3.0).abs() < 1e-12 && (q[1] - 2.5).abs() < 1e-12);
        let (mut q2, mut dq2) = ([0.0; 2], [0.0; 2]);
        for &s in &p.knots()[1..p.pieces()] {
            p.eval(s - 1e-9, &mut q, &mut dq, &mut ddq);
            p.eval(s + 1e-9, &mut q2, &mut dq2, &mut ddq);
            for j in 0..2 {
                assert!((q[j] - q2[j]).abs() < 1e-8, "position jumps at {s}");
                assert!((dq[j] - dq2[j]).abs() < 1e-6, "tangent jumps at {s}");
            }
        }
    }

    /// A long segment beside short ones, the shape a natural cubic spline
    /// swings far off: the blended path stays inside the waypoints' range.
    #[test]
    fn never_leaves_the_range_of_its_waypoints() {
        let pts = vec![
            vec![0.0, 0.0],
            vec![0.01, 0.0],
            vec![0.02, 0.0],
            vec![0.02, 1.5],
            vec![0.03, 1.5],
            vec![0.04, 1.51],
        ];
        let (p, _) = path(&pts);
        let (mut q, mut dq, mut ddq) = ([0.0; 2], [0.0; 2], [0.0; 2]);
        for m in 0..=2000 {
            p.eval(p.length() * m as f64 / 2000.0, &mut q, &mut dq, &mut ddq);
            assert!((-1e-12..=0.04 + 1e-12).contains(&q[0]), "{q:?}");
            assert!((-1e-12..=1.51 + 1e-12).contains(&q[1]), "{q:?}");
        }
    }
}
