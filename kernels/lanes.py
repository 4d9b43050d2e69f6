"""Lock-step SIMD driver: LANES trajectories advanced side by side in vector lanes.

Each lane is one trajectory with its own time, step size and accept/reject decision: SciPy
RK45's or DOP853's sequence of attempts (or the PI controller's), the trajectory module's
state machine.
These loops run across the lanes with straight-line arithmetic, so LLVM vectorises them:

- trajectory.next_attempts: the next step of every lane whose step needs no special care;
- `_attempt`: one Dormand-Prince attempt (six right-hand sides, stage sums, error norm);
  `_attempt8` its DOP853 counterpart (twelve right-hand sides; solver.method = "dop853").
  Their stages are written out from each method's tableau by kernels.stages (straight-line
  code; the scalar driver loops over the same tableau): there is no hand-written copy;
- `_pi_factors`: the PI controller's step-size factors (only when that controller is chosen);
- `_finish`: accept/reject and the step-size update of every lane, and the metrics of an
  ordinary accepted step;
- `_locate_extrema`: for the RK45 steps that hold an extremum of q, where it lies on the dense
  output (safeguarded Newton), run only when some lane has one. A DOP853 step that holds one is
  located by trajectory.record_step on DOP853's dense output (trajectory.interpolant: its own
  seventh-order interpolant below rtol 3e-6, whose three extra right-hand sides it computes for
  that lane alone; the quintic Hermite one above, and for a random record).

Whatever else is not ordinary (a lane's first or last step, a step near SciPy's minimum, the
extremum's bookkeeping, the tail's start, a time-series sample, a threshold crossing, a
divergence) goes to the scalar state machine (`trajectory.record_step`) for that lane alone, so
the metrics are the scalar driver's. A lane whose trajectory ends takes the next point of its
block at once.

No libm call may sit in those loops: cos(W t) is `vecmath.fast_cos` (Cody-Waite reduction and
fdlibm's kernels) and the controller's err^(-1/5) is `vecmath.inv_fifth_root` (range reduction
by powers of two and Newton's method), both to an ulp or two; the loops fuse multiply-adds
(`CONTRACT`), and the right-hand side uses each point's coefficients divided by -m (`_accel`)
rather than dividing by m. Results therefore equal the scalar driver's to round-off, not bit
for bit: to what a trajectory makes of round-off, which on strongly nonlinear points reaches
~1e-9 relative (tests/test_lanes.py measures it with a one-ulp change of q(0) in the scalar
driver).

A random base acceleration (kernels.excitation's record kind: `base` is the records) runs here
too, on stage chains of its own (`_chains`' kind r, written out from the tableau as
the others): each lane's record is read at the attempt's stage times before the attempt, in a
scalar loop (`_stage_reads`), and the chain's right-hand side (`_accel_read`) reads those
values from W, so the chain's loop across the lanes vectorises as the sine kinds' does. A
record's accepted step with anything to locate inside it (an extremum of q, the
tail's start, a divergence) goes to record_step as above; its ordinary steps get the
record's statistics in `_record_statistics`, on the lane's own accumulator: the record's
reads in a scalar loop, then the observers record_step calls (trajectory.observe_acceleration,
observe_random, observe_level_crossings: straight-line selects) in vector loops, and, with
DOP853, the spectra's samples (`_record_samples`: trajectory.take_hermite_samples, as
record_step takes them), so the same bits as the scalar path.

A sine sweep (`solve_swept_block`) runs on the record kind's chains too (`reads_switch`): each
lane's a_b at its attempt's stage times is written before the attempt from its step's anchor
(`_read_sweeps`: excitation.sweep_state lane by lane, then the anchor's sine and every stage in
a loop across the lanes), each lane ends with its own sweep (`_point_settings`), and its
point's peak frequency and envelope are transverse.swept_outputs' where it ends (`_end_point`).
"""

import math

import numba as nb
import numpy as np
from numba.core import types
from numba.extending import overload

from . import dop853
from . import excitation as ex
from . import metrics as mt
from . import stages
from . import trajectory as tj
from .dopri5 import (DENSE_TERMS, EXTREMUM_RESIDUAL, QUARTIC_TERMS, A, B, C, E, MAX_FACTOR,
                     MIN_FACTOR, MIN_RTOL, N_STAGES, P, RHS_PER_ATTEMPT, SAFETY, pi_log2_err,
                     pi_step_factor)
from .flags import CONTRACT
from .layout import N_LEVELS, RTOL, SAMPLE_DT, T_END, TOL, WANT_SETTLING
from .oscillator import (BOUND, EXCITATION, N_PARAMS, acceleration, base_acceleration, prepare,
                         record_stages, shaken)
from .transverse import classify, reject_point, swept_outputs, valid
from .vecmath import FAST_TRIG_BELOW, fast_sin_cos, inv_fifth_root

LANES = 16             # trajectories per lock-step group (a multiple of the SIMD width)
SIMD = 4                # doubles per vector register the loops are rounded to (AVX2)

# The lanes' working memory is one flat array W, row r of lane j at W[r * LANES + j]: one
# underlying object with constant offsets between rows, so LLVM proves the rows independent and
# vectorises across lanes with no run-time alias checks. Rows 0 .. tj.N_SLOTS - 1 are the
# trajectory's accumulator slots (so W[j::LANES] is lane j's accumulator for the scalar
# state machine), then the parameter row (oscillator columns), then the attempt's work rows.
W_P = tj.SCALAR_SLOTS             # parameter column c at row W_P + c (the oscillator's
                                  # coefficients divided by -m: see `_load_lane`)
W_H = W_P + N_PARAMS              # signed step of the attempt (s); 0 for an idle lane
W_K = W_H + 1                     # stage s, component c at row W_K + 2 s + c (s >= 1)
W_QN = W_K + 2 * (N_STAGES + 1)   # fifth-order q (m)
W_VN = W_QN + 1                   # fifth-order q' (m/s)
W_ERR = W_QN + 2                  # SciPy's error norm
W_FLAG = W_QN + 3                 # NEEDS_SCALAR or HAS_EXTREMUM: the scalar state machine's turn
W_XE = W_QN + 4                   # the accepted step's extremum of q: x = (t - t_old)/h, or -1
W_QE = W_QN + 5                   # q there (m)
W_FACTOR = W_QN + 6               # the PI controller's step-size factor for the attempt
W_AB = W_QN + 7                   # base excitation a_b(t + h) at the attempt's end (m/s^2)
W_K8 = W_QN + 8                   # DOP853's stage s = 1..11, component c: W_K8 + 2 (s - 1) + c
W_START = W_K8 + 2 * (dop853.N_STAGES - 1)   # a record's attempt starts at (t s, q m, q' m/s,
                                             # q'' m/s^2) in rows W_START + 0..3 (`_keep_start`)
