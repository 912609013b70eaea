"""Where the smoothness gap comes from: the final greedy policies of the comparison runs, bin by bin.

For every finished run of the listed algorithms that still has its ``model.zip`` (``docs/results/*/runs/`` is
not committed: the runs must have been trained on this machine), 10 greedy episodes (reset seeds 20 000 + k,
none of them seen by the runner's evaluations) give the runner's figures (task return, penalty, |a|, |da|,
SM with its spread over the episodes) and how the policy uses the bin grid: the share of action entries at
each of the 9 bin values of [-1, 1] (normalized actions; SAC's continuous actions are counted in the nearest
bin), the share at the extremes (the bins -1 and +1), the share of steps on which an entry changes, and the
share of consecutive changes that reverse direction (chatter): ``sb3_gqn.metrics.bin_usage``. Rows go to
``docs/results/final_policies.csv`` (replacing earlier rows of the same run); ``make readme-tables`` turns
the CSV into the results report's table (docs/results/README.md).

    .venv/bin/python docs/results/final_policies.py                    # the runs of the results report's comparison
    .venv/bin/python docs/results/final_policies.py --algos gqn-adaptive decqn-9 --tables finger-spin_c0.1_100k
    .venv/bin/python docs/results/final_policies.py --algos decqn-9+residual+1update --only-new   # added runs only
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

import numpy as np

from sb3_gqn.variants import RunSpec

RESULTS = Path("docs/results")
OUT = RESULTS / "final_policies.csv"
EPISODES, FIRST_SEED = 10, 20_000
BIN_VALUES = np.linspace(-1.0, 1.0, 9)
#: CSV columns from sb3_gqn.metrics.SmoothnessFigures, averaged over the episodes
FIGURES = {
    "task_return": "task_return",
    "action_penalty": "penalty",
    "action_magnitude": "action_magnitude",
    "action_change": "action_change",
    "smoothness": "smoothness",
}
COLUMNS = [
    "table",
    "algo",
    "env",
    "seed",
    *FIGURES,
    "smoothness_std",
    "extreme_share",
    "change_rate",
    "reversal_rate",
    *(f"share_{value:+.2f}" for value in BIN_VALUES),
]


def run_spec(run_dir: Path) -> RunSpec:
    """The run's spec, as the runner recorded it in ``done.json``."""
    return RunSpec(**json.loads((run_dir / "done.json").read_text())["spec"])


def probe(run_dir: Path, spec: RunSpec) -> dict[str, float | str]:
    import torch as th
    from stable_baselines3 import SAC

    from sb3_gqn import GQN
    from sb3_gqn.metrics import bin_usage, control_frequency, episode_figures, rollout_episodes
    from sb3_gqn.variants import make_eval_env, run_overrides
    from sb3_gqn.zoo import register

    th.set_num_threads(1)
    register()  # the dm_control and Meta-World ids
    env = make_eval_env(spec)
    model = (SAC if run_overrides(spec)[0] == "sac" else GQN).load(run_dir / "model.zip", device="cpu")
    freq = control_frequency(env) or 1.0
    episodes = rollout_episodes(model, env, EPISODES, seed=FIRST_SEED)
    figures = [episode_figures(episode, freq) for episode in episodes]
    usage = [bin_usage(episode.actions, BIN_VALUES) for episode in episodes]
    return {
        "table": run_dir.parent.parent.name,
        "algo": spec.algo,
        "env": spec.env,
        "seed": spec.seed,
        **{column: float(np.mean([getattr(figure, field) for figure in figures])) for column, field in FIGURES.items()},
        "smoothness_std": float(np.std([figure.smoothness for figure in figures])),
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
    parser.add_argument("--only-new", action="store_true", help="skip the runs that already have rows in the CSV")
    parser.add_argument(
        "--out", type=Path, default=OUT, help="the CSV (default: final_policies.csv; a probe's runs: its folder's)"
    )
    args = parser.parse_args(argv)
    rows = {(row["table"], row["algo"], row["env"], row["seed"]): row for row in _read(args.out)}
    for run_dir, spec in finished_runs(args.tables, args.algos):
        if args.only_new and run_key(run_dir, spec) in rows:
            continue
        row = probe(run_dir, spec)
        rows[(str(row["table"]), str(row["algo"]), str(row["env"]), str(row["seed"]))] = row
        sm, extremes = float(row["smoothness"]), float(row["extreme_share"])
        print(f"{row['table']} {row['algo']} seed {row['seed']}: SM {sm:.4f}, extremes {extremes:.2f}")
    _write(args.out, rows, COLUMNS)
    print(f"{args.out}: {len(rows)} runs")
    return 0


def finished_runs(table_names: list[str] | None, algos: list[str]) -> list[tuple[Path, RunSpec]]:
    """The runs (folder and spec) of the named result folders (default: every ``docs/results/*/results.csv``)
    that finished and kept their ``model.zip``, for the listed algorithms (``gqn-adaptive`` covers its
    ``+...`` variants; a variant's full name, e.g. ``gqn-adaptive+residual+1update``, only itself)."""
    every_table = sorted(path.parent for path in RESULTS.glob("*/results.csv"))
    tables = [RESULTS / name for name in table_names] if table_names else every_table
    runs = [
        (run_dir, run_spec(run_dir))
        for table in tables
        for run_dir in sorted((table / "runs").glob("*"))
        if (run_dir / "model.zip").is_file() and (run_dir / "done.json").is_file()
    ]
    return [(run_dir, spec) for run_dir, spec in runs if spec.algo in algos or spec.algo.split("+")[0] in algos]


def run_key(run_dir: Path, spec: RunSpec) -> tuple[str, str, str, str]:
    """A run's key in the CSVs these scripts write: its result folder, algorithm, env and seed, as the CSV holds them."""
    return run_dir.parent.parent.name, spec.algo, spec.env, str(spec.seed)


def _write(path: Path, rows: dict[tuple[str, ...], dict[str, float | str]], columns: list[str]) -> None:
    """``rows`` in key order, floats rounded, as ``path``'s CSV."""
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=columns)
        writer.writeheader()
        for key in sorted(rows):
            writer.writerow({column: _rounded(rows[key][column]) for column in columns})


def _read(path: Path) -> list[dict[str, str]]:
    if not path.is_file():
        return []
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def _rounded(value: float | str) -> float | str:
    return round(float(value), 6) if isinstance(value, float) else value


if __name__ == "__main__":
    sys.exit(main())
