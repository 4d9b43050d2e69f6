"""The modal oscillator of docs/model.md in general form (SI units).

    m q'' + c q' + (k0 + k1 cos W t) q + (g0 + g1 cos W t) q^3 + h q^5 = 0

q is the midspan deflection (m), t the time (s). A point's coefficients live in one row of a
float64 parameter array; the column of each is named below.

Q_SCALE and V_SCALE are the size of the point's response (sweep.models.state_scale): with
settings[ATOL_SCALE] > 0 the absolute tolerances are that fraction of rtol times these scales
(trajectory.point_atol), so a response and the same response scaled by any factor are
integrated alike. They must be > 0 then; with ATOL_SCALE = 0 they are not read.
"""

import math

import numba as nb

# Columns of a parameter row.
MASS = 0        # m   (kg-like: any consistent scaling of the equation; must be > 0)
DAMPING = 1     # c   (m's units / s)
K0 = 2          # k0  linear stiffness, mean part           (m's units / s^2)
K1 = 3          # k1  linear stiffness, cos(W t) part       (m's units / s^2)
G0 = 4          # g0  cubic stiffness, mean part            (m's units / (s^2 m^2))
G1 = 5          # g1  cubic stiffness, cos(W t) part        (m's units / (s^2 m^2))
H = 6           # h   quintic stiffness                     (m's units / (s^2 m^4))
OMEGA = 7       # W   load angular frequency                (rad/s)
Q0 = 8          # q(0)                                      (m)
V0 = 9          # q'(0)                                     (m/s)
BOUND = 10      # |q| beyond which the point is diverged    (m)
Q_SCALE = 11    # the point's displacement scale            (m)
V_SCALE = 12    # the point's velocity scale                (m/s)
N_PARAMS = 13

PARAM_NAMES = ("mass", "damping", "k0", "k1", "g0", "g1", "h", "omega", "q0", "v0", "bound",
               "q_scale", "v_scale")


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def acceleration(t, q, v, p):
    """q'' (m/s^2) at time t (s) for deflection q (m), velocity v (m/s), parameter row p."""
    cw = math.cos(p[OMEGA] * t)
    q2 = q * q
    force = (p[DAMPING] * v + (p[K0] + p[K1] * cw) * q
             + (p[G0] + p[G1] * cw) * q * q2 + p[H] * q * q2 * q2)
    return -force / p[MASS]


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def stiffness(t, q, p):
    """d(restoring force)/dq (N/m per unit modal mass m) at time t (s) and deflection q (m):
    k0 + k1 cos Wt + 3 (g0 + g1 cos Wt) q^2 + 5 h q^4, the derivative of `acceleration`'s
    force at zero velocity."""
    cw = math.cos(p[OMEGA] * t)
    q2 = q * q
    return p[K0] + p[K1] * cw + 3.0 * (p[G0] + p[G1] * cw) * q2 + 5.0 * p[H] * q2 * q2
