"""One span over several values of an axis (`sweep design --over AXIS ...`, sweep/design.py
reduce_over): the longest span that passes at every value of a stepped test's frequencies and
directions, or of an uncertain damping ratio or mass. Synthetic results built here whose
spans are closed forms (the pinned f1 = pi / (2 l^2) sqrt(EI / m), an amplitude linear in l)
and whose minimum over the axis is computed here by hand; one tiny real stepped sine end to
end through the command, against a walk of its amplitudes written here."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import xarray as xr

import sweep
from sweep.cli import main
from sweep.design import max_span, refine_span, table

LENGTHS = np.linspace(0.1, 0.6, 11)                        # m
F_MIN = 100.0                                              # Hz
STATE = dict(flag_values=np.array([0, 2, 5], np.int8), units="1",
             flag_meanings="invalid_input steady diverged", long_name="state")
STEADY = 2


def l_max(ei: float, m: float, f_min: float = F_MIN) -> float:
    """The pinned span whose f1 = pi / (2 l^2) sqrt(EI / m) is f_min (m)."""
    return math.sqrt(math.pi * math.sqrt(ei / m) / (2.0 * f_min))


def pinned(masses: list[float], rigidities: list[float]) -> xr.Dataset:
    """A result over length x linear_mass x bending_rigidity: every point steady, its
    natural_frequency the pinned closed form."""
    m, ei = np.asarray(masses), np.asarray(rigidities)
    f1 = (math.pi / (2.0 * LENGTHS[:, None, None] ** 2)) * np.sqrt(ei[None, None, :]
                                                                   / m[None, :, None])
    dims = ("length", "linear_mass", "bending_rigidity")
    return xr.Dataset(
        {"state": xr.DataArray(np.full(f1.shape, STEADY, np.int8), dims=dims, attrs=STATE),
         "natural_frequency": xr.DataArray(f1, dims=dims, attrs={"units": "Hz"})},
        coords={"length": ("length", LENGTHS, {"units": "m", "long_name": "span"}),
                "linear_mass": ("linear_mass", m, {"units": "kg/m",
                                                   "long_name": "mass per unit length"}),
                "bending_rigidity": ("bending_rigidity", ei, {"units": "N m^2",
                                                              "long_name": "EI"})},
        attrs={"title": "pinned-synthetic"})


def test_over_the_mass_is_the_heaviest_cables_closed_form_span():
    """f1 falls with the mass: over linear_mass the heaviest cable binds, at its closed-form
    l_max to round-off (log f against log l is exact for l^-2), for each rigidity kept."""
    masses, rigidities = [0.05, 0.08, 0.03], [0.2, 0.31515]     # the heaviest in the middle
    ds = pinned(masses, rigidities)
    out = max_span(ds, min_frequency=F_MIN, over=("linear_mass",))
    assert out["max_span"].dims == ("bending_rigidity",)
    by_hand = [min(l_max(ei, m) for m in masses) for ei in rigidities]
    np.testing.assert_allclose(out["max_span"].values, by_hand, rtol=1e-9)
    assert list(out["limited_by"].values) == ["min_frequency"] * 2
    np.testing.assert_array_equal(out["binding_linear_mass"].values, [0.08, 0.08])
    attrs = out["binding_linear_mass"].attrs
    assert attrs["units"] == "kg/m" and "linear_mass" in attrs["long_name"]
    assert "mass per unit length" in attrs["comment"]
    assert "binding_linear_mass" in out["max_span"].attrs["ancillary_variables"]
    assert out.attrs["over_axes"] == "linear_mass"
    # over both axes: one span, the lightest rigidity's and the heaviest mass's
    both = max_span(ds, min_frequency=F_MIN, over=["bending_rigidity", "linear_mass"])
    assert both["max_span"].dims == ()
    assert float(both["max_span"]) == pytest.approx(
        min(l_max(ei, m) for ei in rigidities for m in masses), rel=1e-9)
    assert float(both["binding_linear_mass"]) == 0.08
    assert float(both["binding_bending_rigidity"]) == 0.2
    assert "binding_bending_rigidity" in table(both) and "0.08" in table(both)


def test_the_design_bar_gives_each_binding_value_with_its_units():
    """The bar of a span over every axis says where it binds: each value was written bare
    ("at linear_mass 0.08"); now in its axis's units as every other label (a level in g, a
    dB level in dB, a pure number bare). Read from the figure's text (Agg)."""
    import matplotlib
    matplotlib.use("Agg")
    from test_design_random import synthetic

    from sweep import schema
    from sweep.plot import plot_design

    def note(design: xr.Dataset) -> str:
        return plot_design(design).axes[0].texts[0].get_text()

    pinned_both = max_span(pinned([0.05, 0.08, 0.03], [0.2, 0.31515]), min_frequency=F_MIN,
                           over=["bending_rigidity", "linear_mass"])
    text = note(pinned_both)
    assert "at linear_mass 0.08 kg/m" in text and "at bending_rigidity 0.2 N m^2" in text, text
    level = stepped().rename(damping_ratio="base_acceleration_g")
    level["base_acceleration_g"].attrs.update(units=schema.G_UNITS, long_name="level")
    text = note(max_span(level, max_amplitude=2e-3,
                         over=["base_acceleration_g", "direction", "base_frequency_ratio"]))
    assert "at base_acceleration_g 0.02 g" in text and "at direction up" in text, text
    assert "at base_frequency_ratio 1\n" in text + "\n", text          # f / f1: no unit
    random = synthetic(scales=(-3.0, 0.0))          # a real result's level: units 1, "in dB"
    random["base_asd_scale"].attrs = {"units": "1",
                                      "long_name": schema.BY_AXIS["base_asd_scale"].long_name}
    text = note(max_span(random, max_rms=0.002, over="base_asd_scale"))
    assert "at base_asd_scale 0 dB" in text, text


