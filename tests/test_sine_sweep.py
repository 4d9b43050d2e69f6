"""Continuous logarithmic sine sweeps of the clamps ([base] sweep, docs/model.md secs. 5-6)
against references built in this file.

One mode, consistent coefficients, m = 1, no end load (load.amplitude = 0):

    q'' + 2 zeta w1 q' + w1^2 q + K3 q^3 + K5 q^5 = -(4/pi) a_b(t)
    w1^2 = (EI/rhoA) k^4,  K3 = alpha (E/rho) k^4 - (5/4)(EI/rhoA) k^6,
    K5 = -(21/16)(EI/rhoA) k^8,  k = pi/l,  alpha = 3/8

and the sweep from f_s to f_e at r octaves per minute:

    lam = s r ln2 / 60 (s = +1 up, -1 down),  f(t) = f_s exp(lam t),
    T = 60 |log2(f_e/f_s)| / r,  phi(t) = 2 pi f_s (exp(lam t) - 1) / lam,
    a_b(t) = A(f(t)) R(t) sin(phi(t)) for t <= T,
    R(t) = (1 - cos(pi t / T_r)) / 2 for t < T_r = 10 / f_s, else 1 (the level's rise),

A(f) constant or a table of (Hz, g) breakpoints interpolated log-log. Each point starts from
rest and ends at T; `peak_amplitude` is max |q| over the sweep, `peak_frequency` f(t) at that
extremum, `envelope` the largest |q| of the extrema (q' = 0) whose f(t) falls in each base-2
1/N-octave band (centre 1000 2^(k/N) Hz, k = floor(N log2(f/1000) + 0.5)).

References (never the engine's models or kernels, which are only cross-checked):
1. SciPy's DOP853 at rtol 1e-11 on that equation, every extremum of q located as an event
   q' = 0 on its dense output: peak, its frequency, the banded envelope;
2. the linear steady resonance (4/pi) A / sqrt((w1^2 - w^2)^2 + (2 zeta w1 w)^2), maximised
   over w, which a slow sweep of a nearly linear span approaches from below;
3. libm's sin and cos for the lanes' fast sine at the phases a stepped sweep reaches.

Measured on the 0.31 m span (f1 = 39.7 Hz, zeta 0.02) and the 0.15 m one (f1 = 170 Hz,
below resonance all sweep) at 4 oct/min, solver.rtol 1e-10, RK45 and DOP853 (its own
seventh-order dense output): peak_amplitude within 4.3e-10 relative of SciPy (0.5 g up/down,
0.1 g up/down, quasi-static up/down), peak_frequency within 2e-11 Hz, envelope within 1.3e-9 in
every band (DOP853 was up to 1.6x high below resonance while its dense output's extra stages
evaluated a fixed sine instead of the sweep); peaks at
59.99 / 45.22 Hz (0.5 g up / down: the up sweep rides the upper branch to its end), 42.53 /
40.55 Hz (0.1 g), 58.10 Hz (table); slow sweeps at 8, 2, 0.5 oct/min reach 0.905, 0.981,
0.998 of the steady resonance; three modes at rtol 1e-8 and 1e-10 agree to 1.3e-10;
fast_sin / fast_cos within 2 ulp of libm to |x| = 1e6.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

import sweep
from sweep.errors import SceneError, UserError

from conftest import fast_first

# The default cable (docs/model.md sec. 1): inertia area^2 / (4 pi), the solid round section.
E = 1.1e11                     # Young's modulus, Pa
RHO = 8900.0                   # density, kg/m^3
AREA = 6e-6                    # m^2
INERTIA = AREA ** 2 / (4.0 * math.pi)
ALPHA = 0.375                  # model.membrane
GAMMA = 4.0 / math.pi          # participation of sin(pi x/l) under uniform base motion
G = 9.80665                    # m/s^2 per g

LENGTH = 0.31                  # m: f1 = pi sqrt(EI/rhoA) / (2 l^2) = 39.7 Hz
ZETA = 0.02
RATE = 4.0                     # octaves per minute
BANDS = 3                      # bands per octave


def span(length: float = LENGTH) -> dict[str, float]:
    """w1 (rad/s), K3 (1/(m^2 s^2)), K5 (1/(m^4 s^2)) of the unloaded span."""
    k = math.pi / length
    ei_over_rho_a = E * INERTIA / (RHO * AREA)
    return {"w1": math.sqrt(ei_over_rho_a) * k * k,
            "k3": ALPHA * E / RHO * k ** 4 - 1.25 * ei_over_rho_a * k ** 6,
            "k5": -21.0 / 16.0 * ei_over_rho_a * k ** 8}


F1 = span()["w1"] / (2.0 * math.pi)


def constant_level(g: float):
    """A(f) = g in m/s^2, whatever the frequency."""
    return lambda f: g * G


def table_level(table):
    """A(f) (m/s^2) of (Hz, g) breakpoints: on [F_k, F_k+1] the power law through both ends,
    g_k (f/F_k)^(ln(g_k+1/g_k) / ln(F_k+1/F_k)) (a straight line on log-log axes)."""
    def level(f):
        for (fa, ga), (fb, gb) in zip(table[:-1], table[1:]):
            if fa <= f <= fb:
                return ga * (f / fa) ** (math.log(gb / ga) / math.log(fb / fa)) * G
        raise AssertionError(f"{f} Hz is outside the table")
    return level


RAMP_CYCLES = 10.0             # the level rises over 10 cycles of the start frequency


def chirp(start: float, stop: float, rate: float):
    """(lam (1/s), T (s), f(t), phi(t)) of the logarithmic sweep, from its definition."""
    lam = math.copysign(rate * math.log(2.0) / 60.0, stop - start)
    duration = 60.0 * abs(math.log2(stop / start)) / rate
    return (lam, duration, lambda t: start * math.exp(lam * t),
            lambda t: 2.0 * math.pi * start * math.expm1(lam * t) / lam)


class Reference:
    """SciPy DOP853 at rtol 1e-11 from rest over the whole sweep; `t`, `q`, `f`: every extremum
    of q (q' = 0, located by solve_ivp's event root finder on the dense output), its value and
    the sweep frequency then."""

    def __init__(self, start: float, stop: float, level, rate: float = RATE,
                 length: float = LENGTH, ramp_cycles: float = RAMP_CYCLES):
        c = span(length)
        w1, k3, k5 = c["w1"], c["k3"], c["k5"]
        lam, self.duration, freq, phase = chirp(start, stop, rate)
        rise = ramp_cycles / start          # s: the level's rise from 0, as a shaker's

        def ramp(t):
            return 0.5 - 0.5 * math.cos(math.pi * t / rise) if t < rise else 1.0

        def rhs(t, y):
            q, v = y
            a_b = (level(freq(t)) * ramp(t) * math.sin(phase(t)) if t <= self.duration
                   else 0.0)
            return [v, -2.0 * ZETA * w1 * v - w1 * w1 * q - k3 * q ** 3 - k5 * q ** 5
                    - GAMMA * a_b]

        def extremum(t, y):
            return y[1]

        sol = solve_ivp(rhs, (0.0, self.duration), [0.0, 0.0], method="DOP853", rtol=1e-11,
                        atol=1e-16, events=extremum)
        assert sol.success, sol.message
        self.t = sol.t_events[0]
        self.q = sol.y_events[0][:, 0]
        assert np.all(np.abs(sol.y_events[0][:, 1]) < 1e-9)       # located: q' = 0 there
        self.f = start * np.exp(lam * self.t)
        i = int(np.argmax(np.abs(self.q)))
        self.peak, self.peak_frequency = abs(self.q[i]), self.f[i]
        # The final sample is no larger than the last extremum (it is one, or on the way).
        assert abs(sol.y[0, -1]) <= self.peak

    def envelope(self, bands_per_octave: int = BANDS) -> dict[int, float]:
        """{band k: largest |q| of the extrema whose f lies in band k}."""
        out: dict[int, float] = {}
        for f, q in zip(self.f, self.q):
            k = math.floor(bands_per_octave * math.log2(f / 1000.0) + 0.5)
            out[k] = max(out.get(k, 0.0), abs(q))
        return out


def scene(base: str, extra: str = "", length: float = LENGTH, rtol: float = 1e-10,
          modes: int = 1):
    """A scene of the default cable (one mode unless told), pure base excitation; `base` the
    [base] lines, `extra` more lines after [solver]'s rtol."""
    return sweep.load_scene_text(f"""name = "sine-sweep-test"
[model]
modes = {modes}
membrane = {ALPHA!r}
[cable]
length = {length!r}
damping_ratio = {ZETA!r}
[load]
amplitude = 0.0
[base]
{base}
[solver]
rtol = {rtol!r}
{extra}""")