W_A_MID = W_START + 4   # a record's a_b at an ordinary step's middle (m/s^2; `_record_reads`)
W_A_OLD = W_START + 5   # q'' + a_b at its start where no step-end sample holds it (m/s^2)
W_AB_STAGES = W_START + 6   # a record's a_b (m/s^2) at the attempt's stage s = 1 .. n (the
                            # last at t + h) in row W_AB_STAGES + s - 1, read before the
                            # attempt (`_stage_reads`)
W_B1 = W_AB_STAGES + dop853.N_STAGES   # a record's integrals of a_b and a_b^2 over an ordinary
W_B2 = W_B1 + 1                         # step (m/s, m^2/s^3; `_record_reads`)
W_ANCHOR = W_B2 + 1     # a sweep's state at the attempt's start, excitation.sweep_state's five
                        # values in rows W_ANCHOR + 0..4 (`_read_sweeps`)
W_ROWS = W_ANCHOR + 5

# W_FLAG values.
ORDINARY = 0.0        # nothing for the scalar state machine to do
NEEDS_SCALAR = 1.0    # this lane's step or metrics need the scalar state machine
HAS_EXTREMUM = 2.0    # as NEEDS_SCALAR, and the step holds an extremum of q for `_locate_extrema`

_P_COLUMNS = tuple(tuple(float(row[c]) for row in P) for c in range(4))   # P[:, c]

# Controller: below this error the accepted factor is MAX_FACTOR, SAFETY err^(-1/5) >= 10
# (RK45), SAFETY err^(-1/8) >= 10 (DOP853).
_ERR_MAX_FACTOR = (SAFETY / MAX_FACTOR) ** 5
_ERR_MAX_FACTOR_8 = (SAFETY / MAX_FACTOR) ** 8
@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _step_factor(err, rejected_before, eighth):
    """dopri5.step_factor across lanes: RK45's (eighth None; err^(-1/5) by
    `vecmath.inv_fifth_root`) or DOP853's (eighth True; err^(-1/8) as three square roots)."""
    if eighth is None:
        root = inv_fifth_root(min(max(err, 1e-9), 1e9))
        err_max_factor = _ERR_MAX_FACTOR
    else:
        root = 1.0 / math.sqrt(math.sqrt(math.sqrt(min(max(err, 1e-18), 1e18))))
        err_max_factor = _ERR_MAX_FACTOR_8
    accept = min(MAX_FACTOR, SAFETY * root)
    accept = MAX_FACTOR if err < err_max_factor else accept
    accept = min(1.0, accept) if rejected_before else accept
    reject = SAFETY * root
    reject = reject if reject > MIN_FACTOR else MIN_FACTOR
    reject = MIN_FACTOR if err > 1e9 else reject
    reject = MIN_FACTOR if err != err else reject
    return accept if err < 1.0 else reject


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _accel(W, j, t, q, v, parametric, base):
    """q'' (m/s^2) of lane j at (t, q, v): the System's one right-hand side
    (oscillator.acceleration) on the lane's prepared row, with vecmath's cos and sin."""
    return acceleration(t, q, v, W, W_P * LANES + j, LANES, True, parametric, base)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _accel_read(W, j, t, q, v, parametric, base, stage):
    """q'' (m/s^2) of lane j at (t, q, v) under a random record, its a_b at the attempt's
    stage `stage` read from row W_AB_STAGES + stage - 1 (`_stage_reads`): the System's
    right-hand side without the base term, then that term (oscillator.shaken, as
    `acceleration` adds it), so the chain's loop across the lanes has no record read in it
    and vectorises."""
    L = LANES
    return shaken(acceleration(t, q, v, W, W_P * L + j, L, True, parametric, None), W,
                  W_P * L + j, L, W[(W_AB_STAGES + stage - 1) * L + j])


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _read_stages(W, n_run, eighth, swept, base):
    """Each lane's a_b (m/s^2) at its attempt's stage times t + C[s] h, s = 1 .. n - 1, and at
    t + h (rows W_AB_STAGES ..; `_accel_read`): a random record's reads (swept: unused, the
    sine kinds' `_read_sweeps` takes it), before the attempt, so that its chain's loop has
    none and vectorises. The reads stay a scalar loop, lane by
    lane (oscillator.record_stages reads a lane's columns once for its stages): LLVM will not
    vectorise a gather from the records beside a store into W, which it cannot prove apart."""
    L = LANES
    nodes = dop853.C if eighth is not None else C
    for j in range(n_run):       # f(t + h, y_new): both methods' last stage is at t + h
        record_stages(W[tj.T * L + j], W[W_H * L + j], nodes, W, W_P * L + j, L, base, W,
                      W_AB_STAGES * L + j, L)


_IDLE = (0.0, 0.0, 0.0, 0.0, 0.0)     # an idle lane's sweep state (`_read_sweeps`)


# excitation.anchored as a function of its own that LLVM inlines where it is called (Numba's
# own inlining copied its IR into each of DOP853's twelve stage writes: 8 s of compile)
_anchored = nb.njit(nogil=True, error_model="numpy", _nrt=False,
                    forceinline=True)(ex.anchored.py_func)   # not cached: excitation.anchored's
                                                             # own entries share its cache key


def _anchored_stages(nodes, name):
    """A function (W, j, anchor, h, lam), inlined by LLVM, that writes lane j's a_b (m/s^2) at
    t + nodes[i] h, i = 1 .. len(nodes) - 1, and at t + h into rows W_AB_STAGES .. from its
    step's anchor (excitation.anchored): one statement a stage, written out from the nodes, so
    that each store has a constant row and the loop across the lanes that calls it
    vectorises (a loop over the stages inside it stops LLVM vectorising)."""
    times = [repr(float(c)) for c in nodes[1:]] + ["1.0"]
    source = f"def {name}(W, j, anchor, h, lam):\n" + "".join(
        f"    W[{W_AB_STAGES + i} * {LANES} + j] = anchored(anchor, {c} * h, lam)\n"
        for i, c in enumerate(times))
    namespace = {"anchored": _anchored}
    exec(compile(source, f"<anchored stages {name}>", "exec"), namespace)
    return nb.njit(nogil=True, error_model="numpy", _nrt=False,
                   forceinline=True)(namespace[name])


