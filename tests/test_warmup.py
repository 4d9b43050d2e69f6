"""`sweep compile`: a scene's kernels compiled ahead of its first run (sweep/warmup.py).

The check that counts is the slow one: on an empty Numba cache, after `sweep compile SCENE`,
the scene's own run (on other values of its axes) compiles nothing: it prints none of the
cold start's lines, which sweep.execute prints whenever Numba compiles.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import sweep
from conftest import COMPILE_LINES, sweep_env
from sweep.warmup import POINTS_PER_AXIS, reduced



def sweep_cli(argv: list[str], cwd: Path, cache: Path | None = None
              ) -> subprocess.CompletedProcess:
    env = sweep_env()
    if cache is not None:
        env["NUMBA_CACHE_DIR"] = str(cache)
    return subprocess.run([sys.executable, "-m", "sweep.cli", *argv], capture_output=True,
                          text=True, cwd=cwd, env=env, timeout=900)


def test_the_warm_up_runs_a_few_points_of_the_same_scene():
    """Every axis cut to its first values, [points] to its first set, the threads backend; the
    rest of the scene (what decides which kernels compile) unchanged."""
    scene = sweep.load_scene("harness-stepped-sine", overrides={"run.backend": "dask"})
    small = reduced(scene)
    assert small.axes.keys() == scene.axes.keys()
    for name, axis in small.axes.items():
        np.testing.assert_array_equal(axis, scene.axes[name][:POINTS_PER_AXIS])
    assert small.get("run.backend") == "threads"
    changed = {k for k in scene.values if scene.values[k] != small.values[k]}
    assert changed == {"run.backend"}
    text = ('name = "p"\n[load]\namplitude = 0.0\n[base]\nacceleration_g = 0.5\n'
            'frequency = 30.0\n[points]\nlength = [0.3, 0.4, 0.5]\n'
            'damping_ratio = [0.01, 0.02, 0.03]\n')
    zipped = reduced(sweep.load_scene_text(text))
    assert {k: list(v) for k, v in zipped.points.items()} == {"length": [0.3],
                                                              "damping_ratio": [0.01]}


def test_the_warm_up_compiles_the_follow_up_passes_no_point_needed():
    """paper-fig5's points are all steady about zero: none needs the second pass, yet the
    warm-up compiles its entry point (and a plain run does not)."""
    from sweep import specialise
    from sweep.kernels import transverse
    from sweep.warmup import warm_up

    def second_pass_entries() -> int:
        return sum(1 for kernel, _ in specialise._ENTRIES
                   if kernel is transverse.settle_second_pass)

    specialise._ENTRIES.clear()
    sweep.run(reduced(sweep.load_scene("paper-fig5")), progress=False)
    assert second_pass_entries() == 0
    warm_up(sweep.load_scene("paper-fig5"))
    assert second_pass_entries() == 1


def test_compile_says_one_line_a_scene_and_refuses_a_bad_name_in_one_line(tmp_path):
    ok = sweep_cli(["compile", "paper-fig5"], tmp_path)
    assert ok.returncode == 0, ok.stderr
    lines = ok.stdout.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("paper-fig5: "), ok.stdout
    bad = sweep_cli(["compile", "paper-fig5", "no-such-scene"], tmp_path)
    assert bad.returncode == 2 and bad.stdout == ""
    err = bad.stderr.strip().splitlines()
    assert len(err) == 1 and "no-such-scene" in err[0] and "sweep scenes" in err[0], bad.stderr


@pytest.mark.slow
def test_after_compile_the_first_run_compiles_nothing(tmp_path):
    """Empty NUMBA_CACHE_DIR: `sweep compile` compiles (it says so); then the scene's run on
    other axis values prints no compile line, and a second `sweep compile` finds nothing to
    compile. The base-excited harness scene with one mode (with three its cold compile took
    2 of CI's 20 minutes)."""
    cache = tmp_path / "cache"
    cache.mkdir()
    first = sweep_cli(["compile", "harness-base-sine", "--set", "model.modes=1"], tmp_path,
                      cache)
    assert first.returncode == 0, first.stderr
    assert "compiled in" in first.stdout, first.stdout
    run = sweep_cli(["run", "harness-base-sine", "--set", "model.modes=1",
                     "--set", "axes.length=[0.45, 0.6]", "--set", "axes.base_frequency=[40.0]",
                     "-o", "out.nc"], tmp_path, cache)
    assert run.returncode == 0, run.stderr
    assert not any(line.startswith(COMPILE_LINES) for line in run.stderr.splitlines()), \
        run.stderr
    again = sweep_cli(["compile", "harness-base-sine", "--set", "model.modes=1"], tmp_path,
                      cache)
    assert again.returncode == 0 and "nothing to compile" in again.stdout, again.stdout