def swept(start: float, stop: float, rate: float = RATE) -> str:
    return f"sweep = {{ start = {start!r}, stop = {stop!r}, rate = {rate!r} }}"


def state_code(ds, meaning: str) -> int:
    attrs = ds["state"].attrs
    return int(attrs["flag_values"][attrs["flag_meanings"].split().index(meaning)])


# --------------------------------------------------------------------------- the span itself

def test_the_span_resonates_inside_the_sweep_and_the_coefficients_are_the_engines():
    """f1 = pi sqrt(EI/rhoA) / (2 l^2) lies in 20-60 Hz; the package's own coefficients
    (cross-check only) equal those written here, and its natural_frequency f1."""
    assert 35.0 < F1 < 45.0
    assert abs(F1 - math.pi * math.sqrt(E * INERTIA / (RHO * AREA)) / (2 * LENGTH ** 2)) < 1e-9
    from sweep.models.modal import consistent
    c = consistent({"youngs_modulus": E, "density": RHO, "area": AREA, "inertia": INERTIA,
                    "length": LENGTH, "membrane": ALPHA, "load_amplitude": 0.0})
    mine = span()
    assert c["k"] == pytest.approx(mine["w1"] ** 2, rel=1e-13)
    assert c["g"] == pytest.approx(mine["k3"], rel=1e-13)
    assert c["h"] == pytest.approx(mine["k5"], rel=1e-13)


