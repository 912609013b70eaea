"""The comparison runner: table schema, resume, restart of interrupted runs, every plot file."""

from __future__ import annotations

import csv
import importlib
import importlib.util
import json
import re
import shutil
import sys
import threading
import time
from pathlib import Path

import pytest

import sb3_gqn.experiments.runs as runs_module
from sb3_gqn.experiments.runner import main, parse_args
from sb3_gqn.experiments.runs import COLUMNS, collect
from sb3_gqn.experiments.variants import (
    VARIANTS,
    RunSpec,
    learning_starts,
    penalized_wrappers,
    run_overrides,
    untrained_runs,
    warm_started,
)
from sb3_gqn.zoo.hyperparams import shipped_entry

REPOSITORY = Path(__file__).resolve().parents[1]
REFERENCE_TORSO = "dict(layer_norm=True, activation_fn=nn.ELU)"
RESIDUAL_TORSO = "dict(residual_layer_norm=True)"
PLAIN_TORSO = "dict(layer_norm=False, activation_fn=nn.ReLU)"
#: the paper's growth as written, the ablation's starting point
PAPER_AS_WRITTEN = {
    "growth": "adaptive",
    "growth_kwargs": {"init": "none", "patience": None, "eval_freq": 5_000},
    "exploration": "per_dimension",
    "acting_tau": None,
}


def flat_settings(hyperparams: dict) -> dict:
    """``hyperparams`` with ``growth_kwargs``'s keys beside the others (``growth_kwargs.init``)."""
    growth_kwargs = hyperparams.get("growth_kwargs") or {}
    flat = {key: value for key, value in hyperparams.items() if key != "growth_kwargs"}
    return {**flat, **{f"growth_kwargs.{key}": value for key, value in growth_kwargs.items()}}


TINY = ["--envs", "Pendulum-v1", "--penalties", "0.1", "--seeds", "0", "--steps", "400", "--eval-freq", "200"]
TINY += ["--eval-episodes", "1", "--jobs", "2"]


