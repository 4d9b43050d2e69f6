"""Cable data as a harness engineer has it (issue 37): values with units, the data-sheet keys
(linear_mass, bending_rigidity, axial_rigidity), EI from a measured f1, and the wire table's
bundles. The bad-input lines (wrong dimension, unknown unit, a unit on a dimensionless key, both
sets of cable keys, a missing key) are in tests/data/bad (unit_*, cable_*), run by
tests/test_bad_input.py.

Every expected number here is a hand conversion or a textbook formula, not the code's output.
Only one test runs the engine (the f1 round trip, on the clamped one-mode scene that
tests/test_clamps.py compiles already).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import sweep
from sweep import schema, wires
from sweep.grid import coordinates, parameters
from sweep.models import cable
from sweep.models.modal import oscillator
from sweep.scene.units import to_si

G0 = 9.80665
LB, FT, INCH = 0.45359237, 0.3048, 0.0254

# For every schema unit: a string in other units and its value in the SI unit, by hand.
BY_HAND: dict[str, tuple[str, float]] = {
    "m": ("2.5 mm", 2.5e-3),
    "kg m-1": ("3.2 lb/kft", 3.2 * LB / (1000 * FT)),
    "N m2": ("2000 N mm^2", 2000e-6),
    "N": ("1.5 kN", 1500.0),
    "Hz": ("0.1 kHz", 100.0),
    "Pa": ("110 GPa", 1.1e11),
    "kg m-3": ("8.9 g/cm^3", 8900.0),
    "m2": ("6 mm^2", 6e-6),
    "m4": ("2 mm^4", 2e-12),
    "s": ("250 ms", 0.25),
    "m s-1": ("3 cm/s", 0.03),
    "m s-2": ("0.5 g", 0.5 * G0),
    schema.G_UNITS: ("4.903325 m/s^2", 0.5),
    "N m rad-1": ("500 N mm/rad", 0.5),
    "N m-1": ("1 kN/mm", 1e6),
    "min-1": ("3 /h", 0.05),
    "m2 s-4 Hz-1": ("0.16 g^2/Hz", 0.16 * G0 ** 2),
    schema.G2_UNITS: ("961.7038422250001 m^2/s^4/Hz", 10.0),
}
DIMENSIONAL = [k for k in schema.KEYS
               if k.kind in ("float", "floats", "pairs") and k.units not in ("", "1")]


def load(text: str, **overrides) -> sweep.Scene:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # the zero-solution warning of bare scenes
        return sweep.load_scene_text(text, overrides=overrides or None)


@pytest.mark.parametrize("key", DIMENSIONAL, ids=lambda k: k.dotted)
def test_every_dimensional_key_converts_a_unit_string_by_hand(key):
    text, expected = BY_HAND[key.units]     # a KeyError: a new unit needs its hand conversion
    assert to_si(f"scene key '{key.dotted}'", key, text) == pytest.approx(expected, rel=1e-14)


@pytest.mark.parametrize("text, expected", [
    ("33.3 g/m", 0.0333), ("4.76 g/m", 4.76e-3), ("3.2 lb/kft", 3.2 * LB / 304.8),
    ("0.0333 kg/m", 0.0333), ("33.3 mg/mm", 0.0333)])
def test_linear_mass_strings_in_a_scene(text, expected):
    scene = load(f'[cable]\nlinear_mass = "{text}"\nbending_rigidity = 2e-3\n'
                 'axial_rigidity = 1.6e6\n')
    assert scene.get("cable.linear_mass") == pytest.approx(expected, rel=1e-14)


@pytest.mark.parametrize("text, expected", [
    ("0.31515 N m2", 0.31515), ("315150 N mm2", 0.31515), ("315150 N mm**2", 0.31515),
    ("0.31515 N*m^2", 0.31515), ("45.66 lbf in2", 45.66 * 4.4482216152605 * INCH ** 2)])
def test_udunits_exponents_read_as_powers(text, expected):
    """'N m2' as the messages spell the key's unit: a power, not an unknown unit 'm2'."""
    key = schema.BY_DOTTED["cable.bending_rigidity"]
    assert to_si("scene key 'cable.bending_rigidity'", key, text) == pytest.approx(expected,
                                                                                  rel=1e-12)


def test_udunits_exponents_after_a_slash():
    key = schema.BY_DOTTED["cable.density"]
    assert to_si("scene key 'cable.density'", key, "8.9 g/cm3") == pytest.approx(8900.0,
                                                                                rel=1e-14)