# --------------------------------------------------------- 1. up and down sweeps against SciPy

CASES = {   # name: (level g, start Hz, stop Hz)
    # 0.5 g: the upper branch carries the up sweep to its very end (the backbone passes 60 Hz
    # at ~1.5 mm; K3 a^2 / w1^2 ~ 1.8 there), the down sweep jumps up at the lower fold.
    "0.5 g up": (0.5, 20.0, 60.0),
    "0.5 g down": (0.5, 60.0, 20.0),
    # 0.1 g: the up sweep's jump down falls inside the band (K3 a^2 / w1^2 ~ 0.2).
    "0.1 g up": (0.1, 20.0, 60.0),
    "0.1 g down": (0.1, 60.0, 20.0),
}
# Below resonance the whole sweep: a 0.15 m span (f1 = 170 Hz) driven quasi-statically at
# 20-60 Hz, up and down (DOP853's dense output once evaluated a fixed sine here, 1.6x high).
QUASI_STATIC = {"quasi-static up": (0.5, 20.0, 60.0), "quasi-static down": (0.5, 60.0, 20.0)}
SHORT = 0.15                   # m
CASES.update(QUASI_STATIC)
METHODS = ["rk45", "dop853"]
DRIVERS = ["lanes", "scalar"]  # one mode: the lanes by default, the scalar driver on request


def case_length(name: str) -> float:
    return SHORT if name in QUASI_STATIC else LENGTH


@pytest.fixture(scope="module")
def references():
    """SciPy's run of each case (computed once, on first use)."""
    cache: dict[str, Reference] = {}

    def get(name: str) -> Reference:
        if name not in cache:
            g, start, stop = CASES[name]
            cache[name] = Reference(start, stop, constant_level(g), length=case_length(name))
        return cache[name]
    return get


@pytest.fixture(scope="module")
def runs():
    """The package's run of each case with each method and driver, with the envelope
    (computed once, on first use)."""
    cache: dict[tuple[str, str, str], object] = {}

    def get(name: str, method: str = "rk45", driver: str = "lanes"):
        if (name, method, driver) not in cache:
            g, start, stop = CASES[name]
            cache[name, method, driver] = sweep.run(scene(
                f"acceleration_g = {g!r}\n{swept(start, stop)}",
                f'method = "{method}"\ndriver = "{driver}"\n[outputs]\nenvelope = true\n'
                f"bands_per_octave = {BANDS}\n", length=case_length(name)))
        return cache[name, method, driver]
    return get


