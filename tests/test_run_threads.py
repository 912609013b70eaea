"""A run's --threads bounds JAX (SBX's agents) as it bounds torch."""

import os
import subprocess
import sys

from sb3_gqn.experiments.runs import bound_jax_threads


def test_one_thread_sets_xlas_single_thread_flag_and_keeps_the_others(monkeypatch):
    monkeypatch.setenv("XLA_FLAGS", "--xla_dump_to=/tmp/x intra_op_parallelism_threads=8 --xla_cpu_multi_thread_eigen=true")
    bound_jax_threads(1)
    assert os.environ["XLA_FLAGS"] == "--xla_dump_to=/tmp/x --xla_cpu_multi_thread_eigen=false"
    # XLA has no flag for another count: its default, with the other flags kept
    bound_jax_threads(2)
    assert os.environ["XLA_FLAGS"] == "--xla_dump_to=/tmp/x"
    monkeypatch.delenv("XLA_FLAGS")
    bound_jax_threads(2)
    assert "XLA_FLAGS" not in os.environ
    bound_jax_threads(1)
    assert os.environ["XLA_FLAGS"] == "--xla_cpu_multi_thread_eigen=false"


def test_jax_computes_under_the_flags_it_sets():
    """XLA refuses flags it cannot parse with a fatal error (a bare word is read as a flag file): both settings run."""
    import pytest

    pytest.importorskip("jax")
    for threads in (1, 2):
        code = (
            "from sb3_gqn.experiments.runs import bound_jax_threads; "
            f"bound_jax_threads({threads}); import jax.numpy as jnp; print(float(jnp.ones((8, 8)).sum()))"
        )
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
        assert done.returncode == 0 and done.stdout.strip() == "64.0", done.stderr[-500:]
