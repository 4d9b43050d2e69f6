"""Stability charts (outputs.stability): the Ince-Strutt chart of a stability-only result (no
`state`), the Floquet boundary over the time-domain map of a result with both kinds, `sweep
plot` writing them, and the checks that let a stability-only result load."""

from __future__ import annotations

import matplotlib.image as mpimg
import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

import sweep
from sweep import cli
from sweep import plot as splot
from sweep.errors import UserError
from sweep.plot.overlays import MATHIEU_LABEL, mathieu_boundaries
from sweep.plot.stability import (FLOQUET_LABEL, plot_growth_rate, plot_stability_chart,
                                  plot_stability_over_map)

STABILITY_ONLY = """
name = "stab-tiny"
[model]
coefficients = "consistent"
[cable]
length = 1.0
damping_ratio = 0.02
[load]
type = "harmonic"
[axes]
frequency_ratio = {start = 0.5, stop = 2.6, num = 20}
load_amplitude = {start = 0.0, stop = 3.0, num = 8}
[outputs]
stability = true
amplitude = false
peak_amplitude = false
settling_time = false
response_period = false
solver_stats = false
"""

BOTH = """
name = "both-tiny"
[model]
coefficients = "consistent"
[cable]
damping_ratio = 0.02
[load]
amplitude = 2.0
[initial]
displacement = 1e-4
[axes]
length = [0.6, 0.8, 1.0]
frequency_ratio = [0.9, 1.0, 1.6, 1.9, 2.0, 2.1, 2.4]
[solver]
t_end = 2.0
[outputs]
stability = true
"""

ONE_AXIS = STABILITY_ONLY.replace("load_amplitude = {start = 0.0, stop = 3.0, num = 8}",
                                  "").replace('type = "harmonic"',
                                              'type = "harmonic"\namplitude = 2.0')


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    base = tmp_path_factory.mktemp("stability")
    out = {}
    for name, text in (("stab", STABILITY_ONLY), ("both", BOTH), ("line", ONE_AXIS)):
        path = base / f"{name}.nc"
        out[name] = (sweep.run(sweep.load_scene_text(text), output=path, progress=False), path)
    return out


def _png(path, fig=None):
    assert path.is_file() and path.stat().st_size > 1000, path
    image = mpimg.imread(path)
    assert float(image[..., :3].std()) > 0.01, f"{path} is blank"
    if fig is not None:
        w, h = fig.get_size_inches() * 100
        assert abs(image.shape[0] - h) <= 1 and abs(image.shape[1] - w) <= 1


def _texts(ax):
    return [t.get_text() for t in ax.texts]


def _legend(ax):
    return [t.get_text() for t in ax.get_legend().get_texts()]


def test_stability_only_result_has_no_state_and_loads(results):
    ds, path = results["stab"]
    assert "state" not in ds and {"growth_rate", "stability", "load_ratio"} <= set(ds)
    loaded = splot.load_result(path)
    assert "state" not in loaded
    splot.check_result(loaded)
    assert splot.swept_axes(loaded) == ["frequency_ratio", "load_amplitude"]
    one = splot.select_points(loaded, {"load_amplitude": float(loaded.load_amplitude[3])})
    assert splot.swept_axes(one) == ["frequency_ratio"]
    # Its footer tells the Floquet computation, not a time-domain solver it never ran.
    text = splot.footer(loaded)
    assert "Floquet" in text and "t_end" not in text and "rtol" not in text


def test_checks_stay_strict(results):
    ds, _ = results["stab"]
    with pytest.raises(UserError, match="no 'state' variable"):
        splot.check_result(ds.drop_vars("stability"))
    bad = ds.copy()
    bad["stability"] = bad["stability"].copy(data=np.full(bad["stability"].shape, 9, np.int8))
    with pytest.raises(UserError, match="not among its flag_values"):
        splot.check_result(bad)
    both, _ = results["both"]
    with pytest.raises(UserError, match="no 'state' variable"):
        splot.check_result(both.drop_vars(["state", "growth_rate"]))
    worse = both.copy()
    worse["stability"] = worse["stability"].astype(float)
    with pytest.raises(UserError, match="stability"):
        splot.check_result(worse)