def test_the_design_line_writes_where_each_span_binds_with_units():
    """Over one axis left the chart coloured each point by its criterion but drew no binding
    value; now each point is labelled with the --over values it binds at, in their units,
    and the legend names the axes. The values are the hand-computed ones of
    test_over_frequency_and_direction_is_the_resonant_steps_span (1.1 down at 5 % damping,
    1 up at 2 %) and the heaviest cable of the closed form (0.08 kg/m). Read from the
    figure's text (Agg)."""
    import matplotlib
    matplotlib.use("Agg")

    from sweep.plot import plot_design

    def labels(design: xr.Dataset) -> tuple[dict[float, str], str]:
        ax = plot_design(design).axes[0]
        legend = [t.get_text() for t in ax.get_legend().get_texts()]
        assert any("max_amplitude" in t or "min_frequency" in t for t in legend), legend
        return ({round(float(t.xy[0]), 9): t.get_text() for t in ax.texts},
                "\n".join(legend))

    texts, legend = labels(max_span(stepped(), max_amplitude=2e-3,
                                    over=("base_frequency_ratio", "direction")))
    assert texts == {0.05: "1.1\ndown", 0.02: "1\nup"}, texts
    assert "base_frequency_ratio / direction it binds at" in legend, legend
    texts, legend = labels(max_span(pinned([0.05, 0.08, 0.03], [0.2, 0.31515]),
                                    min_frequency=F_MIN, over="linear_mass"))
    assert texts == {0.2: "0.08 kg/m", 0.31515: "0.08 kg/m"}, texts
    assert "linear_mass it binds at" in legend, legend
    # over more than a dozen points a value is written where it changes: here once
    texts, legend = labels(max_span(pinned([0.05, 0.08], list(np.linspace(0.2, 0.32, 13))),
                                    min_frequency=F_MIN, over="linear_mass"))
    assert texts == {0.2: "0.08 kg/m"}, texts
    assert "where they change" in legend, legend


def test_no_span_at_one_value_is_no_span_over_the_axis():
    """A cable so heavy that the shortest grid length already fails has no span (NaN): over
    its axis the NaN binds, named with its criterion and the first such value, however long
    the others' spans."""
    heavy = 0.0534 * (l_max(0.31515, 0.0534) / LENGTHS[0]) ** 4 * 1.1   # f1(0.1 m) < 100 Hz
    masses = [0.03, heavy, heavy * 2, 0.05]
    out = max_span(pinned(masses, [0.31515]), min_frequency=F_MIN, over="linear_mass")
    assert np.isnan(out["max_span"].values).all()
    assert list(out["limited_by"].values) == ["min_frequency"]
    np.testing.assert_array_equal(out["binding_linear_mass"].values, [heavy])
    assert "shortest span fails" in table(out)


