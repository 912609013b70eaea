"""The Markdown documents' relative links point at files and headings that exist: a link written from the wrong
folder, or to a heading renamed since, would render as a dead link on GitHub without any other check noticing. The
product's text (code, tests, shipped files, the docs outside ``docs/research/``) speaks of the product only."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parents[1]
DOCUMENTS = [
    "README.md",
    "CHANGELOG.md",
    "docs/results/README.md",
    "docs/results/metaworld.md",
    "docs/results/myosuite.md",
    "docs/results/paper-scale.md",
    "docs/results/paper-protocol.md",
    "docs/results/mujoco.md",
    "docs/research/README.md",
    "docs/research/benchmarks.md",
]
LINK = re.compile(r"\]\(([^)\s]+)\)")
CODE_BLOCK = re.compile(r"^```.*?^```", re.MULTILINE | re.DOTALL)


def github_anchor(heading: str) -> str:
    """GitHub's anchor for a Markdown heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def anchors(path: Path) -> set[str]:
    text = CODE_BLOCK.sub("", path.read_text())
    return {github_anchor(line.lstrip("#")) for line in text.splitlines() if re.match(r"#{1,6} ", line)}


def test_github_anchor_matches_githubs_rule():
    assert github_anchor(" Train GQN on your own task: DecQN's torso and two critics") == (
        "train-gqn-on-your-own-task-decqns-torso-and-two-critics"
    )
    assert github_anchor("Growth with the new defaults (0.2.0): measured at 100k steps") == (
        "growth-with-the-new-defaults-020-measured-at-100k-steps"
    )
    assert github_anchor("Deploy: export the policy (`sb3_gqn.export`)") == "deploy-export-the-policy-sb3_gqnexport"


@pytest.mark.parametrize("document", DOCUMENTS)
def test_relative_links_resolve(document):
    path = REPOSITORY / document
    broken = []
    for target in LINK.findall(CODE_BLOCK.sub("", path.read_text())):
        if target.startswith(("http://", "https://", "mailto:")):
            continue
        file_part, _, anchor = target.partition("#")
        linked = (path.parent / file_part).resolve() if file_part else path
        if not linked.exists():
            broken.append(f"{target}: no file {linked}")
        elif anchor and linked.suffix == ".md" and anchor not in anchors(linked):
            broken.append(f"{target}: no heading with anchor #{anchor} in {linked.name}")
    assert not broken, "\n".join(broken)


#: where the product's text lives: these files and every text file under these folders, but docs/research/ (the
#: research record)
PRODUCT_TEXT = ["README.md", "CHANGELOG.md", "sb3_gqn", "tests", "docs", "examples", "benchmarks", "hyperparams"]
TEXT_SUFFIXES = {".py", ".md", ".rst", ".yml", ".yaml", ".txt", ".cfg", ".toml"}
#: how the record of the work names itself: tracker issues, the research record's decision rules, work sessions
HISTORY = [
    re.compile(r"\bissue \d+\b", re.IGNORECASE),
    re.compile(r"\b(?:rules?|before|after|since|by) [A-Z]\d\b"),
    re.compile(r"\bsession[- ]?\d+\b", re.IGNORECASE),
    re.compile(
        r"\b(?:a|an|the|this|that|each|every|later|earlier|next|previous|one|another|machine's|per)\s+sessions?\b",
        re.IGNORECASE,
    ),
]


def product_text_files() -> list[Path]:
    research, build = REPOSITORY / "docs" / "research", REPOSITORY / "docs" / "_build"
    paths = [REPOSITORY / name for name in PRODUCT_TEXT]
    paths = [found for path in paths for found in ([path] if path.is_file() else sorted(path.rglob("*")))]
    return [
        path
        for path in paths
        if path.suffix in TEXT_SUFFIXES and path.is_file() and research not in path.parents and build not in path.parents
    ]


def history_references(text: str) -> list[str]:
    return [match.group(0) for pattern in HISTORY for match in pattern.finditer(text)]


def test_the_history_patterns_find_what_they_are_for():
    # written in pieces, so that this file holds none of them
    word, number = "session", 9
    record = [f"Issue {11} item 5", f"by rule R{1}", f"as before D{4}", f"{word}-{number}", f"a later {word}"]
    assert all(history_references(phrase) for phrase in [*record, f"this machine's {word}s"])
    product = 'the plateau rule; max(Q1, Q2); onnxruntime.InferenceSession(path); session.run(); scope="session"'
    assert history_references(product) == []


def test_the_product_text_names_no_issue_rule_or_session():
    """Issue, decision-rule and session names belong to the research record (docs/research/), not to the product's
    code, tests and pages."""
    files = product_text_files()
    assert {
        REPOSITORY / "README.md",
        REPOSITORY / "tests" / "test_docs.py",
        REPOSITORY / "docs" / "results" / "metaworld.md",
    } <= set(files)
    found = [
        f"{path.relative_to(REPOSITORY)}:{number}: {reference}"
        for path in files
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1)
        for reference in history_references(line)
    ]
    assert not found, "history in the product's text (move it to docs/research/):\n" + "\n".join(found)
