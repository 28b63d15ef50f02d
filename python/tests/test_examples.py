"""The example scripts of python/examples run and print what they promise."""

import subprocess
import sys
from pathlib import Path

from conftest import REPO

SCRIPTS = Path(__file__).resolve().parents[1] / "examples"


def run(script: str) -> str:
    done = subprocess.run([sys.executable, str(SCRIPTS / script)], cwd=REPO, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_the_plan_example_prints_each_subgoals_trajectory():
    out = run("plan_default.py")
    assert out.startswith("sort-blue-squares: 3 sub-goal(s) planned, 0 not")
    assert out.count("gripper close") == 3 and out.count("gripper open") == 3
    assert "lbr_iiwa_joint_1" in out or "joint" in out.split("t [s]")[1].split("\n")[0]


def test_the_monitor_example_waits_for_the_hand_and_completes():
    out = run("monitor_stream.py")
    verdicts = [line.split()[2] for line in out.splitlines() if line[:8].strip().endswith("s") is False and " s  " in line[:12]]
    assert "wait" in out and "completed at" in out
    assert verdicts or out
