"""How the final utilities of the opened bins relate to their coarse neighbours: a warm-start diagnostic.

``growth_init="interpolate"`` starts each opened bin at the mean of its two nested neighbours. This script asks
two questions of the trained 9-bin networks (every finished run of the listed algorithms that still has its
``model.zip``; ``docs/results/*/runs/`` is not committed, so the runs must have been trained on this machine):

1. Would a different interpolation have predicted the bins better? For each growth step (3 -> 5 opens bins 2
   and 6; 5 -> 9 opens 1, 3, 5, 7) the final utilities of the opened bins are compared with the linear
   interpolation of their two neighbours (what ``growth_init="interpolate"`` does) and with a quadratic one
   through the three nearest coarser bins (also a fixed linear combination of head rows, so it could be
   applied to the parameters exactly).
2. Does GQN end with its later bins valued lower, relative to their neighbours, than DecQN-9 does? That is the
   sign of ``linear_bias`` (interpolation minus final utility): positive means the opened bins end *below*
   their neighbours' mean, so the greedy policy prefers the coarser bins, the ends included.

States: 5 000 steps of the run's own greedy policy with 30 % uniformly random actions (reset seeds 30 000 +
k, the random actions seeded too, the env from the runner's spec). Errors are divided by the mean utility
range (max - min over the 9 bins) of the same states so that tasks compare. Rows go to
``docs/results/bin_interpolation.csv`` (replacing earlier rows of the same run).

    .venv/bin/python docs/results/bin_interpolation.py
    .venv/bin/python docs/results/bin_interpolation.py --tables walker-walk_c0.1_100k_torso
    .venv/bin/python docs/results/bin_interpolation.py --algos gqn-linear+residual+1update --only-new   # added runs
"""

from __future__ import annotations

import argparse
import itertools
import sys
from pathlib import Path

import numpy as np
from final_policies import RESULTS, _read, _write, finished_runs, run_key

from sb3_gqn.variants import RunSpec

OUT = RESULTS / "bin_interpolation.csv"
STEPS, RANDOM_SHARE, FIRST_SEED = 5_000, 0.3, 30_000
MAX_BINS = 9
COLUMNS = [
    "table",
    "algo",
    "env",
    "seed",
    "growth_step",
    "utility_range",
    "linear_bias",
    "linear_error",
    "quadratic_bias",
    "quadratic_error",
]


def quadratic_weights(new: int, coarse: list[int]) -> tuple[list[int], np.ndarray]:
    """Lagrange weights at bin ``new`` of the three consecutive ``coarse`` bins centred on its nearest coarse bin
    (a tie goes to the outer one, so that the grid's two halves mirror; bin values on [-1, 1]). E.g. bin 2 from
    bins 0, 4, 8: weights 3/8, 3/4, -1/8; bin 3 of 9 from 0, 2, 4 and bin 5 from 4, 6, 8."""
    values = np.linspace(-1.0, 1.0, MAX_BINS)
    centre = (MAX_BINS - 1) / 2
    nearest = min(range(len(coarse)), key=lambda k: (abs(coarse[k] - new), -abs(coarse[k] - centre)))
    middle = int(np.clip(nearest, 1, len(coarse) - 2))
    points = coarse[middle - 1 : middle + 2]
    x = values[new]
    weights = [
        np.prod([(x - values[other]) / (values[point] - values[other]) for other in points if other != point])
        for point in points
    ]
    return points, np.array(weights)


def growth_step_errors(utilities: np.ndarray, coarse: list[int]) -> dict[str, float]:
    """Bias and mean absolute error of linear and quadratic interpolation from the ``coarse`` bins.

    :param utilities: final utilities ``(states, action_dims, 9)``
    :param coarse: the bins active before the growth step (e.g. ``[0, 4, 8]``)
    """
    utility_range = float((utilities.max(-1) - utilities.min(-1)).mean())
    linear, quadratic, final = [], [], []
    for left, right in itertools.pairwise(coarse):
        new = (left + right) // 2
        points, weights = quadratic_weights(new, coarse)
        linear.append((utilities[..., left] + utilities[..., right]) / 2)
        quadratic.append(np.tensordot(utilities[..., points], weights, axes=([-1], [0])))
        final.append(utilities[..., new])
    final_array = np.stack(final, -1)
    figures = {"utility_range": utility_range}
    for name, predicted in (("linear", linear), ("quadratic", quadratic)):
        error = np.stack(predicted, -1) - final_array
        figures[f"{name}_bias"] = float(error.mean()) / utility_range
        figures[f"{name}_error"] = float(np.abs(error).mean()) / utility_range
    return figures


def probe(run_dir: Path, spec: RunSpec) -> list[dict[str, float | str]]:
    import torch as th

    from sb3_gqn import GQN
    from sb3_gqn.variants import make_eval_env
    from sb3_gqn.zoo import register

    th.set_num_threads(1)
    register()
    env = make_eval_env(spec)
    model = GQN.load(run_dir / "model.zip", device="cpu")
    if model.policy.max_bins != MAX_BINS or model.active_bins != MAX_BINS:
        return []
    rng = np.random.default_rng(0)
    env.action_space.seed(FIRST_SEED)
    observation, _ = env.reset(seed=FIRST_SEED)
    observations, episode = [], 0
    for _ in range(STEPS):
        observations.append(observation)
        action = (
            env.action_space.sample() if rng.random() < RANDOM_SHARE else model.predict(observation, deterministic=True)[0]
        )
        observation, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            episode += 1
            observation, _ = env.reset(seed=FIRST_SEED + episode)
    with th.no_grad():
        utilities = model.q_net(th.as_tensor(np.array(observations), dtype=th.float32)).numpy()
    return [
        {
            "table": run_dir.parent.parent.name,
            "algo": spec.algo,
            "env": spec.env,
            "seed": spec.seed,
            "growth_step": step,
            **growth_step_errors(utilities, coarse),
        }
        for step, coarse in (("3->5", [0, 4, 8]), ("5->9", [0, 2, 4, 6, 8]))
    ]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--algos", nargs="+", default=["gqn-adaptive", "gqn-linear", "decqn-9"])
    parser.add_argument("--tables", nargs="+", default=None, help="result folders under docs/results (default: all)")
    parser.add_argument("--only-new", action="store_true", help="skip the runs that already have rows in the CSV")
    parser.add_argument(
        "--out", type=Path, default=OUT, help="the CSV (default: bin_interpolation.csv; a probe's runs: its folder's)"
    )
    args = parser.parse_args(argv)
    rows = {(row["table"], row["algo"], row["env"], row["seed"], row["growth_step"]): row for row in _read(args.out)}
    done = {key[:4] for key in rows}
    for run_dir, spec in finished_runs(args.tables, args.algos):
        if args.only_new and run_key(run_dir, spec) in done:
            continue
        for row in probe(run_dir, spec):
            rows[tuple(str(row[key]) for key in COLUMNS[:5])] = row
            print(
                f"{row['table']} {row['algo']} seed {row['seed']} {row['growth_step']}: linear bias "
                f"{float(row['linear_bias']):+.3f}, error {float(row['linear_error']):.3f} | quadratic "
                f"{float(row['quadratic_bias']):+.3f}, {float(row['quadratic_error']):.3f}"
            )
    _write(args.out, rows, COLUMNS)
    print(f"{args.out}: {len(rows)} rows")
    return 0


if __name__ == "__main__":
    sys.exit(main())
