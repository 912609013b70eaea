"""The comparison suite's agents and runs: runner variants over the shipped hyperparameter entries (``VARIANTS``),
the suites (``SHORT_SUITE``, ``FULL_SUITE``, ``ABLATION``), one run (``RunSpec``) and what each run trains and is
evaluated on (its rl-zoo3 algorithm, the overrides on its entry, its penalized evaluation env).

Experiments layer: used by :mod:`sb3_gqn.benchmark` (the runner), :mod:`sb3_gqn.ray_suite` and
:mod:`sb3_gqn.report`.
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass
from typing import Any

import gymnasium as gym

#: GQN-adaptive as it was before warm start, the plateau rule and shared exploration (issue 11's ablation)
BEFORE_GROWTH_FIXES: dict[str, Any] = {
    "growth": "adaptive",
    "growth_init": "none",
    "growth_patience": None,
    "growth_eval_freq": 5_000,
    "exploration": "per_dimension",
    "acting_tau": None,
}
#: Shipped entries as they were before issue 11 changed them; the ablation (``gqn-before*``) runs on these, so
#: that its seeds stay comparable with the ones recorded before the change
ENTRIES_BEFORE_ISSUE_11: dict[str, dict[str, Any]] = {
    "dm_control/walker-walk-v0": {"train_freq": 2, "policy_kwargs": None},
    "dm_control/finger-spin-v0": {"train_freq": 2, "policy_kwargs": None},
}
REFERENCE_TORSO = "dict(layer_norm=True, activation_fn=nn.ELU)"
RESIDUAL_TORSO = "dict(residual_layer_norm=True)"
#: Algorithm variants: (rl-zoo3 algorithm, hyperparameter overrides on its shipped file)
VARIANTS: dict[str, tuple[str, dict[str, Any]]] = {
    "gqn-adaptive": ("gqn", {"growth": "adaptive"}),
    "gqn-linear": ("gqn", {"growth": "linear"}),
    "decqn-2": ("decqn", {"bins": 2}),
    "decqn-9": ("decqn", {"bins": 9}),
    "sac": ("sac", {}),
    "td3": ("td3", {}),
    # ablation: the old behaviour, then each change alone
    "gqn-before": ("gqn", BEFORE_GROWTH_FIXES),
    "gqn-before+warm-start": ("gqn", {**BEFORE_GROWTH_FIXES, "growth_init": "interpolate"}),
    "gqn-before+plateau": ("gqn", {**BEFORE_GROWTH_FIXES, "growth_patience": 2, "growth_eval_freq": 2_500}),
    "gqn-before+shared": ("gqn", {**BEFORE_GROWTH_FIXES, "exploration": "shared"}),
    # DecQN's reference torso (Acme's LayerNormMLP): Linear -> LayerNorm -> tanh, then ELU layers; alone, at the
    # 1 update per 2 env steps its walker runs were recorded with (walker's and finger's entries now ship 1 per step)
    "gqn-adaptive+layernorm": ("gqn", {"growth": "adaptive", "policy_kwargs": REFERENCE_TORSO, "train_freq": 2}),
    "decqn-9+layernorm": ("decqn", {"bins": 9, "policy_kwargs": REFERENCE_TORSO, "train_freq": 2}),
    # ... with 1 gradient step per env step (SAC's ratio) instead of 1 per 2
    "gqn-adaptive+layernorm+1update": ("gqn", {"growth": "adaptive", "policy_kwargs": REFERENCE_TORSO, "train_freq": 1}),
    "gqn-linear+layernorm+1update": ("gqn", {"growth": "linear", "policy_kwargs": REFERENCE_TORSO, "train_freq": 1}),
    "decqn-2+layernorm+1update": ("decqn", {"bins": 2, "policy_kwargs": REFERENCE_TORSO, "train_freq": 1}),
    "decqn-9+layernorm+1update": ("decqn", {"bins": 9, "policy_kwargs": REFERENCE_TORSO, "train_freq": 1}),
    # DecQN's residual torso as its reference experiments run it (use_residual=True): LayerNorm(x + MLP(x)) + ELU
    # and VarianceScaling(1/3) initialization, at cartpole's 1 update per 2 env steps and walker's/finger's 1 per step
    "gqn-adaptive+residual": ("gqn", {"growth": "adaptive", "policy_kwargs": RESIDUAL_TORSO, "train_freq": 2}),
    "gqn-adaptive+residual+1update": ("gqn", {"growth": "adaptive", "policy_kwargs": RESIDUAL_TORSO, "train_freq": 1}),
    "decqn-9+residual": ("decqn", {"bins": 9, "policy_kwargs": RESIDUAL_TORSO, "train_freq": 2}),
    "decqn-9+residual+1update": ("decqn", {"bins": 9, "policy_kwargs": RESIDUAL_TORSO, "train_freq": 1}),
    "gqn-linear+residual+1update": ("gqn", {"growth": "linear", "policy_kwargs": RESIDUAL_TORSO, "train_freq": 1}),
    "decqn-2+residual+1update": ("decqn", {"bins": 2, "policy_kwargs": RESIDUAL_TORSO, "train_freq": 1}),
    # probation of opened levels (growth_probation): predict keeps the previous level until a greedy episode over the
    # new one holds the return, at most 4 evaluations; on the entry's own torso and update ratio
    "gqn-adaptive+probation": ("gqn", {"growth": "adaptive", "growth_probation": 4}),
    # two critics (DecQN's use_double_q) on the entry's own torso and update ratio (POLICY_KWARGS_ADDED)
    "gqn-adaptive+twin": ("gqn", {"growth": "adaptive"}),
    "decqn-9+twin": ("decqn", {"bins": 9}),
    # acting on a Polyak-averaged copy of the online network (acting_tau, rule D3; 0.001 is the default since rule
    # D4, so +avg0.001 trains and acts as the plain name), training unchanged; +online acts on the online network
    # (acting_tau=None), as every run recorded before D4 did
    "gqn-adaptive+avg0.005": ("gqn", {"growth": "adaptive", "acting_tau": 0.005}),
    "gqn-adaptive+avg0.001": ("gqn", {"growth": "adaptive", "acting_tau": 0.001}),
    "decqn-9+avg0.005": ("decqn", {"bins": 9, "acting_tau": 0.005}),
    "decqn-9+avg0.001": ("decqn", {"bins": 9, "acting_tau": 0.001}),
    "gqn-linear+avg0.001": ("gqn", {"growth": "linear", "acting_tau": 0.001}),
    "decqn-2+avg0.001": ("decqn", {"bins": 2, "acting_tau": 0.001}),
    "gqn-adaptive+online": ("gqn", {"growth": "adaptive", "acting_tau": None}),
    "decqn-9+online": ("decqn", {"bins": 9, "acting_tau": None}),
}
#: Policy keyword arguments a variant adds to its entry's ``policy_kwargs`` (keeping the entry's torso), as the
#: source of a ``dict(...)`` call like the entries' own
POLICY_KWARGS_ADDED: dict[str, str] = {"gqn-adaptive+twin": "n_critics=2", "decqn-9+twin": "n_critics=2"}


def warm_started(algo: str) -> bool:
    """Whether runner variant ``algo`` opens bins with a warm start (``growth_init="interpolate"``, the class default
    and every shipped entry's): all variants but the ``gqn-before`` ablation's without ``+warm-start``. Names the
    runner does not know (tables written elsewhere) count as warm-started, the default."""
    _, overrides = VARIANTS.get(algo, ("gqn", {}))
    return overrides.get("growth_init", "interpolate") == "interpolate"


ABLATION = ["gqn-before", "gqn-before+warm-start", "gqn-before+plateau", "gqn-before+shared", "gqn-adaptive"]
SHORT_SUITE = dict(
    algos=["gqn-linear", "decqn-2", "decqn-9", "sac"], envs=["Pendulum-v1"], penalties=[0.1], seeds=[0], steps=10_000
)
FULL_SUITE = dict(
    algos=["gqn-adaptive", "gqn-linear", "decqn-2", "decqn-9", "sac", "td3"],
    envs=[
        "dm_control/cartpole-swingup-v0",
        "dm_control/reacher-easy-v0",
        "dm_control/finger-spin-v0",
        "dm_control/walker-walk-v0",
        "dm_control/cheetah-run-v0",
        "dm_control/humanoid-walk-v0",
        "sb3_gqn/metaworld-reach-v3",
    ],
    penalties=[0.0, 0.1, 0.5],
    seeds=[0, 1, 2, 3],
    steps=1_000_000,
)


@dataclass(frozen=True)
class RunSpec:
    """One training run of the suite."""

    algo: str
    env: str
    penalty: float
    seed: int
    steps: int

    @property
    def key(self) -> tuple[str, str, float, int]:
        """``(algo, env, penalty, seed)``: how ``results.csv`` identifies the run."""
        return self.algo, self.env, float(self.penalty), self.seed

    @property
    def name(self) -> str:
        return f"{self.algo}__{self.env.replace('/', '-')}__c{self.penalty:g}__seed{self.seed}"


def penalized_wrappers(env_wrapper: Any, penalty: float) -> list[Any]:
    """The entry's ``env_wrapper`` list with the ``ActionPenalty`` coefficient set to ``penalty``."""
    wrappers = [] if env_wrapper is None else list(env_wrapper if isinstance(env_wrapper, list) else [env_wrapper])
    name = "sb3_gqn.wrappers.ActionPenalty"
    kept = [w for w in wrappers if not (w == name or (isinstance(w, dict) and name in w))]
    return [*kept, {name: {"coef": float(penalty)}}]


def run_overrides(spec: RunSpec) -> tuple[str, dict[str, Any]]:
    """The run's rl-zoo3 algorithm and the hyperparameters its variant sets over the shipped entry."""
    zoo_algo, overrides = VARIANTS[spec.algo]
    if spec.algo.startswith("gqn-before"):
        overrides = {**ENTRIES_BEFORE_ISSUE_11.get(spec.env, {}), **overrides}
    if spec.algo in POLICY_KWARGS_ADDED:
        entry_kwargs = shipped_entry(zoo_algo, spec.env).get("policy_kwargs")
        overrides = {**overrides, "policy_kwargs": added_policy_kwargs(entry_kwargs, POLICY_KWARGS_ADDED[spec.algo])}
    return zoo_algo, overrides


def added_policy_kwargs(entry_kwargs: str | None, added: str) -> str:
    """An entry's ``policy_kwargs`` source (``"dict(...)"`` or none) with the keyword arguments ``added``:
    ``added_policy_kwargs("dict(residual_layer_norm=True)", "n_critics=2")`` is
    ``"dict(residual_layer_norm=True, n_critics=2)"``."""
    if entry_kwargs is None:
        return f"dict({added})"
    source = str(entry_kwargs).strip()
    if not (source.startswith("dict(") and source.endswith(")")):
        raise ValueError(f"Cannot add {added!r} to policy_kwargs {source!r}: expected 'dict(...)'")
    inner = source[len("dict(") : -1].strip()
    return f"dict({inner}, {added})" if inner else f"dict({added})"


def learning_starts(spec: RunSpec) -> int:
    """Steps of random actions before a run's first gradient step (its entry's value, else the class default)."""
    zoo_algo, overrides = run_overrides(spec)
    entry = {**shipped_entry(zoo_algo, spec.env), **overrides}
    if "learning_starts" in entry:
        return int(entry["learning_starts"])
    from stable_baselines3 import SAC, TD3

    from sb3_gqn import GQN

    algorithm = {"gqn": GQN, "decqn": GQN, "sac": SAC, "td3": TD3}[zoo_algo]  # DecQN passes its kwargs to GQN
    return int(inspect.signature(algorithm).parameters["learning_starts"].default)


def untrained_runs(specs: list[RunSpec]) -> list[str]:
    """One warning per algorithm and env whose budget does not exceed its ``learning_starts``: such runs never
    train, and their rows look like a result."""
    warnings = {}
    for spec in specs:
        starts = learning_starts(spec)
        if spec.steps <= starts:
            warnings[(spec.algo, spec.env)] = (
                f"NO LEARNING: {spec.algo} on {spec.env} has a budget of {spec.steps} steps <= its learning_starts={starts}"
            )
    return list(warnings.values())


def make_eval_env(spec: RunSpec) -> gym.Env:
    """A single env for the run's greedy evaluations: ``spec.env`` with its entry's wrappers, the action penalty
    set to ``spec.penalty``. Call :func:`sb3_gqn.zoo.register` first for the dm_control and Meta-World ids."""
    from rl_zoo3.utils import get_wrapper_class

    zoo_algo, _ = run_overrides(spec)
    wrappers = penalized_wrappers(shipped_entry(zoo_algo, spec.env).get("env_wrapper"), spec.penalty)
    wrapper = get_wrapper_class({"env_wrapper": wrappers})
    env = gym.make(spec.env)
    return wrapper(env) if wrapper is not None else env


def shipped_entry(zoo_algo: str, env_id: str) -> dict[str, Any]:
    import yaml

    from sb3_gqn.zoo import shipped_hyperparams

    path = shipped_hyperparams(zoo_algo)
    with open(path) as handle:  # type: ignore[arg-type]
        entries = yaml.safe_load(handle)
    if env_id not in entries:
        raise ValueError(f"{path} has no entry for {env_id!r} (entries: {', '.join(entries)})")
    return entries[env_id]
