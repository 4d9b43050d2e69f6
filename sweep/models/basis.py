"""Mode shapes of a span: the Galerkin basis of the multi-mode System (docs/model.md secs. 7, 10).

A Basis holds N mode shapes phi_n(s) of the span, s = x / l in [0, 1], each in beam-function
form

    phi_n(s) = A cos(beta s) + B sin(beta s) + C exp(-beta s) + D exp(-beta (1 - s)),

(beta = b_n l; pinned sines: beta = n pi, B = 1, the rest 0; clamped and elastic ends add the
two decaying exponentials, the numerically stable form of the cosh/sinh beam functions), with
what the System's right-hand side and its Observer need of them, all dimensionless:

- the linear natural frequencies w_n / w_p and base participations Gamma_n / (4 / pi), both
  against the pinned span's first mode (w_p = (pi / l)^2 sqrt(EI / rho A), Gamma = 4 / pi), so
  a point's row holds the cable's data and the basis its shapes' ratios (the modes are the
  span's own linear modes: the mass and bending stiffness are diagonal; for beam functions
  w_n / w_p = (beta_n / pi)^2);
- a quadrature rule on (0, 1) exact (to round-off) for the projections of the nonlinear and
  axial-load terms, and the shapes' derivatives at its nodes: the kernel evaluates the
  deflection's fields there and projects on each mode (kernels/modes.py), so an axial load or a
  stretching term that couples the modes (a non-diagonal A_ij = int phi_i' phi_j') needs no
  code of its own;
- each mode's value at midspan (the watched deflection) and at stations along the span (the
  largest deflection over the span, refined on the shapes themselves).

`Basis.kernel_arrays()` is the tuple the kernels take (kernels/modes.py: T, stations, midspan,
ratios, shapes, coupling, clamps). The kernels know nothing of sines: a new end condition is a new Basis.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

SPAN_STATIONS_PER_MODE = 8
"""Stations along the span per mode (8 per half-wave of the highest pinned mode) at which the
largest deflection is first looked for, before Newton's method refines it on the shapes."""


@dataclass(frozen=True, eq=False)
class Basis:
    """N mode shapes of a span and what the multi-mode kernels read of them (module docstring).

    shapes: (N, 5) rows (beta, A, B, C, D) of the beam-function form; frequency_ratio (N,):
    w_n / w_p; participation_ratio (N,): Gamma_n / (4 / pi) (Gamma_n = int phi_n /
    int phi_n^2, uniform base motion); tables (7, N, J): at the J quadrature nodes s_j, phi_n' / pi,
    phi_n'' / pi^2, phi_n''' / pi^3, phi_n'''' / pi^4 (derivatives in s, so these are the
    derivatives in xi = pi s, the kernel's fields' units), the projection weights
    w_j phi_n(s_j) / int phi_n^2, and the weak form's on the shapes' slopes and curvatures,
    w_j (phi_n'(s_j) / pi) / int phi_n^2 and w_j (phi_n''(s_j) / pi^2) / int phi_n^2 (the
    bending force from the span's energy, kernels/modes.py); midspan (N,): phi_n(1/2); stations ((M + 1), N): phi_n at
    s_k = k / M, M = SPAN_STATIONS_PER_MODE N; coupling (N, N): A_ij / pi^2, A_ij = int phi_i'
    phi_j' ds (the span's elongation is (l k^2 / 2) q^T coupling q, k = pi / l: the uniform
    stretching tension's); clamps (10, N): what the load observers watch per unit q_n
    (`OBSERVED`): phi_n'' at both clamps and at midspan (the curvature times l^2), phi_n'''
    and phi_n' at both clamps (the shear and the slope), then `reaction_rows` (each mode's
    share of a uniform load's reaction at the clamp, and of the axial load's). name: what
    the modes are; mode_text and frequency_text: mode n and its frequency in words, for the
    dataset's long names."""

    name: str
    shapes: np.ndarray
    frequency_ratio: np.ndarray
    participation_ratio: np.ndarray
    tables: np.ndarray
    midspan: np.ndarray
    stations: np.ndarray
    coupling: np.ndarray
    clamps: np.ndarray
    mode_text: str = "mode shape n"
    frequency_text: str = "(beta_n l / pi)^2 f1 of the pinned span"
    _arrays: tuple = field(default=(), repr=False)

    @property
    def n_modes(self) -> int:
        return int(self.shapes.shape[0])

    def kernel_arrays(self) -> tuple[Any, ...]:
        """(tables, stations, midspan, ratios, shapes, coupling, clamps, polynomial): the
        basis as kernels/modes.py reads it; tables: folded about midspan
        (`mirrored_quadrature`); ratios is (2, N): w_n / w_p and Gamma_n / (4 / pi); shapes
        with each mode's bound of max |phi_n| (`shape_sizes`) as a sixth column;
        polynomial: the force as each mode's polynomial in q where that costs the right-hand
        side less than the quadrature (`force_polynomial`), else an empty one
        (kernels.modes.no_polynomial: both forms one type to Numba, one compile)."""
        if not self._arrays:
            ratios = np.ascontiguousarray(np.stack([self.frequency_ratio,
                                                    self.participation_ratio]), np.float64)
            arrays = (mirrored_quadrature(self.tables),) + tuple(
                np.ascontiguousarray(a, np.float64) for a in (self.stations, self.midspan)) + (
                ratios, np.ascontiguousarray(np.column_stack([self.shapes,
                                                              shape_sizes(self.shapes)]),
                                             np.float64),
                np.ascontiguousarray(self.coupling, np.float64),
                np.ascontiguousarray(self.clamps, np.float64),
                cheaper_polynomial(self.tables))
            object.__setattr__(self, "_arrays", arrays)
        return self._arrays


POLYNOMIAL_MAX_MODES = 6
"""Above this many modes the force's polynomial has more terms than the quadrature has
multiply-adds (its quintic part grows as N^6, the quadrature as N^2), and is not built."""


