"""Runs that survive: the comparison runner's checkpoints, resuming after a kill, damaged checkpoints, and a resumed
run that follows the uninterrupted one exactly."""

import csv
import hashlib
import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import torch as th

from sb3_gqn import GQN
from sb3_gqn.experiments.checkpoints import (
    KEEP,
    RunCheckpointCallback,
    checkpoint_steps,
    is_whole,
    newest_whole_checkpoint,
    write_checkpoint,
)
from sb3_gqn.experiments.runs import run
from sb3_gqn.experiments.variants import RunSpec
from tests.envs import DecliningEnv

REPOSITORY = Path(__file__).resolve().parents[1]
STEPS, FREQ, EVAL_FREQ = 1_600, 800, 400  # Pendulum's episodes are 200 steps: each checkpoint is at an episode end
SPEC = RunSpec("gqn-adaptive", "Pendulum-v1", 0.1, 0, STEPS)
RUN = f"""
import sys
from pathlib import Path
from sb3_gqn.experiments.runs import run
from sb3_gqn.experiments.variants import RunSpec
run(RunSpec("gqn-adaptive", "Pendulum-v1", 0.1, 0, {STEPS}), Path(sys.argv[1]), {EVAL_FREQ}, 2, 1, checkpoint_freq={FREQ})
"""


def kill_after_first_checkpoint(out: Path) -> None:
    """Start the run in a process and SIGKILL it once its first checkpoint is whole."""
    process = subprocess.Popen([sys.executable, "-c", RUN, str(out)], cwd=REPOSITORY, stdout=subprocess.DEVNULL)
    folder = out / "runs" / SPEC.name / "checkpoints"
    deadline = time.monotonic() + 300
    while newest_whole_checkpoint(folder) is None:
        assert process.poll() is None, "the run ended before its first checkpoint"
        assert time.monotonic() < deadline
        time.sleep(0.2)
    process.send_signal(signal.SIGKILL)
    process.wait()
    assert not (out / "runs" / SPEC.name / "done.json").exists()


def curve_steps(out: Path, spec: RunSpec = SPEC, decoding: str = "") -> list[int]:
    """The steps of a run's evaluations read with its own decoding (``""``) or with a paired one."""
    with open(out / "runs" / spec.name / "curve.csv", newline="") as handle:
        return [int(row["step"]) for row in csv.DictReader(handle) if row["decoding"] == decoding]


def kill_after_two_checkpoints(out: Path) -> tuple[int, int]:
    """Start :data:`SPEC`'s run with a checkpoint every ``EVAL_FREQ`` steps in a process, SIGKILL it once two
    checkpoints are whole, and return their steps (newest first)."""
    code = RUN.replace(f"checkpoint_freq={FREQ}", f"checkpoint_freq={EVAL_FREQ}")
    process = subprocess.Popen([sys.executable, "-c", code, str(out)], cwd=REPOSITORY, stdout=subprocess.DEVNULL)
    folder = out / "runs" / SPEC.name / "checkpoints"
    deadline = time.monotonic() + 300
    while len([step for step in checkpoint_steps(folder) if is_whole(folder / f"step_{step}")]) < 2:
        assert process.poll() is None, "the run ended before its second checkpoint"
        assert time.monotonic() < deadline
        time.sleep(0.1)
    process.send_signal(signal.SIGKILL)
    process.wait()
    newest, before = checkpoint_steps(folder)[:2]
    return newest, before


def final_parameters(out: Path) -> dict[str, th.Tensor]:
    return dict(GQN.load(out / "runs" / SPEC.name / "model.zip").policy.state_dict())


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("uninterrupted")
    th.set_num_threads(1)
    run(SPEC, out, EVAL_FREQ, 2, 1, checkpoint_freq=FREQ)
    return out


