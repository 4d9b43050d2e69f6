"""`max_deflection`: the largest |w(x, t)| over the span and the tail window, against SciPy.

The reference is independent of the engine: SciPy's DOP853 at rtol 1e-11 on the Galerkin
equations of tests/galerkin.py (`shapes_rhs`: the textbook pinned sines or clamped cosh/cos
modes, the uniform tension N = k_s e of immovable clamps, the bending terms from the span's
energy), its dense output sampled on a grid of 200 instants per period of the fastest motion
times 1601 stations, each grid crest within 1e-3 of the largest refined by a bounded search
in time of the span's maximum, itself refined by a bounded search in x.

The engine used to look for the crest only at some instants of each step (a mode's extremum,
where the deflection at the place of the largest so far turned, the tail's start): a span with
mode 2 moving (released from q_2 = 50 um) under a 3 g base sine near mode 3's resonance crested
off midspan inside steps where no mode turned, and read up to 2.1e-3 low (5 of 9 points of a
scan, 9.536 f1: 1.4e-3, 9.827 f1: 2.1e-3). It now searches every step that `_span_bound` leaves
room in (kernels/modal_driver.py, `observe_span`): within the solver's tolerance (measured
<= 2.9e-8 at rtol 1e-10, 3e-10 at 1e-12) below, at and above resonance, pinned and clamped.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

import sweep

import galerkin as g

LENGTH = 0.4                   # m (f1 = 23.9 Hz pinned)
ZETA = 0.02
G = 9.80665                    # m/s^2
EA = 1.1e11 * 6e-6             # N: the scene's cable
T_END = 0.3                    # s; the tail window is its second half
LEVEL_G = 3.0                  # base sine, g


def scene_text(rotation: str, modes: int, ratios: list[float], q0: list[float] | None,
               driver: str, method: str) -> str:
    """A Table 1 span between immovable clamps (the uniform tension), `modes` modes, under a
    LEVEL_G base sine at each of `ratios` x its f1, from q_n(0) = q0 (m; rest if None), by
    the solver driver and method given."""
    initial = f"[initial]\nmodal_displacement = {q0!r}\n" if q0 else ""
    return f"""
