//! How the monitor reads a real detector's observations
//! (`safety.detection`): a hand that was seen counts as present for a hold
//! time after it was last seen (detectors drop frames; a hand that flickers
//! in and out of view is one hand that stays), and a target or goal box
//! that moved less than a tolerance did not move (detectors jitter by a
//! pixel or two from frame to frame).
//!
//! The tolerance is a distance on the table, metres, between the box the
//! plan was made for and the box seen now (the largest shift of an edge):
//! the grasp stays valid while the piece lies within the open fingers'
//! slack, so the tolerance used is the smaller of the setting and half the
//! grasp's slack (the open fingers' half-width less the piece's half-width
//! across them).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::scenario::{Hand, PixelBox};

/// Defaults: hold a hand 0.5 s after it was last seen, ignore box
/// shifts of up to 5 mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DetectionSettings {
    /// How long a hand counts as present after it was last seen, s: five
    /// frames of a 10 Hz detector, fifteen of a 30 Hz one. Resuming after
    /// a hand needs the way to have been clear this long.
    pub hand_hold_s: f64,
    /// Box shifts up to this distance on the table are detector noise,
    /// not a move, m (at most half the grasp's slack is used).
    pub position_tolerance_m: f64,
}

impl Default for DetectionSettings {
    fn default() -> Self {
        Self {
            hand_hold_s: 0.5,
            position_tolerance_m: 0.005,
        }
    }
}

/// Largest hold a scenario may ask for, s.
pub const MAX_HAND_HOLD_S: f64 = 10.0;
/// Largest tolerance a scenario may ask for, m.
pub const MAX_POSITION_TOLERANCE_M: f64 = 0.05;

impl DetectionSettings {
    /// The fields out of range: (field, what is wrong).
    pub fn problems(&self) -> Vec<(&'static str, String)> {
        let mut out = Vec::new();
        if !(self.hand_hold_s.is_finite() && (0.0..=MAX_HAND_HOLD_S).contains(&self.hand_hold_s)) {
            out.push((
                "hand_hold_s",
                format!(
                    "must be between 0 and {MAX_HAND_HOLD_S} s, got {:?}",
                    self.hand_hold_s
                ),
            ));
        }
        let t = self.position_tolerance_m;
        if !(t.is_finite() && (0.0..=MAX_POSITION_TOLERANCE_M).contains(&t)) {
            out.push((
                "position_tolerance_m",
                format!("must be between 0 and {MAX_POSITION_TOLERANCE_M} m, got {t:?}"),
            ));
        }
        out
    }
}

/// The hands the detector lists now, and those it dropped within the
/// hold (each with the time it was first missed).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct HandMemory {
    detected: Vec<Hand>,
    dropped: BTreeMap<String, (Hand, f64)>,
}

impl HandMemory {
    /// The detector's hands at `t`: `Some(list)` from an observation that
    /// lists them (replacing the list), `None` from a frame that saw the
    /// same hands. Returns the hands to believe in: the ones listed now,
    /// then the ones missing for less than `hold` s (where they were last
    /// seen), in name order.
    pub fn update(&mut self, listed: Option<&[Hand]>, t: f64, hold: f64) -> Vec<Hand> {
        if let Some(list) = listed {
            for h in &self.detected {
                if !list.iter().any(|l| l.name == h.name) {
                    self.dropped.insert(h.name.clone(), (h.clone(), t));
                }
            }
            self.dropped
                .retain(|name, _| !list.iter().any(|l| &l.name == name));
            self.detected = list.to_vec();
        }
        self.dropped
            .retain(|_, (_, since)| t - *since < hold - 1e-9);
        let mut out = self.detected.clone();
        out.extend(self.dropped.values().map(|(h, _)| h.clone()));
        out
    }

    /// When the next dropped hand stops counting, s.
    pub fn next_expiry(&self, hold: f64) -> Option<f64> {
        self.dropped
            .values()
            .map(|(_, since)| since + hold)
            .min_by(f64::total_cmp)
    }
}

/// `a` and `b` differ by more than `tolerance` metres on the table at any
/// edge (a move or a change of size); `[mu, mv]` metres per pixel.
pub fn moved_beyond([mu, mv]: [f64; 2], a: PixelBox, b: PixelBox, tolerance: f64) -> bool {
    let edges = |p: PixelBox| [p.u, p.v, p.u + p.w, p.v + p.l];
    let (ea, eb) = (edges(a), edges(b));
    let scale = [mu, mv, mu, mv];
    (0..4).any(|i| ((ea[i] - eb[i]) * scale[i]).abs() > tolerance + 1e-12)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hand(name: &str) -> Hand {
        Hand {
            name: name.into(),
            bbox: PixelBox {
                u: 100.0,
                v: 100.0,
                w: 40.0,
                l: 40.0,
            },
            height: 0.08,
        }
    }

    #[test]
    fn a_hand_dropped_by_the_detector_for_less_than_the_hold_stays_present() {
        let mut memory = HandMemory::default();
        assert_eq!(memory.update(Some(&[hand("h")]), 3.3, 0.5).len(), 1);
        assert_eq!(memory.update(Some(&[]), 3.4, 0.5), vec![hand("h")]);
        assert_eq!(memory.update(None, 3.89, 0.5), vec![hand("h")]);
        assert_eq!(memory.next_expiry(0.5), Some(3.9));
        assert!(memory.update(None, 3.9, 0.5).is_empty());
        assert_eq!(memory.next_expiry(0.5), None);
    }

    #[test]
    fn a_hand_seen_again_within_the_hold_restarts_it() {
        let mut memory = HandMemory::default();
        memory.update(Some(&[hand("h")]), 1.0, 0.5);
        memory.update(Some(&[]), 1.1, 0.5);
        memory.update(Some(&[hand("h")]), 1.2, 0.5);
        assert_eq!(memory.next_expiry(0.5), None);
        memory.update(Some(&[]), 1.3, 0.5);
        assert_eq!(memory.update(None, 1.75, 0.5).len(), 1);
    }

    #[test]
    fn a_hand_listed_once_stays_until_a_list_leaves_it_out() {
        let mut memory = HandMemory::default();
        memory.update(Some(&[hand("h")]), 3.0, 0.5);
        assert_eq!(memory.update(None, 6.9, 0.5), vec![hand("h")]);
    }

    #[test]
    fn a_hold_of_zero_believes_the_detector_frame_by_frame() {
        let mut memory = HandMemory::default();
        memory.update(Some(&[hand("h")]), 1.0, 0.0);
        assert!(memory.update(Some(&[]), 1.0, 0.0).is_empty());
    }
}
