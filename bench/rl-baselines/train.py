"""Trains stable-baselines3 DQN, PPO and A2C on one exported MDP and measures them.

Success: the greedy (deterministic) policy, followed from the start state,
ends with DROP (`afford_mdp.greedy_rollout`: a refused action or a repeated
state is a failure, as in afford's greedy rollout).

Convergence: the greedy policy is evaluated every `eval_every` environment
steps (one batched forward pass over all states); training stops when it has
succeeded at `patience` consecutive evaluations, or when the step budget runs
out. Steps to converge = environment steps trained when training stopped on
convergence: like afford's count, which includes its own stability window
(100 identical successful greedy rollouts).

Cost: wall time (time.perf_counter), CPU time of this process
(time.process_time; torch runs on one thread), and energy from RAPL
(/sys/class/powercap/intel-rapl:*) when readable, else None. RAPL counts the
whole CPU package, other processes included.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import torch
from stable_baselines3 import A2C, DQN, PPO
from stable_baselines3.common.callbacks import BaseCallback

import afford_mdp
from afford_mdp import AffordGridEnv, Mdp

ALGORITHMS = {"DQN": DQN, "PPO": PPO, "A2C": A2C}

# stable-baselines (2.x, the paper's library) defaults, as far as
# stable-baselines3 can express them; net [64, 64] MLP for all three.
# Exception: DQN trains every 4 steps (stable-baselines3's default; 2.x
# trained every step), which makes it about 3 times cheaper per step.
HYPERPARAMETERS = {
    "DQN": dict(
        learning_rate=5e-4,
        buffer_size=50_000,
        learning_starts=1_000,
        batch_size=32,
        gamma=0.99,
        train_freq=4,
        target_update_interval=500,
        exploration_fraction=0.1,
        exploration_final_eps=0.02,
    ),
    "PPO": dict(
        learning_rate=2.5e-4,
        n_steps=128,
        batch_size=32,
        n_epochs=4,
        gamma=0.99,
        gae_lambda=0.95,
        clip_range=0.2,
        ent_coef=0.01,
        vf_coef=0.5,
    ),
    "A2C": dict(
        learning_rate=7e-4,
        n_steps=5,
        gamma=0.99,
        ent_coef=0.01,
        vf_coef=0.25,
        rms_prop_eps=1e-5,
    ),
}
POLICY_KWARGS = dict(net_arch=[64, 64])


@dataclass
class Budget:
    """What one training run may spend."""

    timesteps: int = 5_000
    eval_every: int = 250
    patience: int = 3


@dataclass
class RunResult:
    scene: str
    algorithm: str
    solvable: bool
    success: bool
    converged: bool
    steps: int
    wall_s: float
    cpu_s: float
    energy_j: float | None
    # (timesteps, greedy success) at every evaluation.
    curve: list = field(default_factory=list)


class GreedyCheck(BaseCallback):
    """Evaluates the greedy policy every `eval_every` steps; stops on `patience` successes in a row."""

    def __init__(self, mdp: Mdp, budget: Budget):
        super().__init__()
        self.mdp, self.budget = mdp, budget
        self.obs = torch.as_tensor(afford_mdp.observations(mdp))
        self.curve: list[tuple[int, bool]] = []
        self.streak = 0

    def greedy_success(self) -> bool:
        with torch.no_grad():
            greedy = greedy_actions(self.model, self.obs)
        return afford_mdp.greedy_rollout(self.mdp, greedy)[0]

    def _on_step(self) -> bool:
        if self.num_timesteps % self.budget.eval_every:
            return True
        ok = self.greedy_success()
        self.curve.append((self.num_timesteps, ok))
        self.streak = self.streak + 1 if ok else 0
        return self.streak < self.budget.patience


def greedy_actions(model, obs: torch.Tensor) -> np.ndarray:
    """The deterministic action of every state, one forward pass."""
    policy = model.policy
    policy.set_training_mode(False)
    obs = obs.to(policy.device)
    if isinstance(model, DQN):
        return policy.q_net(obs).argmax(dim=1).cpu().numpy()
    return policy.get_distribution(obs).mode().cpu().numpy()


def rapl_energy_uj() -> list[tuple[int, int]] | None:
    """(energy, wrap range) of each RAPL package domain, µJ; None when unreadable."""
    domains = sorted(Path("/sys/class/powercap").glob("intel-rapl:[0-9]*"))
    domains = [d for d in domains if d.name.count(":") == 1]
    try:
        readings = [
            (int((d / "energy_uj").read_text()), int((d / "max_energy_range_uj").read_text())) for d in domains
        ]
    except OSError:
        return None
    return readings or None


def energy_between(before, after) -> float | None:
    """Joules between two RAPL readings (counter wrap-around handled)."""
    if before is None or after is None:
        return None
    total = sum((b - a) % wrap for (a, wrap), (b, _) in zip(before, after))
    return total / 1e6


def train(mdp: Mdp, algorithm: str, budget: Budget, seed: int) -> RunResult:
    """One training run of `algorithm` on `mdp`."""
    torch.set_num_threads(1)
    env = AffordGridEnv(mdp)
    energy0, wall0, cpu0 = rapl_energy_uj(), time.perf_counter(), time.process_time()
    model = ALGORITHMS[algorithm](
        "MlpPolicy",
        env,
        seed=seed,
        device="cpu",
        verbose=0,
        policy_kwargs=POLICY_KWARGS,
        **HYPERPARAMETERS[algorithm],
    )
    check = GreedyCheck(mdp, budget)
    model.learn(total_timesteps=budget.timesteps, callback=check)
    converged = check.streak >= budget.patience
    success = converged or check.greedy_success()
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    energy = energy_between(energy0, rapl_energy_uj())
    steps = int(model.num_timesteps)
    if not check.curve or check.curve[-1][0] != steps:
        check.curve.append((steps, success))
    return RunResult(
        scene=mdp.name,
        algorithm=algorithm,
        solvable=mdp.solvable,
        success=bool(success),
        converged=converged,
        steps=steps,
        wall_s=wall,
        cpu_s=cpu,
        energy_j=energy,
        curve=[(int(t), bool(ok)) for t, ok in check.curve],
    )


def result_dict(result: RunResult) -> dict:
    return asdict(result)
