"""outputs.response_asd: the response's spectral densities of a random scene
(sweep/models/response_asd.py, docs/model.md sec. 11.6), against independent references.

- `welch` against scipy.signal.welch on the same samples (its definition: Hann window, half
  overlap, mean removed, one-sided density).
- The reduction of a chunk's samples: the absolute acceleration's ASD from the deflection's
  samples (second difference, corrected) and the record's (cross term kept), against
  scipy.signal.welch of the exact q'' + a_b of a signal known in closed form.
- A linear span (clamps.axial_stiffness = 0: no stretching), one pinned mode and three: the
  deflection's and the absolute acceleration's ASD integrated over bands below, at and above
  each resonance against the exact integrals of |H|^2 W in the same bands (quadrature written
  here), within the records' statistical error; the deflection ASD's integral against the
  RMS the kernels accumulate; the input spectrum beside them.
- The scene: rules in one line, the frequency dimension selectable, the same bits over
  threads and chunks, time series and spectra together.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.signal
from scipy.integrate import quad

import sweep
from sweep.errors import SceneError
from sweep.models import response_asd
from sweep.schema import STANDARD_GRAVITY as G

FLAT = [[10.0, 0.04], [500.0, 0.04]]        # g^2/Hz


def scene(overrides: dict | None = None, axes: dict | None = None):
    """A random scene of a 0.3 m Table-1 span (f1 = 42.4 Hz) under FLAT, spectra on."""
    text = ["[cable]", "length = 0.3", "damping_ratio = 0.05", "inertia = 2.865e-12",
            "[base]", f"asd_g2 = {FLAT}", "duration = 1.0", "realisations = 2", "seed = 3",
            "[outputs]", "response_asd = true"]
    if axes:
        text.append("[axes]")
        text += [f"{k} = {v}" for k, v in axes.items()]
    return sweep.load_scene_text("\n".join(text) + "\n", overrides=overrides or {})


# ------------------------------------------------------------------- 1. Welch's estimate

@pytest.mark.parametrize("n, nperseg", [(5000, 512), (4099, 1024), (1000, 1000)])
def test_welch_is_scipys(n, nperseg):
    x = np.random.default_rng(n).standard_normal(n) + 0.3
    f, p = response_asd.welch(x, 1234.0, nperseg)
    f_ref, p_ref = scipy.signal.welch(x, 1234.0, nperseg=nperseg)
    np.testing.assert_allclose(f, f_ref, rtol=1e-14)
    np.testing.assert_allclose(p, p_ref, rtol=1e-10, atol=1e-14 * p_ref.max())


def test_the_absolute_acceleration_asd_is_welchs_of_the_exact_signal():
    """q(t) and a_b(t) sums of sines with random phases over the band: the reduction sees
    q at fs / m and the record at fs; its acceleration ASD is scipy's Welch of the exact
    q'' + a_b at the same instants, bin by bin where the signal has power."""
    rng = np.random.default_rng(5)
    fs, m, top = 8000.0, 2, 1000.0
    rate = fs / m
    freqs = rng.uniform(20.0, top, 40)
    aq = rng.uniform(0.5, 1.0, 40) * 1e-3 / (1.0 + (freqs / 100.0) ** 2)
    ab = rng.uniform(0.5, 1.0, 40) * 10.0
    pq, pb = rng.uniform(0, 2 * np.pi, 40), rng.uniform(0, 2 * np.pi, 40)
    t_end = 4.0
    n_rec = int(t_end * fs) + 1
    t_rec = np.arange(n_rec) / fs
    w = 2 * np.pi * freqs
    a_b = (ab * np.sin(np.outer(t_rec, w) + pb)).sum(1)
    records = np.zeros((2, n_rec, 2))
    records[1, :, 0] = a_b                                  # record 1, level factor 0.5
    t = np.arange(int(t_end * rate) + 1) / rate
    q = (aq * np.sin(np.outer(t, w) + pq)).sum(1)
    q2 = (-aq * w * w * np.sin(np.outer(t, w) + pq)).sum(1)
    nperseg = 1024
    red = response_asd.Reduction(rate=rate, decimation=m, nperseg=nperseg,
                                 n_freq=int(top * nperseg / rate) + 1, t_end=t_end,
                                 record_column=0, scale_column=1, window_column=0,
                                 keep_series=False)
    window = 3.0                                          # s, the last 3 s
    solved = {"series": q[None, :], "reals": np.array([[window]])}
    out = red.empty(1)
    red.fill(np.array([[1.0, 0.5]]), records, solved, out, 0, 1)
    first = int(math.ceil((t_end - window) * rate))
    exact = q2 + 0.5 * (ab * np.sin(np.outer(t, w) + pb)).sum(1)
    _, ref = scipy.signal.welch(exact[first + 1:-1], rate, nperseg=nperseg)
    _, ref_q = scipy.signal.welch(q[first + 1:-1], rate, nperseg=nperseg)
    ref, ref_q = ref[:red.n_freq], ref_q[:red.n_freq]
    got, got_q = out["acceleration_asd"][0], out["deflection_asd"][0]
    np.testing.assert_allclose(got_q, ref_q, rtol=1e-10, atol=1e-12 * ref_q.max())
    strong = ref > 1e-3 * ref.max()
    assert strong.sum() > 50
    np.testing.assert_allclose(got[strong], ref[strong], rtol=2e-2)
    assert abs(got.sum() / ref.sum() - 1.0) < 2e-3


# --------------------------------------------------- 2. a linear span against |H|^2 W

def _transfer(f, f1, zeta, modes):
    """Midspan receptance G(f) of pinned sines (mode n at n^2 f1, midspan sin(n pi / 2),
    participation 4 / (n pi)) and the absolute acceleration's 1 - w^2 G."""
    w = 2 * np.pi * np.asarray(f, float)
    g = 0.0
    for n in range(1, modes + 1):
        wn = 2 * np.pi * f1 * n * n
        g = g - math.sin(n * math.pi / 2) * 4 / (n * math.pi) / (wn * wn - w * w
                                                                 + 2j * zeta * wn * w)
    return g, 1.0 - w * w * g