@pytest.mark.parametrize("key, text", [("cable.linear_mass", "0a176 kg/m"),
                                       ("base.sweep.rate", "2 a300/min")])
def test_a_unit_whose_size_overflows_is_one_line(key, text):
    """The fuzz test's '0a176 kg/m' (a character edit of '0.176 kg/m'): pint reads a^176, years
    to the 176th power, whose size overflows a float while the angle check reduced it to root
    units (OverflowError, a traceback); now one line naming the key."""
    from sweep.errors import SceneError
    with pytest.raises(SceneError) as caught:
        sweep.load_scene("launch-sine-qualification", {key: text})
    assert key in str(caught.value) and "\n" not in str(caught.value)


def test_mil_is_a_thousandth_of_an_inch():
    key = schema.BY_DOTTED["cable.diameter"]
    assert to_si("scene key 'cable.diameter'", key, "109 mil") == pytest.approx(109e-3 * INCH,
                                                                               rel=1e-14)
    assert to_si("scene key 'cable.diameter'", key, "109 mils") == pytest.approx(109e-3 * INCH,
                                                                                rel=1e-14)


@pytest.mark.parametrize("text, hertz", [
    ("20 rad/s", 20.0 / (2.0 * math.pi)), ("1200 rpm", 20.0), ("20 cycles/s", 20.0),
    ("360 deg/s", 1.0), ("20 Hz", 20.0), ("0.02 kHz", 20.0), ("1200 /min", 20.0)])
def test_an_angle_per_time_on_a_frequency_key_is_read_in_cycles(text, hertz):
    """pint takes the radian for a pure number: "20 rad/s" was 20 Hz and "1200 rpm" 125.7 Hz,
    2 pi off without a word. A frequency key reads an angle per time in cycles; a plain 1/s
    stays as it is."""
    key = schema.BY_DOTTED["base.frequency"]
    assert to_si("scene key 'base.frequency'", key, text) == pytest.approx(hertz, rel=1e-14)


@pytest.mark.parametrize("dotted, text, expected", [
    ("base.acceleration", "0.5 G", 0.5 * G0), ("base.acceleration_g", "1.5 G", 1.5),
    ("base.levels_g", "2 G", 2.0), ("base.asd_g2", "0.16 G^2/Hz", 0.16),
    ("base.asd", "0.16 G^2/Hz", 0.16 * G0 ** 2), ("base.asd_g2", "0.04 G2 Hz-1", 0.04)])
def test_a_capital_g_is_standard_gravity_on_the_acceleration_keys(dotted, text, expected):
    """Test specifications write "G^2/Hz" and "G": pint read the gauss, and "0.16 G^2/Hz" was
    refused as "of dimension [mass] / [length] / [time]" (a reviewer's finding)."""
    key = schema.BY_DOTTED[dotted]
    assert to_si(f"scene key '{dotted}'", key, text) == pytest.approx(expected, rel=1e-14)


@pytest.mark.parametrize("dotted, text", [("cable.linear_mass", "33 G/m"),
                                          ("base.frequency", "20 G")])
def test_a_capital_g_elsewhere_is_one_line_saying_where_it_means_gravity(dotted, text):
    with pytest.raises(sweep.SceneError) as info:
        to_si(f"scene key '{dotted}'", schema.BY_DOTTED[dotted], text)
    message = str(info.value)
    assert "\n" not in message and f"scene key '{dotted}'" in message
    assert "'G'" in message and "base.acceleration_g" in message and "dimension" not in message


@pytest.mark.parametrize("dotted, text, expected", [
    ("base.acceleration", "0.5 g0", 0.5 * G0), ("base.acceleration", "0.5 gn", 0.5 * G0),
    ("base.acceleration", "0.5 g_0", 0.5 * G0), ("base.acceleration", "0.5g0", 0.5 * G0),
    ("base.acceleration", "500 mG", 0.5 * G0), ("base.acceleration_g", "0.5 g0", 0.5),
    ("base.acceleration_g", "0.5 gn", 0.5), ("base.acceleration_g", "500 mG", 0.5),
    ("base.acceleration_g", "25 mG", 0.025), ("base.levels_g", "1875 mG", 1.875),
    ("base.asd_g2", "0.16 g0^2/Hz", 0.16), ("base.asd_g2", "160 mG^2/Hz", 160e-6),
    ("base.asd", "0.16 gn^2/Hz", 0.16 * G0 ** 2), ("base.asd", "400 mG^2/Hz", 0.4e-3 * G0 ** 2)])
