//! The discretised path and its constraint rows.
//!
//! The path parameter is cut into `N` segments `[s_i, s_{i+1}]`, every spline
//! knot being a grid point, so each segment lies inside one cubic piece. On a
//! segment `s̈ = a_i` is constant, hence `b(s) = ṡ²` is linear in `s`:
//! `b(θ) = (1−θ) b_i + θ b_{i+1}`, `θ = (s − s_i)/Δs_i`, `a_i = (b_{i+1} − b_i)/(2Δs_i)`.
//!
//! Joint `j` then has, for every `θ ∈ [0, 1]`,
//!
//! ```text
//! velocity²    q'_j(θ)² b(θ)                                  ≤ v_j²
//! acceleration q''_j(θ) b(θ) + q'_j(θ) a_i
//!            = b_i [q''_j(1−θ) − q'_j/(2Δs_i)] + b_{i+1} [q''_j θ + q'_j/(2Δs_i)] ∈ [−A_j, A_j]
//! ```
//!
//! Both are polynomials in `θ` (degree 5 and 2) whose coefficients are linear
//! in `(b_i, b_{i+1})`. A polynomial lies between the extremes of its
//! Bernstein coefficients, so bounding Bernstein coefficients bounds the
//! whole segment, not just its end points. Every row is then made
//! *lattice-compatible*: a bound on one variable, or `α b_i + β b_{i+1} ≤ 1`
//! with `α β ≤ 0` (see [`push_speed_rows`] for the velocity and tool-speed
//! rows, [`push_lattice_row`] for acceleration rows with both coefficients
//! positive, which occur where a joint turns round, `q' ≈ 0`). Such rows are
//! closed under the componentwise maximum of two solutions, so the feasible
//! set has a **greatest element** `b*`, and `b*` minimises every function
//! decreasing in each `b_i`, the traversal time included (see the `topp` module).
//!
//! In the `(b_i, b_{i+1})` plane only the rows on the upper-right convex
//! frontier of `{0} ∪ {(α, β)}` can be active (`b ≥ 0`); the others are
//! dropped, leaving typically 2–4 rows per segment.

use super::spline::PiecewiseCubic;

/// Linear rows `α b_i + β b_{i+1} ≤ 1`, grouped by segment.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SegmentRows {
    /// Rows of segment `i` are `rows[offsets[i]..offsets[i + 1]]`.
    pub offsets: Vec<usize>,
    pub rows: Vec<(f64, f64)>,
}

/// The discretised path: grid points and the spline piece of each segment.
#[derive(Debug, Clone, PartialEq)]
pub struct PathGrid {
    /// Grid points `s_0 = 0 < s_1 < … < s_N = L`.
    pub s: Vec<f64>,
    /// Spline piece holding segment `i`.
    pub piece: Vec<usize>,
}

impl PathGrid {
    /// About `segments` segments, spread over the pieces by length, at least
    /// one per piece, uniform inside a piece.
    pub fn new(spline: &PiecewiseCubic, segments: usize) -> Self {
        let knots = spline.knots();
        let length = spline.length();
        let pieces = spline.pieces();
        let share: Vec<f64> = knots
            .windows(2)
            .map(|w| segments as f64 * (w[1] - w[0]) / length)
            .collect();
        let mut count: Vec<usize> = share.iter().map(|x| (x.floor() as usize).max(1)).collect();
        let used: usize = count.iter().sum();
        if used < segments {
            let mut order: Vec<usize> = (0..pieces).collect();
            order.sort_by(|&a, &b| {
                let (fa, fb) = (share[a] - share[a].floor(), share[b] - share[b].floor());
                fb.total_cmp(&fa).then(a.cmp(&b))
            });
            for k in order.into_iter().cycle().take(segments - used) {
                count[k] += 1;
            }
        }
        let total: usize = count.iter().sum();
        let mut s = Vec::with_capacity(total + 1);
        let mut piece = Vec::with_capacity(total);
        for (k, &n) in count.iter().enumerate() {
            let (s0, s1) = (knots[k], knots[k + 1]);
            for m in 0..n {
                s.push(s0 + (s1 - s0) * m as f64 / n as f64);
                piece.push(k);
            }
        }
        s.push(length);
        Self { s, piece }
    }

