"""Decodings of a trained GQN's utilities into actions that need no retraining, measured against the greedy argmax.

A greedy argmax over bins is a discontinuous function of the state: near a decision boundary the action chatters
between bins. Two decodings act on the same utilities ``u[j, k]`` (dimension ``j``, active bin ``k``):

- :class:`Hysteresis` ``(margin)``: per dimension, keep the previous step's bin unless another active bin's utility
  beats it by more than ``margin`` (the first step of an episode is greedy);
- :class:`SoftmaxExpectation` ``(temperature)``: per dimension, the expected bin value under
  ``softmax(u[j, :] / temperature)`` over the active bins, a continuous action (``Box`` envs only); with
  ``relative=True`` the temperature is scaled by the state's spread ``max u[j, :] - min u[j, :]`` (GQN's
  ``decoding="relative"``).

:func:`compare_decodings` evaluates each on a trained model with the suite's greedy-episode protocol and reports task
return, return, SM and ``|Δa|`` (:func:`sb3_gqn.common.evaluation.rollout_figures`).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import torch as th

from sb3_gqn.common.evaluation import rollout_figures
from sb3_gqn.common.masking import masked_expectation
from sb3_gqn.gqn.gqn import GQN


class Decoding:
    """Greedy decoding: ``model.predict(obs, deterministic=True)``; the base of the others (SB3's ``predict``
    signature, so the suite's rollouts take it as a model)."""

    name = "greedy"

    def __init__(self, model: GQN):
        self.model = model

    def reset(self) -> None:
        """Forget the previous episode (called at every env reset)."""

    def utilities(self, observation: Any) -> np.ndarray:
        """The acting network's utilities ``(action_dims, max_bins)`` for one observation, ``-inf`` on inactive bins."""
        policy = self.model.policy
        obs_tensor, _ = policy.obs_to_tensor(observation)
        with th.inference_mode():
            values = policy.greedy_utilities(obs_tensor)[0].cpu().numpy().astype(np.float64)
        mask = policy.active_bins_mask.cpu().numpy()
        return np.where(mask[None, :], values, -np.inf)

    def bins(self, observation: Any) -> np.ndarray:
        return self.utilities(observation).argmax(axis=1)

    def predict(self, observation: Any, state: Any = None, episode_start: Any = None, deterministic: bool = True) -> Any:
        bins = self.bins(observation)
        return self.model.to_env_action(bins[None])[0], state


class Hysteresis(Decoding):
    """Keep the previous bin of a dimension unless another active bin's utility exceeds it by more than ``margin``."""

    def __init__(self, model: GQN, margin: float):
        super().__init__(model)
        self.margin = float(margin)
        self.name = f"hysteresis {margin:g}"
        self.previous: np.ndarray | None = None

    def reset(self) -> None:
        self.previous = None

    def bins(self, observation: Any) -> np.ndarray:
        utilities = self.utilities(observation)
        best = utilities.argmax(axis=1)
        if self.previous is not None:
            kept = utilities[np.arange(len(best)), self.previous]
            best = np.where(utilities.max(axis=1) > kept + self.margin, best, self.previous)
        self.previous = best
        return best


class SoftmaxExpectation(Decoding):
    """The expected bin value under a softmax of the utilities at ``temperature``, per dimension (``Box`` envs);
    ``relative``: the temperature relative to the state's spread of utilities."""

    def __init__(self, model: GQN, temperature: float, relative: bool = False):
        super().__init__(model)
        if model.action_grid is None:
            raise ValueError("SoftmaxExpectation needs a Box action space (a continuous action between bin values)")
        self.temperature, self.relative = float(temperature), relative
        self.name = f"{'relative' if relative else 'softmax'} {temperature:g}"

    def predict(self, observation: Any, state: Any = None, episode_start: Any = None, deterministic: bool = True) -> Any:
        grid = self.model.action_grid
        assert grid is not None
        utilities = th.as_tensor(self.utilities(observation))  # -inf on inactive bins: weight 0
        mask = self.model.policy.active_bins_mask.cpu()
        bin_values = th.as_tensor(grid.values, dtype=utilities.dtype)
        values = masked_expectation(utilities[None], mask, bin_values, self.temperature, self.relative)[0].numpy()
        return values.reshape(grid.box.shape).astype(grid.box.dtype), state


class ResetsDecoding(gym.Wrapper):
    """Calls ``decoding.reset()`` at every reset of the wrapped env."""

    def __init__(self, env: gym.Env, decoding: Decoding):
        super().__init__(env)
        self.decoding = decoding

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        self.decoding.reset()
        return self.env.reset(**kwargs)


def compare_decodings(
    model: GQN, env: gym.Env, decodings: list[Decoding], n_episodes: int = 5, seed: int = 10_000
) -> list[dict[str, Any]]:
    """Each decoding's greedy-episode figures on ``env`` (the same seeded episodes for all): one row per decoding
    with ``decoding``, ``return``, ``task_return``, ``smoothness`` (SM) and ``action_change`` (``|Δa|``)."""
    rows = []
    for decoding in decodings:
        figures = rollout_figures(decoding, ResetsDecoding(env, decoding), n_episodes, seed=seed)
        rows.append(
            {
                "decoding": decoding.name,
                "return": figures.return_,
                "task_return": figures.task_return,
                "smoothness": figures.smoothness,
                "action_change": figures.action_change,
                "success": figures.success,
            }
        )
    return rows


def main(argv: list[str] | None = None) -> int:
    """``python -m sb3_gqn.experiments.decodings MODEL.zip ... --env ID --penalty C``: each model's greedy, hysteresis
    and softmax-expectation figures (a Markdown table per model, then the means over the models; ``--csv`` also writes
    the rows)."""
    import argparse

    import pandas as pd

    from sb3_gqn.common.envs import make_env
    from sb3_gqn.experiments.variants import RunSpec, make_eval_env
    from sb3_gqn.zoo.registration import register

    parser = argparse.ArgumentParser(description=main.__doc__)
    parser.add_argument("models", nargs="+")
    parser.add_argument("--env", required=True)
    parser.add_argument("--penalty", type=float, default=0.1)
    parser.add_argument(
        "--algo", help="the runner agent that trained the models: read them on the runner's evaluation env (its wrappers)"
    )
    parser.add_argument("--margins", type=float, nargs="*", default=[0.1, 0.3, 1.0, 3.0])
    parser.add_argument("--temperatures", type=float, nargs="*", default=[0.03, 0.1, 0.3, 1.0])
    parser.add_argument("--relative-temperatures", type=float, nargs="*", default=[])
    parser.add_argument("--episodes", type=int, default=5)
    parser.add_argument("--csv", help="also write every model's rows to this CSV file")
    args = parser.parse_args(argv)
    rows = []
    for path in args.models:
        if args.algo:
            register()
            env = make_eval_env(RunSpec(args.algo, args.env, args.penalty, 0, 1))
        else:
            env = make_env(args.env, action_penalty=args.penalty)
        model = GQN.load(path, env=env)
        decodings = [Decoding(model), *(Hysteresis(model, m) for m in args.margins)]
        decodings += [SoftmaxExpectation(model, t) for t in args.temperatures]
        decodings += [SoftmaxExpectation(model, t, relative=True) for t in args.relative_temperatures]
        for row in compare_decodings(model, env, decodings, n_episodes=args.episodes):
            rows.append({"model": path, **row})
        env.close()
    table = pd.DataFrame(rows)
    if args.csv:
        table.to_csv(args.csv, index=False)
    columns = ["return", "task_return", "smoothness", "action_change"]
    print("| model | decoding | return | task return | SM | |Δa| |\n| --- | --- | --- | --- | --- | --- |")
    for _, row in table.iterrows():
        print(f"| {row['model']} | {row['decoding']} | " + " | ".join(f"{row[c]:.4g}" for c in columns) + " |")
    print(f"\nMeans over {len(args.models)} models:\n\n| decoding | return | task return | SM | |Δa| |")
    print("| --- | --- | --- | --- | --- |")
    for decoding, means in table.groupby("decoding", sort=False)[columns].mean().iterrows():
        print(f"| {decoding} | " + " | ".join(f"{means[c]:.4g}" for c in columns) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
