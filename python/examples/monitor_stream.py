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


def hands_seen(monitor: afford.Monitor, hand_came: bool) -> "list | None":
    """The scripted camera: the hand's list when it changes, else None (same scene)."""
    subgoal, phase, fraction = monitor.position
    if not hand_came and (subgoal, phase) == (0, "carry") and fraction >= 0.2:
        return [HAND]
    if hand_came and monitor.clock >= 6.0:
        return []
    return None


def main() -> None:
    data = afford.Scenario.from_file(REPO / "examples" / "monitor" / "hand-in-the-way.yaml").to_dict()
    data.pop("observations", None)
    scenario = afford.Scenario.from_dict(data)
    plan = afford.plan(scenario)
    monitor = afford.Monitor(scenario, plan)
    hand_came, hand_left, last = False, False, None
    while monitor.status == "running":
        t = monitor.clock
        hands = None if hand_left else hands_seen(monitor, hand_came)
        verdict = monitor.observe(t, hands=hands)
        if hands is not None:
            hand_left, hand_came = hand_came, True
        if verdict.kind != last:
            why = f": {verdict.message}" if verdict.message else ""
            print(f"{t:7.2f} s  {verdict.kind}{why}")
            last = verdict.kind
        setpoints = monitor.advance(afford.CAMERA_PERIOD_S)
        for g in setpoints.gripper:
            print(f"{g.start:7.2f} s  gripper {g.command}")
    print(f"\n{monitor.status} at {monitor.clock:.2f} s; events:")
    for e in monitor.events:
        print(f"  {e.time:7.2f} s  {e.verdict:9} {'; '.join(e.changes)} {e.message or ''}")
    for e in monitor.executed:
        print(f"executed {e.object} -> {e.goal}: {e.positions.shape[0]} samples from {e.start_time:.2f} s")


if __name__ == "__main__":
    main()
