//! The hands of an executed run: what the detector delivered over time
//! ([`presence`]) against every robot body and the held object, sample by
//! sample ([`check_hands`]). A hand is present from a sighting to the next
//! hand list without it, and across a dropout shorter than the scenario's
//! hold time (`safety.detection.hand_hold_s`): a detector that loses a hand
//! for a frame does not mean the person withdrew it. While a hand is
//! present no body may touch it (`hand_contact`) nor come from outside its
//! perimeter (`safety.hand_margin`) into it (`perimeter_entry`). "Outside"
//! is what a stop can keep: when the hand comes, the body lies farther
//! than the perimeter plus the stopping term of the tool's speed then
//! (`v·T_r + v²/(2·a_s)`, the distance the separation rule lets a stop
//! take, [`crate::stops`]). A body nearer when the hand came (the person
//! reached in closer than any stop can answer) must still not touch it.
//!
//! Shares no code with the monitor: the presence rule is this module's own
//! reading of the raw hand lists, forward kinematics is k's, distances are
//! parry's over the dense check's 1 mm steps ([`crate::dense`]).

use afford_kinematics::RobotModel;
use afford_planner::scenario::{Hand, PixelBox, Scenario};

use crate::bodies::{Body, body, robot_bodies};
use crate::chain::{Iso, Kinematics, to_parry};
use crate::dense::{Findings, Other, Pair, Phase, describe};
use crate::file::PlanFile;
use crate::format;
use crate::report::ViolationClass;
use crate::scene::{Footprint, Obstacle, Role, pieces, signed_distance};
use crate::stops::stopping_term;

/// One hand present over `[from, until)` (run time, s) with one box.
#[derive(Debug, Clone, PartialEq)]
pub struct Presence {
    pub hand: Hand,
    pub from: f64,
    pub until: f64,
}

/// Which hands were there when: from `sightings` (`(time, hands)`, the
/// hand lists delivered, in time order), a dropout shorter than `hold_s`
/// bridged. A hand that moved starts a new presence at its new box.
pub fn presence(sightings: &[(f64, Vec<Hand>)], hold_s: f64) -> Vec<Presence> {
    let mut out: Vec<Presence> = Vec::new();
    let mut open: Vec<usize> = Vec::new();
    for (t, hands) in sightings {
        open.retain(|&i| {
            let keep = hands.iter().any(|h| same(h, &out[i].hand));
            if !keep {
                out[i].until = *t;
            }
            keep
        });
        for h in hands {
            if open.iter().any(|&i| same(h, &out[i].hand)) {
                continue;
            }
            let bridged = out
                .iter()
                .rposition(|p| same(h, &p.hand) && *t - p.until < hold_s);
            match bridged {
                Some(i) => {
                    out[i].until = f64::INFINITY;
                    open.push(i);
                }
                None => {
                    out.push(Presence {
                        hand: h.clone(),
                        from: *t,
                        until: f64::INFINITY,
                    });
                    open.push(out.len() - 1);
                }
            }
        }
    }
    out
}

/// The same hand at the same place.
fn same(a: &Hand, b: &Hand) -> bool {
    let key = |h: &Hand| {
        let PixelBox { u, v, w, l } = h.bbox;
        [u, v, w, l, h.height].map(f64::to_bits)
    };
    a.name == b.name && key(a) == key(b)
}

/// What [`check_hands`] found: one sentence per (body, hand) pair.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct HandReport {
    pub contacts: Vec<String>,
    pub perimeter_entries: Vec<String>,
}

impl HandReport {
    pub fn passed(&self) -> bool {
        self.contacts.is_empty() && self.perimeter_entries.is_empty()
    }

    /// Adds `other`'s findings.
    pub fn extend(&mut self, other: HandReport) {
        self.contacts.extend(other.contacts);
        self.perimeter_entries.extend(other.perimeter_entries);
    }
}