def test_g0_gn_and_milli_g_are_standard_gravity_on_the_acceleration_keys(dotted, text, expected):
    """"0.5 g0" was read as g to the power 0 (a pure number, refused), "0.5 gn" and "500 mG"
    (pint's milligauss) as unknown or of a wrong dimension; on the acceleration keys they are
    standard gravity and a thousandth of it (9.80665 m/s^2 per g, by hand)."""
    key = schema.BY_DOTTED[dotted]
    assert to_si(f"scene key '{dotted}'", key, text) == pytest.approx(expected, rel=1e-14)


@pytest.mark.parametrize("dotted, text, expected", [
    ("base.asd_g2", "0.16 gn2/Hz", 0.16), ("base.asd_g2", "0.16 g_n2 Hz-1", 0.16),
    ("base.asd", "0.16 gn2/Hz", 0.16 * G0 ** 2), ("base.asd", "0.16 gn^2/Hz", 0.16 * G0 ** 2)])
def test_gn_takes_a_udunits_exponent_as_g_and_mg_do(dotted, text, expected):
    """"0.16 gn2/Hz" (UDUNITS' exponent, as "G2/Hz" and "mG2/Hz" are read) was "unknown unit
    'gn'", in a line that said gn is standard gravity on the key: it is (g0 keeps no exponent
    written so: "g02" would read as g to the power 02); by hand, 9.80665 m/s^2 per g."""
    key = schema.BY_DOTTED[dotted]
    assert to_si(f"scene key '{dotted}'", key, text) == pytest.approx(expected, rel=1e-14)


@pytest.mark.parametrize("dotted, text, words", [
    ("base.acceleration", "500 mg", ["'500 mG'", "'0.5 g'"]),
    ("base.acceleration_g", "500 mg", ["'500 mG'", "'0.5 g'"]),
    ("base.levels_g", "250 mg", ["'250 mG'", "'0.25 g'"]),
    ("base.asd_g2", "0.16 mg^2/Hz", ["'0.16 mG^2/Hz'", "'1.6e-07 g^2/Hz'"])])
def test_a_milligram_on_an_acceleration_key_is_one_line_suggesting_milli_g(dotted, text, words):
    """"500 mg" is 500 milligrams: refused, in one line that says it is a mass and gives the
    level in mG and in g."""
    with pytest.raises(sweep.SceneError) as info:
        to_si(f"scene key '{dotted}'", schema.BY_DOTTED[dotted], text)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"scene key '{dotted}': ")
    assert "is a mass" in message and "milligram" in message, message
    for word in words:
        assert word in message, message


@pytest.mark.parametrize("dotted, text", [
    ("base.acceleration_g", "14.1 grms"), ("base.acceleration_g", "14.1 Grms"),
    ("base.acceleration", "1 g rms"), ("base.levels_g", "2 GRMS")])
def test_an_rms_level_on_a_sine_level_key_is_one_line_asking_for_the_peak(dotted, text):
    """A sine's level is its peak: "14.1 grms" was "unknown unit 'grms'"; now one line that
    says what the key takes."""
    with pytest.raises(sweep.SceneError) as info:
        to_si(f"scene key '{dotted}'", schema.BY_DOTTED[dotted], text)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"scene key '{dotted}': ")
    assert "RMS" in message and "peak" in message and "g or m/s^2" in message, message
    assert "unknown unit" not in message


@pytest.mark.parametrize("dotted, text, expected", [
    ("base.asd_g2", "0.16 grms^2/Hz", 0.16), ("base.asd_g2", "0.16 grms2/Hz", 0.16),
    ("base.asd_g2", "0.16 g_rms^2/Hz", 0.16), ("base.asd_g2", "0.04 GRMS2 Hz-1", 0.04),
    ("base.asd", "0.16 Grms^2/Hz", 0.16 * G0 ** 2),
    ("base.asd", "0.16 grms**2/Hz", 0.16 * G0 ** 2)])
def test_grms_squared_per_hertz_on_a_spectral_density_is_g_squared_per_hertz(
        dotted, text, expected):
    """An ASD written "0.16 grms^2/Hz" (as engineers write it beside g^2/Hz, the same density)
    was "unknown unit 'grms'"; it reads as g^2/Hz (by hand, 9.80665 m/s^2 per g)."""
    key = schema.BY_DOTTED[dotted]
    assert to_si(f"scene key '{dotted}'", key, text) == pytest.approx(expected, rel=1e-14)