def _drop_rows(table, algo):
    with open(table, newline="") as handle:
        rows = [row for row in csv.DictReader(handle) if row["algo"] != algo]
    with open(table, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows(rows)


def test_penalized_wrappers_replace_only_the_penalty():
    flatten = "gymnasium.wrappers.FlattenObservation"
    entry = [flatten, {"sb3_gqn.common.wrappers.ActionPenalty": {"coef": 0.1}}]
    assert penalized_wrappers(entry, 0.5) == [flatten, {"sb3_gqn.common.wrappers.ActionPenalty": {"coef": 0.5}}]
    assert penalized_wrappers(None, 0.0) == [{"sb3_gqn.common.wrappers.ActionPenalty": {"coef": 0.0}}]
    spec = RunSpec("decqn-2", "dm_control/walker-walk-v0", 0.5, 3, 10)
    assert spec.name == "decqn-2__dm_control-walker-walk-v0__c0.5__seed3"


def test_suites_and_bad_env(capsys):
    short = parse_args([])
    assert short.algos == ["gqn-linear", "decqn-2", "decqn-9", "sac"] and short.envs == ["Pendulum-v1"]
    assert short.eval_freq == short.steps // 10
    full = parse_args(["--full"])
    assert len(full.algos) == 6 and full.penalties == [0.0, 0.1, 0.5] and "dm_control/humanoid-walk-v0" in full.envs
    assert main(["--envs", "NoSuchEnv-v0", "--list"]) == 2
    assert "NoSuchEnv-v0" in capsys.readouterr().err


def test_budgets_that_never_reach_learning_starts_are_flagged():
    # gqn-linear: the class default (the Pendulum entry sets none); sac: the entry's learning_starts
    assert learning_starts(RunSpec("gqn-linear", "Pendulum-v1", 0.1, 0, 400)) == 1000
    assert learning_starts(RunSpec("sac", "Pendulum-v1", 0.1, 0, 400)) == 1000
    specs = [
        RunSpec(algo, "Pendulum-v1", 0.1, seed, steps)
        for algo in ("gqn-linear", "sac")
        for seed in (0, 1)
        for steps in (1000,)
    ]
    assert untrained_runs(specs) == [
        f"NO LEARNING: {algo} on Pendulum-v1 has a budget of 1000 steps <= its learning_starts=1000"
        for algo in ("gqn-linear", "sac")
    ]  # one warning per algorithm and env, not per seed
    assert untrained_runs([RunSpec("gqn-linear", "Pendulum-v1", 0.1, 0, 1001)]) == []


def test_tiny_suite_end_to_end_and_resume(tmp_path, capsys):
    out = tmp_path / "suite"
    assert main(["--algos", "gqn-linear", "sac", *TINY, "--out", str(out)]) == 0
    # 400 steps never reach learning_starts: the runner says so loudly (and the learning-curve plot in red)
    assert "WARNING: NO LEARNING: sac on Pendulum-v1 has a budget of 400 steps <= its learning_starts=1000" in (
        capsys.readouterr().err
    )
    with open(out / "results.csv", newline="") as handle:
        reader = csv.DictReader(handle)
        rows = list(reader)
    assert reader.fieldnames == COLUMNS
    assert {(row["algo"], int(row["step"])) for row in rows} == {(a, s) for a in ("gqn-linear", "sac") for s in (200, 400)}
    gqn_final = next(row for row in rows if row["algo"] == "gqn-linear" and row["step"] == "400")
    assert gqn_final["active_bins"] == "9" and float(gqn_final["smoothness_freq"]) == pytest.approx(20.0)  # 1 / dt
    for name in (
        "learning_curves_Pendulum-v1_c0.1.png",
        "aggregate_iqm.png",
        "smoothness_radar_Pendulum-v1.png",
        "q_values_gqn-linear__Pendulum-v1__c0.1__seed0.png",
    ):
        assert (out / name).stat().st_size > 5_000, name

    # A second invocation trains nothing; an interrupted run (no done.json) is retrained from scratch
    finished = out / "runs" / "sac__Pendulum-v1__c0.1__seed0"
    stamp = (finished / "curve.csv").stat().st_mtime_ns
    interrupted = out / "runs" / "gqn-linear__Pendulum-v1__c0.1__seed0"
    (interrupted / "done.json").unlink()
    (interrupted / "curve.csv").write_text("garbage from a killed run\n")
    _drop_rows(out / "results.csv", "gqn-linear")  # a killed run never reached the table
    capsys.readouterr()
    assert main(["--algos", "gqn-linear", "sac", *TINY, "--out", str(out), "--no-plots"]) == 0
    assert "2 runs, 1 already finished, 1 to train" in capsys.readouterr().out
    assert (finished / "curve.csv").stat().st_mtime_ns == stamp
    assert (interrupted / "done.json").is_file() and "garbage" not in (interrupted / "curve.csv").read_text()
    assert main(["--algos", "gqn-linear", "sac", *TINY, "--out", str(out), "--list"]) == 0
    assert "2 runs, 2 already finished, 0 to train" in capsys.readouterr().out


def test_a_committed_table_alone_resumes_and_accumulates(tmp_path, capsys):
    # A checkout has only the committed results.csv (runs/ is not in git): recorded runs are not retrained, and a
    # new invocation with another algorithm adds its rows to the same table.
    out = tmp_path / "suite"
    assert main(["--algos", "decqn-2", *TINY, "--out", str(out), "--no-plots"]) == 0
    table = out / "results.csv"
    decqn_rows = table.read_text().splitlines()[1:]
    shutil.rmtree(out / "runs")
    capsys.readouterr()
    assert main(["--algos", "decqn-2", *TINY, "--out", str(out), "--list"]) == 0
    assert "1 runs, 1 already finished, 0 to train" in capsys.readouterr().out
    assert main(["--algos", "decqn-2", "gqn-adaptive", *TINY, "--out", str(out), "--no-plots"]) == 0
    assert "2 runs, 1 already finished, 1 to train" in capsys.readouterr().out
    with open(table, newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert sorted({row["algo"] for row in rows}) == ["decqn-2", "gqn-adaptive"]
    assert [line for line in table.read_text().splitlines()[1:] if line.startswith("decqn-2")] == decqn_rows
    assert all(row["growth_events"] == "" for row in rows if row["algo"] == "decqn-2")


def test_invocations_collecting_into_one_table_at_once_keep_each_others_runs(tmp_path, monkeypatch):
    # Two invocations sharing --out finish together: each reads the table, adds its run and writes it back.
    # Reading is slowed so the two read-modify-writes overlap unless collect() serializes them; without the
    # lock the later writer drops the earlier one's run.
    out = tmp_path / "suite"
    specs = [RunSpec("decqn-2", "Pendulum-v1", 0.1, seed, 400) for seed in (0, 1)]
    for spec in specs:
        run_dir = out / "runs" / spec.name
        run_dir.mkdir(parents=True)
        row = {"algo": spec.algo, "env": spec.env, "penalty": spec.penalty, "seed": spec.seed, "step": 400, "return": -1.0}
        with open(run_dir / "curve.csv", "w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=list(row))
            writer.writeheader()
            writer.writerow(row)
        (run_dir / "done.json").write_text(json.dumps({}))
    read_table = runs_module.recorded_rows

    def slow_read(table):
        rows = read_table(table)
        time.sleep(0.3)
        return rows

    monkeypatch.setattr(runs_module, "recorded_rows", slow_read)
    threads = [threading.Thread(target=collect, args=([spec], out)) for spec in specs]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    with open(out / "results.csv", newline="") as handle:
        assert sorted(int(row["seed"]) for row in csv.DictReader(handle)) == [0, 1]
    assert not list(out.glob("*.tmp"))


def test_ablation_variants_differ_from_the_paper_as_written_in_one_change_each(research_variants):
    assert research_variants["gqn-before"].hyperparams == PAPER_AS_WRITTEN
    for name in ["gqn-before+warm-start", "gqn-before+plateau", "gqn-before+shared"]:
        paper = flat_settings(PAPER_AS_WRITTEN)
        changed = {key for key, value in flat_settings(research_variants[name].hyperparams).items() if paper.get(key) != value}
        assert (
            changed
            == {
                "gqn-before+warm-start": {"growth_kwargs.init"},
                "gqn-before+plateau": {"growth_kwargs.patience", "growth_kwargs.eval_freq"},
                "gqn-before+shared": {"exploration"},
            }[name]
        )


def trained(algo: str, env: str, variants) -> dict:
    """The hyperparameters the runner trains agent ``algo`` of ``variants`` with on ``env``: the shipped entry with the
    variant's overrides."""
    zoo_algo, overrides = run_overrides(RunSpec.of(algo, env, 0.1, 0, 1000, variants))
    return {**shipped_entry(zoo_algo, env), **overrides}


def test_humanoid_probes_train_gqns_humanoid_entry_changed_in_one_setting_each(research_variants):
    humanoid = "dm_control/humanoid-stand-v0"
    defaults = trained("gqn-adaptive", humanoid, research_variants)
    for name, change in {
        "gqn-adaptive+torso2048": {"policy_kwargs": "dict(net_arch=[2048, 2048])"},
        "gqn-adaptive+2updates": {"gradient_steps": 2},
    }.items():
        probe = trained(name, humanoid, research_variants)
        assert {key: value for key, value in probe.items() if defaults.get(key) != value} == change


RESULTS_SCRIPTS = Path(__file__).parents[1] / "docs" / "results"


def results_script(name):
    """docs/results/<name>.py, loaded afresh: the results pages' scripts (not modules of the package), which import each
    other by name as they do when make results-page runs build.py. docs/results is on sys.path only while the script
    loads: its result folders (docs/results/myosuite) would otherwise pass for installed packages in later tests."""
    sys.path.insert(0, str(RESULTS_SCRIPTS))
    try:
        spec = importlib.util.spec_from_file_location(f"results_{name}", RESULTS_SCRIPTS / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(RESULTS_SCRIPTS))
    return module


def test_loading_a_results_script_leaves_no_result_folder_importable():
    results_script("build")
    assert str(RESULTS_SCRIPTS) not in sys.path
    myosuite = importlib.util.find_spec("myosuite")
    assert myosuite is None or myosuite.origin is not None  # a namespace package (a folder) has no origin


def results_page():
    """docs/results/build.py: the results page, the README's blocks and the suite pages."""
    return results_script("build")


def paper_scale_page():
    """docs/results/paper_scale_blocks.py: the paper-scale page's blocks."""
    return results_script("paper_scale_blocks")


def test_walker_and_finger_runs_of_the_shipped_entries_are_their_1update_torso_variants(research_variants):
    """sb3_gqn.experiments.report's --shipped (and docs/results/build.py) report these variants' walker and finger runs
    under the plain names: that holds only while they train exactly what the shipped entries train (walker: DecQN's
    residual torso; finger: DecQN's default torso)."""
    walker, finger, cartpole = "dm_control/walker-walk-v0", "dm_control/finger-spin-v0", "dm_control/cartpole-swingup-v0"

    assert {walker: "+residual+1update", finger: "+layernorm+1update"} == results_page().SHIPPED
    for algo in ("gqn-adaptive", "gqn-linear", "decqn-2", "decqn-9"):
        assert trained(algo, walker, research_variants) == trained(f"{algo}+residual+1update", walker, research_variants)
        assert trained(algo, finger, research_variants) == trained(f"{algo}+layernorm+1update", finger, research_variants)
        assert trained(algo, walker, research_variants)["policy_kwargs"] == RESIDUAL_TORSO
        for env in (walker, finger):
            assert trained(algo, env, research_variants)["train_freq"] == 1
        # cartpole (the main job) trains the class defaults: the entry sets no torso and no update ratio
        assert "train_freq" not in trained(algo, cartpole, research_variants)
        assert "policy_kwargs" not in trained(algo, cartpole, research_variants)
    # The torso-alone probes and the ablation keep what they were recorded with (1 update per 2 steps; the MLP torso)
    for algo in ("gqn-adaptive+layernorm", "decqn-9+layernorm"):
        assert (
            trained(algo, walker, research_variants)["train_freq"] == 2
            and trained(algo, walker, research_variants)["policy_kwargs"] == REFERENCE_TORSO
        )
    for env in (walker, finger):
        before = trained("gqn-before+shared", env, research_variants)
        assert before["train_freq"] == 2 and before["policy_kwargs"] == PLAIN_TORSO and before["exploration"] == "shared"
        assert run_overrides(RunSpec.of("gqn-before", env, 0.1, 0, 1000, research_variants))[1] == {
            "train_freq": 2,
            "policy_kwargs": PLAIN_TORSO,
            **PAPER_AS_WRITTEN,
        }


def test_the_torso_variants_differ_from_the_entries_only_in_the_torso(research_variants):
    """Walker's ``+layernorm+1update`` and finger's ``+residual+1update`` each train the task's shipped entry with
    the other torso and nothing else changed, so their runs compare with the shipped ones seed for seed."""
    walker, finger = "dm_control/walker-walk-v0", "dm_control/finger-spin-v0"
    for algo in ("gqn-adaptive", "gqn-linear", "decqn-2", "decqn-9"):
        for env, other, torso in [
            (walker, "+layernorm+1update", REFERENCE_TORSO),
            (finger, "+residual+1update", RESIDUAL_TORSO),
        ]:
            shipped, candidate = trained(algo, env, research_variants), trained(f"{algo}{other}", env, research_variants)
            assert {key for key in shipped | candidate if shipped.get(key) != candidate.get(key)} == {"policy_kwargs"}
            assert candidate["policy_kwargs"] == torso


def test_the_results_page_refuses_a_shipped_entry_without_every_agents_runs():
    """A task's shipped variant must have run on every seed an earlier entry ran, for every agent of the main
    comparison: otherwise the first entry's runs would stay in the tables under the plain name, mixed with the shipped
    ones, or the tables would lose seeds."""
    import pandas as pd

    tables = results_page()
    walker = "dm_control/walker-walk-v0"
    suffix = tables.SHIPPED[walker]
    runs = [(agent, seed) for agent in tables.MAIN_ALGOS for seed in (0, 1)]
    first_entry = pd.DataFrame([{"algo": agent, "env": walker, "seed": seed, "return": 1.0} for agent, seed in runs])
    shipped = pd.DataFrame([{"algo": agent + suffix, "env": walker, "seed": seed, "return": 2.0} for agent, seed in runs])
    table = tables.shipped(pd.concat([first_entry, shipped], ignore_index=True))
    assert sorted(table["algo"]) == sorted(agent for agent, _ in runs) and set(table["return"]) == {2.0}
    with pytest.raises(SystemExit, match=re.escape(f"decqn-9{suffix} (the shipped entry) lacks seeds [1]")):
        tables.shipped(pd.concat([first_entry, shipped.iloc[:-1]], ignore_index=True))


def test_the_results_page_task_table_by_hand():
    """One row per task, the agents in the page's order, mean [bootstrap interval], seeds and mean SM of the final
    evaluations: decqn-9's runs 0 and 10 (and SM 0.01, 0.03) read 5 [0, 10] (2 seeds), SM 0.0200."""
    import pandas as pd

    rows = [
        {"algo": algo, "env": "dm_control/cartpole-swingup-v0", "penalty": 0.1, "seed": seed, "step": step, "return": value,
         "smoothness": sm}
        for algo, seed, value, sm in [("gqn-adaptive", 0, 7.0, 0.02), ("decqn-9", 0, 0.0, 0.01), ("decqn-9", 1, 10.0, 0.03)]
        for step, value in [(50_000, -100.0), (100_000, value)]
    ]  # fmt: skip
    body = results_page().task_table(pd.DataFrame(rows)).splitlines()
    assert body[0] == "| task | gqn-adaptive | decqn-9 |"
    assert body[2] == "| cartpole-swingup | 7 (1 seed), SM 0.0200 | 5 [0, 10] (2 seeds), SM 0.0200 |"


def test_the_development_table_reads_the_final_evaluations_and_success(tmp_path):
    """Meta-World reach: W ends at 10 and 20 over two seeds (success 1 and 0), SAC at 4 on one (no flag recorded);
    reacher has no success column values. Earlier evaluations (step 25k) are ignored."""
    import pandas as pd

    w = "gqn-adaptive+layernorm+1update+bins3-9"
    rows = [
        {"algo": algo, "env": env, "penalty": 0.5, "seed": seed, "step": step, "return": value if step == 50_000 else -1.0,
         "success": flag}
        for algo, env, seed, value, flag in [
            (w, "sb3_gqn/metaworld-reach-v3", 0, 10.0, 1.0), (w, "sb3_gqn/metaworld-reach-v3", 1, 20.0, 0.0),
            ("sac", "sb3_gqn/metaworld-reach-v3", 0, 4.0, None), (w, "dm_control/reacher-easy-v0", 0, -3.0, None),
        ]
        for step in (25_000, 50_000)
    ]  # fmt: skip
    pd.DataFrame(rows).to_csv(tmp_path / "results.csv", index=False)
    body = results_page().development_block(tmp_path / "results.csv").splitlines()
    assert body[0] == "| task | c | GQN (defaults) | SAC |"
    assert body[2] == "| reacher-easy | 0.5 | -3 (1) | - |"
    assert body[3] == "| reach-v3 | 0.5 | 15 [10, 20] (2), success 0.50 | 4 (1) |"


def test_the_generated_blocks_match_the_committed_tables(monkeypatch):
    """The README's, the results page's and the suite pages' generated tables are what docs/results/build.py makes of
    the committed results.csv files: a table extended without `make results-page` fails here."""
    root = Path(__file__).parents[1]
    monkeypatch.chdir(root)
    page = results_page()

    def block(path, name):
        after_begin = path.read_text().split(f"<!-- BEGIN generated: {name} -->\n", 1)[1]
        return after_begin.split(f"\n<!-- END generated: {name} -->")[0]

    table = page.comparison_table()
    assert block(page.README, "development") == page.development_block()
    assert block(page.README, "main-job") == page.main_job_block()
    assert block(page.README, "results") == page.task_table(table)
    if len(page.smooth_control_runs()):
        assert block(page.PAGE, "smooth-control") == page.smooth_control_block(table)
    assert block(page.PAGE, "smooth-default") == page.smooth_default_block()
    paper = paper_scale_page()
    if (paper.PAPER_SCALE / "results.csv").exists():
        paper_scale = page.load([paper.PAPER_SCALE / "results.csv"])
        assert block(page.RESULTS / "paper-scale.md", "paper-scale") == paper.paper_scale_block(paper_scale)
        figures = [
            page.RESULTS / link.split("](")[1].rstrip(")")
            for link in block(page.RESULTS / "paper-scale.md", "paper-scale-figures").split("\n\n")
        ]
        # curves and a radar per task, one IQM
        assert all(figure.exists() for figure in figures) and len(figures) == 2 * paper_scale["env"].nunique() + 1
        probes = paper.probes_block(paper.probe_runs(), paper_scale)
        assert block(page.RESULTS / "paper-scale.md", "paper-scale-probes") == probes
    for name, (path, agents) in page.SUITES.items():
        if (path / "results.csv").exists():
            suite_table = page.load([path / "results.csv"])
            assert block(page.RESULTS / f"{name}.md", name) == page.suite_block(suite_table, agents)


def test_the_relative_decoding_table_by_hand(tmp_path, monkeypatch):
    """door-open: the runner's two runs end at task return 200 and 300 read with the argmax, 100 and 250 with the
    relative decoding (SM 0.004, 0.006 and 0.001, 0.003); paired differences -100 and -50: mean -75, and the bootstrap
    replicates of two values are -100, -75 or -50. SAC's SM is 0.002 (two seeds), so SM 2.50x and 1.00x SAC's. The
    readings file: two models at 10 and 20 with the argmax, 30 and 20 with the relative decoding: +20 and 0, mean 10
    [0, 20]; no SAC runs for its env ("-")."""
    import pandas as pd

    page = results_page()
    door, reacher = "sb3_gqn/metaworld-door-open-v3", "dm_control/reacher-easy-v0"

    def row(algo, seed, task_return, sm, decoding=""):
        return {"algo": algo, "env": door, "penalty": 0.5, "seed": seed, "step": 50_000, "return": task_return,
                "task_return": task_return, "smoothness": sm, "action_change": 0.1, "decoding": decoding}  # fmt: skip

    agent = page.SMOOTH_DEFAULT_AGENT
    runs = [row(agent, 0, 100.0, 0.001), row(agent, 1, 250.0, 0.003)]
    runs += [row(agent, 0, 200.0, 0.004, "argmax"), row(agent, 1, 300.0, 0.006, "argmax")]
    early = [{**run, "step": 10_000, "task_return": 0.0} for run in runs]
    (tmp_path / "evidence").mkdir()
    pd.DataFrame(early + runs).to_csv(tmp_path / "evidence" / "results.csv", index=False)
    (tmp_path / "sac").mkdir()
    pd.DataFrame([{**row("sac", seed, 500.0, 0.002), "decoding": ""} for seed in (0, 1)]).to_csv(
        tmp_path / "sac" / "results.csv", index=False
    )
    pd.DataFrame(
        [{"model": f"m{index}", "decoding": decoding, "return": value, "task_return": value, "smoothness": 0.01}
         for index, (greedy, relative) in enumerate([(10.0, 30.0), (20.0, 20.0)])
         for decoding, value in [("greedy", greedy), ("relative 0.1", relative), ("softmax 0.3", 99.0)]]
    ).to_csv(tmp_path / "decodings-reacher.csv", index=False)  # fmt: skip
    monkeypatch.setattr(page, "SMOOTH_DEFAULT_SAC", {door: tmp_path / "sac"})
    monkeypatch.setattr(page, "SMOOTH_DEFAULT_READINGS", {"decodings-reacher.csv": {"env": reacher, "source": "models"}})
    body = page.smooth_default_block(tmp_path).splitlines()
    assert body[2] == (
        "| door-open-v3 | runner, paired readings | 2 | 250 [200, 300] | 175 [100, 250] | -75 [-100, -50] | 2.50x | 1.00x |"
    )
    assert body[3] == "| reacher-easy | models | 2 | 15 [10, 20] | 25 [20, 30] | 10 [0, 20] | - | - |"
    assert len(body) == 4


def test_the_paper_scale_table_by_hand(monkeypatch):
    """finger-turn_hard, 40k-step runs (the first quarter: the 10k evaluation). GQN's two seeds end at return 100 and
    200 (SM 0.002, 0.004; with the relative decoding 0.001) after -10 and -30 at 10k (and 3 at 20k for seed 0);
    DecQN-9's at 50 and 150 (SM 0.005) after -50 and -70. So GQN 150 [100, 200], first quarter -20 [-30, -10], area
    under the curve (the mean of each run's evaluations) 31 and 85, so 58 [31, 85]; DecQN-9 100 [50, 150], -60 [-70,
    -50], area 0 and 40, so 20 [0, 40]. The differences of means: first quarter +40, whose bootstrap replicates lie in
    [+20, +60] with each end at probability 1/16 (both means at their extremes), so the 95 % interval is [+20, +60];
    final +50 [-50, +150] alike (100 - 150 and 200 - 50), area +38 [-9, +85] (31 - 40 and 85 - 0). SM over DecQN-9's:
    0.003 / 0.005 = 0.60x, relative 0.001 / 0.005 = 0.20x; the task returns (return + 1) differ as the returns do,
    an interval that holds 0: matched. With 2 seeds a cell, the first quarter reads "GQN higher" (the interval lies
    above 0) and the final return and the area "no resolved difference"; with 3 a cell, each says that it is not read
    yet. DecQN-2 and SAC did not run: no row, no comparison."""
    import pandas as pd

    from sb3_gqn.experiments.scores import with_paired_readings

    page = paper_scale_page()

    def row(algo, seed, step, value, sm=0.005, decoding=""):
        return {"algo": algo, "env": "dm_control/finger-turn_hard-v0", "penalty": 0.5, "seed": seed, "step": step,
                "return": value, "task_return": value + 1.0, "smoothness": sm, "decoding": decoding}  # fmt: skip

    rows = [row("gqn-adaptive", 0, 10_000, -10.0), row("gqn-adaptive", 0, 20_000, 3.0)]
    rows += [row("gqn-adaptive", 0, 40_000, 100.0, 0.002), row("gqn-adaptive", 1, 10_000, -30.0)]
    rows += [row("gqn-adaptive", 1, 40_000, 200.0, 0.004)]
    rows += [row("gqn-adaptive", seed, 40_000, 0.0, 0.001, "relative") for seed in (0, 1)]
    rows += [row("decqn-9", seed, step, value) for seed, step, value in [(0, 10_000, -50.0), (0, 40_000, 50.0)]]
    rows += [row("decqn-9", seed, step, value) for seed, step, value in [(1, 10_000, -70.0), (1, 40_000, 150.0)]]
    table = with_paired_readings(pd.DataFrame(rows))
    monkeypatch.setattr(page, "PAPER_SCALE_SEEDS", 2)
    body = page.paper_scale_block(table).splitlines()
    assert body[2] == (
        "| finger-turn_hard | GQN | 2 | 150 [100, 200] | 151 [101, 201] | 58 [31, 85] | -20 [-30, -10] | 0.0030 | 0.0010 |"
    )
    assert body[3] == (
        "| finger-turn_hard | DecQN-9 | 2 | 100 [50, 150] | 101 [51, 151] | 20 [0, 40] | -60 [-70, -50] | 0.0050 | - |"
    )
    assert body[4:] == [
        "",
        "- finger-turn_hard, first-quarter return, GQN - DecQN-9: +40 [+20, +60] (GQN higher)",
        "- finger-turn_hard, final return, GQN - DecQN-9: +50 [-50, +150] (no resolved difference); area under the "
        "curve: +38 [-9, +85] (no resolved difference)",
        "- finger-turn_hard, SM, GQN over DecQN-9: argmax 0.60x, relative 0.20x; final task return, GQN - DecQN-9: "
        "+50 [-50, +150] (matched)",
    ]
    monkeypatch.setattr(page, "PAPER_SCALE_SEEDS", 3)
    assert page.paper_scale_block(table).splitlines()[5:] == [
        "- finger-turn_hard, first-quarter return, GQN - DecQN-9: +40 [+20, +60] (not read yet: 2 and 2 of 3 seeds)",
        "- finger-turn_hard, final return, GQN - DecQN-9: +50 [-50, +150] (not read yet: 2 and 2 of 3 seeds); area "
        "under the curve: +38 [-9, +85] (not read yet: 2 and 2 of 3 seeds)",
        "- finger-turn_hard, SM, GQN over DecQN-9: argmax 0.60x, relative 0.20x; final task return, GQN - DecQN-9: "
        "+50 [-50, +150] (matched) (not read yet: 2 and 2 of 3 seeds)",
    ]


def test_a_paper_scale_difference_below_0_reads_for_the_baseline_and_shows_its_side_of_0():
    """GQN's runs at 10 and 20 against DecQN-9's at 40 and 50: the replicates' means are 10, 15 or 20 against 40, 45
    or 50, so the difference -30 has the interval [-40, -20] (each end at probability 1/16), below 0: DecQN-9 higher.
    A bound that rounds to 0 keeps its sign and two digits: -0.29 is below 0, +0.5 above it, 0 is +0."""
    import numpy as np

    page = paper_scale_page()
    gqn, decqn = np.array([10.0, 20.0]), np.array([40.0, 50.0])
    assert page.resolved([gqn, decqn], "gqn-adaptive", "decqn-9", None) == "-30 [-40, -20] (DecQN-9 higher)"
    signed = results_script("page_cells").signed
    assert [signed(value) for value in (-0.294, 0.5, 0.0, -1.4, 12.6)] == ["-0.29", "+0.5", "+0", "-1", "+13"]


def test_the_figures_block_links_each_known_figure_in_page_order(tmp_path):
    """Curves first, then the IQM, then the radars, each kind by name; a figure of another kind is not linked."""
    page = results_script("page_cells")
    folder = tmp_path / "suite"
    names = ["smoothness_radar_b.png", "aggregate_iqm.png", "learning_curves_b_c0.5.png", "learning_curves_a_c0.5.png"]
    body = page.figures_block([folder / name for name in [*names, "q_values_a.png"]], tmp_path)
    assert body.split("\n\n") == [
        "![learning curves, a_c0.5](suite/learning_curves_a_c0.5.png)",
        "![learning curves, b_c0.5](suite/learning_curves_b_c0.5.png)",
        "![IQM across tasks](suite/aggregate_iqm.png)",
        "![smoothness, b](suite/smoothness_radar_b.png)",
    ]


def test_the_paper_scale_smoothness_reading_says_when_returns_differ():
    """Two SAC runs at task return 300 (SM 0.002) against GQN's two at 100 and 120 (SM 0.001, argmax only): SM 0.50x
    SAC's, and the task returns differ by -190 [-200, -180], an interval without 0: not matched."""
    import pandas as pd

    page = paper_scale_page()
    runs = pd.DataFrame(
        [
            {"algo": "gqn-adaptive", "seed": 0, "task_return": 100.0, "smoothness": 0.001},
            {"algo": "gqn-adaptive", "seed": 1, "task_return": 120.0, "smoothness": 0.001},
            {"algo": "sbx-sac", "seed": 0, "task_return": 300.0, "smoothness": 0.002},
            {"algo": "sbx-sac", "seed": 1, "task_return": 300.0, "smoothness": 0.002},
        ]
    )
    assert page.smoothness_reading(runs, "gqn-adaptive", "sbx-sac") == (
        "SM, GQN over SAC (SBX): argmax 0.50x; final task return, GQN - SAC (SBX): -190 [-200, -180] "
        "(not matched: the SM ratio compares unequal returns)"
    )


def test_the_humanoid_probes_table_by_hand():
    """Budget 30k, bar 50. The plan's seed 0 scores task return 5, 6 and 7 at 10k-30k (and 200 at 40k, past the
    budget): final 7, highest 7, never above 50: does not stand. The penalty probe scores 5, 80 and 30: highest 80,
    first above 50 at 20k, final 30: rises. The update-ratio probe scores 40, 45 and 60 (its relative reading 500 is
    not the argmax): final 60: stands. Seed 1 and c = 0.5 runs of the penalty probe's agent are other runs. The
    capacity probe has not finished; with it at 10, 20 and 30 no probe moves but the two that did."""
    import pandas as pd

    page = paper_scale_page()
    choices = {**page.PROBES, "steps": 30_000}
    env = choices["env"]

    def evaluations(algo, penalty, task_returns, seed=0, steps=(10_000, 20_000, 30_000)):
        return [{"algo": algo, "env": env, "penalty": penalty, "seed": seed, "step": step, "return": value - 100.0,
                 "task_return": value, "action_magnitude": 0.25} for step, value in zip(steps, task_returns)]  # fmt: skip

    plan = pd.DataFrame(evaluations("gqn-adaptive", 0.5, [5.0, 6.0, 7.0, 200.0], steps=(10_000, 20_000, 30_000, 40_000)))
    probes = evaluations("gqn-adaptive", 0.1, [5.0, 80.0, 30.0]) + evaluations("gqn-adaptive", 0.1, [99.0] * 3, seed=1)
    probes += evaluations("gqn-adaptive", 0.5, [99.0] * 3) + evaluations("gqn-adaptive+2updates", 0.5, [40.0, 45.0, 60.0])
    probes += evaluations("gqn-adaptive+2updates (relative)", 0.5, [500.0] * 3)
    body = page.probes_block(pd.DataFrame(probes), plan, choices).splitlines()
    labels = [choices["reference"]["label"], *(entry["label"] for entry in choices["runs"])]
    assert body[2:6] == [
        f"| {labels[0]} | 30k | 7 | 7 | - | -93 | 0.25 | does not stand |",
        f"| {labels[1]} | 30k | 30 | 80 | 20k | -70 | 0.25 | rises |",
        f"| {labels[2]} | - | - | - | - | - | - | not finished |",
        f"| {labels[3]} | 30k | 60 | 60 | 30k | -40 | 0.25 | stands |",
    ]
    read = f"Stands or rises: {labels[1]} (rises); {labels[3]} (stands)."
    assert body[-1].startswith(read)
    probes += evaluations("gqn-adaptive+torso2048", 0.5, [10.0, 20.0, 30.0])
    assert page.probes_block(pd.DataFrame(probes), plan, choices).splitlines()[-1].startswith(read)
    nothing_moves = [run for run in probes if run["algo"] == "gqn-adaptive+torso2048"]
    nothing_moves += [{**run, "task_return": 10.0} for run in probes if run["algo"] != "gqn-adaptive+torso2048"]
    assert page.probes_block(pd.DataFrame(nothing_moves), plan, choices).splitlines()[-1] == (
        "No probe stands or rises: the probes do not point to the penalty, the capacity or the update ratio within 30k "
        "steps. What remains is the budget."
    )
    assert page.probes_block(None, plan, choices).splitlines()[-1] == (
        "Not read yet: 0 of 3 probes finished; none stands or rises."
    )


def test_the_smooth_control_table_by_hand(tmp_path):
    """cartpole: the shipped entry's seeds 0-1 (seed 2 has no remedy run, so it is left out) end at task return 100
    and 100, SM 0.004 and 0.006; the remedy at 150 and 150, SM 0.001 and 0.003 (mean 0.002, bootstrap interval
    [0.001, 0.003]: the replicates of two values are 0.001, 0.002 or 0.003); SAC at 100 (3 seeds), SM 0.002. So SM
    1.00x SAC's, task return +50 [+50, +50] against both. The rate-penalty agent at 120 and 80 (SM 0.002 and 0.004,
    mean 0.003): SM 1.50x SAC's, task return +0 [-20, +20] against both (the replicates' means are 80, 100 or 120)."""
    import pandas as pd

    env = "dm_control/cartpole-swingup-v0"

    def run(algo, seed, task_return, sm, change):
        return {
            "algo": algo,
            "env": env,
            "penalty": 0.1,
            "seed": seed,
            "step": 100_000,
            "return": task_return,
            "task_return": task_return,
            "smoothness": sm,
            "action_change": change,
        }

    comparison = pd.DataFrame(
        [run("gqn-adaptive", 0, 100.0, 0.004, 0.2), run("gqn-adaptive", 1, 100.0, 0.006, 0.2),
         run("gqn-adaptive", 2, 999.0, 0.5, 0.9)] + [run("sac", seed, 100.0, 0.002, 0.01) for seed in range(3)]
    )  # fmt: skip
    page = results_page()
    remedy = [run(page.SMOOTH_REMEDY, 0, 150.0, 0.001, 0.02), run(page.SMOOTH_REMEDY, 1, 150.0, 0.003, 0.02)]
    remedy += [run(page.SMOOTH_RATE, 0, 120.0, 0.002, 0.05), run(page.SMOOTH_RATE, 1, 80.0, 0.004, 0.05)]
    early = [{**row, "step": 50_000, "task_return": -5.0} for row in remedy]
    pd.DataFrame(early + remedy).to_csv(tmp_path / "results.csv", index=False)
    model = f"runs/{page.SMOOTH_REMEDY}__dm_control-cartpole-swingup-v0__c0.1__seed{{}}/model.zip"
    pd.DataFrame(
        [{"model": model.format(seed), "decoding": decoding, "return": value, "task_return": value,
          "smoothness": sm, "action_change": 0.1} for seed in (0, 1)
         for decoding, value, sm in [("greedy", 140.0, 0.005), ("softmax 0.3", 150.0, 0.001), ("hysteresis 0.1", 0.0, 0.0)]]
    ).to_csv(tmp_path / "decodings-cartpole.csv", index=False)  # fmt: skip
    body = page.smooth_control_block(comparison, tmp_path).splitlines()
    assert body[0] == "**cartpole-swingup**"
    assert body[4] == "| GQN, argmax (shipped entry) | 2 | 100 [100, 100] | 0.0050 [0.0040, 0.0060] | 0.200 [0.200, 0.200] |"
    assert body[5] == "| GQN, expectation 0.3 | 2 | 150 [150, 150] | 0.0020 [0.0010, 0.0030] | 0.020 [0.020, 0.020] |"
    assert body[6] == "| GQN, rate penalty 0.3 | 2 | 100 [80, 120] | 0.0030 [0.0020, 0.0040] | 0.050 [0.050, 0.050] |"
    assert body[7] == (
        "| GQN, argmax, on the same final models | 2 | 140 [140, 140] | 0.0050 [0.0050, 0.0050] | 0.100 [0.100, 0.100] |"
    )
    assert body[8].startswith("| GQN, expectation 0.3, on the same final models | 2 | 150 [150, 150] | 0.0010")
    assert body[9] == "| SAC | 3 | 100 [100, 100] | 0.0020 [0.0020, 0.0020] | 0.010 [0.010, 0.010] |"
    assert body[11] == (
        "Expectation 0.3: SM 1.00x SAC's (goal: at most 1.5x); task return minus the shipped entry's +50 [+50, +50], "
        "minus SAC's +50 [+50, +50]."
    )
    assert body[13] == (
        "Rate penalty 0.3: SM 1.50x SAC's (goal: at most 1.5x); task return minus the shipped entry's +0 [-20, +20], "
        "minus SAC's +0 [-20, +20]."
    )


def test_a_suite_table_by_hand():
    """door-open at c = 0.5, final evaluations: GQN seeds 0-2 with success 1, 0, 1 (mean 0.67; the bootstrap replicates
    of three values are all 0 with probability 1/27 > 2.5 %, all 1 with 8/27, so the interval is [0, 1]), return 300,
    100, 200 (mean 200 [100, 300] the same way), task return 400, 200, 300, SM 0.01-0.03 (mean 0.02); SAC one seed
    without a success flag. The early column is the evaluation nearest 10k steps (a fifth of 50k): 10k for GQN's seeds
    (returns -100, -200, -300: mean -200 [-300, -100]), 5k on SAC's tie between 5k and 15k (return 7); so its
    header says "early return". Agents left out of the table and agents without runs are not shown."""
    import pandas as pd

    def row(algo, seed, step, success, value, sm):
        return {"algo": algo, "env": "sb3_gqn/metaworld-door-open-v3", "penalty": 0.5, "seed": seed, "step": step,
                "return": value, "task_return": value + 100.0, "smoothness": sm, "success": success}  # fmt: skip

    rows = [row("gqn-adaptive", seed, 50_000, success, value, sm)
            for seed, success, value, sm in [(0, 1.0, 300.0, 0.01), (1, 0.0, 100.0, 0.02), (2, 1.0, 200.0, 0.03)]]  # fmt: skip
    rows += [row("gqn-adaptive", seed, step, 0.0, value, 1.0)
             for seed in range(3) for step, value in [(10_000, -100.0 * (seed + 1)), (25_000, -1000.0)]]  # fmt: skip
    rows += [row("sac", 0, step, None, value, 0.005) for step, value in [(5_000, 7.0), (15_000, 8.0), (50_000, 50.0)]]
    rows += [row("td3", 0, 50_000, 1.0, 999.0, 0.5)]
    body = results_page().suite_block(pd.DataFrame(rows), {"gqn-adaptive": "GQN 9 -> 65", "decqn-9": "DecQN-9", "sac": "SAC"})
    assert body.splitlines() == [
        "| task | agent | seeds | success | return | task return | SM | early return |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
        "| door-open-v3 (c = 0.5) | GQN 9 -> 65 | 3 | 0.67 [0.00, 1.00] | 200 [100, 300] | 300 [200, 400] | 0.0200 "
        "| -200 [-300, -100] |",
        "| door-open-v3 (c = 0.5) | SAC | 1 | - | 50 | 150 | 0.0050 | 7 |",
    ]
    header = results_page().suite_block(pd.DataFrame(rows), {"gqn-adaptive": "GQN 9 -> 65"}).splitlines()[0]
    assert header.endswith("| SM | return at 10k |")  # every shown run's early evaluation is at 10k


@pytest.mark.parametrize(
    "module", ["sb3_gqn.experiments.runner", "sb3_gqn.experiments.reference_run", "sb3_gqn.experiments.report"]
)
def test_help_texts_are_plain_text(module, capsys):
    entry_point = importlib.import_module(module).main
    with pytest.raises(SystemExit):
        entry_point(["--help"])
    text = capsys.readouterr().out
    assert "usage:" in text and "``" not in text and not re.search(r":(func|mod|class|meth):", text)


def test_the_local_runner_imports_no_ray():
    import subprocess
    import sys

    code = (
        "import sys; from sb3_gqn.experiments.runner import main\n"
        "main(['--algos', 'gqn-linear', '--envs', 'Pendulum-v1', '--list'])\n"
        "print('ray' in sys.modules)"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip().splitlines()[-1] == "False"


def test_warm_started_is_every_variant_but_the_cold_ablation(research_variants):
    def warm(algo):
        return warm_started(algo, research_variants)

    assert not warm("gqn-before") and not warm("gqn-before+plateau") and not warm("gqn-before+shared")
    assert warm("gqn-before+warm-start") and warm("gqn-adaptive") and warm("gqn-linear")
    assert warm("gqn-adaptive+residual+1update")
    assert warm("a-table-from-elsewhere")  # the class default
    assert warm_started("gqn-before")  # an agent of a variants file is known only where its agents are passed


def test_warm_started_reads_a_variants_file_in_either_spelling(tmp_path):
    from sb3_gqn.experiments.variants import load_variants

    (tmp_path / "variants.yml").write_text(
        "cold-0-2:\n  algo: gqn\n  hyperparams: {growth_init: none}\n"
        "cold:\n  algo: gqn\n  hyperparams: {growth_kwargs: {init: none}}\n"
        "warm:\n  algo: gqn\n  hyperparams: {growth_kwargs: {patience: 2}}\n"
    )
    variants = load_variants(tmp_path / "variants.yml")
    assert [warm_started(algo, variants) for algo in ("cold-0-2", "cold", "warm")] == [False, False, True]


def test_loading_a_variants_file_changes_nothing_global(tmp_path):
    from sb3_gqn.experiments.variants import load_variants, with_variants_files

    shipped = dict(VARIANTS)
    (tmp_path / "variants.yml").write_text("gqn-cold:\n  algo: gqn\n  hyperparams: {growth_init: none}\n")
    loaded = load_variants(tmp_path / "variants.yml")
    assert list(loaded) == ["gqn-cold"] and dict(VARIANTS) == shipped
    agents = with_variants_files([tmp_path / "variants.yml"])
    assert list(agents) == [*shipped, "gqn-cold"] and dict(VARIANTS) == shipped
    with pytest.raises(TypeError):
        VARIANTS["gqn-cold"] = loaded["gqn-cold"]  # read-only
    with pytest.raises(ValueError, match="Unknown agent 'gqn-cold'"):
        RunSpec("gqn-cold", "Pendulum-v1", 0.1, 0, 400)
    assert RunSpec.of("gqn-cold", "Pendulum-v1", 0.1, 0, 400, agents).variant == loaded["gqn-cold"]
    with pytest.raises(ValueError, match="redefines an agent"):
        (tmp_path / "again.yml").write_text("gqn-cold:\n  algo: gqn\n  hyperparams: {growth_init: interpolate}\n")
        with_variants_files([tmp_path / "variants.yml", tmp_path / "again.yml"])


def test_two_critics_keep_the_entry_torso(research_variants):
    """``gqn-adaptive+twin`` adds DecQN's second critic to the entry's own torso (walker's residual one: the reference
    as its experiments run it), not in place of it."""
    from sb3_gqn.experiments.variants import added_policy_kwargs

    assert trained("gqn-adaptive+twin", "dm_control/walker-walk-v0", research_variants)["policy_kwargs"] == (
        "dict(residual_layer_norm=True, n_critics=2)"
    )
    assert trained("gqn-adaptive+twin", "dm_control/walker-walk-v0", research_variants)["train_freq"] == 1
    # cartpole's entry is the class defaults: the second critic alone (its recorded twin runs trained the plain MLP
    # the entry pinned then)
    assert trained("gqn-adaptive+twin", "dm_control/cartpole-swingup-v0", research_variants)["policy_kwargs"] == (
        "dict(n_critics=2)"
    )
    # decqn-9's twin keeps decqn.yml's entry (finger's DecQN default torso) at 9 bins
    finger_decqn = trained("decqn-9+twin", "dm_control/finger-spin-v0", research_variants)
    assert finger_decqn["policy_kwargs"] == "dict(layer_norm=True, activation_fn=nn.ELU, n_critics=2)"
    assert finger_decqn["bins"] == 9 and finger_decqn["train_freq"] == 1
    assert trained("decqn-9+twin", "dm_control/walker-walk-v0", research_variants)["policy_kwargs"] == (
        "dict(residual_layer_norm=True, n_critics=2)"
    )
    assert added_policy_kwargs("dict()", "n_critics=2") == "dict(n_critics=2)"
    with pytest.raises(ValueError, match="expected 'dict"):
        added_policy_kwargs("{'a': 1}", "n_critics=2")


def test_the_main_job_sentence_reads_the_committed_reference_runs(tmp_path):
    """Ranges over the seeds' final_evaluation.json: returns 700 and 812.4, level 9 reached by one of two seeds."""
    page = results_page()
    for seed, value, events, speed in [
        (0, 700.0, [(9_000, 3), (20_500, 5), (40_000, 9)], 150.0),
        (1, 812.4, [(12_000, 3), (30_000, 5)], 171.6),
    ]:
        run = tmp_path / f"run{seed}"
        run.mkdir()
        summary = {
            "args": {**{key: value for key, value in page.MAIN_JOB_ARGS.items() if key != "threads"}, "seed": seed},
            "machine": {"threads": 1},
            "final_evaluation": {"return_mean": value},
            "env_steps_per_second": speed,
            "growth_events": [{"step": step, "active_bins": bins} for step, bins in events],
        }
        (run / "final_evaluation.json").write_text(json.dumps(summary))
        curve = [500.0, 875.0] if seed == 0 else [812.4]  # seed 0 ends at 700 / 875 = 0.80 of its best
        (run / "learning_curve.csv").write_text("step,return_\n" + "".join(f"{k},{v}\n" for k, v in enumerate(curve)))
    sentence = page.main_job_block(tmp_path)
    assert "Over seeds 0, 1 of the committed runs (`docs/results/reference_run/`, each made as `make results`" in sentence
    assert "the final greedy return is 700-812 (10 episodes each), 0.80-1.00 of each seed's best evaluation" in sentence
    assert "the levels open to 3 at 9k-12k steps, to 5 at 20k-30k steps, to 9 at 40k-40k steps (1 of 2 seeds)" in sentence
    assert "training runs at 150-172 env steps/s" in sentence


def test_the_main_job_sentence_refuses_runs_not_made_as_make_results_makes_them(tmp_path):
    page = results_page()
    (tmp_path / "run").mkdir()
    summary = {"args": {**page.MAIN_JOB_ARGS, "seed": 0}, "machine": {"threads": 2}}
    (tmp_path / "run" / "final_evaluation.json").write_text(json.dumps(summary))
    with pytest.raises(SystemExit, match=r"was not made as make results makes the main job: threads=2 \(make results: 1\)"):
        page.main_job_block(tmp_path)
    assert all(not page.made_as_make_results(json.loads(path.read_text()))
               for path in (REPOSITORY / "docs" / "results" / "reference_run").glob("*/final_evaluation.json"))  # fmt: skip


def test_make_results_runs_the_main_job_as_the_sentence_assumes():
    """The Makefile's reference-run line parses to :data:`MAIN_JOB_ARGS` (seed 0)."""
    from sb3_gqn.experiments.reference_run import load_hyperparams, parse_args, resolve_resolution

    makefile = (REPOSITORY / "Makefile").read_text()
    line = next(line for line in makefile.splitlines() if "sb3-gqn reference-run" in line)
    parsed = parse_args(line.split("reference-run", 1)[1].split())
    resolve_resolution(parsed, load_hyperparams(parsed.hyperparams, parsed.env))  # bins and growth: the entry's
    args = vars(parsed)
    expected = results_page().MAIN_JOB_ARGS
    assert {key: args[key] for key in expected} == expected and args["seed"] == 0