/// Checks the one sub-goal of `plan` (an executed sub-goal, begun at run
/// time `start_time` in `scene`: the scene's hands are ignored, the
/// present ones come from `hands`) against every hand while present. A
/// sub-goal the check cannot read is left to [`crate::check_plan`].
pub fn check_hands(
    scene: &Scenario,
    robot: &RobotModel,
    plan: &PlanFile,
    start_time: f64,
    hands: &[Presence],
) -> HandReport {
    let mut report = HandReport::default();
    let (Some(sub), Ok(kin)) = (plan.subgoals.first(), Kinematics::new(robot)) else {
        return report;
    };
    let (Ok(checked), Ok(events)) = (format::check(scene, robot, sub), format::events(sub)) else {
        return report;
    };
    let Ok(q0) = crate::start::state(robot, plan.start_state.as_ref()) else {
        return report;
    };
    let arm = checked.arm;
    let points = &sub.trajectory.points;
    let times: Vec<f64> = points
        .iter()
        .map(|p| start_time + p.time_from_start)
        .collect();
    let positions: Vec<&[f64]> = points.iter().map(|p| p.positions.as_slice()).collect();
    let Ok(bodies) = robot_bodies(robot, &kin) else {
        return report;
    };
    let tool_link = robot.link_index(&arm.tool_link).unwrap_or(0);
    let whole = |k: usize| {
        let mut q = q0.clone();
        arm.joint_indices
            .iter()
            .zip(positions[k])
            .for_each(|(&j, &v)| q[j] = v);
        q
    };
    let piece = &pieces(scene)[checked.target];
    let held = events.close.map(|c| {
        let rel = kin.link_poses(&whole(c.sample))[tool_link].inverse() * piece.pose;
        let name = format!("held {}", piece.name);
        body(robot, &kin, name, tool_link, piece.shape(), rel)
    });
    let holding: Vec<Body> = bodies.iter().cloned().chain(held).collect();
    let n = points.len();
    let (c, o) = (
        events.close.map_or(n, |e| e.sample),
        events.open.map_or(n, |e| e.sample),
    );
    let speeds: Vec<f64> = (arm.joint_indices.iter())
        .map(|&j| robot.joints()[j].velocity)
        .collect();
    let mut findings = Findings::new();
    for (from, to) in windows(hands, &times) {
        let present: Vec<&Presence> = hands
            .iter()
            .filter(|p| p.from <= times[from] + 1e-9 && p.until > times[from])
            .collect();
        if present.is_empty() {
            continue;
        }
        let obstacles: Vec<Obstacle> = present.iter().map(|p| hand_box(scene, &p.hand)).collect();
        // Split at the close and the open: the held object rides between.
        let mut cuts = vec![from];
        cuts.extend([c, o].into_iter().filter(|&s| s > from && s < to));
        cuts.push(to);
        for part in cuts.windows(2) {
            let (a, b) = (part[0], part[1]);
            let bodies = match a >= c && a < o {
                true => &holding,
                false => &bodies,
            };
            let rest = whole(a);
            let poses = kin.link_poses(&rest);
            let next = kin.link_poses(&whole((a + 1).min(n - 1)))[tool_link];
            let dt = times[(a + 1).min(n - 1)] - times[a];
            let step = (next.translation.vector - poses[tool_link].translation.vector).norm();
            let speed = if dt > 0.0 { step / dt } else { 0.0 };
            let reach = scene.safety.hand_margin + stopping_term(scene, speed);
            let margin = scene.safety.hand_margin;
            let pairs = pairs_from_outside(bodies, &obstacles, &poses, margin, reach);
            let phase = Phase {
                kin: &kin,
                bodies,
                obstacles: &obstacles,
                pairs,
                rest: &rest,
                arm: &arm.joint_indices,
                speeds: &speeds,
                positions: &positions[a..=b],
                times: &times[a..=b],
                first_sample: a,
            };
            phase.run(&mut findings);
        }
    }
    for (key, f) in &findings {
        let line = describe(key, f);
        match key.0 {
            ViolationClass::Penetration => report.contacts.push(line),
            _ => report.perimeter_entries.push(line),
        }
    }
    report
}