def test_every_value_passing_the_grid_is_bound_at_none():
    out = max_span(pinned([0.03, 0.05], [0.31515]), min_frequency=1.0, over="linear_mass")
    assert float(out["max_span"].squeeze()) == pytest.approx(LENGTHS[-1])
    assert str(out["limited_by"].squeeze().values) == "grid"
    assert np.isnan(out["binding_linear_mass"].values).all()
    assert table(out).splitlines()[1].split()[-1] == "-"


# --- a stepped test: frequencies x directions, amplitude linear in l ---------------------------

RATIOS = np.array([0.8, 0.95, 1.0, 1.1, 1.3])
DAMPING = np.array([0.05, 0.02])
GAIN = 4e-4                                  # m per m of span at a transmissibility of 1


def transmissibility(r: np.ndarray, zeta: float, direction: str) -> np.ndarray:
    """|H| of a linear oscillator at f / f1 = r; 'down' (a hardening span's other branch)
    3 times it at 1.1, 0.85 times it below resonance, the same at 1.0 and 1.3."""
    h = 1.0 / np.sqrt((1 - r ** 2) ** 2 + (2 * zeta * r) ** 2)
    if direction == "down":
        h = h * np.select([np.isclose(r, 1.1), r < 1.0], [3.0, 0.85], 1.0)
    return h


def stepped() -> xr.Dataset:
    """A stepped result over direction x length x base_frequency_ratio x damping_ratio whose
    amplitude is GAIN * l * transmissibility: linear in l, so each span is limit / (GAIN h)."""
    amp = np.stack([GAIN * LENGTHS[:, None, None]
                    * np.stack([transmissibility(RATIOS, z, d) for z in DAMPING], axis=-1)[None]
                    for d in ("up", "down")])
    dims = ("direction", "length", "base_frequency_ratio", "damping_ratio")
    return xr.Dataset(
        {"state": xr.DataArray(np.full(amp.shape, STEADY, np.int8), dims=dims, attrs=STATE),
         "amplitude": xr.DataArray(amp, dims=dims, attrs={"units": "m"})},
        coords={"direction": ("direction", np.array(["up", "down"], dtype=object),
                              {"long_name": "direction of the stepped sweep"}),
                "length": ("length", LENGTHS, {"units": "m"}),
                "base_frequency_ratio": ("base_frequency_ratio", RATIOS,
                                         {"units": "1", "long_name": "f / f1"}),
                "damping_ratio": ("damping_ratio", DAMPING, {"units": "1",
                                                             "long_name": "damping"})},
        attrs={"title": "stepped-synthetic", "continuation_axis": "base_frequency_ratio"})


def test_over_frequency_and_direction_is_the_resonant_steps_span():
    """Over the stepped axis and the directions, the span is limit / (GAIN h) at the
    largest transmissibility of any step in either direction, there named; per damping."""
    limit = 2e-3
    out = max_span(stepped(), max_amplitude=limit,
                   over=("base_frequency_ratio", "direction"))
    assert out["max_span"].dims == ("damping_ratio",)
    for k, zeta in enumerate(DAMPING):
        h = {d: transmissibility(RATIOS, zeta, d) for d in ("up", "down")}
        worst = np.maximum(h["up"], h["down"])
        i = int(np.argmax(worst))
        expected = limit / (GAIN * worst[i])
        assert LENGTHS[0] < expected < LENGTHS[-1]
        assert float(out["max_span"][k]) == pytest.approx(expected, rel=1e-12)
        assert float(out["binding_base_frequency_ratio"][k]) == RATIOS[i]
        assert str(out["binding_direction"].values[k]) == max(h, key=lambda d: h[d][i])
    assert set(out["limited_by"].values) == {"max_amplitude"}
    # 1.1 and 'down' bind at 5 % damping; at 2 % resonance (1.0), where both directions give
    # the same span and the first binds
    assert list(out["binding_base_frequency_ratio"].values) == [1.1, 1.0]
    assert list(out["binding_direction"].values) == ["down", "up"]
    assert out["binding_base_frequency_ratio"].attrs["units"] == "1"
    assert "units" not in out["binding_direction"].attrs      # a label, as limited_by


