//! Near people, slower: a speed-and-separation rule after ISO/TS 15066
//! (building on ISO 13855) that caps the **tool** speed at each path point
//! by the distance from the tool to the nearest hand.
//!
//! The protective separation distance for a tool speed `v_r` (m/s) is
//!
//! ```text
//! S_p(v_r) = S_h + S_r + S_s + C + Z_d + Z_r
//!   S_h = v_h (T_r + T_s)         the person moves while the robot reacts and stops
//!   S_r = v_r T_r                 the robot moves before it starts stopping
//!   S_s = v_r² / (2 a_s)          braking distance at deceleration a_s
//!   T_s = v_r / a_s               stopping time
//! ```
//!
//! The allowed tool speed at hand distance `d` is the largest `v_r` with
//! `S_p(v_r) ≤ d`, the positive root of
//! `v_r²/(2a_s) + v_r (T_r + v_h/a_s) + (v_h T_r + C + Z_d + Z_r − d) = 0`.
//! Inside [`SeparationSettings::reduced_speed_distance_m`] of a hand the cap
//! is further limited to the collaborative reduced speed (0.25 m/s, ISO
//! 10218-1). Where the formula asks for a stop (`d ≤ S_p(0)`) a plan cannot
//! stop and go on: the tool crawls at [`SeparationSettings::min_tool_speed_m_s`]
//! (the protective stop itself is the runtime monitor's job), or, with that
//! floor set to 0, the path is refused with
//! [`TimingError::InsideProtectiveDistance`](super::TimingError::InsideProtectiveDistance).
//!
//! Distances are from the tool point to the surface of a [`Hand`] sphere
//! (centre and radius in the robot base frame, metres).

use serde::{Deserialize, Serialize};

use super::TimingError;

/// A hand seen by the camera, as a sphere enclosing it (robot base frame).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hand {
    /// Centre, metres.
    pub centre: [f64; 3],
    /// Radius enclosing the hand's detected extent, metres (≥ 0).
    pub radius: f64,
}

impl Hand {
    /// Distance from `point` to the sphere's surface, 0 inside it.
    pub fn distance(&self, point: [f64; 3]) -> f64 {
        let d2: f64 = (0..3).map(|k| (point[k] - self.centre[k]).powi(2)).sum();
        (d2.sqrt() - self.radius).max(0.0)
    }
}

/// Speed-and-separation parameters. Every default is written here once and
/// cites its source; meant for a scenario's `safety` section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SeparationSettings {
    /// `v_h` within [`human_speed_far_beyond_m`](Self::human_speed_far_beyond_m)
    /// of the robot: hand/arm approach speed, 2.0 m/s (ISO 13855 §6.2.3).
    pub human_speed_m_s: f64,
    /// `v_h` beyond that distance: body approach speed, 1.6 m/s (ISO 13855).
    pub human_speed_far_m_s: f64,
    /// Separation above which the 1.6 m/s body speed may be used, 0.5 m (ISO 13855).
    pub human_speed_far_beyond_m: f64,
    /// `T_r`: time from the hand moving to the robot starting to stop: camera
    /// frame, detection and controller cycle, 0.1 s (assumed; measure yours).
    pub reaction_time_s: f64,
    /// `a_s`: tool deceleration during a stop, 2.0 m/s², a conservative value
    /// for a 7-DoF arm (use the robot's stopping data, ISO 10218-1 Annex B).
    pub stop_deceleration_m_s2: f64,
    /// `C`: how far a hand reaches past its tracked sphere (fingers past the
    /// detected box), 0.05 m (assumed; ISO 13855 §8 defines C for sensors).
    pub intrusion_distance_m: f64,
    /// `Z_d`: hand position uncertainty of the overhead camera, 0.02 m
    /// (≈ 0.8 mm/px × a few pixels + calibration; assumed).
    pub sensing_uncertainty_m: f64,
    /// `Z_r`: robot position uncertainty, 0.01 m (assumed).
    pub robot_uncertainty_m: f64,
    /// Collaborative reduced tool speed, 0.25 m/s (ISO 10218-1 §5.6).
    pub reduced_speed_m_s: f64,
    /// Inside this distance of a hand the tool moves at most at
    /// [`reduced_speed_m_s`](Self::reduced_speed_m_s): 0.5 m, the zone where
    /// ISO 13855 counts with the 2.0 m/s hand speed.
    pub reduced_speed_distance_m: f64,
    /// Crawl speed where the formula asks for a stop, 0.05 m/s (afford's
    /// choice). 0 refuses such paths instead.
    pub min_tool_speed_m_s: f64,
}

impl Default for SeparationSettings {
    fn default() -> Self {
        Self {
            human_speed_m_s: 2.0,
            human_speed_far_m_s: 1.6,
            human_speed_far_beyond_m: 0.5,
            reaction_time_s: 0.1,
            stop_deceleration_m_s2: 2.0,
            intrusion_distance_m: 0.05,
            sensing_uncertainty_m: 0.02,
            robot_uncertainty_m: 0.01,
            reduced_speed_m_s: 0.25,
            reduced_speed_distance_m: 0.5,
            min_tool_speed_m_s: 0.05,
        }
    }
}

