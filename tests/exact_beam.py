"""The exact steady state of a linear Euler-Bernoulli span under a uniform base acceleration
A sin(W t), written independently of the tool: rho A w_tt + EI w_xxxx = -rho A a_b (w the
deflection relative to the clamps, undamped), w = A / W^2 + C1 cosh bx + C2 sinh bx +
C3 cos bx + C4 sin bx with b^4 = rho A W^2 / EI, the four constants from the end conditions
w = 0 and EI w_xx = +-k w_x at x = 0, l (k the clamps' rotational stiffness, N m/rad; 0
pinned, None clamped: w_x = 0), solved as a 4 x 4 system. Its first natural frequency is the
smallest b where that system is singular."""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq


def _rows(b: float, length: float, bending: float, k_end: float | None) -> np.ndarray:
    """The end conditions on (C1, C2, C3, C4) at wavenumber b (1/m)."""
    def value(x):
        return [np.cosh(b * x), np.sinh(b * x), np.cos(b * x), np.sin(b * x)]

    def slope(x):
        return [b * np.sinh(b * x), b * np.cosh(b * x), -b * np.sin(b * x), b * np.cos(b * x)]

    def curve(x):
        return [b * b * np.cosh(b * x), b * b * np.sinh(b * x), -b * b * np.cos(b * x),
                -b * b * np.sin(b * x)]

    rows = [value(0.0), value(length)]
    for x, sign in ((0.0, 1.0), (length, -1.0)):
        if k_end is None:
            rows.append(slope(x))
        else:                                   # EI w'' - sign k w' = 0
            rows.append([bending * c - sign * k_end * s for c, s in zip(curve(x), slope(x))])
    return np.array(rows)


def steady_loads(omega: float, level: float, length: float, linear_mass: float,
                 bending: float, k_end: float | None) -> tuple[float, float, float]:
    """(|w(l/2)| (m), |EI w_xx(0)| (N m), |EI w_xxx(0)| (N)) of the steady state at omega
    (rad/s) under a base acceleration of amplitude `level` (m/s^2)."""
    b = (linear_mass * omega * omega / bending) ** 0.25
    particular = level / omega ** 2
    c = np.linalg.solve(_rows(b, length, bending, k_end),
                        np.array([-particular, -particular, 0.0, 0.0]))
    half = b * length / 2
    mid = (c[0] * np.cosh(half) + c[1] * np.sinh(half) + c[2] * np.cos(half)
           + c[3] * np.sin(half) + particular)
    return (abs(mid), abs(bending * b * b * (c[0] - c[2])),
            abs(bending * b ** 3 * (c[1] - c[3])))


def first_frequency(length: float, linear_mass: float, bending: float,
                    k_end: float | None) -> float:
    """The first natural angular frequency (rad/s): the smallest b l in (2, 5) where the end
    conditions are singular (a sign change of their determinant, then brentq)."""
    def det(bl: float) -> float:
        return float(np.linalg.det(_rows(bl / length, length, bending, k_end)))

    grid = np.linspace(2.0, 5.0, 3001)
    values = [det(x) for x in grid]
    for x0, x1, d0, d1 in zip(grid[:-1], grid[1:], values[:-1], values[1:]):
        if d0 * d1 < 0.0:
            bl = brentq(det, x0, x1, xtol=1e-14)
            return (bl / length) ** 2 * np.sqrt(bending / linear_mass)
    raise RuntimeError("no first eigenvalue in 2 < b l < 5")


BUNDLE_SCENE = """
name = "clamp-loads-exact"
[model]
kind = "transverse"
coefficients = "consistent"
[cable]
linear_mass = "53.4 g/m"
bending_rigidity = "0.31515 N m^2"
axial_rigidity = "660 kN"
diameter = "2.76395 mm"
damping_ratio = 0.005
[clamps]
axial_stiffness = 0.0
[base]
acceleration_g = 0.1
[metrics]
tail = 0.2
[initial]
displacement = 0.0
velocity = 0.0
[axes]
length = [0.3]
base_frequency_ratio = [0.3, 0.7, 1.4]
"""
"""The tool's scene of a linear span to hold against these closed forms: the built-in harness
scenes' bundle (rho A 53.4 g/m, EI 0.31515 N m^2), 0.3 m, sliding clamps (no stretching),
0.1 g, damping 0.005 (which moves the steady state by about 1e-4 at these ratios), each output
its peak over the last 20 % of the run."""
