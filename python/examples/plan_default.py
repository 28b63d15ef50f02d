"""Plans the default scenario (examples/sort-blue-squares.yaml) and prints its trajectory.

    python python/examples/plan_default.py [SCENARIO] [--every N]
"""

import argparse
from pathlib import Path

import afford

REPO = Path(__file__).resolve().parents[2]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", nargs="?", default=REPO / "examples" / "sort-blue-squares.yaml")
    parser.add_argument("--every", type=int, default=50, help="print every N-th sample")
    args = parser.parse_args()

    scenario = afford.Scenario.from_file(args.scenario)
    plan = afford.plan(scenario)
    print(f"{plan.scenario}: {len(plan.subgoals)} sub-goal(s) planned, {len(plan.unsolved)} not")
    for k, s in enumerate(plan.subgoals):
        samples, joints = s.positions.shape
        print(f"\nsub-goal {k}: {s.object} -> {s.goal}, arm {s.arm}, {samples} samples of {joints} joints, "
              f"{s.time_from_start[-1]:.2f} s")
        for g in s.gripper:
            print(f"  gripper {g.command} from {g.start:.2f} s to {g.end:.2f} s")
        print("  t [s]   " + " ".join(f"{name:>9}" for name in s.joint_names))
        for i in list(range(0, samples, args.every)) + [samples - 1]:
            q = " ".join(f"{x:9.4f}" for x in s.positions[i])
            print(f"  {s.time_from_start[i]:6.2f}  {q}")
    for u in plan.unsolved:
        print(f"\nnot planned: {u.object} -> {u.goal}: {u.reason} [{u.refusal.kind}]")


if __name__ == "__main__":
    main()
