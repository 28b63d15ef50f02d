"""afford: from an overhead camera scene and a spoken instruction to verified robot plans.

The library's operations on Python data and numpy arrays:

- ``Scenario.from_file(path)``, ``Scenario.from_dict(d)``, ``Scenario.default()``,
  ``scenario.to_dict()``, ``scenario.with_joint_state(joint_state)``
- ``plan(scenario, seed=1, rate_hz=100, until=None) -> Plan``
- ``check(scenario, plan, physics=False) -> Report``
- ``Monitor(scenario, plan)``: ``observe(t, objects=, goals=, hands=) -> Verdict``,
  ``advance(dt) -> Setpoints``, ``executed``, ``events``
- ``robots()``, ``load_robot(model, base_dir=None)``

Bad input raises ``BadInput`` (``file``, ``field``, ``message``, ``issues``); a
sub-goal that cannot be planned is data (``plan.unsolved``); a defect of afford
raises ``InternalError``.
"""

from ._afford import (
    CAMERA_PERIOD_S,
    MAX_EXECUTION_TIME_S,
    BadInput,
    Event,
    Executed,
    GripperEvent,
    InternalError,
    Monitor,
    Plan,
    Reason,
    Refusal,
    Report,
    Robot,
    Scenario,
    Setpoints,
    Subgoal,
    Unsolved,
    Verdict,
    Violation,
    __version__,
    check,
    load_robot,
    plan,
    robots,
)

__all__ = [
    "CAMERA_PERIOD_S",
    "MAX_EXECUTION_TIME_S",
    "BadInput",
    "Event",
    "Executed",
    "GripperEvent",
    "InternalError",
    "Monitor",
    "Plan",
    "Reason",
    "Refusal",
    "Report",
    "Robot",
    "Scenario",
    "Setpoints",
    "Subgoal",
    "Unsolved",
    "Verdict",
    "Violation",
    "__version__",
    "check",
    "load_robot",
    "plan",
    "robots",
]
