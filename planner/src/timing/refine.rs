//! The convex program on the path grid, refined where a constraint binds:
//! the hands' tool-speed caps (lowered where the tool was over them), the
//! rows of every segment and the solve (LP or SOCP, see the `topp` module)
//! on the first grid and on each refined one.

use std::time::Instant;

use super::deviation::ToolPathCheck;
use super::grid::{self, PathGrid};
use super::outcome::{SeparationSummary, TimingError};
use super::separation::nearest_hand_distance;
use super::settings::{JointLimits, Proximity, TimingSettings};
use super::spline::PiecewiseCubic;
use super::tool_speed::Excess;
use super::topp::{self, ProfileSolution, ProgramSettings, SegmentRows, SolverOutcome};

/// Most times a path is timed again with its caps lowered where the tool
/// was over a hand's cap (see `time_path`).
pub(super) const TOOL_SPEED_ROUNDS: u32 = 4;

/// A lowered cap lands this fraction below the measured excess.
pub(super) const LOWER_SLACK: f64 = 2e-3;

/// A cut never takes the interpolant's cap below this share of the limit:
/// a real tool more than twice as fast as the interpolant is a path whose
/// forward kinematics and tool positions disagree, not a timing to slow
/// down without end (the rounds then end in a `LimitViolated` status).
pub(super) const LOWEST_CUT: f64 = 0.5;

/// The filter's window is taken this much wider than the width it had
/// when the caps are lowered for it (the path timed again may filter wider).
pub(super) const WINDOW_SLACK: f64 = 1.25;

/// How the hands' caps are lowered below the rule's.
#[derive(Debug, Default)]
pub(super) struct CapShape {
    /// Each segment's cap to the smallest over the stretch of path the jerk
    /// filter mixes into its samples; none before the first filter.
    pub(super) window: Option<FilterWindow>,
    /// At most this cap, m/s, on the segments the stretch `[s_lo, s_hi]`
    /// touches.
    pub(super) cuts: Vec<((f64, f64), f64)>,
}

impl CapShape {
    /// Lowers each excess's stretch to the interpolant speed at which the
    /// tool meets its limit: the interpolant's speed there times
    /// `limit / speed`, at least [`LOWEST_CUT`] of the limit, as a cap
    /// before the program's `tool_shrink`.
    pub(super) fn lower(&mut self, excess: &[Excess], tool_shrink: f64) {
        self.cuts.extend(excess.iter().map(|e| {
            let meets = e.interpolant * e.limit / e.speed * (1.0 - LOWER_SLACK);
            (e.stretch, meets.max(LOWEST_CUT * e.limit) / tool_shrink)
        }));
    }

    /// Applies the cuts to `caps`, one per segment of `grid`.
    fn cut(&self, grid: &PathGrid, caps: &mut [f64]) {
        for &(stretch, most) in &self.cuts {
            for cap in &mut caps[touched(grid, stretch)] {
                *cap = cap.min(most);
            }
        }
    }

    /// `grid` with each segment a cut touches split into parts about as
    /// long as the cut's stretch (at most [`MOST_PARTS`]), so that a cut
    /// slows no more of the path than it must.
    fn split(&self, grid: PathGrid) -> PathGrid {
        if self.cuts.is_empty() {
            return grid;
        }
        let mut parts = vec![1; grid.segments()];
        for &((lo, hi), _) in &self.cuts {
            for i in touched(&grid, (lo, hi)) {
                let wanted = (grid.step(i) / (hi - lo).max(f64::MIN_POSITIVE)).ceil();
                parts[i] = parts[i].max(wanted.min(MOST_PARTS as f64) as usize);
            }
        }
        grid.split(|i| parts[i])
    }
}

/// Where the jerk filter mixes speeds: a sample at time `t` averages the
/// path over `[t − τ, t]`, so every sample that averages a point of the
/// stretch `[lo, hi]` averages only path the profile crosses within `τ`
/// before `lo` or after `hi`. Read on the profile timed before the caps
/// are lowered: lowered caps only lower the time-optimal profile, so the
/// stretch found covers the one the slower motion mixes, with
/// [`WINDOW_SLACK`] for a wider filter. Where the motion timed again is
/// still over a cap (a rounded peak moved, say), the samples' check finds
/// it and the cuts of [`CapShape::lower`] follow, as before.
#[derive(Debug)]
pub(super) struct FilterWindow {
    /// The earlier profile's grid points and their times (s, seconds).
    pub(super) s: Vec<f64>,
    pub(super) t: Vec<f64>,
    /// The window, seconds.
    pub(super) tau: f64,
}

