//! Planning time of the safety campaign: wall seconds per sub-goal (every
//! attempt at it, from the planner's own per-sub-goal clock) and per scene
//! (the whole `plan` call), as median, 99th percentile and maximum per
//! robot, and the slowest scenes by index (to plan them again alone).
//! Wall-clock figures: the only part of the campaign's report that differs
//! from run to run (scenes run in parallel on every core).

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
    /// The [`SLOWEST`] scenes with the slowest sub-goals, slowest first.
    pub slowest: Vec<SlowScene>,
}

/// How many of the slowest scenes a report names.
pub const SLOWEST: usize = 5;

/// A scene named for its slow sub-goal.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SlowScene {
    /// The scene's index in the series.
    pub scene: usize,
    /// Its slowest sub-goal's wall seconds.
    pub subgoal_s: f64,
    /// The whole scene's wall seconds.
    pub scene_s: f64,
}

/// One scene's times: its index, robot, sub-goal times and scene time.
pub type SceneTimes<'a> = (usize, &'a str, &'a [f64], f64);

/// A robot's sub-goal times, scene times and scenes, as gathered.
type Gathered = (Vec<f64>, Vec<f64>, Vec<SlowScene>);

/// Per robot and in total (`"total"`), from each scene's times.
pub fn planning_times<'a>(
    scenes: impl Iterator<Item = SceneTimes<'a>>,
) -> BTreeMap<String, PlanningTimes> {
    let mut gathered: BTreeMap<String, Gathered> = BTreeMap::new();
    for (index, robot, subgoals, scene) in scenes {
        let slow = SlowScene {
            scene: index,
            subgoal_s: subgoals.iter().copied().fold(0.0, f64::max),
            scene_s: scene,
        };
        for key in [robot, "total"] {
            let (s, w, named) = gathered.entry(key.to_string()).or_default();
            s.extend_from_slice(subgoals);
            w.push(scene);
            named.push(slow);
        }
    }
    gathered
        .into_iter()
        .map(|(robot, (s, w, mut named))| {
            named.sort_by(|a, b| b.subgoal_s.total_cmp(&a.subgoal_s));
            named.truncate(SLOWEST);
            let times = PlanningTimes {
                subgoal: TimeStats::of(&s),
                scene: TimeStats::of(&w),
                slowest: named,
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
        let t = planning_times([(0, "iiwa", &a[..], 2.0), (1, "cob", &b[..], 3.0)].into_iter());
        assert_eq!(t["iiwa"].subgoal.max_s, 1.5);
        assert_eq!(t["total"].slowest[0].scene, 1);
        assert_eq!(t["total"].slowest[1].subgoal_s, 1.5);
        assert_eq!(t["cob"].scene.count, 1);
        assert_eq!(t["total"].subgoal.count, 3);
        assert_eq!(t["total"].scene.max_s, 3.0);
    }
}