@pytest.mark.parametrize("driver", DRIVERS)
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", fast_first(CASES, "0.1 g up"))
def test_sweep_peak_matches_scipy(name, method, driver, references, runs):
    """peak_amplitude to 1e-4 relative, peak_frequency to 0.05 Hz (half a period's frequency
    change is ~0.02 Hz, so a neighbouring extremum would already be close); amplitude is the
    same max (metrics.tail = 1 for a sweep); completed at the sweep's end T. Both methods (at
    rtol 1e-10 DOP853 reads its peaks off its own seventh-order dense output) and both drivers
    (the lanes read each stage's a_b before the attempt, kernels.lanes._read_sweeps)."""
    ref, ds = references(name), runs(name, method, driver)
    length = case_length(name)
    assert int(ds["state"]) == state_code(ds, "completed") == 8
    assert float(ds["sweep_duration"]) == pytest.approx(ref.duration, rel=1e-12)
    f1 = span(length)["w1"] / (2.0 * math.pi)
    assert float(ds["natural_frequency"]) == pytest.approx(f1, rel=1e-12)
    assert float(ds["peak_amplitude"]) == pytest.approx(ref.peak, rel=1e-4, abs=0)
    # Nothing that means nothing for a sweep: its tail is the whole sweep, so a tail amplitude
    # would be peak_amplitude again, and a sweep has no response period.
    assert "amplitude" not in ds and "response_period" not in ds
    assert "load_frequency" not in ds               # no end load
    g = CASES[name][0]
    quasi_static = GAMMA * g * G / span(length)["w1"] ** 2
    if name in QUASI_STATIC:
        # Far below f1 the response follows the clamps: the peak is the quasi-static
        # deflection (4/pi) A / (w1^2 - w^2) at the sweep's top, 60 Hz (+14 % over w = 0),
        # up and down alike: the level's rise over 10 cycles leaves no start-up transient
        # to speak of (from rest at full level the down sweep peaked 1.32x higher).
        w_top = 2.0 * math.pi * 60.0
        linear_top = GAMMA * g * G / (span(length)["w1"] ** 2 - w_top ** 2)
        assert 0.98 * linear_top < ref.peak < 1.02 * linear_top
    else:
        assert abs(float(ds["peak_frequency"]) - ref.peak_frequency) <= 0.05
        # The peak is a resonance, far above the quasi-static response.
        assert ref.peak > 5.0 * quasi_static


@pytest.mark.slow
def test_a_sweep_from_rest_at_full_level_keeps_its_start_up_transient(references):
    """base.sweep.ramp_cycles = 0: the clamps start at full level at the sweep's first
    frequency, the old start. The quasi-static span swept down from 60 Hz then peaks at its
    start-up transient (SciPy, no ramp: 1.32x the ramped sweep's peak), and the engine agrees
    with SciPy on it to 1e-4."""
    g, start, stop = CASES["quasi-static down"]
    ref = Reference(start, stop, constant_level(g), length=SHORT, ramp_cycles=0.0)
    ds = sweep.run(scene(f"acceleration_g = {g!r}\n"
                         f"sweep = {{ start = {start!r}, stop = {stop!r}, rate = {RATE!r}, "
                         "ramp_cycles = 0.0 }", length=SHORT))
    assert float(ds["peak_amplitude"]) == pytest.approx(ref.peak, rel=1e-4, abs=0)
    ramped = references("quasi-static down").peak
    assert 1.2 * ramped < ref.peak < 1.5 * ramped


@pytest.mark.parametrize("g", fast_first([0.5, 0.1], 0.1))
def test_up_sweep_peaks_above_down_sweep(g, references, runs):
    """A hardening span swept up rides the upper branch past f1 (and the sweep rate delays the
    peak in the sweep's direction); swept down it jumps up at the lower fold: the up sweep's
    peak frequency is the higher, both references' and the package's, both above f1."""
    up, down = references(f"{g} g up"), references(f"{g} g down")
    assert up.peak_frequency > down.peak_frequency > F1
    assert (float(runs(f"{g} g up")["peak_frequency"])
            > float(runs(f"{g} g down")["peak_frequency"]) > F1)
    if g == 0.1:     # an interior jump: the upper branch ends before the sweep does
        assert up.peak_frequency < 55.0
        assert up.peak > down.peak


# ------------------------------------ several sweeps of their own durations in one lanes call

GRID_RATES = [4.0, 8.0]             # octaves per minute: sweeps of 23.8 and 11.9 s
GRID_LENGTHS = [SHORT, LENGTH]      # below resonance the whole sweep, and through it


