"""The paper's figure 2 for Pendulum: GQN's per-bin utilities over the (angle, angular velocity) grid at the end of every
growth level, saved during training (:class:`QValueSnapshots`) and drawn afterwards (:func:`q_value_picture`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import torch as th
from stable_baselines3.common.callbacks import BaseCallback

from sb3_gqn.gqn.gqn import GQN

# Pendulum-v1's state grid for the Q-value picture (figure 2): angle x angular velocity
PENDULUM_ANGLES = np.linspace(-np.pi, np.pi, 41)
PENDULUM_VELOCITIES = np.linspace(-8.0, 8.0, 41)


class QValueSnapshots(BaseCallback):
    """Saves GQN's per-bin utilities over Pendulum's (angle, velocity) grid at the end of every growth level.

    ``q_level<g>.npz`` holds ``utilities`` ``(angles, velocities, max_bins)``, the level's active bins and the grid.
    """

    def __init__(self, run_dir: Path):
        super().__init__()
        self.run_dir = Path(run_dir)
        self.level = 0

    @property
    def gqn(self) -> GQN:
        """The model trained: a GQN (or DecQN)."""
        assert isinstance(self.model, GQN), f"Q-value snapshots need a GQN or DecQN, got {type(self.model).__name__}"
        return self.model

    def _snapshot(self, level: int) -> None:
        angle, velocity = np.meshgrid(PENDULUM_ANGLES, PENDULUM_VELOCITIES, indexing="ij")
        observations = np.stack([np.cos(angle), np.sin(angle), velocity], axis=-1).reshape(-1, 3).astype(np.float32)
        with th.no_grad():
            utilities = self.gqn.q_net(th.as_tensor(observations, device=self.gqn.device))
        utilities = utilities[:, 0, :].cpu().numpy().reshape(len(PENDULUM_ANGLES), len(PENDULUM_VELOCITIES), -1)
        grid = self.gqn.action_grid
        np.savez(
            self.run_dir / f"q_level{level}.npz",
            utilities=utilities,
            bin_values=grid.values[0] if grid is not None else np.arange(utilities.shape[-1], dtype=np.float32),
            active_bins=self.gqn.bin_levels[level],
            max_bins=self.gqn.bin_levels[-1],
            angles=PENDULUM_ANGLES,
            velocities=PENDULUM_VELOCITIES,
            step=self.num_timesteps,
        )

    def _on_step(self) -> bool:
        level = self.gqn.growth_level
        if level != self.level:  # the network as it was trained at the previous level
            self._snapshot(self.level)
            self.level = level
        return True

    def _on_training_end(self) -> None:
        self._snapshot(self.gqn.growth_level)


def save_q_snapshot(run_dir: Path) -> QValueSnapshots:
    return QValueSnapshots(run_dir)


def q_value_picture(run_dir: Path, out: Path) -> Path | None:
    """Figure 2: per-bin utilities over Pendulum's (angle, velocity) grid at each growth level, active bins outlined."""
    snapshots = sorted(run_dir.glob("q_level*.npz"), key=lambda path: int(path.stem.removeprefix("q_level")))
    if not snapshots:
        return None
    loaded: list[Any] = [np.load(path) for path in snapshots]
    max_bins = int(loaded[0]["max_bins"])
    bin_values = loaded[0].get("bin_values")  # older snapshots lack them
    figure, axes = plt.subplots(
        len(loaded), max_bins, figsize=(1.35 * max_bins + 1.2, 1.5 * len(loaded) + 1.0), squeeze=False, layout="constrained"
    )
    for row, snapshot in enumerate(loaded):
        utilities, active = snapshot["utilities"], int(snapshot["active_bins"])
        active_indices = set(np.linspace(0, max_bins - 1, active).round().astype(int).tolist())
        low, high = np.percentile(utilities, [2, 98])
        angles, velocities = snapshot["angles"], snapshot["velocities"]
        extent = (velocities[0], velocities[-1], angles[0], angles[-1])
        for column in range(max_bins):
            axis = axes[row, column]
            image = axis.imshow(utilities[:, :, column], origin="lower", aspect="auto", extent=extent, vmin=low, vmax=high)
            axis.set_xticks([velocities[0], 0, velocities[-1]] if row == len(loaded) - 1 else [])
            axis.set_yticks([angles[0], 0, angles[-1]] if column == 0 else [])
            axis.tick_params(labelsize=6)
            if column == 0:
                axis.set_yticklabels(["-π", "0", "π"])
            for spine in axis.spines.values():
                spine.set_linewidth(2.5 if column in active_indices else 0.5)
                spine.set_color("red" if column in active_indices else "grey")
            if row == 0:
                value = f"\na = {bin_values[column]:+.2f}" if bin_values is not None else ""
                axis.set_title(f"bin {column}{value}", fontsize=7)
        axes[row, 0].set_ylabel(f"{active} bins, step {int(snapshot['step'])}\nangle [rad]", fontsize=7)
        colorbar = figure.colorbar(image, ax=axes[row, :].tolist(), shrink=0.9, pad=0.01)
        colorbar.ax.tick_params(labelsize=6)
        colorbar.set_label("utility Q(s, bin)", fontsize=7)
    for axis in axes[-1, :]:
        axis.set_xlabel("velocity [rad/s]", fontsize=6)
    figure.suptitle(
        f"{run_dir.name}: per-bin utilities over angle x angular velocity at the end of each level "
        "(a: the bin's torque; red frame: active bins; colour scale per row)",
        fontsize=8,
    )
    path = out / f"q_values_{run_dir.name}.png"
    figure.savefig(path, dpi=100)
    plt.close(figure)
    return path
