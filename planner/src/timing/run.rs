//! The timing stage as one pure function: a joint path in, a checked
//! trajectory out (its settings in `settings`, its results in `outcome`).

use std::time::Instant;

use super::deviation::{ToolFk, ToolPathCheck, narrow_radii};
use super::finish::{finish, ramp_at_switches};
use super::outcome::{SolveStats, Timing, TimingError, TimingStatus};
use super::refine::{
    CapShape, FilterWindow, Inputs, ProgramLimits, TOOL_SPEED_ROUNDS, WINDOW_SLACK, solve_refined,
};
use super::sample::{self, JointTrajectory, LimitKind, LimitViolation};
use super::settings::{JointLimits, Proximity, TimingSettings};
use super::spline::{PiecewiseCubic, chord_knots, widest_radii};
use super::taut;
use super::topp::SolverOutcome;

/// Times a joint path without the arm's forward kinematics: as
/// [`time_parameterize_tool`] with the corners blended at their widest and
/// no tool-path check.
pub fn time_parameterize(
    waypoints: &[Vec<f64>],
    limits: &JointLimits,
    proximity: Option<&Proximity>,
    settings: &TimingSettings,
) -> Result<Timing, TimingError> {
    time_parameterize_tool(waypoints, limits, proximity, None, settings)
}

/// Times one arm's joint path: blended path → grid → separation caps →
/// rows → LP (two passes) or SOCP (Clarabel) → sampling → check of every sample (positions,
/// velocities, accelerations, tool speed near hands, and with `fk` the
/// tool's distance from the planned tool path). `Err` only for bad input
/// (a waypoint outside the position limits included); a solver that stops
/// early or a sample outside a limit is a [`TimingStatus`]. Consecutive
/// identical waypoints are merged; a path of one configuration gives a
/// one-sample trajectory at rest.
pub fn time_parameterize_tool(
    waypoints: &[Vec<f64>],
    limits: &JointLimits,
    proximity: Option<&Proximity>,
    fk: Option<ToolFk>,
    settings: &TimingSettings,
) -> Result<Timing, TimingError> {
    let started = Instant::now();
    settings.validate()?;
    validate_input(waypoints, limits, proximity)?;

    // Merge repeated waypoints (zero chord) with their tool positions.
    let mut keep: Vec<usize> = vec![0];
    for k in 1..waypoints.len() {
        let last = &waypoints[*keep.last().expect("non-empty")];
        if waypoints[k] != *last {
            keep.push(k);
        }
    }
    if keep.len() == 1 {
        return Ok(at_rest(&waypoints[0], started));
    }
    let points: Vec<&[f64]> = keep.iter().map(|&k| waypoints[k].as_slice()).collect();
    let tool_points: Option<Vec<[f64; 3]>> = proximity
        .filter(|p| !p.hands.is_empty())
        .map(|p| keep.iter().map(|&k| p.tool_positions[k]).collect());
    let planned = fk.map(|fk| ToolPathCheck::new(&points, fk, settings.max_tool_deviation_m));
    let taut = match (fk, &planned) {
        (Some(fk), Some(planned)) if settings.taut_tool_budget_m > 0.0 => taut::pull_taut(
            &points,
            &chord_knots(&points),
            (&limits.lower, &limits.upper),
            fk,
            planned,
            settings.taut_tool_budget_m,
        )
        .filter(|q| q.windows(2).all(|w| w[0] != w[1])),
        _ => None,
    };
    let path = Path {
        points: &points,
        tool_points: tool_points.as_deref(),
        planned: planned.as_ref(),
    };
    // The joints pulled taut, else (no budget, or a sample off the planned
    // tool path or beyond a limit) the waypoints as they are.
    if let Some(taut) = &taut {
        let taut_points: Vec<&[f64]> = taut.iter().map(Vec::as_slice).collect();
        let taut_tools: Option<Vec<[f64; 3]>> = tool_points
            .as_ref()
            .zip(fk)
            .map(|(_, fk)| taut.iter().map(|q| fk(q)).collect());
        let timing = time_path(
            &Path {
                points: &taut_points,
                tool_points: taut_tools.as_deref(),
                planned: planned.as_ref(),
            },
            limits,
            proximity,
            fk,
            settings,
            started,
        )?;
        if timing.status == TimingStatus::Solved {
            return Ok(timing);
        }
    }
    time_path(&path, limits, proximity, fk, settings, started)
}