@pytest.mark.slow
def test_sweeps_of_their_own_durations_share_the_lanes(references):
    """Four sweeps in one lanes call (two spans x two rates, 0.5 g up, 20 -> 60 Hz: below
    resonance the whole sweep, and up the resonant branch to its end): each lane ends with its
    own sweep (23.8 or 11.9 s), and each point's peak, its frequency and its envelope equal
    SciPy's run of that sweep alone (1e-4, 0.05 Hz, 1e-4 in every band) and the scalar
    driver's (1e-6; it runs each point with its own end time)."""
    known = {(SHORT, RATE): "quasi-static up", (LENGTH, RATE): "0.5 g up"}
    runs = {driver: sweep.run(scene(
        f"acceleration_g = 0.5\n{swept(20.0, 60.0)}",
        f'driver = "{driver}"\n[outputs]\nenvelope = true\nbands_per_octave = {BANDS}\n'
        f"[axes]\nlength = {GRID_LENGTHS!r}\nbase_sweep_rate = {GRID_RATES!r}\n"))
        for driver in DRIVERS}
    ds = runs["lanes"]
    assert np.all(ds["state"].values == state_code(ds, "completed"))
    for length in GRID_LENGTHS:
        for rate in GRID_RATES:
            point = ds.sel(length=length, base_sweep_rate=rate)
            ref = (references(known[length, rate]) if (length, rate) in known
                   else Reference(20.0, 60.0, constant_level(0.5), rate=rate, length=length))
            assert float(point["sweep_duration"]) == pytest.approx(ref.duration, rel=1e-12)
            assert float(point["peak_amplitude"]) == pytest.approx(ref.peak, rel=1e-4)
            if length == LENGTH:      # a resonance's frequency (below it the peak is the top's)
                assert abs(float(point["peak_frequency"]) - ref.peak_frequency) <= 0.05
            expected = ref.envelope()
            centres = point["band_frequency"].values
            for k, v in zip(np.round(BANDS * np.log2(centres / 1000.0)).astype(int),
                            point["envelope"].values):
                if k in expected:
                    assert v == pytest.approx(expected[k], rel=1e-4), (length, rate, k)
                else:
                    assert np.isnan(v), (length, rate, k)
    for name in ("peak_amplitude", "peak_frequency", "envelope", "absolute_acceleration"):
        np.testing.assert_allclose(ds[name].values, runs["scalar"][name].values, rtol=1e-6)


def test_a_bad_row_in_a_lanes_sweep_is_answered_and_the_others_run():
    """A row the kernel cannot integrate (a NaN mass) among good ones in one lanes call of a
    sweep: its state is invalid_input and its envelope NaN, and the other rows equal those of
    a call without it (the lanes keep nothing of one row for the next)."""
    from sweep.kernels import metrics as mt
    from sweep.kernels import oscillator as osc
    from sweep.models import transverse as tm
    sc = scene(f"acceleration_g = 0.1\n{swept(20.0, 60.0)}",
               f"[outputs]\nenvelope = true\n[axes]\nlength = [0.2, {LENGTH!r}, 0.4]\n",
               rtol=1e-8)
    system = tm._system(tm.resolve(sc), tm.settings_vector(sc))
    rows = system.rows_at(np.arange(3))
    good = system.chunk_fn(rows, *system.args, threads=1)
    bad_rows = rows.copy()
    bad_rows[1, osc.MASS] = math.nan
    bad = system.chunk_fn(bad_rows, *system.args, threads=1)
    assert bad["states"][1] == mt.INVALID_INPUT
    assert np.all(np.isnan(bad["envelope"][1])) and bad["envelope"].shape[1] > 0
    for k in (0, 2):
        assert bad["states"][k] == good["states"][k] == mt.COMPLETED
        np.testing.assert_array_equal(bad["envelope"][k], good["envelope"][k])
        np.testing.assert_array_equal(bad["reals"][k], good["reals"][k])


# ------------------------------------------------------ 2. slow sweep -> steady resonance

SLOW_LEVEL = 0.005             # g
SLOW_RATES = [8.0, 2.0, 0.5]   # octaves per minute