name = "span-maximum"
[model]
modes = {modes}
[clamps]
rotation = "{rotation}"
[cable]
damping_ratio = {ZETA}
inertia = 2.865e-12
[base]
acceleration_g = {LEVEL_G}
{initial}[solver]
t_end = {T_END}
rtol = 1e-10
driver = "{driver}"
method = "{method}"
[metrics]
tail = 0.5
[axes]
length = [{LENGTH}]
base_frequency_ratio = {[float(r) for r in ratios]!r}
"""


def shapes_and_frequencies(rotation: str, modes: int) -> tuple[list, np.ndarray]:
    """The textbook mode shapes (tests/galerkin.py callables) and natural angular frequencies
    (rad/s) of the span."""
    cable = g.Cable(length=LENGTH)
    if rotation == "pinned":
        return g.sine_shapes(modes, LENGTH), np.arange(1, modes + 1) ** 2 * cable.w1
    shapes = g.clamped_shapes(modes, LENGTH)
    x = 0.3 * LENGTH                     # b_n^4 = phi'''' / phi anywhere phi is not 0
    b4 = np.array([float(s(x, 4) / s(x, 0)) for s in shapes])
    ei_rho = cable.youngs_modulus * cable.inertia / (cable.density * cable.area)
    return shapes, np.sqrt(b4 * ei_rho)


@functools.lru_cache(maxsize=None)
def reference(rotation: str, modes: int, ratio: float,
              q0: tuple[float, ...] | None) -> tuple[float, float]:
    """(max |w(x, t)| (m), its x / l) over the span and [T_END / 2, T_END] by SciPy, sampled
    densely and refined (module docstring)."""
    cable = g.Cable(length=LENGTH, damping_ratio=ZETA)
    shapes, omegas = shapes_and_frequencies(rotation, modes)
    f = g.shapes_rhs(cable, shapes, omegas, LEVEL_G * G, ratio * omegas[0] / (2 * math.pi),
                     tension_stiffness=EA / LENGTH)
    y0 = np.concatenate((q0 if q0 else np.zeros(modes), np.zeros(modes)))   # at rest
    sol = solve_ivp(f, (0.0, T_END), y0, method="DOP853", rtol=1e-11, atol=1e-16,
                    dense_output=True)
    assert sol.success
    sol = sol.sol
    t0 = 0.5 * T_END
    fastest = max(omegas[-1], ratio * omegas[0]) / (2 * math.pi)
    t = np.linspace(t0, T_END, int(200 * fastest * (T_END - t0)) + 2)
    x = np.linspace(0.0, LENGTH, 1601)
    phi = np.array([s(x, 0) for s in shapes])                # (N, stations)
    w = np.abs(sol(t)[:modes].T @ phi)                        # (instants, stations)
    at = np.argmax(w, axis=1)
    crest, place = w[np.arange(t.size), at], x[at]
    dx = x[1] - x[0]

    def span_max(s: float, near: float) -> tuple[float, float]:
        q = sol(s)[:modes]
        found = minimize_scalar(
            lambda z: -abs(sum(q[i] * float(shapes[i](z, 0)) for i in range(modes))),
            bounds=(max(0.0, near - 2 * dx), min(LENGTH, near + 2 * dx)), method="bounded",
            options={"xatol": 1e-14})
        return -float(found.fun), float(found.x)

    best, where = float(crest.max()), float(place[np.argmax(crest)])
    for i in range(t.size):
        lo, hi = max(i - 1, 0), min(i + 1, t.size - 1)
        if crest[i] < crest[lo] or crest[i] < crest[hi] or crest[i] < (1 - 1e-3) * best:
            continue
        found = minimize_scalar(lambda s: -span_max(s, place[i])[0], bounds=(t[lo], t[hi]),
                                method="bounded", options={"xatol": 1e-13})
        value, z = span_max(float(found.x), place[i])
        if value > best:
            best, where = value, z
    return best, where / LENGTH


CASES = {
    # mode 2 released from 50 um, 3 g near mode 3's resonance: the crest lies 2-5 mm off
    # midspan between the instants the engine used to look at (1.4e-3 and 2.1e-3 low), and
    # below (0.5 f1), at and above (1.5 f1) the first resonance
    "pinned-3-modes-mode-2-moving": ("pinned", 3, [0.5, 1.0, 1.5, 9.536, 9.827],
                                     [0.0, 5e-5, 0.0]),
    # from rest, clamped: at resonance (crest at midspan) and between modes 1 and 3 (5.5 f1:
    # the crest at 0.217 l)
    "clamped-3-modes": ("clamped", 3, [1.0, 5.5], None),
    # five pinned modes, mode 2 moving, near mode 5's resonance (25.5 f1: the crest 6.5 mm off
    # midspan)
    "pinned-5-modes-mode-2-moving": ("pinned", 5, [25.5], [0.0, 5e-5, 0.0, 0.0, 0.0]),
}


RUNS = [(name, driver, "dop853") for name in CASES for driver in ("lanes", "scalar")] + [
    ("pinned-3-modes-mode-2-moving", driver, "rk45") for driver in ("lanes", "scalar")]


@pytest.mark.parametrize("name, driver, method", RUNS)
def test_max_deflection_is_the_dense_searchs_maximum(name, driver, method):
    """max_deflection within 1e-7 of the dense SciPy search (the engine at rtol 1e-10: it
    measured <= 2.9e-8, all of it the solver's error), its place (max_deflection_position,
    from the nearer clamp) within 1e-3 l of the search's; the midspan's amplitude never above
    it. Both drivers (the lanes search their ordinary steps apart from the steps they hand to
    the scalar path) and both methods (their interpolants differ)."""
    rotation, modes, ratios, q0 = CASES[name]
    ds = sweep.run(sweep.load_scene_text(scene_text(rotation, modes, ratios, q0, driver,
                                                    method)), progress=False)
    largest = ds["max_deflection"].values.ravel()
    position = ds["max_deflection_position"].values.ravel()
    amplitude = ds["amplitude"].values.ravel()
    for k, ratio in enumerate(ratios):
        ref, place = reference(rotation, modes, ratio, tuple(q0) if q0 else None)
        assert abs(largest[k] / ref - 1.0) < 1e-7, (ratio, largest[k], ref)
        nearer = min(place, 1.0 - place) * LENGTH
        assert abs(position[k] - nearer) < 1e-3 * LENGTH, (ratio, position[k], nearer)
        assert amplitude[k] <= largest[k]