def test_grms_squared_per_hertz_through_a_scene_file():
    text = ('[cable]\nlength = 0.15\nlinear_mass = 0.176\nbending_rigidity = 0.1\n'
            'axial_rigidity = 1.65e6\n[base]\n'
            'asd_g2 = [[20.0, "0.026 grms^2/Hz"], [2000.0, "0.026 grms2/Hz"]]\n'
            'duration = 2.0\n')
    assert load(text).get("base.asd_g2") == ((20.0, 0.026), (2000.0, 0.026))


@pytest.mark.parametrize("dotted, text, named", [
    ("cable.linear_mass", "0.5 g0", "'g0'"), ("load.amplitude", "2 gn", "'gn'"),
    ("base.frequency", "500 mG", "'mG'")])
def test_gravity_spelled_otherwise_elsewhere_is_one_line_saying_where_it_means_gravity(
        dotted, text, named):
    """"0.5 g0" on a mass per length was read as g^0, "a pure number"; g0, gn and mG are
    standard gravity, which only the acceleration keys take."""
    with pytest.raises(sweep.SceneError) as info:
        to_si(f"scene key '{dotted}'", schema.BY_DOTTED[dotted], text)
    message = str(info.value)
    assert "\n" not in message and named in message and "base.acceleration_g" in message


def test_gravity_units_through_a_scene_file_and_an_override():
    """The same spellings in a scene file and in --set, to SI once (9.80665 m/s^2 per g)."""
    text = ('[cable]\nlength = 0.4\n[base]\nacceleration_g = "750 mG"\nfrequency = 20.0\n'
            "[solver]\nt_end = 0.5\n")
    assert load(text).get("base.acceleration_g") == pytest.approx(0.75, rel=1e-14)
    scene = load(text, **{"base.acceleration": "0.25 gn"})
    assert scene.get("base.acceleration") == pytest.approx(0.25 * G0, rel=1e-14)
    assert scene.get("base.acceleration_g") is None


@pytest.mark.parametrize("dotted, text, expected", [
    ("base.frequency", "20 1/s", 20.0), ("base.frequency", "120 1/min", 2.0),
    ("base.sweep.rate", "2 1/min", 2.0), ("base.sweep.rate", "2 1 / min", 2.0),
    ("base.sweep.rate", "0.05 1/s", 3.0), ("base.frequency", "2 1/ms", 2000.0)])
def test_a_reciprocal_unit_may_keep_its_one(dotted, text, expected):
    """"20 1/s" and "2 1/min" were refused as a number inside the unit; the 1 of a reciprocal
    unit is read as "/s" is."""
    key = schema.BY_DOTTED[dotted]
    assert to_si(f"scene key '{dotted}'", key, text) == pytest.approx(expected, rel=1e-14)


def test_a_g_in_a_scene_file_reads_on_the_acceleration_keys():
    scene = load('[base]\nacceleration = "0.5 G"\nfrequency = "20 1/s"\n[cable]\n'
                 "length = 0.4\n")
    assert scene.get("base.acceleration") == pytest.approx(0.5 * G0, rel=1e-14)
    assert scene.get("base.frequency") == pytest.approx(20.0, rel=1e-14)


def test_an_angle_where_the_key_has_none_is_refused_and_data_sheet_spellings_read():
    """An octave rate given in rpm is refused in one line; "oct/min" (a sweep rate as a test
    specification writes it) and "Nm" (pint's "number metre") read as meant."""
    rate = schema.BY_DOTTED["base.sweep.rate"]
    with pytest.raises(sweep.SceneError) as info:
        to_si("scene key 'base.sweep.rate'", rate, "2 rpm")
    assert "holds an angle" in str(info.value) and "\n" not in str(info.value)
    assert to_si("scene key 'base.sweep.rate'", rate, "2 oct/min") == 2.0
    assert to_si("scene key 'base.sweep.rate'", rate, "3 octaves/min") == 3.0
    spring = schema.BY_DOTTED["clamps.rotational_stiffness"]
    assert to_si("k", spring, "0.5 Nm/rad") == pytest.approx(0.5, rel=1e-14)
    assert to_si("k", spring, "0.5 N m/deg") == pytest.approx(0.5 * 180.0 / math.pi,
                                                              rel=1e-14)
    bending = schema.BY_DOTTED["cable.bending_rigidity"]
    assert to_si("k", bending, "0.31515 Nm^2") == pytest.approx(0.31515, rel=1e-14)