def test_slow_sweep_approaches_steady_resonance():
    """At 0.005 g the span is linear to K3 a^2 / w1^2 = 5e-4 (a frequency shift of 2e-4, an
    amplitude change of about as much): a sweep over 0.8-1.2 f1 at 8, 2, 0.5 oct/min peaks
    below the steady resonance (4/pi) A / sqrt((w1^2 - w^2)^2 + (2 zeta w1 w)^2) maximised over
    w, closer the slower (measured 0.905, 0.981, 0.998), the slowest within 2 %; its peak
    frequency lies past resonance in the sweep's direction, closer the slower."""
    c = span()
    w1 = c["w1"]
    a = SLOW_LEVEL * G

    def steady(w):
        return GAMMA * a / math.sqrt((w1 ** 2 - w ** 2) ** 2 + (2 * ZETA * w1 * w) ** 2)
    best = minimize_scalar(lambda w: -steady(w), bounds=(0.9 * w1, 1.1 * w1), method="bounded",
                           options={"xatol": 1e-10 * w1})
    resonance, w_r = -best.fun, best.x
    assert resonance == pytest.approx(GAMMA * a / (2 * ZETA * w1 ** 2 * math.sqrt(1 - ZETA ** 2)),
                                      rel=1e-9)
    assert c["k3"] * resonance ** 2 / w1 ** 2 < 1e-3
    ds = sweep.run(scene(f"acceleration_g = {SLOW_LEVEL!r}\n{swept(0.8 * F1, 1.2 * F1)}",
                         f"[axes]\nbase_sweep_rate = {SLOW_RATES!r}\n", rtol=1e-9))
    assert ds["peak_amplitude"].dims == ("base_sweep_rate",)
    assert np.all(ds["state"].values == 8)
    ratio = ds["peak_amplitude"].sel(base_sweep_rate=SLOW_RATES).values / resonance
    assert np.all(np.diff(ratio) > 0), ratio
    assert np.all(ratio < 1.0), ratio
    assert ratio[-1] > 0.98, ratio
    shift = ds["peak_frequency"].sel(base_sweep_rate=SLOW_RATES).values / (w_r / (2 * math.pi))
    assert np.all(np.diff(shift) < 0) and np.all(shift > 1.0), shift
    assert shift[-1] < 1.005, shift
    np.testing.assert_allclose(ds["sweep_duration"].values,
                               60 * math.log2(1.5) / np.array(SLOW_RATES), rtol=1e-12)


# -------------------------------------------------------------------- 3. the envelope

@pytest.mark.parametrize("driver", DRIVERS)
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", fast_first(["0.5 g up", "0.5 g down", "0.1 g up",
                                             "0.1 g down", "quasi-static up",
                                             "quasi-static down"], "0.1 g up"))
def test_envelope_matches_scipy_extrema_binned(name, method, driver, references, runs):
    """The envelope against the SciPy extrema binned into the same bands: equal to 1e-4 in
    every band (20-35 Hz below resonance, the resonant bands, those above; the quasi-static
    span below resonance throughout), NaN exactly where no extremum falls; the coordinates are
    1000 2^(k/N) Hz with edges 2^(+-1/2N) about them, and selecting by nearest frequency
    works."""
    ref, ds = references(name), runs(name, method, driver)
    env = ds["envelope"]
    assert env.dims == ("band_frequency",)
    centres = env["band_frequency"].values
    k = np.round(BANDS * np.log2(centres / 1000.0)).astype(int)
    np.testing.assert_allclose(centres, 1000.0 * 2.0 ** (k / BANDS), rtol=1e-14)
    assert np.all(np.diff(k) == 1)
    bounds = ds["band_frequency_bounds"].values
    np.testing.assert_allclose(bounds, np.stack([centres * 2 ** (-0.5 / BANDS),
                                                 centres * 2 ** (0.5 / BANDS)], axis=1),
                               rtol=1e-14)
    expected = ref.envelope()
    # The bands cover the sweep: 20 Hz lies in band -17 (19.7 Hz), 60 Hz in band -12 (62.5 Hz).
    assert set(expected) <= set(k) and set(expected) == set(range(-17, -11))
    values = env.values
    for kk, v in zip(k, values):
        if kk in expected:
            assert v == pytest.approx(expected[kk], rel=1e-4, abs=0), (kk, v, expected[kk])
        else:
            assert np.isnan(v), (kk, v)
    # The envelope's largest band is the peak.
    assert np.nanmax(values) == pytest.approx(float(ds["peak_amplitude"]), rel=1e-14)
    at_40 = env.sel(band_frequency=40.0, method="nearest")
    assert float(at_40["band_frequency"]) == pytest.approx(1000.0 * 2 ** (-14 / 3), rel=1e-14)
    assert float(at_40) == pytest.approx(expected[-14], rel=1e-4)


# ------------------------------------------------------------------ 4. a level table

LEVELS_G = [[10.0, 0.2], [40.0, 0.2], [50.0, 0.4], [100.0, 0.4]]
TABLE_BANDS = 12               # 1/12-octave bands (6 % wide): the envelope follows the level


