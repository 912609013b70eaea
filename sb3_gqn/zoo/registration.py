"""GQN and DecQN in rl-zoo3's registries.

rl-zoo3 has no plugin mechanism: its ``ALGOS`` dict and the Optuna ``HYPERPARAMS_SAMPLER`` /
``HYPERPARAMS_CONVERTER`` dicts are read when its argument parsers and experiment manager run.
:func:`register` fills them in place, so every rl-zoo3 entry point called afterwards in the same
process (``sb3-gqn train``, ``sb3-gqn enjoy``, ``sb3-gqn record-video``) knows ``gqn`` and ``decqn`` next to
rl-zoo3's own algorithms.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterable
from typing import Any

from sb3_gqn.common.envs import register_envs
from sb3_gqn.decqn.decqn import DecQN
from sb3_gqn.gqn.gqn import GQN

#: The project's algorithms under their rl-zoo3 names
ZOO_ALGOS: dict[str, type[GQN]] = {"gqn": GQN, "decqn": DecQN}
#: SBX (Stable-Baselines-Jax, the ``sbx`` extra) algorithms under their rl-zoo3 names: ``(module, class)``. They are
#: registered only when asked for (:func:`register`'s ``algos``): importing JAX costs seconds.
SBX_ALGOS: dict[str, tuple[str, str]] = {"sbx_sac": ("sbx", "SAC")}


def zoo_algorithms() -> list[str]:
    """Every algorithm name ``sb3-gqn train --algo`` takes: rl-zoo3's own, the project's (:data:`ZOO_ALGOS`) and SBX's
    (:data:`SBX_ALGOS`, also when the extra is not installed), sorted."""
    from rl_zoo3.utils import ALGOS

    return sorted({*ALGOS, *ZOO_ALGOS, *SBX_ALGOS})


def zoo_algo_name(name: str) -> str:
    """rl-zoo3's spelling of algorithm ``name``: with underscores where the comparison runner's agents have hyphens
    (``sbx-sac`` is ``sbx_sac``), when that spelling is an algorithm of :func:`zoo_algorithms`; any other name as
    given."""
    underscored = name.replace("-", "_")
    return underscored if name not in zoo_algorithms() and underscored in zoo_algorithms() else name


def sbx_algorithm(name: str) -> type[Any]:
    """The SBX class of rl-zoo3 name ``name`` (:data:`SBX_ALGOS`).

    :raises ImportError: naming the extra to install when SBX is not installed
    """
    module_name, class_name = SBX_ALGOS[name]
    try:
        module = importlib.import_module(module_name)
    except ImportError as error:
        raise ImportError(f"{name} trains SBX's {class_name}: install the sbx extra, pip install 'sb3-gqn[sbx]'") from error
    return getattr(module, class_name)


def register(algos: Iterable[str | None] = ()) -> None:
    """Put ``gqn`` and ``decqn`` into rl-zoo3's ``ALGOS``, Optuna samplers and converters, and register the suites'
    env ids (idempotent). The SBX algorithms among ``algos`` (:data:`SBX_ALGOS`) are added to ``ALGOS`` too."""
    from rl_zoo3 import hyperparams_opt, utils

    from sb3_gqn.zoo.tuning import convert_gqn_params, sample_decqn_params, sample_gqn_params

    utils.ALGOS.update(ZOO_ALGOS)
    utils.ALGOS.update({name: sbx_algorithm(name) for name in set(algos) if name in SBX_ALGOS})
    hyperparams_opt.HYPERPARAMS_SAMPLER.update({"gqn": sample_gqn_params, "decqn": sample_decqn_params})
    # rl-zoo3's dict is typed by its own converters, whose parameter has another name
    hyperparams_opt.HYPERPARAMS_CONVERTER.update({"gqn": convert_gqn_params, "decqn": convert_gqn_params})  # type: ignore[dict-item]
    register_envs()


def loader_without_replay_memory(algo_class: type[GQN]) -> type[GQN]:
    """``algo_class`` whose ``load`` defaults to ``buffer_size=1``: replaying an agent needs no replay memory.

    rl-zoo3's enjoy and record_video do this only for their own off-policy algorithms.
    """

    class Loader(algo_class):  # type: ignore[valid-type, misc]  # a base class given as an argument: mypy needs a literal one
        @classmethod
        def load(cls, path: Any, *args: Any, **kwargs: Any) -> GQN:
            kwargs.setdefault("buffer_size", 1)
            return algo_class.load(path, *args, **kwargs)

    Loader.__name__ = Loader.__qualname__ = algo_class.__name__
    return Loader