def test_over_direction_alone_keeps_the_worst_of_both_and_names_it():
    """direction counts at its worst already: over it max_span is unchanged, and
    binding_direction is the direction whose own span limit / (GAIN h_d) is the shorter."""
    ds, limit = stepped(), 2e-3
    plain = max_span(ds, max_amplitude=limit)
    out = max_span(ds, max_amplitude=limit, over="direction")
    np.testing.assert_array_equal(out["max_span"].values, plain["max_span"].values)
    assert out["max_span"].dims == plain["max_span"].dims
    named = set()
    for r, zeta in [(r, z) for r in RATIOS for z in DAMPING]:
        own = {d: limit / (GAIN * transmissibility(np.array([r]), zeta, d)[0])
               for d in ("up", "down")}
        if min(own.values()) >= LENGTHS[-1]:
            expected = ""                                     # no length fails: none binds
        else:                                                 # the first of equals: up
            expected = "up" if own["up"] <= own["down"] else "down"
        got = str(out["binding_direction"].sel(base_frequency_ratio=r,
                                                damping_ratio=zeta).values)
        assert got == expected, (r, zeta, own)
        named.add(expected)
    assert named == {"", "up", "down"}
    assert "binding_direction" in table(out)


def test_over_points_names_the_set_and_its_values():
    """Over a [points] dimension the binding set is named by its index and its values."""
    ds = pinned([0.03, 0.08, 0.05], [0.31515]).squeeze("bending_rigidity")
    ds = ds.rename({"linear_mass": "point"}).assign_coords(
        linear_mass=("point", [0.03, 0.08, 0.05], {"units": "kg/m", "long_name": "mass"}))
    ds = ds.drop_vars("point")
    out = max_span(ds, min_frequency=F_MIN, over="point")
    assert float(out["max_span"]) == pytest.approx(l_max(0.31515, 0.08), rel=1e-9)
    assert float(out["binding_point"]) == 1.0
    assert float(out["binding_linear_mass"]) == 0.08
    assert out["binding_linear_mass"].attrs["units"] == "kg/m"
    assert "linear_mass" not in out.coords


@pytest.mark.parametrize("over, fragment", [
    ("length", "length is the axis the span is found along"),
    ("damping", "not an axis of the result"),
    (("base_frequency_ratio", "tension"), "--over tension: not an axis"),
    (3, "give an axis name or a list of them"),
])
def test_an_axis_over_cannot_take_is_one_line_naming_those_it_can(over, fragment):
    with pytest.raises(sweep.UserError) as info:
        max_span(stepped(), max_amplitude=2e-3, over=over)
    message = str(info.value)
    assert fragment in message and "\n" not in message
    if over != 3:
        assert "--over takes direction, base_frequency_ratio, damping_ratio" in message


@pytest.mark.parametrize("over", [("damping_ratio", "damping_ratio"),
                                  ["direction", "base_frequency_ratio", "direction"]])
def test_an_axis_named_twice_is_one_line_naming_it(over):
    """`over` naming an axis twice was quietly taken once; one line names the repeated axis
    and asks for each once."""
    with pytest.raises(sweep.UserError) as info:
        max_span(stepped(), max_amplitude=2e-3, over=over)
    message = str(info.value)
    repeated = over[0]
    assert "\n" not in message and f"names the axis '{repeated}' 2 times" in message, message
    assert "name each axis once" in message, message