/// The joint path to time and the tool path it must keep to.
struct Path<'a> {
    /// Joint waypoints (consecutive ones distinct).
    points: &'a [&'a [f64]],
    /// The tool at each waypoint when hands are near, metres.
    tool_points: Option<&'a [[f64; 3]]>,
    /// The planned tool path (the collision-checked joint polyline's).
    planned: Option<&'a ToolPathCheck<'a>>,
}

/// Blended path → grid → program → jerk filter → samples → checks.
fn time_path(
    path: &Path,
    limits: &JointLimits,
    proximity: Option<&Proximity>,
    fk: Option<ToolFk>,
    settings: &TimingSettings,
    started: Instant,
) -> Result<Timing, TimingError> {
    let points = path.points;
    let knots = chord_knots(points);
    let mut radii = widest_radii(&knots);
    if let Some(fk) = fk {
        narrow_radii(
            points,
            &knots,
            &mut radii,
            fk,
            0.5 * settings.max_tool_deviation_m,
        );
    }
    let spline = PiecewiseCubic::blended(points, &knots, &radii);

    // Limits inside the program: scaled, with the margin taken off.
    let k = settings.speed_scale;
    let shrink = 1.0 - settings.limit_margin;
    let program = ProgramLimits {
        vel_sq: limits
            .velocity
            .iter()
            .map(|v| (v * k * shrink).powi(2))
            .collect(),
        acc: limits
            .acceleration
            .iter()
            .map(|a| a * k * k * shrink)
            .collect(),
        tool_shrink: shrink * (1.0 - settings.tool_speed_margin),
    };
    let tool_spline = path.tool_points.map(|tools| {
        let tools: Vec<&[f64]> = tools.iter().map(|p| p.as_slice()).collect();
        PiecewiseCubic::blended(&tools, &knots, &radii)
    });
    let tool = tool_spline.as_ref().zip(proximity);

    let inputs = Inputs {
        spline: &spline,
        program: &program,
        tool,
        tool_spline: tool_spline.as_ref(),
        limits,
        settings,
        points,
        planned: path.planned,
        started,
    };
    // Where the tool is over a hand's cap at some sample (the jerk filter
    // mixing the speeds of a stretch of path, or the real tool faster than
    // the interpolant the program bounds), the caps there are lowered and
    // the path is timed again: first, with the filter, every cap to the
    // smallest within the distance the filter spans; then each over-cap
    // stretch's caps by its measured excess. A trajectory still over after
    // `TOOL_SPEED_ROUNDS` is a `LimitViolated` status, never emitted.
    let mut shape = CapShape::default();
    let mut round = 0;
    loop {
        let solved = solve_refined(&inputs, &shape)?;
        let (mut timing, excess) = finish(&inputs, ramp_at_switches(&inputs, solved))?;
        timing.stats.tool_speed_rounds = round;
        let over = matches!(
            timing.status,
            TimingStatus::LimitViolated {
                violation: LimitViolation {
                    kind: LimitKind::ToolSpeed,
                    ..
                },
            }
        );
        if !over || excess.is_empty() || round == TOOL_SPEED_ROUNDS {
            return Ok(timing);
        }
        match &timing.profile {
            Some(profile) if timing.stats.jerk_filter_s > 0.0 && shape.window.is_none() => {
                shape.window = Some(FilterWindow {
                    s: profile.s.clone(),
                    t: profile.t.clone(),
                    tau: WINDOW_SLACK * timing.stats.jerk_filter_s,
                });
            }
            _ => shape.lower(&excess, program.tool_shrink),
        }
        round += 1;
    }
}

