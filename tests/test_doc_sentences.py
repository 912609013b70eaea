"""What the README and the documentation say about the product holds: each sentence a user would act on, checked
against the code."""

from __future__ import annotations

from pathlib import Path

import numpy as np
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
    **{
        f"{task}-v5": "Gymnasium MuJoCo's (one update per 4 env steps"
        for task in ("HalfCheetah", "Hopper", "Walker2d", "Ant", "Humanoid")
    },
}
TUNED = ("dm_control/finger-spin-v0", "dm_control/walker-walk-v0")
#: what an entry may set and still be the class defaults
DEFAULT_KEYS = {"n_timesteps", "policy", "env_wrapper", "bins", "growth"}


def test_every_entry_that_changes_a_default_says_so_in_a_comment():
    """An entry with keys beyond its budget, bins, growth and wrappers, or other bins than (3, 9) or (9, 65), has a
    comment: inside it, or in the lines right above it."""
    from sb3_gqn.zoo.hyperparams import HYPERPARAMS_DIR, read_entries

    for name in ("gqn.yml", "decqn.yml"):
        lines = (HYPERPARAMS_DIR / name).read_text().splitlines()
        starts = [index for index, line in enumerate(lines) if line and not line[0].isspace() and not line.startswith("#")]
        for env_id, entry in read_entries(HYPERPARAMS_DIR / name).items():
            static = name == "decqn.yml" and entry.get("bins") in (9, 65)
            if set(entry) <= DEFAULT_KEYS and (static or entry.get("bins") in ([3, 9], [9, 65])):
                continue
            start = next(index for index in starts if lines[index] == f"{env_id}:")
            following = [index for index in starts if index > start]
            block = lines[start + 1 : following[0] if following else len(lines)]
            above = lines[max(0, start - 3) : start]
            assert any(line.strip().startswith("#") for line in [*block, *above]), (name, env_id)


def test_the_untuned_entries_keep_the_class_defaults_but_the_named_exceptions():
    from sb3_gqn.zoo.hyperparams import HYPERPARAMS_DIR, read_entries

    readme = flat("README.md")
    assert "Only finger-spin and walker-walk were tuned." in readme
    for env_id, entry in read_entries(HYPERPARAMS_DIR / "gqn.yml").items():
        if env_id in TUNED:
            continue
        if env_id in EXCEPTIONS:
            assert EXCEPTIONS[env_id] in readme, env_id
            continue
        assert set(entry) <= DEFAULT_KEYS, env_id
        assert entry["growth"] == "adaptive" and entry["bins"] in ([3, 9], [9, 65]), env_id


def test_reference_run_help_says_the_entry_gives_bins_and_growth(capsys):
    from sb3_gqn.experiments.reference_run import load_hyperparams, parse_args
    from sb3_gqn.zoo.hyperparams import HYPERPARAMS_DIR

    with pytest.raises(SystemExit):
        parse_args(["--help"])
    assert "--bins and --growth replace the entry's" in " ".join(capsys.readouterr().out.split())
    arguments = load_hyperparams(str(HYPERPARAMS_DIR / "gqn.yml"), "dm_control/cartpole-swingup-v0")
    assert arguments == {"n_timesteps": 70_000.0, "bins": [3, 9], "growth": "adaptive"}


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


def raised(function) -> str:
    try:
        function()
    except (ValueError, TypeError) as error:
        return " ".join(str(error).split())
    raise AssertionError("no error")


