//! Speed-and-separation monitoring at run time (ISO/TS 15066 §5.5.4 with
//! the numbers and the reading of [`crate::timing::separation`]): each
//! camera frame, the distance `d` from the tool to the nearest hand sphere
//! gives the tool-speed cap `v(d)` the timing stage plans with (the
//! protective-separation formula, the collaborative reduced speed inside
//! `reduced_speed_distance_m`, the crawl floor). When the speed the plan
//! asks for at a sample of the next [`LOOKAHEAD_S`] exceeds the cap at that
//! sample's distance, the robot slows by `scale = v(d) / v_planned` (planned speeds within [`TOLERANCE`] of the
//! cap pass: the planner's own cap is evaluated per waypoint); when the tool
//! is inside a hand's safety perimeter (its box grown by `hand_margin`,
//! the perimeter the grid and the collision check keep) or the formula
//! asks for a stop with no crawl floor, it stops (protective stop) until
//! the hand is back outside.

use crate::scenario::Scenario;
use crate::timing::Hand;
use crate::timing::separation::nearest_hand_distance;

/// How far ahead the planned tool speed is compared with the cap, seconds
/// of plan time: the reaction time of the default settings and a stop at
/// the reduced speed, rounded up.
pub const LOOKAHEAD_S: f64 = 0.5;

/// Relative excess of the planned tool speed over the cap that still
/// passes (5 %).
pub const TOLERANCE: f64 = 0.05;

/// What the separation rule asks for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Separation {
    /// The plan's speed is within the cap.
    Clear,
    /// Slow to `scale` (0–1) of the planned speed; `distance` m to the hand.
    Slow { scale: f64, distance: f64 },
    /// A hand is inside the tool's protective distance.
    Stop { distance: f64 },
}

/// The rule for the tool now at `tools[0]` (base frame, m), with the
/// positions and planned tool speeds (m/s) of the samples of the next
/// [`LOOKAHEAD_S`]: each sample's speed against the cap at its own distance
/// from the nearest hand; the scale is the smallest ratio.
pub fn rule(scene: &Scenario, hands: &[Hand], tools: &[[f64; 3]], speeds: &[f64]) -> Separation {
    let Some(&now) = tools.first().filter(|_| !hands.is_empty()) else {
        return Separation::Clear;
    };
    let settings = &scene.safety.separation;
    let distance = nearest_hand_distance(hands, now);
    if inside_perimeter(scene, now) {
        return Separation::Stop { distance };
    }
    let mut scale: f64 = 1.0;
    for (tool, &planned) in tools.iter().zip(speeds) {
        let cap = settings.tool_speed_cap(nearest_hand_distance(hands, *tool));
        if cap <= 0.0 {
            return Separation::Stop { distance };
        }
        if planned > cap * (1.0 + TOLERANCE) {
            scale = scale.min(cap / planned);
        }
    }
    match scale < 1.0 {
        true => Separation::Slow { scale, distance },
        false => Separation::Clear,
    }
}

/// The tool is inside a hand's safety perimeter: over its box grown by
/// `hand_margin` and below its top plus `hand_margin`.
fn inside_perimeter(scene: &Scenario, tool: [f64; 3]) -> bool {
    let [mu, mv] = scene.metres_per_pixel();
    let margin = scene.safety.hand_margin;
    let pixel = scene.base_to_pixel([tool[0], tool[1]]);
    scene.hands.iter().any(|h| {
        h.bbox.grown(margin / mu, margin / mv).contains(pixel)
            && tool[2] <= scene.camera.table_z + h.height + margin
    })
}
