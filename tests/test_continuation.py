"""Stepped sweeps with continuation ([continuation], docs/model.md sec. 6) against an
independent SciPy stepped run written here.

A hardening span (the Table 1 cable with membrane stretching) driven by base excitation whose
frequency steps up, then down: each dwell of solver.t_end seconds starts from the previous
dwell's final state, the excitation phase running on (phi_(k+1) = phi_k + 2 pi f_k T_d). The
reference integrates the same sequence of dwells with SciPy's DOP853 at rtol 1e-11 on the
one-mode equation written below from the cable data (not from the engine's coefficients), and
reads each dwell's tail maximum |q| on its dense output. Checked:

1. every dwell's tail amplitude, up and down, to 1e-3 relative away from the jumps, and the
   jumps at the same dwells;
2. the up sweep's jump down and the down sweep's jump up bracket the folds of first-order
   harmonic balance (docs/model.md sec. 5) within one frequency step, in the weakly nonlinear
   range, and the two sweeps follow different branches between them (hysteresis);
3. with several modes, the carried state is every mode's (against tests/galerkin.py);
4. the dataset: a `direction` dimension that .sel works on, CF flag attributes of `jump`,
   results in the axis's own order; and the bad input refused with one line.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import sweep
from sweep.errors import UserError

import galerkin

E, RHO, AREA, INERTIA, ALPHA = 1.1e11, 8900.0, 6e-6, 2.865e-12, 0.375
G = 9.80665
LENGTH = 0.5
ZETA = 0.02
T_DWELL = 4.0
TAIL = 0.5


def one_mode(length: float = LENGTH) -> dict[str, float]:
    """w1 (rad/s), K3 (1/(s^2 m^2)), K5, Gamma of the unloaded span, from docs/model.md sec. 2."""
    k = math.pi / length
    ei_rho_a = E * INERTIA / (RHO * AREA)
    return {"w1": math.sqrt(ei_rho_a) * k * k,
            "k3": ALPHA * E / RHO * k ** 4 - 1.25 * ei_rho_a * k ** 6,
            "k5": -21.0 / 16.0 * ei_rho_a * k ** 8, "gamma": 4.0 / math.pi}


def stepped_reference(freqs: np.ndarray, accel: float, order: np.ndarray) -> np.ndarray:
    """Tail amplitude (m) of each dwell of a stepped sweep visiting freqs (Hz) in `order`, base
    level accel (m/s^2), from rest: SciPy DOP853, rtol 1e-11, phase carried."""
    c = one_mode()
    w1, k3, k5, gamma = c["w1"], c["k3"], c["k5"], c["gamma"]
    y = np.zeros(2)
    phase = 0.0
    out = np.empty(freqs.size)
    for k in order:
        w = 2.0 * math.pi * freqs[k]

        def f(t, s, w=w, phase=phase):
            q, v = s
            return [v, -2.0 * ZETA * w1 * v - w1 * w1 * q - k3 * q ** 3 - k5 * q ** 5
                    - gamma * accel * math.sin(w * t + phase)]
        sol = solve_ivp(f, (0.0, T_DWELL), y, method="DOP853", rtol=1e-11, atol=1e-16,
                        dense_output=True)
        assert sol.success
        t0 = T_DWELL * (1.0 - TAIL)
        grid = np.linspace(t0, T_DWELL, int(64 * max(freqs[k], w1 / (2 * math.pi))
                                            * (T_DWELL - t0)) + 2)
        out[k] = galerkin._tail_max(lambda s: sol.sol(s)[0], lambda s: sol.sol(s)[1], grid)
        y = sol.y[:, -1]
        phase = math.remainder(phase + w * T_DWELL, 2.0 * math.pi)
    return out


def scene_text(freqs, level_g: float, direction: str, modes: int = 1) -> str:
    return f"""