def _band(ds, name, lo, hi):
    f = ds.asd_frequency.values
    df = f[1] - f[0]
    inside = (f >= lo) & (f < hi)
    return float(ds[name].isel(asd_frequency=np.flatnonzero(inside)).sum("asd_frequency")) * df


@pytest.mark.parametrize("modes, bands", [
    (1, [(10.0, 30.0), (30.0, 60.0), (60.0, 500.0)]),
    (3, [(10.0, 30.0), (30.0, 60.0), (60.0, 300.0), (300.0, 500.0)])])
def test_a_linear_span_meets_the_exact_asd_in_every_band(modes, bands):
    """16 records of 4 s, stretching off: each band's integral of the deflection ASD and of
    the absolute acceleration ASD (g^2) against the exact one within 4 standard errors of a
    mean square over that band (the band's response: 1 / sqrt(zeta w1 R T) at the resonance,
    less elsewhere, bounded here by 12 %), below, at and above mode 1 and around mode 3."""
    ds = sweep.run(scene({"clamps.axial_stiffness": 0.0, "model.modes": modes,
                          "base.realisations": 16, "base.duration": 4.0}), progress=False)
    f1 = float(ds.natural_frequency)
    zeta = 0.05
    w0 = 0.04 * G * G                                     # (m/s^2)^2/Hz
    for lo, hi in bands:
        exact_q = quad(lambda f: abs(_transfer(f, f1, zeta, modes)[0]) ** 2 * w0, lo, hi,
                       limit=200, points=[f1, 9 * f1])[0]
        exact_a = quad(lambda f: abs(_transfer(f, f1, zeta, modes)[1]) ** 2 * w0, lo, hi,
                       limit=200, points=[f1, 9 * f1])[0] / G ** 2
        got_q = _band(ds, "deflection_asd", lo, hi)
        got_a = _band(ds, "acceleration_asd", lo, hi)
        assert got_q == pytest.approx(exact_q, rel=0.12), (lo, hi, got_q, exact_q)
        assert got_a == pytest.approx(exact_a, rel=0.12), (lo, hi, got_a, exact_a)
    # the exact linear densities stored beside them are this test's closed forms
    nu = ds.asd_frequency.values
    g, t = _transfer(nu, f1, zeta, modes)
    inside = (nu >= 10.0) & (nu <= 500.0)
    np.testing.assert_allclose(ds.linear_deflection_asd.values, np.abs(g) ** 2 * w0 * inside,
                               rtol=1e-9, atol=0.0)
    np.testing.assert_allclose(ds.linear_acceleration_asd.values,
                               np.abs(t) ** 2 * w0 * inside / G ** 2, rtol=1e-9, atol=0.0)
    # the whole spectrum is the mean square the kernels integrated (same records, windows)
    total = _band(ds, "deflection_asd", 0.0, 1e9)
    assert total == pytest.approx(float((ds.rms_deflection ** 2).mean()), rel=0.03)
    # the input beside it: the spectrum in g^2/Hz inside its band, 0 outside
    assert float(ds.base_asd_g2.sel(asd_frequency=100.0, method="nearest")) == pytest.approx(0.04)
    assert float(ds.base_asd_g2.sel(asd_frequency=5.0, method="nearest")) == 0.0
    assert ds.acceleration_asd.attrs["units"] == f"{G ** 2:.10g} m2 s-4 Hz-1"
    assert ds.deflection_asd.attrs["units"] == "m2 Hz-1"