def test_a_killed_run_resumes_from_its_checkpoint_and_follows_the_uninterrupted_run(tmp_path, uninterrupted):
    kill_after_first_checkpoint(tmp_path)
    th.set_num_threads(1)
    run(SPEC, tmp_path, EVAL_FREQ, 2, 1, checkpoint_freq=FREQ)  # the same call resumes it
    done = json.loads((tmp_path / "runs" / SPEC.name / "done.json").read_text())
    assert done["resumed_from"] and done["resumed_from"][0] >= FREQ
    assert json.loads((uninterrupted / "runs" / SPEC.name / "done.json").read_text())["resumed_from"] == []
    # every evaluation once, up to the budget; the final model at the budget
    assert curve_steps(tmp_path) == list(range(EVAL_FREQ, STEPS + 1, EVAL_FREQ)) == curve_steps(uninterrupted)
    assert curve_steps(tmp_path, decoding="relative") == curve_steps(tmp_path)  # each paired reading once too
    resumed = GQN.load(tmp_path / "runs" / SPEC.name / "model.zip")
    assert resumed.num_timesteps == STEPS
    # resumed at an episode end on one torch thread: the same parameters and evaluations as without the kill
    expected = final_parameters(uninterrupted)
    assert all(th.equal(value, expected[key]) for key, value in resumed.policy.state_dict().items())
    with open(tmp_path / "runs" / SPEC.name / "curve.csv") as a, open(uninterrupted / "runs" / SPEC.name / "curve.csv") as b:
        for row_a, row_b in zip(csv.DictReader(a), csv.DictReader(b)):
            assert row_a["return"] == row_b["return"] and row_a["growth_events"] == row_b["growth_events"]
    assert not (tmp_path / "runs" / SPEC.name / "checkpoints").exists()  # the finished run's model supersedes them


def test_a_torn_newest_checkpoint_falls_back_to_the_one_before(tmp_path):
    model = GQN("MlpPolicy", DecliningEnv(), policy_kwargs=dict(net_arch=[8]), learning_starts=10, train_freq=1)
    callback = RunCheckpointCallback(tmp_path, freq=10)
    model.learn(60, callback=callback)
    # DecliningEnv's episodes end every 5 steps, so each checkpoint is at the first rollout after 10, 20, ...
    assert callback.written == [10, 20, 30, 40, 50, 60][: len(callback.written)] and len(callback.written) >= 4
    assert checkpoint_steps(tmp_path) == sorted(callback.written, reverse=True)[:KEEP]  # the last two kept
    newest, before = checkpoint_steps(tmp_path)
    (tmp_path / f"step_{newest}" / "model.zip").write_bytes(b"torn")
    with pytest.warns(UserWarning, match=f"step_{newest} is damaged"):
        assert newest_whole_checkpoint(tmp_path) == tmp_path / f"step_{before}"
    (tmp_path / f"step_{before}" / "complete").unlink()  # a write that never finished
    with pytest.warns(UserWarning, match="damaged"):
        assert newest_whole_checkpoint(tmp_path) is None


def test_a_truncated_replay_buffer_is_found_by_its_size_and_old_checkpoints_still_count(tmp_path):
    model = GQN("MlpPolicy", DecliningEnv(), policy_kwargs=dict(net_arch=[8]), learning_starts=10, train_freq=1)
    model.learn(20)
    checkpoint = write_checkpoint(tmp_path, model, None, {})
    record = json.loads((checkpoint / "complete").read_text())
    buffer = checkpoint / "replay_buffer.pkl"
    assert record["step"] == 20 and record["sizes"]["replay_buffer.pkl"] == buffer.stat().st_size > 0
    assert is_whole(checkpoint)
    whole = buffer.read_bytes()
    buffer.write_bytes(whole[:-1])  # one byte short: the write was cut
    assert not is_whole(checkpoint)
    # a checkpoint from before the sizes were recorded: its buffer is unpickled instead
    (checkpoint / "complete").write_text("20")
    assert not is_whole(checkpoint)
    buffer.write_bytes(whole)
    assert is_whole(checkpoint)


def test_a_run_without_a_whole_checkpoint_starts_again_with_a_warning(tmp_path):
    spec = RunSpec("gqn-adaptive", "Pendulum-v1", 0.1, 0, 400)
    run_dir = tmp_path / "runs" / spec.name
    (run_dir / "checkpoints" / "step_200").mkdir(parents=True)
    (run_dir / "checkpoints" / "step_200" / "model.zip").write_bytes(b"torn")
    (run_dir / "curve.csv").write_text("stale rows\n")
    with pytest.warns(UserWarning, match="starting again from scratch"):
        run(spec, tmp_path, 200, 1, 1, checkpoint_freq=FREQ)
    assert json.loads((run_dir / "done.json").read_text())["resumed_from"] == []
    assert curve_steps(tmp_path, spec) == [200, 400]


