//! The time-optimal speed profile as one convex program: the LP below solved
//! exactly by two passes over the segments ((`greatest_profile`)), the SOCP
//! by Clarabel (`min ½xᵀPx + qᵀx  s.t.  Ax + s = h, s ∈ K`).
//!
//! Both forms below have the variables `b_i = ṡ²(s_i)`, `i = 1…N−1`, with
//! `b_0 = b_N = 0` substituted (start and end at rest), and the pruned
//! linear rows `α_r b_i + β_r b_{i+1} ≤ 1` of [`grid`](super::grid) (ℝ₊ cone).
//!
//! **[`Program::GreatestProfile`] (default, an LP).** The rows are
//! lattice-compatible, so the feasible set `F` has a greatest element `b*`
//! (`b ≤ b*` for every `b ∈ F`). The exact discretised time
//! `T(b) = Σ_i 2Δs_i/(√b_i + √b_{i+1})` decreases in every `b_i`, hence
//! `T(b*) ≤ T(b)` on `F`: `b*` is time-optimal. It is also the unique
//! maximiser of any positive weighting, so the program is
//!
//! ```text
//! minimise    −Σ_i w_i b_i,   w_i = (Δs_{i−1} + Δs_i) / 2
//! subject to  α_r b_i + β_r b_{i+1} ≤ 1
//! ```
//!
//! `N − 1` variables and a few rows per segment, each coupling neighbours.
//! Each row bounds one neighbour by a nondecreasing function of the other,
//! so `b*` is found by TOPP-RA's reachability analysis (Pham & Pham, IEEE
//! T-RO 2018): a backward pass for the largest `b_i` from which the end is
//! reachable, a forward pass taking the largest reachable `b_{i+1}` — exact,
//! `O(rows)`, where Clarabel's interior point stops within its tolerance
//! below `b*` and took half the stage's time. A row set
//! off the lattice (none is built) would still go to Clarabel.
//!
//! **[`Program::ExactTime`] (an SOCP).** The time objective itself, after
//! Verscheure et al. (2009) and Lipp & Boyd (2014), with `c_i ≤ √b_i` and
//! `d_i ≥ 1/(c_i + c_{i+1})` (`c_0 = c_N = 0`):
//!
//! ```text
//! minimise   Σ_i 2 Δs_i d_i                                   (= Σ_i Δt_i at the optimum)
//! subject to α_r b_i + β_r b_{i+1} ≤ 1                        (ℝ₊)
//!            ‖(2 c_i, b_i − 1)‖ ≤ b_i + 1     ⇔ c_i² ≤ b_i               (SOC₃)
//!            ‖(2, d_i − c_i − c_{i+1})‖ ≤ d_i + c_i + c_{i+1}
//!                                             ⇔ d_i (c_i + c_{i+1}) ≥ 1  (SOC₃)
//! ```
//!
//! `3N − 2` variables and `2N − 1` cones: same optimum (the tests check the
//! durations agree), far slower, kept as the reference form and for
//! the smoothing term `w Σ_i (a_{i+1} − a_i)²`, `a_i = (b_{i+1} − b_i)/(2Δs_i)`,
//! which enters `P` (with a smoothing weight the LP form is not used).

use std::collections::BTreeMap;
use std::time::Instant;

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use serde::{Deserialize, Serialize};

use super::grid::PathGrid;
pub use super::grid::SegmentRows;

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

/// Which convex program computes the profile (same optimum, see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Program {
    /// The LP `max Σ w_i b_i` over the lattice-compatible rows.
    #[default]
    GreatestProfile,
    /// The SOCP with the exact time objective.
    ExactTime,
}

/// Solver knobs of the program.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProgramSettings {
    pub program: Program,
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
    let socp = settings.program == Program::ExactTime || settings.smoothing_weight > 0.0;
    let started = Instant::now();
    match (!socp).then(|| greatest_profile(rows)).flatten() {
        Some(b) => ProfileSolution {
            b,
            outcome: SolverOutcome::Solved,
            iterations: 0,
            solve_time_s: started.elapsed().as_secs_f64(),
        },
        None => interior_point(grid, rows, settings, socp),
    }
}