def _term_tensor(tables: np.ndarray, row: int, fields: tuple[int, ...]) -> np.ndarray:
    """D[m, i_1..i_d] = sum_j tables[row, m, j] prod_k tables[fields[k], i_k, j]: the
    quadrature of one FORCE_TERM's product of fields, projected on mode m, per unit
    q_i1 .. q_id (kernels/modes.py)."""
    n, nodes = tables.shape[1], tables.shape[2]
    product = tables[row]                               # (N, nodes), then one axis a field
    for f in fields:
        product = product[..., None, :] * tables[f].reshape((1,) * (product.ndim - 1)
                                                            + (n, nodes))
    return product.sum(axis=-1)


def _symmetrised(tensor: np.ndarray) -> np.ndarray:
    """The sum of `tensor` over every order of its axes after the first."""
    d = tensor.ndim - 1
    total = np.zeros_like(tensor)
    for order in itertools.permutations(range(1, d + 1)):
        total += tensor.transpose((0,) + order)
    return total


POLYNOMIAL_ZERO = 1e-12
"""A polynomial coefficient whose size is below this fraction of the sum of its quadrature's
terms' sizes is a cancellation to round-off (a coefficient the shapes' symmetry or
orthogonality makes 0) and is dropped."""


def force_polynomial(tables: np.ndarray) -> tuple[np.ndarray, ...]:
    """The right-hand side's nonlinear and axial-load force (kernels/modes.py FORCE_TERMS, the
    quadrature on `tables`) expanded into each mode's polynomial in q: (program (K, 2),
    starts (N, N_GROUPS + 1), monomials (T,), coefficients (T,), symmetric (N, N_GROUPS),
    pure).
    Monomial k >= N is the product of monomials program[k] (k < N: q_k); mode m's terms of
    group g are starts[m, g]..starts[m, g + 1] - 1, each a monomial's index and its coefficient
    (the quadrature's, summed over the monomial's orderings; those that cancel to round-off,
    POLYNOMIAL_ZERO, dropped), those whose monomial holds symmetric modes alone first, up to
    symmetric[m, g], and those monomials first in the program too, below `pure` (an int; where
    the tables fold about midspan, `mirrored_quadrature`; else no term and every monomial):
    with the antisymmetric modes at rest the others are 0, and the kernels stop there. The
    kernel multiplies each group's sum by its scale (beta_b, beta_q, the axial load, the
    membrane term) lane by lane."""
    from ..kernels.modes import FORCE_TERMS, N_GROUPS
    n = tables.shape[1]
    # each group's monomials: (coefficient, size of its quadrature's terms) for every mode
    terms: list[dict[tuple[int, ...], list[np.ndarray]]] = [{} for _ in range(N_GROUPS)]
    for group, row, c, fields in FORCE_TERMS:
        d = len(fields)
        value = _symmetrised(_term_tensor(tables, row, fields)) * c
        size = _symmetrised(_term_tensor(np.abs(tables), row, fields)) * abs(c)
        for mono in itertools.combinations_with_replacement(range(n), d):
            ways = math.prod(math.factorial(mono.count(i)) for i in set(mono))
            at = (slice(None),) + mono
            sums = terms[group].setdefault(mono, [np.zeros(n), np.zeros(n)])
            sums[0] += value[at] / ways
            sums[1] += size[at] / ways
    index = {(i,): i for i in range(n)}
    program = [(0, 0)] * n

    def monomial(mono: tuple[int, ...]) -> int:
        if mono not in index:
            split = {2: 1, 3: 2, 4: 2, 5: 3}[len(mono)]
            left, right = monomial(mono[:split]), monomial(mono[split:])
            index[mono] = len(program)
            program.append((left, right))
        return index[mono]

    folded = _parities(tables) is not None

    def mixed(mono: tuple[int, ...]) -> bool:
        """Whether a monomial holds an antisymmetric mode (odd index, where the tables
        fold: mode n is symmetric for odd n)."""
        return folded and any(i % 2 for i in mono)

    kept = [[sorted((mono for mono, (value, size) in terms[g].items()
                     if abs(value[m]) > POLYNOMIAL_ZERO * size[m]), key=mixed)
             for g in range(N_GROUPS)] for m in range(n)]
    for pure in (True, False):          # the symmetric modes' own monomials first
        for groups in kept:
            for group in groups:
                for mono in group:
                    if mixed(mono) != pure:
                        monomial(mono)
        if pure:
            pure_count = len(program)
    starts = np.zeros((n, N_GROUPS + 1), np.int64)
    symmetric = np.zeros((n, N_GROUPS), np.int64)
    monos: list[int] = []
    coefs: list[float] = []
    for m in range(n):
        for g in range(N_GROUPS):
            starts[m, g] = len(monos)
            symmetric[m, g] = starts[m, g] + sum(not mixed(mono) for mono in kept[m][g])
            for mono in kept[m][g]:
                monos.append(monomial(mono))
                coefs.append(float(terms[g][mono][0][m]))
        starts[m, N_GROUPS] = len(monos)
    return (np.array(program, np.int64).reshape(-1, 2), starts,
            np.array(monos, np.int64), np.array(coefs, np.float64), symmetric, pure_count)


def with_force_form(arrays: tuple[Any, ...], polynomial: bool,
                    mirrored: bool = True) -> tuple[Any, ...]:
    """A basis' kernel arrays with its force evaluated as the polynomial (True) or by
    quadrature (False), whatever the basis would choose, and its quadrature folded about
    midspan (`mirrored_quadrature`) or read node by node: for comparing the forms."""
    from ..kernels.modes import no_polynomial
    tables = unfolded_tables(arrays[0])
    quadrature = mirrored_quadrature(tables) if mirrored else _unfolded(tables)
    return ((quadrature,) + arrays[1:7]
            + (force_polynomial(tables) if polynomial else no_polynomial(tables.shape[1]),))


TABLE_ORDERS = (1, 2, 3, 4, 0, 1, 2)
"""The derivative order, in s, of the shapes in each row of a basis' tables (the fields a, b,
c, d, then the projections on phi_n, phi_n' and phi_n''): under the mirror s -> 1 - s a mode of
parity p (+1 symmetric about midspan, -1 antisymmetric) has row k's value times p (-1)^order."""

