//! From a solved profile to checked samples: the jerk filter (widened at
//! the switches of the path acceleration where jerk limits ask for it),
//! sampling at the controller rate and the check of every sample.

use super::outcome::{MAX_SAMPLES, SolveStats, Timing, TimingError, TimingStatus};
use super::refine::{Inputs, Solved, usable};
use super::sample::{self, SpeedProfile};
use super::settings::{JointLimits, TimingSettings};
use super::tool_speed::{self, Excess, ToolSpeedCheck};
use super::topp::{self, ProgramSettings, SegmentRows, SolverOutcome};
use super::{jerk, ramp};

/// Samples the solved profile through the jerk filter and checks every
/// sample; also every sample interval where the tool is over a hand's cap.
pub(super) fn finish(
    inputs: &Inputs,
    Ramped {
        solved,
        rounds,
        narrow,
        ramp_s,
    }: Ramped,
) -> Result<(Timing, Vec<Excess>), TimingError> {
    let Inputs {
        spline,
        program,
        limits,
        settings,
        points,
        planned,
        started,
        ..
    } = *inputs;
    let k = settings.speed_scale;
    let Solved {
        grid,
        rows,
        solution,
        tool: tool_caps,
    } = solved;
    let n = grid.segments();
    let tool = inputs.tool_spline.zip(tool_caps);
    let mut stats = SolveStats {
        outcome: solution.outcome,
        iterations: solution.iterations,
        segments: n,
        linear_rows: rows.rows.len(),
        solve_time_s: solution.solve_time_s,
        refinements: rounds,
        jerk_filter_s: 0.0,
        jerk_ramp_s: ramp_s,
        tool_speed_rounds: 0,
        total_time_s: 0.0,
    };
    let separation = tool.as_ref().map(|(_, t)| t.summary.clone());
    if !usable(&solution) {
        stats.total_time_s = started.elapsed().as_secs_f64();
        let outcome = match solution.outcome {
            SolverOutcome::Solved | SolverOutcome::AlmostSolved => SolverOutcome::NumericalError,
            other => other,
        };
        let timing = Timing {
            status: TimingStatus::SolverStopped { outcome },
            trajectory: None,
            profile: None,
            stats,
            separation,
        };
        return Ok((timing, Vec::new()));
    }

    let profile = SpeedProfile::new(&grid, &solution.b);
    let velocity: Vec<f64> = limits.velocity.iter().map(|v| v * k).collect();
    let acceleration: Vec<f64> = limits.acceleration.iter().map(|a| a * k * k).collect();
    // The filter keeps the jerk within the limits less the program's margin,
    // so the samples stay strictly inside them whatever the rounding.
    let jerk_kept = jerk_kept(limits, settings);
    let widest = jerk::jerk_bound_width(&program.acc, &jerk_kept).unwrap_or(0.0);
    let samples = ((profile.duration() + widest) * settings.rate_hz).ceil() + 1.0;
    if !samples.is_finite() || samples > MAX_SAMPLES as f64 {
        return Err(TimingError::TooManySamples {
            duration_s: profile.duration() + widest,
            rate_hz: settings.rate_hz,
            samples,
        });
    }
    let ends = (points[0], points[points.len() - 1]);
    let sample_limits = sample::SampleLimits {
        lower: &limits.lower,
        upper: &limits.upper,
        velocity: &velocity,
        acceleration: &acceleration,
        jerk: &limits.jerk,
        tolerance: settings.tolerance,
    };
    // The narrowest filter found on the profile, then (should its samples
    // break a limit) the width that bounds every joint's jerk.
    let mut widths = vec![narrow];
    if widest > narrow {
        widths.push(widest);
    }
    // Every sample's interpolant speed within the caps the program kept
    // (`tool_speed_margin` below the rule's: the margin is for the real
    // tool's speed, not for the averaging), the real tool's within the
    // rule's.
    let kept_caps: Option<Vec<f64>> = tool
        .as_ref()
        .map(|(_, t)| t.limits.iter().map(|c| c * program.tool_shrink).collect());
    let speed_check = tool
        .as_ref()
        .zip(kept_caps.as_deref())
        .zip(inputs.tool)
        .map(|(((spline, caps), kept), (_, proximity))| ToolSpeedCheck {
            tool: spline,
            kept,
            limits: &caps.limits,
            hands: &proximity.hands,
            rule: &proximity.rule,
            real: planned,
        });
    let mut outcome = None;
    for tau in widths {
        let motion = jerk::Filtered::new(spline, &profile, tau);
        let trajectory = sample::sample(&motion, settings.rate_hz, ends);
        let tools: Option<Vec<[f64; 3]>> = planned.map(|planned| {
            trajectory
                .points
                .iter()
                .map(|p| planned.fk_of(&p.positions))
                .collect()
        });
        let excess = speed_check.as_ref().map_or_else(Vec::new, |c| {
            tool_speed::excess(
                &trajectory,
                &profile,
                &motion,
                c,
                tools.as_deref(),
                settings.tolerance,
            )
        });
        let check = match excess.first() {
            Some(over) => Err(over.violation()),
            None => sample::verify(
                &trajectory,
                &sample_limits,
                &sample::PathChecks {
                    path: spline,
                    motion: &motion,
                    tool_path: planned.zip(tools.as_deref()),
                },
            ),
        };
        stats.jerk_filter_s = tau;
        let passed = check.is_ok();
        outcome = Some((check, trajectory, excess));
        if passed {
            break;
        }
    }
    let (check, trajectory, excess) = outcome.expect("at least one filter width is tried");
    debug_assert_eq!(trajectory.points[0].positions.len(), limits.velocity.len());
    stats.total_time_s = started.elapsed().as_secs_f64();
    let (status, trajectory) = match check {
        Ok(()) => (TimingStatus::Solved, Some(trajectory)),
        Err(violation) => (TimingStatus::LimitViolated { violation }, None),
    };
    let timing = Timing {
        status,
        trajectory,
        profile: Some(profile),
        stats,
        separation,
    };
    Ok((timing, excess))
}

