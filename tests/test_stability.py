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
