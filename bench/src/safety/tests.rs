//! The campaign runner's counts: violations per trajectory, refusals and
//! the probe's verdicts per kind, every refused sub-goal probed.

use super::*;

fn outcome(findings: Vec<(&str, Option<usize>)>) -> SceneOutcome {
    SceneOutcome {
        index: 0,
        robot: scenes::ROBOTS[0],
        outcome: Outcome::Planned,
        trajectories: 2,
        refusals: vec![("no_route", "no free route".into())],
        free_poses: vec![Some(true)],
        probe_error: None,
        findings: findings
            .into_iter()
            .map(|(class, subgoal)| Finding {
                class: class.into(),
                subgoal,
                message: String::new(),
            })
            .collect(),
        structural: Structural::default(),
        subgoal_s: vec![0.25, 0.5],
        scene_s: 0.75,
    }
}

#[test]
fn violations_count_trajectories_not_messages() {
    let report = SafetyReport::of(
        1,
        &[outcome(vec![
            ("margin", Some(0)),
            ("margin", Some(0)),
            ("margin", Some(1)),
            ("format", None),
        ])],
    );
    let t = &report.total;
    assert_eq!(t.violations["margin"], 2);
    assert_eq!(t.violations["format"], 1);
    assert_eq!(t.violations["penetration"], 0);
    assert_eq!(t.refusals["no_route"], 1);
    assert_eq!(report.robots[scenes::ROBOTS[0]], *t);
    assert_eq!(report.robots[scenes::ROBOTS[1]].scenarios, 0);
}

#[test]
fn report_carries_refusals_with_free_poses_per_kind() {
    let mut refused = outcome(Vec::new());
    refused
        .refusals
        .push(("hand_covers_target", "covered".into()));
    refused.free_poses.push(Some(false));
    let report = SafetyReport::of(1, &[outcome(Vec::new()), refused]);
    let v = serde_json::to_value(&report).unwrap();
    let counts = &v["refusals_with_free_poses"];
    for kind in REFUSAL_KINDS {
        assert!(counts[kind]["with_free_poses"].is_u64(), "{kind}: {counts}");
    }
    let no_route = serde_json::json!({"refusals": 2, "probed": 2, "with_free_poses": 2});
    assert_eq!(counts["no_route"], no_route);
    let covered = serde_json::json!({"refusals": 1, "probed": 1, "with_free_poses": 0});
    assert_eq!(counts["hand_covers_target"], covered);
    let robot = &v["robots"][scenes::ROBOTS[0]]["refusals_with_free_poses"];
    assert_eq!(robot["no_route"], no_route);
    assert!(report.table().contains("with free poses"));
    assert!(report.examples.contains_key("no_route with free poses"));
}

/// A planned scene of the series with refusals: every refusal naming a
/// sub-goal is probed, and the report counts them per kind.
#[test]
fn campaign_scenes_probe_every_refused_subgoal() {
    let robots = Robots::load().unwrap();
    let none = |_: &Scenario, _: &RobotModel, _: &Plan| Vec::new();
    let scene = (0..40)
        .map(|k| run_scene(&robots, 1, k, &none))
        .find(|s| s.refusals.len() >= 2 && s.free_poses.iter().all(Option::is_some))
        .expect("a scene with refusals among the first 40");
    assert_eq!(scene.free_poses.len(), scene.refusals.len());
    assert_eq!(scene.probe_error, None);
    let report = SafetyReport::of(1, std::slice::from_ref(&scene));
    let counts = &report.total.refusals_with_free_poses;
    let probed: usize = counts.values().map(|c| c.probed).sum();
    assert_eq!(probed, scene.refusals.len());
    for (kind, c) in counts {
        assert_eq!(c.refusals, report.total.refusals[kind], "{kind}");
    }
    eprintln!(
        "scene {}: {:?} {:?}",
        scene.index, scene.refusals, scene.free_poses
    );
}
