"""The precision of the critic's matrix products in training: float32, or bfloat16 with float32 master weights.

``precision="bf16"`` runs every linear layer (and convolution) of the training forward passes, and their backward
passes, on bfloat16 operands with float32 accumulation, and hands float32 tensors on: the weights, their gradients,
the optimizer state, the TD targets, the loss and the priorities stay float32. It is the arithmetic of
``torch.autocast(dtype=torch.bfloat16)`` restricted to the matrix products, which hold nearly all of an update's
FLOPs. Where the device has bfloat16 matrix units (:func:`has_bf16_matrix_units`) the products run on bfloat16
kernels; elsewhere they run on float32 kernels with their operands and results rounded to bfloat16 at the same
points, so a model learns the same on either machine (and no faster on the second).

``precision="auto"`` picks bfloat16 where the device has the units and float32 elsewhere: a CPU with AVX-512 BF16
(without AMX too) trains in bfloat16. A model with ``verbose >= 1`` says what ``"auto"`` resolved to, and why, when it
is set up (:func:`resolution_note`); every ``learn()`` records the resolved precision in SB3's log as
``train/precision``. Acting (``predict``, exploration, evaluation) and the exports stay float32: at batch 1 an action
costs launch overheads, not FLOPs.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import torch as th
from torch.nn import functional
from torch.overrides import TorchFunctionMode

#: The values of GQN's ``precision`` argument
PRECISIONS = ("auto", "fp32", "bf16")
#: CPU flags (Linux ``/proc/cpuinfo``) of bfloat16 matrix instructions: Intel AMX tiles, AVX-512 BF16 dot products
CPU_BF16_FLAGS = frozenset({"amx_bf16", "avx512_bf16"})
#: The matrix products :class:`BFloat16Matmuls` runs on bfloat16 operands
MATMUL_FUNCTIONS: frozenset[Callable[..., Any]] = frozenset({functional.linear, functional.conv1d, functional.conv2d})


@functools.cache
def cpu_flags(cpuinfo: Path = Path("/proc/cpuinfo")) -> frozenset[str]:
    """The CPU's feature flags as the kernel lists them (empty where ``/proc/cpuinfo`` does not exist: not Linux)."""
    try:
        text = cpuinfo.read_text()
    except OSError:
        return frozenset()
    for line in text.splitlines():
        if line.startswith(("flags", "Features")):
            return frozenset(line.partition(":")[2].split())
    return frozenset()


def has_bf16_matrix_units(device: th.device | str) -> bool:
    """Whether ``device`` multiplies bfloat16 matrices in hardware: a CUDA GPU of compute capability 8.0 or later
    (Ampere), or a CPU with AMX or AVX-512 BF16 (:data:`CPU_BF16_FLAGS`). Other devices: ``False``."""
    device = th.device(device)
    if device.type == "cuda":
        return th.cuda.is_available() and th.cuda.get_device_capability(device) >= (8, 0)
    if device.type == "cpu":
        return bool(cpu_flags() & CPU_BF16_FLAGS)
    return False


def resolve_precision(precision: str, device: th.device | str) -> str:
    """``"fp32"`` or ``"bf16"``: ``precision`` itself, or for ``"auto"`` bfloat16 where ``device`` has bfloat16
    matrix units (:func:`has_bf16_matrix_units`) and float32 elsewhere."""
    if precision == "auto":
        return "bf16" if has_bf16_matrix_units(device) else "fp32"
    return precision


def bf16_units_reason(device: th.device | str) -> str:
    """Why :func:`has_bf16_matrix_units` says what it says for ``device``, in words: ``"this CPU has AVX-512 BF16 matrix
    instructions"``, ``"this GPU (compute capability 8.0) has bfloat16 matrix units"``, ``"this CPU has no bfloat16
    matrix instructions (AMX or AVX-512 BF16)"``, ..."""
    device = th.device(device)
    if device.type == "cuda":
        if not th.cuda.is_available():
            return "CUDA is not available"
        major, minor = th.cuda.get_device_capability(device)
        units = "has" if (major, minor) >= (8, 0) else "has no"
        return f"this GPU (compute capability {major}.{minor}) {units} bfloat16 matrix units"
    if device.type == "cpu":
        flags = cpu_flags()
        if "amx_bf16" in flags:
            return "this CPU has AMX bfloat16 tiles"
        if "avx512_bf16" in flags:
            return "this CPU has AVX-512 BF16 matrix instructions"
        return "this CPU has no bfloat16 matrix instructions (AMX or AVX-512 BF16)"
    return f"no bfloat16 matrix units are known on {device.type} devices"