    /// The grid with segment `i` cut into `parts(i) ≥ 1` equal segments
    /// (every old grid point stays one, so every spline knot too).
    pub fn split(&self, parts: impl Fn(usize) -> usize) -> Self {
        let mut s = Vec::with_capacity(self.s.len());
        let mut piece = Vec::with_capacity(self.piece.len());
        for i in 0..self.segments() {
            let n = parts(i).max(1);
            for m in 0..n {
                s.push(self.s[i] + self.step(i) * m as f64 / n as f64);
                piece.push(self.piece[i]);
            }
        }
        s.push(*self.s.last().expect("a grid has points"));
        Self { s, piece }
    }

    /// Number of segments `N`.
    pub fn segments(&self) -> usize {
        self.piece.len()
    }

    /// `Δs_i`.
    pub fn step(&self, i: usize) -> f64 {
        self.s[i + 1] - self.s[i]
    }
}

/// Monomial coefficients in `θ` of `q'_j` (degree 2) and `q''_j` (degree 1)
/// on segment `i`.
pub fn derivatives_on_segment(
    spline: &PiecewiseCubic,
    grid: &PathGrid,
    i: usize,
    j: usize,
) -> ([f64; 3], [f64; 2]) {
    let piece = grid.piece[i];
    let u0 = grid.s[i] - spline.knots()[piece];
    let ds = grid.step(i);
    let [_, c1, c2, c3] = spline.piece(piece, j);
    let n0 = 2.0 * c2 + 6.0 * c3 * u0;
    (
        [
            c1 + 2.0 * c2 * u0 + 3.0 * c3 * u0 * u0,
            n0 * ds,
            3.0 * c3 * ds * ds,
        ],
        [n0, 6.0 * c3 * ds],
    )
}

/// Bernstein coefficients of a polynomial given by monomial coefficients
/// (`m.len() − 1` is the degree): `β_k = Σ_{i≤k} C(k,i)/C(n,i) m_i`.
fn bernstein<const N: usize>(m: &[f64; N]) -> [f64; N] {
    let n = N - 1;
    let mut out = [0.0; N];
    for (k, out_k) in out.iter_mut().enumerate() {
        let mut acc = 0.0;
        for (i, m_i) in m.iter().enumerate().take(k + 1) {
            acc += binomial(k, i) / binomial(n, i) * m_i;
        }
        *out_k = acc;
    }
    out
}

fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// Rows `α b_i + β b_{i+1} ≤ 1` of segment `i`, appended to `rows`, every
/// one a single-variable bound (`α = 0` or `β = 0`) or opposite-signed.
/// `vel_sq[j] = v_j²`, `acc[j] = A_j` (already scaled and margined);
/// `tool` is the tool spline (same knots) and the squared cap on this segment.
pub fn segment_rows(
    spline: &PiecewiseCubic,
    grid: &PathGrid,
    i: usize,
    vel_sq: &[f64],
    acc: &[f64],
    tool: Option<(&PiecewiseCubic, f64)>,
    rows: &mut Vec<(f64, f64)>,
) {
    for j in 0..spline.dim() {
        let (bu, bw) = acceleration_bernstein(spline, grid, i, j);
        for k in 0..3 {
            let (alpha, beta) = (bu[k] / acc[j], bw[k] / acc[j]);
            push_lattice_row(alpha, beta, rows);
            push_lattice_row(-alpha, -beta, rows);
        }
        let (d1, _) = derivatives_on_segment(spline, grid, i, j);
        let mut g = square(&d1);
        g.iter_mut().for_each(|c| *c /= vel_sq[j]);
        push_speed_rows(&g, rows);
    }
    if let Some((tool, cap_sq)) = tool {
        let mut g = [0.0; 5];
        for d in 0..tool.dim() {
            let (d1, _) = derivatives_on_segment(tool, grid, i, d);
            for (acc, v) in g.iter_mut().zip(square(&d1)) {
                *acc += v / cap_sq;
            }
        }
        push_speed_rows(&g, rows);
    }
}

