"""Clamped and elastic ends ([clamps], docs/model.md sec. 10): the span's own modes through the
same engine, against references written here from the textbook, not from sweep.models.basis:

1. the linearised clamped span under base excitation: the closed-form steady response of its
   modes (b_n l from cos(b l) cosh(b l) = 1, shapes and participations by quadrature of the
   textbook cosh/cos form), below, at and above resonance, one mode and three;
2. the nonlinear clamped span (stretching and curvature terms of Eq.17) against SciPy's DOP853
   on Galerkin equations projected on the textbook shapes (tests/galerkin.py);
3. elastic ends: f1 and the linear response from the rotational-spring eigenvalues
   (docs/model.md sec. 10);
4. bad [clamps] input, one line each.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
import pytest

import sweep
from sweep.errors import SceneError

import galerkin as g

LENGTH = 0.4
ZETA = 0.02


def scene(rotation: str = "clamped", modes: int = 1, level_g: float = 1e-5,
          ratio: float = 1.0, t_end: float = 4.0, extra: str = "") -> sweep.Scene:
    return sweep.load_scene_text(scene_text(rotation, modes, level_g, ratio, t_end, extra))


def scene_text(rotation: str = "clamped", modes: int = 1, level_g: float = 1e-5,
               ratio: float = 1.0, t_end: float = 4.0, extra: str = "") -> str:
    return f"""
name = "clamps-check"
[model]
modes = {modes}
[clamps]
rotation = "{rotation}"
{extra}
[cable]
damping_ratio = {ZETA}
inertia = 2.865e-12
[base]
acceleration_g = {level_g}
frequency_ratio = {ratio}
[solver]
t_end = {t_end}
rtol = 1e-10
[metrics]
tail = 0.25
[axes]
length = [{LENGTH}]
"""


def _one(ds, name: str) -> float:
    """The value of variable `name` at the scene's one point."""
    return float(ds[name].squeeze())


