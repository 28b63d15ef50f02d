"""Python's overhead on a plan: `afford.plan` (median of N) against the same plan in Rust
(`afford bench pipeline`, median of N, same scenario and options), in rounds that
alternate the two so a busy machine slows both alike.

    python python/bench/overhead.py [SCENARIO] [--runs N] [--rounds R] [--afford PATH]

Prints both medians in ms and their ratio (target: at most 1.2). A benchmark, not a test:
nothing here fails on a slow machine.
"""

import argparse
import json
import statistics
import subprocess
import time
from pathlib import Path

import afford

REPO = Path(__file__).resolve().parents[2]


def rust_ms(afford_bin: Path, scenario: Path, runs: int) -> float:
    """The median wall time of one whole plan in Rust, ms."""
    out = subprocess.run(
        [str(afford_bin), "bench", "pipeline", str(scenario), "--runs", str(runs), "--json"],
        capture_output=True, text=True, check=True, cwd=REPO,
    ).stdout
    report = json.loads(out)
    return report["median_ms_per_subgoal"] * report["subgoals"]


def python_ms(scenario: afford.Scenario, runs: int) -> list[float]:
    """Wall time of each of `runs` calls of afford.plan, ms (arrays included)."""
    times = []
    for _ in range(runs):
        started = time.perf_counter()
        plan = afford.plan(scenario)
        times.append((time.perf_counter() - started) * 1e3)
        assert plan.subgoals and plan.subgoals[0].positions.shape[0] > 0
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", nargs="?", type=Path, default=REPO / "examples" / "sort-blue-squares.yaml")
    parser.add_argument("--runs", type=int, default=21)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--afford", type=Path, default=REPO / "target" / "release" / "afford")
    args = parser.parse_args()
    scenario = afford.Scenario.from_file(args.scenario)
    afford.plan(scenario)  # warm-up: numpy imported, robot loaded once
    rust, python = [], []
    for _ in range(args.rounds):
        rust.append(rust_ms(args.afford, args.scenario, args.runs))
        python.extend(python_ms(scenario, args.runs))
    rust_median = statistics.median(rust)
    python_median = statistics.median(python)
    report = {
        "scenario": str(args.scenario.relative_to(REPO) if args.scenario.is_relative_to(REPO) else args.scenario),
        "runs": args.runs * args.rounds,
        "rust_median_ms": round(rust_median, 2),
        "rust_round_medians_ms": [round(r, 2) for r in rust],
        "python_median_ms": round(python_median, 2),
        "ratio": round(python_median / rust_median, 3),
    }
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