def test_a_number_typed_in_full_keeps_its_bits_and_a_short_one_loses_the_noise():
    """A unit string is rounded to 15 significant digits ('33.3 g/m' is 0.0333, not 33.3 x
    0.001's 0.033299999999999996) only when it was typed with 15 or fewer: a value pasted with
    all 17 digits of a float is that float, as the plain number would be."""
    inertia = schema.BY_DOTTED["cable.inertia"]
    assert to_si("k", inertia, "2.8647889756541167e-12 m^4") == 2.8647889756541167e-12
    length = schema.BY_DOTTED["cable.length"]
    assert to_si("k", length, "0.30000000000000004 m") == 0.30000000000000004
    assert to_si("k", length, "300.00000000000004 mm") == 300.00000000000004 * 1e-3
    mass = schema.BY_DOTTED["cable.linear_mass"]
    assert to_si("k", mass, "33.3 g/m") == 0.0333 != 33.3 * 0.001


@pytest.mark.parametrize("text, words", [
    ("53,4 g/m", "comma"), ("1,000 g/m", "comma"), ("53.4 g/m 2", "inside its unit"),
    ("53.4 g/m + 1 g/m", "inside its unit"), ("53.4 g/m - 1 g/m", "inside its unit"),
    ("2 53.4 g/m", "inside its unit"), ("g/m", "does not start with a number"),
    ("kg", "does not start with a number")])
def test_a_unit_string_is_one_number_and_its_unit_not_arithmetic(text, words):
    """pint would compute these ('53,4 g/m' as 534 g/m: a European data sheet's decimal comma
    made the mass 10x): each is refused in one line naming the key."""
    with pytest.raises(sweep.SceneError) as info:
        load(f'[cable]\nlinear_mass = "{text}"\nbending_rigidity = 2e-3\n'
             'axial_rigidity = 1.6e6\n')
    message = str(info.value)
    assert "'cable.linear_mass'" in message and words in message and "\n" not in message


def test_g_is_standard_gravity_on_acceleration_keys_and_the_gram_elsewhere():
    scene = load('[base]\nacceleration = "0.5 g"\nfrequency = "20 Hz"\n'
                 '[cable]\nlinear_mass = "33.3 g/m"\nbending_rigidity = 2e-3\n'
                 'axial_rigidity = 1.6e6\n')
    assert scene.get("base.acceleration") == pytest.approx(0.5 * G0, rel=1e-15)
    assert scene.get("cable.linear_mass") == pytest.approx(0.0333, rel=1e-15)
    table = load('[base]\nlevels_g = [["5 Hz", "0.5 g"], ["0.1 kHz", "9.80665 m/s^2"]]\n'
                 'frequency = 20.0\n')
    assert table.get("base.levels_g") == ((5.0, 0.5), (100.0, pytest.approx(1.0, rel=1e-15)))


def test_units_in_axes_points_and_overrides_and_the_resolved_scene_is_si():
    scene = load('[clamps]\nrotation = "clamped"\n[cable]\nbending_rigidity = "2e-3 N m^2"\n'
                 'axial_rigidity = "1.6 MN"\n[axes]\nlength = {start = "300 mm", stop = "0.5 m", '
                 'num = 3}\n[points]\nlinear_mass = ["33.3 g/m", "3.2 lb/kft"]\n'
                 'diameter = ["3.81 mm", "0.05 in"]\n',
                 **{"base.acceleration_g": "0.25 g", "base.frequency": "50 Hz"})
    assert list(scene.axes["length"]) == [0.3, 0.4, 0.5]
    assert list(scene.points["linear_mass"]) == [0.0333, pytest.approx(3.2 * LB / 304.8)]
    assert list(scene.points["diameter"]) == [0.00381, pytest.approx(0.05 * INCH)]
    assert scene.get("base.acceleration_g") == 0.25
    text = scene.to_toml()
    assert all(isinstance(v, float) for k, v in scene.values.items()
               if schema.BY_DOTTED[k].kind == "float" and v is not None)
    assert "youngs_modulus" not in text and "density" not in text
    assert load(text) == scene


MATERIAL = ('[model]\nmembrane = 0.375\n[cable]\nyoungs_modulus = 1.1e11\ndensity = 8900.0\n'
            'area = 6e-6\ninertia = 2.865e-12\n[initial]\ndisplacement = 1e-4\n'
            '[axes]\nlength = [0.3, 0.55, 1.0]\nload_amplitude = [0.0, 2.0]\n')
