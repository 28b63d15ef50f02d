//! The tool's speed near hands against the speed-and-separation rule of
//! ISO/TS 15066 (with ISO 13855's human speeds), implemented here from the
//! formula with the scenario's `safety.separation` parameters.
//!
//! Protective separation distance for tool speed `v` when the hand is at
//! distance `d` (hand speed `v_h` = `human_speed_m_s` within
//! `human_speed_far_beyond_m`, `human_speed_far_m_s` beyond):
//!
//! `S_p(v) = v_h (T_r + v / a_s) + v T_r + v² / (2 a_s) + C + Z_d + Z_r`
//!
//! The cap is the largest `v >= 0` with `S_p(v) <= d` (the positive root of
//! the quadratic, 0 when even `S_p(0) > d`), at most `reduced_speed_m_s`
//! within `reduced_speed_distance_m`, at least the crawl floor
//! `min_tool_speed_m_s`. The tool's speed is the mean over each sample
//! interval (from the tool positions by forward kinematics), its distance
//! the smaller of the two ends' distances to the nearest hand box (the
//! hand's detected extent, table to its height).

use afford_planner::timing::SeparationSettings;
use nalgebra::{Point3, Vector3};

use crate::chain::Iso;

/// The tool's mean speed over an interval may exceed the cap by this
/// fraction (0.1 mm/s at the 0.05 m/s crawl): a planner that meets the cap
/// at its path points overshoots it between them by about 0.1 % (measured
/// on the cob4 examples: 0.050048 m/s at most); the protective distance
/// changes by well under a millimetre.
pub const TOOL_SPEED_TOLERANCE: f64 = 2e-3;

/// The allowed tool speed (m/s) at hand distance `d` (m).
pub(crate) fn cap(rule: &SeparationSettings, d: f64) -> f64 {
    let v_h = match d > rule.human_speed_far_beyond_m {
        true => rule.human_speed_far_m_s,
        false => rule.human_speed_m_s,
    };
    let (t_r, a_s) = (rule.reaction_time_s, rule.stop_deceleration_m_s2);
    let constant =
        rule.intrusion_distance_m + rule.sensing_uncertainty_m + rule.robot_uncertainty_m;
    let (a, b, c) = (1.0 / (2.0 * a_s), t_r + v_h / a_s, v_h * t_r + constant - d);
    let mut v = match c >= 0.0 {
        true => 0.0,
        false => (-b + (b * b - 4.0 * a * c).sqrt()) / (2.0 * a),
    };
    if d <= rule.reduced_speed_distance_m {
        v = v.min(rule.reduced_speed_m_s);
    }
    v.max(rule.min_tool_speed_m_s)
}

/// Distance from a point to a solid box (centre pose, half sizes).
fn box_distance(p: &Vector3<f64>, pose: &Iso, half: &[f64; 3]) -> f64 {
    let local = pose.inverse_transform_point(&Point3::from(*p));
    let out: Vector3<f64> = Vector3::from_fn(|k, _| (local[k].abs() - half[k]).max(0.0));
    out.norm()
}

/// The worst interval where the tool is faster than the cap, if any:
/// `tool` and `times` per sample, hands as (name, pose, half sizes).
pub(crate) fn check(
    rule: &SeparationSettings,
    hands: &[(String, Iso, [f64; 3])],
    tool: &[Vector3<f64>],
    times: &[f64],
) -> Option<String> {
    let nearest = |p: &Vector3<f64>| {
        hands
            .iter()
            .map(|(name, pose, half)| (box_distance(p, pose, half), name))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    };
    let mut worst: Option<(f64, String)> = None;
    let mut count = 0;
    for i in 0..tool.len().saturating_sub(1) {
        let dt = times[i + 1] - times[i];
        let speed = (tool[i + 1] - tool[i]).norm() / dt;
        let (d, hand) = [nearest(&tool[i]), nearest(&tool[i + 1])]
            .into_iter()
            .flatten()
            .min_by(|a, b| a.0.total_cmp(&b.0))?;
        let allowed = cap(rule, d);
        if speed > allowed * (1.0 + TOOL_SPEED_TOLERANCE) {
            count += 1;
            let ratio = speed / allowed.max(f64::MIN_POSITIVE);
            if worst.as_ref().is_none_or(|w| ratio > w.0) {
                let message = format!(
                    "the tool moves at {speed:.4} m/s between t = {:.3} s and {:.3} s (samples {i}-{}), {d:.3} m from {hand}: the speed-and-separation cap there is {allowed:.4} m/s",
                    times[i],
                    times[i + 1],
                    i + 1
                );
                worst = Some((ratio, message));
            }
        }
    }
    worst.map(|(_, m)| match count {
        1 => m,
        n => format!("{m} ({n} intervals in all)"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cap meets the protective distance exactly where it binds.
    #[test]
    fn cap_meets_the_protective_distance() {
        let rule = SeparationSettings {
            reduced_speed_distance_m: 0.0,
            min_tool_speed_m_s: 0.0,
            ..SeparationSettings::default()
        };
        for d in [0.3, 0.45, 0.8, 1.5] {
            let v = cap(&rule, d);
            let v_h = if d > rule.human_speed_far_beyond_m {
                1.6
            } else {
                2.0
            };
            let s_p = v_h * (0.1 + v / 2.0) + v * 0.1 + v * v / 4.0 + 0.08;
            assert!(
                v > 0.0 && (s_p - d).abs() < 1e-12,
                "d = {d}: v = {v}, S_p = {s_p}"
            );
        }
        assert_eq!(cap(&rule, 0.1), 0.0);
        assert_eq!(cap(&SeparationSettings::default(), 0.1), 0.05);
    }

    /// Written independently, the same numbers as the planner's rule.
    #[test]
    fn cap_agrees_with_the_planners_rule() {
        let rule = SeparationSettings::default();
        for k in 0..200 {
            let d = k as f64 * 0.01;
            assert!(
                (cap(&rule, d) - rule.tool_speed_cap(d)).abs() < 1e-12,
                "d = {d}"
            );
        }
    }
}
