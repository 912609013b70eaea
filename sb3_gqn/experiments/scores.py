"""What the report and the figures read from a ``results.csv`` table: each run's growth events and final evaluation, the
final returns min-max normalized per task, and rliable's IQM of them with bootstrap intervals."""

from __future__ import annotations

import numpy as np
import pandas as pd

from sb3_gqn.experiments.significance import seeded_numpy_global_generator


def with_action_columns(table: pd.DataFrame) -> pd.DataFrame:
    """The table under today's action columns: a table of an earlier release held ``Σa²`` (the squared actions summed
    over the episode: the penalty at c = 1) under ``action_penalty``; it becomes ``action_squares``, and
    ``penalty_paid``, the penalty the agent paid, is each row's ``penalty`` times it (see
    :func:`~sb3_gqn.experiments.runs.upgraded_row`). Today's tables, and tables without the column, are unchanged."""
    if "action_penalty" not in table.columns or "action_squares" in table.columns:
        return table
    upgraded = table.rename(columns={"action_penalty": "action_squares"})
    upgraded.insert(
        list(upgraded.columns).index("action_squares") + 1,
        "penalty_paid",
        upgraded["penalty"] * upgraded["action_squares"],
    )
    return upgraded


def _decodings(table: pd.DataFrame) -> pd.Series:
    """Each row's ``decoding``: ``""`` for a run's own decoding (and for every row of a table without the column)."""
    if "decoding" not in table.columns:
        return pd.Series("", index=table.index, dtype=object)
    return table["decoding"].fillna("").astype(str)


def readings(table: pd.DataFrame, paired: bool = False) -> pd.DataFrame:
    """The rows a figure draws, each with the column ``agent``: the agent whose run it reads, which gives its colour.

    Each run's own decoding (the rows with an empty ``decoding``), under its agent's name; with ``paired``, also its
    paired readings (the rows whose ``decoding`` names the decoding that read the run's model beside its own, see
    :data:`~sb3_gqn.experiments.runs.PAIRED_DECODING`), each under ``agent (decoding)``, e.g. ``gqn-linear
    (relative)``. A table whose paired rows :func:`with_paired_readings` already named so gives the same rows.
    """
    decoding = _decodings(table)
    names = table["algo"].astype(str)
    agents = [name.removesuffix(f" ({kind})") if kind else name for name, kind in zip(names, decoding)]
    labelled = table.assign(agent=agents)
    labelled["algo"] = [f"{agent} ({kind})" if kind else agent for agent, kind in zip(agents, decoding)]
    return labelled if paired else labelled[(decoding == "").to_numpy()]


def with_paired_readings(table: pd.DataFrame) -> pd.DataFrame:
    """The table with every paired reading (a row whose ``decoding`` names the decoding that read the run's model
    beside its own, see :data:`~sb3_gqn.experiments.runs.PAIRED_DECODING`) as an agent of its own, ``algo (decoding)``:
    the report's tables then show a run's two decodings side by side. Tables without the column are unchanged, and so
    is a table whose paired readings are named so already."""
    if "decoding" not in table.columns:
        return table
    return readings(table, paired=True).drop(columns="agent")


def run_growth_events(runs: pd.DataFrame, column: str = "growth_events") -> list[tuple[int, int]]:
    """``(step, bins)`` growth events of one run, from the ``growth_events`` column of its last row (``deployments``:
    the changes of the level its evaluations acted on)."""
    if column not in runs or runs.empty:
        return []
    text = runs.sort_values("step")[column].iloc[-1]
    if not isinstance(text, str) or not text.strip():
        return []
    return [(int(step), int(bins)) for step, bins in (event.split(":") for event in text.split())]


def final_rows(table: pd.DataFrame) -> pd.DataFrame:
    """The last evaluation of every run."""
    last = table.groupby(["algo", "env", "penalty", "seed"])["step"].transform("max")
    return table[table["step"] == last]