name = "stepped-test"
[model]
modes = {modes}
membrane = {ALPHA}
[cable]
inertia = {INERTIA}
damping_ratio = {ZETA}
length = {LENGTH}
[load]
amplitude = 0.0
[base]
acceleration_g = {level_g}
[solver]
t_end = {T_DWELL}
rtol = 1e-10
method = "dop853"
[metrics]
tail = {TAIL}
[axes]
base_frequency = {[float(f) for f in freqs]}
[continuation]
axis = "base_frequency"
direction = "{direction}"
"""


F1 = one_mode()["w1"] / (2.0 * math.pi)          # 15.26 Hz


def harmonic_balance_folds(accel: float) -> tuple[float, float]:
    """The fold frequencies (Hz) of first-order harmonic balance (docs/model.md sec. 5),
    [(w1^2 + 3/4 K3 a^2 + 5/8 K5 a^4 - w^2)^2 + (2 zeta w1 w)^2] a^2 = (Gamma A)^2: solved for
    w^2 on its larger root w_+(a), the branch that comes down from high frequency at small a,
    bends up with the hardening and ends at the peak. A bistable curve has a local minimum of
    w_+ (the lower fold: where a down sweep jumps up) and then a local maximum (the upper fold:
    where an up sweep jumps down). Returns (lower, upper); NaN, NaN if not bistable."""
    c = one_mode()
    w1, k3, k5, force = c["w1"], c["k3"], c["k5"], c["gamma"] * accel
    a = np.geomspace(1e-6, 1e-1, 200001)
    backbone = w1 * w1 + 0.75 * k3 * a * a + 0.625 * k5 * a ** 4
    b = 2.0 * backbone - (2.0 * ZETA * w1) ** 2
    with np.errstate(invalid="ignore"):
        disc = b * b / 4.0 - (backbone ** 2 - (force / a) ** 2)
        w_plus = np.sqrt(b / 2.0 + np.sqrt(disc))
    ok = np.isfinite(w_plus)
    a, w_plus = a[ok], w_plus[ok]
    slope = np.sign(np.diff(w_plus))
    turns = np.nonzero(slope[1:] != slope[:-1])[0] + 1
    if turns.size < 2:
        return math.nan, math.nan
    return w_plus[turns[0]] / (2 * math.pi), w_plus[turns[1]] / (2 * math.pi)


def test_the_reference_case_is_bistable_inside_the_stepped_band():
    low, high = harmonic_balance_folds(STEP_LEVEL_G * G)
    assert STEP_FREQS[0] < low < high < STEP_FREQS[-1], (low, high)
    assert math.isnan(harmonic_balance_folds(0.005 * G)[0])      # a weak level: no folds


def _stepped(freqs, level_g, direction, modes=1):
    return sweep.run(sweep.load_scene_text(scene_text(freqs, level_g, direction, modes)),
                     progress=False)


def _jump_indices(amplitude: np.ndarray, order: np.ndarray, ratio: float = 1.5) -> list[int]:
    """Where the tail amplitude changes by more than `ratio` from the dwell before, in the
    sweep's order (the first dwell of each run of such changes), as axis indices."""
    a = amplitude[order]
    change = (a[1:] > ratio * a[:-1]) | (a[1:] * ratio < a[:-1])
    first = change & ~np.r_[False, change[:-1]]
    return sorted(int(order[i + 1]) for i in np.nonzero(first)[0])


STEP_FREQS = F1 * np.linspace(0.95, 1.30, 36)     # steps of 0.01 f1
STEP_LEVEL_G = 0.03


@pytest.fixture(scope="module")
def both_ways():
    return _stepped(STEP_FREQS, STEP_LEVEL_G, "both")