MIRROR_TOLERANCE = 1e-12
"""How closely (relative to each row's largest entry) a basis' tables must mirror about
midspan for the kernels to read half of them (`mirrored_quadrature`); the built-in bases
mirror to 4e-15."""


def _unfolded(tables: np.ndarray) -> np.ndarray:
    """`mirrored_quadrature`'s form of tables read node by node: every node's column, and the
    parity row 0."""
    return np.ascontiguousarray(np.concatenate([tables, np.zeros((1,) + tables.shape[1:])]),
                                np.float64)


def _parities(tables: np.ndarray) -> np.ndarray | None:
    """Each mode's parity about midspan (+1 symmetric, -1 antisymmetric) where the tables
    (7, N, J) mirror about it to MIRROR_TOLERANCE (`TABLE_ORDERS`) and the modes alternate
    +1, -1, +1, ... (a symmetric span's modes in order of frequency: mode n has n - 1 nodes),
    else None."""
    n, nodes = tables.shape[1], tables.shape[2]
    if nodes < 2:
        return None
    parity = np.empty(n)
    for i in range(n):
        j = int(np.argmax(np.abs(tables[4, i])))
        parity[i] = 1.0 if tables[4, i, nodes - 1 - j] * tables[4, i, j] > 0.0 else -1.0
    signs = parity[None, :, None] * (-1.0) ** np.array(TABLE_ORDERS)[:, None, None]
    scale = np.abs(tables).max(axis=2, keepdims=True)
    if np.any(np.abs(signs * tables[:, :, ::-1] - tables) > MIRROR_TOLERANCE * scale):
        return None
    if np.any(parity != np.where(np.arange(n) % 2 == 0, 1.0, -1.0)):
        return None             # the kernels take mode n's parity as (-1)^(n + 1)
    return parity


SIZE_SAMPLES = 4096
"""Intervals of the span at whose ends `shape_sizes` samples each shape."""


def shape_sizes(shapes: np.ndarray) -> np.ndarray:
    """An upper bound of max |phi_n(s)| over s in [0, 1] for each beam-function row (beta, A,
    B, C, D) of `shapes` (N, 5), phi = A cos(beta s) + B sin(beta s) + C e^(-beta s)
    + D e^(-beta (1 - s)) (kernels.modes.shape_at): the largest |phi_n| at SIZE_SAMPLES + 1
    equal steps, plus half a step times a bound of |phi_n'|, beta (sqrt(A^2 + B^2) + |C| +
    |D|); at most sqrt(A^2 + B^2) + |C| + |D| (a bound everywhere); for a pinned sine at most
    1 + beta / (2 SIZE_SAMPLES). The kernels' tests of whether a step could hold a new largest
    deflection read it (kernels.modal_driver.shape_size): the closer it is to the maximum,
    the fewer steps they search."""
    beta, a, b, c, d = (shapes[:, k][:, None] for k in range(5))
    s = np.linspace(0.0, 1.0, SIZE_SAMPLES + 1)[None, :]
    phi = (a * np.cos(beta * s) + b * np.sin(beta * s) + c * np.exp(-beta * s)
           + d * np.exp(-beta * (1.0 - s)))
    everywhere = (np.hypot(shapes[:, 1], shapes[:, 2]) + np.abs(shapes[:, 3])
                  + np.abs(shapes[:, 4]))
    sampled = (np.max(np.abs(phi), axis=1) + 0.5 / SIZE_SAMPLES * shapes[:, 0] * everywhere)
    return np.minimum(everywhere, sampled * (1.0 + 1e-12))