def test_sweep_plot_writes_the_chart_of_a_stability_only_result(results, tmp_path, capsys):
    _, path = results["stab"]
    assert cli.main(["plot", str(path), "-o", str(tmp_path)]) == 0
    written = capsys.readouterr().out.split()
    assert [p.rsplit("/", 1)[-1] for p in written] == ["stab-stability.png"]
    _png(tmp_path / "stab-stability.png")


def test_chart_colour_bar_boundaries_and_tongues(results):
    ds, _ = results["stab"]
    fig = plot_stability_chart(ds)
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    # x: W/w1; y: P0/Pcr (load_ratio lies over load_amplitude alone).
    assert "W/w1" in ax.get_xlabel() and "P0/Pcr" in ax.get_ylabel()
    ratio = ds["load_ratio"].values
    assert ax.get_ylim()[1] == pytest.approx(ratio[-1] + 0.5 * (ratio[-1] - ratio[-2]))
    bars = [a for a in fig.axes if a is not ax]
    assert len(bars) == 1 and ("1/s" in bars[0].get_ylabel() or "s-1" in bars[0].get_ylabel())
    # The first-order undamped boundaries: principal 2 sqrt(1 -+ mu/2), the second zone's.
    lines = {line.get_gid(): line for line in ax.lines if str(line.get_gid()).startswith(
        "mathieu-")}
    assert set(lines) == {"mathieu-principal_low", "mathieu-principal_high",
                          "mathieu-second_low", "mathieu-second_high"}
    low = lines["mathieu-principal_low"]
    np.testing.assert_allclose(low.get_xdata(), 2 * np.sqrt(1 - low.get_ydata() / 2))
    high = lines["mathieu-second_high"]
    mu = high.get_ydata()
    np.testing.assert_allclose(high.get_xdata() ** 2, (1 + np.sqrt(1 + mu ** 2 / 3)) / 2)
    assert MATHIEU_LABEL in _legend(ax) and MATHIEU_LABEL == "first-order boundaries (undamped)"
    # The tongues: m = 1 at W/w1 = 2, then 2 at 1, 3 at 2/3 (0.5-2.6 holds m = 1 to 4).
    tongues = {t.get_gid(): t for t in ax.texts if str(t.get_gid()).startswith("tongue-label")}
    assert tongues["tongue-label-1"].get_text() == "m = 1"
    assert tongues["tongue-label-1"].get_position()[0] == pytest.approx(2.0)
    assert tongues["tongue-label-2"].get_position()[0] == pytest.approx(1.0)
    assert tongues["tongue-label-3"].get_position()[0] == pytest.approx(2 / 3)
    # The damped boundary (growth rate 0) is outlined; stable and unstable counted.
    assert any(c.get_gid() == "growth-rate-zero" for c in ax.collections)
    labels = _legend(ax)
    n_stable = int((ds["stability"] == 0).sum())
    assert f"stable ({n_stable})" in labels
    assert any(t.startswith("unstable (") for t in labels)


def test_chart_keeps_newtons_when_asked_and_without_a_ratio(results):
    ds, _ = results["stab"]
    ax = plot_stability_chart(ds, y="load_amplitude").axes[0]
    assert "[N]" in ax.get_ylabel()
    # With one buckling load the boundaries are still drawn (mu = P0/Pcr).
    assert any(str(line.get_gid()).startswith("mathieu-") for line in ax.lines)
    ax = plot_stability_chart(ds.drop_vars("load_ratio")).axes[0]
    assert "[N]" in ax.get_ylabel()