/// The pruned rows of every segment of `grid` (with `b_0 = b_N = 0`
/// substituted): [`segment_rows`] with the squared tool-speed cap
/// `tool_caps_sq[i]` of each segment when given, then [`prune_rows`].
pub fn program_rows(
    spline: &PiecewiseCubic,
    grid: &PathGrid,
    vel_sq: &[f64],
    acc: &[f64],
    tool: Option<(&PiecewiseCubic, &[f64])>,
) -> SegmentRows {
    let n = grid.segments();
    let mut rows = SegmentRows {
        offsets: Vec::with_capacity(n + 1),
        rows: Vec::with_capacity(4 * n),
    };
    let (mut seg_rows, mut scratch) = (Vec::new(), Vec::new());
    rows.offsets.push(0);
    for i in 0..n {
        seg_rows.clear();
        let tool_i = tool.map(|(spline, caps_sq)| (spline, caps_sq[i]));
        segment_rows(spline, grid, i, vel_sq, acc, tool_i, &mut seg_rows);
        // b_0 = b_N = 0: their coefficients vanish.
        if i == 0 {
            seg_rows.iter_mut().for_each(|r| r.0 = 0.0);
        }
        if i == n - 1 {
            seg_rows.iter_mut().for_each(|r| r.1 = 0.0);
        }
        prune_rows(&mut seg_rows, &mut scratch);
        rows.rows.extend_from_slice(&seg_rows);
        rows.offsets.push(rows.rows.len());
    }
    rows
}

/// Bernstein coefficients (in `θ`) of the acceleration of joint `j` on
/// segment `i` that multiply `b_i` and `b_{i+1}`:
/// `q̈_j(θ) = u(θ) b_i + w(θ) b_{i+1}`.
fn acceleration_bernstein(
    spline: &PiecewiseCubic,
    grid: &PathGrid,
    i: usize,
    j: usize,
) -> ([f64; 3], [f64; 3]) {
    let (d1, d2) = derivatives_on_segment(spline, grid, i, j);
    let half = 0.5 / grid.step(i);
    let u = [
        d2[0] - half * d1[0],
        d2[1] - d2[0] - half * d1[1],
        -d2[1] - half * d1[2],
    ];
    let w = [half * d1[0], d2[0] + half * d1[1], d2[1] + half * d1[2]];
    (bernstein(&u), bernstein(&w))
}

/// True when an acceleration row of segment `i` (as [`segment_rows`] writes
/// it) is within `slack` of its bound at `(b_i, b_{i+1})`: the segment is
/// acceleration-bound, where cutting it gains time (its bounds are
/// conservative to first order in `Δs`, the speed rows to second order).
pub fn acceleration_bound(
    spline: &PiecewiseCubic,
    grid: &PathGrid,
    i: usize,
    acc: &[f64],
    (b0, b1): (f64, f64),
    slack: f64,
) -> bool {
    (0..spline.dim()).any(|j| {
        let (bu, bw) = acceleration_bernstein(spline, grid, i, j);
        (0..3).any(|k| {
            [1.0, -1.0].into_iter().any(|sign| {
                let (alpha, beta) = (sign * bu[k] / acc[j], sign * bw[k] / acc[j]);
                let value = if alpha > 0.0 && beta > 0.0 {
                    (alpha + beta) * b0.max(b1)
                } else {
                    alpha * b0 + beta * b1
                };
                value >= 1.0 - slack
            })
        })
    })
}

/// Points `θ = k/(UTILISATION_POINTS − 1)` at which [`joint_utilisation`]
/// measures a segment.
pub const UTILISATION_POINTS: usize = 9;

