"""Named configurations: the paper's protocol (Seyde et al., L4DC 2024, which follows "the general parameterization
of" DecQN, Seyde et al., ICLR 2023, and its public code ``tseyde/decqn``) for GQN and its two DecQN baselines.

::

    from sb3_gqn import GQN, DecQN, paper_preset

    gqn = GQN("MlpPolicy", env, **paper_preset("gqn-paper"))            # bins 2 -> 3 -> 5 -> 9, adaptive (eq. 4)
    linear = GQN("MlpPolicy", env, **paper_preset("gqn-paper-linear"))  # a level every 1/(N+1) of the budget
    decqn = DecQN("MlpPolicy", env, **paper_preset("decqn-paper-9"))    # or "decqn-paper-2"

From the command line: ``sb3-gqn train --preset gqn-paper --env dm_control/finger-turn_hard-v0`` (the env's entry gives
the budget and the action penalty; the preset replaces every other setting).

Every value is the paper's or the reference code's; the table :data:`PAPER_SOURCES` says where each is written. Where
the class defaults add something the paper does not have, the preset follows the paper: opened bins start as they are
(``init="none"``, no interpolation), eq. 4 alone decides growth (``patience=None``: no plateau rule; no probation),
and ``predict`` acts on the online network (``acting_tau=None``: no averaged acting network). The paper gives no
cadence for eq. 4's readings: the preset keeps the class default, one greedy episode every 5 % of the budget
(``eval_fraction``), a window of 3 readings.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from torch import nn

#: The settings every paper preset shares (GQN's and DecQN's constructor arguments), DecQN's reference values
_REFERENCE: Mapping[str, Any] = MappingProxyType(
    {
        "learning_rate": 1e-4,
        "buffer_size": 1_000_000,
        "learning_starts": 1000,
        "batch_size": 256,
        "gamma": 0.99,
        "train_freq": 8,
        "gradient_steps": 1,
        "n_steps": 3,
        "target_update_interval": 100,
        "tau": 1.0,
        "exploration_initial_eps": 0.1,
        "exploration_final_eps": 0.1,
        "exploration": "shared",
        "max_grad_norm": 40.0,
        "replay_buffer_kwargs": {"prioritized": True, "alpha": 0.6, "beta": 0.2, "beta_annealing": False},
        "acting_tau": None,
        "decoding": "argmax",
        "precision": "fp32",
        "policy_kwargs": {"net_arch": [512, 512], "layer_norm": True, "activation_fn": nn.ELU, "n_critics": 1},
    }
)

#: Where each value of the paper presets is written ("config" is ``decqn/config_default.py`` of ``tseyde/decqn``,
#: "agent" ``decqn/agents/dqn/agent.py``, "networks" ``decqn/agents/dqn/networks.py``, "paper" the GQN paper)
PAPER_SOURCES: Mapping[str, str] = MappingProxyType(
    {
        "learning_rate": "config: learning_rate = 1e-4 (Adam)",
        "buffer_size": "config: max_replay_size = 1000000",
        "learning_starts": "config: min_replay_size = 1000 (agent: min_observations = max(batch_size, min_replay_size))",
        "batch_size": "config: batch_size = 256",
        "gamma": "config: discount = 0.99",
        "train_freq": "agent: observations_per_step = batch_size / samples_per_insert = 256 / 32 = 8 env steps per "
        "learner step",
        "gradient_steps": "agent: one learner step per observations_per_step",
        "n_steps": "config: adder_n_step = 3; paper eq. 1 (n-step returns)",
        "target_update_interval": "config: target_update_period = 100 (learner steps)",
        "tau": "decqn/agents/dqn/learning.py: the online variables are copied to the target (a hard update)",
        "exploration_initial_eps": "config: epsilon = 0.1 (constant)",
        "exploration_final_eps": "config: epsilon = 0.1 (constant)",
        "exploration": "agent: epsilon_greedy of decqn/misc/utils.py (the project's 'shared' mode)",
        "max_grad_norm": "config: clip_gradients_norm = 40.0",
        "replay_buffer_kwargs": "config: priority_exponent = 0.6, importance_sampling_exponent = 0.2 (constant)",
        "acting_tau": "the paper acts on the online network (no averaged acting network)",
        "decoding": "the paper: greedy (argmax) bins",
        "precision": "the reference trains in float32",
        "policy_kwargs": "config: layer_size_network = [512, 512]; networks: Acme's LayerNormMLP (Linear, LayerNorm, "
        "tanh, then ELU); use_double_q = False (one critic)",
        "bins": "paper section 5: GQN 2 -> 9 ({2, 3, 5, 9}); DecQN 2 and DecQN 9",
        "growth": "paper section 4: the adaptive schedule (eq. 4) or the linear one (a level every 1/(N+1) of training)",
        "growth_kwargs": "paper section 4: eq. 4 alone (no plateau rule, no probation); opened bins are not warm-started",
    }
)

_PAPER_GROWTH = {"init": "none", "patience": None, "probation": None}

#: The named presets: which algorithm each builds (``"gqn"`` or ``"decqn"``) and its settings beyond :data:`_REFERENCE`
_PRESETS: Mapping[str, tuple[str, dict[str, Any]]] = MappingProxyType(
    {
        "gqn-paper": ("gqn", {"bins": (2, 9), "growth": "adaptive", "growth_kwargs": _PAPER_GROWTH}),
        "gqn-paper-linear": ("gqn", {"bins": (2, 9), "growth": "linear", "growth_kwargs": {"init": "none"}}),
        "decqn-paper-2": ("decqn", {"bins": 2}),
        "decqn-paper-9": ("decqn", {"bins": 9}),
    }
)
#: The preset names, e.g. for ``sb3-gqn train --preset``
PRESET_NAMES: tuple[str, ...] = tuple(_PRESETS)


def _checked(name: str) -> tuple[str, dict[str, Any]]:
    if name not in _PRESETS:
        raise ValueError(f"Unknown preset {name!r}: the presets are {', '.join(PRESET_NAMES)}")
    return _PRESETS[name]


def preset_algorithm(name: str) -> str:
    """The rl-zoo3 algorithm preset ``name`` builds: ``"gqn"`` or ``"decqn"``.

    :raises ValueError: naming the presets, for an unknown ``name``
    """
    return _checked(name)[0]


def paper_preset(name: str = "gqn-paper") -> dict[str, Any]:
    """The constructor arguments of preset ``name`` (:data:`PRESET_NAMES`), a fresh copy: pass them to
    ``GQN("MlpPolicy", env, **paper_preset("gqn-paper"))`` (``"gqn-paper"``, ``"gqn-paper-linear"``) or to
    ``DecQN`` (``"decqn-paper-2"``, ``"decqn-paper-9"``).

    :raises ValueError: naming the presets, for an unknown ``name``
    """
    _, settings = _checked(name)
    merged = {**_REFERENCE, **settings}
    return {key: dict(value) if isinstance(value, dict) else value for key, value in merged.items()}


def zoo_hyperparams(name: str) -> dict[str, Any]:
    """Preset ``name``'s settings as rl-zoo3 hyperparameters (``policy_kwargs`` as source text, as rl-zoo3's files
    write it): what ``sb3-gqn train --preset`` and the comparison runner set over an entry."""
    settings = paper_preset(name)
    policy_kwargs = settings["policy_kwargs"]
    parts = [
        f"{key}=nn.{value.__name__}" if isinstance(value, type) else f"{key}={value!r}" for key, value in policy_kwargs.items()
    ]
    settings["policy_kwargs"] = f"dict({', '.join(parts)})"
    return settings