/// The LP (`socp = false`) or the SOCP solved by Clarabel.
fn interior_point(
    grid: &PathGrid,
    rows: &SegmentRows,
    settings: &ProgramSettings,
    socp: bool,
) -> ProfileSolution {
    let n = grid.segments();
    let inner = n - 1;
    let b_col = |i: usize| (i >= 1 && i < n).then(|| i - 1);
    let c_col = |i: usize| (i >= 1 && i < n).then(|| inner + i - 1);
    let d_col = |i: usize| 2 * inner + i;
    let vars = if socp { 2 * inner + n } else { inner };

    let lin = rows.rows.len();
    let m = if socp { lin + 3 * inner + 3 * n } else { lin };
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
        }
    }
    h[..lin].fill(1.0);
    let mut q = vec![0.0; vars];
    let mut cones = Vec::with_capacity(1 + inner + n);
    if lin > 0 {
        cones.push(SupportedConeT::NonnegativeConeT(lin));
    }
    if socp {
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
        for i in 0..n {
            q[d_col(i)] = 2.0 * grid.step(i);
        }
        cones.extend(std::iter::repeat_n(
            SupportedConeT::SecondOrderConeT(3),
            inner + n,
        ));
    } else {
        for i in 1..n {
            q[i - 1] = -0.5 * (grid.step(i - 1) + grid.step(i));
        }
    }
    let a = CscMatrix::new_from_triplets(m, vars, ti, tj, tv);
    let p = if socp {
        smoothing_matrix(grid, settings.smoothing_weight, vars)
    } else {
        CscMatrix::zeros((vars, vars))
    };

    let clarabel_settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(settings.max_iterations)
        .tol_gap_abs(settings.tolerance)
        .tol_gap_rel(settings.tolerance)
        // The LP's rows are normalised (right-hand sides 1, coefficients of
        // order 1/v², 1/(A Δs)): equilibration and iterative refinement
        // cost more than half the solve and change no figure we use.
        .equilibrate_enable(socp)
        .iterative_refinement_enable(socp)
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
/// The LP's greatest element `b*` exactly, in two passes over the
/// segments (the reachability analysis of TOPP-RA, Pham & Pham, IEEE T-RO
/// 2018, on these rows); `None` when a row couples `b_i` and `b_{i+1}` with
/// two positive coefficients or some `b_i` has no upper bound (then the
/// feasible set is no lattice, or the LP unbounded: Clarabel decides).
///
/// Each row `α b_i + β b_{i+1} ≤ 1` of segment `i` is an upper bound on
/// `b_i` nondecreasing in `b_{i+1}` (`α > 0 ≥ β`), or one on `b_{i+1}`
/// nondecreasing in `b_i` (`β > 0 ≥ α`), or holds for every `b ≥ 0`. The
/// backward pass gives `K_i`, the largest `b_i` from which some profile
/// reaches rest at `s = L` (`K_N = 0`): with `Y(x) = min(K_{i+1},
/// min_β>0 (1 − α x)/β)` the largest `b_{i+1}` reachable from `b_i = x`,
/// `K_i` is the largest `x` with `α x + β Y(x) ≤ 1` for every row with
/// `α > 0`, the smallest of that row's bounds against `K_{i+1}` and
/// against each `β > 0` row. The forward pass from `b_0 = 0` takes
/// `b_{i+1} = Y(b_i)`, the largest feasible value at each step, which is
/// `b*` (every feasible `b` stays below it by induction).
fn greatest_profile(rows: &SegmentRows) -> Option<Vec<f64>> {
    let n = rows.offsets.len() - 1;
    let segment = |i: usize| &rows.rows[rows.offsets[i]..rows.offsets[i + 1]];
    if rows.rows.iter().any(|&(a, b)| a > 0.0 && b > 0.0) {
        return None;
    }
    // `Y(x)` on segment `i` below `cap`.
    let reach = |i: usize, x: f64, cap: f64| {
        segment(i)
            .iter()
            .filter(|r| r.1 > 0.0)
            .map(|&(a, b)| (1.0 - a * x) / b)
            .fold(cap, f64::min)
    };
    let mut most = vec![0.0; n + 1];
    for i in (1..n).rev() {
        let next = most[i + 1];
        let mut x = f64::INFINITY;
        for &(a, b) in segment(i).iter().filter(|r| r.0 > 0.0) {
            // Against `b_{i+1} ≤ K_{i+1}`.
            x = x.min((1.0 - b * next) / a);
            // Against `b_{i+1} ≤ (1 − a' x)/b'`: x (a b' − b a') ≤ b' − b.
            for &(a2, b2) in segment(i).iter().filter(|r| r.1 > 0.0) {
                let slope = a * b2 - b * a2;
                if slope > 0.0 {
                    x = x.min((b2 - b) / slope);
                }
            }
        }
        if !(x.is_finite() && x > 0.0) {
            return None;
        }
        most[i] = x;
    }
    let mut b = vec![0.0; n + 1];
    for i in 0..n - 1 {
        b[i + 1] = reach(i, b[i], most[i + 1]).max(0.0);
    }
    Some(b)
}

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