/// The jerk limits the filter keeps: the limits less the program's margin,
/// so the samples stay strictly inside them whatever the rounding.
pub(super) fn jerk_kept(limits: &JointLimits, settings: &TimingSettings) -> Vec<f64> {
    limits
        .jerk
        .iter()
        .map(|j| j * (1.0 - settings.limit_margin))
        .collect()
}

/// A solved profile with the narrowest jerk filter found for it.
pub(super) struct Ramped {
    pub(super) solved: Solved,
    /// Refinement rounds run.
    pub(super) rounds: u32,
    /// The narrowest filter width whose probes keep the jerk, seconds.
    pub(super) narrow: f64,
    /// How much longer the profile is than the time-optimal one, seconds.
    pub(super) ramp_s: f64,
}

/// The time-optimal profile with its narrowest jerk filter, or (with jerk
/// limits and `settings.jerk_ramp_rounds > 0`) the same lattice rows with
/// `b ≤ g`, `g` the time-optimal profile with its peaks rounded
/// ([`ramp::rounded_peaks`], each round at the last profile's speeds),
/// whichever ends sooner with its own narrowest filter. Every one keeps
/// every limit the lattice rows bound; the samples of the one kept are
/// checked as every profile's are.
pub(super) fn ramp_at_switches(inputs: &Inputs, (solved, rounds): (Solved, u32)) -> Ramped {
    let Inputs {
        spline,
        program,
        limits,
        settings,
        ..
    } = *inputs;
    let kept = jerk_kept(limits, settings);
    let profile = |solved: &Solved| SpeedProfile::new(&solved.grid, &solved.solution.b);
    let plain = match solved.usable() {
        true => jerk::filter_width(spline, &profile(&solved), &program.acc, &kept),
        false => 0.0,
    };
    if settings.jerk_ramp_rounds == 0 || plain == 0.0 {
        return Ramped {
            solved,
            rounds,
            narrow: plain,
            ramp_s: 0.0,
        };
    }
    let optimal = solved.duration();
    let program_settings = ProgramSettings {
        program: settings.program,
        smoothing_weight: settings.smoothing_weight,
        max_iterations: settings.max_iterations,
        tolerance: settings.solver_tolerance,
    };
    let mut speeds = solved.solution.b.clone();
    let mut ramped: Option<Ramped> = None;
    for _ in 0..settings.jerk_ramp_rounds {
        let rounded = ramp::rounded_peaks(
            spline,
            &solved.grid,
            &solved.solution.b,
            &speeds,
            &kept,
            RAMP_SHARE,
        );
        let rows = capped_rows(&solved.rows, &rounded);
        let solution = topp::solve_profile(&solved.grid, &rows, &program_settings);
        if !usable(&solution) {
            break;
        }
        let candidate = Solved {
            grid: solved.grid.clone(),
            rows,
            solution,
            tool: solved.tool.clone(),
        };
        let ramp_s = candidate.duration() - optimal;
        speeds.clone_from(&candidate.solution.b);
        let so_far = ramped.as_ref().map_or(plain, |r| r.ramp_s + r.narrow);
        // Only a width that makes the candidate end sooner is searched for.
        let narrower = jerk::filter_width_below(
            spline,
            &profile(&candidate),
            &program.acc,
            &kept,
            so_far - ramp_s,
        );
        if let Some(narrow) = narrower {
            ramped = Some(Ramped {
                solved: candidate,
                rounds,
                narrow,
                ramp_s,
            });
        }
    }
    ramped.unwrap_or(Ramped {
        solved,
        rounds,
        narrow: plain,
        ramp_s: 0.0,
    })
}

/// The share of each joint's jerk limit the path acceleration's fall may
/// use at a rounded peak: the rest is for the grid's steps (the fall is a
/// staircase of one step a segment), taken up by the filter.
pub(super) const RAMP_SHARE: f64 = 0.75;

/// `rows` with `b_i ≤ cap_i` added at every inner grid point `i`.
pub(super) fn capped_rows(rows: &SegmentRows, cap: &[f64]) -> SegmentRows {
    let n = rows.offsets.len() - 1;
    let mut capped = SegmentRows {
        offsets: Vec::with_capacity(n + 1),
        rows: Vec::with_capacity(rows.rows.len() + n),
    };
    capped.offsets.push(0);
    for (i, (range, most)) in rows.offsets.windows(2).zip(cap).enumerate() {
        capped
            .rows
            .extend_from_slice(&rows.rows[range[0]..range[1]]);
        if i > 0 {
            capped.rows.push((1.0 / most, 0.0));
        }
        capped.offsets.push(capped.rows.len());
    }
    capped
}
