"""The gymnasium env behaves as afford's learner's MDP: afford's own CQL plan,
replayed in the env, ends with a successful DROP on every exported scene."""

import json

import numpy as np
import pytest

import afford_mdp
from afford_mdp import ACTIONS, DONE, REFUSED, AffordGridEnv


def test_env_replays_afford_plan_to_drop_on_every_scene(mdps):
    replayed = 0
    for mdp in mdps:
        plan = mdp.cql_plan
        if not plan["solved"]:
            # afford's CQL never fails a solvable grid (docs/design/grid-and-cql.md).
            assert not mdp.solvable, f"{mdp.name}: CQL failed a solvable MDP"
            continue
        env = AffordGridEnv(mdp)
        success, total, steps = afford_mdp.replay(env, plan["actions"])
        assert success, f"{mdp.name}: afford's plan does not end with DROP in the env"
        assert steps == len(plan["actions"]) >= mdp.optimal_length
        # The plan's rewards: +10 for GOAL and +10 for the final DROP.
        assert total == pytest.approx(20.0), mdp.name
        replayed += 1
    solvable = sum(m.solvable for m in mdps)
    assert replayed == solvable > 0, f"{replayed} plans replayed, {solvable} scenes solvable"


def test_plan_cut_short_is_no_success(mdps):
    mdp = next(m for m in mdps if m.cql_plan["solved"])
    env = AffordGridEnv(mdp)
    success, _, steps = afford_mdp.replay(env, mdp.cql_plan["actions"][:-1])
    assert not success and steps == len(mdp.cql_plan["actions"]) - 1


def test_refused_action_leaves_agent_in_place_with_penalty(mdps):
    mdp = mdps[0]
    env = AffordGridEnv(mdp)
    obs, _ = env.reset()
    refused = np.flatnonzero(mdp.next[mdp.start_state] == REFUSED)
    assert refused.size, "the start state affords everything"
    obs2, r, terminated, truncated, info = env.step(int(refused[0]))
    assert info["refused"] and not terminated and not truncated
    assert r == mdp.reward[mdp.start_state, refused[0]] < 0
    np.testing.assert_array_equal(obs, obs2)


def test_episode_truncates_after_afford_episode_length(mdps):
    mdp = mdps[0]
    env = AffordGridEnv(mdp)
    env.reset()
    truncated, steps = False, 0
    while not truncated:
        _, _, terminated, truncated, _ = env.step(ACTIONS.index("GRASP"))
        assert not terminated
        steps += 1
    assert steps == mdp.episode_steps


def test_greedy_rollout_of_the_plan_succeeds_and_a_loop_fails(mdps):
    mdp = next(m for m in mdps if m.cql_plan["solved"])
    greedy = np.zeros(mdp.states, dtype=np.int64)
    s = mdp.start_state
    for name in mdp.cql_plan["actions"]:
        greedy[s] = ACTIONS.index(name)
        if mdp.next[s, greedy[s]] != DONE:
            s = int(mdp.next[s, greedy[s]])
    assert afford_mdp.greedy_rollout(mdp, greedy) == (True, len(mdp.cql_plan["actions"]))
    assert afford_mdp.greedy_rollout(mdp, np.full(mdp.states, ACTIONS.index("DROP")))[0] is False


def test_observations_identify_the_state(mdps):
    mdp = mdps[0]
    obs = afford_mdp.observations(mdp)
    assert len({o.tobytes() for o in obs}) == mdp.states


def test_reader_refuses_another_format_version(mdps, tmp_path):
    data = json.loads(mdps[0].path.read_text())
    data["format_version"] = 99
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    with pytest.raises(afford_mdp.ExportError, match="format_version"):
        afford_mdp.load(bad)
