"""benchmarks/fma_peak.py's flop counter, checked against counts worked out by hand from the
tableaux (the share of the FMA peak in RESULTS.md rests on it)."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import fma_peak  # noqa: E402
from sweep.kernels import dop853, dopri5, stages  # noqa: E402


def test_index_arithmetic_and_comparisons_are_not_flops():
    source = ("def f(W, j, q, v):\n"
              "    o = 31 * 16 + j\n"
              "    a = W[o + 2 * 16] * q + 1.0\n"
              "    b = a if (a == 1.0) | (q > 0.0) else -a\n"
              "    return rhs(W, j, a / b - v, q)\n")
    assert fma_peak.count_flops(source) == (4, 1)     # *, +, /, -


def _by_hand(A, B, C, sums, skip_zeros):
    """Flops of chain_source's straight-line code, from the tableau's entries."""
    def terms(row):
        return sum(1 for x in row if not (skip_zeros and x == 0.0))

    def dot(row):                       # sum of k * w over the entries kept
        k = terms(row)
        return 2 * k - 1 if k else 0

    n = len(B)
    flops = 0
    for s in range(1, n):
        row = A[s][:s]
        flops += 2 * ((dot(row) + 2) if terms(row) else 0) + 2   # q_s, k_sq; t + C h
    flops += 2 * (dot(B) + 2) + 1                                 # qn, vn; t + h
    flops += sum(2 * dot(w) for w in sums)
    return flops, n


@pytest.mark.parametrize("method", ["rk45", "dop853"])
def test_chain_flops_match_the_tableau(method):
    if method == "rk45":
        args = (dopri5.A, dopri5.B, dopri5.C, (dopri5.E,), False)
    else:
        args = (dop853.A, dop853.B, dop853.C, (dop853.E5, dop853.E3), True)
    source = stages.chain_source(*args)
    assert fma_peak.count_flops(source) == _by_hand(*args)


def test_flops_per_attempt_adds_the_right_hand_sides():
    f = fma_peak.flops_per_attempt("rk45", parametric=True, base=False)
    assert f["rhs_calls"] == 6 and f["per_rhs"] > 20
    assert f["total"] == f["chain"] + 6 * f["per_rhs"]
    g = fma_peak.flops_per_attempt("dop853", parametric=True, base=True)
    assert g["rhs_calls"] == 12
    assert g["per_rhs"] > f["per_rhs"]          # the base term's sine on top of the load's cosine