def test_cli_design_over_an_axis_twice_is_one_line_exit_2(tmp_path, capsys):
    from sweep.version import package_version
    path = tmp_path / "stepped.nc"
    stepped().assign_attrs(cable_sweep_version=package_version()).to_netcdf(path)
    code = main(["design", str(path), "--max-amplitude", "2e-3",
                 "--over", "base_frequency_ratio", "base_frequency_ratio"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert "'base_frequency_ratio' 2 times" in err and "name each axis once" in err, err
    assert "--over base_frequency_ratio)" in err, err
    assert main(["design", str(path), "--max-amplitude", "2e-3",
                 "--over", "base_frequency_ratio"]) == 0


def test_realisation_is_refused_its_criteria_are_over_it_already():
    from test_design_random import synthetic
    with pytest.raises(sweep.UserError, match="statistics over its realisations") as info:
        max_span(synthetic(scales=(-3.0, 0.0)), max_rms=0.002, over="realisation")
    assert "--over takes base_asd_scale" in str(info.value)
    out = max_span(synthetic(scales=(-3.0, 0.0)), max_rms=0.002, over="base_asd_scale")
    # rms = 0.01 l 2^scale: the 0 dB level binds, at l = 100 limit
    assert float(out["max_span"]) == pytest.approx(0.2, rel=1e-12)
    assert float(out["binding_base_asd_scale"]) == 0.0


def test_several_results_over_an_axis_carry_the_binding_direction():
    """Two results: the stepped one's amplitude binds (in it, at its step and direction);
    the other holds only the frequency, whose span is longer."""
    from sweep.governing import governing_span
    sine = stepped().isel(damping_ratio=[0])
    sine["natural_frequency"] = xr.DataArray(2000.0 * (0.1 / LENGTHS) ** 2, dims="length",
                                             attrs={"units": "Hz"})
    other = sine.drop_vars("amplitude").isel(direction=0, drop=True)
    other["state"] = other["state"].isel(base_frequency_ratio=0, drop=True)
    limit = 2e-3
    out = governing_span([("sine.nc", sine), ("frequency.nc", other)], max_amplitude=limit,
                         min_frequency=F_MIN, over=("direction", "base_frequency_ratio"))
    h = {d: transmissibility(RATIOS, DAMPING[0], d) for d in ("up", "down")}
    worst = np.maximum(h["up"], h["down"])
    expected = limit / (GAIN * worst.max())
    assert expected < 0.1 * math.sqrt(20.0)                 # f1 = 100 Hz at 0.447 m: longer
    assert float(out["max_span"].squeeze()) == pytest.approx(expected, rel=1e-12)
    assert str(out["limited_in"].squeeze().values) == "sine.nc"
    assert str(out["binding_direction"].squeeze().values) == "down"
    assert float(out["binding_base_frequency_ratio"].squeeze()) == 1.1
    with pytest.raises(sweep.UserError, match="not an axis of any of the results"):
        governing_span([("sine.nc", sine), ("frequency.nc", other)], min_frequency=F_MIN,
                       over="tension")


# --- a tiny real stepped sine, end to end --------------------------------------------------------

@pytest.fixture(scope="module")
def real_stepped(tmp_path_factory):
    path = tmp_path_factory.mktemp("over") / "stepped.nc"
    scene = sweep.load_scene("harness-stepped-sine", overrides={
        "axes.base_frequency_ratio": [0.9, 1.0, 1.1], "axes.length": [0.3, 0.4, 0.5],
        "model.modes": 1, "solver.t_end": 0.5})
    return sweep.run(scene, output=path, progress=False), path


def _walk(amplitude: np.ndarray, lengths: np.ndarray, limit: float) -> float:
    """The span of one row of amplitudes over the lengths: the last before the first above
    the limit, interpolated linearly; NaN if the first fails, the longest if none."""
    above = np.flatnonzero(amplitude > limit)
    if above.size == 0:
        return float(lengths[-1])
    b = int(above[0])
    if b == 0:
        return math.nan
    la, lb, va, vb = lengths[b - 1], lengths[b], amplitude[b - 1], amplitude[b]
    return float(la + (limit - va) / (vb - va) * (lb - la))


def test_cli_design_over_a_stepped_test_matches_a_walk_by_hand(real_stepped, tmp_path, capsys):
    from test_cf import _readme_unitless, cf_problems
    ds, path = real_stepped
    state = ds["state"]
    failures = [v for v, m in zip(state.attrs["flag_values"], state.attrs["flag_meanings"].split())
                if m in ("invalid_input", "diverged", "step_size_too_small", "max_steps_reached")]
    assert not state.isin(failures).any()
    amp = ds["amplitude"].transpose("direction", "base_frequency_ratio", "length").values
    lengths, ratios = ds["length"].values, ds["base_frequency_ratio"].values
    limit = 0.75 * float(amp[:, :, 1].max())                 # some step fails at 0.4 m
    per_ratio = [_walk(amp[:, i].max(axis=0), lengths, limit) for i in range(len(ratios))]
    i = int(np.nanargmin(per_ratio))
    expected = per_ratio[i]
    assert lengths[0] < expected < lengths[-1]
    own = [_walk(amp[d, i], lengths, limit) for d in range(2)]
    direction = str(ds["direction"].values[int(np.argmin(own))])

    out = tmp_path / "over.nc"
    with warnings.catch_warnings():                        # some unsettled at t_end = 0.5 s
        warnings.simplefilter("ignore", sweep.CableSweepWarning)
        code = main(["design", str(path), "--max-amplitude", f"{limit:.17g}",
                     "--over", "base_frequency_ratio", "direction", "-o", str(out)])
    assert code == 0
    text = capsys.readouterr().out
    assert "binding_base_frequency_ratio" in text and f"{expected * 1e3:.2f}" in text
    assert cf_problems(out) == []
    with xr.open_dataset(out) as back:
        assert back["max_span"].dims == ()
        assert float(back["max_span"]) == pytest.approx(expected, rel=1e-12)
        assert str(back["limited_by"].values) == "max_amplitude"
        assert float(back["binding_base_frequency_ratio"]) == ratios[i]
        assert str(back["binding_direction"].values) == direction
        assert back.attrs["over_axes"] == "base_frequency_ratio, direction"
        unitless = {n for n in back.variables if "units" not in back[n].attrs}
    assert unitless <= _readme_unitless(), unitless - _readme_unitless()
    figs = tmp_path / "figs"
    assert main(["plot", str(out), "-o", str(figs)]) == 0
    assert (figs / "over-max_span.png").stat().st_size > 0
    capsys.readouterr()
    from sweep.plot import load_result, plot_design
    note = plot_design(load_result(out)).axes[0].texts[0].get_text()   # the bar says where
    assert f"base_frequency_ratio {ratios[i]:g}" in note and f"direction {direction}" in note


def test_cli_design_over_refusals_are_one_line_exit_2(real_stepped, capsys):
    _, path = real_stepped
    for flags, fragment in ((["--over", "length"], "--over takes direction, "),
                            (["--over", "damping_ratio"], "not an axis of the result"),
                            (["--over", "direction", "--refine"], "leave direction out")):
        code = main(["design", str(path), "--max-amplitude", "1e-3", *flags])
        assert code == 2
        err = capsys.readouterr().err.strip()
        assert fragment in err and len(err.splitlines()) == 1, err


def test_cli_design_over_before_the_file_takes_the_file_as_the_result(real_stepped, capsys):
    """A reviewer: `sweep design --over AXIS RESULT.nc` gave the file to --over and answered
    'the following arguments are required: RESULT.nc'; the same answer as with the file
    first, and no file at all is one line."""
    _, path = real_stepped
    first = main(["design", str(path), "--max-amplitude", "1e-3", "--over", "direction"])
    text_first = capsys.readouterr().out
    after = main(["design", "--max-amplitude", "1e-3", "--over", "direction", str(path)])
    assert (first, after) == (0, 0) and capsys.readouterr().out == text_first
    assert main(["design", "--max-amplitude", "1e-3", "--over", "direction"]) == 2
    err = capsys.readouterr().err.strip()
    assert "give the result to design from" in err and len(err.splitlines()) == 1


def test_refine_over_an_axis_takes_the_refined_spans_shortest(real_stepped):
    """--refine with --over: each combination refined, then the shortest; the frequency
    criterion alone needs no run and does not move with the step, so every step gives the
    closed-form span and the first binds."""
    ds, _ = real_stepped
    f_min = 30.0
    out = refine_span(ds, min_frequency=f_min, over="base_frequency_ratio")
    assert int(out.attrs["refine_runs"]) == 0
    ei, m = 0.31515, 0.0534                                   # the scene's data sheet
    assert float(out["max_span"]) == pytest.approx(l_max(ei, m, f_min), rel=1e-6)
    assert float(out["binding_base_frequency_ratio"]) == 0.9