SHEET = ('[model]\nmembrane = 0.375\n[cable]\nlinear_mass = "53.4 g/m"\n'
         'bending_rigidity = "0.31515 N m^2"\naxial_rigidity = "660 kN"\n'
         '[initial]\ndisplacement = 1e-4\n[axes]\nlength = [0.3, 0.55, 1.0]\n'
         'load_amplitude = [0.0, 2.0]\n')


@pytest.mark.parametrize("extra", ["", "[clamps]\naxial_stiffness = 1e5\n"])
def test_the_data_sheet_gives_the_material_scene_coefficients(extra):
    """rho A = 8900 x 6e-6 = 0.0534 kg/m, EI = 1.1e11 x 2.865e-12, EA = 1.1e11 x 6e-6: every
    coefficient of the model (stretching, load, Pcr, f1) the same to round-off."""
    text_m = MATERIAL.replace("membrane = 0.375\n", "") + extra if extra else MATERIAL
    text_s = SHEET.replace("membrane = 0.375\n", "") + extra if extra else SHEET
    a, b = (oscillator(parameters(s, coordinates(s))) for s in (load(text_m), load(text_s)))
    for name in ("k0", "k1", "g0", "g1", "h", "natural_frequency", "buckling_load"):
        np.testing.assert_allclose(np.asarray(b[name], float), np.asarray(a[name], float),
                                   rtol=1e-13, err_msg=name)


def test_diameter_reaches_the_clamp_strain_and_rho_a_is_the_linear_mass():
    scene = load('[clamps]\nrotation = "clamped"\n[cable]\nlinear_mass = "33.3 g/m"\n'
                 'bending_rigidity = "2e-3 N m^2"\naxial_rigidity = "1.6 MN"\n'
                 'diameter = "3.81 mm"\nlength = 0.4\n')
    p = parameters(scene, coordinates(scene))
    assert p["diameter"] == 0.00381
    assert p["density"] * p["area"] == pytest.approx(0.0333, rel=1e-15)
    assert p["youngs_modulus"] * p["inertia"] == pytest.approx(2e-3, rel=1e-15)
    assert p["youngs_modulus"] * p["area"] == pytest.approx(1.6e6, rel=1e-15)
    f1 = 4.730040745 ** 2 / (2 * math.pi * 0.4 ** 2) * math.sqrt(2e-3 / 0.0333)
    assert float(oscillator(p)["natural_frequency"]) == pytest.approx(f1, rel=1e-9)


# ---------------------------------------------------------------- the wire table and bundles

@pytest.mark.parametrize("count, ring_sum, rings", [(1, 0.0, 0), (3, 2.0, 1), (7, 6.0, 1),
                                                     (19, 6 * 1 + 6 * 3 + 6 * 4, 2)])
def test_bundle_against_the_formulas(count, ring_sum, rings):
    """Mass n m; diameter (2k + 1) d; EI lower n s E pi d_s^4 / 64; upper E (n A_c^2 / (4 pi)
    + A_c sum r_i^2 / 2), r_i of a hexagonal bundle: ring 1 at d, ring 2 at 2 d and sqrt(3) d."""
    w = wires.WIRES["spec55-22"]
    d, ds, e, s = 0.050 * INCH, 0.005 * 92 ** (2 / 39) * INCH, 1.1e11, 19   # AWG 34 strands
    area = s * math.pi * ds ** 2 / 4
    b = wires.bundle("spec55-22", count)
    assert w.linear_mass == pytest.approx(3.2 * LB / (1000 * FT), rel=1e-15)
    assert b.linear_mass == pytest.approx(count * 3.2 * LB / (1000 * FT), rel=1e-15)
    assert b.diameter == pytest.approx((2 * rings + 1) * d, rel=1e-15)
    assert b.axial_rigidity == pytest.approx(count * e * area, rel=1e-15)
    assert b.bending_lower == pytest.approx(count * s * e * math.pi * ds ** 4 / 64, rel=1e-14)
    upper = e * (count * area ** 2 / (4 * math.pi) + area * ring_sum * d ** 2 / 2)
    assert b.bending_upper == pytest.approx(upper, rel=1e-14)
    assert b.bending_lower < b.bending_upper


