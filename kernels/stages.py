"""The lanes driver's stage chains, written out from a Runge-Kutta tableau at import time.

The scalar driver steps with one loop over the tableau (dopri5.explicit_rk_step). The lanes
driver cannot: a loop over the stages inside its loop across the lanes stops LLVM vectorising
that loop. It needs straight-line code, one statement per stage. Rather than a hand-written
copy of each method's stages, `chain_source` writes that code from the tableau (A, B, C) and
`make_chain` compiles it: an inline-always Numba function

    chain(W, j, t, q, v, h, k0q, k0v, parametric, base) -> (kq, kv, qn, vn, s0q, s0v, s1q, s1v, ...)

for the oscillator y = (q, q') (m, m/s) at time t (s), step h (s), with k0 = f(t, y)
(m/s, m/s^2) given. Stage s (1 .. n - 1) is

    q_s  = q + (k0q A[s][0] + k1q A[s][1] + ... + k(s-1)q A[s][s-1]) h
    ksq  = v + (k0v A[s][0] + ... + k(s-1)v A[s][s-1]) h
    ksv  = rhs(W, j, t + C[s] h, q_s, ksq, parametric, base)

then the solution qn = q + h (k0q B[0] + ...), vn likewise, and the last stage
knq = vn, knv = rhs(W, j, t + h, qn, vn, parametric, base): f at the step's end (FSAL). kq
and kv are the tuples (k0 .. kn) of both components (m/s and m/s^2); s_iq, s_iv are the sums
k0 w_i[0] + ... + kn w_i[n] of each weight vector w_i of `sums` (an error estimator's E, not
yet times h). Every sum runs over the stages in order, left to right; with skip_zeros the
terms whose tableau entry is exactly 0 are left out (a sparse tableau: DOP853's). `rhs` is the
driver's right-hand side (for the lanes, lanes._accel: lane j of the working memory W).

The source is generated and exec'd once per process, at import (microseconds; print it with
`chain_source`). A chain is never compiled on its own: Numba inlines it into its caller's IR
(inline="always"), with the right-hand sides, so the caller's loop is straight-line code,
exactly as if the chain were written out in it by hand, and the caller, an ordinary function
of a real module, keeps Numba's on-disk cache. No file is generated.
"""

from __future__ import annotations

from typing import Callable, Sequence

import numba as nb

CHAIN_ARGS = "W, j, t, q, v, h, k0q, k0v, parametric, base"


def _literal(value: float) -> str:
    """A float as Python source that reads back as the same double."""
    text = repr(float(value))
    return f"({text})" if text.startswith("-") else text


def _weighted(names: Sequence[str], values: Sequence[float], skip_zeros: bool) -> str:
    """'names[0] * values[0] + names[1] * values[1] + ...' over the entries kept."""
    return " + ".join(f"{name} * {_literal(value)}" for name, value in zip(names, values)
                      if not (skip_zeros and value == 0.0))


def chain_source(A: Sequence[Sequence[float]], B: Sequence[float], C: Sequence[float],
                 sums: Sequence[Sequence[float]] = (), skip_zeros: bool = False,
                 name: str = "chain") -> str:
    """Python source of the stage chain of the explicit tableau (A, B, C) (module docstring):
    a function `name`(CHAIN_ARGS) that calls `rhs`, with the tableau's entries written in as
    float literals (each reads back as the same double) and the weighted sums of `sums` (weight
    vectors of length len(B) + 1)."""
    n = len(B)
    if len(A) != n or len(C) != n or any(len(w) != n + 1 for w in sums):
        raise ValueError("tableau sizes disagree: A and C need len(B) rows, sums len(B) + 1")
    kq = [f"k{s}q" for s in range(n + 1)]
    kv = [f"k{s}v" for s in range(n + 1)]
    lines = [f"def {name}({CHAIN_ARGS}):"]
    for s in range(1, n):
        row = [float(A[s][i]) for i in range(s)]
        dq = _weighted(kq[:s], row, skip_zeros)
        dv = _weighted(kv[:s], row, skip_zeros)
        lines.append(f"    q{s} = q + ({dq}) * h" if dq else f"    q{s} = q")
        lines.append(f"    {kq[s]} = v + ({dv}) * h" if dv else f"    {kq[s]} = v")
        lines.append(f"    {kv[s]} = rhs(W, j, t + {_literal(C[s])} * h, q{s}, {kq[s]}, "
                     "parametric, base)")
    weights = [float(x) for x in B]
    sq = _weighted(kq[:n], weights, skip_zeros)
    sv = _weighted(kv[:n], weights, skip_zeros)
    lines.append(f"    qn = q + h * ({sq})" if sq else "    qn = q")
    lines.append(f"    vn = v + h * ({sv})" if sv else "    vn = v")
    lines.append(f"    {kq[n]} = vn")
    lines.append(f"    {kv[n]} = rhs(W, j, t + h, qn, vn, parametric, base)")
    results = [f"({', '.join(kq)})", f"({', '.join(kv)})", "qn", "vn"]
    for i, w in enumerate(sums):
        values = [float(x) for x in w]
        for k, c in ((kq, "q"), (kv, "v")):
            total = _weighted(k, values, skip_zeros)
            lines.append(f"    s{i}{c} = ({total})" if total else f"    s{i}{c} = 0.0")
            results.append(f"s{i}{c}")
    lines.append(f"    return {', '.join(results)}")
    return "\n".join(lines) + "\n"


def _inline_outside_chains(expr, caller_ir, callee_ir) -> bool:
    """Numba's inlining decision for a chain's right-hand side (a cost model): inline it into
    the function the chain is inlined into, not into the chain itself. Numba copies a callee's
    whole IR when it inlines it; a chain with its right-hand sides already inlined is large
    (the copies took seconds of compile time), without them it is a few hundred variables."""
    return not getattr(caller_ir.func_id.func, "stage_chain", False)


def make_chain(A: Sequence[Sequence[float]], B: Sequence[float], C: Sequence[float],
               rhs: Callable, sums: Sequence[Sequence[float]] = (), skip_zeros: bool = False,
               name: str = "chain") -> Callable:
    """The stage chain of (A, B, C) (`chain_source`) as an inline-always Numba function that
    calls `rhs` (a Numba function rhs(W, j, t, q, v, parametric, base) -> q'' in m/s^2)."""
    source = chain_source(A, B, C, sums, skip_zeros, name)
    namespace = {"rhs": nb.njit(nogil=True, error_model="numpy",
                                inline=_inline_outside_chains)(rhs.py_func)}
    exec(compile(source, f"<stage chain {name}>", "exec"), namespace)
    function = namespace[name]
    function.__doc__ = source
    function.stage_chain = True
    return nb.njit(nogil=True, error_model="numpy", inline="always")(function)
