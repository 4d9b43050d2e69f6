"""What a walk through README.md as a new user found: a command it prints that refers to an
axis its result lacks, and two user errors whose one line named the wrong thing (a `--select
direction=up` called 'up' not a number; `--workers 8` on a smaller machine named the scene key
run.workers, not the flag the user typed)."""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from sweep.cli import main as sweep_main
from sweep.errors import UserError
from sweep.plot.result import parse_select, select_points

from conftest import stderr_lines

README = Path(__file__).resolve().parents[1] / "README.md"

TINY = """
name = "walk-test"
[initial]
displacement = 1e-3
[solver]
t_end = 0.2
[axes]
length = [0.5, 0.6]
"""


def test_the_readme_selects_only_axes_its_own_run_made():
    """Every `sweep plot FILE --select AXIS=...` in the README follows a `sweep run ... -o FILE`
    that gives FILE that axis (the Pictures example once selected load_amplitude on map.nc,
    harness-parametric's two-axis map, which has none)."""
    text = README.read_text(encoding="utf-8")
    examples = re.findall(r"sweep plot (\S+\.nc) --select (\w+)=", text)
    assert examples
    for path, axis in examples:
        runs = re.findall(rf"sweep run .*-o {re.escape(path)}\b.*", text)
        assert any(f"axes.{axis}=" in run for run in runs), (path, axis, runs)


def test_select_direction_says_the_figures_draw_both_directions():
    with pytest.raises(UserError) as err:
        parse_select(["direction=up"])
    message = str(err.value)
    assert "\n" not in message and "not a number" not in message
    assert "--select 'direction=up'" in message and "up solid and down dashed" in message


def test_select_direction_from_python_says_the_same():
    ds = xr.Dataset({"state": (("length", "direction"), np.full((2, 2), 2, dtype=np.int8))},
                    coords={"length": [0.4, 0.5], "direction": ["up", "down"]})
    with pytest.raises(UserError, match="up solid and down dashed"):
        select_points(ds, {"direction": "up"})


def test_workers_beyond_the_cores_names_the_flag(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(TINY)
    out = tmp_path / "out.nc"
    workers = (os.cpu_count() or 1) + 1
    assert sweep_main(["run", str(scene), "-q", "-o", str(out), "--backend", "dask",
                       "--workers", str(workers)]) == 2
    lines = stderr_lines(capsys.readouterr().err)
    assert len(lines) == 1, lines
    assert lines[0].startswith(f"sweep: error: --workers {workers}: {workers} worker processes")
    assert f"give --workers {os.cpu_count() or 1} or fewer" in lines[0]
    assert not out.exists()


def test_negative_workers_names_the_flag(tmp_path, capsys):
    """--workers -1 is refused naming the flag the user typed, not the scene key run.workers."""
    scene = tmp_path / "s.toml"
    scene.write_text(TINY)
    out = tmp_path / "out.nc"
    assert sweep_main(["run", str(scene), "-q", "-o", str(out), "--backend", "dask",
                       "--workers", "-1"]) == 2
    lines = stderr_lines(capsys.readouterr().err)
    assert len(lines) == 1, lines
    assert lines[0].startswith("sweep: error: --workers -1: ") and "run.workers" not in lines[0]
    assert not out.exists()
