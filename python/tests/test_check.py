"""afford.check: the independent gate in memory, violations typed as `afford check --json`."""

import json

import pytest

import afford
from conftest import EXAMPLES, load_json, run_afford

SORT = EXAMPLES / "sort-blue-squares.yaml"


@pytest.fixture(scope="module")
def planned():
    scenario = afford.Scenario.from_file(SORT)
    return scenario, afford.plan(scenario)


def test_a_plan_from_the_planner_passes(planned):
    scenario, plan = planned
    report = afford.check(scenario, plan)
    assert report.passed and bool(report)
    assert report.violations == []
    assert report.physics is None
    assert afford.check(scenario, plan.to_dict()).to_dict() == report.to_dict()


def test_the_physical_replay_reports_where_the_pieces_rest(planned):
    scenario, plan = planned
    report = afford.check(scenario, plan, physics=True)
    assert report.passed
    targets = report.physics["targets"]
    assert len(targets) == 3 and all(t["in_goal"] for t in targets)


def test_a_tampered_plan_gives_afford_checks_typed_violations(planned, afford_bin, tmp_path):
    scenario, plan = planned
    data = plan.to_dict()
    point = data["subgoals"][1]["trajectory"]["points"][40]
    point["positions"][2] += 3.0
    report = afford.check(scenario, data)
    assert not report.passed
    assert {"velocity", "acceleration", "jerk"} <= {v.kind for v in report.violations}
    tampered = data["subgoals"][1]["joint_names"][2]
    assert all((v.subgoal, v.joint) == (1, tampered) for v in report.violations)
    jerk = next(v for v in report.violations if v.kind == "jerk")
    assert jerk.sample == 39 and jerk.time_s == pytest.approx(0.405)
    assert jerk.cases >= 1 and jerk.body is None
    path = tmp_path / "tampered.json"
    path.write_text(json.dumps(data))
    done = run_afford(afford_bin, "check", str(SORT), str(path), "--json")
    assert done.returncode == 1
    assert report.to_dict() == load_json(done.stdout.encode())
    first = report.violations[0]
    assert str(first).startswith(f"{first.kind} sub-goal {first.subgoal}: ")


def test_a_plan_dict_that_is_no_plan_is_bad_input(planned):
    scenario, _ = planned
    with pytest.raises(afford.BadInput) as caught:
        afford.check(scenario, {"subgoals": "none"})
    assert caught.value.file == "<plan dict>"
