"""afford.Monitor driven from Python as `afford run` drives it gives `afford run`'s
events and executed samples; its setpoints are the executed samples of the whole robot."""

import numpy as np
import pytest

import afford
from conftest import EXAMPLES, afford_json, load_json

MONITOR = EXAMPLES / "monitor"
# The paper's experiments 2, 4 and 5 on both robots.
EXPERIMENTS = [
    f"{robot}{name}.yaml"
    for robot in ("", "cob4-")
    for name in ("pieces-added", "goal-moved-while-holding", "hand-in-the-way")
]


def play(monitor: afford.Monitor, observations: list) -> tuple[int, list]:
    """`afford run`'s loop in Python: each timeline entry at the first frame or
    controller period it falls due, a camera frame every CAMERA_PERIOD_S in between.
    Returns how many entries were delivered and every advance's setpoints."""
    delivered, frame, setpoints = 0, 0.0, []
    while monitor.status == "running":
        t = monitor.clock
        if t > afford.MAX_EXECUTION_TIME_S:
            setpoints.append(monitor.abort(f"execution ran past {afford.MAX_EXECUTION_TIME_S:g} s"))
            break
        if delivered < len(observations) and monitor.due(observations[delivered]):
            o = observations[delivered]
            monitor.observe(t, objects=o.get("objects"), goals=o.get("goals"), hands=o.get("hands"))
            delivered += 1
        elif t + 1e-9 >= frame:
            monitor.observe(t)
            frame += afford.CAMERA_PERIOD_S
        setpoints.append(monitor.advance(until=t + monitor.period))
    return delivered, setpoints


def run_in_python(path):
    scenario = afford.Scenario.from_file(path)
    monitor = afford.Monitor(scenario, afford.plan(scenario))
    delivered, setpoints = play(monitor, scenario.observations)
    return scenario, monitor, delivered, setpoints


@pytest.mark.parametrize("name", EXPERIMENTS)
def test_the_monitor_from_python_gives_afford_runs_events_and_samples(name, afford_bin, tmp_path):
    scenario, monitor, delivered, _ = run_in_python(MONITOR / name)
    written, code = afford_json(afford_bin, tmp_path, "run", str(MONITOR / name))
    run = load_json(written)
    assert delivered == len(scenario.observations)
    assert [e.to_dict() for e in monitor.events] == run["events"]
    assert [e.to_dict() for e in monitor.executed] == run["subgoals"]
    assert monitor.start_state == run["start_state"]
    assert monitor.status == run["outcome"]
    assert (code == 0) == (run["outcome"] == "completed" and run["physics"]["passed"])
    for executed, written in zip(monitor.executed, run["subgoals"]):
        points = written["trajectory"]["points"]
        assert np.array_equal(executed.positions, [p["positions"] for p in points])
        assert np.array_equal(executed.time_from_start, [p["time_from_start"] for p in points])


@pytest.mark.parametrize("name", ["hand-in-the-way.yaml", "cob4-pieces-added.yaml"])
def test_setpoints_are_the_executed_samples_of_the_whole_robot(name):
    _, monitor, _, setpoints = run_in_python(MONITOR / name)
    names = setpoints[0].joint_names
    assert names == monitor.start_state["joint_names"]
    times = np.concatenate([s.time for s in setpoints])
    positions = np.concatenate([s.positions for s in setpoints])
    assert np.all(np.diff(times) > 0)
    executed = monitor.executed
    # A sub-goal's first sample is where the one before ended: sent once.
    assert len(times) == sum(len(e.time_from_start) for e in executed) - (len(executed) - 1)
    row = 0
    for k, e in enumerate(executed):
        columns = [names.index(j) for j in e.joint_names]
        first = 0 if k == 0 else 1
        rows = slice(row, row + len(e.time_from_start) - first)
        assert np.array_equal(positions[rows][:, columns], e.positions[first:])
        assert np.allclose(times[rows], e.start_time + e.time_from_start[first:], atol=1e-9)
        row = rows.stop
    commands = [g.command for s in setpoints for g in s.gripper]
    assert commands == [g.command for e in executed for g in e.gripper]
    trajectory = setpoints[5].to_joint_trajectory()
    assert trajectory["joint_names"] == names
    assert len(trajectory["points"]) == len(setpoints[5])


