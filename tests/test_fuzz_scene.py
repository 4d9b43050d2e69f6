"""Fuzzing the scene loader: malformed variants of the built-in scenes either load or raise
the project's SceneError with one short, printable line (never another exception).

The variants are cheap `load_scene_text` calls (nothing is run): a line's value replaced by a
hostile value (huge or tiny numbers, integers of thousands of digits, deep nesting, control
characters, wrong types), random character edits, and stray keys or sections.
"""

from __future__ import annotations

import warnings

from hypothesis import HealthCheck, given, settings, strategies as st

from sweep.errors import MAX_LINE, UserError, one_line
from sweep.scene import _scenes_dir, builtin_scenes, load_scene_text

SCENES = [(_scenes_dir() / f"{name}.toml").read_text("utf-8") for name in builtin_scenes()]

HOSTILE_VALUES = [
    "1" * 4301, "1" + "0" * 400, "-1" + "0" * 30, "5e-324", "1e308", "-1e308", "1e-308", "0",
    "-0.0", "nan", "inf", "-inf", "true", '""', '"\\u001b[2J"', '"' + "x" * 5000 + '"',
    "[" * 2000 + "]" * 2000, "{a = " * 1500 + "1" + "}" * 1500, "[]", "[1, 2", "{}",
    "1979-05-27", "07:32:00", "[5e-324, 1.0]", "{start = 5e-324, stop = 1e308, num = 3}",
    "{start = 1, stop = 2, num = " + "9" * 30 + "}", '"\\ud800"', "0x7fffffffffffffff",
]
EXTRA_LINES = ["[axes]", "[cable]", "x = 1", '"\\u001b[31m" = 1', "[[cable]]", "a.b.c = 1",
               "[solver]\nrtol = 1e-300", "[axes]\ndensity = [5e-324]", "= 1", "[" * 50,
               # the keys and rules of this session: ramps, level tables, workers, huge grids
               "[base]\nsweep = { start = 5.0, stop = 100.0, rate = 2.0, ramp_cycles = 1e308 }",
               "[base]\nsweep = { start = 5.0, stop = 100.0, rate = 5e-324, ramp_cycles = -1 }",
               "[base]\nlevels_g = [[5.0, 1e308], [100.0, 1.0]]\nfrequency = 1e300",
               "[base]\nacceleration_g = 1.0\nfrequency_ratio = 1e300",
               "[run]\nbackend = \"dask\"\nworkers = 100000",
               "[axes]\nlength = {start = 0.1, stop = 1.0, num = 10000000}\n"
               "frequency_ratio = {start = 0.5, stop = 3.0, num = 10000000}",
               "[outputs]\nbands_per_octave = 0\nstability = true",
               # [clamps] (issue 35): ends, springs and their axes, hostile values
               "[clamps]\nrotation = \"elastic\"\nrotational_stiffness = 1e308",
               "[clamps]\nrotation = \"elastic\"\nrotational_stiffness = 5e-324",
               "[clamps]\nrotation = \"clamped\"", "[clamps]\nrotation = \"elastic\"",
               "[clamps]\nrotational_stiffness = 0.0",
               "[axes]\nclamp_rotational_stiffness = [0.0, 1e300]",
               "[clamps]\nrotation = \"elastic\"\n[axes]\nclamp_rotational_stiffness = "
               "{start = 5e-324, stop = 1e308, num = 3}"]


def _check(text: str) -> None:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            load_scene_text(text, source="fuzz.toml")
    except UserError as exc:
        message = str(exc)
        assert "\n" not in message and "\r" not in message, message[:200]
        line = one_line(message)
        assert line.isprintable() and len(line) <= MAX_LINE + 10, line[:200]


@st.composite
def value_swaps(draw):
    lines = draw(st.sampled_from(SCENES)).splitlines()
    index = draw(st.sampled_from([i for i, l in enumerate(lines) if "=" in l]))
    key = lines[index].partition("=")[0]
    lines[index] = f"{key}= {draw(st.sampled_from(HOSTILE_VALUES))}"
    return "\n".join(lines)


@st.composite
def char_edits(draw):
    text = draw(st.sampled_from(SCENES))
    for _ in range(draw(st.integers(1, 4))):
        at = draw(st.integers(0, len(text)))
        new = draw(st.text(st.sampled_from("[]{}=\"'.,#\n0123456789e-+xa\\\x1b\x00 "),
                           max_size=3))
        text = text[:at] + new + text[at + draw(st.integers(0, 3)):]
    return text


@st.composite
def extra_lines(draw):
    lines = draw(st.sampled_from(SCENES)).splitlines()
    at = draw(st.integers(0, len(lines)))
    lines.insert(at, draw(st.sampled_from(EXTRA_LINES)))
    return "\n".join(lines)


FUZZ = settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))


@FUZZ
@given(value_swaps())
def test_hostile_values_load_or_give_one_line(text):
    _check(text)


@FUZZ
@given(char_edits())
def test_character_edits_load_or_give_one_line(text):
    _check(text)


@settings(max_examples=60, deadline=None, suppress_health_check=list(HealthCheck))
@given(extra_lines())
def test_stray_lines_load_or_give_one_line(text):
    _check(text)
