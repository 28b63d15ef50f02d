"""Bad input never crashes the interpreter: fuzzed scenario dicts give a scenario or
`afford.BadInput`, never another exception; a panic inside afford is InternalError."""

import subprocess
import sys
import textwrap

import afford
from conftest import EXAMPLES

FUZZ = textwrap.dedent(
    """
    import copy, random, sys
    import afford

    base = afford.Scenario.from_file(sys.argv[1]).to_dict()
    odd = [None, -1, 0, 1e308, -1e-308, 2**70, "", "x" * 300, [], {}, [[[]]], True,
           {"box": [0, 0, 0, 0]}, [1, 2, 3, 4], float("nan"), float("inf"), (1, 2), b"bytes"]

    def paths(value, path=()):
        yield path
        if isinstance(value, dict):
            for k, v in value.items():
                yield from paths(v, path + (k,))
        elif isinstance(value, list):
            for k, v in enumerate(value):
                yield from paths(v, path + (k,))

    def mutate(data, rng):
        data = copy.deepcopy(data)
        for _ in range(rng.randint(1, 3)):
            path = rng.choice(list(paths(data))[1:])
            parent = data
            for key in path[:-1]:
                parent = parent[key]
            roll = rng.random()
            if roll < 0.7:
                parent[path[-1]] = copy.deepcopy(rng.choice(odd))
            elif roll < 0.85 and isinstance(parent, dict):
                del parent[path[-1]]
            else:
                nested = []
                for _ in range(rng.randint(1, 60)):
                    nested = [nested]
                parent[path[-1]] = nested
        return data

    rng = random.Random(int(sys.argv[2]))
    read = refused = planned = 0
    for case in range(int(sys.argv[3])):
        data = mutate(base, rng)
        try:
            scenario = afford.Scenario.from_dict(data)
        except afford.BadInput as e:
            assert isinstance(e.field, str) and e.message, e
            refused += 1
            continue
        read += 1
        if planned < 4:
            try:
                afford.plan(scenario, until="grid")
            except afford.BadInput:
                pass
            planned += 1
    print(f"{read} read, {refused} refused, {planned} planned")
    """
)


def test_fuzzed_scenario_dicts_never_crash_the_interpreter():
    done = subprocess.run(
        [sys.executable, "-c", FUZZ, str(EXAMPLES / "sort-blue-squares.yaml"), "11", "300"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    read, refused = (int(w) for w in done.stdout.split()[0:4:2])
    assert refused > 100 and read + refused == 300


OBSERVE = textwrap.dedent(
    """
    import random, sys
    import afford

    scenario = afford.Scenario.from_file(sys.argv[1])
    monitor = afford.Monitor(scenario, afford.plan(scenario))
    hand = {"name": "hand-1", "box": [200, 250, 40, 40], "height": 0.08}
    odd = [None, -1, 1e308, "", [], {}, [1, 2], float("nan"), True, "hand-1", [[[]]]]
    rng = random.Random(int(sys.argv[2]))
    verdicts = refused = 0
    for case in range(int(sys.argv[3])):
        if rng.random() < 0.4:
            # A hand the camera could see, somewhere on the table, or none.
            box = [rng.uniform(0, 600), rng.uniform(0, 440), 40, 40]
            hands = rng.choice([[dict(hand, box=box)], []])
        else:
            entry = dict(hand)
            key = rng.choice(["name", "box", "height", "extra"])
            entry[key] = rng.choice(odd)
            hands = rng.choice([[entry], entry, [entry, entry], [hand, hand], "hands"])
        try:
            monitor.observe(monitor.clock, hands=hands)
            verdicts += 1
        except afford.BadInput as e:
            assert e.field.startswith("hands"), e
            refused += 1
        monitor.advance(0.05)
    print(verdicts, refused, monitor.status)
    """
)


def test_fuzzed_observations_never_crash_the_interpreter():
    done = subprocess.run(
        [sys.executable, "-c", OBSERVE, str(EXAMPLES / "monitor" / "hand-in-the-way.yaml"), "5", "120"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    verdicts, refused, _ = done.stdout.split()
    assert int(refused) > 40 and int(verdicts) > 20
    assert int(verdicts) + int(refused) == 120


def test_a_panic_inside_afford_is_an_internal_error_not_a_crash():
    code = textwrap.dedent(
        """
        import afford, afford._afford as core
        try:
            core._panic("deliberate")
        except afford.InternalError as e:
            assert "deliberate" in str(e), e
            print("caught")
        print(afford.plan(afford.Scenario.default(), until="grid").subgoals[0].object)
        """
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["caught", "blue-square-1"]
