"""The transverse System: the modal oscillator of docs/model.md, written once (SI units).

    m q'' + c q' + (k0 + k1 cos(W t + phi_W)) q + (g0 + g1 cos(W t + phi_W)) q^3 + h q^5
        = -m G a_b(t),    a_b(t) = A sin(w_b t + phi_b)

(a_b(t) as written for a fixed sine; a swept sine, a level table or a random record in
general: kernels.excitation)

q is the midspan deflection relative to the clamps (m), t the time (s), a_b the transverse
acceleration of both clamps (base excitation, m/s^2) and G its participation factor (4/pi for
the first mode). A point's coefficients live in one row of a float64 parameter array; the
column of each is named below.

Every driver reads a row through the same accessor, p[o + column * s]: a row of its own
(o = 0, s = 1: the scalar driver), or one lane of the lock-step driver's working memory (o the
lane's first parameter slot, s the number of lanes). Before integrating, `prepare` writes the
row in the form `acceleration` reads: the force coefficients divided by -m, so the right-hand
side is a sum of products with no division. Both drivers, the initial step, the metrics
(the Observer, `kernels.trajectory`) and the at-rest test call `acceleration`; the SciPy
references of the benchmarks call its pure-Python form (`acceleration.py_func`). There is no
other copy.

Compile-time switches (None or True: Numba compiles one specialisation per choice, and the
branches not taken are not in it):
    fast   None: libm's cos and sin (the scalar driver, SciPy's arithmetic);
           True: vecmath's vectorisable fast_cos and fast_sin (the lanes driver)
    the optional terms of the equation a scene has (`terms_of`), two separate arguments:
    parametric  the load's cos(W t) parts k1, g1 (None: every row of the scene has k1 = g1 = 0,
                a constant or zero load, and cos is not evaluated; the result is the same to
                the last bit)
    base        the base excitation -G a_b(t), and the absolute acceleration metric
                (kernels.trajectory.observe_acceleration)
Separate None-or-True arguments, not a tuple: Numba prunes a branch on `arg is None` even where
the function is inlined into a caller, so a term a scene does not have is neither typed nor
compiled there (a tuple item's branch would be typed at every inlined copy: seconds of compile
time in the stage chains).

Inlined or called: `acceleration` and `base_acceleration` are inlined where `fast` is True (the
lanes' vector loops, where a call would stop LLVM vectorising; kernels.stages.InlineWhereTrue)
and compiled once and called elsewhere (the scalar paths, where inlining bought nothing but
compile time). The lanes' stage chains do not inline them through Numba: kernels.stages
writes this function's body, and its callees', into their right-hand side's source
(`stages.written_out`), one specialisation per combination of the terms.

Q_SCALE and V_SCALE are the size of the point's response (sweep.models.state_scale): with
settings[ATOL_SCALE] > 0 the absolute tolerances are that fraction of rtol times these scales
(trajectory.point_atol), so a response and the same response scaled by any factor are
integrated alike. They must be > 0 then; with ATOL_SCALE = 0 they are not read.
"""

import math

import numba as nb

from . import excitation as ex
from .flags import CONTRACT
from .stages import InlineWhereTrue
from .vecmath import fast_cos, fast_sin

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
PARTICIPATION = 13  # G    participation factor of the mode (1)
LOAD_PHASE = 14     # phi_W load phase at t = 0 (rad; a stepped sweep's carried phase, else 0)
EXCITATION = 15     # the base excitation block (kernels.excitation: a_b(t), fixed or swept)
BASE_ACCEL = EXCITATION + ex.ACCEL  # A    base acceleration amplitude      (m/s^2 peak)
BASE_OMEGA = EXCITATION + ex.OMEGA  # w_b  base angular frequency (a sweep's start, rad/s)
BASE_PHASE = EXCITATION + ex.PHASE  # phi_b base excitation phase at t = 0   (rad)
N_PARAMS = EXCITATION + ex.SIZE

PARAM_NAMES = ("mass", "damping", "k0", "k1", "g0", "g1", "h", "omega", "q0", "v0", "bound",
               "q_scale", "v_scale", "participation", "load_phase") + ex.NAMES

# The columns `prepare` divides by -m.
FORCE_COLUMNS = (DAMPING, K0, K1, G0, G1, H)



def terms_of(parametric: bool, base: bool) -> tuple:
    """The (parametric, base) switches of a scene: whether any row has a time-varying
    stiffness (k1 or g1 not 0) and whether the scene has base excitation
    (settings[layout.BASE])."""
    return (True if parametric else None, True if base else None)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def prepare(row, p, o, s):
    """Write parameter row `row` (a point's raw row, columns above) to p[o + column * s] in the
    form `acceleration` reads: the columns of FORCE_COLUMNS divided by -m (one division per
    point), the others as they are. The row must be valid (m > 0)."""
    for c in range(N_PARAMS):
        p[o + c * s] = row[c]
    minus_inv_m = -1.0 / row[MASS]
    for c in FORCE_COLUMNS:
        p[o + c * s] = row[c] * minus_inv_m


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _excitation_signal(t, p, o, s, base):
    """kernels.excitation's a_b(t) of the row's block (a sine kind, fixed or swept, or, where
    `base` is an array of records, the record kind: `excitation.signal`): a call of its own, so
    that inlining `base_acceleration` into a vector loop copies no more than its sine; a
    record's read inlined into it (`excitation.inlined_signal`)."""
    return ex.inlined_signal(t, p, o + EXCITATION * s, s, base)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False, forceinline=True)