@pytest.mark.slow
@pytest.mark.parametrize("method", METHODS)
def test_level_table_sweep_matches_scipy(method):
    """levels_g interpolated log-log (+6.2 dB/octave between 40 and 50 Hz): a 20 -> 80 Hz sweep
    against SciPy with the table read in this file, peak to 1e-4, its frequency to 0.05 Hz.
    The peak (58.1 Hz) lies on the 0.4 g plateau, where the upper branch has forgotten the
    level before it; the 1/12-octave envelope, to 1e-4 in every band, checks the ramp too."""
    lev = table_level(LEVELS_G)
    assert lev(45.0) / G == pytest.approx(0.2 * (45 / 40) ** (math.log(2) / math.log(50 / 40)))
    ref = Reference(20.0, 80.0, lev)
    rows = ", ".join(f"[{f!r}, {g!r}]" for f, g in LEVELS_G)
    ds = sweep.run(scene(f"levels_g = [{rows}]\n{swept(20.0, 80.0)}",
                         f'method = "{method}"\n[outputs]\nenvelope = true\n'
                         f"bands_per_octave = {TABLE_BANDS}\n"))
    assert int(ds["state"]) == 8
    assert float(ds["sweep_duration"]) == pytest.approx(30.0, rel=1e-12)
    assert float(ds["peak_amplitude"]) == pytest.approx(ref.peak, rel=1e-4, abs=0)
    assert abs(float(ds["peak_frequency"]) - ref.peak_frequency) <= 0.05
    expected = ref.envelope(TABLE_BANDS)
    centres = ds["band_frequency"].values
    k = np.round(TABLE_BANDS * np.log2(centres / 1000.0)).astype(int)
    np.testing.assert_allclose(centres, 1000.0 * 2.0 ** (k / TABLE_BANDS), rtol=1e-14)
    assert set(expected) == {kk for kk, v in zip(k, ds["envelope"].values) if np.isfinite(v)}
    got = np.array([ds["envelope"].values[list(k).index(kk)] for kk in sorted(expected)])
    np.testing.assert_allclose(got, [expected[kk] for kk in sorted(expected)], rtol=1e-4, atol=0)
    # base_level_g, where stored, is the table at the band centres.
    if "base_level_g" in ds:
        np.testing.assert_allclose(ds["base_level_g"].values,
                                   [lev(min(max(c, 10.0), 100.0)) / G for c in centres],
                                   rtol=1e-12)


# ------------------------------------------------------------------ three modes, two tolerances

@pytest.mark.slow
def test_three_modes_sweep_converges_in_tolerance(references):
    """model.modes = 3 on the 0.5 g up sweep: the midspan deflection q1 - q3 at rtol 1e-8 and
    1e-10 agree (peak to 1e-6, its frequency to 1e-3 Hz), the antisymmetric q2 stays zero from
    rest, and the third mode moves the peak by a little (measured 3.5 %) but not by nothing."""
    base = f"acceleration_g = 0.5\n{swept(20.0, 60.0)}"
    coarse, fine = (sweep.run(scene(base, rtol=rtol, modes=3)) for rtol in (1e-8, 1e-10))
    for ds in (coarse, fine):
        assert int(ds["state"]) == 8
    assert float(coarse["peak_amplitude"]) == pytest.approx(float(fine["peak_amplitude"]),
                                                            rel=1e-6)
    assert abs(float(coarse["peak_frequency"]) - float(fine["peak_frequency"])) < 1e-3
    modal = fine["modal_amplitude"]
    assert float(modal.sel(mode=2)) < 1e-12 * float(modal.sel(mode=1))
    assert 0.0 < float(modal.sel(mode=3)) < 0.1 * float(modal.sel(mode=1))
    one = references("0.5 g up").peak
    assert 1e-3 < abs(float(fine["peak_amplitude"]) / one - 1.0) < 0.1


# ---------------------------------------------------------------------- 5. bad input

SWEEP = swept(20.0, 60.0)
BAD = {
    "sweep without rate": ("acceleration_g = 0.5\nsweep = { start = 20.0, stop = 60.0 }",
                           "", ["base.sweep", "rate"]),
    "start == stop": ("acceleration_g = 0.5\n" + swept(20.0, 20.0), "", ["base.sweep"]),
    "sweep and frequency": (f"acceleration_g = 0.5\nfrequency = 30.0\n{SWEEP}", "",
                            ["base.frequency", "base.sweep"]),
    "table short of the sweep": (f"levels_g = [[30.0, 0.2], [100.0, 0.2]]\n{SWEEP}", "",
                                 ["base.levels_g"]),
    "lanes driver, three modes": (f"acceleration_g = 0.5\n{SWEEP}", 'driver = "lanes"\n',
                                  ["solver.driver", "lanes", "several modes"]),
    "envelope without sweep": ("acceleration_g = 0.5\nfrequency = 30.0",
                               "[outputs]\nenvelope = true\n", ["outputs.envelope"]),
    "unknown sweep key": ("acceleration_g = 0.5\n"
                          "sweep = { start = 20.0, stop = 60.0, rate = 4.0, speed = 1.0 }", "",
                          ["base.sweep.speed"]),
}


