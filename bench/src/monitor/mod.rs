//! `afford bench monitor`: the valid-policy detector on seeded planned
//! scenes in pairs — a KUKA iiwa 14 at a 1.28 × 0.96 m table seen at 2 mm
//! per pixel, a Care-O-bot 4 at a 0.64 × 0.48 m one at 1 mm per pixel; one
//! blue square, one red square, a box, "put all the blue squares in the
//! left box" — perturbed at several points of the execution: the kinds
//! below, and the adversarial ones of [`super::adversary`] (tall and
//! flickering hands ahead of the tool, jitter). Each
//! perturbation is relevant or irrelevant **by construction** — from the
//! geometry of the plan ahead, never by asking the monitor:
//!
//! | kind | relevant | built as |
//! |---|---|---|
//! | `goal_moved` | yes | the box shifted by its width (or length) plus 10 px, so the planned release footprint lies outside it, [`REACH_M`] from every tool position so far |
//! | `hand_on_route` | yes | a hand on a cell the policy still visits, three or more cells ahead, a cell clear of the other pieces' perimeters and of the goal boxes |
//! | `blocker_on_route` | yes | a new object on such a cell |
//! | `new_piece` | yes | a new blue square (the instruction says "all") |
//! | `piece_moved_away` | no | the red square moved where its box, grown by its margin and one cell, misses every cell still visited and lies [`REACH_M`] + margin from every remaining tool position |
//! | `hand_far_away` | no | a hand placed likewise with the hand margin, and where the tool-speed cap of every remaining sample ([`afford_planner::timing::SeparationSettings::tool_speed_cap`]) exceeds its planned speed with the monitor's tolerance |
//!
//! A relevant perturbation is detected when the verdict is anything but
//! `Continue` or `Slow`; an irrelevant one is a false trigger when it is
//! anything but `Continue`. Times: the decision (wall clock, the replan
//! left out) and the replan of each `Replan`.
//!
//! Re-check (when the caller gives one, [`Recheck`]): every perturbed
//! execution then runs on to its end — a hand is withdrawn a second after
//! it came, so a wait resumes — and its executed timeline goes through the
//! independent check, the physical replay and the hand check (every hand
//! the detector delivered against every body, every stop against its
//! stopping term); `check_failures` and `physics_failures` count the
//! executions each flags (a hand contact or perimeter entry counts as a
//! physics failure), `people` reports per kind.

mod kinds;
mod tally;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use crate::adversary;
use afford_planner::monitor::Monitor;
use afford_planner::plan::PlanOptions;
use kinds::scene;
use tally::Tally;

pub(crate) use kinds::apart;

/// The robot of the first scene of each pair; the second is the
/// Care-O-bot's ([`super::adversary::scene_cob4`]).
pub const ROBOT: &str = "kuka_iiwa14";

/// What to run.
#[derive(Debug, Clone, PartialEq)]
pub struct MonitorBenchConfig {
    /// Planned scenes tried (scenes that do not plan are skipped).
    pub scenes: usize,
    pub seed: u64,
    /// Run only this scene pair (`0..scenes` otherwise).
    pub only: Option<usize>,
}

impl Default for MonitorBenchConfig {
    fn default() -> Self {
        Self {
            scenes: 20,
            seed: 1,
            only: None,
        }
    }
}

/// The report (`--json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MonitorBenchReport {
    pub relevant: usize,
    pub detected: usize,
    pub irrelevant: usize,
    pub false_triggers: usize,
    pub median_observe_us: f64,
    pub median_replan_ms: f64,
    /// Perturbed executions run to their end and re-checked; `null`: no
    /// re-check given.
    pub physics_runs: Option<usize>,
    /// Of those, the executions that aborted inside a sub-goal: their
    /// sub-goal cut short was re-checked as far as it went.
    pub cut_short_runs: Option<usize>,
    /// Of those, the executions the independent check flags.
    pub check_failures: Option<usize>,
    /// Each execution the check flags (scene, kind, moment), its violations.
    pub check_findings: Vec<String>,
    /// Of those, the executions the physical replay flags; `null`: no
    /// replay given.
    pub physics_failures: Option<usize>,
    /// Each flagged execution (scene, kind, moment) with the replay's
    /// findings.
    pub physics_findings: Vec<String>,
    /// Perturbations per kind: `[count, triggered]`.
    pub kinds: std::collections::BTreeMap<&'static str, [usize; 2]>,
    /// Per kind, what the re-check measured near people.
    pub people: std::collections::BTreeMap<&'static str, KindSafety>,
    /// Executions per robot model.
    pub executions_by_robot: std::collections::BTreeMap<String, usize>,
    /// Executions that panicked (each caught and counted).
    pub panics: usize,
}

/// What the re-check measured over the executions of one kind.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct KindSafety {
    pub executions: usize,
    /// Executions with a body or the held piece touching a seen hand.
    pub hand_contacts: usize,
    /// Executions with a body entering a seen hand's perimeter from where
    /// a stop could have kept out.
    pub perimeter_entries: usize,
    /// Stops measured, and the largest travel over its stopping term.
    pub stops: usize,
    pub largest_stop_ratio: f64,
    /// The longest stop travel, m.
    pub longest_stop_m: f64,
    /// Executions the monitor completed although a re-check failed.
    pub wrong_outcomes: usize,
}

/// Points of the execution perturbed, as fractions of the trajectory up to
/// the gripper's open command.
pub(crate) const MOMENTS: [f64; 4] = [0.2, 0.45, 0.7, 0.9];

/// Re-checks an executed run ([`Monitor::executed`]): the independent
/// check's violations and the physical replay's findings, one sentence
/// each. The caller gives it (the facade passes afford-check's; the
/// planner does not depend on its checker).
pub type Recheck<'a> = &'a dyn Fn(&Monitor) -> Rechecked;

/// What [`Recheck`] found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Rechecked {
    pub violations: Vec<String>,
    pub physics: Vec<String>,
    /// The hand check: contacts and perimeter entries, one line each.
    pub hand_contacts: Vec<String>,
    pub perimeter_entries: Vec<String>,
    /// Each measured stop: `(travel, stopping term)`, m.
    pub stops: Vec<(f64, f64)>,
}

/// Runs the benchmark; `progress(done)` after each scene; `physics`
/// re-checks each perturbed execution run to its end.
pub fn run(
    config: &MonitorBenchConfig,
    mut progress: impl FnMut(usize),
    physics: Option<Recheck>,
) -> MonitorBenchReport {
    let options = PlanOptions::default();
    let mut tally = Tally::new(physics);
    let pairs = match config.only {
        Some(k) => k..k + 1,
        None => 0..config.scenes,
    };
    for (done, k) in pairs.enumerate() {
        let mut rng =
            ChaCha8Rng::seed_from_u64(config.seed ^ (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
        let kuka = scene(&mut rng, k);
        tally.scene(&kuka, &options, &mut rng);
        let mut rng = ChaCha8Rng::seed_from_u64(!config.seed ^ (k as u64).wrapping_mul(0x9E37));
        let cob4 = adversary::scene_cob4(&mut rng, k);
        tally.scene(&cob4, &options, &mut rng);
        progress(done + 1);
    }
    tally.report()
}