def normalized_final_runs(
    table: pd.DataFrame, normalize: bool = True
) -> tuple[dict[str, list[np.ndarray]], list[tuple[str, float]]]:
    """Final returns min-max normalized per task (env, penalty) over all of that task's runs: ``{algo: [runs of
    each task]}`` (every run, counts may differ between tasks) and the tasks; the final returns as they are with
    ``normalize=False``."""
    final = final_rows(table).copy()
    task_range = final.groupby(["env", "penalty"])["return"].agg(["min", "max"])
    final = final.join(task_range, on=["env", "penalty"])
    spread = (final["max"] - final["min"]).replace(0.0, 1.0)
    final["normalized"] = (final["return"] - final["min"]) / spread if normalize else final["return"]
    final = final.sort_values("seed", kind="stable")  # lowest seeds first, so a cut keeps the same seeds everywhere
    tasks = sorted(set(zip(final["env"], final["penalty"])))
    runs_by_algo = {
        str(algo): [runs[(runs["env"] == env) & (runs["penalty"] == c)]["normalized"].to_numpy() for env, c in tasks]
        for algo, runs in final.groupby("algo")
    }
    return runs_by_algo, tasks


def equal_run_scores(runs_by_algo: dict[str, list[np.ndarray]], max_runs: int | None = None) -> dict[str, np.ndarray]:
    """:func:`normalized_final_runs`' runs as rliable wants them: ``{algo: array (runs, tasks)}``, cut to the
    algorithm's smallest run count over the tasks (its lowest seeds), and to ``max_runs`` when given (a comparison
    fixed at a seed count before later seeds ran); an algorithm missing a task is left out."""
    scores: dict[str, np.ndarray] = {}
    for algo, per_task in runs_by_algo.items():
        n_runs = min(len(values) for values in per_task)
        if max_runs is not None:
            n_runs = min(n_runs, max_runs)
        if n_runs:
            scores[algo] = np.stack([values[:n_runs] for values in per_task], axis=1)  # (runs, tasks)
    return scores


def normalized_final_scores(
    table: pd.DataFrame, max_runs: int | None = None
) -> tuple[dict[str, np.ndarray], list[tuple[str, float]]]:
    """:func:`normalized_final_runs` cut by :func:`equal_run_scores` (``max_runs``: see there), and the tasks."""
    runs_by_algo, tasks = normalized_final_runs(table)
    return equal_run_scores(runs_by_algo, max_runs), tasks


def iqm_scores(
    table: pd.DataFrame, max_runs: int | None = None
) -> tuple[dict[str, np.ndarray], list[tuple[str, float]], bool]:
    """What the IQM figure reads, cut as :func:`equal_run_scores` cuts (``max_runs``: see there), the tasks, and
    whether the scores are normalized: across two tasks or more the min-max normalized final returns
    (:func:`normalized_final_scores`); on one task the final returns as they are, since min-max normalizing one task
    over the agents drawn scores the worst 0 and the best 1 whatever their returns (-1276, -1185 and -906 would read
    0, 0.25 and 1)."""
    normalize = final_rows(table).groupby(["env", "penalty"]).ngroups >= 2
    runs_by_algo, tasks = normalized_final_runs(table, normalize)
    return equal_run_scores(runs_by_algo, max_runs), tasks, normalize


def degenerate_tasks(table: pd.DataFrame) -> list[tuple[str, float]]:
    """Tasks (env, penalty) whose runs all ended at the same return: their min-max normalization has no range."""
    task_range = final_rows(table).groupby(["env", "penalty"])["return"].agg(["min", "max"])
    return [(str(env), float(c)) for (env, c), row in task_range.iterrows() if row["max"] == row["min"]]


def iqm_with_intervals(
    scores: dict[str, np.ndarray], reps: int = 2000, seed: int = 0
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """rliable's IQM per algorithm with 95 % stratified bootstrap intervals (``estimates``, ``intervals``); ``seed``
    fixes the bootstrap draws, so that a regenerated table or figure reads the same."""
    from rliable import library as rly
    from rliable import metrics as rly_metrics

    with seeded_numpy_global_generator(seed):
        return rly.get_interval_estimates(scores, lambda x: np.array([rly_metrics.aggregate_iqm(x)]), reps=reps)
