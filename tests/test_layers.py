"""The package's layers: the algorithm imports nothing from the rl-zoo3 integration, the experiments or the export."""

import subprocess
import sys

ALGORITHM_LAYER = [
    "sb3_gqn",
    "sb3_gqn.gqn",
    "sb3_gqn.decqn",
    "sb3_gqn.policies",
    "sb3_gqn.q_network",
    "sb3_gqn.torsos",
    "sb3_gqn.targets",
    "sb3_gqn.masking",
    "sb3_gqn.growth",
    "sb3_gqn.resolution",
    "sb3_gqn.buffers",
    "sb3_gqn.nstep_dict",
    "sb3_gqn.sum_tree",
    "sb3_gqn.wrappers",
    "sb3_gqn.envs",
    "sb3_gqn.arguments",
]
OTHER_LAYERS = [
    "rl_zoo3",
    "optuna",
    "sb3_gqn.zoo",
    "sb3_gqn.tuning",
    "sb3_gqn.train",
    "sb3_gqn.benchmark",
    "sb3_gqn.processes",
    "sb3_gqn.variants",
    "sb3_gqn.reference_run",
    "sb3_gqn.evaluation",
    "sb3_gqn.metrics",
    "sb3_gqn.plots",
    "sb3_gqn.report",
    "sb3_gqn.export",
]


def test_the_algorithm_layer_imports_no_other_layer():
    code = (
        "import importlib, sys\n"
        f"for name in {ALGORITHM_LAYER!r}: importlib.import_module(name)\n"
        f"print(sorted(name for name in {OTHER_LAYERS!r} if name in sys.modules))"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"
