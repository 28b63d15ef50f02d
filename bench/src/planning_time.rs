//! Planning time of the safety campaign: wall seconds per sub-goal (every
//! attempt at it, from the planner's own per-sub-goal clock) and per scene
//! (the whole `plan` call), as median, 99th percentile and maximum per
//! robot. Wall-clock figures: the only part of the campaign's report that
//! differs from run to run (scenes run in parallel on every core).

use std::collections::BTreeMap;

use serde::Serialize;

/// Median, 99th percentile (nearest rank) and maximum of a set of times, s.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct TimeStats {
    pub count: usize,
    pub median_s: f64,
    pub p99_s: f64,
    pub max_s: f64,
}

impl TimeStats {
    /// The statistics of `times` (seconds); all zero when there are none.
    pub fn of(times: &[f64]) -> Self {
        let mut sorted = times.to_vec();
        sorted.sort_by(f64::total_cmp);
        let rank = |q: f64| {
            let n = sorted.len();
            sorted[((q * n as f64).ceil() as usize).clamp(1, n) - 1]
        };
        match sorted.last() {
            None => Self::default(),
            Some(&max_s) => Self {
                count: sorted.len(),
                median_s: rank(0.5),
                p99_s: rank(0.99),
                max_s,
            },
        }
    }
}

/// The planning times of a set of scenes.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct PlanningTimes {
    pub subgoal: TimeStats,
    pub scene: TimeStats,
}

/// Per robot and in total (`"total"`), from `(robot, sub-goal times, scene
/// time)` per scene.
pub fn planning_times<'a>(
    scenes: impl Iterator<Item = (&'a str, &'a [f64], f64)>,
) -> BTreeMap<String, PlanningTimes> {
    let mut gathered: BTreeMap<String, (Vec<f64>, Vec<f64>)> = BTreeMap::new();
    for (robot, subgoals, scene) in scenes {
        for key in [robot, "total"] {
            let (s, w) = gathered.entry(key.to_string()).or_default();
            s.extend_from_slice(subgoals);
            w.push(scene);
        }
    }
    gathered
        .into_iter()
        .map(|(robot, (s, w))| {
            let times = PlanningTimes {
                subgoal: TimeStats::of(&s),
                scene: TimeStats::of(&w),
            };
            (robot, times)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_are_nearest_rank() {
        let times: Vec<f64> = (1..=200).map(f64::from).collect();
        let s = TimeStats::of(&times);
        assert_eq!(
            (s.count, s.median_s, s.p99_s, s.max_s),
            (200, 100.0, 198.0, 200.0)
        );
        assert_eq!(TimeStats::of(&[]), TimeStats::default());
    }

    #[test]
    fn times_are_gathered_per_robot_and_in_total() {
        let a = [0.5, 1.5];
        let b = [3.0];
        let t = planning_times([("iiwa", &a[..], 2.0), ("cob", &b[..], 3.0)].into_iter());
        assert_eq!(t["iiwa"].subgoal.max_s, 1.5);
        assert_eq!(t["cob"].scene.count, 1);
        assert_eq!(t["total"].subgoal.count, 3);
        assert_eq!(t["total"].scene.max_s, 3.0);
    }
}
