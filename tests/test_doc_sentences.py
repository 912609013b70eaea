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