def test_checkpoint_frequency_must_be_positive():
    with pytest.raises(ValueError, match="checkpoint frequency must be an integer >= 1"):
        RunCheckpointCallback(Path("."), freq=0)


def test_rl_zoo_continues_from_a_checkpoint_with_its_replay_buffer_and_growth(tmp_path):
    from sb3_gqn.zoo.cli import train

    first = ["--algo", "gqn", "--env", "Pendulum-v1", "--seed", "0", "-f", str(tmp_path / "first")]
    assert train([*first, "-n", "1200", "--save-freq", "600", "--save-replay-buffer"]) == 0
    folder = tmp_path / "first" / "gqn" / "Pendulum-v1_1"
    assert (folder / "rl_model_replay_buffer_600_steps.pkl").is_file()  # rl-zoo3 alone saves no buffer per checkpoint
    checkpoint = GQN.load(folder / "rl_model_600_steps.zip")
    # the linear schedule over 1200 steps opened 3 and 5 bins at 240 and 480 (g / 5 of the budget)
    assert checkpoint.growth_events == [(240, 3), (480, 5)] and checkpoint.num_timesteps == 600
    second = ["--algo", "gqn", "--env", "Pendulum-v1", "--seed", "0", "-f", str(tmp_path / "second")]
    assert train([*second, "-n", "600", "-i", str(folder / "rl_model_600_steps.zip"), "--save-replay-buffer"]) == 0
    continued = GQN.load(tmp_path / "second" / "gqn" / "Pendulum-v1_1" / "Pendulum-v1.zip")
    continued.load_replay_buffer(tmp_path / "second" / "gqn" / "Pendulum-v1_1" / "replay_buffer.pkl")
    # SB3's CheckpointCallback saves before it stores the step's transition: 599 + 600 transitions
    assert continued.replay_buffer.pos == 1_199
    # rl-zoo3 restarts num_timesteps; growth goes on from step 600 of the model's life (600 + 600 * 3 / 5)
    assert (continued.num_timesteps, continued.growth_step) == (600, 1_200)
    assert continued.growth_events == [(240, 3), (480, 5), (960, 9)]


@pytest.mark.parametrize("legacy", [False, True])
def test_replayable_resets_repeat_the_last_reset_for_both_kinds_of_generator(legacy):
    """Gymnasium's ``Generator`` and the legacy ``RandomState`` (shimmy's dm_control envs) both replay."""
    from sb3_gqn.experiments.checkpoints import ReplayableResets

    class RandomStart(DecliningEnv):
        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            if legacy and seed is not None:
                self._np_random = np.random.RandomState(seed)
            start = self.np_random.uniform(-1, 1, size=3) if not legacy else self.np_random.uniform(-1, 1, 3)
            return start.astype(np.float32), {}

    env = ReplayableResets(RandomStart())
    env.reset(seed=3)
    first, _ = env.reset()
    state = env.state_before_reset
    second, _ = env.reset()
    assert not np.array_equal(first, second)
    env.replay_next_reset(state)
    np.testing.assert_array_equal(env.reset()[0], first)
    assert isinstance(env.unwrapped.np_random, np.random.RandomState) == legacy


HOLD = """
import sys
from pathlib import Path
from sb3_gqn.experiments.runs import hold_run
from sb3_gqn.experiments.variants import RunSpec
with hold_run(RunSpec("gqn-adaptive", "Pendulum-v1", 0.1, 0, 400), Path(sys.argv[1])):
    print("holding", flush=True)
    sys.stdin.readline()
"""