/// The share of the joint limits used along segment `i` by the profile
/// `(b_i, b_{i+1})`: at each of [`UTILISATION_POINTS`] points `θ`, the
/// largest over the joints of `|q̈_j(θ)|/A_j` and `q̇_j(θ)²/v_j²`. Where the
/// smallest of these is below 1 by `ε`, the limits would let `b` rise by
/// about `ε` there but the segment's linear `b` cannot: cutting it gains time.
pub fn joint_utilisation(
    spline: &PiecewiseCubic,
    grid: &PathGrid,
    i: usize,
    vel_sq: &[f64],
    acc: &[f64],
    (b0, b1): (f64, f64),
) -> [f64; UTILISATION_POINTS] {
    let a = (b1 - b0) / (2.0 * grid.step(i));
    let mut used = [0.0_f64; UTILISATION_POINTS];
    for j in 0..spline.dim() {
        let (d1, d2) = derivatives_on_segment(spline, grid, i, j);
        for (k, used) in used.iter_mut().enumerate() {
            let t = k as f64 / (UTILISATION_POINTS - 1) as f64;
            let speed = d1[0] + t * (d1[1] + t * d1[2]);
            let b = b0 + t * (b1 - b0);
            let acceleration = (d2[0] + d2[1] * t) * b + speed * a;
            *used = used
                .max(acceleration.abs() / acc[j])
                .max(speed * speed * b / vel_sq[j]);
        }
    }
    used
}

/// True when the speed rows of some joint on segment `i` are loose: its
/// squared speed varies more than 2× over the segment (a joint turning
/// round), so [`push_speed_rows`] floors the end values and its bound can be
/// up to 2× below the true one until the segment is cut.
pub fn speed_rows_loose(spline: &PiecewiseCubic, grid: &PathGrid, i: usize) -> bool {
    (0..spline.dim()).any(|j| {
        let (d1, _) = derivatives_on_segment(spline, grid, i, j);
        varies_twofold(&square(&d1))
    })
}

/// True when the tool-speed rows of segment `i` are loose: the tool
/// path's squared speed `‖p'‖²` varies more than 2× over the segment (see
/// [`speed_rows_loose`]).
pub fn tool_speed_rows_loose(tool: &PiecewiseCubic, grid: &PathGrid, i: usize) -> bool {
    let mut g = [0.0; 5];
    for d in 0..tool.dim() {
        let (d1, _) = derivatives_on_segment(tool, grid, i, d);
        for (acc, v) in g.iter_mut().zip(square(&d1)) {
            *acc += v;
        }
    }
    varies_twofold(&g)
}

/// The end values of the quartic `g ≥ 0` below half its largest Bernstein
/// coefficient: [`push_speed_rows`] floors them.
fn varies_twofold(g: &[f64; 5]) -> bool {
    let peak = bernstein(g).into_iter().fold(0.0_f64, f64::max);
    let (g0, g1) = (g[0], g.iter().sum::<f64>());
    peak > 0.0 && g0.min(g1) < 0.5 * peak
}

/// A row with both coefficients positive, `α b_i + β b_{i+1} ≤ 1`, is
/// replaced by the two bounds `b_i, b_{i+1} ≤ 1/(α + β)`, which imply it and
/// coincide with it where `b_i = b_{i+1}`; other rows are kept as they are.
fn push_lattice_row(alpha: f64, beta: f64, rows: &mut Vec<(f64, f64)>) {
    if alpha > 0.0 && beta > 0.0 {
        rows.push((alpha + beta, 0.0));
        rows.push((0.0, alpha + beta));
    } else {
        rows.push((alpha, beta));
    }
}

fn square(p: &[f64; 3]) -> [f64; 5] {
    [
        p[0] * p[0],
        2.0 * p[0] * p[1],
        p[1] * p[1] + 2.0 * p[0] * p[2],
        2.0 * p[1] * p[2],
        p[2] * p[2],
    ]
}