def record_stages(t, h, nodes, p, o, s, records, out, out_o, out_s):
    """A random record's a_b (m/s^2) at a step's stage times t + nodes[i] h (s) and at t + h
    for the row at p[o + column * s] (kernels.excitation.record_at_nodes on its excitation
    block): the same values as `base_acceleration` at each."""
    ex.record_at_nodes(t, h, nodes, p, o + EXCITATION * s, s, records, out, out_o, out_s)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=False, inline=InlineWhereTrue(4),
         _nrt=False)
def base_acceleration(t, p, o, s, fast, base):
    """a_b(t) (m/s^2): the clamps' acceleration at time t (s). fast None: the excitation
    block's own (kernels.excitation: fixed or swept frequency, constant or tabled level, or a
    random record where `base` is the records); fast True (the lanes, which take
    fixed-frequency, fixed-level sine rows and records): A sin(w_b t + phi_b) with vecmath's
    fast_sin, or the record as above."""
    if fast is None or ex.is_record(base):
        return _excitation_signal(t, p, o, s, base)
    x = p[o + BASE_OMEGA * s] * t + p[o + BASE_PHASE * s]
    return p[o + BASE_ACCEL * s] * fast_sin(x)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline=InlineWhereTrue(6), _nrt=False)
def acceleration(t, q, v, p, o, s, fast, parametric, base):
    """q'' (m/s^2) at time t (s) for deflection q (m) and velocity v (m/s), from a prepared
    row (`prepare`) at p[o + column * s]; `fast`, `parametric`, `base`: the module's switches.

    The velocity term is added after the stiffness terms, so in a chain of stages each waits
    on the previous one for two fused multiply-adds rather than for the whole sum."""
    q2 = q * q
    if parametric is not None:
        x = p[o + OMEGA * s] * t + p[o + LOAD_PHASE * s]
        if fast is None:
            cw = math.cos(x)
        else:
            cw = fast_cos(x)
        a = ((p[o + K0 * s] + p[o + K1 * s] * cw) * q
             + (p[o + G0 * s] + p[o + G1 * s] * cw) * q * q2
             + p[o + H * s] * q * q2 * q2)
    else:
        a = p[o + K0 * s] * q + p[o + G0 * s] * q * q2 + p[o + H * s] * q * q2 * q2
    a = a + p[o + DAMPING * s] * v
    if base is not None:
        a = shaken(a, p, o, s, base_acceleration(t, p, o, s, fast, base))
    return a


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def shaken(a, p, o, s, a_b):
    """q'' (m/s^2) of the span with no base excitation, a (m/s^2), with the clamps'
    acceleration a_b (m/s^2) added as the right-hand side's -G a_b (G: the mode's
    participation factor): `acceleration`'s base term, and the lanes' where a_b was read
    before the stages (kernels.lanes._accel_read)."""
    return a - p[o + PARTICIPATION * s] * a_b


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _sine_anchor(t, h, p, o, s, base):
    """A sine row's `excitation.sweep_anchor` for a step of h (s) from t (s); none without base
    excitation."""
    if base is None:
        return (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    return ex.sweep_anchor(t, h, p, o + EXCITATION * s, s)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _no_anchor(t, h, p, o, s, base):
    """A record's steps read their stages each (`acceleration`)."""
    return (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


step_anchor = ex.by_kind(_sine_anchor, _no_anchor)
step_anchor.__doc__ = """step_anchor(t, h, p, o, s, base): what a step of h (s) from t (s) of
the row at p[o + column * s] reads its stages' a_b from (`stage_acceleration`): a sweep's
`excitation.sweep_anchor`, else zeros (each stage reads `acceleration`)."""


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _sine_stage(t, tau, q, v, p, o, s, anchor, parametric, base):
    """`stage_acceleration` of a sine row (or one without base excitation)."""
    a = acceleration(t + tau, q, v, p, o, s, None, parametric, None)
    if base is None:
        return a
    return shaken(a, p, o, s, ex.stage_signal(t, tau, anchor, p, o + EXCITATION * s, s))


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _record_stage(t, tau, q, v, p, o, s, anchor, parametric, base):
    """`stage_acceleration` of a record's row: `acceleration` at t + tau."""
    return acceleration(t + tau, q, v, p, o, s, None, parametric, base)


stage_acceleration = ex.by_kind(_sine_stage, _record_stage)
stage_acceleration.__doc__ = """stage_acceleration(t, tau, q, v, p, o, s, anchor, parametric,
base): q'' (m/s^2) at the stage time t + tau (s) of a step from t whose `step_anchor` is
`anchor`: a sweep's a_b from the anchor where it holds (two short series and one reduced sine
and cosine instead of expm1, exp and sin), else `acceleration` at t + tau, the same bits as
before."""


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def stiffness(t, q, p, o, s):
    """d(restoring force)/dq per unit mass m (1/s^2) at time t (s) and deflection q (m), from a
    prepared row: (k0 + k1 cos Wt + 3 (g0 + g1 cos Wt) q^2 + 5 h q^4) / m, the derivative of
    -`acceleration` with respect to q."""
    cw = math.cos(p[o + OMEGA * s] * t + p[o + LOAD_PHASE * s])
    q2 = q * q
    return -(p[o + K0 * s] + p[o + K1 * s] * cw + 3.0 * (p[o + G0 * s] + p[o + G1 * s] * cw) * q2
             + 5.0 * p[o + H * s] * q2 * q2)