#[cfg(test)]
mod tests {
    use super::super::grid;
    use super::super::spline::{PiecewiseCubic, chord_knots, widest_radii};
    use super::*;

    /// The rows of a wavy 3-joint path with 1 rad/s, 4 rad/s² limits.
    fn wavy_rows(segments: usize) -> (PathGrid, SegmentRows) {
        let path: Vec<Vec<f64>> = (0..12)
            .map(|k| {
                let x = k as f64 * 0.3;
                vec![x, (2.0 * x).sin(), 0.5 * (3.0 * x).cos()]
            })
            .collect();
        let points: Vec<&[f64]> = path.iter().map(Vec::as_slice).collect();
        let knots = chord_knots(&points);
        let spline = PiecewiseCubic::blended(&points, &knots, &widest_radii(&knots));
        let grid = PathGrid::new(&spline, segments);
        let rows = grid::program_rows(&spline, &grid, &[1.0; 3], &[4.0; 3], None);
        (grid, rows)
    }

    const LP: ProgramSettings = ProgramSettings {
        program: Program::GreatestProfile,
        smoothing_weight: 0.0,
        max_iterations: 100,
        tolerance: 1e-9,
    };

    /// The two passes give the LP's optimum that Clarabel approaches from
    /// inside: equal to its tolerance, feasible, and no lower anywhere.
    #[test]
    fn two_pass_greatest_profile_is_the_interior_point_optimum() {
        let (grid, rows) = wavy_rows(120);
        let exact = greatest_profile(&rows).expect("lattice rows");
        let clarabel = interior_point(&grid, &rows, &LP, false);
        assert_eq!(clarabel.outcome, SolverOutcome::Solved);
        for i in 0..grid.segments() {
            for &(a, b) in &rows.rows[rows.offsets[i]..rows.offsets[i + 1]] {
                assert!(a * exact[i] + b * exact[i + 1] <= 1.0 + 1e-12);
            }
        }
        let scale = exact.iter().copied().fold(0.0, f64::max);
        for (e, c) in exact.iter().zip(&clarabel.b) {
            assert!(e - c > -1e-7 * scale, "exact {e} below Clarabel {c}");
            assert!(e - c < 1e-5 * scale, "exact {e} far above Clarabel {c}");
        }
        assert_eq!(solve_profile(&grid, &rows, &LP).b, exact);
    }

    /// A row with two positive coefficients breaks the lattice: Clarabel
    /// solves that program.
    #[test]
    fn rows_off_the_lattice_go_to_the_interior_point_solver() {
        let (grid, mut rows) = wavy_rows(20);
        assert!(greatest_profile(&rows).is_some());
        let at = rows.offsets[5];
        rows.rows.insert(at, (0.1, 0.1));
        rows.offsets[6..].iter_mut().for_each(|o| *o += 1);
        assert!(greatest_profile(&rows).is_none());
        let solution = solve_profile(&grid, &rows, &LP);
        assert!(solution.iterations > 0);
        assert_eq!(solution.outcome, SolverOutcome::Solved);
    }
}
