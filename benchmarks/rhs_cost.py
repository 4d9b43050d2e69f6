"""The N-mode right-hand side alone: its cost per evaluation by end condition and form, and why
a clamped span's quadrature needs the nodes it has.

What it measures
----------------
`kernels.modes.lanes_derivative` called in a compiled loop (no step, no observer) on the row
of one span (benchmarks/clamps_cost.py's scene: the Table 1 cable at 0.3 m, 1 g base
excitation, sweep.models.transverse.modal_rows), for N in --modes:

- pinned sines with the uniform stretching tension and the bending terms from the span's
  energy (what a pinned scene without model.membrane gets), pinned sines with the paper's
  local membrane term (Eq.17's bending terms: harness-base-sine's physics), and clamped ends
  (energy, uniform tension: harness-clamps' physics);
- per lane with 32 lanes side by side (the lanes driver) and with 1 (`derivative`, the scalar
  driver's one state), ns per evaluation, best of 5 loops of --calls calls, with the force
  summed at the quadrature's nodes read one by one, folded about midspan
  (sweep.models.basis.mirrored_quadrature) at states of every mode and at states whose
  antisymmetric modes are at rest ("symmetric": what base excitation leaves), and as its
  polynomial (sweep.models.basis.force_polynomial) at both kinds of state, and which form
  the basis chooses (`polynomial_pays`);
- the quadrature: the clamped basis' nonlinear force (the energy's cubic and quintic parts
  and the axial load's linear one, each projected on every mode) at 20 random modal states,
  with J Gauss-Legendre nodes against 300, largest error over the largest value; the rule in
  use (sweep.models.basis.quadrature_nodes: 6 N + 12) is the first at the round-off floor.

Command
-------
    PYTHONPATH=. python benchmarks/rhs_cost.py [--modes 2 3 4 5 6] [--calls 20000]

Prints two Markdown tables and the command line.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numba as nb
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels
sys.path.insert(0, str(Path(__file__).resolve().parent))       # bench_common

from bench_common import markdown_table  # noqa: E402
from clamps_cost import SCENE  # noqa: E402

import sweep  # noqa: E402
from sweep.kernels import modes as md  # noqa: E402
from sweep.models.basis import (CLAMPED, _eigenvalues, _normalised, from_shapes,  # noqa: E402
                                quadrature_nodes, unfolded_tables, with_force_form)
from sweep.models.transverse import modal_rows, resolve  # noqa: E402

LANES = 32


@nb.njit(cache=False)
def lanes_loop(row, basis, calls, lanes, symmetric):
    """`calls` evaluations of `lanes` states side by side (a distinct state each call);
    symmetric: the even (antisymmetric) modes at rest, as base excitation leaves them."""
    n = md.basis_modes(basis)
    T = basis[md.TABLES]
    pp = np.empty(md.prepared_size(n))
    md.prepare(row, n, pp, basis[md.RATIOS])
    PP = np.empty((pp.shape[0], lanes))
    for l in range(lanes):
        PP[:, l] = pp
    X = np.empty((2 * n, lanes))
    K = np.empty((1, 2 * n, lanes))
    tt = np.zeros(lanes)
    FLD = np.empty((4, md.field_rows(basis), lanes))
    SC = np.empty((4, lanes))
    LB = md.lane_basis(basis, lanes)
    total = 0.0
    for k in range(calls):
        for c in range(2 * n):
            for l in range(lanes):
                X[c, l] = 0.0 if symmetric and (c % n) % 2 == 1 else 1e-3 + k * 1e-12 + l * 1e-9
                tt[l] = k * 1e-5
        md.lanes_derivative(tt, X, K, 0, PP, n, T, FLD, SC, lanes, True, True,
                            basis[md.COUPLING], basis[md.POLYNOMIAL], LB, False)
        total += K[0, n, 0]
    return total


@nb.njit(cache=False)
def one_state_loop(row, basis, calls, symmetric):
    """`calls` evaluations of one state through `derivative` (the scalar driver's);
    symmetric: as for `lanes_loop`."""
    n = md.basis_modes(basis)
    T = basis[md.TABLES]
    S = md.row_scratch(row, basis)
    y = np.full(2 * n, 1e-3)
    if symmetric:
        for c in range(2 * n):
            if (c % n) % 2 == 1:
                y[c] = 0.0
    dy = np.empty(2 * n)
    total = 0.0
    for k in range(calls):
        y[0] = 1e-3 + k * 1e-12
        md.derivative(k * 1e-5, y, dy, S, n, T, True)
        total += dy[n]
    return total


def best_ns(run, evaluations: int) -> float:
    """Best of 5 runs of run(), ns per evaluation."""
    best = float("inf")
    for _ in range(5):
        start = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - start)
    return best / evaluations * 1e9


def span(n: int, rotation: str, membrane: bool) -> tuple[np.ndarray, tuple]:
    """(raw row, basis arrays) of the scene's 0.3 m span."""
    text = SCENE.format(n=n, rotation=rotation).replace(
        "[model]", "[model]\nmembrane = 0.375" if membrane else "[model]")
    scene = sweep.load_scene_text(text, overrides={"axes.length": [0.3]})
    inputs = resolve(scene)
    return modal_rows(inputs, np.arange(1))[0].copy(), inputs.basis.kernel_arrays()


def quadrature_error(n: int, nodes: int, states: list[np.ndarray]) -> float:
    """Largest error of the clamped basis' projected nonlinear force with `nodes` nodes
    against 300, over the largest value, at `states`."""
    shapes = np.array([_normalised(b, CLAMPED) for b in _eigenvalues(n, CLAMPED)])

    def forces(tables: np.ndarray, q: np.ndarray) -> np.ndarray:
        a, b = q @ tables[0], q @ tables[1]
        return np.concatenate([(tables[5] * (a * b * b)).sum(1), (tables[6] * (a * a * b)).sum(1),
                               (tables[5] * (a ** 3 * b * b)).sum(1),
                               (tables[6] * (a ** 4 * b)).sum(1), (tables[4] * b).sum(1)])

    exact = from_shapes("reference", shapes, 300).tables
    rule = from_shapes("rule", shapes, nodes).tables
    worst = 0.0
    for q in states:
        ref = forces(exact, q)
        worst = max(worst, float(np.max(np.abs(forces(rule, q) - ref)) / np.max(np.abs(ref))))
    return worst


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--modes", type=int, nargs="+", default=[2, 3, 4, 5, 6])
    parser.add_argument("--calls", type=int, default=20000)
    args = parser.parse_args()
    rows = []
    for n in args.modes:
        for rotation, membrane, physics in (
                ("pinned", False, "energy, uniform tension"),
                ("pinned", True, "Eq.17, local membrane"),
                ("clamped", False, "energy, uniform tension")):
            row, arrays = span(n, rotation, membrane)
            cells = []
            for polynomial, mirrored, symmetric in ((False, False, False), (False, True, False),
                                                    (False, True, True), (True, True, False),
                                                    (True, True, True)):
                basis = with_force_form(arrays, polynomial, mirrored)
                lanes_loop(row, basis, 10, LANES, symmetric)
                one_state_loop(row, basis, 10, symmetric)
                cells.append((best_ns(lambda: lanes_loop(row, basis, args.calls, LANES,
                                                         symmetric), args.calls * LANES),
                              best_ns(lambda: one_state_loop(row, basis, 10 * args.calls,
                                                             symmetric), 10 * args.calls)))
            chosen = "polynomial" if md.uses_polynomial(arrays) else "quadrature"
            nodes = unfolded_tables(arrays[md.TABLES]).shape[2]
            rows.append([f"{n}", rotation, physics, f"{nodes}"]
                        + [f"{lane:.1f}" for lane, _ in cells] + [f"{one:.0f}" for _, one in cells]
                        + [chosen])
    forms = ["node by node", "folded", "folded, symmetric", "polynomial",
             "polynomial, symmetric"]
    print(markdown_table(["modes", "ends", "terms", "quadrature nodes"]
                         + [f"{form}, ns a lane" for form in forms]
                         + [f"{form}, ns one state" for form in forms] + ["chosen"], rows))
    rng = np.random.default_rng(1)
    table = []
    for n in args.modes:
        states = [rng.normal(size=n) / np.arange(1, n + 1) for _ in range(20)]
        table.append([f"{n}"] + [f"{j}: {quadrature_error(n, j, states):.1e}" for j in (
            3 * n + 1, 4 * n + 8, 5 * n + 8, quadrature_nodes(n))])
    print()
    print(markdown_table(["modes", "3N+1 nodes", "4N+8", "5N+8", "6N+12 (in use)"], table))
    print("\n    PYTHONPATH=. python benchmarks/rhs_cost.py " + " ".join(sys.argv[1:]))


if __name__ == "__main__":
    main()