def test_mathieu_boundaries_first_order():
    zones = mathieu_boundaries(np.array([0.0, 0.2]))
    np.testing.assert_allclose(zones["principal_low"], [2.0, 2 * np.sqrt(0.9)])
    np.testing.assert_allclose(zones["principal_high"], [2.0, 2 * np.sqrt(1.1)])
    # a = 4 / r^2 on the second zone's curves, s = 2 mu / r^2.
    r = zones["second_high"][1]
    s = 2 * 0.2 / r ** 2
    assert 4 / r ** 2 == pytest.approx(4 - s ** 2 / 12)
    r = zones["second_low"][1]
    s = 2 * 0.2 / r ** 2
    assert 4 / r ** 2 == pytest.approx(4 + 5 * s ** 2 / 12)
    assert np.isnan(mathieu_boundaries(np.array([0.9]))["second_low"][0])


def test_both_kinds_get_the_floquet_boundary_over_the_amplitude_map(results, tmp_path, capsys):
    ds, path = results["both"]
    figures = splot.plot(ds)
    assert {"amplitude", "state", "stability", "stability_over_amplitude"} <= set(figures)
    ax = figures["stability_over_amplitude"].axes[0]
    assert FLOQUET_LABEL in _legend(ax) and FLOQUET_LABEL == "Floquet: unstable inside"
    assert any(c.get_gid() == "floquet-boundary" for c in ax.collections)
    assert any("max |q|" in a.get_ylabel() for a in figures["stability_over_amplitude"].axes)
    # The chart over length x W/w1: W/w1 on x, tongues labelled, no load axis: no Mathieu lines.
    chart = figures["stability"].axes[0]
    assert "W/w1" in chart.get_xlabel() and "m = 1" in _texts(chart)
    assert not any(str(line.get_gid()).startswith("mathieu-") for line in chart.lines)
    assert cli.main(["plot", str(path), "-o", str(tmp_path)]) == 0
    names = {p.rsplit("/", 1)[-1] for p in capsys.readouterr().out.split()}
    assert {"both-stability.png", "both-stability_over_amplitude.png"} <= names
    for name in names:
        _png(tmp_path / name)
    with pytest.raises(UserError, match="no time-domain map"):
        plot_stability_over_map(results["stab"][0])


def test_one_swept_axis_growth_rate_line(results, tmp_path):
    ds, path = results["line"]
    figures = splot.plot(splot.load_result(path))
    assert set(figures) == {"stability"}
    ax = figures["stability"].axes[0]
    assert "1/s" in ax.get_ylabel()
    zero = [line for line in ax.lines if list(line.get_ydata()) == [0, 0]]
    assert zero and zero[0].get_ls() == "--"
    assert "m = 1" in _texts(ax)
    paths = splot.save(figures, tmp_path, prefix="line-")
    _png(paths[0], figures["stability"])
    with pytest.raises(UserError, match="one swept axis"):
        plot_growth_rate(results["stab"][0])
    assert isinstance(plot_growth_rate(ds), Figure)


def test_selection_of_a_stability_only_result(results):
    ds, _ = results["stab"]
    with pytest.raises(UserError, match="not a swept axis"):
        splot.plot(ds, {"length": 1.0})
    figures = splot.plot(ds, {"frequency_ratio": float(ds.frequency_ratio[15])})
    assert set(figures) == {"stability"}
    xr.testing.assert_equal(ds, ds)           # the result itself is not altered


def test_invalid_points_are_marked(results):
    ds, _ = results["stab"]
    bad = ds.copy()
    flags = bad["stability"].values.copy()
    flags[:2, :1] = -1
    growth = bad["growth_rate"].values.copy()
    growth[:2, :1] = np.nan
    bad["stability"] = bad["stability"].copy(data=flags)
    bad["growth_rate"] = bad["growth_rate"].copy(data=growth)
    ax = plot_stability_chart(bad).axes[0]
    assert "invalid_input (2)" in _legend(ax)
