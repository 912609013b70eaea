"""A run's --threads bounds JAX (SBX's agents) as it bounds torch."""

import os

from sb3_gqn.experiments.runs import bound_jax_threads


def test_bound_jax_threads_sets_xlas_thread_flags_and_keeps_the_others(monkeypatch):
    monkeypatch.setenv("XLA_FLAGS", "--xla_dump_to=/tmp/x intra_op_parallelism_threads=8 --xla_cpu_multi_thread_eigen=true")
    bound_jax_threads(1)
    assert os.environ["XLA_FLAGS"] == "--xla_dump_to=/tmp/x --xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1"
    bound_jax_threads(2)
    assert os.environ["XLA_FLAGS"] == "--xla_dump_to=/tmp/x intra_op_parallelism_threads=2"
    monkeypatch.delenv("XLA_FLAGS")
    bound_jax_threads(1)
    assert os.environ["XLA_FLAGS"] == "--xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1"
