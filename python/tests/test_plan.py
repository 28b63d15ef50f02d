"""afford.plan: trajectories as numpy arrays, typed refusals, the JSON of `afford plan`."""

import inspect
import threading
import time

import numpy as np
import pytest

import afford
from conftest import EXAMPLES, afford_json, load_json

SORT = EXAMPLES / "sort-blue-squares.yaml"


@pytest.fixture(scope="module")
def sort_plan() -> afford.Plan:
    return afford.plan(afford.Scenario.from_file(SORT))


def test_every_subgoal_has_its_trajectory_as_arrays(sort_plan):
    assert [s.object for s in sort_plan.subgoals] == ["blue-square-1", "blue-square-2", "blue-square-3"]
    for s in sort_plan.subgoals:
        samples = len(s.time_from_start)
        assert s.positions.shape == (samples, len(s.joint_names))
        assert s.velocities.shape == s.accelerations.shape == s.positions.shape
        assert s.time_from_start.shape == (samples,)
        assert np.all(np.diff(s.time_from_start) > 0)
        assert [g.command for g in s.gripper] == ["close", "open"]
        assert s.arm == "arm"
        assert s.actions[-1] == "DROP"
        trajectory = s.to_dict()["trajectory"]
        assert np.array_equal(s.positions, [p["positions"] for p in trajectory["points"]])
    assert sort_plan.unsolved == []
    assert sort_plan.until == "trajectory" and sort_plan.seed == 1 and sort_plan.rate_hz == 100.0


def test_to_json_is_byte_for_byte_what_afford_plan_writes(sort_plan, afford_bin, tmp_path):
    written, code = afford_json(afford_bin, tmp_path, "plan", str(SORT))
    assert code == 0
    assert sort_plan.to_json().encode() == written
    assert sort_plan.to_dict() == load_json(written)


def test_seed_rate_and_stage_are_afford_plans_options(afford_bin, tmp_path):
    scenario = afford.Scenario.from_file(SORT)
    plan = afford.plan(scenario, seed=7, rate_hz=50, until="joints")
    written, _ = afford_json(afford_bin, tmp_path, "plan", str(SORT), "--seed", "7", "--rate", "50", "--until", "joints")
    assert plan.to_json().encode() == written
    assert plan.subgoals[0].positions is None and plan.subgoals[0].joint_names


def test_a_subgoal_that_cannot_be_planned_is_data_with_a_typed_refusal(afford_bin, tmp_path):
    path = EXAMPLES / "hand-blocks-goal.yaml"
    plan = afford.plan(afford.Scenario.from_file(path))
    assert plan.subgoals == []
    refusal = plan.unsolved[0].refusal
    assert refusal.kind == "perimeters_cover_goal"
    assert refusal.goal == "left box"
    assert refusal.message == plan.unsolved[0].reason
    assert set(refusal.fields()) == {"kind", "goal", "message"}
    with pytest.raises(AttributeError):
        refusal.blocked_cells
    written, code = afford_json(afford_bin, tmp_path, "plan", str(path))
    assert code == 1
    assert plan.to_json().encode() == written


def test_an_instruction_that_cannot_be_carried_out_is_bad_input():
    with pytest.raises(afford.BadInput) as caught:
        afford.plan(afford.Scenario.from_file(EXAMPLES / "unsolvable-instruction.yaml"))
    assert caught.value.field == "instruction"
    assert "Not executable instruction" in caught.value.message


@pytest.mark.parametrize("kwargs, field", [({"rate_hz": 0}, "rate_hz"), ({"until": "done"}, "until")])
def test_bad_options_are_bad_input(kwargs, field):
    with pytest.raises(afford.BadInput) as caught:
        afford.plan(afford.Scenario.default(), **kwargs)
    assert caught.value.field == field


def test_the_joint_trajectory_dict_has_ros_shape(sort_plan):
    s = sort_plan.subgoals[0]
    msg = s.to_joint_trajectory()
    assert msg["joint_names"] == s.joint_names
    assert len(msg["points"]) == len(s.time_from_start)
    for point, t, q in zip(msg["points"], s.time_from_start, s.positions):
        d = point["time_from_start"]
        assert 0 <= d["nanosec"] < 1_000_000_000
        assert d["sec"] + d["nanosec"] * 1e-9 == pytest.approx(t, abs=1e-9)
        assert point["positions"] == list(q)


def test_the_gil_is_released_while_planning():
    scenario = afford.Scenario.default()
    started = threading.Event()

    def plan():
        started.set()
        afford.plan(scenario)

    worker = threading.Thread(target=plan)
    worker.start()
    started.wait()
    ticks = 0
    while worker.is_alive():
        ticks += 1
        time.sleep(0.001)
    worker.join()
    # Holding the GIL, the planner would let this loop run at most once or twice.
    assert ticks > 10


def test_help_gives_the_signature_and_the_contract():
    signature = inspect.signature(afford.plan)
    assert list(signature.parameters) == ["scenario", "seed", "rate_hz", "until"]
    assert signature.parameters["seed"].default == 1
    assert signature.parameters["rate_hz"].default == 100.0
    doc = afford.plan.__doc__
    for words in ("plan.unsolved", "afford.BadInput", "afford.InternalError", "GIL"):
        assert words in doc
    assert "BadInput" in afford.Scenario.from_dict.__doc__


def test_the_docstring_example_gives_what_it_shows(monkeypatch):
    import doctest

    from conftest import REPO

    monkeypatch.chdir(REPO)
    parser, runner = doctest.DocTestParser(), doctest.DocTestRunner()
    test = parser.get_doctest(afford.plan.__doc__, {"afford": afford}, "afford.plan", None, 0)
    assert test.examples
    result = runner.run(test)
    assert result.failed == 0 and result.attempted == len(test.examples)