# ---------------------------------------------------------------------------- 3. the scene

def test_the_spectra_select_and_do_not_depend_on_threads_or_chunks():
    sc = scene(axes={"base_asd_scale": [-6.0, 0.0]})
    ds = sweep.run(sc, threads=2, progress=False)
    again = sweep.run(scene({"run.chunk_size": 1}, axes={"base_asd_scale": [-6.0, 0.0]}),
                      threads=1, progress=False)
    for name in ("deflection_asd", "acceleration_asd", "base_asd_g2"):
        np.testing.assert_array_equal(ds[name].values, again[name].values)
    assert ds.deflection_asd.dims == ("base_asd_scale", "asd_frequency")
    assert "displacement" not in ds
    df = float(ds.asd_frequency[1])
    for level in (-6.0, 0.0):   # each level's own mean square (Welch's Hann segments weigh
        # the window's samples unevenly: a 0.7 s window's two figures differ by a few %)
        total = float(ds.deflection_asd.sel(base_asd_scale=level).sum()) * df
        ms = float((ds.rms_deflection.sel(base_asd_scale=level) ** 2).mean())
        assert total == pytest.approx(ms, rel=0.1)
    assert float(ds.base_asd_g2.sel(base_asd_scale=-6.0, asd_frequency=100.0, method="nearest")) \
        == pytest.approx(0.04 * 10 ** (-6 / 10))
    assert ds.asd_frequency.attrs["units"] == "Hz"
    assert float(ds.asd_frequency[-1]) <= 500.0


def test_time_series_and_spectra_together():
    ds = sweep.run(scene({"outputs.time_series": True}), progress=False)
    dt = float(ds.elapsed_time[1] - ds.elapsed_time[0])
    assert dt == pytest.approx(1.0 / response_asd.asd_rate(5000.0, 500.0))
    assert np.all(np.isfinite(ds.displacement.values))
    assert np.all(np.isfinite(ds.deflection_asd.values))