@pytest.mark.parametrize("name", list(BAD))
def test_bad_sweep_input_is_one_clear_line(name):
    base, extra, words = BAD[name]
    with pytest.raises(UserError) as info:
        sweep.run(scene(base, extra, modes=3 if "three modes" in name else 1))
    assert isinstance(info.value, SceneError)
    message = str(info.value)
    assert "\n" not in message and message
    for word in words:
        assert word in message, message


# ------------------------------------------- 6. the lanes' fast sine at a sweep's phases

def _libm_ulps(x, fast, exact):
    ref = exact(x)
    return np.abs(fast(x) - ref) / np.spacing(np.abs(ref))


@pytest.fixture(scope="module")
def fast_trig():
    """Vectorised wrappers of kernels.vecmath.fast_sin / fast_cos (Numba, not cached)."""
    import numba as nb
    from sweep.kernels.vecmath import fast_cos, fast_sin

    @nb.njit
    def apply(x, which):
        out = np.empty_like(x)
        for i in range(x.size):
            out[i] = fast_sin(x[i]) if which == 0 else fast_cos(x[i])
        return out
    return (lambda x: apply(x, 0)), (lambda x: apply(x, 1))


@pytest.mark.parametrize("top", [1e5, 1e6])
def test_fast_sine_is_accurate_at_large_phases(top, fast_trig):
    """vecmath promises 'about an ulp' for |x| < 1e5 (Cody-Waite with a three-part pi/2, whose
    33-bit leading parts times k stay exact to k < 2^20, |x| ~ 1.6e6); a stepped sweep reaches
    2 pi 100 Hz 130 s ~ 8e4 rad. Against libm (itself within an ulp): within 3 ulp of the
    result (measured 2) on random phases to `top` and near every multiple of pi/2 there, where
    the result is tiny and a reduction that lost the tail of pi/2 (k x 2e-21 rad) would miss
    by many ulps. Checked against the Python function too (same arithmetic, no fast-math)."""
    fsin, fcos = fast_trig
    rng = np.random.default_rng(20240)
    k = np.arange(1.0, math.floor(top * 2 / math.pi))
    k = k[:: max(1, k.size // 100_000)]
    x = np.concatenate([rng.uniform(-top, top, 100_000), k * (math.pi / 2), -k * (math.pi / 2),
                        np.nextafter(k * (math.pi / 2), np.inf)])
    assert np.max(np.abs(x)) <= top
    for fast, exact in ((fsin, np.sin), (fcos, np.cos)):
        ulps = _libm_ulps(x, fast, exact)
        assert np.max(ulps) <= 3.0, (exact.__name__, x[np.argmax(ulps)], np.max(ulps))
    from sweep.kernels.vecmath import fast_cos, fast_sin
    for v in (top, -top, 0.5 * top + 0.3, 2 * math.pi * 100 * 130):
        assert abs(fast_sin.py_func(v) - math.sin(v)) <= 3 * math.ulp(abs(math.sin(v)))
        assert abs(fast_cos.py_func(v) - math.cos(v)) <= 3 * math.ulp(abs(math.cos(v)))


@pytest.mark.parametrize("scene_name, key, value", [
    ("paper-fig7", "outputs.bands_per_octave", 6),     # longitudinal, no [base]
    ("paper-fig5", "outputs.bands_per_octave", 12),    # transverse, no [base]
    ("paper-fig5", "outputs.envelope", True),
    ("harness-parametric", "outputs.envelope", True),
])
def test_envelope_keys_without_a_sweep_are_refused_in_every_scene(scene_name, key, value):
    """The envelope and its bands are refused where nothing sweeps, not only in a [base]
    scene (a scene without [base] took them silently)."""
    with pytest.raises(SceneError) as info:
        sweep.load_scene(scene_name, overrides={key: value})
    message = str(info.value)
    assert "\n" not in message and key in message, message
