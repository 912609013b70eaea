"""Every code block of the README runs as written, in a fresh folder (slow: the blocks train, on small budgets).

Python blocks run in order as one script; each line of a bash block runs as a command with the project's environment
on ``PATH``. What a block trains is cut to a small budget by :data:`BUDGETS`; commands that this test cannot run
inside itself are listed in :data:`NOT_RUN_HERE` with where they run instead.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parents[1]
README = (REPOSITORY / "README.md").read_text()
BLOCK = re.compile(r"^```(\w+)\n(.*?)^```", re.MULTILINE | re.DOTALL)
#: text in a block -> what this test runs instead (a smaller training budget)
BUDGETS = {"learn(20_000)": "learn(1_200)"}
#: commands -> where they run instead
NOT_RUN_HERE = {
    "make results": "the main job (~10 min): its two commands run in test_reference_run.py and test_benchmark.py",
    "make test": "the test suite itself, which runs this test (CI)",
    "make results-page": "rewrites committed files; its functions are tested in test_benchmark.py",
}


def blocks(language: str) -> list[str]:
    return [body for lang, body in BLOCK.findall(README) if lang == language]


def commands() -> list[str]:
    """Every command line of the bash blocks, continuation lines joined and comments dropped."""
    lines = []
    for body in blocks("bash"):
        for line in body.replace("\\\n", " ").splitlines():
            command = re.sub(r"\s+#.*$", "", line).strip()
            if command:
                lines.append(command)
    return lines


def run(arguments: list[str] | str, cwd: Path, shell: bool = False) -> subprocess.CompletedProcess:
    environment = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    environment["MUJOCO_GL"] = "disable"
    return subprocess.run(arguments, cwd=cwd, shell=shell, env=environment, capture_output=True, text=True, timeout=900)


def test_the_readme_has_the_blocks_this_test_reads():
    assert len(blocks("python")) >= 3 and len(commands()) >= 8
    assert all(any(text in body for body in blocks("python")) for text in BUDGETS)
    assert set(NOT_RUN_HERE) <= set(commands())


@pytest.mark.slow
def test_the_python_blocks_run(tmp_path):
    script = "\n\n".join(blocks("python"))
    for text, replacement in BUDGETS.items():
        script = script.replace(text, replacement)
    (tmp_path / "readme.py").write_text(script)
    result = run([sys.executable, "readme.py"], tmp_path)
    assert result.returncode == 0, result.stderr[-3000:]
    assert (tmp_path / "policy.onnx").is_file() and (tmp_path / "policy.pt").is_file()
    example = run(
        [sys.executable, str(REPOSITORY / "examples" / "run_exported_policy.py"), "policy.onnx", "policy.pt"], tmp_path
    )
    assert example.returncode == 0 and example.stdout.startswith("onnx:"), example.stderr[-3000:]


@pytest.mark.slow
def test_the_commands_run(tmp_path):
    for command in commands():
        if command in NOT_RUN_HERE:
            continue
        if command.startswith("pip install"):  # resolves the extras against the constraints, installs nothing
            command = command.replace("-c constraints.txt", f"-c {REPOSITORY / 'constraints.txt'}")
            command = command.replace('".[', f'"{REPOSITORY}[') + " --dry-run --quiet"
        result = run(command, tmp_path, shell=True)
        assert result.returncode == 0, f"{command}\n{result.stderr[-3000:]}"
    assert (tmp_path / "results" / "short" / "results.csv").is_file()


def test_the_how_it_works_table_names_functions_that_exist():
    """Every name in the README's "How it works" table resolves (short names relative to ``sb3_gqn``, a bare name to the
    module named before it in the same cell)."""
    import importlib

    section = README.split("## How it works", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("| ") and "`" in line.split("|")[-2]]
    assert len(rows) >= 6
    for row in rows:
        module = None
        for name in re.findall(r"`([\w.]+)`", row.split("|")[-2]):
            if "." in name:
                path = name if name.startswith("sb3_gqn.") else f"sb3_gqn.{name}"
                parts = path.split(".")
                for cut in range(len(parts) - 1, 0, -1):  # the longest importable prefix is the module
                    try:
                        module = importlib.import_module(".".join(parts[:cut]))
                    except ModuleNotFoundError:
                        continue
                    attributes = parts[cut:]
                    break
            else:
                attributes = [name]
            obj = module
            for attribute in attributes:
                obj = getattr(obj, attribute)
            assert obj is not None, name
