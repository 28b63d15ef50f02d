#!/usr/bin/env python3
"""Compare afford's time-parameterisation durations with toppra's.

Not run in CI. Needs `pip install toppra` (which brings numpy and scipy).

1. Write the cases (seeded random smooth 7-joint paths, iiwa-like limits,
   afford's duration at 100/200/300/400/1000 path segments):

       AFFORD_TIMING_CASE=/tmp/timing_case.json \
         cargo test --release -p afford-planner --test timing -- --ignored export_reference_case

2. Compare:

       python3 scripts/toppra_reference.py /tmp/timing_case.json

For every case toppra (TOPP-RA, Pham & Pham 2018) times *the same* joint
path: a natural cubic spline through the waypoints with chord-length knots
(scipy's CubicSpline with bc_type="natural", the spline afford builds), the
same velocity and acceleration limits, at rest at both ends. toppra is run on
a fine grid (default 4000 points) as the time-optimal reference, and on 200
points for a same-grid comparison. toppra enforces the constraints only at
its grid points (it may exceed a limit between them), while afford bounds
them on whole segments, so afford's durations are expected to be slightly
longer, never shorter, than the fine-grid reference.
"""

import argparse
import json
import sys

import numpy as np
import toppra
import toppra.algorithm
import toppra.constraint


def chord_knots(waypoints):
    steps = np.linalg.norm(np.diff(waypoints, axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(steps)])


def toppra_duration(waypoints, vlim, alim, gridpoints):
    ss = chord_knots(waypoints)
    path = toppra.SplineInterpolator(ss, waypoints, bc_type="natural")
    constraints = [
        toppra.constraint.JointVelocityConstraint(np.vstack([-vlim, vlim]).T),
        toppra.constraint.JointAccelerationConstraint(np.vstack([-alim, alim]).T),
    ]
    grid = np.linspace(0.0, ss[-1], gridpoints + 1)
    instance = toppra.algorithm.TOPPRA(
        constraints, path, gridpoints=grid, parametrizer="ParametrizeConstAccel"
    )
    trajectory = instance.compute_trajectory(0.0, 0.0)
    if trajectory is None:
        raise RuntimeError("toppra found no parameterisation")
    return float(trajectory.duration)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cases", help="JSON written by export_reference_case")
    parser.add_argument("--fine", type=int, default=4000, help="toppra reference grid")
    parser.add_argument("--tolerance", type=float, default=1.0, help="allowed difference, percent")
    parser.add_argument("--segments", default="200", choices=["100", "200", "300", "400", "1000"],
                        help="afford's segment count to judge")
    args = parser.parse_args()
    toppra.setup_logging("WARNING")
    with open(args.cases) as f:
        cases = json.load(f)["cases"]

    worst = 0.0
    columns = ["100", "200", "300", "400", "1000"]
    print(f"{'case':>4} {'toppra fine':>12} {'toppra 200':>11} " + " ".join(f"{'afford ' + c:>12}" for c in columns) + f" {'diff ' + args.segments + ' %':>11}")
    for k, case in enumerate(cases):
        waypoints = np.array(case["waypoints"], dtype=float)
        vlim = np.array(case["velocity_limits"], dtype=float)
        alim = np.array(case["acceleration_limits"], dtype=float)
        ours = case["afford_duration_s"]
        fine = toppra_duration(waypoints, vlim, alim, args.fine)
        coarse = toppra_duration(waypoints, vlim, alim, 200)
        diff = 100.0 * (ours[args.segments] - fine) / fine
        worst = max(worst, abs(diff))
        print(f"{k:>4} {fine:>12.5f} {coarse:>11.5f} " + " ".join(f"{ours[c]:>12.5f}" for c in columns) + f" {diff:>+11.3f}")
    print(f"largest |difference| at {args.segments} segments: {worst:.3f} % (tolerance {args.tolerance} %)")
    return 0 if worst <= args.tolerance else 1


if __name__ == "__main__":
    sys.exit(main())
