"""Runs the valid-policy detector on a scripted stream of camera observations.

The robot carries the blue square to the left box (examples/monitor/hand-in-the-way.yaml,
planned without its timeline). A camera loop at 30 Hz feeds the monitor: when the carry
is a fifth done a hand comes to rest on the remaining route, at 6 s it is withdrawn.
The monitor brakes, waits, resumes; each frame's setpoints are what a controller would
track until the next frame.

    python python/examples/monitor_stream.py
"""

from pathlib import Path

import afford

REPO = Path(__file__).resolve().parents[2]
HAND = {"name": "hand-1", "box": [200, 250, 40, 40], "height": 0.08}


def hands_seen(monitor: afford.Monitor, hand_there: "bool | None") -> "list | None":
    """The scripted camera: the hands' list when it changes, else None (the same scene).
    `hand_there`: None before the hand came, True while it is there, False after."""
    subgoal, phase, fraction = monitor.position
    if hand_there is None and (subgoal, phase) == (0, "carry") and fraction >= 0.2:
        return [HAND]
    if hand_there and monitor.clock >= 6.0:
        return []
    return None


def main() -> None:
    data = afford.Scenario.from_file(REPO / "examples" / "monitor" / "hand-in-the-way.yaml").to_dict()
    data.pop("observations", None)
    scenario = afford.Scenario.from_dict(data)
    plan = afford.plan(scenario)
    monitor = afford.Monitor(scenario, plan)
    hand_there, last = None, None
    while monitor.status == "running":
        t = monitor.clock
        hands = hands_seen(monitor, hand_there)
        verdict = monitor.observe(t, hands=hands)
        if hands is not None:
            hand_there = bool(hands)
        if verdict.kind != last:
            why = f": {verdict.message}" if verdict.message else ""
            print(f"{t:7.2f} s  {verdict.kind}{why}")
            last = verdict.kind
        setpoints = monitor.advance(afford.CAMERA_PERIOD_S)
        for g in setpoints.gripper:
            print(f"{g.start:7.2f} s  gripper {g.command}")
    print(f"\n{monitor.status} at {monitor.clock:.2f} s; events:")
    for e in monitor.events:
        said = "; ".join(e.changes + ([e.message] if e.message else []))
        print(f"  {e.time:7.2f} s  {e.verdict:9} {said}")
    for e in monitor.executed:
        print(f"executed {e.object} -> {e.goal}: {e.positions.shape[0]} samples from {e.start_time:.2f} s")


if __name__ == "__main__":
    main()
