"""The comparison suite's agents and runs: the agents (:data:`VARIANTS`: the shipped agents; more from variants files,
:func:`load_variants` and :func:`with_variants_files`, passed explicitly to what needs them), the suites
(:data:`SHORT_SUITE`, :data:`FULL_SUITE`), one run (:class:`RunSpec`) and what each run trains and is evaluated on (its
rl-zoo3 algorithm, the overrides on its shipped entry, its penalized evaluation env).

A variants file (YAML) names further agents, each as the rl-zoo3 algorithm it trains and the hyperparameters it sets
over that algorithm's shipped entry::

    gqn-adaptive+twin:                 # the name the runner's --algos and results.csv use
      algo: gqn                        # gqn, decqn, sac, td3 or sbx_sac (sbx-sac): whose shipped entry it starts from
      hyperparams: {growth: adaptive}  # set over the entry (rl-zoo3's format: policy_kwargs as source text)
      add_policy_kwargs: n_critics=2   # optional: keyword arguments added to the entry's policy_kwargs
      env_hyperparams:                 # optional: per env, set over the entry before ``hyperparams``
        dm_control/walker-walk-v0: {train_freq: 2}
      add_env_wrappers:                # optional: wrappers around the entry's (rl-zoo3's env_wrapper format), in
        - sb3_gqn.common.wrappers.ActionRatePenalty: {coef: 0.1}   # training and evaluation
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import gymnasium as gym

from sb3_gqn.common.presets import PRESET_NAMES, preset_algorithm, zoo_hyperparams
from sb3_gqn.zoo.hyperparams import read_entries, shipped_entry


@dataclass(frozen=True)
class Variant:
    """An agent of the suite: the rl-zoo3 algorithm it trains and what it sets over that algorithm's shipped entry."""

    algo: str
    hyperparams: dict[str, Any] = field(default_factory=dict, hash=False)
    add_policy_kwargs: str | None = None
    env_hyperparams: dict[str, dict[str, Any]] = field(default_factory=dict, hash=False)
    add_env_wrappers: list[Any] = field(default_factory=list, hash=False)

    def overrides(self, env_id: str) -> dict[str, Any]:
        """The hyperparameters this agent sets over its entry for ``env_id``."""
        overrides = {**self.env_hyperparams.get(env_id, {}), **self.hyperparams}
        if self.add_policy_kwargs is not None:
            entry_kwargs = shipped_entry(self.algo, env_id).get("policy_kwargs")
            overrides["policy_kwargs"] = added_policy_kwargs(entry_kwargs, self.add_policy_kwargs)
        return overrides


#: The shipped agents, by runner name (read-only: agents of a variants file go into a mapping of their own,
#: :func:`with_variants_files`)
VARIANTS: Mapping[str, Variant] = MappingProxyType(
    {
        "gqn-adaptive": Variant("gqn", {"growth": "adaptive"}),
        "gqn-linear": Variant("gqn", {"growth": "linear"}),
        "decqn-2": Variant("decqn", {"bins": 2}),
        "decqn-9": Variant("decqn", {"bins": 9}),
        "sac": Variant("sac"),
        "td3": Variant("td3"),
        # SBX's SAC (JAX, the sbx extra): SAC with the same entries, run faster
        "sbx-sac": Variant("sbx_sac"),
        # the paper's protocol (sb3_gqn.common.presets): gqn-paper, gqn-paper-linear, decqn-paper-2, decqn-paper-9
        **{name: Variant(preset_algorithm(name), zoo_hyperparams(name)) for name in PRESET_NAMES},
    }
)
ZOO_ALGOS = ("gqn", "decqn", "sac", "td3", "sbx_sac")


def agent_name(name: str, agents: Iterable[str] = VARIANTS) -> str:
    """The runner's spelling of agent ``name``: with hyphens where rl-zoo3's algorithm names have underscores
    (``sbx_sac``, as ``sb3-gqn train --algo`` takes it, is the agent ``sbx-sac``), when that spelling is one of
    ``agents``; any other name as given."""
    names = set(agents)
    hyphenated = name.replace("_", "-")
    return hyphenated if name not in names and hyphenated in names else name


def load_variants(path: str | Path, known: Mapping[str, Variant] = VARIANTS) -> dict[str, Variant]:
    """Read a variants file (format in the module's docstring): its agents, by name. Nothing global changes: pass
    them (with the shipped ones, :func:`with_variants_files`) to what runs or reads them.

    :param path: the variants file
    :param known: the agents it may not redefine (default: the shipped ones)
    :return: the file's agents
    :raises ValueError: for an entry without a known ``algo``, with unknown keys, or redefining an agent of ``known``
    """
    loaded = {}
    for name, entry in read_entries(path).items():
        unknown = set(entry) - {"algo", "hyperparams", "add_policy_kwargs", "env_hyperparams", "add_env_wrappers"}
        algo = str(entry.get("algo")).replace("-", "_")  # sbx-sac, the runner's agent name, is rl-zoo3's sbx_sac
        if algo not in ZOO_ALGOS or unknown:
            raise ValueError(
                f"{path}: variant {name!r} needs 'algo' (one of {ZOO_ALGOS}) and only the keys hyperparams, "
                f"add_policy_kwargs, env_hyperparams, add_env_wrappers; got {sorted(entry)}"
            )
        variant = Variant(
            algo,
            dict(entry.get("hyperparams") or {}),
            entry.get("add_policy_kwargs"),
            {env: dict(values or {}) for env, values in (entry.get("env_hyperparams") or {}).items()},
            list(entry.get("add_env_wrappers") or []),
        )
        if name in known and known[name] != variant:
            raise ValueError(f"{path}: variant {name!r} redefines an agent the runner already has")
        loaded[name] = variant
    return loaded