impl FilterWindow {
    /// The path the filter mixes into samples on `[lo, hi]`, whole
    /// segments of the earlier profile's grid outward.
    fn stretch(&self, lo: f64, hi: f64) -> (f64, f64) {
        let last = self.s.len() - 1;
        let at_or_before =
            |values: &[f64], x: f64| values.partition_point(|&v| v <= x).saturating_sub(1);
        let at_or_after = |values: &[f64], x: f64| values.partition_point(|&v| v < x).min(last);
        let t_lo = self.t[at_or_before(&self.s, lo)] - self.tau;
        let t_hi = self.t[at_or_after(&self.s, hi)] + self.tau;
        (
            self.s[at_or_before(&self.t, t_lo)],
            self.s[at_or_after(&self.t, t_hi)],
        )
    }
}

/// The segments of `grid` that the stretch `[lo, hi]` touches.
pub(super) fn touched(grid: &PathGrid, (lo, hi): (f64, f64)) -> std::ops::Range<usize> {
    let from = grid.s.partition_point(|&s| s < lo).saturating_sub(1);
    let to = grid.s.partition_point(|&s| s <= hi).min(grid.segments());
    from..to.max(from)
}

/// What [`solve_refined`] and `finish` share.
pub(super) struct Inputs<'a> {
    pub(super) spline: &'a PiecewiseCubic,
    pub(super) program: &'a ProgramLimits,
    pub(super) tool: Option<(&'a PiecewiseCubic, &'a Proximity)>,
    pub(super) tool_spline: Option<&'a PiecewiseCubic>,
    pub(super) limits: &'a JointLimits,
    pub(super) settings: &'a TimingSettings,
    pub(super) points: &'a [&'a [f64]],
    pub(super) planned: Option<&'a ToolPathCheck<'a>>,
    pub(super) started: Instant,
}

/// The program on the first grid, then refined where a constraint binds
/// (`settings.refine_rounds`); the hands' caps lowered as `shape` says.
/// Also the rounds run.
pub(super) fn solve_refined(
    inputs: &Inputs,
    shape: &CapShape,
) -> Result<(Solved, u32), TimingError> {
    let Inputs {
        spline,
        program,
        tool,
        settings,
        ..
    } = *inputs;
    let mut solved = solve_on_grid(
        spline,
        shape.split(PathGrid::new(spline, settings.path_points)),
        program,
        tool,
        settings,
        shape,
    )?;
    let mut rounds = 0;
    let most = settings.path_points.max(solved.grid.segments()) * MAX_REFINED_GROWTH;
    while rounds < settings.refine_rounds && solved.usable() && solved.grid.segments() < most {
        let parts = solved.refinable(inputs);
        if parts.iter().all(|&p| p <= 1) {
            break;
        }
        let finer = solved.grid.split(|i| parts[i]);
        let next = solve_on_grid(spline, finer, program, tool, settings, shape)?;
        rounds += 1;
        if !next.usable() {
            break;
        }
        let (before, after) = (solved.duration(), next.duration());
        solved = next;
        if before - after <= settings.refine_tolerance * before {
            break;
        }
    }
    Ok((solved, rounds))
}

/// The cap of every segment of `grid` (m/s), lowered as `shape` says, and
/// the summary. A segment's distance is the smaller end-point distance less
/// half its chord (a lower bound along a straight chord).
pub(super) fn tool_caps(
    proximity: &Proximity,
    tool: &PiecewiseCubic,
    grid: &PathGrid,
    shape: &CapShape,
) -> Result<ToolCaps, TimingError> {
    let rule = &proximity.rule;
    let (mut x, mut dx, mut ddx) = ([0.0; 3], [0.0; 3], [0.0; 3]);
    let positions: Vec<[f64; 3]> = grid
        .s
        .iter()
        .map(|&s| {
            tool.eval(s, &mut x, &mut dx, &mut ddx);
            x
        })
        .collect();
    let distance: Vec<f64> = positions
        .iter()
        .map(|&p| nearest_hand_distance(&proximity.hands, p))
        .collect();
    let mut summary = SeparationSummary {
        min_distance_m: distance.iter().copied().fold(f64::INFINITY, f64::min),
        min_cap_m_s: f64::INFINITY,
        reduced_segments: 0,
        crawl_segments: 0,
    };
    let mut caps = Vec::with_capacity(grid.segments());
    let mut rises = Vec::with_capacity(grid.segments());
    for i in 0..grid.segments() {
        let chord: f64 = (0..3)
            .map(|k| (positions[i + 1][k] - positions[i][k]).powi(2))
            .sum::<f64>()
            .sqrt();
        let d = (distance[i].min(distance[i + 1]) - 0.5 * chord).max(0.0);
        let cap = rule.tool_speed_cap(d);
        if cap <= 0.0 {
            return Err(TimingError::InsideProtectiveDistance {
                s: grid.s[i],
                distance_m: d,
                required_m: rule.stop_distance(d),
            });
        }
        if cap <= rule.reduced_speed_m_s {
            summary.reduced_segments += 1;
        }
        if rule.formula_speed(d) <= rule.min_tool_speed_m_s {
            summary.crawl_segments += 1;
        }
        summary.min_cap_m_s = summary.min_cap_m_s.min(cap);
        caps.push(cap);
        // The distance anywhere on the segment is at most the farther end's
        // plus half the chord: a finer grid may raise the cap only below that.
        let farthest = distance[i].max(distance[i + 1]) + 0.5 * chord;
        rises.push(rule.tool_speed_cap(farthest) > cap);
    }
    let limits = caps.clone();
    if let Some(window) = &shape.window {
        for (i, cap) in caps.iter_mut().enumerate() {
            let mixed = touched(grid, window.stretch(grid.s[i], grid.s[i + 1]));
            *cap = limits[mixed].iter().copied().fold(*cap, f64::min);
        }
    }
    shape.cut(grid, &mut caps);
    Ok(ToolCaps {
        caps,
        limits,
        rises,
        summary,
    })
}

