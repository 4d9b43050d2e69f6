"""Stress: divergence, solver limits, determinism and properties over random valid scenes.

Every point ends with a named state; nothing hangs; a bad point never changes its neighbours.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings as hsettings, strategies as st

import sweep
from sweep.kernels import metrics as km
from sweep.kernels import transverse as tk

from conftest import param_row, settings, solve

FAILED = {km.DIVERGED, km.STEP_TOO_SMALL, km.MAX_STEPS}
TABLE1 = dict(E=1.1e11, rho=8900.0, A=6e-6, I=5.73e-12)


def scene(text: str, **overrides) -> sweep.Scene:
    return sweep.load_scene_text(text, overrides=overrides)


def run(text: str, **overrides):
    return sweep.run(scene(text, **overrides), progress=False)


def barrier_closed_form(length: float) -> float:
    """docs/model.md: positive root of w1^2 + K3 q^2 + K5 q^4 = 0 (unloaded, alpha = 3/8)."""
    k = np.pi / length
    ei_ra = TABLE1["E"] * TABLE1["I"] / (TABLE1["rho"] * TABLE1["A"])
    w1sq = ei_ra * k ** 4
    K3 = 0.375 * TABLE1["E"] / TABLE1["rho"] * k ** 4 - 1.25 * ei_ra * k ** 6
    K5 = -21 / 16 * ei_ra * k ** 8
    return math.sqrt((-K3 - math.sqrt(K3 ** 2 - 4 * K5 * w1sq)) / (2 * K5))


def test_softening_quintic_escapes_just_past_its_barrier_only():
    qb = barrier_closed_form(1.0)
    ds = run(f"""
[model]
membrane = 0.375
[cable]
inertia = 5.73e-12
[load]
amplitude = 0.0
[metrics]
divergence_bound = 1e6
[axes]
initial_displacement = [{0.98 * qb!r}, {1.02 * qb!r}]
[solver]
t_end = 2e-4        # s: about 35 periods at this huge amplitude (w ~ sqrt(K3) q ~ 1e6 rad/s)
""")
    # 55 m for a 1 m span: mode slope pi q_b / l = 174, beyond the model's range, so NaN; the
    # dynamics still escape just past the closed-form root.
    assert np.isnan(float(ds["escape_barrier"]))
    inside, outside = ds["state"].values
    assert inside == km.STEADY                      # undamped, periodic: bounded
    assert outside == km.DIVERGED
    assert 0 < float(ds["failure_time"][1]) < 2e-4


DIVERGING = {
    "above buckling, membrane off": dict(text="""
[model]
membrane = 0.0
[load]
type = "constant"
amplitude = 8.0
[initial]
displacement = 1e-4
"""),
    "undamped principal parametric resonance, membrane off": dict(text="""
[model]
membrane = 0.0
[load]
amplitude = 4.0
frequency_ratio = 2.0
[initial]
displacement = 1e-4
"""),
    "huge initial displacement": dict(text="""
[initial]
displacement = 10.0
"""),
    "huge load": dict(text="""
[load]
amplitude = 1e7
frequency_ratio = 2.0
[initial]
displacement = 1e-4
"""),
}


@pytest.mark.parametrize("case", DIVERGING)
def test_diverging_points_are_flagged_with_a_time(case):
    ds = run(DIVERGING[case]["text"])
    state = int(ds["state"])
    assert state in FAILED, km.STATE_MEANINGS[state]
    assert 0.0 <= float(ds["failure_time"]) <= 5.0
    assert math.isnan(float(ds["amplitude"]))


def test_a_diverging_point_leaves_its_neighbours_bit_for_bit_unchanged():
    base = """
[cable]
damping_ratio = 0.01
[initial]
displacement = 1e-3
[axes]
length = [0.4, 0.6, 0.8]
initial_displacement = [1e-3, 2e-3, 5.0]
[solver]
t_end = 1.0
"""
    with_bad = run(base)
    without = run(base.replace("[1e-3, 2e-3, 5.0]", "[1e-3, 2e-3]"))
    assert (with_bad["state"].sel(initial_displacement=5.0) == km.DIVERGED).all()
    for name in ("state", "amplitude", "peak_amplitude", "settling_time", "n_steps"):
        np.testing.assert_array_equal(
            with_bad[name].sel(initial_displacement=[1e-3, 2e-3]).values, without[name].values)


def test_max_steps_bounds_the_cost_of_the_worst_point():
    ds = run("""