def with_variants_files(paths: Iterable[str | Path] = ()) -> dict[str, Variant]:
    """The shipped agents (:data:`VARIANTS`) and those of the variants files ``paths``, by name, in that order.

    :raises ValueError: as :func:`load_variants`, also for a file redefining an earlier file's agent
    """
    variants = dict(VARIANTS)
    for path in paths:
        variants.update(load_variants(path, variants))
    return variants


def warm_started(algo: str, variants: Mapping[str, Variant] = VARIANTS) -> bool:
    """Whether agent ``algo`` of ``variants`` opens bins with a warm start (``growth_kwargs=dict(init="interpolate")``,
    the class default and every shipped entry's; a variants file of 0.2 may still spell it ``growth_init``). Names
    ``variants`` does not hold (tables written elsewhere) count as warm-started."""
    variant = variants.get(algo)
    if variant is None:
        return True
    growth_kwargs = variant.hyperparams.get("growth_kwargs") or {}
    init = growth_kwargs.get("init", variant.hyperparams.get("growth_init", "interpolate"))
    return init == "interpolate"


SHORT_SUITE: dict[str, Any] = dict(
    algos=["gqn-linear", "decqn-2", "decqn-9", "sac"], envs=["Pendulum-v1"], penalties=[0.1], seeds=[0], steps=10_000
)
FULL_SUITE: dict[str, Any] = dict(
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
    #: what the agent ``algo`` trains (default: the shipped agent of that name, :data:`VARIANTS`; :meth:`of` takes it
    #: from other agents); carried with the run to worker processes
    variant: Variant | None = field(default=None, compare=False)

    @classmethod
    def of(
        cls, algo: str, env: str, penalty: float, seed: int, steps: int, variants: Mapping[str, Variant] = VARIANTS
    ) -> RunSpec:
        """The run of agent ``algo`` of ``variants`` (e.g. :func:`with_variants_files`' agents).

        :raises ValueError: for an agent ``variants`` does not hold
        """
        if algo not in variants:
            raise ValueError(f"Unknown agent {algo!r}: {', '.join(variants)} (more through a variants file)")
        return cls(algo, env, penalty, seed, steps, variants[algo])

    def __post_init__(self) -> None:
        if isinstance(self.steps, bool) or not isinstance(self.steps, int) or self.steps < 1:
            raise ValueError(f"steps must be an integer >= 1, got {self.steps!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise ValueError(f"seed must be an integer >= 0, got {self.seed!r}")
        if not math.isfinite(self.penalty) or self.penalty < 0:
            raise ValueError(f"penalty must be a finite number >= 0, got {self.penalty!r}")
        if self.variant is None:
            if self.algo not in VARIANTS:
                raise ValueError(
                    f"Unknown agent {self.algo!r}: {', '.join(VARIANTS)} (an agent of a variants file: RunSpec.of)"
                )
            object.__setattr__(self, "variant", VARIANTS[self.algo])

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
    name = "sb3_gqn.common.wrappers.ActionPenalty"
    kept = [w for w in wrappers if not (w == name or (isinstance(w, dict) and name in w))]
    return [*kept, {name: {"coef": float(penalty)}}]


def run_wrappers(spec: RunSpec) -> list[Any]:
    """The run's ``env_wrapper`` list: its entry's, with the ``ActionPenalty`` coefficient set to ``spec.penalty``, then
    the wrappers its agent adds (``add_env_wrappers``), for training and evaluation alike."""
    assert spec.variant is not None  # set by RunSpec.__post_init__
    wrappers = penalized_wrappers(shipped_entry(spec.variant.algo, spec.env).get("env_wrapper"), spec.penalty)
    return [*wrappers, *spec.variant.add_env_wrappers]


def run_overrides(spec: RunSpec) -> tuple[str, dict[str, Any]]:
    """The run's rl-zoo3 algorithm and the hyperparameters its agent sets over the shipped entry."""
    assert spec.variant is not None  # set by RunSpec.__post_init__
    return spec.variant.algo, spec.variant.overrides(spec.env)


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
    from sb3_gqn.zoo.registration import SBX_ALGOS, sbx_algorithm

    if zoo_algo in SBX_ALGOS:
        algorithm: type[Any] = sbx_algorithm(zoo_algo)
    else:  # DecQN passes its kwargs to GQN
        algorithm = {"gqn": GQN, "decqn": GQN, "sac": SAC, "td3": TD3}[zoo_algo]
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

    wrapper = get_wrapper_class({"env_wrapper": run_wrappers(spec)})
    env = gym.make(spec.env)
    return wrapper(env) if wrapper is not None else env
