"""Deploy a trained GQN without SB3, sb3-gqn or the env: a self-contained policy ``observation -> env action``.

    from sb3_gqn.export import export_onnx, export_torchscript

    export_torchscript(model, "policy.pt")                  # torch.jit.load("policy.pt")(obs)
    export_onnx(model, "policy.onnx")                       # onnxruntime.InferenceSession("policy.onnx")
    export_onnx(model, "policy.onnx", vec_normalize=stats)  # with VecNormalize's observation statistics

The file holds the network ``predict`` acts on (the Polyak average of the online network with ``acting_tau``, the
online network without), the current active-bin mask and the bin grid (see
:class:`~sb3_gqn.export.policy.DeployedPolicy`): it returns the env's action (continuous values for a
``Box`` env, bin indices for ``Discrete``/``MultiDiscrete``) for a batch of observations, greedily, and matches
``model.predict(obs, deterministic=True)``. Export again after the model grows: the mask is baked in.

Non-finite observations: ``predict`` raises on an observation holding NaN or +-inf. An exported file cannot raise, so
it answers such a row with no valid action: NaN for a ``Box`` env, bin ``-1`` for ``Discrete``/``MultiDiscrete``.
A controller checks ``isfinite`` (or ``>= 0``) on the output, as it would check any sensor fault.
"""

from __future__ import annotations

import logging
import warnings
from pathlib import Path
from typing import Any

import torch as th
from gymnasium import spaces
from stable_baselines3.common.vec_env import VecNormalize

from sb3_gqn.export.policy import DeployedPolicy
from sb3_gqn.gqn.gqn import GQN

__all__ = ["DeployedPolicy", "export_onnx", "export_torchscript"]


def export_torchscript(model: GQN, path: str | Path, vec_normalize: VecNormalize | None = None) -> Path:
    """Write ``model``'s greedy policy as a TorchScript file (loads with ``torch.jit.load``, no Python code needed).

    :param model: a GQN or DecQN model
    :param path: the file to write (``.pt`` by convention)
    :param vec_normalize: the ``VecNormalize`` the model was trained with, if any: its observation statistics
        (mean, variance, clipping) are baked in, so the file takes raw env observations
    :return: the path written
    """
    policy = DeployedPolicy(model, vec_normalize)
    example = policy.example_observation(batch_size=2)
    with warnings.catch_warnings():
        # PyTorch 2.13 deprecates torch.jit in favour of torch.export; TorchScript files still load in every
        # libtorch runtime, which is what robot controllers embed. export_onnx is the export-based path.
        warnings.filterwarnings("ignore", category=DeprecationWarning, module=r"torch\.jit")
        traced = th.jit.trace(policy, (example,), check_trace=False)
    path = Path(path)
    traced.save(str(path))
    return path


#: ONNX files are protobuf messages, which cannot exceed 2 GiB; weights past this size go to a side file
ONNX_EMBEDDED_LIMIT_BYTES = 2**31 - 2**27


def export_onnx(
    model: GQN,
    path: str | Path,
    vec_normalize: VecNormalize | None = None,
    opset_version: int | None = None,
    external_data: bool | None = None,
) -> Path:
    """Write ``model``'s greedy policy as an ONNX file (runs with ONNX Runtime, no PyTorch needed).

    The graph's inputs are named ``observation`` (or the observation space's keys for a ``Dict`` space) and
    take a batch (first dimension of any size) in the observation space's dtype; its output is ``action``.
    Needs the ``export`` extra (``onnx``, ``onnxscript``; ``onnxruntime`` to run it).

    The file is self-contained: the weights are embedded in the graph, so ``path`` alone deploys. Only networks
    whose weights exceed ONNX's 2 GiB message limit (:data:`ONNX_EMBEDDED_LIMIT_BYTES`) are written with their
    weights in a side file ``<path>.data``, which must then travel with ``path``.

    :param model: a GQN or DecQN model
    :param path: the file to write (``.onnx``)
    :param vec_normalize: the ``VecNormalize`` the model was trained with, if any (see :func:`export_torchscript`)
    :param opset_version: ONNX opset (default: PyTorch's exporter default)
    :param external_data: ``None`` (default): embed the weights unless they exceed the limit; ``True``: always
        write the side file; ``False``: always embed (fails past the limit)
    :return: the path written
    """
    try:
        import onnxscript  # noqa: F401  (torch.onnx's exporter needs it)
    except ImportError as error:
        raise ImportError("export_onnx needs onnx and onnxscript: pip install 'sb3-gqn[export]' -c constraints.txt") from error
    policy = DeployedPolicy(model, vec_normalize)
    if external_data is None:
        weight_bytes = sum(tensor.numel() * tensor.element_size() for tensor in policy.state_dict().values())
        external_data = weight_bytes > ONNX_EMBEDDED_LIMIT_BYTES
    example = policy.example_observation(batch_size=2)
    batch = th.export.Dim("batch")
    dynamic_shapes: dict[str, Any]
    if isinstance(example, dict):
        input_names = list(example)
        dynamic_shapes = {"observation": {key: {0: batch} for key in example}}
    else:
        input_names = ["observation"]
        dynamic_shapes = {"observation": {0: batch}}
    path = Path(path)
    onnx_logger = logging.getLogger("torch.onnx")
    previous_level = onnx_logger.level
    onnx_logger.setLevel(logging.ERROR)  # the exporter logs every skipped torchvision op
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", category=FutureWarning)
            th.onnx.export(
                policy,
                (),  # a dict in args would be read as keyword arguments: pass the observation by name
                str(path),
                kwargs={"observation": example},
                input_names=input_names,
                output_names=["action"],
                dynamic_shapes=dynamic_shapes,
                opset_version=opset_version,
                dynamo=True,
                external_data=external_data,
                verbose=False,
            )
    finally:
        onnx_logger.setLevel(previous_level)
    return path


def observation_dtypes(observation_space: spaces.Space) -> dict[str, str]:
    """NumPy dtype names an exported policy expects per input (``{"observation": ...}`` or one per Dict key)."""
    if isinstance(observation_space, spaces.Dict):
        return {key: str(space.dtype) for key, space in observation_space.spaces.items()}
    return {"observation": str(observation_space.dtype)}
