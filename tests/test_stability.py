"""outputs.stability: Floquet multipliers of the straight span in a result (docs/model.md sec. 8),
checked against a SciPy DOP853 monodromy written here from the cable data, for one mode and
for several, with and without the time-domain run."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import sweep

E, RHO, AREA, INERTIA = 1.1e11, 8900.0, 6e-6, 2.865e-12

CHART = """
name = "chart"
[cable]
inertia = 2.865e-12
damping_ratio = {zeta}
length = 0.8
[load]
type = "harmonic"
[axes]
frequency_ratio = [0.6, 1.0, 1.3, 2.0, 2.4, 7.9]
load_amplitude = [0.5, 2.0, 4.0]
[outputs]
stability = true
amplitude = false
peak_amplitude = false
settling_time = false
response_period = false
solver_stats = false
"""


def reference(ratio: float, load: float, zeta: float, length: float, n: int = 1
              ) -> tuple[float, float]:
    """(max |lambda|, growth rate 1/s) of mode n of the straight span from the cable data:
    q'' + 2 zeta w_n q' + w_n^2 (1 - (P0/Pcr_n) cos W t) q = 0, w_n = n^2 w1, Pcr_n = n^2 Pcr,
    W = ratio w1, by solve_ivp DOP853 over one period from the identity."""
    k = math.pi / length
    w1 = math.sqrt(E * INERTIA / (RHO * AREA)) * k * k
    pcr = E * INERTIA * k * k
    wn, ratio_n = n * n * w1, load / (n * n * pcr)
    omega = ratio * w1
    period = 2.0 * math.pi / omega

    def rhs(t, y):
        q1, v1, q2, v2 = y
        s = wn * wn * (1.0 - ratio_n * math.cos(omega * t))
        return [v1, -2 * zeta * wn * v1 - s * q1, v2, -2 * zeta * wn * v2 - s * q2]

    y = solve_ivp(rhs, (0.0, period), [1.0, 0.0, 0.0, 1.0], method="DOP853", rtol=1e-12,
                  atol=1e-14).y[:, -1]
    lam = np.linalg.eigvals(np.array([[y[0], y[2]], [y[1], y[3]]]))
    top = float(np.max(np.abs(lam)))
    return top, math.log(top) / period


@pytest.fixture(scope="module")
def chart():
    return sweep.run(sweep.load_scene_text(CHART.format(zeta=0.01)))


def test_a_stability_only_scene_runs_no_time_domain(chart):
    assert {"floquet_multiplier", "growth_rate", "stability"} <= set(chart.data_vars)
    assert not {"state", "amplitude", "n_steps"} & set(chart.data_vars)
    assert chart["growth_rate"].attrs["units"] == "s-1"
    meanings = chart["stability"].attrs["flag_meanings"].split()
    assert "stable" in meanings and "unstable_period_2" in meanings
    # .sel on the values the scene wrote
    assert chart["stability"].sel(frequency_ratio=2.0, load_amplitude=4.0).item() == 2


def test_multipliers_and_growth_rates_match_a_scipy_monodromy(chart):
    worst = 0.0
    for r in chart["frequency_ratio"].values:
        for p in chart["load_amplitude"].values:
            top, rate = reference(float(r), float(p), 0.01, 0.8)
            point = chart.sel(frequency_ratio=r, load_amplitude=p)
            assert point["floquet_multiplier"].item() == pytest.approx(top, rel=1e-7)
            assert point["growth_rate"].item() == pytest.approx(rate, rel=1e-6, abs=1e-7)
            flag = point["stability"].item()
            assert (flag != 0) == (top > 1.0)
            worst = max(worst, abs(point["floquet_multiplier"].item() / top - 1.0))
    assert worst < 1e-7


def test_the_principal_zone_is_period_two_and_the_second_period_one(chart):
    principal = chart.sel(frequency_ratio=2.0, load_amplitude=4.0)
    second = chart.sel(frequency_ratio=1.0, load_amplitude=4.0)
    assert principal["stability"].item() == 2 and principal["growth_rate"].item() > 0
    assert second["stability"].item() == 1 and second["growth_rate"].item() > 0
    calm = chart.sel(frequency_ratio=1.3, load_amplitude=0.5)
    assert calm["stability"].item() == 0
    zeta_w1 = 0.01 * math.sqrt(E * INERTIA / (RHO * AREA)) * (math.pi / 0.8) ** 2
    assert calm["growth_rate"].item() == pytest.approx(-zeta_w1, rel=1e-9)   # a complex pair


def test_several_modes_take_the_largest_and_name_its_mode():
    """W = 7.9 w1 lies in mode 2's principal zone (near 2 w2 = 8 w1), which one mode cannot
    see."""
    ds = sweep.run(sweep.load_scene_text(CHART.format(zeta=0.01),
                                         overrides={"model.modes": 3}))
    point = ds.sel(frequency_ratio=7.9, load_amplitude=4.0)
    top, _ = reference(7.9, 4.0, 0.01, 0.8, n=2)
    assert top > 1.0
    assert point["floquet_mode"].item() == 2
    assert point["floquet_multiplier"].item() == pytest.approx(top, rel=1e-7)
    one = sweep.run(sweep.load_scene_text(CHART.format(zeta=0.01)))
    assert one.sel(frequency_ratio=7.9, load_amplitude=4.0)["stability"].item() == 0


def test_stability_beside_the_time_domain_agrees_with_it():
    """With the time-domain run too: where the straight span is unstable a tiny seed grows,
    where it is stable it decays."""
    text = CHART.format(zeta=0.01).replace("amplitude = false\npeak_amplitude", "peak_amplitude")
    ds = sweep.run(sweep.load_scene_text(text, overrides={
        "initial.displacement": 1e-7, "solver.t_end": 3.0, "axes.frequency_ratio": [1.3, 2.0],
        "axes.load_amplitude": [0.5, 4.0]}))
    assert "amplitude" in ds and "stability" in ds and "state" in ds
    grows = ds.sel(frequency_ratio=2.0, load_amplitude=4.0)
    decays = ds.sel(frequency_ratio=1.3, load_amplitude=0.5)
    assert grows["growth_rate"].item() > 0 and grows["amplitude"].item() > 1e-6
    assert decays["growth_rate"].item() < 0 and decays["amplitude"].item() < 1e-7


@pytest.mark.parametrize("text, words", [
    ('[load]\ntype = "constant"\n[outputs]\nstability = true\n', ("outputs.stability",
                                                                    "harmonic")),
    ('[model]\nkind = "longitudinal"\n[outputs]\nstability = true\n', ("outputs.stability",
                                                                       "transverse")),
])
def test_stability_without_a_period_is_refused_in_one_line(text, words):
    with pytest.raises(sweep.UserError) as info:
        sweep.load_scene_text(text)
    message = str(info.value)
    assert "\n" not in message and all(w in message for w in words), message


def test_points_without_a_floquet_answer_are_warned_with_the_reason():
    """A load frequency so low that one period needs more steps than the kernel takes gives
    invalid_input at those points (the rest of the chart answers) and one warning line
    saying why and what to keep (a reviewer found the flag alone, without a reason)."""
    from sweep.errors import CableSweepWarning
    scene = sweep.load_scene("harness-stability",
                             overrides={"axes.frequency_ratio": [2e-5, 2.0]})
    with pytest.warns(CableSweepWarning, match=r"have no Floquet answer .* W/w1 down to 2e-05"):
        ds = sweep.run(scene, progress=False)
    kinds = ds.stability.transpose("frequency_ratio", ...).values
    assert np.all(kinds[0] == -1) and np.all(kinds[1] >= 0)


# ------------------------------------------------------- the load as a multiple of Pcr

RATIO_CHART = CHART.replace("load_amplitude = [0.5, 2.0, 4.0]", "load_ratio = [0.1, 0.4, 0.8]")


def test_a_load_ratio_axis_is_p0_over_the_spans_own_pcr():
    """load.amplitude_ratio (axis load_ratio): P0 = ratio x Pcr, Pcr = EI (pi/l)^2 written
    here for pinned ends: every multiplier against the SciPy monodromy of the Mathieu equation
    at that load, and load_amplitude (N) stored beside the axis."""
    ds = sweep.run(sweep.load_scene_text(RATIO_CHART.format(zeta=0.01)), progress=False)
    assert "load_ratio" in ds.dims and "load_ratio" in ds.coords
    pcr = E * INERTIA * (math.pi / 0.8) ** 2
    assert ds["load_amplitude"].attrs["units"] == "N"
    np.testing.assert_allclose(ds["load_amplitude"].values, [0.1 * pcr, 0.4 * pcr, 0.8 * pcr],
                               rtol=1e-13)
    for r in ds["frequency_ratio"].values:
        for s in ds["load_ratio"].values:
            top, _ = reference(float(r), float(s) * pcr, 0.01, 0.8)
            got = float(ds["floquet_multiplier"].sel(frequency_ratio=r, load_ratio=s))
            assert got == pytest.approx(top, rel=1e-8), (r, s)


@pytest.mark.parametrize("rotation, extra", [("clamped", ""),
                                             ("elastic", "rotational_stiffness = 3.0")])
def test_a_load_ratio_reads_the_same_whatever_the_clamps(rotation, extra):
    """With other ends Pcr is theirs (buckling_load: 4 pi^2 EI/l^2 clamped): the chart at
    load_ratio s is the chart at load_amplitude s x buckling_load, to round-off, and the
    clamped buckling load is the exact one to 2e-4."""
    clamps = f'\n[clamps]\nrotation = "{rotation}"\n{extra}\n'
    by_ratio = sweep.run(sweep.load_scene_text(RATIO_CHART.format(zeta=0.01) + clamps),
                         progress=False)
    pcr = float(by_ratio["buckling_load"])
    if rotation == "clamped":
        assert pcr == pytest.approx(4.0 * math.pi ** 2 * E * INERTIA / 0.8 ** 2, rel=2e-4)
    loads = [0.1 * pcr, 0.4 * pcr, 0.8 * pcr]
    by_load = sweep.run(sweep.load_scene_text(CHART.format(zeta=0.01).replace(
        "load_amplitude = [0.5, 2.0, 4.0]", f"load_amplitude = {loads!r}") + clamps),
        progress=False)
    np.testing.assert_allclose(by_ratio["floquet_multiplier"].values,
                               by_load["floquet_multiplier"].values, rtol=1e-12)
    assert int((by_ratio["stability"] != 0).sum()) > 0           # some zone is crossed


def test_a_load_ratio_drives_the_time_domain_as_its_load():
    """A time-domain run with load.amplitude_ratio is the run with load.amplitude = ratio x
    buckling_load (clamped, three modes), bit for bit."""
    base = """
