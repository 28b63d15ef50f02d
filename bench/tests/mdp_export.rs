//! The MDP export of generated scenes (`afford export-mdp --generated`):
//! the format round-trips and refuses what it does not know, the tables are
//! bounded and consistent, and afford's own plans replay in them.

use afford_bench::cql::generated_export;
use afford_planner::export::{DONE, FORMAT_VERSION, MAX_STATES, MdpExport, REFUSED};
use afford_planner::{Action, LearnerSettings};

/// The format reads back to the same value (serde, JSON).
#[test]
fn mdp_export_round_trips_through_json() {
    let export = generated_export(1, 0, true);
    let text = serde_json::to_string(&export).unwrap();
    let back: MdpExport = serde_json::from_str(&text).unwrap();
    assert_eq!(back, export);
    assert_eq!(back.format_version, FORMAT_VERSION);
}

/// A reader must know the version: a file without it is refused, as is
/// a field the format does not have.
#[test]
fn mdp_export_refuses_missing_version_and_unknown_fields() {
    let export = generated_export(1, 1, false);
    let mut value = serde_json::to_value(&export).unwrap();
    value.as_object_mut().unwrap().remove("format_version");
    assert!(serde_json::from_value::<MdpExport>(value.clone()).is_err());
    value["format_version"] = 1.into();
    value["surprise"] = 1.into();
    assert!(serde_json::from_value::<MdpExport>(value).is_err());
}

/// Tables are one row per state, and the state count stays within the
/// bound the scenario limits imply; every next state is on the table.
#[test]
fn mdp_export_tables_are_bounded_and_consistent() {
    for index in 0..10 {
        let e = generated_export(1, index, false);
        let states = e.rows * e.cols * 2;
        assert!(states <= MAX_STATES, "{}: {states} states", e.name);
        assert_eq!(e.next.len(), states);
        assert_eq!(e.reward.len(), states);
        assert_eq!(e.grid.len(), e.rows);
        assert!(e.grid.iter().all(|row| row.len() == e.cols));
        let on_table = |n: i64| n == REFUSED || n == DONE || (0..states as i64).contains(&n);
        assert!(e.next.iter().flatten().all(|&n| on_table(n)), "{}", e.name);
    }
}

/// afford's own CQL plan, replayed through the exported transitions,
/// reaches DROP in exactly its length; a plan cut short does not.
#[test]
fn exported_cql_plan_replays_to_drop() {
    let mut solved = 0;
    for index in 0..20 {
        let e = generated_export(1, index, false);
        if !e.cql_plan.solved {
            assert_eq!(
                e.optimal_length, None,
                "{}: CQL failed a solvable MDP",
                e.name
            );
            continue;
        }
        solved += 1;
        let plan = &e.cql_plan.actions;
        assert_eq!(e.replay(plan), Some(plan.len()), "{}", e.name);
        assert!(plan.len() >= e.optimal_length.unwrap());
        assert_eq!(e.replay(&plan[..plan.len() - 1]), None, "{}", e.name);
    }
    // Most generated scenes leave no resting spot in the goal (see
    // `afford bench cql`: 36 of seed 1's first 100 are solvable).
    assert!(solved >= 5, "only {solved} of 20 scenes solved");
}

/// The exported rewards and terminal are the learner's: the last step
/// of a solved plan earns `reward_drop`, GOAL earns `reward_goal`, a
/// refused action `reward_refused`.
#[test]
fn exported_rewards_follow_the_learner_settings() {
    let settings = LearnerSettings::default();
    let e = (0..20)
        .map(|index| generated_export(1, index, false))
        .find(|e| e.cql_plan.solved)
        .unwrap();
    let mut state = e.start_state;
    for a in &e.cql_plan.actions {
        let (next, r) = (e.next[state][a.index()], e.reward[state][a.index()]);
        let expected = match (next, a) {
            (DONE, _) => settings.reward_drop,
            (_, Action::Goal) => settings.reward_goal,
            (_, Action::Grasp) => settings.reward_grasp,
            _ => settings.reward_move,
        };
        assert_eq!(r, expected);
        if next >= 0 {
            state = next as usize;
        }
    }
    let refused = e.next.iter().flatten().zip(e.reward.iter().flatten());
    assert!(
        refused
            .filter(|&(&n, _)| n == REFUSED)
            .all(|(_, &r)| r == settings.reward_refused)
    );
}

/// Learner statistics are there only when asked for, and the CQL run
/// they report is the exported plan.
#[test]
fn learner_stats_describe_the_exported_plan() {
    assert!(generated_export(1, 3, false).learners.is_none());
    let e = generated_export(1, 3, true);
    let stats = e.learners.as_ref().unwrap();
    assert_eq!(stats.cql.plan, e.cql_plan);
    assert!(stats.cql.wall_ms >= 0.0 && stats.ql.wall_ms >= 0.0);
}