[initial]
displacement = 1e-3
[axes]
length = [0.05, 1.0]
[solver]
max_steps = 20000
""")
    short, long_ = ds["state"].values
    assert short == km.MAX_STEPS and ds["n_steps"].values[0] == 20000
    assert long_ not in FAILED and ds["n_steps"].values[1] <= 20000


def test_minimum_step_size_gives_a_named_state():
    ds = run("""
[initial]
displacement = 1e-3
[solver]
min_step = 1e-2     # s: the 6 Hz response needs ~1.5 ms steps at rtol 1e-8
t_end = 1.0
""")
    assert int(ds["state"]) == km.STEP_TOO_SMALL
    assert float(ds["failure_time"]) < 1.0


@pytest.mark.parametrize("rtol", [1e-14, 1e-2])
def test_extreme_tolerances_end_with_named_states(rtol):
    ds = run("""
[cable]
damping_ratio = 0.02
[initial]
displacement = 1e-3
[axes]
length = [0.3, 1.0]
[solver]
t_end = 0.5
max_steps = 200000
""", **{"solver.rtol": rtol, "solver.atol": 1e-16 if rtol < 1e-10 else 1e-6})
    states = set(ds["state"].values.tolist())
    assert states <= set(range(len(km.STATE_MEANINGS)))
    assert not states & {km.INVALID_INPUT}


def test_short_stiff_spans_next_to_long_soft_ones():
    ds = run("""
[cable]
damping_ratio = 0.02
[load]
amplitude = 4.0
[initial]
displacement = 1e-4
[axes]
length = {start = 0.05, stop = 5.0, num = 6, spacing = "log"}
frequency_ratio = [0.5, 2.0]
[solver]
t_end = 1.0
max_steps = 300000
""")
    assert ds["state"].shape == (6, 2)
    assert (ds["n_steps"] <= 300000).all()
    # The soft span takes far fewer steps than the stiff one: each keeps its own step size.
    assert int(ds["n_steps"][0, 0]) > 20 * int(ds["n_steps"][-1, 0])


DETERMINISM = """
[cable]
damping_ratio = 0.01
[initial]
displacement = 1e-3
[axes]
length = [0.3, 0.5, 0.9]
frequency_ratio = [0.8, 1.9, 2.1, 2.6]
load_amplitude = [2.0, 8.0]
[solver]
t_end = 1.0
"""


def test_results_do_not_depend_on_threads_chunking_or_axis_order():
    ref = run(DETERMINISM, **{"run.threads": 1})
    variants = [run(DETERMINISM, **{"run.threads": 2}),
                run(DETERMINISM, **{"run.chunk_size": 1}),
                run(DETERMINISM, **{"run.chunk_size": 7, "run.threads": 2})]
    order = DETERMINISM.replace(
        "length = [0.3, 0.5, 0.9]\nfrequency_ratio = [0.8, 1.9, 2.1, 2.6]\n"
        "load_amplitude = [2.0, 8.0]",
        "load_amplitude = [2.0, 8.0]\nlength = [0.3, 0.5, 0.9]\n"
        "frequency_ratio = [0.8, 1.9, 2.1, 2.6]")
    variants.append(run(order).transpose(*ref["state"].dims))
    for ds in variants:
        for name in ref.data_vars:
            np.testing.assert_array_equal(ds[name].values, ref[name].values, err_msg=name)


def test_longitudinal_results_do_not_depend_on_threads_or_chunking():
    text = "[model]\nkind = 'longitudinal'\n[solver]\nintervals = 64\n[axes]\n" \
           "length = [0.3, 0.7, 1.1, 1.5]\nload_amplitude = [1.0, 3.0]\n"
    ref = run(text, **{"run.threads": 1})
    other = run(text, **{"run.threads": 2, "run.chunk_size": 3})
    for name in ref.data_vars:
        np.testing.assert_array_equal(other[name].values, ref[name].values, err_msg=name)


# --- properties over random valid scenes --------------------------------------------------

def _axis(values):
    return "[" + ", ".join(repr(float(v)) for v in values) + "]"


scene_values = st.fixed_dictionaries({
    "length": st.lists(st.floats(0.2, 2.0), min_size=1, max_size=3, unique=True),
    # one amplitude at least above 0: a load frequency axis without a load is refused
    "load_amplitude": st.lists(st.floats(0.0, 20.0), min_size=1, max_size=2, unique=True)
    .filter(lambda amplitudes: any(a > 0.0 for a in amplitudes)),
    "frequency_ratio": st.lists(st.floats(0.3, 3.0), min_size=1, max_size=2, unique=True),
    "damping_ratio": st.floats(0.0, 0.1),
    "q0": st.floats(-5e-3, 5e-3),
    "t_end": st.floats(0.2, 1.5),
    "coefficients": st.sampled_from(["consistent", "paper"]),
})


@hsettings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scene_values)
def test_every_point_gets_a_state_and_consistent_metrics(v):
    text = f"""