def test_a_hand_on_the_route_is_a_typed_wait():
    scenario = afford.Scenario.from_file(MONITOR / "hand-in-the-way.yaml")
    monitor = afford.Monitor(scenario, afford.plan(scenario))
    hand = scenario.observations[0]["hands"]
    while monitor.position[1] != "carry":
        monitor.advance(afford.CAMERA_PERIOD_S)
    monitor.advance(0.3)
    verdict = monitor.observe(monitor.clock, hands=hand)
    assert verdict.kind == "wait"
    assert verdict.reason.kind == "hand_on_route"
    assert verdict.reason.hand == "hand-1"
    assert verdict.reason.subgoal == 0
    assert verdict.message.startswith("hand-1 is on the remaining route")
    assert monitor.events[-1].changes == ["hand hand-1 appeared"]
    # Braked: the robot comes to rest and stays there while the hand is there.
    monitor.advance(2.0)
    still = monitor.advance(0.5)
    assert np.allclose(still.velocities, 0.0)
    # A hand the detector stops listing is held for safety.detection.hand_hold_s
    # (0.5 s): the robot goes on only once the way has been clear that long.
    assert monitor.observe(monitor.clock, hands=[]).kind == "wait"
    monitor.advance(0.6)
    assert monitor.events[-1].verdict == "continue"


def test_a_bad_observation_is_bad_input_named_by_list():
    scenario = afford.Scenario.from_file(MONITOR / "hand-in-the-way.yaml")
    monitor = afford.Monitor(scenario, afford.plan(scenario))
    with pytest.raises(afford.BadInput) as caught:
        monitor.observe(0.0, hands=[{"name": "hand-1", "box": [200, 250, -40, 40], "height": 0.08}])
    assert caught.value.field.startswith("hands[0].box")
    with pytest.raises(afford.BadInput) as caught:
        monitor.observe(0.0, hands=[{"name": "hand-1", "box": "here"}])
    assert caught.value.field.startswith("hands[0]")
    with pytest.raises(afford.BadInput) as caught:
        monitor.observe(float("nan"))
    assert caught.value.field == "t"
    with pytest.raises(afford.BadInput):
        monitor.advance(-1.0)
    with pytest.raises(afford.BadInput):
        monitor.advance(until=afford.MAX_EXECUTION_TIME_S + 1)
    assert monitor.clock == 0.0 and monitor.events == []


def test_a_plan_without_trajectories_cannot_be_followed():
    scenario = afford.Scenario.from_file(EXAMPLES / "sort-blue-squares.yaml")
    with pytest.raises(afford.BadInput) as caught:
        afford.Monitor(scenario, afford.plan(scenario, until="joints"))
    assert "trajectory" in caught.value.message


def test_abort_brakes_to_rest_and_stops():
    scenario = afford.Scenario.from_file(EXAMPLES / "sort-blue-squares.yaml")
    monitor = afford.Monitor(scenario, afford.plan(scenario))
    moving = monitor.advance(1.0)
    braking = monitor.abort("operator pressed stop")
    assert monitor.status == "aborted"
    assert braking.time[0] > moving.time[-1] and len(braking) > 1
    assert np.allclose(braking.velocities[-1], 0.0)
    assert monitor.reason.kind == "no_plan" and monitor.reason.message == "operator pressed stop"
    assert monitor.executed[-1].cut_short
    assert np.allclose(monitor.executed[-1].velocities[-1], 0.0)
    assert len(monitor.advance(1.0)) == 0
