"""The response's acceleration spectral densities of a random scene (outputs.response_asd,
docs/model.md sec. 11.6): Welch's estimate of the midspan deflection's ASD (m^2/Hz) and of the
midspan's absolute acceleration (g^2/Hz) over each record's statistics window, averaged over the
realisations, on an `asd_frequency` dimension up to the spectrum's top frequency, with the input
spectrum beside them.

How. The kernels sample q(t) on their dense output at fs_asd = fs / m (fs the records' rate,
m = `decimation`, so fs_asd >= 4 x the spectrum's top frequency where fs allows) at the
instants k / fs_asd, which are the records' own samples k m / fs: there a_b is exact. Chunk by
chunk (`Reduction`, run by sweep.execute.reduced_chunk) each point's samples inside its window
become Welch's estimate (`welch`: Hann window, half-overlapping segments of `nperseg` samples,
each segment's mean removed, one-sided density: SciPy's scipy.signal.welch defaults), and the
samples are dropped: the series of a long record never sits in memory for the whole grid. The
relative acceleration q'' is the samples' central second difference, whose spectrum is q's
times -(2/dt)^2 sin^2(pi f dt); each segment's transform is divided by that factor's ratio to
-(2 pi f)^2, (sin x / x)^2 with x = pi f dt (smooth over the band: 1.14 at the top frequency of
the default rate), and the base acceleration's transform added before squaring, so the
absolute acceleration q'' + a_b keeps its cross term.

Resolution: outputs.asd_resolution (Hz), or by default the finest with at least `SEGMENTS`
half-overlapping segments in the shortest statistics window of the grid; each segment has a
power-of-two length. A window too short for one segment at the asked resolution is refused in
one line (`segment_length`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from ..scene.messages import _fail, _show

FREQUENCY_DIM = "asd_frequency"
"""The spectra's dimension (Hz); not `frequency`, which is an end load's axis."""
SEGMENTS = 8
"""Half-overlapping Welch segments in the shortest statistics window, by default."""
OVERSAMPLING = 4.0
"""The ASD's samples are taken at the records' rate divided by the largest whole m that keeps
them at or above this many times the spectrum's top frequency."""
NAMES = ("deflection_asd", "acceleration_asd")
"""The reduced outputs, per point: (n, n_freq) each."""


def decimation(sample_rate: float, top: float) -> int:
    """m: the ASD's samples are every m-th of the records' (fs = sample_rate Hz, the
    spectrum's top frequency `top` Hz)."""
    ratio = sample_rate / (OVERSAMPLING * top)
    return max(1, int(math.floor(ratio + 1e-9))) if math.isfinite(ratio) else 1


def asd_rate(sample_rate: float, top: float) -> float:
    """fs_asd (Hz): the rate the kernels sample q(t) at for the ASD."""
    return sample_rate / decimation(sample_rate, top)


def segment_length(window: float, rate: float, resolution: float | None) -> int:
    """Welch's segment (samples, a power of two) for a shortest statistics window of `window`
    s sampled at `rate` Hz: the shortest at least rate / resolution long, or without a
    resolution the longest that fits SEGMENTS half-overlapping segments. Refuses (one line)
    a window that holds no segment at that resolution."""
    most = 2.0 ** 52               # beyond any record that fits in memory: no overflow below
    fits = min(window * rate - 2.0, most) if math.isfinite(window) else 0.0
    if resolution is None:
        n = 2 ** int(math.floor(math.log2(max(fits * 2.0 / (SEGMENTS + 1), 2.0))))
    else:
        n = 2 ** int(math.ceil(math.log2(min(max(rate / resolution, 2.0), most))))
    if n < 16 and resolution is not None and fits >= 16:
        _fail("scene key 'outputs.asd_resolution'", f"{_show(resolution)} Hz is coarser than "
              f"a Welch segment of 16 samples at {rate:.6g} Hz resolves",
              f"give outputs.asd_resolution = {rate / 16.0:.3g} (Hz) or finer")
    if n < 16 or n > fits:
        finest = 2 ** int(math.floor(math.log2(max(fits, 1.0))))
        coarsest = rate / max(finest, 1)
        _fail("scene key 'outputs.asd_resolution'" if resolution is not None
              else "scene key 'outputs.response_asd'",
              f"the shortest statistics window ({window:.3g} s, after the start-up transient) "
              + (f"holds no Welch segment at {_show(resolution)} Hz"
                 if resolution is not None else "is too short for a spectrum"),
              (f"give outputs.asd_resolution = {coarsest:.3g} (Hz) or coarser, or a longer "
               "base.duration" if finest >= 16 else "give a longer base.duration"))
    return n


def max_bins(random: Any, resolution: float | None) -> int:
    """An upper bound on the spectra's bins (for the memory check before the run): the
    spectrum's top frequency over the resolution, or over the finest the run allows."""
    top = float(random.spectrum[0][-1])
    finest = resolution if resolution is not None else (SEGMENTS + 1) / (2.0 * random.t_end)
    return int(min(math.ceil(2.0 * top / finest), 2.0 ** 52)) + 1   # no overflow for absurd input


