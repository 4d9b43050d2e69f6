"""Flight wires as their data sheets give them, and a bundle of n identical ones.

Data only, plus the bundle rules: a scene names a row (``cable.wire = "spec55-22"``), a count
(``cable.wires = 7``) and a bound of the bundle's bending stiffness (``cable.bending =
"lower" | "upper"``); sweep/models/cable.py turns them into the model's m, EI and EA.

Every row cites its source (SPEC55_SOURCE: the Spec-55 gauges 26 to 12 of one Raychem
specification control drawing, as printed). A row holds only what a source gives: no ESCC 3901
row yet (its detail specifications were not at hand; add rows with their source).

Bundle rules (SI units throughout):
- mass per length: n m_wire (kg/m);
- axial stiffness: n E_c A_c (N), the conductors' copper only (the insulation's modulus is
  about 1 % of copper's);
- packing: the wires' centres on a hexagonal lattice of pitch d (the wire's outer diameter),
  filled ring by ring from the centre (1, 7, 19, 37 ... wires fill whole rings); the bundle's
  diameter is (2 k + 1) d with k the outermost ring used (3 d for 7 wires);
- bending stiffness, two bounds: lower, every strand of every wire bending about its own axis
  (strands slipping freely): n s E_c pi d_s^4 / 64 (s strands of diameter d_s a wire);
  upper, the bundle's copper bending as one solid section about the bundle's axis (nothing
  slips): E_c (n A_c^2 / (4 pi) + A_c sum_i r_i^2 / 2), each wire's conductor a solid round
  of area A_c = s pi d_s^2 / 4 at distance r_i from the bundle's centre (the sum halved: the
  mean over bending planes, exact for whole rings). The insulation is left out of both (it
  would add a few per cent to the upper bound). A real bundle lies in between, often far
  from both: a measured first natural frequency (cable.f1_measured) beats both bounds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

INCH = 0.0254
"""m per inch (exact)."""
POUND = 0.45359237
"""kg per pound (exact)."""
FOOT = 0.3048
"""m per foot (exact)."""
COPPER_MODULUS = 1.1e11
"""Young's modulus of the conductors' copper (Pa): Table 1 of the paper the model follows
(docs/model.md sec. 1), the project's default cable.youngs_modulus."""


@dataclass(frozen=True)
class Wire:
    """One wire of the table.

    name: the scene's name for it (cable.wire); title: what it is.
    diameter: outer diameter (m); linear_mass: mass per length (kg/m).
    strands, strand_diameter: the conductor's construction (count; m).
    modulus: Young's modulus of the conductor (Pa).
    source: where each number comes from.
    """

    name: str
    title: str
    diameter: float
    linear_mass: float
    strands: int
    strand_diameter: float
    modulus: float
    source: str

    @property
    def conductor_area(self) -> float:
        """The conductor's metal area s pi d_s^2 / 4 (m^2)."""
        return self.strands * math.pi * self.strand_diameter ** 2 / 4.0

    @property
    def axial_rigidity(self) -> float:
        """E_c A_c of the conductor (N)."""
        return self.modulus * self.conductor_area

    @property
    def strand_bending(self) -> float:
        """s E_c pi d_s^4 / 64 (N m^2): the strands bending each about its own axis."""
        return self.strands * self.modulus * math.pi * self.strand_diameter ** 4 / 64.0


def awg_diameter(gauge: int) -> float:
    """The diameter (m) of a solid round wire of AWG `gauge`, by the gauge's definition (ASTM
    B258): 0.005 in x 92^((36 - n) / 39)."""
    return 0.005 * INCH * 92.0 ** ((36 - gauge) / 39.0)


SPEC55_SOURCE = ("TE Connectivity (Raychem) Specification Control Drawing 55A0813, revision S "
                 "(2017-01-12), Table I: wire, radiation-crosslinked modified ETFE, normal "
                 "weight, nickel-coated copper, 600 V (Spec 55A): stranding, finished wire "
                 "diameter (nominal, in) and maximum weight (lb/1000 ft); strand diameter: the "
                 "AWG definition (ASTM B258, `awg_diameter`); copper E: COPPER_MODULUS")