/// Segments an active segment is cut into at each refinement round
/// without a looseness (the reference's refinement).
pub(super) const REFINE_PARTS: usize = 4;

/// Most segments a loose segment is cut into at one refinement round.
pub(super) const MOST_PARTS: usize = 8;

/// Relative slack below which a row counts as active (binding).
pub(super) const ACTIVE_SLACK: f64 = 1e-4;

/// Refinement stops once the grid has this many times the segments it
/// started with (bounds the work).
pub(super) const MAX_REFINED_GROWTH: usize = 8;

/// The limits as the program uses them (scaled, margined).
pub(super) struct ProgramLimits {
    /// `v_j²`, (rad/s)².
    pub(super) vel_sq: Vec<f64>,
    /// `A_j`, rad/s².
    pub(super) acc: Vec<f64>,
    /// Factor on every tool-speed cap.
    pub(super) tool_shrink: f64,
}

/// One solve of the program on one grid.
pub(super) struct Solved {
    pub(super) grid: PathGrid,
    pub(super) rows: SegmentRows,
    pub(super) solution: ProfileSolution,
    /// Tool-speed caps near hands.
    pub(super) tool: Option<ToolCaps>,
}

/// The tool-speed cap of every segment near hands.
#[derive(Clone)]
pub(super) struct ToolCaps {
    /// Cap the program keeps, m/s.
    pub(super) caps: Vec<f64>,
    /// The separation rule's cap of each segment, m/s (`caps` may be lower,
    /// see [`solve_refined`]).
    pub(super) limits: Vec<f64>,
    /// A finer grid may raise the cap: the cap at the segment's largest
    /// possible hand distance is higher (the formula's graded part, or a
    /// clamped cap that the half-chord penalty moved off its plateau).
    pub(super) rises: Vec<bool>,
    pub(super) summary: SeparationSummary,
}

impl Solved {
    pub(super) fn usable(&self) -> bool {
        usable(&self.solution)
    }

    /// The exact discretised time `Σ 2Δs_i/(√b_i + √b_{i+1})`, seconds.
    pub(super) fn duration(&self) -> f64 {
        let b = &self.solution.b;
        (0..self.grid.segments())
            .map(|i| 2.0 * self.grid.step(i) / (b[i].max(0.0).sqrt() + b[i + 1].max(0.0).sqrt()))
            .sum()
    }