@pytest.mark.parametrize("overrides, words", [
    ({"outputs.sample_interval": 1e-3}, "remove outputs.sample_interval"),
    ({"outputs.response_asd": False, "outputs.asd_resolution": 1.0},
     "only with outputs.response_asd"),
    ({"outputs.asd_resolution": 0.1}, "holds no Welch segment at 0.1 Hz"),
    ({"outputs.asd_resolution": 1000.0}, "(Hz) or finer"),
    ({"base.duration": 5000.0}, "samples a point, more than 10,000,000"),
])
def test_bad_spectra_keys_are_one_line(overrides, words):
    with pytest.raises(SceneError) as err:
        scene(overrides)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_response_asd_needs_a_spectrum():
    with pytest.raises(SceneError, match="only for a random base acceleration"):
        sweep.load_scene_text("[outputs]\nresponse_asd = true\n")


def test_a_finer_resolution_is_kept():
    """A resolution finer than the default's: the power-of-two segment at or below it."""
    coarse = sweep.run(scene(), progress=False)
    ds = sweep.run(scene({"outputs.asd_resolution": 4.0}), progress=False)
    df = float(ds.asd_frequency[1] - ds.asd_frequency[0])
    assert 2.0 < df <= 4.0 < float(coarse.asd_frequency[1])


def test_a_run_too_short_for_the_start_up_is_refused_for_that_not_the_spectra():
    with pytest.raises(SceneError) as err:
        sweep.run(scene({"base.duration": 0.3}), progress=False)
    assert "start-up transient" in str(err.value) and "response_asd" not in str(err.value)


def test_points_get_their_own_spectra():
    """[points]: the spectra on (point, frequency), each point's linear density its own."""
    text = ["[cable]", "inertia = 2.865e-12", "[base]", f"asd_g2 = {FLAT}", "duration = 1.0",
            "seed = 3", "[outputs]", "response_asd = true", "[points]",
            "length = [0.3, 0.25]", "damping_ratio = [0.05, 0.04]"]
    ds = sweep.run(sweep.load_scene_text("\n".join(text) + "\n"), progress=False)
    assert ds.acceleration_asd.dims == ("point", "asd_frequency")
    assert ds.linear_deflection_asd.dims == ("point", "asd_frequency")
    peaks = ds.linear_deflection_asd.idxmax("asd_frequency").values
    f1 = ds.natural_frequency.values
    assert np.all(np.abs(peaks - f1) <= float(ds.asd_frequency[1]))    # each its own resonance


@pytest.mark.parametrize("lengths", [[0.2, 0.25, 0.3], [0.12, 0.3]])
def test_the_segment_fits_the_shortest_window_of_a_length_by_damping_grid(lengths):
    """A damping axis beside a length axis: the Welch segment fits SEGMENTS half-overlapping
    in the shortest statistics window over the whole product grid, read from the result's own
    per-point windows (a reviewer: with 3 lengths and 2 dampings the run failed with a
    traceback; with 2 and 2 the two axes were paired point by point, so the grid's shortest
    window, at the longest span's lowest damping, was missed and the segment was 2.2 times too
    long for it)."""
    ds = sweep.run(scene({"base.duration": 4.0},
                         axes={"length": lengths, "damping_ratio": [0.015, 0.05]}),
                   progress=False)
    shortest = float(ds.statistics_window.min())
    segment = 1.0 / float(ds.asd_frequency[1] - ds.asd_frequency[0])      # s
    assert segment <= 2.0 * shortest / (response_asd.SEGMENTS + 1)
    assert segment >= 0.99 * shortest / (response_asd.SEGMENTS + 1)       # the longest that fits


def test_an_end_loads_frequency_axis_and_the_spectra_are_two_dimensions():
    """A harmonic end load swept in `frequency` (Hz) beside the spectra's `asd_frequency`."""
    sc = scene({"load.type": "harmonic", "load.amplitude": 1.0},
               axes={"frequency": [30.0, 60.0]})
    ds = sweep.run(sc, progress=False)
    assert ds.acceleration_asd.dims == ("frequency", "asd_frequency")
    assert ds.frequency.values.tolist() == [30.0, 60.0]
    assert float(ds.asd_frequency[-1]) <= 500.0