_anchored5 = _anchored_stages(C, "anchored_rk45")
_anchored8 = _anchored_stages(dop853.C, "anchored_dop853")


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _read_sweeps(W, n_run, eighth, swept, base):
    """With a swept sine (`swept` True), each running lane's a_b (m/s^2) at its attempt's stage
    times and at t + h into rows W_AB_STAGES .., so that the record kind's chains
    (`_accel_read`) take them; a fixed frequency reads nothing (its chains evaluate the vector
    sine). The scalar step's reads (excitation.sine_at_nodes) to round-off: each lane's sweep
    state at its step's start (excitation.sweep_state: libm's expm1 and exp and the level
    table's search, a scalar loop), then, in a loop across the lanes that LLVM vectorises, the
    anchor's sine and cosine of the phase (vecmath.fast_sin_cos) and every stage from it
    (excitation.anchored), then, in the lanes whose anchor does not hold or whose phase is past
    vecmath.FAST_TRIG_BELOW, the scalar step's own reads."""
    if swept is None:
        return
    L = LANES
    nodes = dop853.C if eighth is not None else C
    block = (W_P + EXCITATION) * L
    for j in range(n_run):
        h = W[W_H * L + j]
        state = ex.sweep_state(W[tj.T * L + j], h, W, block + j, L) if h > 0.0 else _IDLE
        W[W_ANCHOR * L + j] = state[0]
        W[(W_ANCHOR + 1) * L + j] = state[1]
        W[(W_ANCHOR + 2) * L + j] = state[2]
        W[(W_ANCHOR + 3) * L + j] = state[3]
        W[(W_ANCHOR + 4) * L + j] = state[4]
    for j in range(n_run):
        sin0, cos0 = fast_sin_cos(W[(W_ANCHOR + 1) * L + j])
        anchor = (W[W_ANCHOR * L + j], sin0, cos0, W[(W_ANCHOR + 2) * L + j],
                  W[(W_ANCHOR + 3) * L + j], W[(W_ANCHOR + 4) * L + j])
        h = W[W_H * L + j]
        lam = W[block + ex.RATE * L + j]
        if eighth is None:
            _anchored5(W, j, anchor, h, lam)
        else:
            _anchored8(W, j, anchor, h, lam)
    for j in range(n_run):
        held = (W[W_ANCHOR * L + j] != 0.0) & (abs(W[(W_ANCHOR + 1) * L + j]) < FAST_TRIG_BELOW)
        if not held and W[W_H * L + j] > 0.0:
            ex.sine_at_nodes(W[tj.T * L + j], W[W_H * L + j], nodes, W, block + j, L, W,
                             W_AB_STAGES * L + j, L)


# a sweep's reads for the sine kinds, a record's for the record kind
_stage_reads = ex.by_kind(_read_sweeps, _read_stages)


def reads_switch(swept, base):
    """None, or True where the attempts take each stage's a_b from rows W_AB_STAGES ..
    (`_stage_reads`): a random record (`base` an array) or a swept sine (`swept` True). A
    switch whose `is None` branches Numba prunes before it inlines (a branch on
    `excitation.is_record(base)` is pruned only after, so both sides' inlined code would be
    copied and typed)."""
    raise TypeError("kernels.lanes.reads_switch runs only in compiled code")


@overload(reads_switch, inline="always")
def _reads_switch(swept, base):
    if isinstance(base, types.Array) or not isinstance(swept, types.NoneType):
        return lambda swept, base: True
    return lambda swept, base: None


# Each method's stages, written out from its tableau (kernels.stages): straight-line code in
# the tableau's order, so the loops across the lanes stay vectorised. RK45 sums every entry
# of its tableau; DOP853 leaves out the zeros of its sparse one. One chain per combination of
# the System's optional terms (suffix p: parametric, b: a sine base excitation, r: a random
# record: the right-hand side `_accel_read`, which takes the stage's number and reads the
# stage's a_b from W), its right-hand side written out for those terms alone; `_chains`
# makes them one function that the attempts call, which inlines only the chain of the
# caller's switches (each copy costs compile time).
_KINDS = (({"parametric": None, "base": None}, ""), ({"parametric": True, "base": None}, "_p"),
          ({"parametric": None, "base": True}, "_b"), ({"parametric": True, "base": True}, "_pb"),
          ({"parametric": None}, "_r"), ({"parametric": True}, "_pr"))


def _chains(A, B, C, sums, skip_zeros, name):
    """The stage chains of tableau (A, B, C) (`stages.make_chain`), one a kind of _KINDS, as
    one function for compiled code, chain(W, j, parametric, base, record): the stages of lane
    j's attempt from its t, q, v, h, f(t, y) in W, by the chain of the switches' types as its
    caller compiles (parametric, base: None where the System has no such term; record True:
    base is a random record's array), inlined by LLVM (forceinline: the attempt's loop stays
    vectorised; Numba's own inlining of an overload typed the chain twice, 5 s more compile):
    so the caller copies that chain alone, as branches on the switches would only in the
    function that owns them."""
    chains = {suffix: stages.make_chain(A, B, C, _accel_read if "base" not in switches
                                        else _accel, sums, skip_zeros, f"{name}{suffix}",
                                        switches, stage_argument="base" not in switches)
              for switches, suffix in _KINDS}

    def chain(W, j, parametric, base, record):
        raise TypeError(f"kernels.lanes {name} runs only in compiled code")

    @overload(chain, prefer_literal=True, jit_options={"forceinline": True})
    def _choose(W, j, parametric, base, record):
        terms = ("" if isinstance(parametric, types.NoneType) else "p") + (
            "r" if not isinstance(record, types.NoneType)
            else "" if isinstance(base, types.NoneType) else "b")
        chosen = chains[f"_{terms}" if terms else ""]
        L = LANES

        def lane_chain(W, j, parametric, base, record):
            return chosen(W, j, W[tj.T * L + j], W[tj.Q * L + j], W[tj.V * L + j],
                          W[W_H * L + j], W[tj.FQ * L + j], W[tj.FV * L + j], parametric,
                          base)
        return lane_chain

    chain.__name__ = chain.__qualname__ = name
    chain.kinds = chains               # by suffix (benchmarks/fma_peak.py counts their flops)
    return chain