    /// Segments where a finer grid gains time: a row within
    /// [`ACTIVE_SLACK`] of its bound, and with `settings.refine_looseness > 0`
    /// some point of the segment where the profile uses less than
    /// `1 − refine_looseness` of every limit ([`Self::utilisation`]); with 0,
    /// every such segment whose binding rows may be conservative to first
    /// order in `Δs` — an acceleration row, a speed row of a joint turning
    /// round or of the tool ([`grid::speed_rows_loose`],
    /// [`grid::tool_speed_rows_loose`]), or a tool-speed cap a finer grid may
    /// raise ([`ToolCaps::rises`]).
    fn refinable(&self, inputs: &Inputs) -> Vec<usize> {
        let (spline, program) = (inputs.spline, inputs.program);
        let looseness = inputs.settings.refine_looseness;
        let b = &self.solution.b;
        (0..self.grid.segments())
            .map(|i| {
                let rows = &self.rows.rows[self.rows.offsets[i]..self.rows.offsets[i + 1]];
                let ends = (b[i], b[i + 1]);
                let active = rows
                    .iter()
                    .any(|(alpha, beta)| alpha * ends.0 + beta * ends.1 >= 1.0 - ACTIVE_SLACK);
                if !active {
                    return 1;
                }
                if looseness > 0.0 {
                    // The gap is first order in Δs: cut into enough parts
                    // to bring it to about the looseness.
                    let gap = 1.0 - self.utilisation(inputs, i);
                    return if gap > looseness {
                        ((gap / looseness).ceil() as usize).clamp(2, MOST_PARTS)
                    } else {
                        1
                    };
                }
                let loose = grid::acceleration_bound(
                    spline,
                    &self.grid,
                    i,
                    &program.acc,
                    ends,
                    ACTIVE_SLACK,
                ) || grid::speed_rows_loose(spline, &self.grid, i)
                    || self.tool.as_ref().is_some_and(|t| t.rises[i])
                    || inputs
                        .tool_spline
                        .is_some_and(|tool| grid::tool_speed_rows_loose(tool, &self.grid, i));
                if loose { REFINE_PARTS } else { 1 }
            })
            .collect()
    }

    /// The least share of the limits the profile uses at any point of
    /// segment `i` (at each point the largest share of any limit): the
    /// joints' ([`grid::joint_utilisation`]) and the tool's speed near hands
    /// against the separation rule's cap at that point (the program's cap
    /// where the jerk filter lowered it), as the program margins them.
    fn utilisation(&self, inputs: &Inputs, i: usize) -> f64 {
        let ends = (self.solution.b[i], self.solution.b[i + 1]);
        let program = inputs.program;
        let mut used = grid::joint_utilisation(
            inputs.spline,
            &self.grid,
            i,
            &program.vel_sq,
            &program.acc,
            ends,
        );
        if let (Some((tool, proximity)), Some(caps)) = (inputs.tool, self.tool.as_ref()) {
            let (mut x, mut dx, mut ddx) = ([0.0; 3], [0.0; 3], [0.0; 3]);
            let last = (used.len() - 1) as f64;
            for (k, used) in used.iter_mut().enumerate() {
                let t = k as f64 / last;
                tool.eval(
                    self.grid.s[i] + t * self.grid.step(i),
                    &mut x,
                    &mut dx,
                    &mut ddx,
                );
                let distance = nearest_hand_distance(&proximity.hands, x);
                let cap =
                    proximity.rule.tool_speed_cap(distance).min(caps.caps[i]) * program.tool_shrink;
                let b = ends.0 + t * (ends.1 - ends.0);
                *used = used.max(dx.iter().map(|v| v * v).sum::<f64>() * b / (cap * cap));
            }
        }
        used.into_iter().fold(f64::INFINITY, f64::min)
    }
}

pub(super) fn usable(solution: &ProfileSolution) -> bool {
    let n = solution.b.len() - 1;
    matches!(
        solution.outcome,
        SolverOutcome::Solved | SolverOutcome::AlmostSolved
    ) && solution.b[1..n].iter().all(|b| b.is_finite() && *b > 0.0)
}

/// Rows of every segment of `grid` (with the tool-speed caps near hands),
/// then the program.
pub(super) fn solve_on_grid(
    spline: &PiecewiseCubic,
    grid: PathGrid,
    limits: &ProgramLimits,
    tool: Option<(&PiecewiseCubic, &Proximity)>,
    settings: &TimingSettings,
    shape: &CapShape,
) -> Result<Solved, TimingError> {
    let caps = tool
        .map(|(tool, proximity)| tool_caps(proximity, tool, &grid, shape))
        .transpose()?;
    let caps_sq: Option<Vec<f64>> = caps.as_ref().map(|t| {
        t.caps
            .iter()
            .map(|c| (c * limits.tool_shrink).powi(2))
            .collect()
    });
    let rows = grid::program_rows(
        spline,
        &grid,
        &limits.vel_sq,
        &limits.acc,
        tool.zip(caps_sq.as_deref())
            .map(|((spline, _), caps_sq)| (spline, caps_sq)),
    );
    let solution = topp::solve_profile(
        &grid,
        &rows,
        &ProgramSettings {
            program: settings.program,
            smoothing_weight: settings.smoothing_weight,
            max_iterations: settings.max_iterations,
            tolerance: settings.solver_tolerance,
        },
    );
    Ok(Solved {
        grid,
        rows,
        solution,
        tool: caps,
    })
}