impl SeparationSettings {
    /// Checks every field is finite and in range.
    pub fn validate(&self) -> Result<(), TimingError> {
        let positive = [
            ("human_speed_m_s", self.human_speed_m_s),
            ("human_speed_far_m_s", self.human_speed_far_m_s),
            ("stop_deceleration_m_s2", self.stop_deceleration_m_s2),
            ("reduced_speed_m_s", self.reduced_speed_m_s),
        ];
        let non_negative = [
            ("human_speed_far_beyond_m", self.human_speed_far_beyond_m),
            ("reaction_time_s", self.reaction_time_s),
            ("intrusion_distance_m", self.intrusion_distance_m),
            ("sensing_uncertainty_m", self.sensing_uncertainty_m),
            ("robot_uncertainty_m", self.robot_uncertainty_m),
            ("reduced_speed_distance_m", self.reduced_speed_distance_m),
            ("min_tool_speed_m_s", self.min_tool_speed_m_s),
        ];
        for (field, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(TimingError::Setting {
                    field,
                    value,
                    expected: "finite and > 0",
                });
            }
        }
        for (field, value) in non_negative {
            if !(value.is_finite() && value >= 0.0) {
                return Err(TimingError::Setting {
                    field,
                    value,
                    expected: "finite and ≥ 0",
                });
            }
        }
        if self.min_tool_speed_m_s > self.reduced_speed_m_s {
            return Err(TimingError::Setting {
                field: "min_tool_speed_m_s",
                value: self.min_tool_speed_m_s,
                expected: "≤ reduced_speed_m_s",
            });
        }
        Ok(())
    }

    /// `S_p(0)`: the distance below which the formula asks for a stop, with
    /// the human speed that applies at distance `d`.
    pub fn stop_distance(&self, d: f64) -> f64 {
        self.human_speed_at(d) * self.reaction_time_s + self.constant_terms()
    }

    /// Protective separation distance `S_p` for tool speed `v_r` (m/s) when the
    /// person moves at the speed that applies at distance `d`.
    pub fn protective_distance(&self, v_r: f64, d: f64) -> f64 {
        let v_h = self.human_speed_at(d);
        let t_s = v_r / self.stop_deceleration_m_s2;
        v_h * (self.reaction_time_s + t_s)
            + v_r * self.reaction_time_s
            + v_r * v_r / (2.0 * self.stop_deceleration_m_s2)
            + self.constant_terms()
    }

    /// Largest tool speed `v_r ≥ 0` with `S_p(v_r) ≤ d`, before the reduced
    /// speed and the crawl floor.
    pub fn formula_speed(&self, d: f64) -> f64 {
        let a_s = self.stop_deceleration_m_s2;
        let v_h = self.human_speed_at(d);
        let qa = 1.0 / (2.0 * a_s);
        let qb = self.reaction_time_s + v_h / a_s;
        let qc = self.stop_distance(d) - d;
        if qc >= 0.0 {
            return 0.0;
        }
        // Positive root, in the cancellation-free form 2c / (−b − √(b² − 4ac)).
        let disc = qb * qb - 4.0 * qa * qc;
        2.0 * qc / (-qb - disc.sqrt())
    }

    /// The tool-speed cap (m/s) at hand distance `d` (m): the formula speed,
    /// at most the reduced speed inside the reduced-speed distance, at least
    /// the crawl floor. 0 means the path must be refused. Far from every hand
    /// the formula speed grows like `√(2 a_s d)` and rarely binds.
    pub fn tool_speed_cap(&self, d: f64) -> f64 {
        let mut cap = self.formula_speed(d);
        if d <= self.reduced_speed_distance_m {
            cap = cap.min(self.reduced_speed_m_s);
        }
        cap.max(self.min_tool_speed_m_s)
    }

    fn human_speed_at(&self, d: f64) -> f64 {
        if d > self.human_speed_far_beyond_m {
            self.human_speed_far_m_s
        } else {
            self.human_speed_m_s
        }
    }

    fn constant_terms(&self) -> f64 {
        self.intrusion_distance_m + self.sensing_uncertainty_m + self.robot_uncertainty_m
    }
}

/// Distance from `point` to the nearest hand (∞ with no hands).
pub fn nearest_hand_distance(hands: &[Hand], point: [f64; 3]) -> f64 {
    hands
        .iter()
        .map(|h| h.distance(point))
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formula_speed_meets_the_distance() {
        let s = SeparationSettings::default();
        for d in [0.3, 0.4, 0.5, 0.8, 1.5] {
            let v = s.formula_speed(d);
            assert!(v > 0.0);
            assert!((s.protective_distance(v, d) - d).abs() < 1e-12, "d={d}");
        }
        assert_eq!(s.formula_speed(0.1), 0.0);
        assert_eq!(s.tool_speed_cap(0.1), 0.05);
        assert!(s.tool_speed_cap(0.45) <= 0.25);
    }
}