def test_a_wire_scene_gives_the_bundle_to_the_model():
    """7 x spec55-22, lower bound: f1 = (pi / l)^2 / (2 pi) sqrt(EI_lower / (7 m))."""
    b = wires.bundle("spec55-22", 7)
    for bound in ("lower", "upper"):
        scene = load(f'[cable]\nwire = "spec55-22"\nwires = 7\nbending = "{bound}"\n'
                     'length = "300 mm"\n')
        p = parameters(scene, coordinates(scene))
        f1 = math.pi / (2 * 0.3 ** 2) * math.sqrt(b.bending(bound) / b.linear_mass)
        assert float(oscillator(p)["natural_frequency"]) == pytest.approx(f1, rel=1e-12)
        assert p["diameter"] == pytest.approx(3 * 0.050 * INCH)
        assert cable.bending_note(scene.values).startswith(f"bound: the {bound} bound")
    # the bracket as an axis: the wire's mass and EA, EI swept between the two bounds
    scene = load('[cable]\nwire = "spec55-22"\nwires = 7\n[axes]\n'
                 f'bending_rigidity = [{b.bending_lower!r}, {b.bending_upper!r}]\n')
    f1 = oscillator(parameters(scene, coordinates(scene)))["natural_frequency"]
    np.testing.assert_allclose(f1.values, [math.pi / 2 * math.sqrt(b.bending(x) / b.linear_mass)
                                           for x in ("lower", "upper")], rtol=1e-12)
    assert cable.bending_note(scene.values).startswith("given")


# ---------------------------------------------------------------- EI from a measured f1

@pytest.mark.parametrize("rotation, beta", [("pinned", math.pi), ("clamped", 4.730040745)])
def test_bending_from_f1_inverts_the_textbook_frequency(rotation, beta):
    ei = cable.bending_from_f1(12.0, 0.5, 0.0333, rotation)
    assert ei == pytest.approx(0.0333 * (2 * math.pi * 12.0 * 0.5 ** 2 / beta ** 2) ** 2,
                               rel=1e-9)


@pytest.mark.parametrize("stiffness_ratio, beta", [(1.0, 3.3988), (10.0, 4.1557),
                                                   (100.0, 4.6413)])
def test_bending_from_f1_of_elastic_ends_matches_model_md_table(stiffness_ratio, beta):
    """docs/model.md sec. 10 (the rotational-spring table): K = k_t l / EI -> b_1 l. Pick EI0 and k_t = K EI0 / l, make f1 from the
    table's b_1 l, and solve back: EI0 to the table's 5 digits."""
    ei0, span, mass = 2e-3, 0.4, 0.0333
    f1 = beta ** 2 / (2 * math.pi * span ** 2) * math.sqrt(ei0 / mass)
    ei = cable.bending_from_f1(f1, span, mass, "elastic", stiffness_ratio * ei0 / span)
    assert ei == pytest.approx(ei0, rel=2e-4)


def test_f1_round_trip_through_a_run():
    """EI from f1 = 40 Hz measured on a 0.4 m clamped span: the run of that span gives
    natural_frequency = 40 Hz back, and the dataset says where EI came from."""
    text = ('name = "f1-round-trip"\n[model]\nmodes = 1\n[clamps]\nrotation = "clamped"\n'
            '[cable]\nlinear_mass = "53.4 g/m"\naxial_rigidity = "660 kN"\n'
            'diameter = "2.76 mm"\nf1_measured = "40 Hz"\nf1_span = "400 mm"\n'
            'damping_ratio = 0.02\n[base]\nacceleration_g = 1e-5\nfrequency_ratio = 1.0\n'
            '[solver]\nt_end = 0.2\nrtol = 1e-10\n[metrics]\ntail = 0.25\n'
            '[axes]\nlength = [0.4]\n')
    ds = sweep.run(load(text), progress=False)
    assert float(ds["natural_frequency"].squeeze()) == pytest.approx(40.0, rel=1e-9)
    source = ds.attrs["bending_rigidity_source"]
    ei = 0.0534 * (2 * math.pi * 40.0 * 0.4 ** 2 / 4.730040745 ** 2) ** 2
    assert source.startswith("measured") and f"{ei:.6g}" in source and "40 Hz" in source
    assert 'f1_measured = 40.0' in ds.attrs["scene"]


def test_sweep_keys_shows_the_unit_and_what_it_accepts():
    from sweep import keys
    from sweep.scene import parse_override
    text = keys.text("cable.linear_mass")
    assert "[kg m-1]" in text and "'33.3 g/m'" in text and "mass per length" in text
    assert "standard gravity" in keys.text("base.acceleration")
    assert keys.accepted_units(schema.BY_DOTTED["cable.damping_ratio"]) == ""
    assert parse_override("cable.diameter=1.27 mm") == ("cable.diameter", "1.27 mm")


