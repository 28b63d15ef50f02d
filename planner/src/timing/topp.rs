//! The time-optimal speed profile as one second-order cone program, solved
//! by Clarabel (`min ½xᵀPx + qᵀx  s.t.  Ax + s = h, s ∈ K`).
//!
//! Variables, with `b_0 = b_N = 0` substituted (start and end at rest):
//! `b_i = ṡ²(s_i)` and `c_i ≤ √b_i` for `i = 1…N−1`, and `d_i ≥ 1/(c_i + c_{i+1})`
//! for `i = 0…N−1` (`c_0 = c_N = 0`):
//!
//! ```text
//! minimise   Σ_i 2 Δs_i d_i                                   (= Σ_i Δt_i at the optimum)
//! subject to α_r b_i + β_r b_{i+1} ≤ 1       for every kept row r of segment i  (ℝ₊)
//!            ‖(2 c_i, b_i − 1)‖ ≤ b_i + 1     ⇔ c_i² ≤ b_i               (SOC₃)
//!            ‖(2, d_i − c_i − c_{i+1})‖ ≤ d_i + c_i + c_{i+1}
//!                                             ⇔ d_i (c_i + c_{i+1}) ≥ 1  (SOC₃)
//! ```
//!
//! With constant `s̈` on a segment, `Δt_i = 2Δs_i / (√b_i + √b_{i+1})` exactly,
//! so the objective is the exact traversal time (Verscheure et al. 2009; Lipp
//! & Boyd 2014). Size: `3N − 2` variables, `2N − 1` three-dimensional cones
//! and the pruned linear rows (see [`grid`](super::grid)); the acceleration
//! `a_i = (b_{i+1} − b_i)/(2Δs_i)` is eliminated, and every row and cone
//! couples only neighbouring grid points, so the KKT matrix is banded.
//!
//! An optional smoothing term `w Σ_i (a_{i+1} − a_i)²` enters `P`.

use std::collections::BTreeMap;

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use serde::Serialize;

use super::grid::PathGrid;

/// Linear rows `α b_i + β b_{i+1} ≤ 1`, grouped by segment.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SegmentRows {
    /// Rows of segment `i` are `rows[offsets[i]..offsets[i + 1]]`.
    pub offsets: Vec<usize>,
    pub rows: Vec<(f64, f64)>,
}

/// How Clarabel ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum SolverOutcome {
    /// Converged to the requested accuracy.
    Solved,
    /// Converged to Clarabel's reduced accuracy only.
    AlmostSolved,
    /// The constraints admit no motion (e.g. a zero speed cap inside the path).
    Infeasible,
    /// Iteration or time limit reached.
    LimitReached,
    /// Numerical trouble or no progress.
    NumericalError,
}

/// Solver knobs of the program.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProgramSettings {
    pub smoothing_weight: f64,
    pub max_iterations: u32,
    pub tolerance: f64,
}

/// The solved profile `b_i = ṡ²` at every grid point.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileSolution {
    pub b: Vec<f64>,
    pub outcome: SolverOutcome,
    pub iterations: u32,
    /// Clarabel's own solve time, seconds.
    pub solve_time_s: f64,
}

