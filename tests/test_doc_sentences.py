"""What the README and the documentation say about the product holds: each sentence a user would act on, checked
against the code."""

from __future__ import annotations

from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parents[1]


def flat(path: str) -> str:
    """A document's text with its line breaks and runs of spaces as single spaces."""
    return " ".join((REPOSITORY / path).read_text().split())


def test_the_quick_starts_dict_observation_sentence_holds():
    """``GQN("MultiInputPolicy", id)`` keeps the ``Dict`` observation; ``MlpPolicy`` with the bare id names both ways."""
    pytest.importorskip("shimmy")
    from gymnasium import spaces

    from sb3_gqn import GQN

    quickstart = flat("docs/quickstart.rst")
    assert '``GQN("MultiInputPolicy", "dm_control/cartpole-swingup-v0")`` also works' in quickstart
    model = GQN("MultiInputPolicy", "dm_control/cartpole-swingup-v0", policy_kwargs=dict(net_arch=[8]), buffer_size=1000)
    assert isinstance(model.observation_space, spaces.Dict) and model.bins == (3, 9)
    with pytest.raises(ValueError, match=r"policy='MlpPolicy' needs a flat observation.*'MultiInputPolicy', or flatten"):
        GQN("MlpPolicy", "dm_control/cartpole-swingup-v0")


def test_the_intros_name_the_default_levels():
    from gymnasium import spaces

    from sb3_gqn.gqn.growth.schedules import bin_levels_from, default_bins

    levels = " -> ".join(map(str, bin_levels_from(default_bins(spaces.Box(-1, 1, (1,)))[0])))
    assert levels == "3 -> 5 -> 9"
    for path in ("README.md", "docs/index.rst", "docs/modules/gqn.rst"):
        text = flat(path)
        assert f"by default {levels} bins" in text, path
        assert "from bang-bang (2 bins) to fine" not in text and "Training starts at bang-bang" not in text, path


#: the untuned entries that set more than their bins, as the README names them
EXCEPTIONS = {
    "Pendulum-v1": "Pendulum's (the quick demo",
    "FetchReachDense-v4": "FetchReachDense's (bins `[2, 9]`)",
    "FetchReach-v4": "FetchReach's (SB3's HER settings",
    "myoHandPoseRandom-v0": "MyoSuite's hand tasks' (gamma 0.95, 2048 x 2048)",
    "myoHandReachFixed-v0": "MyoSuite's hand tasks'",
    "myoHandKeyTurnFixed-v0": "MyoSuite's hand tasks'",
}
TUNED = ("dm_control/cartpole-swingup-v0", "dm_control/finger-spin-v0", "dm_control/walker-walk-v0")


def test_the_untuned_entries_keep_the_class_defaults_but_the_named_exceptions():
    from sb3_gqn.zoo.hyperparams import HYPERPARAMS_DIR, read_entries

    readme = flat("README.md")
    assert "Only cartpole-swingup, finger-spin and walker-walk were tuned." in readme
    for env_id, entry in read_entries(HYPERPARAMS_DIR / "gqn.yml").items():
        if env_id in TUNED:
            continue
        if env_id in EXCEPTIONS:
            assert EXCEPTIONS[env_id] in readme, env_id
            continue
        assert set(entry) <= {"n_timesteps", "policy", "env_wrapper", "bins", "growth"}, env_id
        assert entry["growth"] == "adaptive" and entry["bins"] in ([3, 9], [9, 65]), env_id


def test_reference_run_help_says_which_entry_keys_it_ignores(capsys):
    from sb3_gqn.experiments.reference_run import load_hyperparams, parse_args
    from sb3_gqn.zoo.hyperparams import HYPERPARAMS_DIR

    with pytest.raises(SystemExit):
        parse_args(["--help"])
    assert "its bins and growth are ignored: --bins and --growth set them" in " ".join(capsys.readouterr().out.split())
    arguments = load_hyperparams(str(HYPERPARAMS_DIR / "gqn.yml"), "dm_control/cartpole-swingup-v0")
    assert "bins" not in arguments and "growth" not in arguments and arguments["train_freq"] == 2


def test_train_help_names_the_default_files_and_gqns_options(capsys):
    from sb3_gqn.zoo.cli import train

    assert train(["--help"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("sb3-gqn train: rl-zoo3's train with gqn and decqn registered")
    assert "sb3_gqn/zoo/hyperparams/<algo>.yml" in out and '-params bins:"(3, 9)"' in out and "--algo" in out


def test_how_to_replicate_trains_what_it_lists(tmp_path, capsys):
    """The README's replication command lists runs that a fresh folder trains; in the committed folder every one is
    recorded already."""
    from sb3_gqn.experiments.runner import main

    readme = (REPOSITORY / "README.md").read_text()
    section = readme[readme.index("## How to replicate") :]
    command = section[section.index("sb3-gqn benchmark") : section.index("--list") + len("--list")]
    argv = command.replace("\\\n", " ").split()[2:]
    out = argv.index("--out") + 1
    assert argv[out] == "results/walker-walk_c0.1_100k" and "`--list` shows the 6 runs" in flat("README.md")
    argv[out] = str(tmp_path / "fresh")
    assert main(argv) == 0
    assert "6 runs, 0 already finished, 6 to train" in capsys.readouterr().out
    argv[out] = str(REPOSITORY / "docs" / "results" / "walker-walk_c0.1_100k")
    assert main(argv) == 0
    assert "6 runs, 6 already finished, 0 to train" in capsys.readouterr().out
