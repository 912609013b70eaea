"""Where the smoothness gap comes from: the final greedy policies of the comparison runs, bin by bin.

For every finished run of the listed algorithms that still has its ``model.zip`` (``docs/results/*/runs/`` is
not committed: the runs must have been trained on this machine), 10 greedy episodes (reset seeds 20 000 + k,
none of them seen by the runner's evaluations) give the runner's figures (task return, penalty, |a|, |da|,
SM with its spread over the episodes) and how the policy uses the bin grid: the share of action entries at
each of the 9 bin values of [-1, 1] (normalized actions; SAC's continuous actions are counted in the nearest
bin), the share at the extremes (the bins -1 and +1), the share of steps on which an entry changes, and the
share of consecutive changes that reverse direction (chatter): ``sb3_gqn.metrics.bin_usage``. Rows go to
``docs/results/final_policies.csv`` (replacing earlier rows of the same run); ``make readme-tables`` turns
the CSV into the README's table.

    .venv/bin/python docs/results/final_policies.py                    # the runs of the README's comparison
    .venv/bin/python docs/results/final_policies.py --algos gqn-adaptive decqn-9 --tables finger-spin_c0.1_100k
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np

RESULTS = Path("docs/results")
OUT = RESULTS / "final_policies.csv"
EPISODES, FIRST_SEED = 10, 20_000
BIN_VALUES = np.linspace(-1.0, 1.0, 9)
COLUMNS = [
    "table",
    "algo",
    "env",
    "seed",
    "task_return",
    "action_penalty",
    "action_magnitude",
    "action_change",
    "smoothness",
    "smoothness_std",
    "extreme_share",
    "change_rate",
    "reversal_rate",
    *(f"share_{value:+.2f}" for value in BIN_VALUES),
]


def probe(run_dir: Path) -> dict[str, float | str]:
    import torch as th
    from rl_zoo3.utils import get_wrapper_class
    from stable_baselines3 import SAC

    from sb3_gqn import GQN
    from sb3_gqn.benchmark import RunSpec, _shipped_entry, penalized_wrappers, run_overrides
    from sb3_gqn.metrics import bin_usage, control_frequency, normalized_actions, smoothness
    from sb3_gqn.zoo import register

    th.set_num_threads(1)
    register()  # the dm_control and Meta-World ids
    spec = RunSpec(**json.loads((run_dir / "done.json").read_text())["spec"])
    zoo_algo, _ = run_overrides(spec)
    wrappers = penalized_wrappers(_shipped_entry(zoo_algo, spec.env).get("env_wrapper"), spec.penalty)
    env = get_wrapper_class({"env_wrapper": wrappers})(gym.make(spec.env))
    model = (SAC if zoo_algo == "sac" else GQN).load(run_dir / "model.zip", device="cpu")
    freq = control_frequency(env) or 1.0
    episodes, figures = [], []
    for episode in range(EPISODES):
        observation, _ = env.reset(seed=FIRST_SEED + episode)
        actions, task_return, done = [], 0.0, False
        while not done:
            action, _ = model.predict(observation, deterministic=True)
            observation, reward, terminated, truncated, info = env.step(action)
            actions.append(np.asarray(action, dtype=np.float64).reshape(-1))
            task_return += float(info.get("task_reward", reward))
            done = terminated or truncated
        scaled = normalized_actions(np.stack(actions), env.action_space)
        episodes.append(scaled)
        figures.append(
            [
                task_return,
                float((scaled**2).sum()),
                float(np.abs(scaled).mean()),
                float(np.abs(np.diff(scaled, axis=0)).mean()),
                smoothness(scaled, freq),
            ]
        )
    means = np.mean(figures, axis=0)
    usage = [bin_usage(actions, BIN_VALUES) for actions in episodes]
    return {
        "table": run_dir.parent.parent.name,
        "algo": spec.algo,
        "env": spec.env,
        "seed": spec.seed,
        **dict(zip(COLUMNS[4:9], map(float, means))),
        "smoothness_std": float(np.std([row[4] for row in figures])),
        **{
            key: float(np.mean([getattr(episode, key) for episode in usage]))
            for key in ("extreme_share", "change_rate", "reversal_rate")
        },
        **{
            f"share_{value:+.2f}": float(np.mean([episode.shares[k] for episode in usage]))
            for k, value in enumerate(BIN_VALUES)
        },
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--algos", nargs="+", default=["gqn-adaptive", "gqn-linear", "decqn-9", "sac"])
    parser.add_argument("--tables", nargs="+", default=None, help="result folders under docs/results (default: all)")
    args = parser.parse_args(argv)
    every_table = sorted(path.parent for path in RESULTS.glob("*/results.csv"))
    tables = [RESULTS / name for name in args.tables] if args.tables else every_table
    run_dirs = [
        run_dir
        for table in tables
        for run_dir in sorted((table / "runs").glob("*"))
        if (run_dir / "model.zip").is_file()
        and (run_dir / "done.json").is_file()
        and json.loads((run_dir / "done.json").read_text())["spec"]["algo"].split("+")[0] in args.algos
    ]
    rows = {(row["table"], row["algo"], row["env"], row["seed"]): row for row in _read(OUT)}
    for run_dir in run_dirs:
        row = probe(run_dir)
        rows[(str(row["table"]), str(row["algo"]), str(row["env"]), str(row["seed"]))] = row
        sm, extremes = float(row["smoothness"]), float(row["extreme_share"])
        print(f"{row['table']} {row['algo']} seed {row['seed']}: SM {sm:.4f}, extremes {extremes:.2f}")
    with open(OUT, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=COLUMNS)
        writer.writeheader()
        for key in sorted(rows):
            writer.writerow({column: _rounded(rows[key][column]) for column in COLUMNS})
    print(f"{OUT}: {len(rows)} runs")
    return 0


def _read(path: Path) -> list[dict[str, str]]:
    if not path.is_file():
        return []
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def _rounded(value: float | str) -> float | str:
    return round(float(value), 6) if isinstance(value, float) else value


if __name__ == "__main__":
    sys.exit(main())