def _textbook(n_modes: int, cable: g.Cable) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(w_n (rad/s), Gamma_n = int phi / int phi^2, phi_n(l/2)) of the clamped span's modes
    1..N from tests/galerkin.py's textbook shapes (their b_n l from cos(b l) cosh(b l) = 1),
    by a fine Gauss-Legendre rule."""
    shapes = g.clamped_shapes(n_modes, cable.length)
    x, w = np.polynomial.legendre.leggauss(200)
    x, w = 0.5 * cable.length * (x + 1.0), 0.5 * cable.length * w
    phi = np.array([s(x, 0) for s in shapes])
    gamma = (phi @ w) / (phi ** 2 @ w)
    mid = np.array([float(s(cable.length / 2.0, 0)) for s in shapes])
    # w_n^2 = EI b_n^4 / rho A, b_n^4 = (4th derivative of phi) / phi, anywhere phi is not 0
    b4 = np.array([float(s(x[7], 4) / s(x[7], 0)) for s in shapes])
    ei_rho = cable.youngs_modulus * cable.inertia / (cable.density * cable.area)
    return np.sqrt(b4 * ei_rho), gamma, mid


def _linear_midspan(n_modes: int, ratio: float, level_g: float) -> tuple[float, float]:
    """(mode 1's steady amplitude, the midspan's) of the linearised clamped span at
    f = ratio f1, A = level_g g: q_n = Gamma_n A / (w_n^2 - w^2 + 2 i zeta w_n w), midspan =
    |sum phi_n(l/2) q_n| (the modes' phases added), mode 1 scaled to its midspan value."""
    cable = g.Cable(length=LENGTH, damping_ratio=ZETA)
    omega_n, gamma, mid = _textbook(n_modes, cable)
    omega = ratio * omega_n[0]
    accel = level_g * 9.80665
    q = gamma * accel / (omega_n ** 2 - omega ** 2 + 2j * ZETA * omega_n * omega)
    return abs(q[0] * mid[0]), abs(np.sum(q * mid))


@pytest.mark.parametrize("modes", [1, 3])
@pytest.mark.parametrize("ratio", [0.5, 1.0, 1.6])
def test_the_linear_clamped_span_is_the_textbook_response(modes, ratio):
    """At 1e-5 g the clamped span is linear to 1e-7: its midspan amplitude, and mode 1's
    (modal_amplitude, scaled to the midspan), equal the closed-form steady response of the
    textbook modes below (0.5 f1), at and above (1.6 f1) resonance, f1 the clamped span's own
    (natural_frequency = (4.73004 / pi)^2 x the pinned span's)."""
    ds = sweep.run(scene(modes=modes, ratio=ratio), progress=False)
    cable = g.Cable(length=LENGTH)
    omega_n, _, _ = _textbook(3, cable)
    assert _one(ds, "natural_frequency") == pytest.approx(omega_n[0] / (2 * math.pi),
                                                           rel=1e-9)
    assert _one(ds, "buckling_load") == pytest.approx(
        4 * math.pi ** 2 * cable.youngs_modulus * cable.inertia / LENGTH ** 2, rel=2e-4)
    mode1, midspan = _linear_midspan(modes, ratio, 1e-5)
    assert str(ds["state"].attrs["flag_meanings"].split()[int(ds["state"].squeeze())]) == "steady"
    assert _one(ds, "amplitude") == pytest.approx(midspan, rel=1e-4)
    if modes > 1:
        assert float(ds["modal_amplitude"].sel(mode=1).squeeze()) == pytest.approx(mode1, rel=1e-4)
        np.testing.assert_allclose(ds["modal_frequency"].values.ravel(),
                                   omega_n / (2 * math.pi), rtol=1e-9)
        assert _one(ds, "linear_amplitude") == pytest.approx(midspan, rel=1e-9)   # N modes
    else:
        assert _one(ds, "linear_amplitude") == pytest.approx(mode1, rel=1e-9)


@pytest.mark.parametrize("overrides, words", [
    ({"clamps.rotation": "elastic"}, ["clamps.rotation", "rotational_stiffness"]),
    ({"clamps.rotational_stiffness": 0.5}, ["clamps.rotational_stiffness", "elastic"]),
    ({"clamps.rotation": "clamped", "clamps.rotational_stiffness": 0.5},
     ["rotational_stiffness", "'clamped'"]),
    ({"axes.clamp_rotational_stiffness": [0.1, 1.0]}, ["clamp_rotational_stiffness", "elastic"]),
    ({"clamps.rotation": "hinged"}, ["clamps.rotation", "hinged"]),
    ({"clamps.rotation": "elastic", "clamps.rotational_stiffness": -1.0},
     ["clamps.rotational_stiffness"]),
])
def test_bad_clamps_are_one_clear_line(overrides, words):
    with pytest.raises(SceneError) as info:
        sweep.load_scene("harness-base-sine", overrides=overrides)
    message = str(info.value)
    assert "\n" not in message
    for word in words:
        assert word in message, message


@pytest.mark.parametrize("name, overrides, words", [
    ("paper-fig5", {"clamps.rotation": "clamped"}, ["clamps.rotation", "paper"]),
    ("paper-fig7", {"clamps.rotation": "clamped"}, ["clamps.rotation", "transverse"]),
])
def test_clamps_a_scene_cannot_honour_are_refused(name, overrides, words):
    """The paper's Eq.32 is the pinned span's and a longitudinal scene has no bending modes:
    each refuses other clamps in one line (the Floquet chart takes any clamps:
    tests/test_floquet_coupled.py)."""
    with pytest.raises(SceneError) as info:
        sweep.load_scene(name, overrides=overrides)
    message = str(info.value)
    assert "\n" not in message
    for word in words:
        assert word in message, message


# --- elastic ends: a rotational spring K = k_t l / EI at each clamp -------------------------

EI = 1.1e11 * 2.865e-12        # N m^2 of the scene's cable


def _symmetric_parts(b: float, u: np.ndarray) -> tuple[np.ndarray, ...]:
    """phi = cos(b u) + c cosh(b u), c = -cos(b/2) / cosh(b/2), and its first three
    derivatives in u (= s - 1/2)."""
    c = -math.cos(b / 2) / math.cosh(b / 2)
    return (np.cos(b * u) + c * np.cosh(b * u),
            b * (-np.sin(b * u) + c * np.sinh(b * u)),
            b * b * (-np.cos(b * u) + c * np.cosh(b * u)),
            b ** 3 * (np.sin(b * u) + c * np.sinh(b * u)))


def _symmetric_modes(stiffness: float, count: int) -> list[tuple[float, Callable]]:
    """The symmetric modes of the span with springs K at both ends, written about midspan
    (u = s - 1/2): phi = cos(b u) + c cosh(b u), c = -cos(b/2) / cosh(b/2) (phi = 0 at the
    ends), b the roots of phi''(end) + K phi'(end) = 0 at u = 1/2 (brentq on a scan): another
    formulation than sweep.models.basis's (its 4 x 4 determinant over the whole span).
    Returns (b, phi(s)) for the first `count`; `_symmetric_parts(b, u)` gives phi and its
    first three derivatives in s."""
    from scipy.optimize import brentq

    parts = _symmetric_parts

    def residual(b: float) -> float:
        _, d1, d2, _ = parts(b, np.array(0.5))
        return float(d2 + stiffness * d1) / (b * b + stiffness * b)

    grid = np.linspace(0.5, 40.0, 40000)
    values = [residual(b) for b in grid]
    roots = []
    for k in range(len(grid) - 1):
        if values[k] * values[k + 1] < 0 and abs(values[k] - values[k + 1]) < 1.0:
            roots.append(brentq(residual, grid[k], grid[k + 1], xtol=1e-14))
        if len(roots) == count:
            break
    return [(b, lambda s, b=b: parts(b, np.asarray(s) - 0.5)[0]) for b in roots]


@pytest.mark.parametrize("stiffness, table", [(1.0, 1.170), (10.0, 1.750), (100.0, 2.183)])
def test_elastic_ends_give_the_spring_table_frequency(stiffness, table):
    """f1 over the pinned span's f1 (docs/model.md sec. 10's spring table, 3 digits) equals
    (b_1 l / pi)^2 of the symmetric formulation written here, to 1e-9."""
    ds = sweep.run(scene("elastic", t_end=0.2,
                         extra=f"rotational_stiffness = {stiffness * EI / LENGTH!r}"),
                   progress=False)
    pinned = sweep.run(scene("pinned", t_end=0.2), progress=False)
    ratio = _one(ds, "natural_frequency") / _one(pinned, "natural_frequency")
    assert ratio == pytest.approx(table, abs=6e-4)
    b1 = _symmetric_modes(stiffness, 1)[0][0]
    assert ratio == pytest.approx((b1 / math.pi) ** 2, rel=1e-9)


@pytest.mark.parametrize("modes", [1, 3])
@pytest.mark.parametrize("ratio", [0.5, 1.0, 1.6])
def test_the_linear_elastic_span_is_the_closed_form_response(modes, ratio):
    """K = 10: the linearised span's midspan amplitude against the closed-form steady response
    of the symmetric modes written here (their b, participations int phi / int phi^2 and
    midspan values by quadrature; the antisymmetric ones are not excited), below, at and
    above its own resonance."""
    stiffness = 10.0
    ds = sweep.run(scene("elastic", modes=modes, ratio=ratio,
                         extra=f"rotational_stiffness = {stiffness * EI / LENGTH!r}"),
                   progress=False)
    symmetric = _symmetric_modes(stiffness, 2 if modes == 3 else 1)
    x, w = np.polynomial.legendre.leggauss(200)
    s, w = (x + 1.0) / 2.0, w / 2.0
    rho_a = 8900.0 * 6e-6
    omega_n = np.array([(b / LENGTH) ** 2 * math.sqrt(EI / rho_a) for b, _ in symmetric])
    gamma = np.array([(phi(s) @ w) / (phi(s) ** 2 @ w) for _, phi in symmetric])
    mid = np.array([float(phi(0.5)) for _, phi in symmetric])
    omega = ratio * omega_n[0]
    q = gamma * 1e-5 * 9.80665 / (omega_n ** 2 - omega ** 2 + 2j * ZETA * omega_n * omega)
    assert _one(ds, "amplitude") == pytest.approx(abs(np.sum(q * mid)), rel=1e-4)
    assert _one(ds, "linear_amplitude") == pytest.approx(abs(np.sum(q * mid)), rel=1e-9)
    # the loads of the steady complex shape W(s) = sum q_n phi_n(s) (derivatives in s): the
    # curvatures |W''| / l^2, the reaction EI |W'''(0)| / l^3 (N W' is of order q^3: nil) and
    # the tension's peak k_s (int |W'|^2 + |int W'^2|) / (4 l) over a cycle, k_s = EA / l
    def shape(u, k):
        return sum(qn * _symmetric_parts(b, np.asarray(u) - 0.5)[k]
                   for qn, (b, _) in zip(q, symmetric))
    d = math.sqrt(4 * 6e-6 / math.pi)
    assert _one(ds, "midspan_bending_strain") == pytest.approx(
        d / 2 * abs(shape(0.5, 2)) / LENGTH ** 2, rel=1e-4)
    assert _one(ds, "clamp_bending_strain") == pytest.approx(
        d / 2 * abs(shape(0.0, 2)) / LENGTH ** 2, rel=1e-4)
    # the reaction with the base inertia the modes leave out: -rho A l r a_b at x = 0
    # (r = 1/2 - sum Gamma_n int (1 - s) phi_n ds, a_b = A sin: in phase with q's forcing)
    left_out = 0.5 - sum(gn * ((phi(s) * (1.0 - s)) @ w) for gn, (_, phi) in zip(gamma, symmetric))
    reaction = EI * shape(0.0, 3) / LENGTH ** 3 - rho_a * LENGTH * left_out * 1e-5 * 9.80665
    assert _one(ds, "clamp_force") == pytest.approx(abs(reaction), rel=1e-4)
    slope = shape(s, 1)
    peak_e = ((np.abs(slope) ** 2 @ w) + abs(slope ** 2 @ w)) / (4 * LENGTH)
    assert _one(ds, "axial_tension") == pytest.approx(1.1e11 * 6e-6 / LENGTH * peak_e,
                                                      rel=1e-3)


@pytest.mark.parametrize("driver", ["lanes", "scalar"])
def test_an_elastic_grid_is_its_points_run_alone(driver):
    """Where K varies over the grid (lengths x spring stiffness) each point's modes are its
    own: every point of the grid equals the same point run alone on the same driver, to the
    bit (the lanes run the grid's four bases in one call, each lane on its own), and f1 rises
    with the spring from the pinned span's towards the clamped one's."""
    base = {"clamps.rotation": "elastic", "model.modes": 3, "solver.t_end": 0.6,
            "base.acceleration_g": 0.5, "base.frequency_ratio": 0.9, "solver.driver": driver}
    text = scene_text("elastic", modes=3)
    grid = sweep.run(sweep.load_scene_text(text, overrides={
        **base, "axes.length": [0.3, 0.45], "axes.clamp_rotational_stiffness": [0.1, 10.0]}),
        progress=False)
    for length in (0.3, 0.45):
        for k_t in (0.1, 10.0):
            alone = sweep.run(sweep.load_scene_text(text, overrides={
                **base, "axes.length": [length], "clamps.rotational_stiffness": k_t}),
                progress=False)
            at = grid.sel(length=length, clamp_rotational_stiffness=k_t)
            for name in ("amplitude", "modal_amplitude", "natural_frequency", "n_steps"):
                np.testing.assert_array_equal(at[name].values,
                                              alone[name].squeeze("length").values, name)
    f1 = grid["natural_frequency"].sel(length=0.45).values
    pinned = sweep.run(sweep.load_scene_text(text, overrides={
        **base, "clamps.rotation": "pinned", "axes.length": [0.45]}), progress=False)
    f_pinned = _one(pinned, "natural_frequency")
    assert f_pinned < f1[0] < f1[1] < 2.267 * f_pinned


def test_design_refines_an_elastic_span_on_its_own_frequency(tmp_path):
    """With elastic clamps K = k_t l / EI grows with the span, so f1 is not ~ l^-2 and the
    log-log interpolation that is exact between pins is not: --refine finds the length where
    the span's own f1 (from the symmetric formulation written here) crosses the limit, to the
    tolerance."""
    from sweep.design import refine_span
    k_t = 1.0
    text = scene_text("elastic", t_end=0.2, extra=f"rotational_stiffness = {k_t}")
    ds = sweep.run(sweep.load_scene_text(text, overrides={"axes.length": [0.2, 0.3, 0.4]}),
                   output=tmp_path / "r.nc", progress=False)
    out = refine_span(ds, min_frequency=60.0, tolerance=1e-5)
    span = float(out["max_span"])
    assert str(out["limited_by"].values) == "min_frequency"
    rho_a = 8900.0 * 6e-6

    def f1(length: float) -> float:
        b = _symmetric_modes(k_t * length / EI, 1)[0][0]
        return (b / length) ** 2 * math.sqrt(EI / rho_a) / (2 * math.pi)

    assert f1(span) >= 60.0 > f1(span + 2e-5)
    grid_guess = float(np.exp(np.interp(np.log(60.0), np.log(ds["natural_frequency"].values[::-1]),
                                        np.log(ds["length"].values[::-1]))))
    assert abs(grid_guess - span) > 1e-4       # the pinned span's shortcut would miss it


def test_the_file_says_what_the_clamps_hold_and_how_the_span_stretches(tmp_path):
    """Global attributes `clamps` and `stretching` name the ends and the stretching a run used
    (with the values given), and the mode coordinate names the span's own modes."""
    import xarray as xr
    cases = [("clamped", "axial_stiffness = 2e5", 3, ["clamped", "no rotation"],
              ["uniform tension", "200000 N/m"]),
             ("elastic", "rotational_stiffness = 0.5", 1, ["elastic", "0.5 N m/rad"],
              ["uniform tension", "immovable"]),
             ("pinned", "", 1, ["pinned", "sin(n pi x/l)"], ["uniform tension", "immovable"])]
    for rotation, extra, modes, clamps, stretching in cases:
        out = tmp_path / f"{rotation}.nc"
        sweep.run(scene(rotation, modes=modes, t_end=0.2, extra=extra), output=out,
                  progress=False)
        with xr.open_dataset(out) as ds:
            for word in clamps:
                assert word in ds.attrs["clamps"], ds.attrs["clamps"]
            for word in stretching:
                assert word in ds.attrs["stretching"], ds.attrs["stretching"]
            if modes > 1:
                full = ds["mode"].attrs["long_name"] + ds["mode"].attrs.get("comment", "")
                assert "clamped-clamped" in full       # the label, or the whole text in comment
    paper = sweep.run(sweep.load_scene_text(scene_text("pinned", t_end=0.2).replace(
        "[model]", "[model]\nmembrane = 0.375")), progress=False)
    assert "local membrane" in paper.attrs["stretching"] and "0.375" in paper.attrs["stretching"]


def test_a_sine_sweep_with_elastic_clamps_runs_each_way():
    """A logarithmic sweep (base.sweep.direction) of a span with elastic clamps: it ran into an
    IndexError sizing its rows (the basis of no points). Each direction equals that direction
    run alone, and clamps of a vanishing stiffness (K = 1e-9) answer as pins do, to 1e-6."""
    def swept(text: str) -> str:
        return text.replace("frequency_ratio = 1.0", "sweep = { start = 15.0, stop = 30.0, "
                            "rate = 60.0, direction = \"both\" }").replace("t_end = 1.0\n", "")
    text = swept(scene_text("elastic", modes=1, level_g=0.5, t_end=1.0,
                            extra=f"rotational_stiffness = {1e-9 * EI / LENGTH!r}"))
    both = sweep.run(sweep.load_scene_text(text), progress=False)
    for direction in ("up", "down"):
        alone = sweep.run(sweep.load_scene_text(text.replace('"both"', f'"{direction}"')),
                          progress=False)
        got = both.sel(direction=direction)
        assert got.peak_amplitude.values.item() == alone.peak_amplitude.values.item()
    pinned = sweep.run(sweep.load_scene_text(swept(scene_text("pinned", modes=1, level_g=0.5,
                                                              t_end=1.0))), progress=False)
    np.testing.assert_allclose(both.peak_amplitude.values.ravel(),
                               pinned.peak_amplitude.values.ravel(), rtol=1e-6)


@pytest.mark.parametrize("ratio, warned", [(1.0, False), (1.4, False), (2.5, True)])
def test_one_modes_clamp_force_is_warned_of_above_its_resonance(ratio, warned):
    """One mode's clamp_force shaken above 1.6 f1 (where the clamps' inertia opposes the
    span's shear and the modes left out move: -18 to -63 % against five modes at 1.7-3 f1,
    sweep.models.loads) is warned of in one line; at and just above resonance it is not."""
    import warnings

    from sweep.errors import CableSweepWarning
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = sweep.run(scene(ratio=ratio, level_g=1.0, t_end=1.0), progress=False)
    assert np.isfinite(_one(ds, "clamp_force"))
    said = [str(w.message) for w in caught if issubclass(w.category, CableSweepWarning)
            and "clamp_force of one mode" in str(w.message)]
    assert len(said) == (1 if warned else 0), said
    if warned:
        assert "\n" not in said[0] and "model.modes = 3" in said[0]
        assert "1 point(s)" in said[0]


@pytest.mark.parametrize("rotation", ["pinned", "clamped"])
def test_a_span_past_buckling_with_no_base_gets_no_resonance_warning(rotation):
    """A constant end load past buckling (k0 < 0) and no [base]: nothing shakes the span, so
    one mode's clamp_force warning for a span shaken above 1.6 f1 is not said (it was: omega^2
    > 2.56 k0 holds for any omega when k0 < 0); the reaction is the static one, finite."""
    import warnings

    from sweep.errors import CableSweepWarning
    text = scene_text(rotation, t_end=0.5).replace(
        "[base]\nacceleration_g = 1e-05\nfrequency_ratio = 1.0\n",
        "[load]\ntype = \"constant\"\namplitude_ratio = 1.5\n[initial]\n"
        "displacement = 1e-4\n")
    assert "[base]" not in text and "amplitude_ratio" in text
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = sweep.run(sweep.load_scene_text(text), progress=False)
    said = [str(w.message) for w in caught if issubclass(w.category, CableSweepWarning)
            and "clamp_force of one mode" in str(w.message)]
    assert not said, said
    assert np.isfinite(_one(ds, "clamp_force")) and _one(ds, "clamp_force") > 0.0


PEAKS_BESIDE_THE_AMPLITUDE = ("amplitude", "modal_amplitude", "max_deflection",
                              "max_deflection_position", "clamp_bending_strain", "clamp_moment",
                              "clamp_force", "midspan_bending_strain", "axial_tension",
                              "axial_strain", "max_strain")


@pytest.mark.parametrize("modes", [1, 2])
def test_outputs_amplitude_governs_every_tail_window_peak(modes):
    """outputs.amplitude is the switch of the tail window's peaks, as its key says: on, a span
    whose clamps hold rotation gets the midspan's amplitude and every peak beside it (each
    mode's, the span's largest deflection, the loads; one mode: no modal or span variables);
    off, none of them, modal_amplitude included (it was stored alone, beside the loads dropped),
    while the other outputs stay."""
    text = scene_text("elastic", modes=modes, level_g=0.5, t_end=0.4,
                      extra="rotational_stiffness = 1.0")
    multi = {"modal_amplitude", "max_deflection", "max_deflection_position"}
    expected = {n for n in PEAKS_BESIDE_THE_AMPLITUDE if modes > 1 or n not in multi}
    on = sweep.run(sweep.load_scene_text(text), progress=False)
    assert expected <= set(on.data_vars), expected - set(on.data_vars)
    off = sweep.run(sweep.load_scene_text(text, overrides={"outputs.amplitude": False}),
                    progress=False)
    assert not set(PEAKS_BESIDE_THE_AMPLITUDE) & set(off.data_vars)
    for name in ("peak_amplitude", "settling_time", "natural_frequency", "state"):
        assert name in off, name
    if modes > 1:
        assert "modal_frequency" in off      # a closed form of the span, not a peak


def test_a_stability_run_with_solver_stats_stores_no_modal_amplitude():
    """outputs.stability with the tail amplitude off and only the solver's counters asked of
    the time domain: no modal_amplitude (it was stored as zeros beside state = decayed, as one
    mode stores no amplitude), the Floquet outputs and counters are."""
    text = """
name = "stability-stats"
[model]
modes = 2
[cable]
damping_ratio = 0.02
length = 1.0
[load]
type = "harmonic"
amplitude = 2.0
[solver]
t_end = 0.5
[axes]
frequency_ratio = [1.0, 2.0]
[outputs]
stability = true
amplitude = false
solver_stats = true
"""
    ds = sweep.run(sweep.load_scene_text(text), progress=False)
    assert "stability" in ds and "n_steps" in ds
    assert "modal_amplitude" not in ds and "amplitude" not in ds


@pytest.mark.parametrize("rotation, quoted, not_quoted", [
    ("pinned", "exact beam", "five modes"), ("clamped", "five modes", "exact beam"),
    ("elastic", "tens of per cent", "%")])
def test_one_modes_clamp_force_warning_reads_cleanly_for_its_ends(rotation, quoted, not_quoted):
    """The warning named a base_acceleration_g axis value as '0.3 9.80665 m s-2' (its units
    attribute after the number) and quoted the clamped span's measured miss on a pinned span:
    it gives the excitation over the span's first frequency in words, a level in g, and the
    measured miss of the span's own ends only (none for elastic ends, which were not
    measured)."""
    import warnings

    from sweep.errors import CableSweepWarning
    extra = "rotational_stiffness = 1.0" if rotation == "elastic" else ""
    text = scene_text(rotation, level_g=0.3, t_end=0.3, extra=extra).replace(
        "frequency_ratio = 1.0", "frequency = 400.0").replace(
        "[axes]", "[axes]\nbase_acceleration_g = [0.3]").replace("acceleration_g = 0.3\n", "")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = sweep.run(sweep.load_scene_text(text), progress=False)
    said = [str(w.message) for w in caught if issubclass(w.category, CableSweepWarning)
            and "clamp_force of one mode" in str(w.message)]
    assert len(said) == 1, said
    ratio = 400.0 / _one(ds, "natural_frequency")
    assert ratio > 1.6
    assert f"at {ratio:.2g} times the span's first natural frequency" in said[0]
    assert "base_acceleration_g 0.3 g" in said[0] and "9.80665" not in said[0]
    assert quoted in said[0] and not_quoted not in said[0]