/// Bounds that imply `g(θ) b(θ) ≤ 1` on the whole segment for a quartic
/// `g ≥ 0` (a squared speed over its squared limit). With `G_0, G_1` the
/// end values of `g`, floored at half its largest Bernstein coefficient (a
/// joint at rest at one end must not squeeze the other end's bound), and
/// `M` the largest Bernstein coefficient of
/// `g(θ) [(1−θ)/G_0 + θ/G_1]`, the rows are `b_i ≤ 1/(M G_0)`,
/// `b_{i+1} ≤ 1/(M G_1)`: then `g b(θ) ≤ g [(1−θ)/G_0 + θ/G_1]/M ≤ 1`.
/// Where `g` varies by less than 2× over the segment (every joint that can
/// bind) `M − 1 = O(Δs²)`, so the bounds are the end-point limits up to that.
fn push_speed_rows(g: &[f64; 5], rows: &mut Vec<(f64, f64)>) {
    let peak = bernstein(g).into_iter().fold(0.0_f64, f64::max);
    if peak <= 0.0 {
        return;
    }
    let floor = 0.5 * peak;
    let g0 = g[0].max(floor);
    let g1 = g.iter().sum::<f64>().max(floor);
    // g(θ) (1/G_0 + θ (1/G_1 − 1/G_0)) as a quintic.
    let (c0, c1) = (1.0 / g0, 1.0 / g1 - 1.0 / g0);
    let mut f = [0.0; 6];
    for k in 0..5 {
        f[k] += g[k] * c0;
        f[k + 1] += g[k] * c1;
    }
    let m = bernstein(&f).into_iter().fold(0.0_f64, f64::max);
    rows.push((m * g0, 0.0));
    rows.push((0.0, m * g1));
}

/// Keeps only the rows that can be active for `b ≥ 0`: the vertices of the
/// upper-right frontier of `conv({0} ∪ rows)`. Order: decreasing `β`.
pub fn prune_rows(rows: &mut Vec<(f64, f64)>, scratch: &mut Vec<(f64, f64)>) {
    rows.retain(|&(a, b)| a > 0.0 || b > 0.0);
    if rows.len() <= 1 {
        return;
    }
    rows.push((0.0, 0.0));
    rows.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)));
    // Upper hull, left to right (Andrew's monotone chain).
    scratch.clear();
    for &p in rows.iter() {
        while scratch.len() >= 2 {
            let (o, a) = (scratch[scratch.len() - 2], scratch[scratch.len() - 1]);
            let cross = (a.0 - o.0) * (p.1 - o.1) - (a.1 - o.1) * (p.0 - o.0);
            if cross >= 0.0 {
                scratch.pop();
            } else {
                break;
            }
        }
        scratch.push(p);
    }
    // From the highest vertex (rightmost on ties) to the end.
    let mut top = 0;
    for (k, p) in scratch.iter().enumerate() {
        if p.1 >= scratch[top].1 {
            top = k;
        }
    }
    rows.clear();
    rows.extend(
        scratch[top..]
            .iter()
            .filter(|p| p.0 > 0.0 || p.1 > 0.0)
            .copied(),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bernstein_of_quadratic() {
        // 1 + 2θ + 3θ² → B = [1, 2, 6].
        assert_eq!(bernstein(&[1.0, 2.0, 3.0]), [1.0, 2.0, 6.0]);
    }

    #[test]
    fn pruning_keeps_the_binding_rows() {
        let mut rows = vec![
            (1.0, 0.0),
            (0.6, 0.6),
            (0.2, 0.2),
            (0.0, 1.0),
            (-1.0, -1.0),
            (0.9, 0.05),
        ];
        let mut scratch = Vec::new();
        prune_rows(&mut rows, &mut scratch);
        assert_eq!(rows, vec![(0.0, 1.0), (0.6, 0.6), (1.0, 0.0)]);
    }
}
