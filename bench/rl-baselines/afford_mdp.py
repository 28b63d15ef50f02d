"""afford's grid MDP (`afford export-mdp`, docs/guide/mdp-export.md) as a gymnasium env.

The transitions and rewards are the exported tables, produced by the code
afford's learners run (planner/src/discrete/task.rs, cql.rs): this module
only looks them up, it restates no rule of the task.

- State index: (row * cols + col) * 2 + holding.
- `next[s][a]`: next state, REFUSED (-1: the scene does not afford the
  action; the agent stays, reward `reward[s][a]`, as afford's plain QL) or
  DONE (-2: the terminal DROP).
- An episode is truncated after `episode_steps` steps, the length after
  which afford's learner restarts an episode.
- Observation: one-hot row, one-hot column and the holding flag
  (rows + cols + 1 floats): the agent's state, which is all that changes
  within one MDP.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import gymnasium as gym
import numpy as np

FORMAT_VERSION = 1
REFUSED = -1
DONE = -2
ACTIONS = ["UP", "DOWN", "LEFT", "RIGHT", "GRASP", "DROP", "GOAL"]


class ExportError(ValueError):
    """An export file that this reader cannot use, with the file and field named."""


@dataclass
class Mdp:
    """One exported MDP (the fields of docs/guide/mdp-export.md that learners need)."""

    name: str
    rows: int
    cols: int
    start_state: int
    next: np.ndarray  # (states, 7) int64
    reward: np.ndarray  # (states, 7) float64
    episode_steps: int
    optimal_length: int | None
    cql_plan: dict
    learners: dict | None
    path: Path

    @property
    def states(self) -> int:
        return self.rows * self.cols * 2

    @property
    def solvable(self) -> bool:
        return self.optimal_length is not None


def load(path: str | Path) -> Mdp:
    """Reads and checks one export file."""
    path = Path(path)
    data = json.loads(path.read_text())

    def field(name):
        if name not in data:
            raise ExportError(f"{path}: field `{name}` is missing")
        return data[name]

    version = field("format_version")
    if version != FORMAT_VERSION:
        raise ExportError(f"{path}: format_version is {version}, this reader knows {FORMAT_VERSION}")
    if field("actions") != ACTIONS:
        raise ExportError(f"{path}: actions are {data['actions']}, expected {ACTIONS}")
    rows, cols = int(field("rows")), int(field("cols"))
    states = rows * cols * 2
    nxt = np.asarray(field("next"), dtype=np.int64)
    rew = np.asarray(field("reward"), dtype=np.float64)
    for name, table in (("next", nxt), ("reward", rew)):
        if table.shape != (states, len(ACTIONS)):
            raise ExportError(f"{path}: `{name}` has shape {table.shape}, expected ({states}, 7)")
    if ((nxt < DONE) | (nxt >= states)).any():
        raise ExportError(f"{path}: `next` holds a state outside 0..{states}")
    start = int(field("start_state"))
    if not 0 <= start < states:
        raise ExportError(f"{path}: start_state {start} is outside 0..{states}")
    return Mdp(
        name=field("name"),
        rows=rows,
        cols=cols,
        start_state=start,
        next=nxt,
        reward=rew,
        episode_steps=int(field("episode_steps")),
        optimal_length=field("optimal_length"),
        cql_plan=field("cql_plan"),
        learners=data.get("learners"),
        path=path,
    )


def load_dir(folder: str | Path) -> list[Mdp]:
    """Every export in a folder, in scene order (bench-SEED-INDEX by index)."""

    def key(p: Path):
        tail = p.stem.rsplit("-", 1)[-1]
        return (p.stem.rsplit("-", 1)[0], int(tail) if tail.isdigit() else 0, p.stem)

    return [load(p) for p in sorted(Path(folder).glob("*.json"), key=key)]


def observations(mdp: Mdp) -> np.ndarray:
    """The observation of every state, (states, rows + cols + 1) float32."""
    index = np.arange(mdp.states)
    cell, holding = index // 2, index % 2
    obs = np.zeros((mdp.states, mdp.rows + mdp.cols + 1), dtype=np.float32)
    obs[index, cell // mdp.cols] = 1.0
    obs[index, mdp.rows + cell % mdp.cols] = 1.0
    obs[index, -1] = holding
    return obs


class AffordGridEnv(gym.Env):
    """The exported MDP as a gymnasium env (deterministic; `reset` seeds nothing random)."""

    metadata = {"render_modes": []}

    def __init__(self, mdp: Mdp):
        self.mdp = mdp
        self._obs = observations(mdp)
        self.observation_space = gym.spaces.Box(0.0, 1.0, shape=self._obs.shape[1:], dtype=np.float32)
        self.action_space = gym.spaces.Discrete(len(ACTIONS))
        self.state = mdp.start_state
        self.steps = 0

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.state, self.steps = self.mdp.start_state, 0
        return self._obs[self.state].copy(), {"state": self.state}

    def step(self, action):
        a = int(action)
        nxt, r = int(self.mdp.next[self.state, a]), float(self.mdp.reward[self.state, a])
        self.steps += 1
        terminated = nxt == DONE
        refused = nxt == REFUSED
        if not terminated and not refused:
            self.state = nxt
        truncated = not terminated and self.steps >= self.mdp.episode_steps
        info = {"state": self.state, "refused": refused, "success": terminated}
        return self._obs[self.state].copy(), r, terminated, truncated, info


def greedy_rollout(mdp: Mdp, greedy: np.ndarray) -> tuple[bool, int]:
    """Follows a deterministic policy (`greedy[s]` = action) from the start, as
    afford's greedy rollout does: success on DROP; failure on a refused action
    or a repeated state (a deterministic policy that repeats a state loops).
    Returns (success, actions taken)."""
    seen = np.zeros(mdp.states, dtype=bool)
    s, steps = mdp.start_state, 0
    while not seen[s]:
        seen[s] = True
        nxt = int(mdp.next[s, int(greedy[s])])
        steps += 1
        if nxt == DONE:
            return True, steps
        if nxt == REFUSED:
            return False, steps
        s = nxt
    return False, steps


def replay(env: AffordGridEnv, actions: list[str]) -> tuple[bool, float, int]:
    """Steps the env through named actions from a reset.
    Returns (terminated with DROP, total reward, steps taken)."""
    env.reset()
    total, steps = 0.0, 0
    for name in actions:
        _, r, terminated, truncated, _ = env.step(ACTIONS.index(name))
        total += r
        steps += 1
        if terminated or truncated:
            return terminated and name == "DROP", total, steps
    return False, total, steps
