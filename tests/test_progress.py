"""The progress bar: tqdm's, on stderr, one line however narrow the terminal, only on a terminal,
with the time Numba spends compiling kept off its clock."""

from __future__ import annotations

import fcntl
import os
import re
import struct
import subprocess
import sys
import termios

import numpy as np
import pytest

import sweep
from sweep.execute import Progress, announce_compilation, execute

from conftest import stderr_lines, sweep_env


SMALL = """
name = "progress-test"
[load]
amplitude = 4.0
[axes]
length = {start = 0.3, stop = 1.0, num = 6}
frequency_ratio = {start = 0.5, stop = 3.0, num = 5}
[solver]
t_end = 1.0
"""


def _place_into(values: np.ndarray):
    def place(lo, hi, arrays):
        values[lo:hi] = arrays["value"]
    return place


def _double(rows: np.ndarray, threads: int = 0) -> dict:
    return {"value": 2.0 * rows}


def test_the_bar_is_tqdms_and_ends_at_the_total(capsys):
    values = np.zeros(50)
    execute(_double, lambda lo, hi: np.arange(lo, hi, dtype=float), 50, (),
            _place_into(values), chunk_size=7, progress=True)
    err = capsys.readouterr().err
    np.testing.assert_array_equal(values, 2.0 * np.arange(50))
    frames = [f for f in err.rstrip("\n").split("\r") if f]
    assert err.count("\n") == 1 and err.endswith("\n"), repr(err)     # one line, closed once
    assert re.match(r" *0%\|.*\| 0/50 \[00:00<\?, \? points/s\]", frames[0]), frames[0]
    assert re.match(r"100%\|.*\| 50/50 \[", frames[-1]), frames[-1]
    assert "inf" not in err


def test_no_bar_without_progress_or_when_stderr_is_not_a_terminal(capsys):
    values = np.zeros(10)
    execute(_double, lambda lo, hi: np.arange(lo, hi, dtype=float), 10, (),
            _place_into(values), chunk_size=3, progress=False)
    sweep.run(sweep.load_scene_text(SMALL))       # progress=None: stderr (captured) is no tty
    # no bar; only a cold start's two compile lines, if the kernels were not in the cache
    assert stderr_lines(capsys.readouterr().err) == []


def _fresh_compile(rows: np.ndarray, threads: int = 0) -> dict:
    """A chunk kernel whose every call compiles a Numba function made anew (no cache)."""
    import numba

    @numba.njit
    def double(x):
        return 2.0 * x

    return {"value": np.array([double(float(r)) for r in rows])}


def test_compiling_is_kept_off_the_bars_clock(capsys):
    """The bar's clock starts later by exactly the time spent compiling, so the rate and the
    time left are the kernel's, not the compiler's."""
    bar = Progress(4, 0, True)
    started = bar.bar.start_t
    with announce_compilation(True, bar) as clock:
        _fresh_compile(np.arange(2.0))
        _fresh_compile(np.arange(2.0))
    assert clock.seconds > 0.0
    # (start_t is time.time(), ~1.7e9 s: its ulp is ~2e-7 s)
    assert abs((bar.bar.start_t - started) - clock.seconds) < 1e-5
    bar.close()
    err = capsys.readouterr().err
    assert err.count("compiling the Numba kernels") == 1 and "compiled in" in err


@pytest.mark.slow
def test_a_terminal_gets_one_line_that_fits_a_narrow_window(tmp_path):
    """`sweep run` on a 40-column terminal: a tqdm bar from the start, every redraw within 40
    columns on one line (no wrapping), and the summary after it."""
    (tmp_path / "s.toml").write_text(SMALL)
    master, slave = os.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 40, 0, 0))
    env = sweep_env()
    env.pop("COLUMNS", None)
    proc = subprocess.Popen([sys.executable, "-m", "sweep.cli", "run", "s.toml", "-o", "o.nc"],
                            cwd=tmp_path, env=env, stdin=subprocess.DEVNULL,
                            stdout=subprocess.DEVNULL, stderr=slave)
    os.close(slave)
    chunks = []
    while True:
        try:
            data = os.read(master, 4096)
        except OSError:                  # EIO: the child closed its end
            break
        if not data:
            break
        chunks.append(data)
    os.close(master)
    assert proc.wait(timeout=120) == 0
    text = b"".join(chunks).decode()
    lines = [line for line in text.replace("\r\n", "\n").split("\n") if line.strip()]
    bar = [line for line in lines if "points/s" in line or "%|" in line]
    assert len(bar) == 1, text                          # the bar kept to one line
    frames = [f for f in bar[0].split("\r") if f.strip()]
    assert frames[0].lstrip().startswith("0%|"), frames
    assert frames[-1].startswith("100%|") and "30/30" in frames[-1], frames
    assert all(len(f) <= 40 for f in frames), frames
