"""The Markdown documents' relative links point at files and headings that exist: a link written from the wrong
folder, or to a heading renamed since, would render as a dead link on GitHub without any other check noticing."""

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
    assert github_anchor(" Item 5, run by run: DecQN's residual torso and two critics") == (
        "item-5-run-by-run-decqns-residual-torso-and-two-critics"
    )
    assert github_anchor("Growth with the new defaults (issue 11): measured at 100k steps") == (
        "growth-with-the-new-defaults-issue-11-measured-at-100k-steps"
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