def mirrored_quadrature(tables: np.ndarray) -> np.ndarray:
    """The quadrature `tables` (7, N, J) as the kernels read it, (8, N, columns): where the
    nodes lie symmetrically about midspan and every mode is symmetric or antisymmetric about
    it (parity +1 or -1: alike clamps at both ends), the first (J + 1) // 2 nodes' columns,
    each standing for itself and its mirror node J - 1 - j, whose values are its own times
    parity (-1)^order (`TABLE_ORDERS`); the middle node of an odd J is its own mirror, its
    projection weights (rows 4-6) halved so that the pair counts it once, and its entries that
    vanish by symmetry set to 0. Row 7 (kernels.modes.PARITY) is each mode's parity, along
    every column. The kernels then sum the fields over half the nodes and project the forces
    of each pair at once (kernels/modes.py). Tables that do not mirror come back whole, row 7
    zero: read node by node."""
    tables = np.asarray(tables, np.float64)
    parity = _parities(tables)
    if parity is None:
        return _unfolded(tables)
    n, nodes = tables.shape[1], tables.shape[2]
    half = np.empty((8, n, (nodes + 1) // 2))
    half[:7] = tables[:, :, :half.shape[2]]
    half[7] = parity[:, None]
    if nodes % 2:
        signs = parity[None, :] * (-1.0) ** np.array(TABLE_ORDERS)[:, None]     # (7, N)
        half[:7, :, -1] = np.where(signs < 0.0, 0.0, half[:7, :, -1])
        half[4:7, :, -1] *= 0.5
    return np.ascontiguousarray(half)


def unfolded_tables(folded: np.ndarray) -> np.ndarray:
    """The tables (7, N, J) that `mirrored_quadrature` folded, whole again (an odd J where the
    last column is a middle node, its own mirror: `_has_middle_node`)."""
    if not np.any(folded[7]):
        return folded[:7]
    parity = folded[7, :, 0]
    signs = parity[None, :, None] * (-1.0) ** np.array(TABLE_ORDERS)[:, None, None]
    half = folded[:7]
    middle = _has_middle_node(half, parity)
    if middle:
        whole = half.copy()
        whole[4:7, :, -1] *= 2.0
        return np.concatenate([whole, (signs * whole)[:, :, -2::-1]], axis=2)
    return np.concatenate([half, (signs * half)[:, :, ::-1]], axis=2)


def _has_middle_node(half: np.ndarray, parity: np.ndarray) -> bool:
    """Whether the last column of folded tables is a middle node (its own mirror): there
    every entry that vanishes by symmetry is exactly 0."""
    signs = parity[None, :] * (-1.0) ** np.array(TABLE_ORDERS)[:, None]
    return bool(np.all(half[:, :, -1][signs < 0.0] == 0.0))


POLYNOMIAL_ADVANTAGE = 2.5
"""The polynomial is used where, with the antisymmetric modes at rest (base excitation's usual
case), its symmetric modes' own monomials and terms (of either form of the bending terms, the
span's energy's or Eq.17's, each with the axial ones) number at most this many times the
folded quadrature's nodes (`mirrored_quadrature`) x symmetric modes, and (POLYNOMIAL_LIMIT)
an asymmetric state does not cost it far more than the quadrature. Measured
(benchmarks/rhs_cost.py, twenty-sixth session, lanes and one state, both forms with the
antisymmetric modes at rest): for clamped ends the polynomial costs 0.75 and 0.95 times the
quadrature at 0.75 (2 modes), 0.67 and 0.94 at 1.6 (3), 0.62 and 0.79 at 1.4 (4), 0.66 and
0.92 at 2.8 (5), 0.66 and 0.85 at 2.4 (6); for pinned sines, whose trapezoidal rule needs few
nodes, 1.4 and 1.35 at 3.0 (2 modes), 1.27 and 1.42 at 4.0 (3), 1.22 and 1.23 at 3.4 (4), 1.2
and 1.4 at 5.3 (5)."""

POLYNOMIAL_LIMIT = 4.5
"""... and where all its monomials and terms number at most this many times the folded
quadrature's nodes x modes: measured as above but for states with every mode moving, the
polynomial costs 0.66 and 1.09 times the quadrature at 4.0 (clamped, 4 modes), 1.03 and 1.72
at 6.6 (5), 1.6 and 2.7 at 10 (6): clamped and elastic ends of up to 4 modes take it."""


def cheaper_polynomial(tables: np.ndarray) -> tuple[Any, ...]:
    """The force's polynomial (`force_polynomial`) where it costs the right-hand side less
    than the quadrature on `tables` (7, N, nodes) (`polynomial_pays`), else an empty one
    (kernels.modes.no_polynomial)."""
    from ..kernels.modes import no_polynomial
    if tables.shape[1] <= POLYNOMIAL_MAX_MODES:
        polynomial = force_polynomial(tables)
        if polynomial_pays(tables, polynomial):
            return polynomial
    return no_polynomial(tables.shape[1])


def polynomial_pays(tables: np.ndarray, polynomial: tuple[np.ndarray, ...]) -> bool:
    """Whether `polynomial` (`force_polynomial(tables)`) costs the right-hand side less than
    the quadrature on `tables` (7, N, nodes), folded: POLYNOMIAL_ADVANTAGE, POLYNOMIAL_LIMIT."""
    from ..kernels.modes import (G_ENERGY_CUBIC, G_ENERGY_QUINTIC, G_EQ17_CUBIC,
                                 G_EQ17_QUINTIC)

    def terms(counts: np.ndarray) -> int:
        """The terms of the larger of the two forms of the bending terms."""
        total = counts.sum()
        return max(total - counts[G_EQ17_CUBIC] - counts[G_EQ17_QUINTIC],
                   total - counts[G_ENERGY_CUBIC] - counts[G_ENERGY_QUINTIC])

    n = tables.shape[1]
    nodes = mirrored_quadrature(tables).shape[2]
    program, starts, _, _, symmetric, pure = polynomial
    every = program.shape[0] + terms(np.diff(starts, axis=1).sum(axis=0))
    own = pure + terms((symmetric - starts[:, :-1]).sum(axis=0))
    return (own <= POLYNOMIAL_ADVANTAGE * nodes * ((n + 1) // 2)
            and every <= POLYNOMIAL_LIMIT * nodes * n)


def pinned_sines(n_modes: int) -> Basis:
    """phi_n = sin(n pi s), n = 1..N: the pinned-pinned span (docs/model.md sec. 7), closed
    forms throughout. w_n = n^2 w_p; Gamma_n / (4 / pi) = 1 / n for odd n and 0 for even n;
    the quadrature is the trapezoidal rule on M = 3N + 1 equal intervals (interior nodes
    only: the integrands vanish at the ends), exact for the trigonometric polynomials of
    degree <= 6N the cubic and quintic terms make (the energy's bending terms' projections on
    phi_n' and phi_n'' too: cosine polynomials of degree <= 6N that vanish at the ends);
    phi_n(1/2) = 1, 0, -1, 0, ... exactly."""
    if n_modes < 1:
        raise ValueError(f"n_modes = {n_modes}: at least one mode")
    n = n_modes
    m = 3 * n + 1
    tables = np.empty((7, n, m - 1))
    for i in range(n):
        k = i + 1.0
        for j in range(m - 1):
            xi = (j + 1.0) * math.pi / m
            sn = math.sin(k * xi)
            cn = math.cos(k * xi)
            tables[0, i, j] = k * cn
            tables[1, i, j] = -k * k * sn
            tables[2, i, j] = -k * k * k * cn
            tables[3, i, j] = k * k * k * k * sn
            tables[4, i, j] = 2.0 / m * sn
            tables[5, i, j] = 2.0 / m * k * cn
            tables[6, i, j] = -2.0 / m * k * k * sn
    orders = np.arange(1, n + 1)
    midspan = np.zeros(n)
    midspan[0::2] = [1.0 if (i // 2) % 2 == 0 else -1.0 for i in range(0, n, 2)]
    stations_m = SPAN_STATIONS_PER_MODE * n
    stations = np.empty((stations_m + 1, n))
    for k in range(stations_m + 1):
        for i in range(n):
            stations[k, i] = math.sin((i + 1.0) * math.pi * k / stations_m)
    shapes = np.zeros((n, 5))
    shapes[:, 0] = orders * math.pi
    shapes[:, 2] = 1.0
    return Basis(name=f"pinned-pinned: sin(n pi x / l), n = 1..{n}", shapes=shapes,
                 frequency_ratio=(orders * orders).astype(float),
                 participation_ratio=np.where(orders % 2 == 1, 1.0 / orders, 0.0),
                 tables=tables, midspan=midspan, stations=stations,
                 coupling=np.diag(orders * orders / 2.0), clamps=_pinned_rows(n),
                 mode_text="sin(n pi x/l)", frequency_text="n^2 f1")


def shape_values(shapes: np.ndarray, s: np.ndarray, derivative: int = 0) -> np.ndarray:
    """The mode shapes' derivative of order `derivative` (0..4, in s) at the points s, as an
    array (N, len(s)), from their beam-function rows (beta, A, B, C, D) (module docstring)."""
    s = np.asarray(s, float)
    beta, a, b, c, d = (shapes[:, k][:, None] for k in range(5))
    x = beta * s[None, :]
    cos, sin = np.cos(x), np.sin(x)
    e_left, e_right = np.exp(-x), np.exp(-beta * (1.0 - s[None, :]))
    # d/ds of (cos, sin, e^-bs, e^-b(1-s)) = beta (-sin, cos, -e^-bs, e^-b(1-s))
    trig = [(a * cos + b * sin), (-a * sin + b * cos), -(a * cos + b * sin),
            (a * sin - b * cos)][derivative % 4]
    sign = -1.0 if derivative % 2 else 1.0
    return beta ** derivative * (trig + sign * c * e_left + d * e_right)


OBSERVED = ((2, 0.0), (2, 1.0), (2, 0.5), (3, 0.0), (3, 1.0), (1, 0.0), (1, 1.0))
"""(derivative in s, place s) of each row of Basis.clamps: kernels/modes.py's BEND_0, BEND_1,
BEND_MID, SHEAR_0, SHEAR_1, SLOPE_0, SLOPE_1."""


def observed_rows(shapes: np.ndarray) -> np.ndarray:
    """The rows of Basis.clamps (`OBSERVED`, (7, N)) of beam-function shapes: the curvature at
    both clamps and at midspan, the third derivative and the slope at both clamps (per unit
    q_n, in s = x / l)."""
    return np.array([shape_values(shapes, np.array([s]), k)[:, 0] for k, s in OBSERVED])


def reaction_rows(shapes: np.ndarray, nodes: int) -> np.ndarray:
    """The rows of Basis.clamps that make the clamp's reaction the span's equilibrium rather
    than the modes' shear sum (Gauss-Legendre on `nodes` nodes; docs/model.md sec. 10.5),
    (3, N):

    - INERTIA: Gamma_n int (1 - s) phi_n ds (Gamma_n = int phi_n / int phi_n^2): mode n's
      share of the reaction at the clamp s = 0 to a uniform load, per unit load times l.
      Statically that reaction is 1/2; the modes' shares sum to 1/2 only as N -> infinity,
      and the observers add the rest (kernels.modes.inertia_factor: mode acceleration);
    - AXIAL_0, AXIAL_1: sum_m A_nm int (1 - s) phi_m / int phi_m^2 and -sum_m A_nm int s
      phi_m / int phi_m^2 (A_nm = int phi_n' phi_m' ds): the axial load's (N - P) w_xx
      reaction at s = 0 and 1 per unit q_n, as the modes kept carry it with the part they
      leave out carried statically: phi_n'(0), phi_n'(1) where the axial load's field has no
      part outside the modes (pinned sines); not 0 at a clamped end, where phi_n' is.

    A span whose ends are alike has the same inertia share at s = 1 (each mode has
    Gamma_n = 0 or is symmetric)."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    s, w = (x + 1.0) / 2.0, w / 2.0
    phi = shape_values(shapes, s)
    slope = shape_values(shapes, s, 1)
    mass = phi ** 2 @ w
    gamma = (phi @ w) / mass
    left = (phi * (1.0 - s)) @ w
    right = (phi * s) @ w
    axial = (slope * w) @ slope.T
    return np.array([gamma * left, axial @ (left / mass), -axial @ (right / mass)])


def _pinned_rows(n: int) -> np.ndarray:
    """`observed_rows` and `reaction_rows` of sin(n pi s) in closed form: phi'' = 0 at the
    clamps, -(n pi)^2 sin(n pi / 2) at midspan; phi''' = -(n pi)^3 cos(n pi s); phi' = n pi
    cos(n pi s); Gamma_n int (1 - s) phi_n = (4 / (n pi)) (1 / (n pi)) for odd n, 0 for even
    (over the odd n they sum to (4 / pi^2) (pi^2 / 8) = 1/2); the axial rows are the slopes
    (A is diagonal, (n pi)^2 / 2: A_nn (1 / (n pi)) / (1/2) = n pi)."""
    k = np.arange(1, n + 1) * math.pi
    sign = np.where(np.arange(1, n + 1) % 2 == 0, 1.0, -1.0)          # cos(n pi)
    mid = np.array([0.0 if i % 2 else (1.0 if (i // 2) % 2 == 0 else -1.0) for i in range(n)])
    zero = np.zeros(n)
    inertia = np.where(np.arange(1, n + 1) % 2 == 1, 4.0 / k ** 2, 0.0)
    return np.array([zero, zero, -k ** 2 * mid, -k ** 3, -k ** 3 * sign, k, k * sign, inertia,
                     k, k * sign])


def from_shapes(name: str, shapes: np.ndarray, nodes: int, mode_text: str = "mode shape n",
                frequency_text: str = "(b_n / b_1)^2 f1") -> Basis:
    """A Basis of any beam-function shapes (rows (beta, A, B, C, D), each a linear mode of the
    span, w_n / w_p = (beta / pi)^2), its projections by Gauss-Legendre quadrature on `nodes`
    nodes of (0, 1), its participations and masses from the shapes (the same quadrature): the
    general case, for shapes whose integrals the kernel has no closed form of (clamped and
    elastic ends). The nodes must make the projections exact to round-off for the shapes and
    number of modes in use (products of six shapes): the caller checks that, e.g. by doubling
    them. Where the shapes are symmetric and antisymmetric about midspan (alike ends:
    `mirrored_quadrature` finds the parities), what vanishes by symmetry is set to 0 rather
    than left at round-off: an antisymmetric mode's participation, midspan value, curvature
    at midspan and share of the inertia's reaction, and the coupling of modes of unlike
    parity; so a symmetric motion under base excitation stays exactly symmetric, as it does
    on pinned sines (their closed forms)."""
    shapes = np.asarray(shapes, float)
    n = shapes.shape[0]
    x, w = np.polynomial.legendre.leggauss(nodes)
    s, w = (x + 1.0) / 2.0, w / 2.0
    phi = shape_values(shapes, s)
    mass = phi ** 2 @ w                                   # int phi_n^2 ds
    gamma = (phi @ w) / mass                              # int phi_n / int phi_n^2
    tables = np.empty((7, n, nodes))
    for order in range(1, 5):
        tables[order - 1] = shape_values(shapes, s, order) / math.pi ** order
    tables[4] = w[None, :] * phi / mass[:, None]
    tables[5:7] = w[None, None, :] * tables[0:2] / mass[None, :, None]
    stations_m = SPAN_STATIONS_PER_MODE * n
    stations = shape_values(shapes, np.arange(stations_m + 1) / stations_m).T
    midspan = shape_values(shapes, np.array([0.5]))[:, 0]
    slope = shape_values(shapes, s, 1)
    coupling = (slope * w) @ slope.T / math.pi ** 2
    clamps = np.vstack([observed_rows(shapes), reaction_rows(shapes, nodes)])
    parity = _parities(tables)
    if parity is not None:  # alike ends: what vanishes by symmetry is 0, not round-off, so
        odd = parity < 0.0  # that a symmetric motion stays exactly symmetric
        gamma[odd] = 0.0
        midspan[odd] = 0.0
        clamps[OBSERVED.index((2, 0.5)), odd] = 0.0         # phi_n''(1/2)
        clamps[len(OBSERVED), odd] = 0.0                    # the inertia's share (Gamma_n = 0)
        coupling[parity[:, None] != parity[None, :]] = 0.0
    return Basis(name=name, shapes=shapes, frequency_ratio=(shapes[:, 0] / math.pi) ** 2,
                 coupling=coupling, clamps=clamps,
                 participation_ratio=gamma / (4.0 / math.pi),
                 tables=tables, midspan=midspan, stations=np.ascontiguousarray(stations),
                 mode_text=mode_text, frequency_text=frequency_text)


CLAMPED = math.inf
"""The rotational stiffness K = k_t l / EI of a clamped end (no rotation)."""


def _end_conditions(beta: float, stiffness: float) -> np.ndarray:
    """The 4 x 4 matrix whose null vector is (A, B, C, D) of a mode with eigenvalue beta of a
    span with w = 0 and a rotational spring K = `stiffness` (k_t l / EI) at both ends:
    phi(0) = 0, phi''(0) = K phi'(0), phi(1) = 0, phi''(1) = -K phi'(1) (derivatives in s).
    Rows scaled to stay bounded for any beta and K (CLAMPED: phi' = 0 at both ends)."""
    e = math.exp(-beta)
    c, s = math.cos(beta), math.sin(beta)
    spring, slope = ((0.0, 1.0) if stiffness == CLAMPED
                     else (beta / (beta + stiffness), stiffness / (beta + stiffness)))
    return np.array([
        [1.0, 0.0, 1.0, e],                                               # phi(0)
        [-spring, -slope, spring + slope, (spring - slope) * e],          # phi'' - K phi' at 0
        [c, s, e, 1.0],                                                   # phi(1)
        [-spring * c - slope * s, -spring * s + slope * c,                # phi'' + K phi' at 1
         (spring - slope) * e, spring + slope],
    ])


def _eigenvalues(n_modes: int, stiffness: float) -> np.ndarray:
    """The first n_modes roots beta = b_n l of the end conditions' determinant: the n-th lies
    in [n pi, the clamped span's] (pinned at K = 0, clamped as K -> inf), found by a scan of
    that interval and bisection to round-off."""
    def det(beta: float) -> float:
        return float(np.linalg.det(_end_conditions(beta, stiffness)))

    roots = []
    for n in range(1, n_modes + 1):
        if stiffness == 0.0:
            roots.append(n * math.pi)
            continue
        lo, hi = n * math.pi, (n + 0.5) * math.pi + 0.02
        grid = np.linspace(lo, hi, 401)
        values = [det(b) for b in grid]
        found = None
        for k in range(len(grid) - 1):
            if values[k] == 0.0:
                found = grid[k]
                break
            if values[k] * values[k + 1] < 0.0:
                a, b, fa = grid[k], grid[k + 1], values[k]
                for _ in range(200):
                    mid = 0.5 * (a + b)
                    fm = det(mid)
                    if mid in (a, b) or fm == 0.0:
                        break
                    if fa * fm < 0.0:
                        b = mid
                    else:
                        a, fa = mid, fm
                found = 0.5 * (a + b)
                break
        if found is None:
            raise ValueError(f"no eigenvalue of mode {n} found for K = {stiffness}")
        roots.append(found)
    return np.array(roots)


def _normalised(beta: float, stiffness: float) -> np.ndarray:
    """The beam-function row (beta, A, B, C, D) of the mode with eigenvalue beta, scaled to
    max |phi| = 1 over the span, signed so that phi'(0) + phi''(0) / beta > 0 (a sine's
    sign)."""
    _, _, vt = np.linalg.svd(_end_conditions(beta, stiffness))
    row = np.concatenate([[beta], vt[-1]])
    s = np.linspace(0.0, 1.0, 4097)
    phi = shape_values(row[None, :], s)[0]
    k = int(np.argmax(np.abs(phi)))
    x = s[k]
    for _ in range(8):                           # Newton on phi' = 0 at the largest value
        d1 = shape_values(row[None, :], np.array([x]), 1)[0, 0]
        d2 = shape_values(row[None, :], np.array([x]), 2)[0, 0]
        if d2 == 0.0:
            break
        x = min(1.0, max(0.0, x - d1 / d2))
    largest = abs(shape_values(row[None, :], np.array([x]))[0, 0])
    start = shape_values(row[None, :], np.array([0.0]), 1)[0, 0] + \
        shape_values(row[None, :], np.array([0.0]), 2)[0, 0] / beta
    row[1:] *= math.copysign(1.0 / largest, start)
    return row


def quadrature_nodes(n_modes: int) -> int:
    """Gauss-Legendre nodes for a beam-function basis of n_modes modes: its projections (a
    product of six shapes, degree about 6 beta_N / pi in the trigonometric part) exact to
    round-off (tests/test_basis.py doubles them). Measured against 300 nodes on the clamped
    modes' nonlinear force at random states (N = 1..8): 6 N + 12 nodes are at the round-off
    floor of the force itself, as 8 N + 24 were (the right-hand side's cost grows with the
    nodes: 30 instead of 48 for 3 modes)."""
    return 6 * n_modes + 12


def elastic_ends(n_modes: int, stiffness: float) -> Basis:
    """The span's N lowest modes with a rotational spring of stiffness K = k_t l / EI
    (dimensionless) at both ends and no deflection there (docs/model.md sec. 10): K = 0 is the
    pinned span (use pinned_sines: its closed forms), CLAMPED the clamped one; each mode
    scaled to max |phi| = 1, its projections by Gauss-Legendre quadrature."""
    if n_modes < 1:
        raise ValueError(f"n_modes = {n_modes}: at least one mode")
    if not (stiffness >= 0.0):
        raise ValueError(f"rotational stiffness K = {stiffness}: must be >= 0")
    betas = _eigenvalues(n_modes, stiffness)
    shapes = np.array([_normalised(b, stiffness) for b in betas])
    if stiffness == CLAMPED:
        return from_shapes(f"clamped-clamped beam functions, n = 1..{n_modes}", shapes,
                           quadrature_nodes(n_modes), mode_text="clamped-clamped mode n",
                           frequency_text="(b_n / b_1)^2 f1, cos(b l) cosh(b l) = 1")
    return from_shapes(f"elastic ends K = k_t l / EI = {stiffness:g}, n = 1..{n_modes}",
                       shapes, quadrature_nodes(n_modes),
                       mode_text=f"mode n of the span with rotational springs K = {stiffness:g}",
                       frequency_text="(b_n / b_1)^2 f1 of the span with rotational springs")


def clamped(n_modes: int) -> Basis:
    """The clamped-clamped span's N lowest modes (elastic_ends with K -> inf)."""
    return elastic_ends(n_modes, CLAMPED)


BUCKLING_MODES = 8
"""Modes of the basis from which a span's buckling load is taken (`buckling_factor`): the
clamped span's is then within 1e-4 of the exact 4 pi^2 EI / l^2."""


def one_mode_integrals(basis: Basis) -> dict[str, float]:
    """The integrals of mode 1 (s = x / l, derivatives in s, each over int phi^2) that make the
    one-mode equation of the span (docs/model.md secs. 2 and 10): beta = b_1 l; load =
    int phi'' phi; stretch = int phi'' phi'^2 phi (the membrane and the load's cubic term);
    curvature = int (3 phi''^3 + 11 phi'' phi''' phi' + 3 phi'''' phi'^2) phi (the cubic
    curvature terms); quintic = int phi''^3 phi'^2 phi (Eq.17's); bend_cubic = 6 int phi'^2
    phi''^2 and bend_quintic = 18 int phi'^4 phi''^2 (the same terms from the span's bending
    energy (EI / 2) int w''^2 (1 - 3 w'^2 + 6 w'^4): its force on one mode is EI (-bend_cubic
    q^3 + bend_quintic q^5) int phi^2 / l^6, ^8); gamma = int phi / int phi^2 (base
    participation); slope = max |phi'| (the mode's largest slope per unit amplitude);
    clamp_curvature = |phi''(0)| (the curvature at the clamps per unit amplitude);
    midspan_curvature = |phi''(1/2)|; clamp_shear = |phi'''(0)| (the clamp's reaction,
    docs/model.md sec. 10.5); slope_square = int phi'^2 (the span's elongation is
    slope_square q^2 / (2 l)); inertia = 1/2 - gamma int (1 - s) phi (the share of a uniform
    load's reaction at a clamp that the one mode leaves out: kernels.modes inertia_factor) and
    axial_slope (the axial load's reaction at a clamp per unit q and (N - P) / l:
    `reaction_rows`' AXIAL_0; pi for the pinned mode, 3.22 for the clamped one, whose
    phi'(0) is 0); mass =
    int phi^2 itself (not divided). By
    Gauss-Legendre on 4 x the basis' own nodes; pinned sines give -pi^2, -pi^4 / 4, 5 pi^6 /
    4, -pi^8 / 8, 3 pi^6 / 2, 9 pi^8 / 4, 4 / pi and pi."""
    row = basis.shapes[:1]
    x, w = np.polynomial.legendre.leggauss(4 * quadrature_nodes(basis.n_modes))
    s, w = (x + 1.0) / 2.0, w / 2.0
    d = [shape_values(row, s, k)[0] for k in range(5)]
    mass = d[0] ** 2 @ w
    fine = np.linspace(0.0, 1.0, 4097)
    bend_0, _, bend_mid, shear_0, _, _, _ = observed_rows(row)[:, 0]
    gamma_share, axial_slope, _ = reaction_rows(row, 4 * quadrature_nodes(1))[:, 0]
    return {
        "mass": float(mass),
        "beta": float(row[0, 0]),
        "load": float(d[2] * d[0] @ w / mass),
        "stretch": float(d[2] * d[1] ** 2 * d[0] @ w / mass),
        "curvature": float((3.0 * d[2] ** 3 + 11.0 * d[2] * d[3] * d[1]
                            + 3.0 * d[4] * d[1] ** 2) * d[0] @ w / mass),
        "quintic": float(d[2] ** 3 * d[1] ** 2 * d[0] @ w / mass),
        "bend_cubic": float(6.0 * d[1] ** 2 * d[2] ** 2 @ w / mass),
        "bend_quintic": float(18.0 * d[1] ** 4 * d[2] ** 2 @ w / mass),
        "gamma": float(d[0] @ w / mass),
        "slope": float(np.abs(shape_values(row, fine, 1)).max()),
        "clamp_curvature": float(abs(bend_0)),
        "midspan_curvature": float(abs(bend_mid)),
        "clamp_shear": float(abs(shear_0)),
        "slope_square": float(d[1] ** 2 @ w),
        "inertia": float(0.5 - gamma_share),
        "axial_slope": float(axial_slope),
    }


def buckling_factor(basis: Basis) -> float:
    """Pcr l^2 / EI of the span whose modes `basis` holds: the least P with (B - P A) q = 0,
    B = diag(beta_n^4 int phi_n^2) and A_ij = int phi_i' phi_j' (s units) over its modes
    (Galerkin: an upper bound that the symmetric modes converge to from above)."""
    x, w = np.polynomial.legendre.leggauss(quadrature_nodes(basis.n_modes))
    s, w = (x + 1.0) / 2.0, w / 2.0
    phi, slope = shape_values(basis.shapes, s), shape_values(basis.shapes, s, 1)
    stiffness = np.diag(basis.shapes[:, 0] ** 4 * (phi ** 2 @ w))
    axial = (slope * w) @ slope.T
    return float(np.min(np.linalg.eigvals(np.linalg.solve(axial, stiffness)).real))


def end_stiffness(rotation: str, rotational_stiffness: Any, length: Any, bending: Any) -> Any:
    """K = k_t l / EI (1) of a span's ends: 0 pinned, CLAMPED clamped, else from the clamps'
    rotational stiffness k_t (N m/rad), the length l (m) and the bending stiffness EI (N m^2);
    element-wise on numbers, arrays or DataArrays."""
    if rotation == "pinned":
        return 0.0
    if rotation == "clamped":
        return CLAMPED
    return rotational_stiffness * length / bending


@lru_cache(maxsize=4096)
def _basis_of(stiffness: float, n_modes: int) -> Basis:
    return pinned_sines(n_modes) if stiffness == 0.0 else elastic_ends(n_modes, stiffness)


@lru_cache(maxsize=4096)
def _ends_of(stiffness: float) -> dict[str, float]:
    return {**one_mode_integrals(_basis_of(stiffness, 1)),
            "buckling": buckling_factor(_basis_of(stiffness, BUCKLING_MODES))}


def span_basis(stiffness: float, n_modes: int) -> Basis:
    """The basis of N modes of a span with ends K = `stiffness` (pinned_sines for 0; cached:
    a grid has few distinct K)."""
    return _basis_of(float(stiffness), int(n_modes))


def span_ends(stiffness: Any) -> dict[str, Any]:
    """Mode 1's integrals (`one_mode_integrals`) and the buckling factor Pcr l^2 / EI of spans
    with ends K = `stiffness` (a number, an array or a DataArray of them), each of the same
    shape as `stiffness`: what sweep.models.modal takes as a span's ends."""
    if np.ndim(stiffness) == 0 and not hasattr(stiffness, "dims"):
        return _ends_of(float(stiffness))
    values = np.asarray(stiffness, float)
    unique, where = np.unique(values, return_inverse=True)
    tables = [_ends_of(float(k)) for k in unique]
    if not tables:                        # no points (a caller sizing its rows): empty columns
        return {name: np.empty(values.shape) for name in _ends_of(0.0)}
    out = {}
    for name in tables[0]:
        column = np.array([t[name] for t in tables])[where].reshape(values.shape)
        out[name] = stiffness.copy(data=column) if hasattr(stiffness, "dims") else column
    return out


@lru_cache(maxsize=None)
def elastic_bases_stack(n_modes: int) -> bool:
    """Whether the bases of N modes of spans with elastic clamps (K > 0) stack into one lanes
    call (kernels.modes.stacked): they do where each carries the force's polynomial, whose
    structure does not depend on K (up to 4 modes; tests/test_basis.py checks it over K)."""
    from ..kernels.modes import stacked
    return stacked([span_basis(k, n_modes).kernel_arrays() for k in (0.5, 50.0)]) is not None


@dataclass(frozen=True, eq=False)
class BasisFamily:
    """The bases of N modes of spans whose ends differ over a grid (elastic clamps: K = k_t l /
    EI varies with the length, the cable and the clamps' stiffness): one Basis for each
    distinct K (`stiffness`, increasing). The kernels take one basis a call: a point's row
    carries its index into `bases` (sweep.execute.modes_chunk groups the rows by it)."""

    stiffness: np.ndarray
    bases: tuple[Basis, ...]

    @classmethod
    def of(cls, stiffness: Any, n_modes: int) -> "BasisFamily":
        """The family of the distinct values of `stiffness` (an array or DataArray of K)."""
        values = np.unique(np.asarray(stiffness, float))
        return cls(values, tuple(span_basis(k, n_modes) for k in values))

    @property
    def n_modes(self) -> int:
        return self.bases[0].n_modes

    @property
    def mode_text(self) -> str:
        return "mode n of the span with rotational springs K = k_t l / EI at its clamps"

    @property
    def frequency_text(self) -> str:
        return "(b_n / b_1)^2 f1, b_n of the span's rotational springs"

    def index(self, stiffness: np.ndarray) -> np.ndarray:
        """Each K's index into `bases` (K computed as the family's were: the same bits)."""
        at = np.searchsorted(self.stiffness, stiffness)
        at = np.minimum(at, self.stiffness.size - 1)
        if not np.array_equal(self.stiffness[at], stiffness):
            raise ValueError("a span's rotational stiffness K is not one of the family's")
        return at

    def kernel_arrays(self) -> list[tuple[Any, ...]]:
        """One Basis.kernel_arrays() per K, in `bases` order (sweep.execute.modes_chunk)."""
        return [b.kernel_arrays() for b in self.bases]

    def frequency_ratios(self, stiffness: Any) -> np.ndarray:
        """w_n / w_1 (N) of each K of `stiffness` (its shape + (N,))."""
        table = np.array([b.frequency_ratio / b.frequency_ratio[0] for b in self.bases])
        return table[self.index(np.asarray(stiffness, float))]