/// Builds and solves the program.
pub fn solve_profile(
    grid: &PathGrid,
    rows: &SegmentRows,
    settings: &ProgramSettings,
) -> ProfileSolution {
    let n = grid.segments();
    let inner = n - 1;
    let b_col = |i: usize| (i >= 1 && i < n).then(|| i - 1);
    let c_col = |i: usize| (i >= 1 && i < n).then(|| inner + i - 1);
    let d_col = |i: usize| 2 * inner + i;
    let vars = 2 * inner + n;

    let lin = rows.rows.len();
    let m = lin + 3 * inner + 3 * n;
    let mut ti = Vec::with_capacity(2 * lin + 3 * inner + 5 * n);
    let mut tj = Vec::with_capacity(ti.capacity());
    let mut tv = Vec::with_capacity(ti.capacity());
    let mut h = vec![0.0; m];
    let mut push = |r: usize, c: usize, v: f64| {
        ti.push(r);
        tj.push(c);
        tv.push(v);
    };

    // ℝ₊: α b_i + β b_{i+1} + s = 1.
    for i in 0..n {
        for r in rows.offsets[i]..rows.offsets[i + 1] {
            let (alpha, beta) = rows.rows[r];
            if let Some(col) = b_col(i) {
                push(r, col, alpha);
            }
            if let Some(col) = b_col(i + 1) {
                push(r, col, beta);
            }
            h[r] = 1.0;
        }
    }
    // SOC₃: s = (1 + b_i, b_i − 1, 2 c_i).
    let mut row = lin;
    for i in 1..n {
        let (bc, cc) = (b_col(i).unwrap_or(0), c_col(i).unwrap_or(0));
        push(row, bc, -1.0);
        h[row] = 1.0;
        push(row + 1, bc, -1.0);
        h[row + 1] = -1.0;
        push(row + 2, cc, -2.0);
        row += 3;
    }
    // SOC₃: s = (d_i + c_i + c_{i+1}, d_i − c_i − c_{i+1}, 2).
    for i in 0..n {
        push(row, d_col(i), -1.0);
        push(row + 1, d_col(i), -1.0);
        for c in [c_col(i), c_col(i + 1)].into_iter().flatten() {
            push(row, c, -1.0);
            push(row + 1, c, 1.0);
        }
        h[row + 2] = 2.0;
        row += 3;
    }
    let a = CscMatrix::new_from_triplets(m, vars, ti, tj, tv);

    let mut q = vec![0.0; vars];
    for i in 0..n {
        q[d_col(i)] = 2.0 * grid.step(i);
    }
    let p = smoothing_matrix(grid, settings.smoothing_weight, vars);

    let mut cones = Vec::with_capacity(1 + inner + n);
    if lin > 0 {
        cones.push(SupportedConeT::NonnegativeConeT(lin));
    }
    cones.extend(std::iter::repeat_n(
        SupportedConeT::SecondOrderConeT(3),
        inner + n,
    ));

    let clarabel_settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(settings.max_iterations)
        .tol_gap_abs(settings.tolerance)
        .tol_gap_rel(settings.tolerance)
        .build()
        .expect("every Clarabel setting used here has a valid value");
    let mut solver = match DefaultSolver::new(&p, &q, &a, &h, &cones, clarabel_settings) {
        Ok(solver) => solver,
        // Dimensions are consistent by construction; report rather than panic.
        Err(_) => {
            return ProfileSolution {
                b: vec![0.0; n + 1],
                outcome: SolverOutcome::NumericalError,
                iterations: 0,
                solve_time_s: 0.0,
            };
        }
    };
    solver.solve();
    let solution = &solver.solution;
    let outcome = match solution.status {
        SolverStatus::Solved => SolverOutcome::Solved,
        SolverStatus::AlmostSolved => SolverOutcome::AlmostSolved,
        SolverStatus::PrimalInfeasible
        | SolverStatus::DualInfeasible
        | SolverStatus::AlmostPrimalInfeasible
        | SolverStatus::AlmostDualInfeasible => SolverOutcome::Infeasible,
        SolverStatus::MaxIterations | SolverStatus::MaxTime => SolverOutcome::LimitReached,
        _ => SolverOutcome::NumericalError,
    };
    let mut b = vec![0.0; n + 1];
    for (i, b_i) in b.iter_mut().enumerate().take(n).skip(1) {
        *b_i = solution.x[i - 1].max(0.0);
    }
    ProfileSolution {
        b,
        outcome,
        iterations: solution.iterations,
        solve_time_s: solution.solve_time,
    }
}

/// `P = 2w GᵀG` (upper triangle) with `(Gb)_i = a_{i+1} − a_i`.
fn smoothing_matrix(grid: &PathGrid, weight: f64, vars: usize) -> CscMatrix<f64> {
    let n = grid.segments();
    if weight <= 0.0 || n < 2 {
        return CscMatrix::zeros((vars, vars));
    }
    let mut upper: BTreeMap<(usize, usize), f64> = BTreeMap::new();
    for i in 0..n - 1 {
        let (g0, g2) = (0.5 / grid.step(i), 0.5 / grid.step(i + 1));
        let terms = [(i, g0), (i + 1, -(g0 + g2)), (i + 2, g2)];
        let cols: Vec<(usize, f64)> = terms
            .iter()
            .filter(|(k, _)| *k >= 1 && *k < n)
            .map(|&(k, g)| (k - 1, g))
            .collect();
        for &(r, gr) in &cols {
            for &(c, gc) in &cols {
                if r <= c {
                    *upper.entry((c, r)).or_insert(0.0) += 2.0 * weight * gr * gc;
                }
            }
        }
    }
    let (mut ti, mut tj, mut tv) = (Vec::new(), Vec::new(), Vec::new());
    for ((c, r), v) in upper {
        ti.push(r);
        tj.push(c);
        tv.push(v);
    }
    CscMatrix::new_from_triplets(vars, vars, ti, tj, tv)
}
