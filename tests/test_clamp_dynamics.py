"""The stretching between the clamps and the bending at them ([clamps], docs/model.md sec. 10),
nonlinear, against SciPy's DOP853 on Galerkin equations over the textbook modes written in
tests/galerkin.py (clamped cosh/cos shapes, pinned sines), whose stretching tension is
integrated in the test and whose curvature at the clamp is the shapes' own second derivative:

1. the uniform tension N = k_s e between immovable, elastic and sliding clamps, pinned and
   clamped, one mode and three; one pinned mode has the classical coefficient alpha = 1/4;
2. the curvature at the clamp (clamp_moment / EI, clamp_bending_strain) and the midspan
   amplitude, below, at and above resonance, one mode and three.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import sweep
from sweep.errors import SceneError
from sweep.models import loads, modal

import galerkin as g
from conftest import fast_first
from test_clamps import EI, LENGTH, ZETA, _linear_midspan, _one, _textbook, scene, scene_text

EA = 1.1e11 * 6e-6             # N of the scene's cable


def _scipy(n_modes: int, level_g: float, ratio: float, t_end: float, clamped: bool = True,
           tension: float | None = EA / LENGTH) -> tuple[float, float]:
    """(tail max |w(l/2, t)| (m), tail max |w_xx(0, t)| (1/m)) over [0.75 t_end, t_end]
    (`_scipy_peaks`)."""
    peaks = _scipy_peaks(n_modes, level_g, ratio, t_end, clamped, tension)
    return peaks["midspan"], peaks["clamp_curvature"]


def _scipy_peaks(n_modes: int, level_g: float, ratio: float, t_end: float,
                 clamped: bool = True, tension: float | None = EA / LENGTH) -> dict[str, float]:
    """Tail maxima over [0.75 t_end, t_end] of the span from rest under base excitation
    level_g at ratio x its f1, by SciPy DOP853 on Galerkin equations over the textbook modes
    (clamped cosh/cos or pinned sines), stretching by the uniform tension k_s e (tension = k_s,
    N/m; default the immovable clamps' EA / l): |w(l/2)| (m, midspan), |w_xx(0)| (1/m,
    clamp_curvature), |w_xx(l/2)| (midspan_curvature), N = k_s (1/2) int w_x^2 dx (N, tension,
    the integral by Gauss-Legendre here) and the reaction at either clamp (N, force:
    `_peaks_of`), each located at the sign change of its own rate (brentq)."""
    from scipy.integrate import solve_ivp
    cable = g.Cable(length=LENGTH, damping_ratio=ZETA)
    if clamped:
        omega_n = _textbook(n_modes, cable)[0]
        shapes = g.clamped_shapes(n_modes, LENGTH)
    else:
        omega_n = np.arange(1, n_modes + 1) ** 2 * cable.w1
        shapes = g.sine_shapes(n_modes, LENGTH)
    f = g.shapes_rhs(cable, shapes, omega_n, level_g * 9.80665,
                     ratio * omega_n[0] / (2 * math.pi), tension_stiffness=tension)
    sol = solve_ivp(f, (0.0, t_end), np.zeros(2 * n_modes), method="DOP853", rtol=1e-10,
                    atol=1e-15, dense_output=True).sol
    level, w_b = level_g * 9.80665, ratio * omega_n[0]
    base = (lambda s: level * np.sin(w_b * s), lambda s: level * w_b * np.cos(w_b * s), level)
    return _peaks_of(sol, n_modes, shapes, np.linspace(0.75 * t_end, t_end, 20001), tension,
                     base)


def _peaks_of(sol, n: int, shapes: list, t: np.ndarray, tension: float | None,
              base: tuple) -> dict[str, float]:
    """`_scipy_peaks`' maxima over the times t (s) of a dense solution `sol` of the Galerkin
    equations on `shapes` (k_s = tension, N/m, None: no stretching) under the base
    acceleration base = (a_b(t), a_b'(t), its peak) (m/s^2): the reaction at either clamp,
    V = -EI w_xxx + N w_x with the mode-acceleration correction, the parts of the loads the
    modes leave out carried to the clamps as statically (`force`: the axial load's through
    galerkin.axial_reaction in place of w_x, the base inertia's -+ rho A l r a_b(t) at x = 0,
    l, r from galerkin.reaction_left_out on these shapes), and, for one mode's bound, the
    modes' part's peak (`force_modes`) and that part's (`left_out`)."""
    rho_a_l_r = (8900.0 * 6e-6 * LENGTH) * g.reaction_left_out(shapes, LENGTH)
    accel, jerk, peak_level = base
    x, w = np.polynomial.legendre.leggauss(60)
    x, w = 0.5 * LENGTH * (x + 1.0), 0.5 * LENGTH * w
    slopes = np.array([s(x, 1) for s in shapes])
    axial = (slopes * w) @ slopes.T                        # int phi_i' phi_j' dx (1/m)
    k_s = 0.0 if tension is None else tension
    mid = np.array([float(s(LENGTH / 2.0, 0)) for s in shapes])
    at_clamp = np.array([float(s(0.0, 2)) for s in shapes])
    bend_mid = np.array([float(s(LENGTH / 2.0, 2)) for s in shapes])
    ends = list(zip([np.array([float(s(e, 3)) for s in shapes]) for e in (0.0, LENGTH)],
                    g.axial_reaction(shapes, LENGTH)))       # the shear's, the axial load's

    def linear(weights: np.ndarray) -> float:
        return g._tail_max(lambda s: weights @ sol(s)[:n], lambda s: weights @ sol(s)[n:], t)

    def tension_of(s):
        y = sol(s)
        q, v = y[:n], y[n:]
        return (k_s * 0.5 * np.einsum("i...,ij,j...->...", q, axial, q),
                k_s * np.einsum("i...,ij,j...->...", q, axial, v))

    def force(s, e, inertia=1.0):
        y = sol(s)
        q, v = y[:n], y[n:]
        third, slope = ends[e]
        big_n, rate_n = tension_of(s)
        sign = inertia * (-1.0 if e == 0 else 1.0)
        value = -EI * (third @ q) + big_n * (slope @ q) + sign * rho_a_l_r * accel(s)
        rate = (-EI * (third @ v) + rate_n * (slope @ q) + big_n * (slope @ v)
                + sign * rho_a_l_r * jerk(s))
        return value, value * rate                     # d|V|/dt has the sign of V V'

    return {"midspan": linear(mid), "clamp_curvature": linear(at_clamp),
            "midspan_curvature": linear(bend_mid),
            "tension": g._tail_max(lambda s: tension_of(s)[0], lambda s: tension_of(s)[1], t),
            "force": max(g._tail_max(lambda s, e=e: force(s, e)[0],
                                     lambda s, e=e: force(s, e)[1], t) for e in (0, 1)),
            "force_modes": max(g._tail_max(lambda s, e=e: force(s, e, 0.0)[0],
                                           lambda s, e=e: force(s, e, 0.0)[1], t)
                               for e in (0, 1)),
            "left_out": rho_a_l_r * peak_level}


@pytest.mark.parametrize("rotation", fast_first(["pinned", "clamped"], "clamped"))
@pytest.mark.parametrize("axial, modes", fast_first([(None, 1), (None, 3), (2e5, 3), (0.0, 3),
                                                     (2e5, 1)], (2e5, 3)))
def test_the_uniform_tension_matches_scipy(rotation, axial, modes):
    """The span stretches as a whole between its clamps: N = k_s e, e = (1/2) int w_x^2 dx,
    1 / k_s = l / EA + 2 / k_a (immovable clamps: k_s = EA / l; k_a = 0: no stretching). The
    midspan amplitude at 1 g and resonance against SciPy with the tension integrated in the
    test, to 1e-6, pinned and clamped, one mode and three (modes 1 and 3 couple through it)."""
    extra = "" if axial is None else f"axial_stiffness = {axial!r}"
    ds = sweep.run(scene(rotation, modes=modes, level_g=1.0, ratio=1.0, t_end=1.5,
                         extra=extra), progress=False)
    k_s = EA / LENGTH if axial is None else EA * axial / (axial * LENGTH + 2.0 * EA)
    midspan, _ = _scipy(modes, 1.0, 1.0, 1.5, clamped=rotation == "clamped", tension=k_s)
    assert _one(ds, "amplitude") == pytest.approx(midspan, rel=1e-6)


def test_one_pinned_mode_between_immovable_clamps_has_the_classical_coefficient():
    """One pinned mode: the uniform tension between immovable clamps is the local term with
    alpha = 1/4 (the classical coefficient, docs/model.md sec. 10.4), to round-off: the cubic
    coefficients differ by their bending terms alone, the span's energy's -(3/2)(EI/rho A) k^6
    against Eq.17's -(5/4), which model.membrane keeps (docs/model.md sec. 7; since issue 35
    the two spans no longer share them, so their amplitudes differ by the bending terms' share,
    below 1e-4 here), where the paper's 3/8 gives a stiffer span."""
    text = scene_text("pinned", level_g=1.0, ratio=1.0, t_end=1.5)
    uniform = _one(sweep.run(sweep.load_scene_text(text), progress=False), "amplitude")
    quarter, paper = (_one(sweep.run(sweep.load_scene_text(text, overrides={
        "model.membrane": alpha}), progress=False), "amplitude") for alpha in (0.25, 0.375))
    p = {"youngs_modulus": 1.1e11, "density": 8900.0, "area": 6e-6, "inertia": 2.865e-12,
         "length": LENGTH, "load_amplitude": 0.0}
    bending = EI / (8900.0 * 6e-6) * (math.pi / LENGTH) ** 6
    g_uniform = modal.consistent(p)["g"] + 1.5 * bending
    g_quarter = modal.consistent({**p, "membrane": 0.25})["g"] + 1.25 * bending
    assert g_uniform == pytest.approx(g_quarter, rel=1e-12)
    assert uniform == pytest.approx(quarter, rel=1e-4)
    assert paper < 0.95 * uniform


@pytest.mark.parametrize("modes", fast_first([1, 3], 3))
@pytest.mark.parametrize("ratio", fast_first([0.5, 1.0, 1.6], 1.0))
def test_the_clamped_span_and_its_clamp_bending_match_scipy(modes, ratio):
    """The clamped span at 2 g, between immovable clamps: below (0.5 f1), at and above (1.6
    f1) resonance, one mode and three. Its midspan amplitude and clamp_moment / EI, the largest
    curvature at a clamp over the tail window, equal SciPy's on the textbook modes (their own
    phi''(0)) to 1e-6; near resonance the stretching moves the amplitude more than 5 % from
    the linear one. clamp_bending_strain is (d / 2) times the curvature, d the solid section's
    by default and the scene's cable.diameter when given."""
    ds = sweep.run(scene(modes=modes, ratio=ratio, level_g=2.0, t_end=1.5), progress=False)
    peaks = _scipy_peaks(modes, 2.0, ratio, 1.5)
    midspan, curvature = peaks["midspan"], peaks["clamp_curvature"]
    if ratio == 1.0:
        assert abs(_linear_midspan(modes, ratio, 2.0)[1] / midspan - 1.0) > 0.05
    assert _one(ds, "amplitude") == pytest.approx(midspan, rel=1e-6)
    kappa = _one(ds, "clamp_moment") / EI
    assert kappa == pytest.approx(curvature, rel=1e-6)
    _check_loads(ds, peaks, modes)
    assert _one(ds, "clamp_bending_strain") == pytest.approx(
        math.sqrt(4 * 6e-6 / math.pi) / 2 * kappa, rel=1e-12)
    thick = sweep.run(sweep.load_scene_text(scene_text(
        modes=modes, ratio=ratio, level_g=2.0, t_end=1.5).replace(
        "[cable]", "[cable]\ndiameter = 0.004")), progress=False)
    assert _one(thick, "clamp_bending_strain") == pytest.approx(0.002 * kappa, rel=1e-9)


def _check_loads(ds, peaks: dict[str, float], modes: int = 3) -> None:
    """The span's loads against SciPy's peaks (`_scipy_peaks`), to 1e-6: the midspan bending
    strain (d / 2 the solid section's), the stretching tension and strain, the clamp's
    reaction (one mode, from its steady phase: within 5e-3 of the peak in time, which the
    nonlinear span's harmonics move, and never above the bound of its two parts' peaks
    added), and max_strain from its parts."""
    d = math.sqrt(4 * 6e-6 / math.pi)
    assert _one(ds, "midspan_bending_strain") == pytest.approx(
        d / 2 * peaks["midspan_curvature"], rel=1e-6)
    assert _one(ds, "axial_tension") == pytest.approx(peaks["tension"], rel=1e-6)
    assert _one(ds, "axial_strain") == pytest.approx(peaks["tension"] / EA, rel=1e-6)
    if modes == 1:
        bound = peaks["force_modes"] + peaks["left_out"]
        assert _one(ds, "clamp_force") <= bound * (1.0 + 1e-9)
        assert _one(ds, "clamp_force") == pytest.approx(peaks["force"], rel=5e-3)
    else:
        assert _one(ds, "clamp_force") == pytest.approx(peaks["force"], rel=1e-6)
    bending = max(peaks["clamp_curvature"], peaks["midspan_curvature"]) * d / 2
    assert _one(ds, "max_strain") == pytest.approx(bending + peaks["tension"] / EA, rel=1e-6)


@pytest.mark.parametrize("modes, ratio", fast_first([(1, 1.0), (3, 0.5), (3, 1.0)], (3, 1.0)))
def test_a_pinned_span_reports_its_tension_reaction_and_midspan_strain(modes, ratio):
    """Pinned ends between immovable clamps: no bending at the clamps, but the midspan bending
    strain, the stretching tension and the clamp's reaction (whose stretching part N w_x is
    largest at a pin) against SciPy on sines, below and at resonance, one mode and three."""
    ds = sweep.run(scene("pinned", modes=modes, ratio=ratio, level_g=2.0, t_end=1.5),
                   progress=False)
    peaks = _scipy_peaks(modes, 2.0, ratio, 1.5, clamped=False)
    assert peaks["clamp_curvature"] == 0.0 and "clamp_bending_strain" not in ds
    assert _one(ds, "amplitude") == pytest.approx(peaks["midspan"], rel=1e-6)
    _check_loads(ds, peaks, modes)


def test_pinned_clamps_bend_nothing_and_the_paper_membrane_takes_no_diameter():
    """Pinned ends have no curvature at the clamps: no clamp bending outputs; the midspan strain
    takes the scene's diameter; under the paper's local membrane term a pinned span reports no
    strain, so a diameter there is refused in one line."""
    text = scene_text("pinned", t_end=0.2)
    ds = sweep.run(scene("pinned", t_end=0.2), progress=False)
    assert "clamp_bending_strain" not in ds and "clamp_moment" not in ds
    thick = sweep.run(sweep.load_scene_text(text.replace("[cable]", "[cable]\ndiameter = 0.004")),
                      progress=False)
    assert _one(thick, "midspan_bending_strain") == pytest.approx(
        _one(ds, "midspan_bending_strain") * 0.004 / math.sqrt(4 * 6e-6 / math.pi), rel=1e-12)
    with pytest.raises(SceneError) as info:
        sweep.load_scene_text(text.replace("[cable]", "[cable]\ndiameter = 0.004"),
                              overrides={"model.membrane": 0.375})
    assert "cable.diameter" in str(info.value) and "\n" not in str(info.value)


def test_the_paper_preset_reports_no_loads_of_a_tension_it_does_not_integrate():
    """model.coefficients = 'paper' is Eq.32 as printed, whose numbers hold the paper's local
    membrane term (alpha = 3/8), not the uniform tension the loads are made from: paper-fig5
    reported axial_tension, clamp_force and strains of a model it did not run (a reviewer's
    finding); the same span with the consistent coefficients reports them."""
    paper = sweep.run(sweep.load_scene("paper-fig5", {"axes.length": [0.5]}), progress=False)
    assert not set(loads.NAMES) & set(paper.data_vars)
    assert "Eq.32" in paper.attrs["stretching"]
    consistent = sweep.run(sweep.load_scene("paper-fig5", {"axes.length": [0.5],
                                                           "model.coefficients": "consistent"}),
                           progress=False)
    assert {"axial_tension", "clamp_force", "midspan_bending_strain"} <= set(consistent)
    with pytest.raises(SceneError) as info:
        sweep.load_scene("paper-fig5", {"axes.length": [0.5], "cable.diameter": 0.003})
    assert "cable.diameter" in str(info.value) and "'paper'" in str(info.value)
    for axial in ({"clamps.axial_stiffness": 0.0}, {"axes.clamp_axial_stiffness": [0.0, 1e5]}):
        with pytest.raises(SceneError) as info:       # it was ignored: identical columns
            sweep.load_scene("paper-fig5", {"axes.length": [0.5], **axial})
        assert "axial_stiffness" in str(info.value) and "'paper'" in str(info.value)


@pytest.mark.parametrize("method, driver", fast_first([("dop853", "lanes"), ("rk45", "scalar")],
                                                      ("dop853", "lanes")))
def test_each_method_and_driver_gives_the_clamped_span_and_its_bending(method, driver):
    """The other method (DOP853) and the other driver (scalar) on the clamped span between
    immovable clamps at resonance, three modes: midspan amplitude and curvature at the clamp
    against the same SciPy reference, to 1e-6."""
    text = scene_text(modes=3, ratio=1.0, level_g=2.0, t_end=1.5)
    ds = sweep.run(sweep.load_scene_text(text, overrides={"solver.method": method,
                                                          "solver.driver": driver}),
                   progress=False)
    peaks = _scipy_peaks(3, 2.0, 1.0, 1.5)
    assert _one(ds, "amplitude") == pytest.approx(peaks["midspan"], rel=1e-6)
    assert _one(ds, "clamp_moment") / EI == pytest.approx(peaks["clamp_curvature"], rel=1e-6)
    _check_loads(ds, peaks)


def test_sweep_modes_compares_the_bending_at_the_clamp(tmp_path, capsys):
    """`sweep modes` on clamped ends reports every load beside the midspan (it left out all but
    the clamp's bending: a reviewer's clamp_force moved 6.5 % from 3 to 5 modes unreported):
    each line gives the largest relative change between the two runs, recomputed here from two
    plain runs (the curvature at a clamp converges more slowly with the modes, its shear more
    slowly still)."""
    from sweep.cli import main
    path = tmp_path / "clamped.toml"
    path.write_text(scene_text(modes=1, ratio=1.0, level_g=2.0, t_end=1.5))
    assert main(["modes", str(path), "-q", "--tolerance", "0.001"]) == 0
    out = capsys.readouterr().out
    coarse, fine = (sweep.run(sweep.load_scene(str(path), overrides={"model.modes": n}),
                              progress=False) for n in (1, 3))
    names = [name for name in loads.NAMES if name in fine]
    assert {"clamp_bending_strain", "clamp_force", "axial_tension", "max_strain"} <= set(names)
    for name in names:
        f, c = (_one(ds, name) for ds in (fine, coarse))
        change = abs(f - c) / abs(f)
        line = next(line for line in out.splitlines() if line.strip().startswith(f"{name} "))
        assert float(line.split()[1]) == pytest.approx(change, rel=1e-2), name


@pytest.mark.slow
def test_a_sine_sweep_reports_the_loads_peak_over_the_whole_sweep():
    """A logarithmic sweep 40 -> 80 Hz at 60 octaves/min (1 s; the level rising over 10 cycles
    of its start frequency, as kernels/excitation.py defines it) on the clamped span at 2 g,
    three modes, up and down (direction = "both") in a scene that asks for nothing but the
    sweep (no [metrics]: the default outputs of a sweep): each load's peak over the whole
    sweep (not a tail window), for each direction on the `direction` dimension, against SciPy
    on the textbook modes, the chirp written here from its definition, to 1e-6."""
    from scipy.integrate import solve_ivp
    text = scene_text(modes=3, ratio=1.0, level_g=2.0, t_end=1.0)
    text = text.replace("frequency_ratio = 1.0", "sweep = { start = 40.0, stop = 80.0, "
                        "rate = 60.0, direction = \"both\" }").replace("t_end = 1.0\n", "")
    text = text.replace("[metrics]\ntail = 0.25\n", "")
    assert "[metrics]" not in text
    both = sweep.run(sweep.load_scene_text(text), progress=False)
    cable = g.Cable(length=LENGTH, damping_ratio=ZETA)
    omega_n, gamma, mid = _textbook(3, cable)
    shapes = g.clamped_shapes(3, LENGTH)
    free = g.shapes_rhs(cable, shapes, omega_n, tension_stiffness=EA / LENGTH)
    for direction, start, sign in (("up", 40.0, 1.0), ("down", 80.0, -1.0)):
        ds = both.sel(direction=direction)
        lam, rise = sign * 60.0 * math.log(2.0) / 60.0, 10.0 / start

        def chirp(t: float) -> float:
            ramp = 0.5 - 0.5 * math.cos(math.pi * t / rise) if t < rise else 1.0
            return (2.0 * 9.80665 * ramp
                    * math.sin(2.0 * math.pi * start * math.expm1(lam * t) / lam))

        def rhs(t, y):
            f = free(t, y)
            f[3:] -= gamma * chirp(t)
            return f
        def chirp_rate(t: float) -> float:
            u = math.pi * t / rise
            ramp, ramp_rate = ((0.5 - 0.5 * math.cos(u), 0.5 * math.pi / rise * math.sin(u))
                               if t < rise else (1.0, 0.0))
            phase = 2.0 * math.pi * start * math.expm1(lam * t) / lam
            return 2.0 * 9.80665 * (ramp_rate * math.sin(phase) + ramp * 2.0 * math.pi
                                    * start * math.exp(lam * t) * math.cos(phase))
        sol = solve_ivp(rhs, (0.0, 1.0), np.zeros(6), method="DOP853", rtol=1e-10, atol=1e-15,
                        dense_output=True).sol
        peaks = _peaks_of(sol, 3, shapes, np.linspace(0.0, 1.0, 40001), EA / LENGTH,
                          (np.vectorize(chirp), np.vectorize(chirp_rate), 2.0 * 9.80665))
        assert _one(ds, "peak_amplitude") == pytest.approx(peaks["midspan"], rel=1e-6)
        assert _one(ds, "clamp_moment") / EI == pytest.approx(peaks["clamp_curvature"],
                                                              rel=1e-6)
        _check_loads(ds, peaks)
    for name in ("clamp_bending_strain", "clamp_moment", "clamp_force", "axial_tension",
                 "max_strain"):
        assert both[name].dims[0] == "direction"
    assert "over the whole sweep" in ds["clamp_force"].attrs["long_name"]


@pytest.mark.parametrize("modes, kind", [(1, "constant"), (3, "constant"), (3, "harmonic")])
def test_the_clamp_reaction_holds_the_end_load_part(modes, kind):
    """V = -EI w''' + (N - P) w' at the clamp: under an end load P(t) (P0, or P0 cos(W t)) the
    reaction holds -P w_x, largest at a pin (there P0 w_x is 40 % of the shear here). A linear
    span (clamps.axial_stiffness = 0, a base level of 1e-5 g: the cubic terms are 1e-10 of
    the linear ones) against SciPy's DOP853 on the sines' linear Galerkin equations with the
    load's P(t) A q, M, A and G by quadrature here, and the base inertia the modes leave out
    (galerkin.reaction_left_out; one mode from its steady phase, to 1e-3, never above the
    bound of the two parts' peaks added). (For sines the axial part is -P w_x itself.)"""
    from scipy.integrate import solve_ivp
    p0, load_hz, level, ratio, t_end = 7.8, 7.0, 1e-5 * 9.80665, 0.8, 3.0
    extra = (f"axial_stiffness = 0.0\n[load]\ntype = \"{kind}\"\namplitude = {p0}\n"
             + (f"frequency = {load_hz}" if kind == "harmonic" else ""))
    if kind == "constant":
        load_hz = 0.0
    ds = sweep.run(sweep.load_scene_text(scene_text("pinned", modes=modes, level_g=1e-5,
                                                    ratio=ratio, t_end=t_end, extra=extra)),
                   progress=False)
    cable = g.Cable(length=LENGTH, damping_ratio=ZETA)
    rho_a = cable.density * cable.area
    x, w = np.polynomial.legendre.leggauss(200)
    x, w = 0.5 * LENGTH * (x + 1.0), 0.5 * LENGTH * w
    shapes = g.sine_shapes(modes, LENGTH)
    omega = np.arange(1, modes + 1) ** 2 * cable.w1
    phi = np.array([s(x, 0) for s in shapes])
    slope = np.array([s(x, 1) for s in shapes])
    mass = (phi * w) @ phi.T                                   # int phi_i phi_j (m)
    axial = (slope * w) @ slope.T                              # A_ij (1/m)
    gamma = np.linalg.solve(mass, phi @ w)
    coupling = np.linalg.solve(mass, axial) / rho_a
    w_load, w_base = 2 * math.pi * load_hz, ratio * omega[0]

    def rhs(t, y):
        q, v = y[:modes], y[modes:]
        a = (-2 * ZETA * omega * v - omega ** 2 * q + p0 * math.cos(w_load * t) * (coupling @ q)
             - gamma * level * math.sin(w_base * t))
        return np.concatenate((v, a))

    sol = solve_ivp(rhs, (0.0, t_end), np.zeros(2 * modes), method="DOP853", rtol=1e-11,
                    atol=1e-18, dense_output=True).sol
    times = np.linspace(0.75 * t_end, t_end, 20001)
    ends = list(zip([np.array([float(s(e, 3)) for s in shapes]) for e in (0.0, LENGTH)],
                    g.axial_reaction(shapes, LENGTH)))       # the shear's, the axial load's
    left_out = rho_a * LENGTH * g.reaction_left_out(shapes, LENGTH)

    def force(s, e, inertia=1.0, end_load=1.0):
        y = sol(s)
        q, v = y[:modes], y[modes:]
        third, first = ends[e]
        load = end_load * p0 * np.cos(w_load * s)
        rate = -end_load * p0 * w_load * np.sin(w_load * s)
        sign = inertia * (-1.0 if e == 0 else 1.0) * left_out * level
        value = -EI * (third @ q) - load * (first @ q) + sign * np.sin(w_base * s)
        change = (-EI * (third @ v) - rate * (first @ q) - load * (first @ v)
                  + sign * w_base * np.cos(w_base * s))
        return value, value * change

    def peak(inertia, end_load=1.0):
        return max(g._tail_max(lambda s, e=e: force(s, e, inertia, end_load)[0],
                               lambda s, e=e: force(s, e, inertia, end_load)[1], times)
                   for e in (0, 1))

    expected = peak(1.0)
    assert abs(expected / peak(1.0, 0.0) - 1.0) > 0.05      # the end load's part shows
    if modes == 1:            # from the steady phase (sweep.models.loads), within the bound
        assert _one(ds, "clamp_force") <= (peak(0.0) + left_out * level) * (1.0 + 1e-9)
        assert _one(ds, "clamp_force") == pytest.approx(expected, rel=1e-3)
    else:
        assert _one(ds, "clamp_force") == pytest.approx(expected, rel=1e-6)


def test_one_mode_under_a_harmonic_end_load_reports_no_clamp_force():
    """One mode's reaction is read off its peak |q|, which a harmonic end load's -P(t) w_x
    does not follow: NaN (with two modes or more the observers watch it in time)."""
    extra = ("axial_stiffness = 0.0\n[load]\ntype = \"harmonic\"\namplitude = 7.8\n"
             f"frequency = 7.0\n[axes]\nload_amplitude = [0.0, 7.8]\nlength = [{LENGTH}]")
    text = scene_text("pinned", modes=1, level_g=1e-5, ratio=0.8, t_end=1.0, extra=extra)
    ds = sweep.run(sweep.load_scene_text(text.replace(f"[axes]\nlength = [{LENGTH}]\n", "")),
                   progress=False)
    force = ds["clamp_force"].values.ravel()
    assert np.isfinite(force[0]) and np.isnan(force[1])




@pytest.mark.parametrize("modes", [1, 3])
@pytest.mark.parametrize("rotation", ["pinned", "clamped", "elastic"])
def test_the_clamp_reaction_is_the_continuous_beams(rotation, modes):
    """The clamp's transverse reaction against the exact steady state of the continuous
    Euler-Bernoulli beam (tests/exact_beam.py: no modes at all), a linear 0.3 m bundle span
    (no stretching) at 0.1 g below, near and above its own f1, pinned, clamped and elastic
    (0.1 N m/rad) ends: within 3 % with one mode (the modes left out still move a little
    above resonance: 2.6 % clamped at 1.4 f1, 0.4 % pinned) and 2e-3 with three. The modes'
    shear sum alone (without the base inertia the modes leave out) is 6-80 % off here, and
    converges like 1/N. The damping (0.5 %) moves the exact values by about 1e-4 at these ratios; the
    run is 15 / (zeta w1) long, its tail the last 20 %."""
    from exact_beam import BUNDLE_SCENE, first_frequency, steady_loads
    k_end = {"pinned": 0.0, "clamped": None, "elastic": 0.1}[rotation]
    over = {"clamps.rotation": rotation}
    if rotation == "elastic":
        over["clamps.rotational_stiffness"] = 0.1
    w1 = first_frequency(0.3, 0.0534, 0.31515, k_end)
    ds = sweep.run(sweep.load_scene_text(BUNDLE_SCENE, overrides={
        **over, "model.modes": modes, "solver.t_end": 15.0 / (0.005 * w1),
        "run.threads": 1}), progress=False)
    for ratio in (0.3, 0.7, 1.4):
        exact = steady_loads(ratio * w1, 0.1 * 9.80665, 0.3, 0.0534, 0.31515, k_end)[2]
        force = float(ds["clamp_force"].sel(base_frequency_ratio=ratio).squeeze())
        assert force == pytest.approx(exact, rel=3e-2 if modes == 1 else 2e-3), ratio


@pytest.mark.slow
def test_the_clamp_reaction_under_a_random_record_matches_scipy():
    """Three pinned modes between immovable clamps (damping 0.05) under one record of a flat
    random base acceleration (1 s, 0.04 g^2/Hz, 10-500 Hz): the reaction's peak over the statistics
    window, with the base inertia the modes leave out read off the record's own interpolant
    and its rate (kernels.excitation.record_and_rate), against SciPy's DOP853 on the Galerkin
    equations forced by the same Hermite interpolant (sweep.models.random.hermite), the
    force's parts written here (`_peaks_of`, the record's rate by a central difference), to
    1e-5 (the scalar and lanes drivers and both methods, all at rtol 1e-10, land within
    2.4e-6 of it and of each other on this broadband peak of a nonlinear response: their
    round-off grows over the second; the compiled arithmetic moves it too)."""
    from scipy.integrate import solve_ivp
    from sweep.models import random as rnd
    from sweep.models.random_outputs import RandomInputs
    text = "\n".join(["[model]", "modes = 3", "[cable]", f"length = {LENGTH}",
                      "damping_ratio = 0.05", "inertia = 2.865e-12", "[clamps]",
                      'rotation = "pinned"', "[base]",
                      "asd_g2 = [[10.0, 0.04], [500.0, 0.04]]", "duration = 1.0",
                      "realisations = 1", "seed = 3", "[solver]", "rtol = 1e-10"]) + "\n"
    sc = sweep.load_scene_text(text)
    ds = sweep.run(sc, progress=False)
    random = RandomInputs.of(sc.values)
    record, fs, t_end = random.records()[0], random.sample_rate, random.t_end
    cable = g.Cable(length=LENGTH, damping_ratio=0.05)
    shapes = g.sine_shapes(3, LENGTH)
    omega_n = np.arange(1, 4) ** 2 * cable.w1
    free = g.shapes_rhs(cable, shapes, omega_n, tension_stiffness=EA / LENGTH)
    x, w = np.polynomial.legendre.leggauss(96)
    x, w = 0.5 * LENGTH * (x + 1.0), 0.5 * LENGTH * w
    phi = np.array([s(x, 0) for s in shapes])
    gamma = (phi @ w) / ((phi ** 2) @ w)

    def accel(t):
        return np.asarray(rnd.hermite(record, fs, np.asarray(t, float)), float)

    def jerk(t):
        return (accel(np.asarray(t) + 1e-7) - accel(np.asarray(t) - 1e-7)) / 2e-7

    def rhs(t, y):
        f = free(t, y)
        f[3:] -= gamma * float(accel(t))
        return f
    sol = solve_ivp(rhs, (0.0, t_end), np.zeros(6), method="DOP853", rtol=1e-10, atol=1e-15,
                    dense_output=True, max_step=1.0 / fs).sol
    window = float(ds.statistics_window.values.ravel()[0])
    peaks = _peaks_of(sol, 3, shapes, np.linspace(t_end - window, t_end, 100_001),
                      EA / LENGTH, (accel, jerk, float("nan")))
    assert float(ds.clamp_force.values.ravel()[0]) == pytest.approx(peaks["force"], rel=1e-5)
    assert abs(peaks["force"] / peaks["force_modes"] - 1.0) > 1e-3     # the inertia's part shows