def resolution_note(precision: str, device: th.device | str) -> str | None:
    """One line saying what ``precision="auto"`` resolved to on ``device`` and why (:func:`bf16_units_reason`):
    ``precision="auto" resolved to "bf16" (this CPU has AVX-512 BF16 matrix instructions)``; ``None`` for a precision
    that is not ``"auto"`` (nothing was chosen)."""
    if precision != "auto":
        return None
    return f'precision="auto" resolved to "{resolve_precision(precision, device)}" ({bf16_units_reason(device)})'


def checked_precision(precision: str, device: th.device | str) -> str:
    """GQN's ``precision`` checked (one of :data:`PRECISIONS`, ``ValueError`` naming it) and resolved for ``device``
    (:func:`resolve_precision`); ``"bf16"`` on a device without bfloat16 matrix units warns that it runs no faster."""
    if precision not in PRECISIONS:
        raise ValueError(f"precision must be one of {PRECISIONS}, got {precision!r}")
    if precision == "bf16" and not has_bf16_matrix_units(device):
        warnings.warn(
            f"precision='bf16' on {device}, which has no bfloat16 matrix units: the updates round their matrix "
            "products' operands to bfloat16 on float32 kernels (the same arithmetic as on bfloat16 hardware, no "
            "faster). precision='fp32' or 'auto' train in float32 here.",
            UserWarning,
            stacklevel=3,
        )
    return resolve_precision(precision, device)


def round_to_bf16(tensor: th.Tensor) -> th.Tensor:
    """``tensor`` rounded to the nearest bfloat16 values (round half to even), kept float32; its gradient is rounded
    the same way on the way back, as a bfloat16 kernel's output would be."""
    return tensor.to(th.bfloat16).to(tensor.dtype)


class BFloat16Matmuls(TorchFunctionMode):
    """Within this mode the matrix products (:data:`MATMUL_FUNCTIONS`) take bfloat16 operands and accumulate in
    float32; their outputs come back as float32 tensors (holding bfloat16 values), so every other operation runs in
    float32 as before.

    :param native: run the products on bfloat16 kernels (for a device with bfloat16 matrix units); ``False`` runs them
        on float32 kernels with the operands and the result rounded to bfloat16 (:func:`round_to_bf16`): the same
        arithmetic up to the order of the float32 sums, on any device
    """

    def __init__(self, native: bool):
        super().__init__()
        self.native = native

    def __torch_function__(
        self,
        func: Callable[..., Any],
        types: Any,
        args: tuple[Any, ...] = (),
        kwargs: dict[str, Any] | None = None,
    ) -> Any:
        kwargs = kwargs or {}
        if func not in MATMUL_FUNCTIONS:
            return func(*args, **kwargs)
        if self.native:
            output = func(*_cast_tensors(args, th.bfloat16), **_cast_tensors(kwargs, th.bfloat16))
            return output.float()
        return round_to_bf16(func(*_cast_tensors(args, None), **_cast_tensors(kwargs, None)))


def _cast_tensors(values: Any, dtype: th.dtype | None) -> Any:
    """The floating-point tensors among ``values`` (a tuple or a dict) cast to ``dtype``, or rounded to bfloat16
    values (:func:`round_to_bf16`) when ``dtype`` is ``None``; everything else as it is."""

    def cast(value: Any) -> Any:
        if not isinstance(value, th.Tensor) or not value.is_floating_point():
            return value
        return round_to_bf16(value) if dtype is None else value.to(dtype)

    if isinstance(values, dict):
        return {key: cast(value) for key, value in values.items()}
    return tuple(cast(value) for value in values)


def matmul_precision(precision: str, device: th.device | str) -> BFloat16Matmuls | None:
    """The mode that :meth:`GQN.train <sb3_gqn.GQN.train>` runs its forward passes in for a resolved ``precision``
    (``"fp32"``: ``None``, nothing to enter)."""
    if precision == "fp32":
        return None
    return BFloat16Matmuls(native=has_bf16_matrix_units(device))