_chain5 = _chains(A, B, C, (E,), False, "rk45_chain")
_chain8 = _chains(dop853.A, dop853.B, dop853.C, (dop853.E5, dop853.E3), True, "dop853_chain")


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _attempt(W, rtol, n_run, parametric, base, record):
    """One Dormand-Prince attempt in every lane of W (record: `reads_switch`, True for the
    chains that read each stage's a_b from W: a random record's, a sweep's): the stages
    (`_chain5`, from dopri5.A, B, C), the fifth-order solution (W_QN, W_VN), the stage
    derivatives k1 .. k6 (k6 = f(t + h, y_new)) in W_K and SciPy's error norm from dopri5.E
    (W_ERR). One loop with a run-time trip
    count runs across the lanes with straight-line arithmetic, so LLVM vectorises it rather
    than unrolling it. Each lane's absolute tolerances are its accumulator's
    (trajectory.point_atol, set by trajectory.start). Lanes n_run and above are idle and skipped.
    """
    L = LANES
    for j in range(n_run):
        kq, kv, qn, vn, eq, ev = _chain5(W, j, parametric, base, record)
        t, q, v, h = W[tj.T * L + j], W[tj.Q * L + j], W[tj.V * L + j], W[W_H * L + j]
        rq = (eq * h) / (W[tj.ATOL_Q * L + j] + max(abs(q), abs(qn)) * rtol)
        rv = (ev * h) / (W[tj.ATOL_V * L + j] + max(abs(v), abs(vn)) * rtol)
        W[(W_K + 2) * L + j] = kq[1]
        W[(W_K + 3) * L + j] = kv[1]
        W[(W_K + 4) * L + j] = kq[2]
        W[(W_K + 5) * L + j] = kv[2]
        W[(W_K + 6) * L + j] = kq[3]
        W[(W_K + 7) * L + j] = kv[3]
        W[(W_K + 8) * L + j] = kq[4]
        W[(W_K + 9) * L + j] = kv[4]
        W[(W_K + 10) * L + j] = kq[5]
        W[(W_K + 11) * L + j] = kv[5]
        W[(W_K + 12) * L + j] = kq[6]
        W[(W_K + 13) * L + j] = kv[6]
        W[W_QN * L + j] = qn
        W[W_VN * L + j] = vn
        W[W_ERR * L + j] = math.sqrt(rq * rq + rv * rv) / math.sqrt(2.0)
        if record is not None:    # the last stage's own a_b
            W[W_AB * L + j] = W[(W_AB_STAGES + N_STAGES - 1) * L + j]
        elif base is not None:    # (the same arithmetic)
            W[W_AB * L + j] = base_acceleration(t + h, W, W_P * L + j, L, True, base)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _attempt8(W, rtol, n_run, parametric, base, record):
    """One DOP853 attempt in every lane of W (as `_attempt`, stages by `_chain8`): the
    eighth-order solution (W_QN, W_VN), f(t + h, y_new) in the rows of RK45's last stage
    (W_K + 12, W_K + 13), stages 1 .. 11 in W_K8 (the seventh-order dense output of a step
    that needs one, dop853.dense_output, is built from them by trajectory.record_step) and
    SciPy's DOP853 error norm from dop853.E5, E3 (W_ERR).
    """
    L = LANES
    for j in range(n_run):
        kq, kv, qn, vn, e5q, e5v, e3q, e3v = _chain8(W, j, parametric, base, record)
        t, q, v, h = W[tj.T * L + j], W[tj.Q * L + j], W[tj.V * L + j], W[W_H * L + j]
        sq = W[tj.ATOL_Q * L + j] + max(abs(q), abs(qn)) * rtol
        sv = W[tj.ATOL_V * L + j] + max(abs(v), abs(vn)) * rtol
        W[(W_K + 12) * L + j] = vn
        W[(W_K + 13) * L + j] = kv[dop853.N_STAGES]
        W[(W_K8 + 0) * L + j] = kq[1]
        W[(W_K8 + 1) * L + j] = kv[1]
        W[(W_K8 + 2) * L + j] = kq[2]
        W[(W_K8 + 3) * L + j] = kv[2]
        W[(W_K8 + 4) * L + j] = kq[3]
        W[(W_K8 + 5) * L + j] = kv[3]
        W[(W_K8 + 6) * L + j] = kq[4]
        W[(W_K8 + 7) * L + j] = kv[4]
        W[(W_K8 + 8) * L + j] = kq[5]
        W[(W_K8 + 9) * L + j] = kv[5]
        W[(W_K8 + 10) * L + j] = kq[6]
        W[(W_K8 + 11) * L + j] = kv[6]
        W[(W_K8 + 12) * L + j] = kq[7]
        W[(W_K8 + 13) * L + j] = kv[7]
        W[(W_K8 + 14) * L + j] = kq[8]
        W[(W_K8 + 15) * L + j] = kv[8]
        W[(W_K8 + 16) * L + j] = kq[9]
        W[(W_K8 + 17) * L + j] = kv[9]
        W[(W_K8 + 18) * L + j] = kq[10]
        W[(W_K8 + 19) * L + j] = kv[10]
        W[(W_K8 + 20) * L + j] = kq[11]
        W[(W_K8 + 21) * L + j] = kv[11]
        W[W_QN * L + j] = qn
        W[W_VN * L + j] = vn
        W[W_ERR * L + j] = dop853.combined_error_norm(e5q, e5v, e3q, e3v, h, sq, sv)
        if record is not None:
            W[W_AB * L + j] = W[(W_AB_STAGES + dop853.N_STAGES - 1) * L + j]
        elif base is not None:
            W[W_AB * L + j] = base_acceleration(t + h, W, W_P * L + j, L, True, base)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _pi_factors(W, n_run):
    """The PI controller's step-size factor for every lane's attempt (W_FACTOR), and the
    memory of an accepted attempt's error (LOG2_ERR_PREV). Its own loop: `_finish` stays as
    fast as with SciPy's controller when this one is not used."""
    L = LANES
    for j in range(n_run):
        err = W[W_ERR * L + j]
        memory = W[tj.LOG2_ERR_PREV * L + j]
        W[W_FACTOR * L + j] = pi_step_factor(err, memory, W[tj.REJECTED_NOW * L + j] != 0.0)
        remember = (W[W_H * L + j] > 0.0) & (err < 1.0)
        W[tj.LOG2_ERR_PREV * L + j] = pi_log2_err(err) if remember else memory


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _finish(W, settings, n_samples, n_run, pi, eighth, parametric, base):
    """trajectory.control across lanes (accept/reject, step-size update, counts), then for an
    ordinary accepted step the first metrics pass (threshold tol * peak around 0; the
    base-excitation metric is `_observe_acceleration`'s) and the move
    to the step's end. An accepted step with anything to locate on the dense output, or a
    divergence, is left for trajectory.record_step: W_FLAG = NEEDS_SCALAR, or HAS_EXTREMUM
    when it holds an extremum of q (`_locate_extrema` finds it first). The metrics of an
    ordinary step are the Observer's (trajectory.observe_step_end), as in the scalar driver.

    SciPy's controller is computed here when `pi` is None (RK45's, or DOP853's when `eighth` is
    True); otherwise the PI controller's factor comes from `_pi_factors`.
    Every value is loaded unconditionally at the top: a load under a condition would stop LLVM
    vectorising the loop. Returns how many lanes it flagged, how many of those HAS_EXTREMUM,
    and, with base excitation (`base`), how many ordinary steps end within two steps of the
    tail window or in it (the base-excitation metric needs those: `_observe_acceleration`).
    Compiled without reference counting (`_nrt=False`; nothing here allocates): W passed to the
    Observer as its arrays would otherwise cost atomic counter updates in the loop, which stop
    LLVM vectorising it.
    """
    L = LANES
    track = settings[WANT_SETTLING] != 0.0
    thr_rel = settings[TOL]
    dt_sample = settings[SAMPLE_DT]
    rhs_per_attempt = float(RHS_PER_ATTEMPT if eighth is None else dop853.RHS_PER_ATTEMPT)
    n_flagged = 0
    n_extrema = 0
    n_near = 0
    # a record's samples on DOP853's quintic Hermite are `_record_statistics`' (RK45's are its
    # quartic from the stages: record_step's)
    sampled_here = ex.is_record(base) & (eighth is not None)
    for j in range(n_run):
        t_tail = W[tj.T_TAIL * L + j]         # the lane's own tail window start
        h = W[W_H * L + j]
        active = h > 0.0
        err = W[W_ERR * L + j]
        accepted = err < 1.0
        q_old = W[tj.Q * L + j]
        v_old = W[tj.V * L + j]
        qn = W[W_QN * L + j]
        vn = W[W_VN * L + j]
        fv_new = W[(W_K + 13) * L + j]      # f(t_new, y_new), second component (FSAL)
        t_new = W[tj.T_NEW * L + j]
        peak = W[tj.PEAK * L + j]
        peak_new = max(peak, abs(qn))
        thr = thr_rel * peak_new
        extremum = ((v_old > 0.0) & (vn <= 0.0)) | ((v_old < 0.0) & (vn >= 0.0))
        bounded = (abs(qn) <= W[(W_P + BOUND) * L + j]) & (abs(vn) <= 1e308)
        straddles = (W[tj.T * L + j] < t_tail) & (t_tail <= t_new)
        sample = W[tj.SAMPLE * L + j]
        due = (sample < n_samples) & (sample * dt_sample <= t_new)
        crosses = track & (abs(qn) <= thr) & (thr < abs(q_old))
        event = active & accepted & (extremum | (not bounded) | straddles
                                     | (due & (not sampled_here)) | crosses)
        done = active & accepted & (not event)
        rejected_before = W[tj.REJECTED_NOW * L + j] != 0.0
        if pi is None:
            factor = _step_factor(err, rejected_before, eighth)
        else:
            factor = W[W_FACTOR * L + j]
        locate = extremum & bounded
        W[W_FLAG * L + j] = (HAS_EXTREMUM if locate else NEEDS_SCALAR) if event else ORDINARY
        n_flagged += 1 if event else 0
        n_extrema += 1 if event & locate else 0
        if base is not None:
            n_near += 1 if done & (t_new + 2.0 * h >= t_tail) else 0
        W[tj.RHS_EVALS * L + j] += rhs_per_attempt if active else 0.0
        W[tj.H_ABS * L + j] *= factor if active else 1.0
        W[tj.REJECTED_NOW * L + j] = (0.0 if accepted else 1.0) if active else (
            1.0 if rejected_before else 0.0)
        W[tj.REJECTED * L + j] += 1.0 if active & (not accepted) else 0.0
        W[tj.STEPS * L + j] += 1.0 if active & accepted else 0.0
        tj.observe_step_end(W, j, L, W, W_P * L + j, L, W[tj.T * L + j], h, t_new, qn, vn,
                            fv_new, t_tail, track, 0.0, 0.0, thr_rel, done, True, None)
        W[tj.T * L + j] = t_new if done else W[tj.T * L + j]
        W[tj.Q * L + j] = qn if done else q_old
        W[tj.V * L + j] = vn if done else v_old
        W[tj.FQ * L + j] = vn if done else W[tj.FQ * L + j]
        W[tj.FV * L + j] = fv_new if done else W[tj.FV * L + j]
    return n_flagged, n_extrema, n_near


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _observe_acceleration(W, settings, n_run):
    """trajectory.observe_acceleration for every lane whose attempt `_finish` accepted as an
    ordinary step (the flagged ones get it from record_step): the base-excitation metric, in
    a loop of its own so that `_finish` stays vectorised and scenes without base excitation
    do not pay for it. Returns how many lanes have an extremum to refine (ACC_TURN:
    trajectory.refine_marked_lanes)."""
    L = LANES
    n_turns = 0
    for j in range(n_run):
        done = ((W[W_H * L + j] > 0.0) & (W[W_ERR * L + j] < 1.0)
                & (W[W_FLAG * L + j] == ORDINARY))
        fv = W[tj.FV * L + j]
        turn = tj.observe_acceleration(W, j, L, W[tj.T * L + j], W[tj.Q * L + j],
                                       W[tj.V * L + j], fv, fv + W[W_AB * L + j],
                                       W[tj.T_TAIL * L + j], done)
        n_turns += 1 if turn else 0
    return n_turns


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _sine_acceleration(W, settings, n_run, n_near, series, point, Qc, base):
    """With a sine base excitation (`base` True), and ordinary steps near or in the tail
    window (n_near of them, `_finish`): `_observe_acceleration`, and the acceleration's peaks
    refined where it marked some (trajectory.refine_marked_lanes)."""
    if base is not None and n_near > 0:
        if _observe_acceleration(W, settings, n_run) > 0:
            tj.refine_marked_lanes(W, LANES, W, W_P * LANES, n_run)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _keep_start(W, n_run, base):
    """A record's attempts: each lane's state at the attempt's start (t, q, q', q'') into rows
    W_START + 0..3, for the statistics of an ordinary step (`_record_statistics`), which
    `_finish` moves to its end."""
    L = LANES
    for j in range(n_run):
        W[W_START * L + j] = W[tj.T * L + j]
        W[(W_START + 1) * L + j] = W[tj.Q * L + j]
        W[(W_START + 2) * L + j] = W[tj.V * L + j]
        W[(W_START + 3) * L + j] = W[tj.FV * L + j]


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False, inline="always")
def _ordinary(W, j):
    """Whether lane j's attempt was accepted as an ordinary step (`_finish` moved it)."""
    L = LANES
    return (W[W_H * L + j] > 0.0) & (W[W_ERR * L + j] < 1.0) & (W[W_FLAG * L + j] == ORDINARY)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _record_reads(W, n_run, base):
    """The record's values a record's ordinary steps in the statistics window need (a scalar
    loop: each lane reads its own record): a_b at the step's middle into W_A_MID, the
    integrals of a_b and a_b^2 over the step into W_B1, W_B2 (trajectory.step_integrals), and
    q'' + a_b at its start into W_A_OLD where the step-end samples will not hold it
    (trajectory.record_statistics' a_old: the step before was not sampled). Before
    `_record_sums`, which takes the step-end samples."""
    L = LANES
    for j in range(n_run):
        t = W[W_START * L + j]
        if not (_ordinary(W, j) and t >= W[tj.T_TAIL * L + j]):
            continue
        o = W_P * L + j
        t_new = W[tj.T * L + j]
        W[W_A_MID * L + j] = base_acceleration(0.5 * (t + t_new), W, o, L, None, base)
        W[W_B1 * L + j], W[W_B2 * L + j] = tj.step_integrals(W, j, L, t, t_new, W, o, L, base)
        consecutive = W[tj.ACC_STEP * L + j] == W[tj.STEPS * L + j] - 1.0
        if not consecutive or math.isnan(W[(tj.ACC_SAMPLES + tj.S_A) * L + j]):
            W[W_A_OLD * L + j] = (W[(W_START + 3) * L + j]
                                  + base_acceleration(t, W, o, L, None, base))


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _record_sums(W, settings, n_run):
    """For every lane whose step is ordinary, the Observer's step-end samples of the absolute
    acceleration (trajectory.observe_acceleration, with the attempt's own a_b at its end,
    W_AB) and the record's statistics (trajectory.observe_random: the window, the quintic
    Hermite's squares, Simpson's rule, the zero crossings; observe_level_crossings in a loop of
    its own), in loops across the lanes that LLVM vectorises (both observers are straight-line
    selects; the record's reads are `_record_reads`'), with trajectory.record_statistics'
    inputs and without fused multiply-adds: the scalar path's bits."""
    L = LANES
    for j in range(n_run):
        take = _ordinary(W, j)
        t_new = W[tj.T * L + j]
        q_new = W[tj.Q * L + j]
        v_new = W[tj.V * L + j]
        fv_new = W[tj.FV * L + j]
        tj.observe_acceleration(W, j, L, t_new, q_new, v_new, fv_new,
                                fv_new + W[W_AB * L + j], W[tj.T_TAIL * L + j], take)
        t = W[W_START * L + j]
        q_old = W[(W_START + 1) * L + j]
        v_old = W[(W_START + 2) * L + j]
        fv_old = W[(W_START + 3) * L + j]
        a_new = W[(tj.ACC_SAMPLES + tj.S_A) * L + j]
        a_old = W[(tj.ACC_SAMPLES + tj.SAMPLE_SIZE + tj.S_A) * L + j]
        a_old = W[W_A_OLD * L + j] if a_old != a_old else a_old
        tj.observe_random(W, j, L, t, t_new, q_old, v_old, fv_old, q_new, v_new, fv_new,
                          a_old, a_new, W[W_A_MID * L + j], W[W_B1 * L + j],
                          W[W_B2 * L + j], False, 0.0, take)
    for k in range(int(settings[N_LEVELS])):
        for j in range(n_run):
            window = _ordinary(W, j) & (W[W_START * L + j] >= W[tj.T_TAIL * L + j])
            tj.observe_level_crossings(settings, W, j, L, k, W[(W_START + 1) * L + j], 0.0,
                                       W[tj.Q * L + j], False, window)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _record_samples(W, settings, n_run, series, point, Qc):
    """With DOP853, the time series' samples (for the spectra) inside a record's ordinary
    steps, on the quintic Hermite through both ends, as record_step takes them
    (trajectory.take_hermite_samples into series[point[j]]; Qc: scratch)."""
    L = LANES
    dt_sample = settings[SAMPLE_DT]
    for j in range(n_run):
        if _ordinary(W, j):
            tj.take_hermite_samples(W[j::L], series[point[j]], W[W_START * L + j],
                                    W[tj.T * L + j], W[W_H * L + j], W[(W_START + 1) * L + j],
                                    W[(W_START + 2) * L + j], W[(W_START + 3) * L + j],
                                    W[tj.Q * L + j], W[tj.V * L + j], W[tj.FV * L + j], Qc,
                                    dt_sample)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _record_statistics(W, settings, n_run, n_near, series, point, Qc, base):
    """A record's ordinary accepted steps (`_finish` moved them to their ends; the others go to
    trajectory.record_step): what record_step adds for a record's step with no extremum or
    tail start inside it, the record's reads (`_record_reads`), the step-end samples and
    statistics (`_record_sums`, a vector loop) and the spectra's samples (`_record_samples`)."""
    _record_reads(W, n_run, base)
    _record_sums(W, settings, n_run)
    if series.shape[1] > 0:
        _record_samples(W, settings, n_run, series, point, Qc)


