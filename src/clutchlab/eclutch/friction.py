"""Friction laws of the E-clutch's friction elements, as scalar compiled functions.

The friction elements of the axial models (R_f.ds, R_f.pp of [1] Figs. 5b,
11) and the actuator's seals and spindle
(:func:`clutchlab.eclutch.dynamics.actuator_friction_elements`) share one law
(:class:`FrictionElement`): a kinetic (Coulomb)
force that grows with a normal force and a chamber pressure, a static limit
``r_s`` times that, and a viscous part.  The stick-slip state machine that
switches between them ([2], the Modelica Standard Library's friction element)
is mode logic of the dynamics (:mod:`clutchlab.eclutch.system`); the
equations are here, written once.

References
----------
.. [1] K. Haramina, N. Kranjčević, M. Hoić, J. Deur, A. Tissot, Trans. FAMENA
   48 (2024) 21-35, doi:10.21278/TOF.483057923
.. [2] M. Otter, H. Elmqvist, S. E. Mattsson, "Hybrid modeling in Modelica
   based on the synchronous data flow principle", CACSD 1999.
"""

from __future__ import annotations

import dataclasses

import numba
import numpy as np

from ..errors import ParameterError

__all__ = ["FrictionElement", "kinetic_level", "slip_force", "static_margin"]


@dataclasses.dataclass(frozen=True)
class FrictionElement:
    """A friction element acting on one node of the network (or on the actuator).

    Kinetic force ``F_c = coulomb + coefficient * |f_normal| + pressure_coefficient * |p|``,
    opposing the slip, plus ``viscous * v``; static limit ``static_ratio * F_c``.

    Parameters
    ----------
    name : str
        Label (``"R_f.ds"``).
    node : str
        Network node name, or ``"master"`` / ``"bearing"`` for the actuator pistons.
    coulomb : float
        Constant Coulomb force [N].
    coefficient : float
        Friction per unit force of ``normal`` [-].
    normal : str or None
        Network element whose force presses the contact.
    pressure_coefficient : float
        Friction per unit chamber pressure [N/Pa] (seals).
    pressure : str or None
        ``"master"`` or ``"slave"`` chamber.
    static_ratio : float
        Static over kinetic friction (>= 1).
    viscous : float
        Viscous coefficient [N s/m].
    """

    name: str
    node: str
    coulomb: float = 0.0
    coefficient: float = 0.0
    normal: str | None = None
    pressure_coefficient: float = 0.0
    pressure: str | None = None
    static_ratio: float = 1.0
    viscous: float = 0.0

    def __post_init__(self):
        for fld in ("coulomb", "coefficient", "pressure_coefficient", "viscous"):
            v = getattr(self, fld)
            if not (np.isfinite(v) and v >= 0):
                raise ParameterError(f"friction element {self.name!r}: {fld} = {v!r} must be finite and >= 0")
        if not (np.isfinite(self.static_ratio) and self.static_ratio >= 1.0):
            raise ParameterError(f"friction element {self.name!r}: static_ratio = {self.static_ratio!r} must be >= 1")
        if self.pressure not in (None, "master", "slave"):
            raise ParameterError(f"friction element {self.name!r}: pressure = {self.pressure!r} (use 'master' or 'slave')")

    @property
    def active(self) -> bool:
        """True if the element can exert any Coulomb force."""
        return self.coulomb > 0 or self.coefficient > 0 or self.pressure_coefficient > 0


@numba.njit(cache=True, nogil=True)
def kinetic_level(coulomb, coefficient, normal_force, pressure_coefficient, pressure):
    """Kinetic friction force magnitude ``F_c = F_c0 + mu_n |f_n| + mu_p |p|`` [N].

    Parameters
    ----------
    coulomb : float
        Constant Coulomb force F_c0 [N].
    coefficient : float
        Friction per unit normal force mu_n [-] (R_f.ds: the diaphragm force presses the fulcrum rings).
    normal_force : float
        Force of the element that presses the contact [N] (0 if none).
    pressure_coefficient : float
        Friction per unit chamber pressure mu_p [N/Pa] (seals; the spindle loss ``(1/eta - 1) A_mc``).
    pressure : float
        Gauge pressure of the chamber [Pa] (0 if none).

    Notes
    -----
    A zero normal force means no friction: with ``F_c0 = 0`` an unloaded element is free.
    """
    return coulomb + coefficient * abs(normal_force) + pressure_coefficient * abs(pressure)


@numba.njit(cache=True, nogil=True)
def slip_force(direction, level, viscous, velocity):
    """Friction force on a slipping coordinate, ``F_f = -s F_c - c v`` [N].

    Parameters
    ----------
    direction : float
        Slip direction s of the mode (+1 forward, -1 backward; 0 for a viscous-only element) [-].
    level : float
        Kinetic force F_c [N] (:func:`kinetic_level`).
    viscous : float
        Viscous coefficient c [N s/m].
    velocity : float
        Velocity v [m/s].

    Notes
    -----
    The mode's sign s, not ``sign(v)``, keeps the right-hand side smooth inside a mode: no chattering and no
    regularisation velocity ([2]); the mode changes when v crosses zero (an event).
    """
    return -direction * level - viscous * velocity


@numba.njit(cache=True, nogil=True)
def static_margin(static_ratio, level, force):
    """How far a stuck contact is from breaking away, ``r_s F_c - |F|`` [N] (negative: it slips).

    Parameters
    ----------
    static_ratio : float
        Static over kinetic friction r_s (>= 1) [-].
    level : float
        Kinetic force F_c [N].
    force : float
        Force the contact must carry to stay stuck (every other force on the coordinate) [N].
    """
    return static_ratio * level - abs(force)
