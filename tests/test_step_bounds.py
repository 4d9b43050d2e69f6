"""The bounds that let the multi-mode drivers skip the search of a step for a new largest
deflection (kernels.modal_driver.mode_reach and chord_bound, sweep.models.basis.shape_sizes):
each at least the largest value it bounds, found by dense sampling written here, and close to
it where the drivers rely on it being tight (a bound that is always large skips nothing)."""

import numpy as np
import pytest

from sweep.kernels import dopri5
from sweep.kernels import modal_driver as drv
from sweep.models.basis import clamped, elastic_ends, pinned_sines, shape_sizes


def _largest_shape(shapes: np.ndarray, samples: int = 200_001) -> np.ndarray:
    """max |phi_n| over the span at `samples` points, from the beam-function form."""
    s = np.linspace(0.0, 1.0, samples)
    out = []
    for beta, a, b, c, d in shapes:
        phi = (a * np.cos(beta * s) + b * np.sin(beta * s) + c * np.exp(-beta * s)
               + d * np.exp(-beta * (1.0 - s)))
        out.append(np.max(np.abs(phi)))
    return np.array(out)


@pytest.mark.parametrize("basis", [pinned_sines(6), clamped(6), elastic_ends(6, 0.5),
                                   elastic_ends(4, 30.0)],
                         ids=["pinned", "clamped", "elastic-soft", "elastic-stiff"])
def test_shape_sizes_bound_each_shape_and_are_tight(basis):
    largest = _largest_shape(basis.shapes)
    sizes = shape_sizes(basis.shapes)
    assert np.all(sizes >= largest)
    assert np.all(sizes <= largest * 1.006)          # the beam functions' own: up to 2.3x
    kernel_shapes = basis.kernel_arrays()[4]
    assert kernel_shapes.shape == (basis.n_modes, 6)
    np.testing.assert_array_equal(kernel_shapes[:, 5], sizes)


def _interpolant(y0: float, h: float, coefficients: np.ndarray, s: np.ndarray) -> np.ndarray:
    """q(s) = y0 + h sum_k a_k s^(k+1)."""
    return y0 + h * sum(a * s ** (k + 1) for k, a in enumerate(coefficients))


@pytest.mark.parametrize("terms", [dopri5.QUARTIC_TERMS, dopri5.DENSE_TERMS])
def test_mode_reach_bounds_the_interpolant_everywhere_on_the_step(terms):
    rng = np.random.default_rng(7)
    s = np.linspace(0.0, 1.0, 20_001)
    tighter = 0
    for _ in range(400):
        n = 2
        QA = np.zeros((n, 2, terms))
        QA[:, 0, :] = rng.normal(size=(n, terms)) * 10.0 ** rng.uniform(-3, 1, size=(n, terms))
        y = rng.normal(size=2 * n)
        h = rng.uniform(-0.5, 0.5)
        for c in range(n):
            bound = drv.mode_reach(y, h, QA, c)
            largest = np.max(np.abs(_interpolant(y[c], h, QA[c, 0], s)))
            assert bound >= largest
            plain = abs(y[c]) + abs(h) * np.sum(np.abs(QA[c, 0]))
            assert bound <= plain
            tighter += bound < plain
    assert tighter > 100                               # the chord's is often the tighter


def test_near_a_crest_the_chord_bound_is_close_to_the_crest():
    """A sine over a step of 0.2 rad across its crest: the chord's bound within 1 % of the crest,
    where |q(t_0)| plus the coefficients' sizes is 3.5 % above it."""
    w, h = 1.0, 0.2
    t0 = np.pi / 2 - 0.1
    # Taylor coefficients of sin(w (t0 + h s)) in s, as y0 + h sum_k a_k s^(k+1)
    derivs = [np.sin(w * t0 + k * np.pi / 2) * w ** k for k in range(1, 8)]
    fact = np.cumprod(np.arange(1, 8))
    a = np.array([derivs[k] * h ** k / fact[k] for k in range(7)])
    QA = np.zeros((1, 2, 7))
    QA[0, 0] = a
    y = np.array([np.sin(w * t0), 0.0])
    bound = drv.mode_reach(y, h, QA, 0)
    crest = np.max(_interpolant(y[0], h, a, np.linspace(0.0, 1.0, 20_001)))
    assert crest <= bound <= 1.01 * crest
    assert abs(y[0]) + abs(h) * np.sum(np.abs(a)) > 1.03 * crest


def test_chord_bound_takes_the_tighter_of_the_two():
    assert drv.chord_bound(1.0, -2.0, 10.0, 0.5) == pytest.approx(2.5 + 1e-11)
    assert drv.chord_bound(1.0, -2.0, 2.2, 0.5) == 2.2