/// Sample ranges `(from, to)` over which the set of present hands is one:
/// cut where a hand comes or goes, each range running on to the sample
/// after its end (the motion up to it happened while the hand was there).
fn windows(hands: &[Presence], times: &[f64]) -> Vec<(usize, usize)> {
    let last = times.len() - 1;
    let mut cuts: Vec<usize> = hands
        .iter()
        .flat_map(|p| [p.from, p.until])
        .filter(|t| t.is_finite())
        .map(|t| times.partition_point(|&s| s < t - 1e-9).min(last))
        .chain([0, last])
        .collect();
    cuts.sort_unstable();
    cuts.dedup();
    cuts.windows(2).map(|w| (w[0], w[1])).collect()
}

/// A hand as a solid box on the table, its perimeter the hand margin.
fn hand_box(scene: &Scenario, h: &Hand) -> Obstacle {
    let f = Footprint::of(scene, h.bbox);
    let half = [0.5 * f.size[0], 0.5 * f.size[1], 0.5 * h.height];
    Obstacle::solid(
        &h.name,
        scene.safety.hand_margin,
        &f.pose(scene.camera.table_z, h.height),
        half,
    )
}

/// Every body against every hand: with the perimeter (`margin`) as margin
/// when the body lies beyond `reach` (the perimeter plus the stopping
/// term) at the window's first configuration (`links`), with none (contact
/// only) when the hand came nearer than a stop can answer.
fn pairs_from_outside(
    bodies: &[Body],
    obstacles: &[Obstacle],
    links: &[Iso],
    margin: f64,
    reach: f64,
) -> Vec<Pair> {
    let mut pairs = Vec::new();
    for (b, body) in bodies.iter().enumerate() {
        let pose = to_parry(&(links[body.link] * body.pose_link_shape));
        for (o, obstacle) in obstacles.iter().enumerate() {
            let d = (obstacle.parts.iter())
                .map(|(p, s)| signed_distance(&pose, &body.shape, p, s))
                .fold(f64::INFINITY, f64::min);
            pairs.push(Pair {
                body: b,
                other: Other::Obstacle(o),
                margin: if d >= reach { margin } else { 0.0 },
            });
        }
    }
    debug_assert!(obstacles.iter().all(|o| o.role == Role::Obstacle));
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hand(u: f64) -> Hand {
        Hand {
            name: "hand-1".into(),
            bbox: PixelBox {
                u,
                v: 10.0,
                w: 40.0,
                l: 40.0,
            },
            height: 0.08,
        }
    }

    /// A detector that loses the hand every other frame: one presence
    /// from the first sighting to the list that no longer has it for
    /// longer than the hold.
    #[test]
    fn a_flickering_hand_is_present_through_its_dropouts() {
        let mut sightings = Vec::new();
        for k in 0..10 {
            let t = 1.0 + 0.1 * k as f64;
            sightings.push((t, if k % 2 == 0 { vec![hand(5.0)] } else { vec![] }));
        }
        sightings.push((3.0, vec![]));
        let p = presence(&sightings, 0.5);
        assert_eq!(p.len(), 1, "{p:?}");
        assert_eq!(p[0].from, 1.0);
        assert!((p[0].until - 1.9).abs() < 1e-9, "{p:?}");
    }

    /// A dropout longer than the hold is a hand that left and came back;
    /// a hand that moved is a new presence.
    #[test]
    fn a_long_dropout_or_a_move_ends_a_presence() {
        let sightings = vec![
            (1.0, vec![hand(5.0)]),
            (1.1, vec![]),
            (2.0, vec![hand(5.0)]),
            (2.5, vec![hand(50.0)]),
        ];
        let p = presence(&sightings, 0.5);
        assert_eq!(p.len(), 3, "{p:?}");
        assert_eq!((p[0].from, p[0].until), (1.0, 1.1));
        assert_eq!((p[1].from, p[1].until), (2.0, 2.5));
        assert_eq!(p[2].until, f64::INFINITY);
    }
}
