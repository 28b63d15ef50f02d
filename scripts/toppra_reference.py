#!/usr/bin/env python3
"""Compare afford's time-parameterisation durations with toppra's.

Not run in CI. Needs `pip install toppra` (which brings numpy and scipy).

1. Write the cases (ten seeded random smooth 7-joint paths with iiwa-like
   limits, then every piece of the real paths of two examples with their
   robot's limits; afford's duration at 100/200/300/400/1000 path segments,
   and the path afford times as a piecewise polynomial):

       AFFORD_TIMING_CASE=/tmp/timing_case.json \
         cargo test --release -p afford-planner --test timing -- --ignored export_reference_case

2. Compare:

       python3 scripts/toppra_reference.py /tmp/timing_case.json

For every case toppra (TOPP-RA, Pham & Pham 2018) times *the same* joint
path: afford's blended polyline (the joint polyline with quadratic Bezier
corner blends, see planner/src/timing/spline.rs), read from the case as
breakpoints and coefficients, with the same velocity and acceleration
limits, at rest at both ends. toppra runs on a fine grid (default 4000
points) as the time-optimal reference. toppra enforces the constraints only
at its grid points (it may exceed a limit between them), while afford bounds
them on whole segments, so afford's durations are expected to be slightly
longer, never shorter, than the fine-grid reference. The column "natural"
is toppra's optimum on a natural cubic spline through the same waypoints
(the interpolant afford used before), to show what the path change costs.

Near hands (cases with "tool_path" and "hands": every piece of the real
paths of four examples with hands) toppra also bounds the tool speed as
afford's program does: the speed of the tool-space interpolant (the tool
positions blended with the joint path's knots and radii) within the
speed-and-separation cap at its distance from the nearest hand sphere
(planner/src/timing/separation.rs, reimplemented below), less afford's
margins on the cap. afford times these pieces without the arm's forward
kinematics (the interpolant only: the real tool's check, which can only
lower the caps, is not part of the comparison).
"""

import argparse
import json
import sys

import numpy as np
import toppra
import toppra.algorithm
import toppra.constraint
from scipy.interpolate import PPoly


def chord_knots(waypoints):
    steps = np.linalg.norm(np.diff(waypoints, axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(steps)])


class PiecewisePath(toppra.interpolator.AbstractGeometricPath):
    """afford's path: breakpoints and per-piece [c0, c1, c2, c3] per joint."""

    def __init__(self, breakpoints, coefficients):
        c = np.asarray(coefficients, dtype=float)  # (pieces, joints, 4)
        self.poly = PPoly(np.transpose(c[:, :, ::-1], (2, 0, 1)), np.asarray(breakpoints, dtype=float))
        self.derivatives = [self.poly, self.poly.derivative(1), self.poly.derivative(2)]
        self.breakpoints = np.asarray(breakpoints, dtype=float)

    def __call__(self, path_positions, order=0):
        return self.derivatives[order](path_positions)

    @property
    def dof(self):
        return self.poly.c.shape[2]

    @property
    def path_interval(self):
        return np.array([self.breakpoints[0], self.breakpoints[-1]])

    @property
    def waypoints(self):
        return self.breakpoints, self.poly(self.breakpoints)


def tool_speed_cap(rule, d):
    """The tool-speed cap (m/s) at hand distance d (m): separation.rs's rule."""
    v_h = rule["human_speed_far_m_s"] if d > rule["human_speed_far_beyond_m"] else rule["human_speed_m_s"]
    a_s, t_r = rule["stop_deceleration_m_s2"], rule["reaction_time_s"]
    constant = rule["intrusion_distance_m"] + rule["sensing_uncertainty_m"] + rule["robot_uncertainty_m"]
    qa, qb, qc = 1.0 / (2.0 * a_s), t_r + v_h / a_s, v_h * t_r + constant - d
    v = 0.0 if qc >= 0.0 else 2.0 * qc / (-qb - np.sqrt(qb * qb - 4.0 * qa * qc))
    if d <= rule["reduced_speed_distance_m"]:
        v = min(v, rule["reduced_speed_m_s"])
    return max(v, rule["min_tool_speed_m_s"])