CHUNK_BYTES = 256e6
"""Most bytes of time series in one chunk of a run with outputs.response_asd."""


def capped(options: Any, n_samples: int) -> Any:
    """Run options whose chunks hold at most CHUNK_BYTES of samples (n_samples a point): a
    chunk's series is reduced and dropped as it finishes, never held for the whole grid."""
    import dataclasses
    cap = max(1, int(CHUNK_BYTES // (8 * max(n_samples, 1))))
    if options.chunk_size is not None and options.chunk_size <= cap:
        return options
    return dataclasses.replace(options, chunk_size=cap)


def welch(x: np.ndarray, fs: float, nperseg: int) -> tuple[np.ndarray, np.ndarray]:
    """Welch's one-sided power spectral density of the samples x (last axis, fs Hz): Hann
    window (periodic), segments of nperseg samples overlapping by half, each segment's mean
    removed, the segments' periodograms averaged; as scipy.signal.welch(x, fs, nperseg=nperseg)
    with its defaults. Returns (f Hz, density in x's units^2 / Hz)."""
    window = _hann(nperseg)
    spectra = _transforms(np.asarray(x, float), window, nperseg // 2 + 1)
    return (np.fft.rfftfreq(nperseg, 1.0 / fs),
            _density(_power(spectra), window, fs).mean(axis=-2))


def _hann(n: int) -> np.ndarray:
    """The periodic Hann window of n samples (scipy.signal.get_window('hann', n))."""
    return 0.5 - 0.5 * np.cos(2.0 * np.pi * np.arange(n) / n)


def _segments(x: np.ndarray, nperseg: int) -> np.ndarray:
    """The half-overlapping segments of x's last axis: (..., segments, nperseg), a view."""
    step = nperseg // 2
    count = 1 + (x.shape[-1] - nperseg) // step
    view = np.lib.stride_tricks.sliding_window_view(x, nperseg, axis=-1)
    return view[..., :count * step:step, :]


def _transforms(x: np.ndarray, window: np.ndarray, n_freq: int) -> np.ndarray:
    """The first n_freq bins of the rfft of each of x's half-overlapping segments (last
    axis; `_segments`, window.size samples), its mean removed and `window` applied."""
    segments = _segments(x, window.size)
    centred = segments - segments.mean(axis=-1, keepdims=True)
    centred *= window                  # in place: one large temporary fewer
    return np.fft.rfft(centred, axis=-1)[..., :n_freq]


def _power(spectra: np.ndarray) -> np.ndarray:
    """|X|^2 of complex transforms, as re^2 + im^2 (abs() ** 2 takes a square root to square
    it again)."""
    return spectra.real * spectra.real + spectra.imag * spectra.imag


def _density(power: np.ndarray, window: np.ndarray, fs: float) -> np.ndarray:
    """|X|^2 of windowed segments (the first bins of their rfft, last axis) as a one-sided
    density (units^2 / Hz): divided by fs sum(w^2), doubled except at 0 Hz and, where the
    bins reach it, at the Nyquist frequency of an even segment."""
    nperseg = window.size
    out = power / (fs * float(np.sum(window * window)))
    out[..., 1:] *= 2.0
    if nperseg % 2 == 0 and power.shape[-1] == nperseg // 2 + 1:
        out[..., -1] /= 2.0
    return out


@dataclass(frozen=True)
class Reduction:
    """What reduces a chunk's deflection samples to its spectra (sweep.execute.reduced_chunk):
    rate (Hz, fs_asd), decimation m (the records' samples per ASD sample), nperseg (Welch's
    segment), n_freq (bins kept, 0 .. the spectrum's top frequency), t_end (s, the run's end:
    each window ends there), record_column and scale_column (a row's realisation and level
    factor, kernels.excitation's RECORD and RECORD_SCALE in the System's excitation block),
    keep_series (outputs.time_series: the samples stay as the result's q(t) too; `empty`
    then leaves the System's series in place)."""
    rate: float
    decimation: int
    nperseg: int
    n_freq: int
    t_end: float
    record_column: int
    scale_column: int
    window_column: int
    keep_series: bool

    def frequencies(self) -> np.ndarray:
        """The bins' frequencies (Hz)."""
        return np.arange(self.n_freq) * (self.rate / self.nperseg)

    def empty(self, n: int) -> dict[str, np.ndarray]:
        """The reduced outputs of n points (NaN until filled); without keep_series an empty
        series (n, 0) in place of the System's (n, n_samples)."""
        out = {name: np.full((n, self.n_freq), np.nan) for name in NAMES}
        if not self.keep_series:
            out["series"] = np.empty((n, 0))
        return out

    def fill(self, params: np.ndarray, records: np.ndarray, solved: dict[str, np.ndarray],
             out: dict[str, np.ndarray], lo: int, hi: int) -> None:
        """The spectra of rows lo..hi-1 (out[NAMES]) from their samples (solved['series'])
        over each row's statistics window (its length, solved['reals'][:, window_column])."""
        window = _hann(self.nperseg)
        f = self.frequencies()
        x = math.pi * f / self.rate
        with np.errstate(divide="ignore", invalid="ignore"):
            gain = np.where(x > 0.0, (x / np.sin(x)) ** 2, 1.0)   # (sin x / x)^-2
        series = solved["series"]
        n_rec = records.shape[1]
        for i in range(lo, hi):
            length = solved["reals"][i, self.window_column]
            if not np.isfinite(length):
                continue                                   # no window: NaN
            first = max(int(math.ceil((self.t_end - length) * self.rate - 1e-6)), 0)
            q = series[i, first:]
            if not (q.size >= self.nperseg + 2 and np.all(np.isfinite(q))):
                continue                                   # escaped, or too short: NaN
            a_rel = (q[2:] - 2.0 * q[1:-1] + q[:-2]) * (self.rate * self.rate)
            m = self.decimation                # a_b at the samples k = first + 1 .. q's last - 1
            start, last = (first + 1) * m, (first + q.size - 2) * m
            record = records[int(params[i, self.record_column]), :, 0]
            base = (record[start:last + 1:m] if last < n_rec      # a view: no gather
                    else record[np.arange(start, last + 1, m) % n_rec])
            a_base = params[i, self.scale_column] * base
            fq = _transforms(q[1:-1], window, self.n_freq)
            fr = _transforms(a_rel, window, self.n_freq)
            fb = _transforms(a_base, window, self.n_freq)
            fr *= gain
            fr += fb
            out["deflection_asd"][i] = _density(_power(fq), window, self.rate).mean(-2)
            out["acceleration_asd"][i] = _density(_power(fr), window, self.rate).mean(-2)


def reduction(random: Any, shortest: float, resolution: float | None, t_end: float,
              record_column: int, scale_column: int, window_column: int,
              keep_series: bool) -> Reduction:
    """The Reduction of a random scene (random: its RandomInputs; shortest: the grid's
    shortest statistics window, s, which sets the segment)."""
    top = float(random.spectrum[0][-1])
    m = decimation(random.sample_rate, top)
    rate = asd_rate(random.sample_rate, top)
    nperseg = segment_length(shortest, rate, resolution)
    n_freq = min(int(math.floor(top * nperseg / rate + 1e-9)) + 1, nperseg // 2 + 1)
    return Reduction(rate=rate, decimation=m, nperseg=nperseg, n_freq=n_freq, t_end=t_end,
                     record_column=record_column, scale_column=scale_column,
                     window_column=window_column, keep_series=keep_series)


def variables(spectra: dict[str, np.ndarray], reduction_: Reduction, dims: tuple[str, ...],
              shape: tuple[int, ...], realisation_dim: str, level: xr.DataArray,
              spectrum: tuple[np.ndarray, np.ndarray], g: float, g2_units: str
              ) -> tuple[dict[str, xr.DataArray], dict[str, xr.DataArray]]:
    """The result's spectra (variables, the frequency coordinate): each point's mean over the
    realisations that did not escape (NaN where all did) of the deflection and absolute
    acceleration ASDs, and the input's spectrum at the point's level (g^2/Hz); level: the
    base level factor on the axes it depends on; spectrum: (f Hz, W (m/s^2)^2/Hz) at 0 dB."""
    from .random import asd_at
    f = reduction_.frequencies()
    coord = xr.DataArray(f, dims=FREQUENCY_DIM, attrs={
        "units": "Hz", "long_name": f"frequency of the spectral densities (Welch, "
        f"{reduction_.rate / reduction_.nperseg:.4g} Hz resolution)"})
    full = dims + (FREQUENCY_DIM,)
    n = reduction_.n_freq
    segments = f"Hann-windowed segments of {reduction_.nperseg / reduction_.rate:.4g} s"
    with np.errstate(invalid="ignore"):
        q = xr.DataArray(spectra["deflection_asd"].reshape(shape + (n,)), dims=full).mean(
            realisation_dim)
        a = xr.DataArray(spectra["acceleration_asd"].reshape(shape + (n,)), dims=full).mean(
            realisation_dim) / (g * g)
    out = {
        "deflection_asd": q.assign_attrs(
            units="m2 Hz-1", long_name="spectral density of the midspan deflection over the "
            f"statistics window (Welch: {segments} overlapping by half), mean over the "
            "realisations that did not escape"),
        "acceleration_asd": a.assign_attrs(
            units=g2_units, long_name="spectral density of the absolute midspan "
            f"acceleration q'' + a_b in g^2/Hz (Welch: {segments} overlapping by half), mean "
            "over the realisations that did not escape"),
    }
    given = asd_at(f, spectrum[0], spectrum[1]) / (g * g)
    out["base_asd_g2"] = (level * level * xr.DataArray(given, dims=FREQUENCY_DIM)).assign_attrs(
        units=g2_units, long_name="spectral density of the base acceleration as "
        "specified, at the point's level (g^2/Hz; 0 outside the spectrum's band)")
    return out, {FREQUENCY_DIM: coord}