"""Where every Spec-55 row comes from."""

SPEC55_TABLE = (            # (AWG, strands, strand AWG, finished diameter in, lb/1000 ft)
    (26, 19, 38, 0.040, 1.70),
    (24, 19, 36, 0.045, 2.30),
    (22, 19, 34, 0.050, 3.20),
    (20, 19, 32, 0.058, 4.70),
    (18, 19, 30, 0.070, 7.20),
    (16, 19, 29, 0.077, 9.00),
    (14, 19, 27, 0.094, 13.8),
    (12, 37, 28, 0.111, 20.5),
)
"""SCD 55A0813's Table I, as printed (SPEC55_SOURCE). The weight is the sheet's maximum, so a
span's mass (and its f1 by a few per cent) errs on the heavy side. No ESCC 3901 rows: its
detail specifications were not at hand; add rows with their source."""


def _spec55(gauge: int, strands: int, strand_gauge: int, diameter_in: float,
            weight_lb_kft: float) -> Wire:
    return Wire(f"spec55-{gauge}", f"AWG {gauge} Spec-55 (Raychem 55A0813-{gauge}): modified "
                f"ETFE over {strands}/{strand_gauge} nickel-coated copper",
                diameter=diameter_in * INCH, linear_mass=weight_lb_kft * POUND / (1000.0 * FOOT),
                strands=strands, strand_diameter=awg_diameter(strand_gauge),
                modulus=COPPER_MODULUS, source=SPEC55_SOURCE)


WIRES: dict[str, Wire] = {w.name: w for w in (_spec55(*row) for row in SPEC55_TABLE)}

WIRE_NAMES: tuple[str, ...] = tuple(WIRES)


def ring_of(count: int) -> int:
    """The outermost hexagonal ring k a bundle of `count` wires reaches (0 for one wire; ring
    k holds 6 k wires)."""
    k, held = 0, 1
    while held < count:
        k += 1
        held += 6 * k
    return k


def hexagonal_radii(count: int) -> list[float]:
    """Distances (in wire diameters) of `count` wire centres from the bundle's centre on a
    hexagonal lattice of unit pitch, ring by ring, each ring from its corners (6 at k) to its
    sides."""
    radii = [0.0]
    k = 0
    while len(radii) < count:
        k += 1
        ring = []
        for j in range(k):                       # j steps along a side from a corner
            # a point j along the side between corners k e0 and k e60: |k e0 + j (e120)|
            x = k - 0.5 * j
            y = j * math.sqrt(3.0) / 2.0
            ring.extend([math.hypot(x, y)] * 6)
        ring.sort()
        radii.extend(ring[:count - len(radii)])
    return radii[:count]


@dataclass(frozen=True)
class Bundle:
    """A bundle of n identical wires (see the module's rules): linear_mass (kg/m), diameter
    (m), axial_rigidity (N), bending_lower and bending_upper (N m^2)."""

    wire: Wire
    count: int
    linear_mass: float
    diameter: float
    axial_rigidity: float
    bending_lower: float
    bending_upper: float

    def bending(self, bound: str) -> float:
        """EI (N m^2) of bound "lower" or "upper"."""
        return self.bending_lower if bound == "lower" else self.bending_upper


def bundle(name: str, count: int = 1) -> Bundle:
    """The bundle of `count` wires `name` of WIRES."""
    wire = WIRES[name]
    area = wire.conductor_area
    second = sum(r * r for r in hexagonal_radii(count)) * wire.diameter ** 2 / 2.0
    upper = wire.modulus * (count * area * area / (4.0 * math.pi) + area * second)
    return Bundle(wire, count, linear_mass=count * wire.linear_mass,
                  diameter=(2 * ring_of(count) + 1) * wire.diameter,
                  axial_rigidity=count * wire.axial_rigidity,
                  bending_lower=count * wire.strand_bending, bending_upper=upper)