[model]
coefficients = "{v['coefficients']}"
[cable]
damping_ratio = {v['damping_ratio']!r}
[initial]
displacement = {v['q0']!r}
[axes]
length = {_axis(sorted(v['length']))}
load_amplitude = {_axis(sorted(v['load_amplitude']))}
frequency_ratio = {_axis(sorted(v['frequency_ratio']))}
[solver]
t_end = {v['t_end']!r}
max_steps = 100000
"""
    ds = run(text)
    state = ds["state"].values.ravel()
    assert ((state >= 0) & (state < len(km.STATE_MEANINGS))).all()
    amp = ds["amplitude"].values.ravel()
    peak = ds["peak_amplitude"].values.ravel()
    settle = ds["settling_time"].values.ravel()
    done = ~np.isin(state, list(FAILED | {km.INVALID_INPUT}))
    assert np.all(peak[done] >= amp[done])
    assert np.isnan(amp[~done]).all()
    # an undamped span has no settling time (nothing settles), whatever its state
    has_settling = np.isin(state, [km.DECAYED, km.STEADY]) & (v["damping_ratio"] > 0.0)
    assert np.all((settle[has_settling] >= 0) & (settle[has_settling] <= v["t_end"]))
    assert np.isnan(settle[~has_settling]).all()


@hsettings(max_examples=40, deadline=None)
@given(k0=st.floats(1.0, 1e4), g0=st.floats(0.0, 1e6), h=st.floats(0.0, 1e8),
       q0=st.floats(-0.05, 0.05), v0=st.floats(-1.0, 1.0),
       rtol=st.sampled_from([1e-6, 1e-8, 1e-10]))
def test_undamped_unforced_points_conserve_energy(k0, g0, h, q0, v0, rtol):
    """At the amplitude (a turning point, q' = 0) the potential equals the initial energy."""
    def potential(q):
        return 0.5 * k0 * q * q + 0.25 * g0 * q ** 4 + h * q ** 6 / 6.0
    energy = 0.5 * v0 * v0 + potential(q0)
    if energy < 1e-12:
        return
    t_end = 40.0 / math.sqrt(k0)                     # several periods at the linear frequency
    states, reals, _, _ = solve(param_row(k0=k0, g0=g0, h=h, q0=q0, v0=v0),
                                settings(rtol=rtol, atol=rtol * 1e-4, t_end=t_end))
    assert states[0] == km.STEADY
    assert potential(reals[0, tk.PEAK]) == pytest.approx(energy, rel=1e3 * rtol)


def test_a_grid_too_large_for_memory_is_refused_before_any_work():
    text = ("[load]\namplitude = 4.0\n[axes]\nlength = {start = 0.1, stop = 1.0, num = 200000}\n"
            "frequency_ratio = {start = 0.5, stop = 3.0, num = 200000}\n")
    with pytest.raises(sweep.UserError, match="GiB"):
        sweep.run(scene(text), progress=False)


def test_longitudinal_time_levels_are_bounded_by_max_steps():
    from sweep.kernels import longitudinal as lk
    ds = run("[model]\nkind = 'longitudinal'\n[solver]\nintervals = 100\ntransits = 50\n"
             "max_steps = 1000\n")
    assert int(ds["state"]) == lk.MAX_STEPS and int(ds["n_steps"]) == 1000
    assert float(ds["failure_time"]) == pytest.approx(1000 * float(ds["time_step"]))