def test_a_data_sheet_beyond_double_range_is_one_line():
    """axial_rigidity = 1e308 over a 2.76 mm section makes E overflow (inf) and I = EI / E
    vanish: one line naming the data-sheet keys, not a traceback (found by the scene fuzzer)."""
    with pytest.raises(sweep.SceneError) as info:
        sweep.load_scene("harness-clamps", overrides={"cable.axial_rigidity": 1e308})
    assert "cable.axial_rigidity" in str(info.value) and "\n" not in str(info.value)


def test_a_data_sheet_without_a_diameter_reports_no_bending_strain():
    """A data sheet gives no area to take an outer diameter from: a pinned span under the
    uniform tension reports its tension and axial strain but no bending strain (it once took
    the 1 m^2 reference area's 1.13 m and said 50 % strain); with cable.diameter the midspan's
    is (d / 2) (pi / l)^2 times the one mode's amplitude."""
    text = ('[cable]\nlinear_mass = "53.4 g/m"\nbending_rigidity = "0.31515 N m^2"\n'
            'axial_rigidity = "660 kN"\n[base]\nacceleration_g = 0.5\nfrequency = 20.0\n'
            '[axes]\nlength = [0.3, 0.5]\n[solver]\nt_end = 1.0\n')
    bare = sweep.run(load(text))
    assert "axial_strain" in bare and "midspan_bending_strain" not in bare
    assert "max_strain" not in bare
    given = sweep.run(load(text.replace('axial_rigidity = "660 kN"\n',
                                        'axial_rigidity = "660 kN"\ndiameter = "2 mm"\n')))
    expected = 0.5 * 2e-3 * (np.pi / given.length) ** 2 * given.amplitude
    np.testing.assert_allclose(given.midspan_bending_strain, expected, rtol=1e-12)


@pytest.mark.parametrize("overrides, key", [
    ({"cable.linear_mass": 53.4}, "cable.linear_mass"),
    ({"cable.diameter": 2.76}, "cable.diameter"),
    ({"cable.damping_ratio": 1.5}, "cable.damping_ratio"),
    ({"axes.length": [0.2, 150.0]}, "cable.length")])
def test_a_data_sheet_number_without_its_unit_is_warned_of(overrides, key):
    """Plain numbers are SI: a data sheet's 53.4 (g/m) typed bare is 53.4 kg/m, and the span's
    f1 half a hertz (a reviewer's slip). One warning naming the key and the unit string to
    write; the built-in scene alone warns of nothing."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sweep.load_scene("harness-base-sine", overrides)
        sweep.load_scene("harness-base-sine")
    messages = [str(w.message) for w in caught if issubclass(w.category, sweep.CableSweepWarning)]
    assert len(messages) == 1 and messages[0].startswith(key) and "SI" in messages[0]


@pytest.mark.parametrize("extra", ["wires = 7", 'bending = "lower"'])
def test_bundle_keys_beside_a_data_sheet_without_a_wire_are_refused(extra):
    """A data sheet's mass, EI and EA with `wires = 7` ran one wire's cable: 7x too light and
    7x too little EA, and the stored scene said 7 (a reviewer's finding). The bundle keys need
    cable.wire: one line naming the key."""
    text = ('[cable]\nlinear_mass = "53.4 g/m"\naxial_rigidity = "660 kN"\n'
            f'bending_rigidity = 0.1\n{extra}\n')
    with pytest.raises(sweep.SceneError) as info:
        load(text)
    message = str(info.value)
    assert "cable.wire" in message and extra.split()[0] in message and "\n" not in message


@pytest.mark.parametrize("key, value, words", [
    ("cable.axial_rigidity", "1.65 mN", "is less than 1000 N: a harness cable's EA is kN to MN"),
    ("cable.bending_rigidity", "0.1 N mm^2", "is less than 1e-06 N m^2"),
    ("cable.linear_mass", "0.01 g/m", "is less than 0.0001 kg/m"),
])
def test_a_data_sheet_value_a_million_times_too_small_is_warned(key, value, words):
    """A unit mistyped by 1e6 ('mN' for 'MN') gives a cable that silently does not stretch or
    bend as a cable does: one warning line, the run still allowed (a reviewer's case)."""
    from sweep.errors import CableSweepWarning
    import re
    with pytest.warns(CableSweepWarning, match=re.escape(words)):
        sweep.load_scene("launch-random-gevs", overrides={key: value})