@pytest.mark.slow
@pytest.mark.parametrize("direction", ["up", "down"])
def test_every_dwell_matches_an_independent_stepped_run(both_ways, direction):
    order = np.argsort(STEP_FREQS) if direction == "up" else np.argsort(STEP_FREQS)[::-1]
    reference = stepped_reference(STEP_FREQS, STEP_LEVEL_G * G, order)
    engine = both_ways["amplitude"].sel(direction=direction).values
    jumps = _jump_indices(reference, order)
    assert len(jumps) == 1                                   # one branch change per sweep
    flags = both_ways["jump"].sel(direction=direction).values
    assert list(np.nonzero(flags)[0]) == jumps               # the same dwell flagged
    assert flags[jumps[0]] == (2 if direction == "up" else 1)   # up: falls off; down: jumps up
    # away from the jump (its dwell and the next, still ringing), every dwell to 1e-3
    near = {jumps[0], int(order[list(order).index(jumps[0]) + 1])}
    away = np.array([i not in near for i in range(STEP_FREQS.size)])
    np.testing.assert_allclose(engine[away], reference[away], rtol=1e-3)


def test_jumps_bracket_the_harmonic_balance_folds_and_the_branches_differ(both_ways):
    """Moderately nonlinear (K3 a^2 / w1^2 = 0.57 at the upper fold: the backbone 20 % above
    f1, measured): the up sweep leaves the resonant branch within 1.5 steps of the upper fold
    of first-order harmonic balance, the down sweep joins it within 1.5 steps of the lower fold
    (both measured within one step), and between the folds the up sweep is on the high branch
    and the down sweep on the low one."""
    low, high = harmonic_balance_folds(STEP_LEVEL_G * G)
    step = STEP_FREQS[1] - STEP_FREQS[0]
    up = both_ways.sel(direction="up")
    down = both_ways.sel(direction="down")
    f_down_jump = float(up["base_frequency"][up["jump"] == 2][0])     # first low-branch dwell
    f_up_jump = float(down["base_frequency"][down["jump"] == 1][0])   # first high-branch dwell
    assert abs(f_down_jump - high) <= 1.5 * step, (f_down_jump, high)
    assert abs(f_up_jump - low) <= 1.5 * step, (f_up_jump, low)
    between = (STEP_FREQS > f_up_jump + step) & (STEP_FREQS < f_down_jump - step)
    assert between.sum() >= 5
    assert np.all(up["amplitude"].values[between] > 2.0 * down["amplitude"].values[between])
    c = one_mode()
    a_fold = float(up["amplitude"].values[STEP_FREQS < f_down_jump][-1])
    assert 0.3 < c["k3"] * a_fold ** 2 / c["w1"] ** 2 < 0.7


def test_a_jump_after_a_steep_dwell_keeps_its_flag_both_ways():
    """A reviewer's coarse down sweep (0.05 f1 steps on a hardening 0.4 m span, SciPy's stepped
    run written by them gave the same amplitudes) climbed the low branch's steep side by 1.57x
    into the dwell before its jump (3.6x up): the two flags of one sense were reduced to the
    first, the slope's, which the both-ways check then dropped (up and down agree before it),
    so the real jump lost its flag. Their amplitudes (mm) along 1.00, 1.05, ... 1.20 f1: the
    jump is flagged at 1.05 going down and at 1.15 going up, and nothing else."""
    from sweep.models import continuation as ct
    up = np.array([0.40, 0.50, 0.620, 0.087, 0.070])
    down = np.array([0.40, 0.493, 0.1366, 0.087, 0.070])
    from sweep.kernels import states as km
    states = np.full(5, km.STEADY, np.int8)
    orders = (np.arange(5), np.arange(5)[::-1])
    flags = [ct.jumps(a, states, 0, order, 1.5) for a, order in zip((up, down), orders)]
    flags = ct.branches_differ(flags, [up, down], 0, orders, 1.5)
    flags = [ct.first_only(f, 0, order) for f, order in zip(flags, orders)]
    assert list(flags[0]) == [0, 0, 0, ct.JUMP_DOWN, 0]
    assert list(flags[1]) == [0, ct.JUMP_UP, 0, 0, 0]
    one_way = ct.first_only(ct.jumps(down, states, 0, orders[1], 1.5), 0, orders[1])
    assert list(one_way) == [0, 0, ct.JUMP_UP, 0, 0]     # one way: the run's first (documented)