fn validate_input(
    waypoints: &[Vec<f64>],
    limits: &JointLimits,
    proximity: Option<&Proximity>,
) -> Result<(), TimingError> {
    let joints = limits.velocity.len();
    if waypoints.is_empty() {
        return Err(TimingError::NoWaypoints);
    }
    if joints == 0 {
        return Err(TimingError::SizeMismatch {
            what: "velocity limits",
            len: 0,
            expected: waypoints[0].len().max(1),
        });
    }
    for (what, len) in [
        ("acceleration limits", limits.acceleration.len()),
        ("lower position limits", limits.lower.len()),
        ("upper position limits", limits.upper.len()),
    ] {
        if len != joints {
            return Err(TimingError::SizeMismatch {
                what,
                len,
                expected: joints,
            });
        }
    }
    for (joint, (&lower, &upper)) in limits.lower.iter().zip(&limits.upper).enumerate() {
        if !(lower <= upper && lower < f64::INFINITY && upper > f64::NEG_INFINITY) {
            return Err(TimingError::BadPositionLimits {
                joint,
                lower,
                upper,
            });
        }
    }
    if !limits.jerk.is_empty() && limits.jerk.len() != joints {
        return Err(TimingError::SizeMismatch {
            what: "jerk limits",
            len: limits.jerk.len(),
            expected: joints,
        });
    }
    for (what, values) in [
        ("velocity", &limits.velocity),
        ("acceleration", &limits.acceleration),
        ("jerk", &limits.jerk),
    ] {
        for (joint, &value) in values.iter().enumerate() {
            if !(value.is_finite() && value > 0.0) {
                return Err(TimingError::BadLimit { what, joint, value });
            }
        }
    }
    for (index, w) in waypoints.iter().enumerate() {
        if w.len() != joints {
            return Err(TimingError::WaypointLength {
                index,
                len: w.len(),
                expected: joints,
            });
        }
        if !w.iter().all(|x| x.is_finite()) {
            return Err(TimingError::NonFinite {
                what: "waypoints",
                index,
            });
        }
        let outside = (0..joints).find(|&j| !(limits.lower[j]..=limits.upper[j]).contains(&w[j]));
        if let Some(joint) = outside {
            return Err(TimingError::WaypointOutsideLimits {
                index,
                joint,
                value: w[joint],
                lower: limits.lower[joint],
                upper: limits.upper[joint],
            });
        }
    }
    if let Some(p) = proximity {
        p.rule.validate()?;
        if p.tool_positions.len() != waypoints.len() {
            return Err(TimingError::SizeMismatch {
                what: "tool positions",
                len: p.tool_positions.len(),
                expected: waypoints.len(),
            });
        }
        for (index, t) in p.tool_positions.iter().enumerate() {
            if !t.iter().all(|x| x.is_finite()) {
                return Err(TimingError::NonFinite {
                    what: "tool_positions",
                    index,
                });
            }
        }
        for (index, h) in p.hands.iter().enumerate() {
            if !(h.centre.iter().all(|x| x.is_finite()) && h.radius.is_finite() && h.radius >= 0.0)
            {
                return Err(TimingError::NonFinite {
                    what: "hands",
                    index,
                });
            }
        }
    }
    Ok(())
}

fn at_rest(q: &[f64], started: Instant) -> Timing {
    let dim = q.len();
    Timing {
        status: TimingStatus::Solved,
        trajectory: Some(JointTrajectory {
            points: vec![sample::TrajectoryPoint {
                positions: q.to_vec(),
                velocities: vec![0.0; dim],
                accelerations: vec![0.0; dim],
                time_from_start: 0.0,
            }],
        }),
        profile: None,
        stats: SolveStats {
            outcome: SolverOutcome::Solved,
            iterations: 0,
            segments: 0,
            linear_rows: 0,
            solve_time_s: 0.0,
            refinements: 0,
            jerk_filter_s: 0.0,
            jerk_ramp_s: 0.0,
            tool_speed_rounds: 0,
            total_time_s: started.elapsed().as_secs_f64(),
        },
        separation: None,
    }
}