class ToolSpeedConstraint(toppra.constraint.LinearConstraint):
    """||p'(s)||^2 sdot^2 <= (shrink * cap(d(p(s))))^2 at every grid point."""

    def __init__(self, tool, hands, rule, shrink, dof):
        super().__init__()
        self.tool, self.hands, self.rule, self.shrink, self.dof = tool, hands, rule, shrink, dof

    def compute_constraint_params(self, path, gridpoints):
        positions, tangents = self.tool(gridpoints), self.tool(gridpoints, 1)
        xbound = np.zeros((len(gridpoints), 2))
        for i, (x, dx) in enumerate(zip(positions, tangents)):
            d = min(max(np.linalg.norm(x - np.array(h["centre"])) - h["radius"], 0.0) for h in self.hands)
            cap = self.shrink * tool_speed_cap(self.rule, d)
            xbound[i] = [0.0, cap * cap / max(float(dx @ dx), 1e-300)]
        return None, None, None, None, None, None, xbound


def toppra_duration(path, vlim, alim, gridpoints, tool_speed=None):
    constraints = [
        toppra.constraint.JointVelocityConstraint(np.vstack([-vlim, vlim]).T),
        toppra.constraint.JointAccelerationConstraint(np.vstack([-alim, alim]).T),
    ]
    if tool_speed is not None:
        constraints.append(tool_speed)
    start, end = path.path_interval
    grid = np.linspace(start, end, gridpoints + 1)
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
    parser.add_argument("--segments", default="300", choices=["100", "200", "300", "400", "1000"],
                        help="afford's segment count to judge")
    args = parser.parse_args()
    toppra.setup_logging("WARNING")
    with open(args.cases) as f:
        cases = json.load(f)["cases"]

    worst = 0.0
    columns = ["100", "200", "300", "400", "1000"]
    print(f"{'case':>30} {'toppra fine':>12} {'natural':>11} " + " ".join(f"{'afford ' + c:>12}" for c in columns) + f" {'diff ' + args.segments + ' %':>11}")
    for k, case in enumerate(cases):
        waypoints = np.array(case["waypoints"], dtype=float)
        vlim = np.array(case["velocity_limits"], dtype=float)
        alim = np.array(case["acceleration_limits"], dtype=float)
        ours = case["afford_duration_s"]
        natural_path = toppra.SplineInterpolator(chord_knots(waypoints), waypoints, bc_type="natural")
        # Near hands the natural spline has no tool path to cap: not compared.
        natural = np.nan if "tool_path" in case else toppra_duration(natural_path, vlim, alim, args.fine)
        # Cases written before the blended path (no "path") timed the natural spline.
        tool_speed = None
        if "tool_path" in case:
            tool = PiecewisePath(case["tool_path"]["breakpoints"], case["tool_path"]["coefficients"])
            tool_speed = ToolSpeedConstraint(tool, case["hands"], case["rule"], case["tool_shrink"], len(vlim))
        if "path" in case:
            path = PiecewisePath(case["path"]["breakpoints"], case["path"]["coefficients"])
            fine = toppra_duration(path, vlim, alim, args.fine, tool_speed)
        else:
            fine = natural
        diff = 100.0 * (ours[args.segments] - fine) / fine
        worst = max(worst, abs(diff))
        print(f"{case.get('name', k):>30} {fine:>12.5f} {natural:>11.5f} " + " ".join(f"{ours[c]:>12.5f}" for c in columns) + f" {diff:>+11.3f}")
    print(f"largest |difference| at {args.segments} segments: {worst:.3f} % (tolerance {args.tolerance} %)")
    return 0 if worst <= args.tolerance else 1


if __name__ == "__main__":
    sys.exit(main())
