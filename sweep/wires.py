"""Flight wires as their data sheets give them, and a bundle of n identical ones.

Data only, plus the bundle rules: a scene names a row (``cable.wire = "spec55-22"``), a count
(``cable.wires = 7``) and a bound of the bundle's bending stiffness (``cable.bending =
"lower" | "upper"``); sweep/models/cable.py turns them into the model's m, EI and EA.

Every number of a row cites its source in the row. A row holds only what a source gives: a
gauge whose outer diameter and mass per length could not be sourced is left out (no ESCC 3901
row yet: the detail specifications were not at hand; add rows with their source).

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


WIRES: dict[str, Wire] = {w.name: w for w in (
    Wire("spec55-22", "AWG 22 Spec-55 (SAE AS22759/32-22, Raychem 55A0111-22): ETFE over "
         "19-strand tin-plated copper",
         diameter=0.050 * INCH,                     # 1.27 mm
         linear_mass=3.2 * POUND / (1000.0 * FOOT),  # 3.2 lb/kft = 4.762 g/m
         strands=19, strand_diameter=0.0063 * INCH,  # 19/34: 0.0063 in strands
         modulus=COPPER_MODULUS,
         source="outer diameter 0.050 in and 3.2 lb/1000 ft: the data-sheet values quoted in "
                "issue 37 (1.27 mm, 4.76 g/m), not checked here against SAE AS22759/32 itself; "
                "stranding 19/34, strands 0.0063 in: a stranded-wire chart (Stranded Wire Data "
                "Chart, 22 AWG 19/34), AWG 34 = 0.0063 in by ASTM B258; copper E: "
                "COPPER_MODULUS"),
)}

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
