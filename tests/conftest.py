"""Shared helpers: build kernel parameter rows, run the kernel, the same ODE for SciPy."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

import sweep

from sweep.kernels import oscillator as osc
from sweep.kernels import transverse as tk
from sweep.threads import solve_transverse

SWEEP_ROOT = Path(sweep.__file__).resolve().parents[1]
"""The folder holding the sweep under test, installed or a checkout, as this process imported
it: a subprocess must import the same copy, or it compiles into a Numba cache of its own."""


def sweep_env(env: dict[str, str] | None = None) -> dict[str, str]:
    """`env` (default: this process's environment) for a subprocess that imports the sweep
    under test (SWEEP_ROOT first on its path)."""
    return {**(os.environ if env is None else env), "PYTHONPATH": str(SWEEP_ROOT)}


def param_row(m=1.0, c=0.0, k0=1.0, k1=0.0, g0=0.0, g1=0.0, h=0.0, omega=0.0,
              q0=0.0, v0=0.0, bound=1e9) -> np.ndarray:
    """One kernel parameter row (columns of kernels.oscillator)."""
    row = np.zeros(osc.N_PARAMS)
    for name, value in zip(osc.PARAM_NAMES, (m, c, k0, k1, g0, g1, h, omega, q0, v0, bound)):
        row[osc.PARAM_NAMES.index(name)] = value
    return row


def settings(rtol=1e-8, atol=1e-12, t_end=5.0, max_steps=10**6, max_step=math.inf,
             first_step=0.0, tail=0.5, tol=0.02, sample_dt=0.01, settling=True,
             min_step=0.0, controller="scipy", method="rk45") -> np.ndarray:
    """A kernel settings vector (kernels.transverse)."""
    s = np.zeros(tk.N_SETTINGS)
    s[tk.RTOL], s[tk.ATOL], s[tk.T_END] = rtol, atol, t_end
    s[tk.MAX_STEPS], s[tk.MAX_STEP], s[tk.FIRST_STEP] = max_steps, max_step, first_step
    s[tk.TAIL], s[tk.TOL], s[tk.SAMPLE_DT] = tail, tol, sample_dt
    s[tk.WANT_SETTLING] = 1.0 if settling else 0.0
    s[tk.MIN_STEP] = min_step
    s[tk.CONTROLLER] = 1.0 if controller == "pi" else 0.0
    s[tk.METHOD] = 1.0 if method == "dop853" else 0.0
    return s


def solve(rows, s, n_samples=0, driver="scalar"):
    """Run the batched kernel (the scalar driver unless told); returns (states, reals, counts,
    series)."""
    rows = np.atleast_2d(np.asarray(rows, dtype=float))
    n = rows.shape[0]
    states = np.empty(n, np.int8)
    reals = np.empty((n, tk.N_REALS))
    counts = np.empty((n, tk.N_COUNTS), np.int64)
    series = np.empty((n, n_samples))
    solve_transverse(rows, s, states, reals, counts, series, driver=driver)
    return states, reals, counts, series


def rhs(row):
    """The oscillator as a SciPy right-hand side, written independently of the kernel."""
    m, c, k0, k1, g0, g1, h, w = row[:8]

    def f(t, y):
        q, v = y
        cw = np.cos(w * t)
        return [v, -(c * v + (k0 + k1 * cw) * q + (g0 + g1 * cw) * q ** 3 + h * q ** 5) / m]
    return f


@pytest.fixture
def paper_row():
    """Eq.32 as printed at l = 1 m, n = 1, released with q'(0) = 0.0321 m/s."""
    l = 1.0
    return param_row(m=0.5 * l, k0=1.73 * np.pi ** 2 * l, k1=-1.08 * l ** 5,
                     g0=6.6e5 * np.pi ** 2 * l ** 3 - 2.1 * np.pi ** 4 / l,
                     g1=0.54 * np.pi ** 2 * l ** 3, h=76 * np.pi ** 6 / l ** 3,
                     omega=1.86 * np.pi, v0=0.0321, bound=l)


TABLE1_CABLE = """youngs_modulus = 1.1e11
density = 8900.0
area = 6e-6
inertia = 2.865e-12"""
"""The paper's Table 1 cable (SI) as [cable] keys of a scene, with the bending moment of inertia
of the solid round 6 mm^2 section (docs/model.md sec. 1): scene templates put it under [cable]."""


COMPILE_LINES = ("compiling the Numba kernels", "compiled in ")
"""The lines a cold start prints on stderr, terminal or not (sweep.execute)."""


def stderr_lines(text: str) -> list[str]:
    """The non-empty lines of a run's stderr but the cold start's compile lines: a test that
    counts the lines a run says about an interrupt or an error holds on a cold cache too."""
    return [line for line in text.strip().splitlines()
            if line.strip() and not line.startswith(COMPILE_LINES)]


def fast_first(cases, fast) -> list:
    """pytest parameters of `cases` (a dict's keys or a list), every one but `fast` marked
    slow: the fast tier (`pytest -m "not slow"`) keeps one case of a check, CI runs them all."""
    return [pytest.param(*(c if isinstance(c, tuple) else (c,)),
                         marks=() if c == fast else pytest.mark.slow)
            for c in cases]


@pytest.fixture
def ctrl_c_raises():
    """SIGINT answered by Python's own handler (KeyboardInterrupt) for the test, as in an
    interactive shell: a suite started in the background of a non-interactive shell (CI
    scripts, `nohup`) inherits SIGINT ignored, and the tests that press Ctrl-C in-process
    would see nothing. The handler before is restored after."""
    import signal
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, before)
