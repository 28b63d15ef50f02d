"""The example scripts of python/examples run and print what they promise."""

import re
import subprocess
import sys
from pathlib import Path

from conftest import REPO

SCRIPTS = Path(__file__).resolve().parents[1] / "examples"


def run(script: str) -> str:
    done = subprocess.run(
        [sys.executable, str(SCRIPTS / script)], cwd=REPO, capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_the_plan_example_prints_each_subgoals_trajectory():
    out = run("plan_default.py")
    assert out.startswith("sort-blue-squares: 3 sub-goal(s) planned, 0 not\n")
    assert out.count("gripper close") == out.count("gripper open") == 3
    header = next(line for line in out.splitlines() if line.strip().startswith("t [s]"))
    assert header.split()[2:] == [f"joint_a{k}" for k in range(1, 8)]


def test_the_monitor_example_waits_for_the_hand_and_completes():
    out, events = run("monitor_stream.py").split("\n\n")
    stream = [re.match(r"\s*[\d.]+ s  (\w+)", line).group(1) for line in out.splitlines()]
    assert stream == ["continue", "gripper", "wait", "continue", "gripper"]
    assert events.startswith("completed at ")
    assert "hand hand-1 appeared" in events and "hand hand-1 left" in events
