#!/usr/bin/env python3
"""Cost of a cluttered table: plan time and peak memory of `afford plan`
against the number of objects on the table (8, 32, 128, 256 by default).

Each scene is the iiwa's extra-pieces calibration with one sub-goal (a red
square beside the left box, moved into it) and the rest of the objects as
14 x 14 px cubes on a lattice over the right of the table, clear of the
route. Every run is a fresh process; peak memory is that process's maximum
resident set (wait4), time its wall clock, the median of `--runs`.

    python3 scripts/clutter-growth.py [--afford target/release/afford] [--runs 3]
"""

import argparse
import math
import os
import statistics
import subprocess
import tempfile
import time


def scene(count: int) -> str:
    clutter = count - 1
    cols = max(1, math.ceil(math.sqrt(clutter)))
    rows = max(1, math.ceil(clutter / cols))
    # Lattice over x in [250, 620], y in [20, 460] (pixels), 14 px cubes.
    dx = (620 - 250 - 14) / max(cols - 1, 1)
    dy = (460 - 20 - 14) / max(rows - 1, 1)
    lines = [
        "afford: 1",
        f"name: clutter-{count}",
        "camera:",
        "  width: 640",
        "  height: 480",
        "  pixel_to_base: [[0.0, -0.000625, 0.66], [-0.000625, 0.0, 0.20]]",
        "  table_z: -0.40",
        "robot:",
        "  model: kuka_iiwa14",
        "  start: [80, 200]",
        "objects:",
        "  - {name: red-square-1, color: red, shape: square, box: [60, 120, 40, 40], height: 0.03}",
    ]
    for k in range(clutter):
        r, c = divmod(k, cols)
        u, v = 250 + c * dx, 20 + r * dy
        lines.append(
            f"  - {{name: clutter-{k + 1}, color: green, shape: circle, "
            f"box: [{u:.1f}, {v:.1f}, 14, 14], height: 0.02}}"
        )
    lines += [
        "goals:",
        "  - {name: left box, box: [20, 300, 120, 120], height: 0.10}",
        'instruction: "Put the red square in the left box."',
    ]
    return "\n".join(lines) + "\n"


def run(afford: str, path: str, out: str) -> tuple[float, int, int]:
    """Wall time (s), peak resident set (KiB) and exit code of one plan."""
    start = time.perf_counter()
    child = subprocess.Popen(
        [afford, "plan", path, "--seed", "1", "-o", out],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - start
    return wall, usage.ru_maxrss, os.waitstatus_to_exitcode(status)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--afford", default="target/release/afford")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--counts", default="8,32,128,256")
    args = parser.parse_args()
    counts = [int(c) for c in args.counts.split(",")]
    print("| objects | exit | plan time, median (s) | peak memory (MiB) |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for count in sorted(counts):
            path = os.path.join(tmp, f"clutter-{count}.yaml")
            with open(path, "w") as f:
                f.write(scene(count))
            out = os.path.join(tmp, f"plan-{count}.json")
            results = [run(args.afford, path, out) for _ in range(args.runs)]
            wall = statistics.median(r[0] for r in results)
            peak = max(r[1] for r in results) / 1024
            codes = sorted({r[2] for r in results})
            print(f"| {count} | {','.join(map(str, codes))} | {wall:.3f} | {peak:.1f} |")


if __name__ == "__main__":
    main()
