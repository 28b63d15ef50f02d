//! The tally of `afford bench monitor`: each case executed (detection
//! counted at its first observation), played to its end and re-checked
//! when a re-check is given, its findings counted per kind.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::kinds::{body_links, perturbations, track_of};
use super::{KindSafety, MOMENTS, MonitorBenchReport, Recheck};
use crate::adversary::{self, Case};
use crate::median;
use afford_planner::monitor::{Monitor, Status, Verdict, timeline};
use afford_planner::plan::{Plan, PlanOptions, Planner};
use afford_planner::scenario::Scenario;

#[derive(Default)]
pub(super) struct Tally<'a> {
    physics: Option<Recheck<'a>>,
    physics_runs: usize,
    cut_short_runs: usize,
    check_failures: usize,
    check_findings: Vec<String>,
    physics_failures: usize,
    physics_findings: Vec<String>,
    relevant: usize,
    detected: usize,
    irrelevant: usize,
    false_triggers: usize,
    observe_us: Vec<f64>,
    replan_ms: Vec<f64>,
    kinds: std::collections::BTreeMap<&'static str, [usize; 2]>,
    people: std::collections::BTreeMap<&'static str, KindSafety>,
    by_robot: std::collections::BTreeMap<String, usize>,
    panics: usize,
}

impl<'a> Tally<'a> {
    /// A tally with nothing counted yet; `physics` re-checks each execution.
    pub(super) fn new(physics: Option<Recheck<'a>>) -> Self {
        Self {
            physics,
            ..Self::default()
        }
    }

    /// Every perturbation of one scene, when it plans to one sub-goal: the
    /// kinds by construction at [`MOMENTS`], the adversarial ones at
    /// [`adversary::SPREAD`].
    pub(super) fn scene(&mut self, scene: &Scenario, options: &PlanOptions, rng: &mut ChaCha8Rng) {
        let Ok(plan) = Planner::new(options.clone()).plan(scene) else {
            return;
        };
        if plan.subgoals.len() != 1 {
            return;
        }
        for &moment in &MOMENTS {
            let cases = perturbations(scene, &plan, moment, rng);
            self.execute(scene, &plan, options, moment, cases);
        }
        let sub = &plan.subgoals[0];
        let track = track_of(scene, sub);
        let links = |k: usize| body_links(scene, &plan, k);
        for &moment in &adversary::SPREAD {
            let cases = adversary::cases(scene, sub, &track, &links, moment, rng.random::<u64>());
            self.execute(scene, &plan, options, moment, cases);
        }
    }

    /// Runs each case: the monitor advanced to its time, its first
    /// observation taken there (detection counted), then — when a re-check
    /// was given — the rest of its timeline played to the end of the run
    /// and the executed run re-checked. A panic is caught and counted.
    fn execute(
        &mut self,
        scene: &Scenario,
        plan: &Plan,
        options: &PlanOptions,
        moment: f64,
        cases: Vec<Case>,
    ) {
        for case in cases {
            let Ok(mut monitor) = Monitor::new(plan.clone(), scene, options) else {
                continue;
            };
            *self.by_robot.entry(scene.robot.model.clone()).or_default() += 1;
            let name = format!(
                "{}, {} at {:.0} %",
                scene.name.as_deref().unwrap_or_default(),
                case.kind,
                moment * 100.0
            );
            let ran = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                monitor.advance(case.t);
                let first = case.timeline.first().cloned().unwrap_or_default();
                let verdict = monitor.observe(&first, case.t);
                if self.physics.is_some() {
                    timeline::play(&mut monitor, &case.timeline[1..]);
                }
                (verdict, monitor)
            }));
            match ran {
                Ok((verdict, monitor)) => self.count(&case, &verdict, monitor, name),
                Err(_) => self.panics += 1,
            }
        }
    }

    /// Counts one execution: detection, then the re-check's findings.
    fn count(&mut self, case: &Case, verdict: &Verdict, monitor: Monitor, name: String) {
        let first_event = (monitor.events().iter()).find(|e| e.time + 1e-9 >= case.t);
        if let Some(e) = first_event {
            self.observe_us.push(e.decision_us);
            self.replan_ms.extend(e.replan_ms);
        }
        if let Some(relevant) = case.relevant {
            // An irrelevant perturbation triggers when any verdict of its
            // span is other than `continue` (jitter lasts a second).
            let span_end = case.timeline.last().and_then(|o| o.at).unwrap_or(case.t);
            let triggered = match relevant {
                true => !matches!(verdict, Verdict::Continue | Verdict::Slow { .. }),
                false => {
                    *verdict != Verdict::Continue
                        || (monitor.events().iter())
                            .filter(|e| e.time + 1e-9 >= case.t && e.time <= span_end + 1e-9)
                            .any(|e| e.verdict != "continue")
                }
            };
            let entry = self.kinds.entry(case.kind).or_default();
            entry[0] += 1;
            entry[1] += usize::from(triggered);
            match relevant {
                true => {
                    self.relevant += 1;
                    self.detected += usize::from(triggered);
                }
                false => {
                    self.irrelevant += 1;
                    self.false_triggers += usize::from(triggered);
                }
            }
        }
        let Some(physics) = self.physics else {
            return;
        };
        self.physics_runs += 1;
        self.cut_short_runs += usize::from(monitor.executed().iter().any(|e| e.cut_short));
        let found = physics(&monitor);
        let completed = *monitor.status() == Status::Completed;
        let people = self.people.entry(case.kind).or_default();
        people.executions += 1;
        people.hand_contacts += usize::from(!found.hand_contacts.is_empty());
        people.perimeter_entries += usize::from(!found.perimeter_entries.is_empty());
        people.stops += found.stops.len();
        for &(travel, term) in &found.stops {
            if term > 0.0 {
                people.largest_stop_ratio = people.largest_stop_ratio.max(travel / term);
            }
            people.longest_stop_m = people.longest_stop_m.max(travel);
        }
        let near = (found.hand_contacts.iter()).chain(&found.perimeter_entries);
        let failed = !found.violations.is_empty() || !found.physics.is_empty() || near.count() > 0;
        people.wrong_outcomes += usize::from(completed && failed);
        let near: Vec<String> = (found.hand_contacts.iter())
            .chain(&found.perimeter_entries)
            .cloned()
            .collect();
        for (findings, count, list) in [
            (
                found.violations,
                &mut self.check_failures,
                &mut self.check_findings,
            ),
            (
                [found.physics, near].concat(),
                &mut self.physics_failures,
                &mut self.physics_findings,
            ),
        ] {
            if !findings.is_empty() {
                *count += 1;
                list.push(format!("{name}: {}", findings.join("; ")));
            }
        }
    }

    pub(super) fn report(self) -> MonitorBenchReport {
        MonitorBenchReport {
            relevant: self.relevant,
            detected: self.detected,
            irrelevant: self.irrelevant,
            false_triggers: self.false_triggers,
            median_observe_us: median(&self.observe_us),
            median_replan_ms: median(&self.replan_ms),
            physics_runs: self.physics.map(|_| self.physics_runs),
            cut_short_runs: self.physics.map(|_| self.cut_short_runs),
            check_failures: self.physics.map(|_| self.check_failures),
            check_findings: self.check_findings,
            physics_failures: self.physics.map(|_| self.physics_failures),
            physics_findings: self.physics_findings,
            kinds: self.kinds,
            people: self.people,
            executions_by_robot: self.by_robot,
            panics: self.panics,
        }
    }
}
