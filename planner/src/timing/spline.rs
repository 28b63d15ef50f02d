//! C2 path through waypoints: a natural cubic spline in the path parameter
//! `s` with chord-length knots, one polynomial per piece and dimension.
//!
//! For waypoints `q_0 … q_{W-1}` (any dimension) the knots are
//! `s_0 = 0`, `s_{k+1} = s_k + ‖q_{k+1} − q_k‖₂`, so `s` has the units of the
//! waypoints (rad for a joint path, m for a tool path) and `‖q'(s)‖ ≈ 1`.
//! Piece `k` is `q(s_k + u) = c0 + c1 u + c2 u² + c3 u³`, `u ∈ [0, h_k]`,
//! with `q'' = 0` at both ends (natural spline).

/// A natural cubic spline through waypoints, C2 in `s`.
#[derive(Debug, Clone, PartialEq)]
pub struct CubicSpline {
    dim: usize,
    /// Knots `s_k`, strictly increasing, `knots[0] = 0`.
    knots: Vec<f64>,
    /// `coeffs[piece * dim + j] = [c0, c1, c2, c3]` of dimension `j`.
    coeffs: Vec<[f64; 4]>,
}

impl CubicSpline {
    /// Spline through `points` at the given strictly increasing `knots`.
    /// Callers guarantee `points.len() == knots.len() ≥ 2`, equal dimensions.
    pub fn with_knots(points: &[&[f64]], knots: &[f64]) -> Self {
        let count = points.len();
        let dim = points[0].len();
        let pieces = count - 1;
        let h: Vec<f64> = knots.windows(2).map(|w| w[1] - w[0]).collect();
        let mut coeffs = vec![[0.0; 4]; pieces * dim];
        // Second derivatives M_k by the tridiagonal (Thomas) solve; M_0 = M_{W-1} = 0.
        let mut second = vec![0.0; count];
        let mut diag = vec![0.0; count];
        let mut rhs = vec![0.0; count];
        for j in 0..dim {
            second.iter_mut().for_each(|m| *m = 0.0);
            if count > 2 {
                for k in 1..count - 1 {
                    diag[k] = 2.0 * (h[k - 1] + h[k]);
                    rhs[k] = 6.0
                        * ((points[k + 1][j] - points[k][j]) / h[k]
                            - (points[k][j] - points[k - 1][j]) / h[k - 1]);
                }
                for k in 2..count - 1 {
                    let factor = h[k - 1] / diag[k - 1];
                    diag[k] -= factor * h[k - 1];
                    rhs[k] -= factor * rhs[k - 1];
                }
                for k in (1..count - 1).rev() {
                    let upper = if k + 1 < count - 1 {
                        h[k] * second[k + 1]
                    } else {
                        0.0
                    };
                    second[k] = (rhs[k] - upper) / diag[k];
                }
            }
            for k in 0..pieces {
                let (y0, y1, m0, m1) = (points[k][j], points[k + 1][j], second[k], second[k + 1]);
                coeffs[k * dim + j] = [
                    y0,
                    (y1 - y0) / h[k] - h[k] * (2.0 * m0 + m1) / 6.0,
                    m0 / 2.0,
                    (m1 - m0) / (6.0 * h[k]),
                ];
            }
        }
        Self {
            dim,
            knots: knots.to_vec(),
            coeffs,
        }
    }

    /// Number of dimensions (joints, or 3 for a tool path).
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Knots `s_k`.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// Total length `s_{W-1}`.
    pub fn length(&self) -> f64 {
        *self.knots.last().expect("a spline has knots")
    }

    /// Number of cubic pieces.
    pub fn pieces(&self) -> usize {
        self.knots.len() - 1
    }

    /// Coefficients `[c0, c1, c2, c3]` of dimension `j` on `piece`.
    pub fn piece(&self, piece: usize, j: usize) -> [f64; 4] {
        self.coeffs[piece * self.dim + j]
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
        s += w[0]
            .iter()
            .zip(w[1])
            .map(|(a, b)| (b - a) * (b - a))
            .sum::<f64>()
            .sqrt();
        knots.push(s);
    }
    knots
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_and_is_c2() {
        let pts: Vec<Vec<f64>> = vec![
            vec![0.0, 1.0],
            vec![1.0, 0.5],
            vec![1.5, 2.0],
            vec![3.0, 2.5],
        ];
        let refs: Vec<&[f64]> = pts.iter().map(|p| p.as_slice()).collect();
        let knots = chord_knots(&refs);
        let spline = CubicSpline::with_knots(&refs, &knots);
        let (mut q, mut dq, mut ddq) = ([0.0; 2], [0.0; 2], [0.0; 2]);
        for (k, p) in pts.iter().enumerate() {
            spline.eval(knots[k], &mut q, &mut dq, &mut ddq);
            assert!((q[0] - p[0]).abs() < 1e-12 && (q[1] - p[1]).abs() < 1e-12);
        }
        // Continuity of q' and q'' across an interior knot.
        let (mut q2, mut dq2, mut ddq2) = ([0.0; 2], [0.0; 2], [0.0; 2]);
        spline.eval(knots[1] - 1e-9, &mut q, &mut dq, &mut ddq);
        spline.eval(knots[1] + 1e-9, &mut q2, &mut dq2, &mut ddq2);
        for j in 0..2 {
            assert!((dq[j] - dq2[j]).abs() < 1e-6);
            assert!((ddq[j] - ddq2[j]).abs() < 1e-6);
        }
        spline.eval(0.0, &mut q, &mut dq, &mut ddq);
        assert!(ddq.iter().all(|v| v.abs() < 1e-12));
    }
}