LINEAR_FREQS = F1 * np.linspace(0.8, 1.2, 9)      # coarse steps of 0.05 f1 over resonance
LINEAR_LEVEL_G = 1e-4                             # K3 a^2 / w1^2 ~ 1e-5: no hysteresis


@pytest.mark.slow
def test_a_steep_slope_both_ways_is_no_jump():
    """A linear span stepped coarsely over its resonance: the tail amplitude changes by more
    than the jump factor 1.5 between neighbouring dwells (SciPy's stepped run, written here,
    says so), but up and down follow the one branch there is (within the 5 % the last
    dwell's ring-down leaves, e^(-zeta w1 T/2) of the change), so no dwell of either direction
    is flagged a jump. The engine's amplitudes are the reference's to 1e-3."""
    up_order = np.argsort(LINEAR_FREQS)
    reference_up = stepped_reference(LINEAR_FREQS, LINEAR_LEVEL_G * G, up_order)
    reference_down = stepped_reference(LINEAR_FREQS, LINEAR_LEVEL_G * G, up_order[::-1])
    np.testing.assert_allclose(reference_up, reference_down, rtol=0.05)
    assert _jump_indices(reference_up, up_order) and \
        _jump_indices(reference_down, up_order[::-1])           # steep: a ratio above 1.5
    ds = _stepped(LINEAR_FREQS, LINEAR_LEVEL_G, "both")
    for direction, reference in (("up", reference_up), ("down", reference_down)):
        np.testing.assert_allclose(ds["amplitude"].sel(direction=direction).values,
                                   reference, rtol=1e-3)
    assert not np.any(ds["jump"].values), ds["jump"].values
    full = ds["jump"].attrs["long_name"] + ds["jump"].attrs.get("comment", "")
    assert "different branches" in full       # the label, or the whole text in comment


@pytest.mark.slow
def test_several_modes_carry_every_mode(tmp_path):
    """modes = 3: each dwell starts from every mode's final state. Against tests/galerkin.py's
    independent projection, two dwells stepped up (the second's start carried), to 1e-4."""
    freqs = np.array([1.0, 1.05]) * F1
    ds = _stepped(freqs, 0.05, "up", modes=3)
    cable = galerkin.Cable(length=LENGTH, damping_ratio=ZETA, inertia=INERTIA, membrane=ALPHA)
    y = np.zeros(6)
    phase = 0.0
    for k, f in enumerate(freqs):
        w = 2.0 * math.pi * f
        shift = phase / w                 # a_b = A sin(w t + phase) = A sin(w (t + shift))
        rhs = galerkin.galerkin_rhs(cable, 3, base_acceleration=0.05 * G, base_frequency=f)
        sol = solve_ivp(lambda t, s: rhs(t + shift, s), (0.0, T_DWELL), y, method="DOP853",
                        rtol=1e-11, atol=1e-15, dense_output=True)
        t = np.linspace(T_DWELL * (1 - TAIL), T_DWELL, 4000)
        modal = [galerkin._tail_max(lambda s, i=i: sol.sol(s)[i],
                                    lambda s, i=i: sol.sol(s)[3 + i], t) for i in range(3)]
        engine = ds["modal_amplitude"].isel(base_frequency=k).values
        np.testing.assert_allclose(engine[[0, 2]], np.array(modal)[[0, 2]], rtol=1e-4)
        y = sol.y[:, -1]
        phase = math.remainder(phase + w * T_DWELL, 2.0 * math.pi)


