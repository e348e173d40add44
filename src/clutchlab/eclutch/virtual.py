"""The virtual clutch: ground truth for the synthetic press-rig and full-clutch records.

clutchlab cannot ship the measurements of Haramina et al. [1], so it ships a
virtual clutch built from the component laws of :mod:`clutchlab.eclutch.components`, richer
than any of the paper's Models 0-4:

* the Belleville body of the diaphragm acts on the *rotation* of the lever
  (edge relative to the yoke support, seen at the tips through ``i_ds``),
  and the finger compliance sits in series between the bearing and the body;
* the yoke support is the support ring and the yoke support spring as two
  separate springs in series;
* the pressure plate with its wear-compensation mechanism is a stiff
  progressive spring between diaphragm edge and pressure plate;
* quasi-static stiction at the diaphragm supports, proportional to the support
  reaction (largest when the clutch is closed, as [1] Section 6 argues), acts
  on the bearing force through a compliant stick (Prandtl stop operator);
* the press rig used to characterise the components is compliant
  (``press_compliance``), so stiff parts look softer than they are ([1],
  Sections 5.3-5.4).

Every value is *representative* of a passenger-car single-plate dry clutch
(clamp load about 5 kN, effective radius 0.103 m, lever ratio -4, release
travel 9 mm, peak release force about 1.3 kN), chosen with the reasoning in
``docs/eclutch.md``; none is measured.

References
----------
.. [1] K. Haramina et al., Trans. FAMENA 48 (2024) 21-35, doi:10.21278/TOF.483057923
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..curves import Curve
from ..params import ParameterSet, quantity
from . import components as law
from .network import GROUND, AxialNetwork, Lever, Node, Spring, solve_static, zero_input

__all__ = ["VirtualClutch"]

_REP = "representative (docs/eclutch.md)"


@dataclasses.dataclass(frozen=True)
class VirtualClutch(ParameterSet):
    """Parameters of the virtual (ground-truth) clutch; see module docstring."""

    kind = "virtual_clutch"

    lever_ratio: float = quantity(-4.0, "1", "diaphragm lever ratio i_ds (tip/edge travel)", source=_REP, bounds=(-20, -0.1))
    bearing_stiffness: float = quantity(8.0e6, "N/m", "release bearing axial stiffness k_b", source=_REP, positive=True)
    bearing_preload: float = quantity(80.0, "N", "CSC preload spring force on the bearing", source=_REP, nonnegative=True)
    belleville_stiffness: float = quantity(6.4e5, "N/m", "Almen-László initial stiffness, tip-referred", source=_REP, positive=True)
    belleville_height: float = quantity(9.0e-3, "m", "Almen-László cone height h, tip-referred", source=_REP, positive=True)
    belleville_thickness: float = quantity(5.0e-3, "m", "Almen-László thickness t, tip-referred", source=_REP, positive=True)
    belleville_prestrain: float = quantity(4.6e-3, "m", "Belleville deflection in the nominal assembly, tip-referred", source=_REP)
    finger_stiffness: float = quantity(1.1e6, "N/m", "finger (lever) stiffness at zero load", source=_REP, positive=True)
    finger_stiffening: float = quantity(10e-3, "m", "finger stiffening length (k = k0 (1 + 2|d|/L))", source=_REP, positive=True)
    pp_spring_stiffness: float = quantity(2.0e7, "N/m", "pressure plate + wear compensation initial stiffness", source=_REP, positive=True)
    pp_spring_length: float = quantity(1.0e-4, "m", "pressure plate spring stiffening length", source=_REP, positive=True)
    cushion_scale: float = quantity(170.0, "N", "cushion spring force scale a (F = a(exp(b s)-1))", source=_REP, positive=True)
    cushion_rate: float = quantity(5000.0, "1/m", "cushion spring rate b", source=_REP, positive=True)
    cushion_prestrain: float = quantity(0.75e-3, "m", "cushion compression in the nominal assembly", source=_REP)
    return_stiffness: float = quantity(3.0e4, "N/m", "return leaf springs, all three", source=_REP, positive=True)
    return_prestrain: float = quantity(8.0e-3, "m", "return spring pre-stretch in the nominal assembly", source=_REP)
    ring_coefficient: float = quantity(2.0e10, "N/m**1.5", "support ring Hertz coefficient", source=_REP, positive=True)
    yoke_spring_stiffness: float = quantity(2.0e7, "N/m", "yoke support spring initial stiffness (Almen-László)", source=_REP, positive=True)
    yoke_spring_height: float = quantity(0.8e-3, "m", "yoke support spring cone height h (h/t < sqrt(2): monotone)", source=_REP, positive=True)
    yoke_spring_thickness: float = quantity(0.65e-3, "m", "yoke support spring thickness t", source=_REP, positive=True)
    yoke_spring_preload: float = quantity(1500.0, "N", "preload of the yoke support spring against the support ring", source=_REP, nonnegative=True)
    r_eff: float = quantity(0.1026, "m", "effective friction radius (r_o = 120 mm, r_i = 82.5 mm, uniform pressure)", source=_REP, positive=True)
    mu: float = quantity(0.27, "1", "friction coefficient of the facings", source=_REP, positive=True)
    support_friction: float = quantity(0.012, "1", "stiction at the bearing per N of support reaction", source=_REP, nonnegative=True)
    stick_stiffness: float = quantity(2.0e6, "N/m", "stick (pre-sliding) stiffness of the support friction at the bearing", source=_REP, positive=True)
    slave_area: float = quantity(7.0e-4, "m**2", "CSC piston area A_sl (F_b = p A_sl)", source=_REP, positive=True)
    press_compliance: float = quantity(4.0e-8, "m/N", "manual press rig compliance seen by the LVDT", source=_REP, nonnegative=True)
    m_pp: float = quantity(3.5, "kg", "pressure plate mass", source=_REP, positive=True)
    m_pps: float = quantity(0.9, "kg", "diaphragm spring mass (edge node)", source=_REP, positive=True)
    m_ds: float = quantity(0.3, "kg", "yoke support mass", source=_REP, positive=True)

    def check(self) -> None:
        from ..errors import ParameterError

        ratio = self.yoke_spring_height / self.yoke_spring_thickness
        if not ratio < 2.0**0.5:
            raise ParameterError(
                f"VirtualClutch: yoke_spring_height / yoke_spring_thickness = {ratio:.4g} must be < sqrt(2) "
                "(Almen-Laszlo: the yoke support spring must be monotone)")

    # ---------------------------------------------------------------- true laws
    def belleville(self) -> Curve:
        """Diaphragm Belleville body, force at the tips vs rigid-lever tip deflection [m -> N]."""
        s = np.linspace(-2e-3, 20e-3, 221)
        return Curve(s, law.almen_laszlo(s, self.belleville_stiffness, self.belleville_height, self.belleville_thickness),
                     kind="pchip", name="Belleville body (true)")

    def fingers(self) -> Curve:
        """Finger (lever) compliance, mildly progressive in both directions [m -> N]."""
        d = np.linspace(-6e-3, 6e-3, 121)
        return Curve(d, self.finger_stiffness * d * (1.0 + np.abs(d) / self.finger_stiffening), kind="pchip",
                     name="fingers (true)")

    def pp_spring(self) -> Curve:
        """Pressure plate with wear-compensation mechanism [m -> N]."""
        s = np.linspace(0.0, 4e-4, 81)
        return Curve(s, law.progressive_quadratic(s, self.pp_spring_stiffness, self.pp_spring_length), kind="pchip",
                     name="pressure plate spring (true)")

    def cushion(self) -> Curve:
        """Woven cushion spring of the friction plate [m -> N]."""
        s = np.linspace(0.0, 1.0e-3, 101)
        return Curve(s, law.progressive_exponential(s, self.cushion_scale, self.cushion_rate), kind="pchip",
                     name="cushion spring (true)")

    def return_springs(self) -> Curve:
        """Return leaf springs (all three in parallel) [m -> N]."""
        return Curve.linear(self.return_stiffness, span=(0.0, 15e-3), name="return springs (true)")

    def support_ring(self) -> Curve:
        """Solid yoke support ring [m -> N]."""
        s = np.linspace(0.0, 1.5e-4, 151)
        return Curve(s, law.hertz_contact(s, self.ring_coefficient), kind="pchip", name="support ring (true)")

    def yoke_spring(self) -> Curve:
        """Yoke support spring, a disk spring like the diaphragm ([1] Sec. 4.6): Almen-László, monotone [m -> N]."""
        s = np.linspace(0.0, 1.0e-3, 101)
        return Curve(s, law.almen_laszlo(s, self.yoke_spring_stiffness, self.yoke_spring_height, self.yoke_spring_thickness),
                     kind="pchip", name="yoke support spring (true)")

    def diaphragm_at_tip(self) -> Curve:
        """What the press measures at the tips with the diaphragm on the pressure plate (test a).

        The Belleville body in series with the fingers: tip deflection
        ``s = p + fingers^-1(F(p))`` for body deflection ``p``.  The body is
        non-monotone but ``ds/dp = 1 + k_body/k_fl > 0``, so the samples stay sorted.
        """
        p = np.linspace(0.0, 18e-3, 361)
        F = self.belleville()(p)
        s = p + self.fingers().inverse(F)
        return Curve(s, F, kind="pchip", name="diaphragm at the tips (true)")

    # ------------------------------------------------------------------ network
    def network(self) -> AxialNetwork:
        """The truth clutch as an :class:`AxialNetwork` (finger compliance in series with the body)."""
        i = self.lever_ratio
        nodes = (Node("bearing"), Node("tip"), Node("edge", self.m_pps), Node("pp", self.m_pp),
                 Node("support", self.m_ds))
        k_b = Curve.linear(self.bearing_stiffness, span=(0.0, 1e-3), name="bearing k_b")
        elements = (
            Spring("bearing", "bearing", k_b, b="tip", unilateral=True),
            Lever("fingers", "tip", "edge", i, pivot="support", stiffness=self.fingers()),
            Spring("belleville", "edge", self.belleville(), b="support", prestrain=self.belleville_prestrain, gain=i),
            Spring("pp_spring", "edge", self.pp_spring(), b="pp", unilateral=True),
            Spring("cushion", "pp", self.cushion(), prestrain=self.cushion_prestrain, unilateral=True),
            Spring("return", "pp", self.return_springs(), prestrain=self.return_prestrain),
            # cover-side support ring and flywheel-side yoke support spring, preloaded against each other
            Spring("ring", GROUND, self.support_ring(), b="support", unilateral=True,
                   prestrain=float(self.support_ring().inverse(self.yoke_spring_preload))),
            Spring("yoke_spring", "support", self.yoke_spring(), unilateral=True,
                   prestrain=float(self.yoke_spring().inverse(self.yoke_spring_preload))),
        )
        net = AxialNetwork(nodes, elements, input="bearing", normal_force="cushion", name="virtual clutch (truth)")
        return zero_input(net, "bearing", self.bearing_preload)

    def static(self, bearing_position_m) -> dict:
        """Static equilibria of the truth network (no friction) along the bearing travel."""
        return solve_static(self.network(), bearing_position_m)

    def inspection(self) -> dict[str, float]:
        """Component deflections in the assembled clutch at bearing position 0 [m].

        These play the role of the pre-strains [1] determined "from the
        inspection and measurements of the actual clutch" (Section 5): what a
        careful engineer would measure on the assembled truth.
        """
        st = self.static(np.array([0.0]))
        names = st["element_names"]
        d = dict(zip(names, st["deflections"][0]))
        x = dict(zip(st["node_names"], st["node_positions"][0]))
        return {
            "diaphragm": d["belleville"] + d["fingers"],  # tip deflection from the free diaphragm
            "cushion": d["cushion"],
            "return": d["return"],
            "pp_spring": d["pp_spring"],
            "tip": x["tip"],
            "support_position": x["support"],
        }

    def support_reaction(self, static: dict) -> np.ndarray:
        """Force between diaphragm and yoke support [N] along a static solution."""
        names = static["element_names"]
        return static["forces"][:, names.index("ring")] - static["forces"][:, names.index("yoke_spring")]
