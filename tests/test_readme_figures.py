"""Every result README.md quotes from a built-in scene matches a fresh run of that scene at the
README's own precision (benchmarks/readme_figures.py holds the phrases and regenerates them):
a change that moves a quoted number fails here until the README says the new one."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import readme_figures as rf  # noqa: E402

pytestmark = pytest.mark.slow      # runs the built-in scenes whole


@pytest.fixture(scope="module")
def runs():
    cache: dict = {}

    def get(scene: str):
        if scene not in cache:
            cache.update(rf.results({scene}))
        return cache[scene]
    return get


@pytest.mark.parametrize("figure", rf.FIGURES, ids=[f"{f.scene}: {f.what}" for f in rf.FIGURES])
def test_the_readme_quotes_what_a_fresh_run_gives(figure, runs):
    phrase = figure.phrase(runs(figure.scene))
    assert rf.flat(phrase) in rf.readme(), (
        f"README.md no longer quotes {figure.scene} ({figure.what}) as a fresh run gives it: "
        f"'{phrase}' (PYTHONPATH=. python benchmarks/readme_figures.py prints every phrase)")


def test_a_stale_phrase_is_caught():
    """The check can fail: a number one digit off is not in the README."""
    assert rf.flat("**4.10, 3.67, 3.42, 3.22 mm**") in rf.readme()
    assert rf.flat("**4.11, 3.67, 3.42, 3.22 mm**") not in rf.readme()
    assert rf.two_figures(29.6) == "30" and rf.two_figures(588.1) == "590"
    assert rf.two_figures(0.0421) == "0.042"