def test_the_bad_input_table_gives_the_messages_the_code_raises(tmp_path):
    """Each row's quoted message is the start of what the code raises for that input."""
    import gymnasium as gym
    from stable_baselines3 import SAC

    from sb3_gqn import GQN, DecQN
    from sb3_gqn.common.wrappers import ActionRatePenalty
    from tests.envs import DecliningEnv

    tiny = dict(policy_kwargs=dict(net_arch=[8]), learning_starts=10, batch_size=8, buffer_size=1_000)
    GQN("MlpPolicy", DecliningEnv(), **tiny).save(tmp_path / "model.zip")
    (tmp_path / "cut.zip").write_bytes((tmp_path / "model.zip").read_bytes()[:100])
    rate = ActionRatePenalty(gym.make("Pendulum-v1"))
    rate.reset(seed=0)
    model = GQN("MlpPolicy", DecliningEnv(), bins=(2, 9), growth=None, **tiny)
    many_choices = DecliningEnv()
    many_choices.action_space = gym.spaces.Discrete(2000)
    cases = {
        "bins must be an int >= 2 or an (initial, final) pair of ints, got '9'": lambda: GQN(
            "MlpPolicy", DecliningEnv(), bins="9"
        ),
        "bins must be integers >= 2, got initial=2.0 (float)": lambda: GQN("MlpPolicy", DecliningEnv(), bins=(2.0, 9)),
        "bins=(2, 8) cannot be nested: doubling the intervals from 2 bins gives [2, 3, 5] then 9, never 8": lambda: GQN(
            "MlpPolicy", DecliningEnv(), bins=(2, 8)
        ),
        "bins: at most MAX_BINS=1025 bins per action dimension (four doublings above the paper's finest, 65), got "
        "1000000000": lambda: GQN("MlpPolicy", DecliningEnv(), bins=10**9),
        "bins must be a single int from 2 to MAX_BINS=1025 for DecQN, got (2, 9); use GQN for (initial, final) "
        "pairs": lambda: DecQN("MlpPolicy", DecliningEnv(), bins=(2, 9)),
        "the env's action space Discrete(2000) has 2000 choices per dimension: GQN and DecQN take at most "
        "MAX_BINS=1025": lambda: GQN("MlpPolicy", many_choices),
        "bins=(3, 9) needs 9 choices per action dimension, but the env's action space Discrete(2) has 2: pass bins=2 "
        "(or a pair ending in it)": lambda: GQN("MlpPolicy", "CartPole-v1", bins=(3, 9)),
        "decoding_kwargs['temperature'] must be None or a number in [1.175e-38, 3.403e+38], float32's positive normal "
        "range (the utilities are float32: outside it the temperature is 0 or inf there and the softmax is NaN)": lambda: GQN(
            "MlpPolicy", DecliningEnv(), decoding_kwargs=dict(temperature=1e300)
        ),
        "growth_kwargs has no setting 'patiense': its keys are ('init', 'eval_freq', 'eval_fraction', 'eval_episodes', "
        "'window', 'returns_source', 'patience', 'min_improvement', 'probation')": lambda: GQN(
            "MlpPolicy", DecliningEnv(), growth_kwargs=dict(patiense=3)
        ),
        "replay_buffer_kwargs['alpha'] must be a finite number in [0, inf), got -1": lambda: GQN(
            "MlpPolicy", DecliningEnv(), replay_buffer_kwargs=dict(alpha=-1)
        ),
        "policy_kwargs['net_arch'] must be a list of layer sizes, integers >= 1, got [0]": lambda: GQN(
            "MlpPolicy", DecliningEnv(), policy_kwargs=dict(net_arch=[0])
        ),
        "replay_buffer_kwargs['n_steps']=5 contradicts n_steps=3, which sets it: pass n_steps=5 instead": lambda: GQN(
            "MlpPolicy", DecliningEnv(), replay_buffer_kwargs=dict(n_steps=5)
        ),
        "seed must be None or an integer in [0, 2**32 - 1], got -1": lambda: GQN("MlpPolicy", DecliningEnv(), seed=-1),
        "total_timesteps must be an integer >= 0, got -5": lambda: model.learn(-5),
        "callback[0] must be a BaseCallback or a callable, got None": lambda: model.learn(1, callback=[None]),
        "log_interval must be an integer >= 1 (episodes between log dumps) or None, got 0": lambda: model.learn(
            1, log_interval=0
        ),
        "policy='MultiInputPolicy' needs a Dict observation, but this env's is Box(-1.0, 1.0, (3,), float32): use "
        "'MlpPolicy' (or 'CnnPolicy' for images)": lambda: GQN("MultiInputPolicy", DecliningEnv()),
        "policy='CnnPolicy' needs an image observation": lambda: GQN("CnnPolicy", DecliningEnv()),
        "env is None: GQN builds its networks from the env's spaces; pass an env or an env id, or load a saved model "
        "with GQN.load(path)": lambda: GQN("MlpPolicy", None),
        "env='NoSuchEnv-v0' is no Gymnasium env id this installation knows: Environment `NoSuchEnv` doesn't exist.": (
            lambda: GQN("MlpPolicy", "NoSuchEnv-v0")
        ),
        "device must be 'auto', a torch.device or a device string torch reads ('cpu', 'cuda', 'cuda:1', 'mps', ...), "
        "got 'gpu'": lambda: GQN("MlpPolicy", DecliningEnv(), device="gpu"),
        "verbose must be an integer >= 0, got '1'": lambda: GQN("MlpPolicy", DecliningEnv(), verbose="1"),
        "acting_tau must be a finite number in (0, 1], got 0; None switches it off (act on the online network)": lambda: GQN(
            "MlpPolicy", DecliningEnv(), acting_tau=0
        ),
        "predict()'s observation is a dict, but the model observes Box(-1.0, 1.0, (3,), float32): pass an array of "
        "shape (3,) (or (n_envs, *(3,)) for a batch)": lambda: model.predict({"state": np.zeros(3)}),
        "callback must be a BaseCallback, a list of them, a callable or None, got 'x'": lambda: model.learn(1, callback="x"),
        "level must be an integer index into bin_levels [2, 3, 5, 9] (or None), got 1.5": lambda: model.grow(1.5),
        "A GQN or DecQN policy acts on bin indices (Discrete or MultiDiscrete), got Box(": lambda: SAC.load(
            tmp_path / "model.zip"
        ),
        "is not a whole model file": lambda: GQN.load(tmp_path / "cut.zip"),
        "is not a replay-buffer file (UnpicklingError": lambda: model.load_replay_buffer(tmp_path / "model.zip"),
        "ActionRatePenalty: coef, the action rate penalty coefficient, must be a finite number >= 0, got '0.1'": lambda: (
            ActionRatePenalty(gym.make("Pendulum-v1"), coef="0.1")
        ),
        "is not finite (index (0,): nan); the env was not stepped": lambda: rate.step(np.array([np.nan])),
    }
    table = flat("docs/modules/gqn.rst")
    table = table[table.index(".. rubric:: Bad input") : table.index("Replay-buffer files")]
    for message, function in cases.items():
        assert message in raised(function), message
        assert message in table, message


def test_the_gqn_page_quotes_the_line_auto_precision_says(monkeypatch):
    from sb3_gqn.common import precision

    monkeypatch.setattr(precision, "cpu_flags", lambda: frozenset({"avx512f", "avx512_bf16"}))
    line = f"GQN: {precision.resolution_note('auto', 'cpu')}"
    assert line == 'GQN: precision="auto" resolved to "bf16" (this CPU has AVX-512 BF16 matrix instructions)'
    assert f"``{line}``" in flat("docs/modules/gqn.rst")
