# Set-up and checks. Every install goes through constraints.txt (torch pinned to the local CPU build).
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
PYTEST_ARGS ?=
# pytest-xdist workers for `make test` (2: the machine's cores; 0: one process, in the suite's own order)
PYTEST_WORKERS ?= 2

.PHONY: venv venv-myo results test test-slow test-myo lint typecheck docs benchmark results-page constraints constraints-myo clean

$(VENV)/.installed: setup.cfg pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --disable-pip-version-check -c constraints.txt -e ".[all,tests,docs]"
	touch $@

venv: $(VENV)/.installed

# MyoSuite's own environment: it cannot share one with Meta-World (mujoco 3.3.0 there, >= 3.4 here)
MYO_VENV ?= .venv-myo
$(MYO_VENV)/.installed: setup.cfg pyproject.toml constraints-myo.txt
	$(PYTHON) -m venv $(MYO_VENV)
	$(MYO_VENV)/bin/pip install --quiet --disable-pip-version-check -c constraints-myo.txt -e ".[myo,zoo,benchmark,tests]"
	touch $@

venv-myo: $(MYO_VENV)/.installed

# Main job (~7-10 min on 2 cores): GQN on penalized cartpole-swingup (learning curve, final evaluation), then the
# short comparison suite (GQN vs DecQN 2/9 vs SAC on penalized Pendulum: table and plots) into results/
results: venv
	$(BIN)/sb3-gqn reference-run --out results --timesteps 40000 --threads 1
	$(BIN)/sb3-gqn benchmark --out results/benchmark

lint: venv
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

# mypy over the package (configured in pyproject.toml)
typecheck: venv
	$(BIN)/mypy

test: venv lint typecheck
	$(BIN)/python -m pytest -m "not slow" -n $(PYTEST_WORKERS) $(PYTEST_ARGS)

test-slow: venv
	$(BIN)/python -m pytest -m slow $(PYTEST_ARGS)

# MyoSuite's tests and its shipped entries, in its own environment (a missing myosuite fails instead of skipping)
test-myo: venv-myo
	SB3_GQN_REQUIRE_MYOSUITE=1 $(MYO_VENV)/bin/python -m pytest tests/test_myosuite.py \
		tests/test_zoo.py::test_every_shipped_entry_builds_its_env_and_model -k "myo" $(PYTEST_ARGS)

# The API documentation (Sphinx, from the docstrings) into docs/_build/html; warnings are errors
docs: venv
	$(BIN)/sphinx-build -W --keep-going -q -b html docs docs/_build/html

benchmark: venv
	$(BIN)/python benchmarks/throughput.py
	$(BIN)/python benchmarks/replay.py
	$(BIN)/python benchmarks/bad_input.py
	$(BIN)/python benchmarks/checkpoints.py

# The results page (docs/results/README.md), the README's results table and docs/results/main's figures, from the
# committed docs/results tables
results-page: venv
	$(BIN)/python docs/results/build.py

# Re-pin the whole dependency set from a fresh environment
constraints:
	rm -rf /tmp/sb3-gqn-constraints && $(PYTHON) -m venv /tmp/sb3-gqn-constraints
	/tmp/sb3-gqn-constraints/bin/pip install --quiet -c constraints.txt ".[all,tests,docs]"
	/tmp/sb3-gqn-constraints/bin/pip freeze | grep -v '^sb3-gqn' | sed 's/+cpu$$//'

constraints-myo:
	rm -rf /tmp/sb3-gqn-constraints-myo && $(PYTHON) -m venv /tmp/sb3-gqn-constraints-myo
	/tmp/sb3-gqn-constraints-myo/bin/pip install --quiet -c constraints-myo.txt ".[myo,zoo,benchmark,tests]"
	/tmp/sb3-gqn-constraints-myo/bin/pip freeze | grep -v '^sb3-gqn' | sed 's/+cpu$$//'

clean:
	rm -rf $(VENV) $(MYO_VENV) .pytest_cache .ruff_cache build *.egg-info docs/_build