def test_a_stepped_result_keeps_the_axis_order_and_writes_a_cf_file(tmp_path):
    from test_cf import cf_problems
    freqs = F1 * np.array([1.2, 1.05, 0.9])              # a decreasing axis
    scene = sweep.load_scene_text(scene_text(freqs, STEP_LEVEL_G, "both"))
    out = tmp_path / "stepped.nc"
    ds = sweep.run(scene, output=out, progress=False)
    np.testing.assert_array_equal(ds["base_frequency"].values, freqs)
    assert ds["amplitude"].dims == ("direction", "base_frequency")
    assert list(ds["direction"].values) == ["up", "down"]
    assert ds["jump"].attrs["flag_meanings"] == "none jump_up jump_down"
    # the up sweep visits 0.9, 1.05, 1.2 f1 (the axis's reverse order): its 1.05 f1 dwell
    # started from 0.9 f1's state, so it equals a stepped run of those two alone
    two = _stepped(F1 * np.array([0.9, 1.05]), STEP_LEVEL_G, "up")
    assert float(ds["amplitude"].sel(direction="up").values[1]) == pytest.approx(
        float(two["amplitude"].values[1]), rel=1e-12)
    assert cf_problems(out) == []
    import xarray as xr
    with xr.open_dataset(out) as back:
        assert float(back["amplitude"].sel(direction="down", base_frequency=freqs[1])) == \
            float(ds["amplitude"].sel(direction="down", base_frequency=freqs[1]))


@pytest.mark.parametrize("extra, key", [
    ('[continuation]\naxis = "length"\n', "continuation.axis"),
    ('[continuation]\ndirection = "down"\n', "continuation.direction"),
    ('[continuation]\naxis = "base_frequency"\n[outputs]\ntime_series = true\n',
     "outputs.time_series"),
    ('[continuation]\naxis = "base_frequency"\ndirection = "sideways"\n',
     "continuation.direction"),
])
def test_bad_continuation_is_refused_with_one_line(extra, key):
    text = scene_text(F1 * np.array([1.0, 1.1]), 0.03, "up").split("[continuation]")[0] + extra
    with pytest.raises(UserError) as err:
        sweep.load_scene_text(text)
    message = str(err.value)
    assert "\n" not in message and key in message


def test_sweep_plot_draws_the_branches_of_a_stepped_result(tmp_path):
    from sweep.cli import main
    out = tmp_path / "stepped.nc"
    assert main(["run", "harness-stepped-sine", "-o", str(out), "-q", "--set",
                 "axes.length=[0.5, 0.6]", "--set",
                 "axes.base_frequency_ratio={start=1.0, stop=1.5, num=11}",
                 "--set", "solver.t_end=2.0"]) == 0
    assert main(["plot", str(out), "-o", str(tmp_path / "figs")]) == 0
    names = sorted(p.name for p in (tmp_path / "figs").iterdir())
    assert names == ["stepped-absolute_acceleration_g.png", "stepped-amplitude.png"]
    import xarray as xr
    from sweep.plot import plot_branches
    ds = xr.open_dataset(out)
    ax = plot_branches(ds, "amplitude")
    assert len(ax.lines) == 4                  # two spans x up and down
    dashed = [line for line in ax.lines if line.get_linestyle() == "--"]
    assert len(dashed) == 2
    ds.close()


def test_a_stepped_result_does_not_depend_on_the_threads():
    scene = sweep.load_scene("harness-stepped-sine", overrides={
        "axes.length": [0.4, 0.45, 0.5, 0.55, 0.6],
        "axes.base_frequency_ratio": {"start": 1.0, "stop": 1.4, "num": 9},
        "solver.t_end": 1.0})
    one = sweep.run(scene, threads=1, progress=False)
    two = sweep.run(scene, threads=2, progress=False)
    for name in ("state", "amplitude", "settling_time", "jump", "n_steps"):
        np.testing.assert_array_equal(one[name].values, two[name].values)