# The ordinary steps' base-excitation metric and statistics, each compiled for its own kind
# only: a sine's acceleration peak, a record's statistics.
_ordinary_acceleration = ex.by_kind(_sine_acceleration, _record_statistics)
_keep_record_start = ex.by_kind(None, _keep_start)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _dense_row(k0, k1, k2, k3, k4, k5, k6, p):
    """Column c of K^T P for one component, p = _P_COLUMNS[c] (dopri5.dense_coefficients, same
    summation order)."""
    s = 0.0
    s += k0 * p[0]
    s += k1 * p[1]
    s += k2 * p[2]
    s += k3 * p[3]
    s += k4 * p[4]
    s += k5 * p[5]
    s += k6 * p[6]
    return s


NEWTON_ITERATIONS = 2       # safeguarded Newton steps for an extremum's position; where they
                            # leave it short of round-off, record_step's root finder takes over
                            # (a third step cost more than those rare fallbacks: 3 % slower)
NEWTON_RESIDUAL = EXTREMUM_RESIDUAL   # |q'(x)| / (|q'_old| + |q'_new|) at which the root is
                                      # at round-off (the scalar dopri5.dense_extremum's too)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _newton_extremum(v0, v1, h, c0, c1, c2, c3):
    """x in [0, 1] where q'(x) = v0 + h x (c0 + x (c1 + x (c2 + x c3))) vanishes (v0, v1: q' at
    the step's ends, of opposite signs), by NEWTON_ITERATIONS steps of Newton's method
    safeguarded by the sign bracket, from the linear guess; and whether the residual is down to
    round-off (NEWTON_RESIDUAL)."""
    positive = v0 > 0.0
    xa = 0.0
    xb = 1.0
    x = v0 / (v0 - v1) if v0 != v1 else 0.5
    x = x if (x >= 0.0) & (x <= 1.0) else 0.5
    for _ in range(NEWTON_ITERATIONS):
        g = v0 + h * (x * (c0 + x * (c1 + x * (c2 + x * c3))))
        dg = h * (c0 + x * (2.0 * c1 + x * (3.0 * c2 + x * (4.0 * c3))))
        same = (g > 0.0) == positive
        xa = x if same else xa
        xb = xb if same else x
        x_new = x - g / dg
        x_new = x_new if (xa <= x_new) & (x_new <= xb) else 0.5 * (xa + xb)
        x = x if g == 0.0 else x_new
    g = v0 + h * (x * (c0 + x * (c1 + x * (c2 + x * c3))))
    return x, abs(g) <= NEWTON_RESIDUAL * (abs(v0) + abs(v1))


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _locate_extrema(W, n_run):
    """For lanes flagged HAS_EXTREMUM after an RK45 attempt: the x in [0, 1] where the step's
    interpolated q' vanishes (W_XE, by `_newton_extremum`) and q there (W_QE). Where the
    residual is not down to round-off, W_XE = -1 and trajectory.record_step's bracketed root
    finder takes over. Other lanes compute too (straight-line code vectorises); their results
    are ignored.
    """
    L = LANES
    for j in range(n_run):
        want = W[W_FLAG * L + j] == HAS_EXTREMUM
        h = W[W_H * L + j]
        q0 = W[tj.Q * L + j]
        v0 = W[tj.V * L + j]
        v1 = W[W_VN * L + j]
        kq0 = W[tj.FQ * L + j]
        kv0 = W[tj.FV * L + j]
        kq1 = W[(W_K + 2) * L + j]
        kv1 = W[(W_K + 3) * L + j]
        kq2 = W[(W_K + 4) * L + j]
        kv2 = W[(W_K + 5) * L + j]
        kq3 = W[(W_K + 6) * L + j]
        kv3 = W[(W_K + 7) * L + j]
        kq4 = W[(W_K + 8) * L + j]
        kv4 = W[(W_K + 9) * L + j]
        kq5 = W[(W_K + 10) * L + j]
        kv5 = W[(W_K + 11) * L + j]
        kq6 = W[(W_K + 12) * L + j]
        kv6 = W[(W_K + 13) * L + j]
        cv0 = _dense_row(kv0, kv1, kv2, kv3, kv4, kv5, kv6, _P_COLUMNS[0])
        cv1 = _dense_row(kv0, kv1, kv2, kv3, kv4, kv5, kv6, _P_COLUMNS[1])
        cv2 = _dense_row(kv0, kv1, kv2, kv3, kv4, kv5, kv6, _P_COLUMNS[2])
        cv3 = _dense_row(kv0, kv1, kv2, kv3, kv4, kv5, kv6, _P_COLUMNS[3])
        x, converged = _newton_extremum(v0, v1, h, cv0, cv1, cv2, cv3)
        cq0 = _dense_row(kq0, kq1, kq2, kq3, kq4, kq5, kq6, _P_COLUMNS[0])
        cq1 = _dense_row(kq0, kq1, kq2, kq3, kq4, kq5, kq6, _P_COLUMNS[1])
        cq2 = _dense_row(kq0, kq1, kq2, kq3, kq4, kq5, kq6, _P_COLUMNS[2])
        cq3 = _dense_row(kq0, kq1, kq2, kq3, kq4, kq5, kq6, _P_COLUMNS[3])
        W[W_XE * L + j] = x if want & converged else -1.0
        W[W_QE * L + j] = q0 + h * (x * (cq0 + x * (cq1 + x * (cq2 + x * cq3))))


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _point_settings(settings, ends, point, swept):
    """The settings row `point` runs with: with a swept sine (`swept` True) a copy whose T_END
    is the point's own end time ends[point] (s; its sweep's), else settings themselves."""
    if swept is None:
        return settings
    own = settings.copy()
    own[T_END] = ends[point]
    return own


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _load_lane(params, settings, point, lane, W, states, reals, counts, series, envelope,
               ends, parametric, base, swept):
    """Give `lane` the trajectory of row `point`; an invalid row is answered at once.
    Returns False when the row needs no integration."""
    p = params[point]
    if not valid(p):
        reject_point(reals[point], counts[point], series[point])
        if swept is not None:
            for b in range(envelope.shape[1]):
                envelope[point, b] = math.nan
        states[point] = mt.INVALID_INPUT
        return False
    prepare(p, W, W_P * LANES + lane, LANES)
    tj.start(W, W_P * LANES + lane, LANES, _point_settings(settings, ends, point, swept),
             W[lane::LANES], series[point], parametric, base)
    return True


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _end_point(W, j, settings, ends, i, buf, states, reals, counts, series, envelope,
               parametric, base, swept):
    """Classify lane j's finished trajectory (point i) into the outputs, with a swept sine's
    peak frequency and envelope too (transverse.swept_outputs); the state written last."""
    L = LANES
    acc = W[j::L]
    tj.end_series(acc, series[i])
    own = _point_settings(settings, ends, i, swept)
    state = classify(W, W_P * L + j, L, own, acc, buf, reals[i], counts[i], parametric, base)
    if swept is not None:
        state = swept_outputs(W, (W_P + EXCITATION) * L + j, L, own, acc, buf, state,
                              reals[i], envelope[i])
    states[i] = state


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _record_lane(W, j, settings, K, Qc, buf, series, i, track, thr_rel, xe, parametric,
                 base, eighth):
    """trajectory.record_step for lane j (point i) after an accepted attempt. The lane's views of
    W and of the point's time-series row are taken here, where Numba keeps no reference counts
    (`_nrt=False`; nothing here allocates): taken in solve_block, each view cost two atomic
    counter updates per flagged lane."""
    L = LANES
    tj.record_step(W, W_P * L + j, L, settings, W[j::L], K, W[W_QN * L + j],
                   W[W_VN * L + j], W[W_H * L + j], Qc, buf, series[i], track,
                   0.0, 0.0, thr_rel, xe, W[W_QE * L + j], parametric, base, eighth)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def solve_block(params, settings, lo, hi, states, reals, counts, series, pi, eighth,
                parametric, base, halt):
    """Solve rows lo..hi-1 of `params` through LANES lock-step lanes: the interface and
    results (to round-off) of transverse.solve_block, several times faster per core.
    (`_drive` with no sweep.)"""
    _drive(params, settings, lo, hi, states, reals, counts, series, np.empty((0, 0)),
           np.empty(0), pi, eighth, parametric, base, None, halt)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def solve_swept_block(params, settings, lo, hi, states, reals, counts, series, envelope, ends,
                      pi, eighth, parametric, base, halt):
    """`solve_block` for a swept base frequency (settings[SWEPT] = 1; transverse's
    solve_swept_block on the lanes): envelope (n, n_bands), the response envelope (m;
    n_bands may be 0), and ends (n,), each point's end time (s; its sweep's). Each lane reads
    its sweep at its attempt's stage times before the attempt (`_read_sweeps`)."""
    _drive(params, settings, lo, hi, states, reals, counts, series, envelope, ends, pi, eighth,
           parametric, base, True, halt)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _drive(params, settings, lo, hi, states, reals, counts, series, envelope, ends, pi, eighth,
           parametric, base, swept, halt):
    """The lanes over rows lo..hi-1 (`solve_block`, `solve_swept_block`; swept None or True).

    `pi` picks the step-size controller and must match settings[CONTROLLER]: None for SciPy's,
    True for the PI controller; `eighth` the method, matching settings[METHOD]: None for RK45,
    True for DOP853 (SciPy's controller only). None is a type of its own to Numba, which
    prunes the branches on `pi is None` at compile time: each combination is its own
    specialisation, compiled without the others' code. `base` likewise: None, or True when
    settings[BASE] is 1 (oscillator's base-excitation switch), or the records of a random base
    acceleration (kernels.excitation's record kind: each lane reads its row's record in its
    stage chain; its ordinary steps' statistics are `_record_statistics`', the rest
    record_step's).

    halt (1,): once another thread sets halt[0] != 0 (an interrupt), the call returns after
    the attempt in hand, the rows in flight left unsolved (their `states` untouched; a lane's
    trajectory of several modes can last seconds, so waiting for them took up to 10 s). Each
    row's state is written after all its other outputs, so a watcher reading `states` sees a
    row's state only once the row is final.
    """
    L = LANES
    rtol = max(settings[RTOL], MIN_RTOL)
    track = settings[WANT_SETTLING] != 0.0
    thr_rel = settings[TOL]
    record = reads_switch(swept, base)  # None, or True: the attempts' stage reads (records, sweeps)
    n_samples = series.shape[1]
    W = np.zeros(W_ROWS * L)
    for j in range(L):
        W[tj.STATUS * L + j] = mt.DIVERGED         # idle until loaded
    bufs = [tj.new_buffer() for _ in range(L)]
    capacity = np.full(L, bufs[0].shape[0], np.int64)   # rows of bufs[j], read without the list:
                                                        # a list access costs two atomic updates
    point = np.full(L, -1, np.int64)
    K = np.empty((N_STAGES + 1 if eighth is None else dop853.N_STAGES_EXTENDED, 2))
    Qc = np.empty((2, QUARTIC_TERMS if eighth is None else DENSE_TERMS))   # RK45: its quartic
    next_point = lo
    n_run = min(L, hi - lo)   # lanes the vector loops cover: the active ones, rounded up to SIMD
                              # width (min() keeps it a run-time int: one compiled next_attempts)
    while True:
        if halt[0] != 0:
            return                # an interrupt: the rows in flight are left unsolved
        tj.next_attempts(W, L, W[W_H * L:(W_H + 1) * L], W[W_FLAG * L:(W_FLAG + 1) * L],
                         settings, n_run)
        top = 0
        for j in range(L):
            if j >= n_run or W[W_FLAG * L + j] != 0.0:
                acc = W[j::L]
                step = 0.0
                while True:
                    if point[j] >= 0:
                        step = tj.next_attempt(settings, acc)
                        if step > 0.0:
                            break
                        _end_point(W, j, settings, ends, point[j], bufs[j], states, reals,
                                   counts, series, envelope, parametric, base, swept)
                        point[j] = -1
                    if next_point >= hi:
                        break
                    if _load_lane(params, settings, next_point, j, W, states, reals, counts,
                                  series, envelope, ends, parametric, base, swept):
                        point[j] = next_point
                        bufs[j] = tj.new_buffer()
                        capacity[j] = bufs[j].shape[0]
                    next_point += 1
                W[W_H * L + j] = step
            if W[W_H * L + j] > 0.0:
                top = j + 1
        if top == 0:
            return
        n_run = min(L, (top + SIMD - 1) // SIMD * SIMD)
        if record is not None:
            _stage_reads(W, n_run, eighth, swept, base)
        if eighth is None:
            _attempt(W, rtol, n_run, parametric, base, record)
        else:
            _attempt8(W, rtol, n_run, parametric, base, record)
        if pi is not None:
            _pi_factors(W, n_run)
        _keep_record_start(W, n_run, base)
        n_flagged, n_extrema, n_near = _finish(W, settings, n_samples, n_run, pi, eighth,
                                               parametric, base)
        _ordinary_acceleration(W, settings, n_run, n_near, series, point, Qc, base)
        if n_flagged == 0:
            continue
        if n_extrema > 0 and eighth is None:
            _locate_extrema(W, n_run)
        for j in range(n_run):
            flag = W[W_FLAG * L + j]
            if flag == ORDINARY:
                continue
            i = point[j]
            K[0, 0] = W[tj.FQ * L + j]
            K[0, 1] = W[tj.FV * L + j]
            if eighth is None:
                for s in range(1, N_STAGES + 1):
                    K[s, 0] = W[(W_K + 2 * s) * L + j]
                    K[s, 1] = W[(W_K + 2 * s + 1) * L + j]
            else:
                for s in range(1, dop853.N_STAGES):
                    K[s, 0] = W[(W_K8 + 2 * (s - 1)) * L + j]
                    K[s, 1] = W[(W_K8 + 2 * s - 1) * L + j]
                K[dop853.N_STAGES, 0] = W[(W_K + 2 * N_STAGES) * L + j]
                K[dop853.N_STAGES, 1] = W[(W_K + 2 * N_STAGES + 1) * L + j]
            xe = W[W_XE * L + j] if (flag == HAS_EXTREMUM) & (eighth is None) else -1.0
            if W[tj.N_EXT * L + j] >= capacity[j]:
                bufs[j] = tj.with_room(bufs[j], W[j::L])
                capacity[j] = bufs[j].shape[0]
            _record_lane(W, j, settings, K, Qc, bufs[j], series, i, track, thr_rel, xe,
                         parametric, base, eighth)
