//! The scenario's optional `observations` timeline: old files stay valid,
//! each entry replaces the lists it names, and a bad entry is named by its
//! field path like the rest of the file.

use afford_planner::scenario::{DEFAULT_SCENARIO, Format, MotionPhase, bounds, parse};

fn with_observations(block: &str) -> Result<afford_planner::Scenario, String> {
    let text = format!("{DEFAULT_SCENARIO}\nobservations:\n{block}");
    parse(&text, Format::Yaml, "scene.yaml").map_err(|e| e.to_string())
}

#[test]
fn observations_absent_old_files_stay_valid() {
    let s = parse(DEFAULT_SCENARIO, Format::Yaml, "scene.yaml").expect("valid");
    assert!(s.observations.is_empty());
}

#[test]
fn observations_replace_only_the_lists_they_name() {
    let s = with_observations(
        "  - {at: 1.5, hands: [{name: hand-9, box: [300, 200, 40, 40], height: 0.08}]}\n  \
         - {when: {subgoal: 1, phase: carry, fraction: 0.5}, hands: []}\n",
    )
    .expect("valid");
    assert_eq!(s.observations.len(), 2);
    let seen = s.observed(&s.observations[0]);
    assert_eq!(seen.hands.len(), 1);
    assert_eq!(seen.hands[0].name, "hand-9");
    assert_eq!(seen.objects, s.objects, "objects not listed stay");
    assert_eq!(seen.goals, s.goals);
    let when = s.observations[1].when.expect("plan point");
    assert_eq!((when.subgoal, when.phase), (1, MotionPhase::Carry));
    assert!(seen.observed(&s.observations[1]).hands.is_empty());
}

#[test]
fn observations_need_exactly_one_time_and_a_change() {
    let both = with_observations("  - {at: 1.0, when: {subgoal: 0, phase: travel}, hands: []}\n")
        .unwrap_err();
    assert!(
        both.contains("observations[0]") && both.contains("exactly one"),
        "{both}"
    );
    let none = with_observations("  - {hands: []}\n").unwrap_err();
    assert!(none.contains("exactly one"), "{none}");
    let empty = with_observations("  - {at: 1.0}\n").unwrap_err();
    assert!(empty.contains("at least one of"), "{empty}");
}

#[test]
fn observations_times_and_fractions_are_bounded() {
    let late = with_observations("  - {at: 1.0e9, hands: []}\n").unwrap_err();
    assert!(late.contains("observations[0].at"), "{late}");
    let nan = with_observations("  - {at: .nan, hands: []}\n").unwrap_err();
    assert!(nan.contains("observations[0].at"), "{nan}");
    let fraction =
        with_observations("  - {when: {subgoal: 0, phase: carry, fraction: 1.5}, hands: []}\n")
            .unwrap_err();
    assert!(
        fraction.contains("observations[0].when.fraction"),
        "{fraction}"
    );
    let subgoal =
        with_observations("  - {when: {subgoal: 99, phase: carry}, hands: []}\n").unwrap_err();
    assert!(
        subgoal.contains("observations[0].when.subgoal"),
        "{subgoal}"
    );
    let phase =
        with_observations("  - {when: {subgoal: 0, phase: flying}, hands: []}\n").unwrap_err();
    assert!(phase.contains("observations[0].when.phase"), "{phase}");
}

#[test]
fn observations_elements_are_validated_with_their_path() {
    let outside = with_observations(
        "  - {at: 1.0, hands: [{name: h, box: [900, 10, 40, 40], height: 0.08}]}\n",
    )
    .unwrap_err();
    assert!(
        outside.contains("observations[0].hands[0].box"),
        "{outside}"
    );
    let twice = with_observations(
        "  - {at: 1.0, hands: [{name: left box, box: [10, 10, 40, 40], height: 0.08}]}\n",
    )
    .unwrap_err();
    assert!(twice.contains("observations[0].hands[0].name"), "{twice}");
    let typo = with_observations("  - {at: 1.0, handz: []}\n").unwrap_err();
    assert!(typo.contains("observations[0]"), "{typo}");
}

#[test]
fn observations_count_is_bounded() {
    let one = "  - {at: 1.0, hands: []}\n";
    let many = one.repeat(bounds::MAX_OBSERVATIONS + 1);
    let e = with_observations(&many).unwrap_err();
    assert!(e.contains("observations") && e.contains("at most"), "{e}");
}