def test_an_interrupt_stops_a_stepped_sweep_between_dwells():
    """With the stop event set part-way (Ctrl-C, SIGTERM), no further dwell starts: the lines
    are reported unfinished at once instead of after every dwell (83 s on a 9-span stepped
    scene before), and a whole run reports them finished."""
    import threading

    from sweep.models import continuation as ct
    carry = ct.Carry(state=(0, 1), base_phase=2, load_phase=3, base_omega=4, load_omega=5,
                     final="final")
    dwells, n_lines = 6, 3
    rows = np.zeros((n_lines * dwells, 6))
    lines = np.arange(n_lines * dwells).reshape(n_lines, dwells)
    outputs = {"states": np.zeros(n_lines * dwells, np.int8),
               "final": np.zeros((n_lines * dwells, 2))}
    stop = threading.Event()
    calls = []

    def solve(batch):
        calls.append(batch.shape[0])
        if len(calls) == 2:
            stop.set()                       # an interrupt during the second dwell
        return {"states": np.zeros(batch.shape[0], np.int8),
                "final": np.zeros((batch.shape[0], 2))}

    order = np.arange(dwells)
    assert ct.solve_lines(rows, [ct.Lines(lines, order, outputs)], carry, 1.0, solve,
                          stop=stop) is False
    assert calls == [n_lines, n_lines]       # the dwell in hand finishes, no other starts
    calls.clear()
    assert ct.solve_lines(rows, [ct.Lines(lines, order, outputs)], carry, 1.0, solve) is True
    assert len(calls) == dwells


def test_lines_resumed_at_different_dwells_share_each_call_and_end_as_if_never_stopped():
    """Resumed lines (begun, carried: a stored progress) go on from their own dwell, side by
    side in one kernel call a dwell, each leaving when done; every dwell's outputs and the
    final carried state equal those of the lines swept from the start."""
    from sweep.models import continuation as ct
    carry = ct.Carry(state=(0, 1), base_phase=2, load_phase=3, base_omega=4, load_omega=5,
                     final="final")
    dwells, n_lines = 5, 3
    rng = np.random.default_rng(7)
    rows = rng.normal(size=(n_lines * dwells, 6))
    lines = np.arange(n_lines * dwells).reshape(n_lines, dwells)
    order = np.array([4, 2, 0, 1, 3])

    def solve(batch):          # a state map that depends on the row, the state and the phases
        final = np.column_stack([0.5 * batch[:, 0] + batch[:, 2] * batch[:, 5],
                                 np.sin(batch[:, 1]) + batch[:, 3]])
        return {"states": np.zeros(batch.shape[0], np.int8), "final": final}

    def outputs():
        return {"states": np.zeros(n_lines * dwells, np.int8),
                "final": np.full((n_lines * dwells, 2), np.nan)}

    whole, kept = outputs(), []
    assert ct.solve_lines(rows, [ct.Lines(lines, order, whole)], carry, 0.3, solve,
                          record=lambda g, p, o, d, c: (ct.write_outputs(g, p, o, d, c),
                                                        kept.append((p, d, c))))
    begun = np.array([0, 2, 4])
    carried = np.zeros((n_lines, 4))
    for points, done, c in kept:               # what a progress file holds after those dwells
        at = points // dwells
        mine = done == begun[at]
        carried[at[mine]] = c[mine]
    resumed = outputs()
    for line, b in enumerate(begun):           # the finished dwells, as a progress file keeps
        done_points = lines[line, order[:b]]
        resumed["final"][done_points] = whole["final"][done_points]
    sizes = []

    def counted(batch):
        sizes.append(batch.shape[0])
        return solve(batch)

    assert ct.solve_lines(rows, [ct.Lines(lines, order, resumed, begun, carried)], carry, 0.3,
                          counted)
    assert sizes == [3, 2, 2, 1, 1]            # 5, 3 and 1 dwells left: line 3 leaves first
    np.testing.assert_array_equal(resumed["final"], whole["final"])