[model]
modes = 3
[clamps]
rotation = "clamped"
[cable]
damping_ratio = 0.01
length = 0.6
[load]
{load}
frequency_ratio = 1.9
[initial]
modal_displacement = [1e-4, 0.0, 0.0]
[solver]
t_end = 0.5
"""
    by_ratio = sweep.run(sweep.load_scene_text(base.format(load="amplitude_ratio = 0.3")),
                         progress=False)
    load = 0.3 * float(by_ratio["buckling_load"])
    by_load = sweep.run(sweep.load_scene_text(base.format(load=f"amplitude = {load!r}")),
                        progress=False)
    assert float(by_ratio["load_amplitude"]) == load
    for name in ("amplitude", "peak_amplitude", "max_deflection", "state"):
        np.testing.assert_array_equal(by_ratio[name].values, by_load[name].values)


@pytest.mark.parametrize("text, words", [
    ("[load]\namplitude = 2.0\namplitude_ratio = 0.5\n", ["load.amplitude", "not both"]),
    ("[load]\namplitude = 2.0\n[axes]\nload_ratio = [0.1, 0.2]\n", ["load_ratio", "not both"]),
    ('[model]\nkind = "longitudinal"\n[load]\ntype = "constant"\namplitude_ratio = 0.5\n',
     ["load.amplitude_ratio", "transverse"]),
    ("[load]\namplitude_ratio = 0.0\n[outputs]\nstability = true\n", ["outputs.stability"]),
])
def test_bad_load_ratios_are_one_line(text, words):
    with pytest.raises(sweep.errors.UserError) as err:
        sweep.load_scene_text(text)
    message = str(err.value)
    assert "\n" not in message and all(w in message for w in words), message


@pytest.mark.parametrize("modes", [1, 3])
def test_a_load_ratio_over_a_length_axis_loads_each_span_by_its_own_pcr(modes):
    """load_ratio x length (Pcr changes along length, the load in N over both axes): every
    point is the run of its own load in N (the time-domain rows crashed on a parameter over
    two axes)."""
    base = """
[model]
modes = {modes}
[cable]
damping_ratio = 0.01
[load]
{load}
frequency_ratio = 1.9
[initial]
modal_displacement = {q0}
[solver]
t_end = 0.3
[axes]
{axes}
"""
    q0 = [1e-4] + [0.0] * (modes - 1)
    ds = sweep.run(sweep.load_scene_text(base.format(
        modes=modes, q0=q0, load="", axes="load_ratio = [0.2, 0.35]\nlength = [0.5, 0.7]")),
        progress=False)
    assert ds["load_amplitude"].dims == ("load_ratio", "length")
    np.testing.assert_allclose(ds["load_amplitude"], ds["load_ratio"] * ds["buckling_load"],
                               rtol=1e-15)
    one = ds.sel(load_ratio=0.35, length=0.7)
    alone = sweep.run(sweep.load_scene_text(base.format(
        modes=modes, q0=q0, load=f"amplitude = {float(one.load_amplitude)!r}",
        axes="length = [0.7]")), progress=False)
    # (the grid runs on the lanes, the single point on the scalar driver: round-off apart)
    assert float(one["amplitude"]) == pytest.approx(float(alone["amplitude"].squeeze()),
                                                    rel=1e-9)