def test_a_run_that_another_process_trains_is_refused_before_anything_is_written(tmp_path, capsys):
    from sb3_gqn.experiments.runner import main
    from sb3_gqn.experiments.runs import RunInProgressError

    spec = RunSpec("gqn-adaptive", "Pendulum-v1", 0.1, 0, 400)
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD, str(tmp_path)], cwd=REPOSITORY, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    try:
        assert holder.stdout.readline().strip() == "holding"
        with pytest.raises(RunInProgressError, match=f"{spec.name}: another process is training this run"):
            run(spec, tmp_path, 200, 1, 1, checkpoint_freq=FREQ)
        argv = ["--algos", "gqn-adaptive", "--envs", "Pendulum-v1", "--penalties", "0.1", "--seeds", "0", "--steps", "400"]
        assert main([*argv, "--out", str(tmp_path), "--no-plots"]) == 2
        assert f"another process is training ['{spec.name}']" in capsys.readouterr().err
        assert not (tmp_path / "runs" / spec.name).exists()
        assert not (tmp_path / "results.csv").exists()
    finally:
        holder.communicate("\n", timeout=60)
    assert holder.returncode == 0
    run(spec, tmp_path, 200, 1, 1)  # the lock goes with its holder
    assert (tmp_path / "runs" / spec.name / "done.json").is_file()


def test_bytes_overwritten_without_a_change_of_size_are_found_by_the_checksum(tmp_path):
    model = GQN("MlpPolicy", DecliningEnv(), policy_kwargs=dict(net_arch=[8]), learning_starts=10, train_freq=1)
    model.learn(20)
    older = write_checkpoint(tmp_path, model, None, {})
    model.learn(20, reset_num_timesteps=False)
    newest = write_checkpoint(tmp_path, model, None, {})
    record = json.loads((newest / "complete").read_text())
    buffer = newest / "replay_buffer.pkl"
    assert record["sha256"]["replay_buffer.pkl"] == hashlib.sha256(buffer.read_bytes()).hexdigest()
    assert set(record["sha256"]) == set(record["sizes"]) == {"model.zip", "replay_buffer.pkl", "state.pkl"}
    whole = buffer.read_bytes()
    damaged = bytearray(whole)
    damaged[len(whole) // 2 : len(whole) // 2 + 64] = bytes(64)  # 64 bytes overwritten, the size kept
    buffer.write_bytes(bytes(damaged))
    assert buffer.stat().st_size == len(whole) and not is_whole(newest)
    with pytest.warns(UserWarning, match=f"{newest.name} is damaged"):
        assert newest_whole_checkpoint(tmp_path) == older
    buffer.write_bytes(whole)
    assert is_whole(newest)


def test_a_run_whose_newest_checkpoint_was_overwritten_resumes_from_the_one_before(tmp_path):
    newest, before = kill_after_two_checkpoints(tmp_path)
    buffer = tmp_path / "runs" / SPEC.name / "checkpoints" / f"step_{newest}" / "replay_buffer.pkl"
    damaged = bytearray(buffer.read_bytes())
    damaged[-200:-136] = bytes(64)  # 64 bytes overwritten, the size kept
    buffer.write_bytes(bytes(damaged))
    with pytest.warns(UserWarning, match=f"step_{newest} is damaged"):
        run(SPEC, tmp_path, EVAL_FREQ, 2, 1, checkpoint_freq=EVAL_FREQ)
    assert json.loads((tmp_path / "runs" / SPEC.name / "done.json").read_text())["resumed_from"] == [before]
    assert curve_steps(tmp_path) == list(range(EVAL_FREQ, STEPS + 1, EVAL_FREQ))


def test_a_checkpoint_that_does_not_load_is_marked_damaged_and_the_run_falls_back(tmp_path):
    newest, before = kill_after_two_checkpoints(tmp_path)
    checkpoint = tmp_path / "runs" / SPEC.name / "checkpoints" / f"step_{newest}"
    # an earlier release's record (sizes only) is accepted unverified; the resume itself then finds the damage
    (checkpoint / "replay_buffer.pkl").write_bytes(b"\0" * (checkpoint / "replay_buffer.pkl").stat().st_size)
    record = json.loads((checkpoint / "complete").read_text())
    (checkpoint / "complete").write_text(json.dumps({"step": newest, "sizes": record["sizes"]}))
    assert is_whole(checkpoint)
    with pytest.warns(UserWarning, match=f"resuming from .*step_{newest} failed"):
        run(SPEC, tmp_path, EVAL_FREQ, 2, 1, checkpoint_freq=EVAL_FREQ)
    assert json.loads((tmp_path / "runs" / SPEC.name / "done.json").read_text())["resumed_from"] == [before]
    assert curve_steps(tmp_path) == list(range(EVAL_FREQ, STEPS + 1, EVAL_FREQ))
