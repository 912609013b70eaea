import os
from pathlib import Path

import pytest

os.environ.setdefault("MUJOCO_GL", "disable")

#: the research record's agents (beyond the shipped ones), which the committed tables hold
RESEARCH_VARIANTS = Path(__file__).resolve().parents[1] / "docs" / "research" / "variants.yml"


@pytest.fixture(scope="session")
def research_variants():
    """The shipped agents and the research record's, by name: passed explicitly to what reads them."""
    from sb3_gqn.experiments.variants import with_variants_files

    return with_variants_files([RESEARCH_VARIANTS])
