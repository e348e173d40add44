"""E-clutch dynamics: actuator plus clutch axial Models 0-4 with stick-slip friction.

Haramina et al. [1] build the axial Models 0-4 with masses (m_pp, m_pps, m_ds)
and friction elements (R_f.ds, R_f.pp) in their bond graphs (Figs. 5b, 11) but
validate them with friction switched off; their future work (i) expects
stiction to explain the force stagnation near the peak and the measured
hysteresis, and (iii) thermal expansion and wear.  This module adds both:

* :class:`FrictionParameters` -- the friction elements, with the stick-slip
  state machine of the Modelica Standard Library (stuck holds zero relative
  acceleration while the force it needs stays within the static limit, breaks
  away above it; a zero normal force means no friction);
* :class:`ClutchDynamics` -- the clutch alone, driven by a prescribed bearing
  motion (the situation of the paper's static curves);
* :class:`EClutch` -- actuator ([1] Sec. 2.1, Fig. 5a) and clutch coupled by
  the bearing stiffness k_b ([1] Sec. 3.2), driven by the motor voltage or by
  a bearing-position reference tracked by the E-clutch's position controller;
* :func:`apply_wear_and_expansion` -- wear and thermal offsets (future work iii).

Equations of motion (coordinates ``z``: master piston, CSC/bearing, free
nodes of the network; ``d = d0 + GA q + Gb u`` are the element deflections)::

    m_j dv_j/dt = F_j(z, p, i) + F_f,j      (mass coordinates)
    0           = F_j(z)                    (massless nodes: algebraic)
    F_q = -GA^T f(d),   F_u = -Gb^T f(d) + p_s A_sl + F_pre - k_pre u

integrated by the Rodas3 method of the integrator core
(:func:`clutchlab.numerics.core.advance_rodas`), stiffly accurate so the
algebraic rows of massless nodes are solved with the dynamics, with
stick/slip, contact and end-stop events located by root finding on the dense
output to within ``event_tol`` seconds.  The model implements the system
contract once, in :mod:`clutchlab.eclutch.system`; the classes here are thin
wrappers that build its :class:`~clutchlab.system.System` and run it with
:func:`clutchlab.system.simulate` (:meth:`EClutch.simulate`,
:meth:`ClutchDynamics.simulate` return a :class:`DynamicsResult` view of the
:class:`~clutchlab.SimulationResult`, kept in its ``result`` attribute).

References
----------
.. [1] K. Haramina, N. Kranjčević, M. Hoić, J. Deur, A. Tissot, Trans. FAMENA
   48 (2024) 21-35, doi:10.21278/TOF.483057923
.. [2] M. Otter, H. Elmqvist, S. E. Mattsson, "Hybrid modeling in Modelica
   based on the synchronous data flow principle", CACSD 1999 (the friction
   state machine of Modelica.Mechanics.Translational).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import math

import numpy as np
import pandas as pd

from .. import system as contract
from .._limits import check_allocation, short_repr
from ..errors import ParameterError, SimulationError
from ..params import ParameterSet, quantity
from ..result import BuiltOnFirstAccess, SimulationResult
from . import system as S
from .actuator import ActuatorParameters
from .friction import FrictionElement
from .models import ClutchModel
from .network import AxialNetwork, Lever, Spring

__all__ = [
    "FrictionParameters", "FrictionElement", "ClutchDynamics", "EClutch", "DynamicsResult",
    "apply_wear_and_expansion", "pedal_reference", "actuator_test_rig", "EVENT_KINDS", "simulate_batch",
    "BatchResult",
]

#: readable labels of the events by event code (the ``description`` column of :attr:`DynamicsResult.events`, whose
#: ``event`` column names them as :data:`clutchlab.eclutch.system.EVENTS`: ``stick``,
#: ``breakaway``, ``slip_reversal``, ``contact_close``, ``contact_open``, ``stop_hit``, ``stop_leave``,
#: ``cavitation_start``, ``cavitation_end``, ``friction_free``, ``friction_engage``)
EVENT_KINDS = {S.EV_STICK: "stick", S.EV_BREAKAWAY: "breakaway", S.EV_REVERSAL: "slip reversal",
               S.EV_CONTACT_CLOSE: "contact closes", S.EV_CONTACT_OPEN: "contact opens",
               S.EV_STOP_HIT: "end stop hit", S.EV_STOP_LEAVE: "end stop left",
               S.EV_CAVITATION_START: "cavitation starts", S.EV_CAVITATION_END: "cavitation ends",
               S.EV_FREE: "friction free", S.EV_ENGAGE: "friction engages"}
_LABELS = {S.EVENTS[code]: label for code, label in EVENT_KINDS.items()}
_STOPS = dict(zip(S.STOPS, ("master rest stop", "master stroke end", "CSC engaged stop", "CSC travel end")))
_CHAMBERS = dict(zip(S.CHAMBERS, ("master chamber", "CSC chamber")))
_REP = "representative (docs/eclutch_dynamics.md)"


@dataclasses.dataclass(frozen=True)
class FrictionParameters(ParameterSet):
    """Friction elements R_f.ds and R_f.pp of the axial models ([1] Sec. 3.2, Figs. 5b, 11).

    ``R_f.ds`` is the friction of the diaphragm spring on its fulcrum rings,
    proportional to the diaphragm force (the paper's conclusion: friction is
    highest where the diaphragm presses hardest on its supports); it acts on
    the diaphragm body -- node ``edge`` of Models 2-4, the pressure plate of
    Models 0-1, where the diaphragm rides on it.  ``R_f.pp`` is the friction of
    the pressure plate in its guides, a constant Coulomb force.
    """

    kind = "eclutch_friction"

    diaphragm_coefficient: float = quantity(0.03, "1", "R_f.ds: kinetic friction per unit diaphragm force", source=_REP, nonnegative=True, bounds=(0.0, 1.0))
    pressure_plate_force: float = quantity(10.0, "N", "R_f.pp: Coulomb friction force of the pressure plate guides", source=_REP, nonnegative=True)
    static_ratio: float = quantity(1.25, "1", "static over kinetic friction (break-away limit)", source=_REP, bounds=(1.0, 5.0))
    diaphragm_viscous: float = quantity(20.0, "N*s/m", "viscous part of R_f.ds", source=_REP, nonnegative=True)
    pressure_plate_viscous: float = quantity(20.0, "N*s/m", "viscous part of R_f.pp", source=_REP, nonnegative=True)

    @classmethod
    def off(cls) -> "FrictionParameters":
        """No friction at all (the setting of [1] Secs. 5-6)."""
        return cls(diaphragm_coefficient=0.0, pressure_plate_force=0.0, static_ratio=1.0, diaphragm_viscous=0.0,
                   pressure_plate_viscous=0.0)


def clutch_friction_elements(network: AxialNetwork, friction: FrictionParameters) -> list[FrictionElement]:
    """Place R_f.ds and R_f.pp on the nodes of ``network`` (see :class:`FrictionParameters`)."""
    nodes = {n.name for n in network.nodes}
    ds_node = "edge" if "edge" in nodes else "pp"
    if "pp" not in nodes:
        raise ParameterError(f"{network.name}: friction needs a pressure plate node 'pp'")
    normal = "diaphragm" if any(e.name == "diaphragm" for e in network.elements) else None
    return [
        FrictionElement("R_f.ds", ds_node, coefficient=friction.diaphragm_coefficient, normal=normal,
                        static_ratio=friction.static_ratio, viscous=friction.diaphragm_viscous),
        FrictionElement("R_f.pp", "pp", coulomb=friction.pressure_plate_force, static_ratio=friction.static_ratio,
                        viscous=friction.pressure_plate_viscous),
    ]


def actuator_friction_elements(actuator: ActuatorParameters) -> list[FrictionElement]:
    """Seal and spindle friction of master cylinder and CSC.

    The spindle efficiency eta is represented as friction proportional to the
    axial load, ``(1/eta - 1) |p_m A_mc|``, which dissipates in both power
    directions (an efficiency factor on the motor force would create energy
    when the spindle is back-driven).
    """
    return [
        FrictionElement("master seal + spindle", "master", coulomb=actuator.master_seal_friction,
                        pressure_coefficient=actuator.load_friction * actuator.master_area, pressure="master",
                        static_ratio=1.2, viscous=5.0),
        FrictionElement("CSC seal", "bearing", coulomb=actuator.slave_seal_friction,
                        pressure_coefficient=actuator.seal_pressure_friction, pressure="slave", static_ratio=1.2,
                        viscous=5.0),
    ]


def pedal_reference(pedal, release_travel: float = 8e-3):
    """Bearing-position reference from the clutch-pedal signal of [1] Fig. 1 [m].

    Parameters
    ----------
    pedal : array_like
        Pedal position as a fraction 0 (released pedal: clutch engaged) to 1
        (pedal down: clutch released) [-].
    release_travel : float
        Bearing travel that fully releases the clutch [m].

    Raises
    ------
    ParameterError
        A pedal value that is not finite or lies outside 0..1.

    Notes
    -----
    A linear map, the simplest of the pedal-to-bearing maps an E-clutch
    controller uses; the controller then tracks this reference.
    """
    p = np.asarray(pedal, dtype=float)
    if np.any(~np.isfinite(p)):
        raise ParameterError("pedal signal contains NaN or infinite values")
    bad = np.flatnonzero((p < 0.0) | (p > 1.0))
    if bad.size:  # a pedal beyond its stops is a unit or scaling slip (percent?), never clipped silently
        raise ParameterError(f"pedal[{int(bad[0])}] = {float(p.ravel()[bad[0]])!r}: a pedal position must lie in 0..1")
    return p * release_travel


def apply_wear_and_expansion(model: ClutchModel, *, wear_m: float = 0.0, temperature_rise_k: float = 0.0,
                             expansion_coefficient: float = 12e-6, stack_height_m: float = 0.03) -> ClutchModel:
    """Shift the characteristics by facing wear and thermal expansion ([1] Sec. 7, future work iii).

    Facing wear ``w`` thins the friction plate, so at the same pressure-plate
    position the cushion spring is compressed ``w`` less; thermal expansion of
    pressure plate and flywheel (height ``h``, coefficient ``alpha``) thickens
    the stack by ``alpha dT h``.  The cushion pre-strain of the built model
    becomes ``prestrain - w + alpha dT h``; the bearing origin is *not*
    re-zeroed, so the static curves shift along the bearing position as they
    do on a worn or hot clutch.

    Parameters
    ----------
    model : ClutchModel
        The model to shift.
    wear_m : float
        Facing wear (both faces together) [m], >= 0.
    temperature_rise_k : float
        Temperature rise of pressure plate and flywheel over assembly [K].
    expansion_coefficient : float
        Linear thermal expansion coefficient [1/K] (cast iron ~ 1.2e-5).
    stack_height_m : float
        Axial height of the expanding stack [m].
    """
    for name, v in (("wear_m", wear_m), ("temperature_rise_k", temperature_rise_k),
                    ("expansion_coefficient", expansion_coefficient), ("stack_height_m", stack_height_m)):
        if not np.isfinite(v):
            raise ParameterError(f"apply_wear_and_expansion: {name} = {v!r} is not finite")
    if wear_m < 0:
        raise ParameterError(f"apply_wear_and_expansion: wear_m = {wear_m!r} m must be >= 0")
    net = model.network
    cushion = net.element(net.normal_force)
    shift = -wear_m + expansion_coefficient * temperature_rise_k * stack_height_m
    new = dataclasses.replace(cushion, prestrain=cushion.prestrain + shift)
    return dataclasses.replace(model, network=net.replace_element(cushion.name, new))


def actuator_test_rig(stiffness: float = 3.0e5, preload: float = 80.0, travel: float = 20e-3) -> ClutchModel:
    """The actuator test rig of [1] Fig. 3 ([2]): a linear load spring in place of the clutch.

    Parameters
    ----------
    stiffness : float
        Load spring rate [N/m].
    preload : float
        Load on the bearing at bearing position 0 [N] (equal to the CSC
        preload, so the actuator starts at rest).
    travel : float
        Span of the spring characteristic [m] (extrapolated linearly beyond).

    Returns
    -------
    ClutchModel
        A one-spring "clutch" whose bearing force is ``preload + stiffness * x``.
    """
    from ..curves import Curve
    from .network import Node

    if not (np.isfinite(stiffness) and stiffness > 0):
        raise ParameterError(f"actuator_test_rig: stiffness = {stiffness!r} N/m must be finite and > 0")
    if not (np.isfinite(preload) and preload >= 0):
        raise ParameterError(f"actuator_test_rig: preload = {preload!r} N must be finite and >= 0")
    spring = Curve.linear(stiffness, force_at_zero=preload, span=(-travel, travel), name="load spring")
    net = AxialNetwork((Node("bearing"), Node("pp", 1.0)),
                       (Spring("bearing", "bearing", spring, b="pp"),
                        Spring("cushion", "pp", Curve.linear(1e9, span=(-1e-3, 1e-3), name="rig frame"))),
                       input="bearing", normal_force="cushion", name="actuator test rig (load spring)")
    return ClutchModel(net, r_eff=0.1, mu=0.27)



# ---------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------


def _states_frame(result) -> pd.DataFrame:
    """The states of a run as a table (one float block)."""
    return pd.DataFrame(np.column_stack([np.asarray(result.time), np.asarray(result.states)]),
                        columns=["time_s", *result.state_columns])


def _outputs_frame(result, asm) -> pd.DataFrame:
    """The measured and derived quantities of a run as a table (one float block, bool flags appended)."""
    T = np.asarray(result.time)
    Y = np.asarray(result.states)
    nz = asm.nz
    b0 = 2 * nz
    col = result.__getitem__
    u = Y[:, 1]
    v_u = Y[:, nz + 1]
    names = ["time_s", "bearing_position_m", "bearing_velocity_m_s", "bearing_force_clutch_N", "normal_force_N",
             "torque_Nm"]
    cols = [T, u, v_u, col("bearing_force_clutch_N"), col("normal_force_N"), col("torque_Nm")]
    if not asm.prescribed:
        names += ["motor_voltage_V", "motor_current_A", "motor_speed_rpm", "master_position_m",
                  "master_pressure_Pa", "line_flow_m3_s", "pressure_Pa", "bearing_force_N"]
        # F_b = p A_sl, as the rig measures it ([1] Sec. 6)
        cols += [col("motor_voltage_V"), Y[:, b0 + 3], col("motor_speed_rpm"), Y[:, 0], Y[:, b0], Y[:, b0 + 1],
                 Y[:, b0 + 2], col("bearing_force_N")]
        if "reference_m" in result.output_columns:
            names.append("reference_m")
            cols.append(col("reference_m"))
    for k, node in enumerate(asm.asm["independent"]):
        names.append(f"x_{node}_m")
        cols.append(Y[:, 2 + k])
    M = np.asarray(result.modes)
    flags = {}
    for j in asm.friction_outputs:
        c = asm.coord_names[j]
        names.append(f"friction_{c}_N")
        cols.append(col(f"friction_{c}_N"))
        flags[f"stuck_{c}"] = M[:, j] == S.STUCK
    outputs = pd.DataFrame(np.column_stack(cols), columns=names)
    if flags:
        outputs = pd.concat([outputs, pd.DataFrame(flags)], axis=1)
    return outputs


def _events_frame(result, asm) -> pd.DataFrame:
    """The located events of a run with readable labels and places."""
    ev = result.events
    kinds = ev["event"].tolist()
    elements = ev["element"].tolist()
    where = []
    for name, element in zip(kinds, elements):
        if name in ("stick", "breakaway", "slip_reversal", "friction_free", "friction_engage"):
            where.append(f"{element} ({asm.friction_names[asm.coord_names.index(element)]})")
        else:
            where.append(_STOPS.get(element, _CHAMBERS.get(element, element)))
    return pd.DataFrame({"time_s": ev["time_s"].to_numpy(float), "event": kinds, "element": elements,
                         "description": [_LABELS.get(n, n) for n in kinds], "where": where})


def _curve_energy(curve, scale, unilateral, d_values, d_ref):
    """Elastic energy ``int_{d_ref}^{d} max?(scale*curve)`` [J] (fine trapezoid on the interpolant)."""
    d_values = np.asarray(d_values, dtype=float)
    lo = min(d_values.min(), d_ref)
    hi = max(d_values.max(), d_ref)
    if hi - lo < 1e-15:
        return np.zeros_like(d_values)
    x = np.linspace(lo, hi, 40001)
    fx = scale * curve(x)
    if unilateral:
        fx = np.maximum(fx, 0.0)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (fx[1:] + fx[:-1]) * np.diff(x))])
    return np.interp(d_values, x, cum) - np.interp(d_ref, x, cum)


@dataclasses.dataclass(repr=False, kw_only=True)
class DynamicsResult(SimulationResult):
    """Result of an E-clutch simulation: the :class:`~clutchlab.SimulationResult` of the ``eclutch`` (or
    ``eclutch_prescribed``) model with the rig's tables and the energy bookkeeping.

    Every field of a :class:`~clutchlab.SimulationResult` is the core's run (``states``, ``outputs`` and ``modes``
    arrays with their unit-suffixed columns, ``stats`` with the run's ``status`` added); ``events`` adds to its
    ``time_s``, ``event`` (:data:`clutchlab.eclutch.system.EVENTS`: ``stick``, ``breakaway``, ``contact_open``, ...)
    and ``element`` the ``description`` (:data:`EVENT_KINDS`: "contact opens", ...) and ``where`` (coordinate and
    friction element, end stop or chamber).  ``result["bearing_position_m"]`` reads a column of the run or of
    its tables.

    Attributes
    ----------
    outputs_table : pandas.DataFrame
        Measured and derived quantities (``time_s``, ``bearing_position_m``, ``pressure_Pa``,
        ``bearing_force_N``, ``x_<node>_m``, ``friction_<coordinate>_N``, ``stuck_<coordinate>``, ...).
    states_table : pandas.DataFrame
        ``time_s`` and the states (positions, velocities, pressures, current, controller integral, energies).
    energy_source : callable or DataFrame, optional
        What :attr:`energy` returns: energy bookkeeping per recorded point [J]: ``input_work_J``,
        ``dissipated_J``, ``friction_dissipated_J`` (integrated with the
        states) and ``stored_J`` (computed from the states).
    """

    outputs_table: pd.DataFrame = BuiltOnFirstAccess()
    states_table: pd.DataFrame = BuiltOnFirstAccess()
    energy_source: object = dataclasses.field(default=None, repr=False)

    def __getstate__(self):
        # the tables are built on first access (:meth:`from_result`): build them before pickling, so the
        # state holds no callable
        self.states_table, self.outputs_table, self.energy  # noqa: B018
        return super().__getstate__()

    @classmethod
    def from_result(cls, result: SimulationResult, source) -> "DynamicsResult":
        """The E-clutch result of a run of ``source`` (an :class:`EClutch` or a :class:`ClutchDynamics`).

        Parameters
        ----------
        result : SimulationResult
            What :func:`clutchlab.system.simulate` returned for ``source.as_system(...)``.
        source : EClutch or ClutchDynamics
            The model that was simulated (names, masses and curves for the energy bookkeeping).
        """
        asm = source.assembly
        Y = np.asarray(result.states)
        nz = asm.nz
        kw = SimulationResult.fields_of(result)
        kw["events"] = lambda: _events_frame(result, asm)
        kw["stats"] = {**result.stats, "status": int(result.status)}
        # the tables are built when first read (pandas costs about 0.6 ms per run, as much as a fifth of a
        # 1 s run: a Monte Carlo loop that reads a few columns, or none, does not pay for them)
        return cls(**kw, outputs_table=lambda: _outputs_frame(result, asm), states_table=lambda: _states_frame(result),
                   energy_source=lambda: _energy(asm, Y, Y[:, 1], Y[:, nz + 1]))

    @property
    def result(self) -> "DynamicsResult":
        """The run itself (a :class:`DynamicsResult` is a :class:`~clutchlab.SimulationResult`; kept for code that
        read the run from here)."""
        return self

    def _column(self, name: str):
        if name in self.state_columns or name in self.output_columns:
            return super()._column(name)
        for table in (self.outputs_table, self.states_table):
            if name in table.columns:
                return table[name].to_numpy()
        return super()._column(name)

    @property
    def energy(self) -> pd.DataFrame | None:
        """Energy bookkeeping (computed on first use; see the class documentation)."""
        src = self.energy_source
        if callable(src):
            self.energy_source = src()
        return self.energy_source

    def to_dataframe(self) -> pd.DataFrame:
        """One table of time, every state and every output (SI units in the column names)."""
        extra = [c for c in self.states_table.columns if c not in self.outputs_table.columns]
        return pd.concat([self.outputs_table, self.states_table[extra]], axis=1)

    def energy_balance(self) -> dict:
        """Input work, dissipated energy and change of stored energy over the run [J].

        ``residual = input - dissipated - stored_change``; ``relative`` divides
        it by the input work.
        """
        if self.energy is None:
            raise SimulationError("this result has no energy bookkeeping")
        e = self.energy
        w_in = float(e["input_work_J"].iloc[-1] - e["input_work_J"].iloc[0])
        diss = float(e["dissipated_J"].iloc[-1] - e["dissipated_J"].iloc[0])
        stored = float(e["stored_J"].iloc[-1] - e["stored_J"].iloc[0])
        res = w_in - diss - stored
        return {"input_J": w_in, "dissipated_J": diss, "stored_change_J": stored, "residual_J": res,
                "relative": res / w_in if w_in else np.nan,
                "friction_dissipated_J": float(e["friction_dissipated_J"].iloc[-1] - e["friction_dissipated_J"].iloc[0])}


def _energy(asm: "S.Assembly", Y, u, v_u) -> pd.DataFrame:
    """Stored energy from the states (independent of the integrator's bookkeeping)."""
    nz = asm.nz
    b0 = 2 * nz
    a = asm.actuator or ActuatorParameters()
    kin = 0.5 * (Y[:, nz: 2 * nz] ** 2 * asm.mass[None, :])
    if asm.prescribed:
        kin[:, :2] = 0.0
    stored = kin.sum(axis=1)
    # elastic energy of the network elements
    q = Y[:, 2: nz]
    D = asm.asm["d0"][None, :] + q @ asm.asm["GA"].T + np.outer(u, asm.asm["Gb"])
    net = asm.model.network
    for e, name in enumerate(asm.element_names):
        elm = net.element(name)
        if isinstance(elm, Lever):
            curve, scl, uni = elm.curve(), 1.0, False
        else:
            curve, scl, uni = elm.curve, elm.scale, elm.unilateral
        stored = stored + _curve_energy(curve, scl, uni, D[:, e], D[0, e])
    if not asm.prescribed:
        def cap(p, c):
            pc = a.vapour_pressure
            below = p < pc
            e = 0.5 * p ** 2 * c
            # below the vapour pressure the compliance is 1000 x larger (actuator.cavitating_compliance)
            e_b = 0.5 * pc ** 2 * c + 0.5 * (p ** 2 - pc ** 2) * c * 1e3
            return np.where(below, e_b, e)
        stored = stored + 0.5 * a.inductance * Y[:, b0 + 3] ** 2
        stored = stored + cap(Y[:, b0], a.master_compliance) + cap(Y[:, b0 + 2], a.slave_compliance)
        stored = stored + 0.5 * a.line_inertance * Y[:, b0 + 1] ** 2
        # CSC preload spring: force F_pre - k_pre u on the piston
        stored = stored - (a.csc_preload * u - 0.5 * a.csc_spring_rate * u ** 2)
        # end stops
        ks = a.stop_stiffness
        for pen in (-Y[:, 0], Y[:, 0] - a.master_stroke, a.slave_min - u, u - a.slave_max):
            stored = stored + 0.5 * ks * np.maximum(pen, 0.0) ** 2
    return pd.DataFrame({"input_work_J": Y[:, b0 + 5], "dissipated_J": Y[:, b0 + 6],
                         "friction_dissipated_J": Y[:, b0 + 7], "stored_J": stored})


def _as_table(value, name: str):
    """``(times, values)`` from a scalar, a pair of sequences, a DataFrame or a mapping."""
    if np.isscalar(value):
        v = float(value)
        if not np.isfinite(v):
            raise ParameterError(f"input {name!r} = {value!r} is not finite")
        return np.array([0.0]), np.array([v])
    if isinstance(value, pd.DataFrame):
        cols = list(value.columns)
        if len(cols) != 2:
            raise ParameterError(f"input {name!r}: expected two columns (time_s and values), got {cols}")
        t, v = value.iloc[:, 0].to_numpy(float), value.iloc[:, 1].to_numpy(float)
    elif isinstance(value, Mapping):
        if set(value) != {"time_s", "value"}:
            raise ParameterError(f"input {name!r}: mapping needs keys 'time_s' and 'value', got {sorted(value)}")
        t, v = np.asarray(value["time_s"], float), np.asarray(value["value"], float)
    else:
        try:
            t, v = (np.asarray(x, dtype=float) for x in value)
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"input {name!r}: expected (times, values), got {type(value).__name__}") from exc
    if t.ndim != 1 or v.shape != t.shape or t.size == 0:
        raise ParameterError(f"input {name!r}: times and values must be 1-D and of equal length")
    if t.size <= 64:
        # a short table (a pedal profile): checked with Python floats, several times faster than NumPy's
        # reductions on a few elements; anything wrong goes to the NumPy checks below for the message
        tl, vl = t.tolist(), v.tolist()
        if all(math.isfinite(a) and math.isfinite(b) for a, b in zip(tl, vl)) and \
                all(b > a for a, b in zip(tl, tl[1:])) and not tl[0] > 0:
            return np.ascontiguousarray(t), np.ascontiguousarray(v)
    bad = ~(np.isfinite(t) & np.isfinite(v))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ParameterError(f"input {name!r}: row {i} (time {short_repr(t[i])} s, value {short_repr(v[i])}) is not finite")
    if t.size > 1 and np.any(np.diff(t) <= 0):
        i = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
        raise ParameterError(f"input {name!r}: times must increase strictly (row {i}: {short_repr(t[i])} s after {short_repr(t[i - 1])} s)")
    if t[0] > 0:
        t = np.concatenate([[0.0], t])
        v = np.concatenate([[v[0]], v])
    return np.ascontiguousarray(t), np.ascontiguousarray(v)


def _follow_rtol(rtol, atol_scale, default_rtol=1e-3):
    """The absolute tolerances' factor of a closed-loop E-clutch run: ``atol_scale`` where given, else
    ``min(1, rtol / default_rtol)`` (the defaults at the default tolerance, shrinking with a tighter one: the
    accuracy follows ``rtol``, issue #30)."""
    return float(atol_scale) if atol_scale is not None else contract.follow_rtol(1.0, rtol, default_rtol)


def _check_run(t_end, rtol, max_steps, atol=None, atol_scale=None):
    if not (np.isfinite(t_end) and t_end > 0):
        raise ParameterError(f"t_end = {t_end!r} s must be finite and > 0")
    contract.check_rtol(rtol)
    if atol is not None and atol_scale is not None:
        raise ParameterError("atol and atol_scale: give one of them (atol sets the absolute tolerances, atol_scale "
                             "scales the defaults)")
    if int(max_steps) < 10:
        raise ParameterError(f"max_steps = {max_steps!r} must be >= 10")


def _grid(output_step, t_end):
    if output_step is None:
        return np.empty(0)
    if not (np.isfinite(output_step) and 0 < output_step <= t_end):
        raise ParameterError(f"output_step = {output_step!r} s must be in (0, t_end]")
    check_allocation(t_end / output_step + 1, 1, f"output_step = {output_step!r} s over t_end = {t_end!r} s")
    n = int(np.floor(t_end / output_step + 1e-9)) + 1
    return np.arange(n) * output_step


def _max_step(max_step, h_max):
    """The largest step [s]: ``max_step`` (the uniform name) or its alias ``h_max``."""
    if max_step is not None and h_max is not None and float(max_step) != float(h_max):
        raise ParameterError(f"max_step = {max_step!r} and h_max = {h_max!r}: give one (h_max is the old name)")
    value = max_step if max_step is not None else h_max
    value = 0.01 if value is None else float(value)
    if not (np.isfinite(value) and value > 0):
        raise ParameterError(f"max_step = {value!r} s must be finite and > 0")
    return value


def _run(source, system: contract.System, t_end: float, max_steps: int, grid, fixed_step=None,
         atol=None) -> DynamicsResult:
    # without a grid every accepted step is kept, in chunks that grow with the run (not max_steps rows up front)
    res = contract.simulate(system, t_end, atol=atol, max_steps=int(max_steps),
                            sample_times=grid if grid.size else None, fixed_step=fixed_step)
    return DynamicsResult.from_result(res, source)


class ClutchDynamics:
    """Clutch axial dynamics driven by a prescribed bearing motion.

    Parameters
    ----------
    model : ClutchModel
        Axial Model 0-4 (:meth:`ClutchModel.preset`) or a variant.
    friction : FrictionParameters or list of FrictionElement, optional
        Friction elements (default :meth:`FrictionParameters.off`).

    Notes
    -----
    The bearing position is imposed (a stiff rig drive); the clutch's masses
    m_pp, m_pps, m_ds move under the element forces and friction, massless
    nodes are in equilibrium at every instant.  With friction off and a slow
    ramp the bearing force reproduces the static curve of
    :meth:`ClutchModel.static_curve`; with friction on it traces a hysteresis
    loop whose area is the energy the friction elements dissipate.
    """

    def __init__(self, model: ClutchModel, friction=None):
        friction = FrictionParameters.off() if friction is None else friction
        if isinstance(friction, FrictionParameters):
            friction = clutch_friction_elements(model.network, friction)
        self.model = model
        #: the packed structure (:class:`clutchlab.eclutch.system.Assembly`)
        self.assembly = S.Assembly(model, None, list(friction), prescribed=True)

    def as_system(self, bearing_position, *, rtol: float = 1e-5, max_step: float = 0.01, event_tol: float = 1e-9,
                  jac_every: int = 4, atol_scale: float | None = None) -> contract.System:
        """The :class:`~clutchlab.system.System` of a run with the bearing position prescribed.

        Parameters
        ----------
        bearing_position : table
            ``(times [s], positions [m])``, linear in between (see :meth:`simulate`).
        rtol, max_step, event_tol, jac_every, atol_scale
            Defaults of the run, as in :meth:`simulate`.
        """
        tin, vin = _as_table(bearing_position, "bearing_position")
        atol_scale = _follow_rtol(rtol, atol_scale, 1e-5)   # (below its default rtol the atol follow it)
        return self.assembly.system(S.PRESCRIBED, tin, vin, 0, float(vin[0]), rtol=rtol, max_step=max_step,
                                    event_tol=event_tol, jac_every=jac_every, atol_scale=atol_scale)

    def simulate(self, bearing_position, t_end: float | None = None, *, rtol: float = 1e-5, atol=None,
                 max_step: float | None = None, h_max: float | None = None, max_steps: int = 500_000,
                 output_step: float | None = None, event_tol: float = 1e-9, jac_every: int = 4,
                 atol_scale: float | None = None, fixed_step: float | None = None) -> DynamicsResult:
        """Simulate with the bearing position prescribed as ``(times [s], positions [m])`` (linear in between).

        Tolerances: ``rtol`` and the default absolute tolerances (10 nm, 10 um/s, 10 Pa, ...) times
        ``atol_scale`` (default ``min(1, rtol / 1e-5)``: below the default rtol they shrink with it, so the error
        follows the tolerance -- with friction, fixed absolute tolerances held the pressure plate's stick-slip
        phase, and the bearing force, at 2.6 % of peak from rtol 1e-5 to 1e-8, issue #30), or ``atol``: absolute
        tolerances given outright (one for every state or one per state, in the states' units: positions [m],
        velocities [m/s], energies [J]; one of ``atol`` and ``atol_scale``); ``bearing_position``, ``t_end``,
        ``max_step`` (alias ``h_max``), ``max_steps``, ``output_step``, ``event_tol``, ``jac_every`` and
        ``fixed_step`` as in :meth:`EClutch.simulate`.
        """
        tin, _vin = _as_table(bearing_position, "bearing_position")
        t_end = float(tin[-1]) if t_end is None else float(t_end)
        _check_run(t_end, rtol, max_steps, atol, atol_scale)
        grid = _grid(output_step, t_end)  # refused before anything is built
        system = self.as_system(bearing_position, rtol=rtol, max_step=_max_step(max_step, h_max),
                                event_tol=event_tol, jac_every=jac_every, atol_scale=atol_scale)
        return _run(self, system, t_end, max_steps, grid, fixed_step, atol)


class EClutch:
    """The E-clutch: electro-hydrostatic actuator coupled to a clutch axial model.

    Parameters
    ----------
    actuator : ActuatorParameters
        Motor, spindle, master cylinder, line and CSC ([1] Sec. 2.1).
    clutch : ClutchModel
        Axial Model 0-4 or a variant; its bearing element is the release
        bearing stiffness k_b coupling the CSC to the clutch ([1] Sec. 3.2).
    friction : FrictionParameters or list of FrictionElement, optional
        Clutch friction elements (default :meth:`FrictionParameters.off`).
        The actuator's seal and spindle friction are always included
        (:func:`actuator_friction_elements`).
    """

    def __init__(self, actuator: ActuatorParameters | None = None, clutch: ClutchModel | None = None, friction=None):
        self.actuator = actuator or ActuatorParameters()
        if not isinstance(self.actuator, ActuatorParameters):
            raise ParameterError(f"actuator must be ActuatorParameters, got {type(self.actuator).__name__}")
        self.clutch = clutch or ClutchModel.preset(4)
        friction = FrictionParameters.off() if friction is None else friction
        if isinstance(friction, FrictionParameters):
            friction = clutch_friction_elements(self.clutch.network, friction)
        self.friction = list(friction) + actuator_friction_elements(self.actuator)
        #: the packed structure (:class:`clutchlab.eclutch.system.Assembly`)
        self.assembly = S.Assembly(self.clutch, self.actuator, self.friction, prescribed=False)
        #: bearing position at rest [m] (0 unless offsets or the preload move it)
        self.rest_position = self.assembly.rest_position()

    def as_system(self, inputs, *, rtol: float = 1e-3, max_step: float = 0.01, event_tol: float = 1e-8,
                  jac_every: int = 10, atol_scale: float | None = None, held_input: bool = False,
                  first_step: float = 1e-5, at_start: bool = False) -> contract.System:
        """The :class:`~clutchlab.system.System` of a run from rest (for :func:`clutchlab.system.simulate`).

        Parameters
        ----------
        inputs : dict
            As in :meth:`simulate`.
        rtol, max_step, event_tol, jac_every, atol_scale
            Defaults of the run, as in :meth:`simulate`.
        held_input : bool
            The input is the system's held input (``motor_voltage`` [V] or ``bearing_reference`` [m],
            set by :meth:`clutchlab.system.Simulation.advance`) instead of the table; it starts at the
            table's first value (co-simulation).
        first_step : float
            First trial step [s].
        at_start : bool
            The run's start derives the clutch's pre-deflections and its state at rest again from the packed
            parameters (a co-simulation, whose host may set them: :func:`clutchlab.eclutch.system.eclutch_start`).
        """
        imode, interp, key, value = _input_mode(inputs)
        tin, vin = _as_table(value, key)
        self._check_reference(key, vin)
        return self._system(imode, interp, tin, vin, held_input=held_input, rtol=rtol, max_step=max_step,
                            event_tol=event_tol, jac_every=jac_every, atol_scale=_follow_rtol(rtol, atol_scale),
                            first_step=first_step, at_start=at_start)

    def _check_reference(self, key: str, values) -> None:
        """A bearing reference inside the CSC travel (the actuator's end stops; #33: 50 mm was taken)."""
        if key != "bearing_reference":
            return
        lo, hi = self.actuator.slave_min, self.actuator.slave_max
        bad = np.flatnonzero((values < lo) | (values > hi))
        if bad.size:
            raise ParameterError(f"input 'bearing_reference' = {float(values[bad[0]]):g} m is outside the CSC travel "
                                 f"[{lo:g}, {hi:g}] m (ActuatorParameters.slave_min, slave_max)")

    def _system(self, imode, interp, tin, vin, **options) -> contract.System:
        """:meth:`as_system` of a checked input table."""
        return self.assembly.system(imode, tin, vin, interp, self.rest_position, **options)

    def operating_point(self, bearing_position: float, *, input: str = "voltage", friction: str = "slip_forward",
                        settle: float = 0.5):
        """Steady state holding the release bearing at ``bearing_position`` (for linear models and control design).

        The actuator is first run under its own position controller (``settle`` seconds towards the
        position, the start of Newton's method), then trimmed by
        :func:`clutchlab.control.operating_point` within one friction mode.

        Parameters
        ----------
        bearing_position : float or str
            Bearing position [m] (or a quantity string such as ``"4 mm"``), inside the CSC travel (``ActuatorParameters.slave_min`` ... ``slave_max``).
        input : {"voltage", "bearing_reference"}
            The held input of the system trimmed: the motor voltage (open loop; the voltage is solved for)
            or the position controller's reference (closed loop; all states steady, the integral action
            included).
        friction : {"slip_forward", "slip_backward"}
            Mode of every coordinate with a friction element (seals, spindle, clutch friction): the
            direction the bearing last moved in. Coulomb friction is then a constant force and only its
            viscous part enters the linear model (a stuck element leaves the steady state undetermined).
        settle : float
            Time [s] of the position-controlled run that gives Newton's method its start.

        Returns
        -------
        clutchlab.control.OperatingPoint
            ``op.system`` is the system with the held input (``motor_voltage`` [V] or ``bearing_reference``
            [m]).

        Raises
        ------
        clutchlab.control.OperatingPointError
            A position outside the travel; a voltage beyond the supply; no convergence.
        """
        from ..trim import OperatingPointError, operating_point

        if input not in ("voltage", "bearing_reference"):
            raise ParameterError(f"input = {input!r}: expected 'voltage' or 'bearing_reference'")
        if friction not in ("slip_forward", "slip_backward"):
            raise ParameterError(f"friction = {friction!r}: expected 'slip_forward' or 'slip_backward'")
        from ..units import to_si

        pos = to_si(bearing_position, "m", name="bearing_position")   # (a number [m], or a quantity: "4 mm")
        lo, hi = self.actuator.slave_min, self.actuator.slave_max
        if not lo <= pos <= hi:
            raise OperatingPointError(f"eclutch: bearing_position = {pos:.6g} m is outside the CSC travel "
                                      f"[{lo:.6g}, {hi:.6g}] m")
        closed = self.as_system({"bearing_reference": pos}, held_input=True)
        run = contract.Simulation(closed)
        run.advance(float(settle))
        modes = {name: friction for name, value in zip(closed.mode_names, closed.m0)
                 if name.startswith("friction_mode_") and value != S.MODE_VALUES.index("free")}
        if input == "bearing_reference":
            return operating_point(closed, inputs={"bearing_reference": pos}, modes=modes, guess=run.x)
        voltage = float(run.outputs()[closed.output_index("motor_voltage")])
        system = self.as_system({"voltage": voltage}, held_input=True)
        return operating_point(system, inputs={"motor_voltage": voltage}, targets={"bearing_position": pos},
                               free_inputs=["motor_voltage"], modes=modes, guess=run.x)

    def simulate(self, inputs, t_end: float, *, rtol: float = 1e-3, atol=None, max_step: float | None = None,
                 h_max: float | None = None, max_steps: int = 500_000, output_step: float | None = None,
                 event_tol: float = 1e-8, jac_every: int = 10, atol_scale: float | None = None,
                 fixed_step: float | None = None) -> DynamicsResult:
        """Simulate from rest (clutch engaged, actuator at its rest stop).

        Parameters
        ----------
        inputs : dict
            Exactly one of ``{"voltage": table}`` (motor voltage [V], held
            between samples) or ``{"bearing_reference": table}`` (bearing
            position reference [m], linear between samples, tracked by the
            position controller); a table is ``(times [s], values)``, a
            two-column DataFrame or a scalar (constant).
        t_end : float
            End time [s].
        rtol : float
            Relative tolerance of the Rodas3 integrator.
        max_step : float
            Largest step [s] (default 0.01).
        h_max : float
            Old name of ``max_step`` (either may be given).
        max_steps : int
            Accepted-step budget.
        output_step : float, optional
            Record on a uniform grid (dense output of the steps); default:
            every accepted step.
        event_tol : float
            Time tolerance of event location [s].
        jac_every : int
            Reuse the finite-difference Jacobian for up to this many accepted
            steps (it is refreshed after every event and every rejected step).
        atol : float or array_like, optional
            Absolute tolerances given outright: one for every state or one
            per state, in the states' units (positions [m], velocities [m/s],
            pressures [Pa], current [A], energies [J]); one of ``atol`` and
            ``atol_scale``.
        atol_scale : float, optional
            Factor on the default absolute tolerances (0.1 um, 0.1 mm/s,
            100 Pa, 1 mA, ...); default ``min(1, rtol / 1e-3)``: below the
            default ``rtol`` they shrink with it, so that the error follows
            the tolerance (with them fixed, the bearing's velocity after its
            break-away stayed 3.5e-4 off an independent solution from rtol
            1e-10 down, issue #30; docs/eclutch_dynamics.md).
        fixed_step : float, optional
            Fixed-step (real-time, HIL frame) mode with this step [s]: Rodas3
            steps on the grid ``k * fixed_step``, no error control, the
            Jacobian every step, mode changes (stick, slip, stops) at the
            first step end after them (:func:`clutchlab.system.simulate`;
            ``rtol``, ``max_step``, ``event_tol`` and ``jac_every`` are then
            unused).  None (default): step-size control.

        Returns
        -------
        DynamicsResult
            States, outputs (motor current, piston position, pressure, bearing
            position, ``bearing_force_N = p A_sl``, clutch forces, torque),
            events and statistics; ``.result`` is the :class:`~clutchlab.SimulationResult`.
        """
        t_end = float(t_end)
        imode, interp, key, value = _input_mode(inputs)
        tin, vin = _as_table(value, key)
        self._check_reference(key, vin)
        _check_run(t_end, rtol, max_steps, atol, atol_scale)
        grid = _grid(output_step, t_end)  # refused before anything is built
        system = self._system(imode, interp, tin, vin, rtol=rtol, max_step=_max_step(max_step, h_max),
                              event_tol=event_tol, jac_every=jac_every, atol_scale=_follow_rtol(rtol, atol_scale))
        return _run(self, system, t_end, max_steps, grid, fixed_step, atol)


def _input_mode(inputs):
    if not isinstance(inputs, Mapping) or len(inputs) != 1:
        raise ParameterError("inputs must be a mapping with exactly one of 'voltage' or 'bearing_reference'")
    (key, value), = inputs.items()
    if key == "voltage":
        return S.VOLTAGE, 1, key, value
    if key == "bearing_reference":
        return S.POSITION, 0, key, value
    raise ParameterError(f"unknown input {key!r}; use 'voltage' [V] or 'bearing_reference' [m]")


@dataclasses.dataclass
class BatchResult:
    """Results of :func:`simulate_batch` on a common time grid.

    Attributes
    ----------
    time : ndarray
        Output grid [s].
    outputs : dict of str to ndarray
        ``(n_variants, n_times)`` arrays: ``bearing_position_m``, ``bearing_force_N`` (``p A_sl``),
        ``pressure_Pa``, ``master_pressure_Pa``, ``motor_current_A``, ``motor_voltage_V``,
        ``master_position_m``, ``normal_force_N``, ``torque_Nm``, ``input_work_J``, ``dissipated_J``,
        ``friction_dissipated_J`` (and ``reference_m`` under position control).
    stats : pandas.DataFrame
        Accepted/rejected steps, right-hand sides, Jacobians, status and event count per variant.
    result : SimulationResult, optional
        The stacked batch as the integrator core returned it.
    """

    time: np.ndarray
    outputs: dict
    stats: pd.DataFrame
    result: object = dataclasses.field(default=None, repr=False)

    def to_dataframe(self, variant: int) -> pd.DataFrame:
        """The outputs of one variant as a table.

        Parameters
        ----------
        variant : int
            Index of the variant (order of the ``eclutches`` given to :func:`simulate_batch`).
        """
        data = {"time_s": self.time}
        data.update({k: v[variant] for k, v in self.outputs.items()})
        return pd.DataFrame(data)


def simulate_batch(eclutches, inputs, t_end: float, *, output_step: float = 1e-3, rtol: float = 1e-3,
                   max_step: float | None = None, h_max: float | None = None, max_steps: int = 500_000,
                   event_tol: float = 1e-8, jac_every: int = 10, chunk: int = 32) -> BatchResult:
    """Simulate many E-clutch variants in parallel, one Rodas3 solver per variant (numba ``prange``).

    A thin wrapper of :func:`clutchlab.system.simulate_batch` over the variants' systems
    (:meth:`EClutch.as_system`).

    Parameters
    ----------
    eclutches : sequence or iterator of EClutch
        The variants, e.g. a sweep of lever ratio and stiffness scales.  They
        must share the model structure (same coordinates, elements and friction
        placement); parameters, masses, lever ratios, pre-strains, stiffness
        scales, component curves and actuator parameters may differ.  Pass a
        generator that builds them (``(EClutch(...) for r in ratios)``) and the
        building overlaps the runs: each chunk of up to ``chunk`` variants runs
        on all cores but one while the next is built; the rest run together on
        all cores once the last is built.
    inputs : dict
        As in :meth:`EClutch.simulate` (one input for every variant).
    t_end, output_step : float
        End time and output grid step [s].
    rtol, max_step, h_max, max_steps, event_tol, jac_every
        As in :meth:`EClutch.simulate`.
    chunk : int
        Variants per chunk when ``eclutches`` is an iterator (at most; default 32).

    Returns
    -------
    BatchResult
    """
    t_end = float(t_end)
    _check_run(t_end, rtol, max_steps)
    grid = _grid(output_step, t_end)
    h = _max_step(max_step, h_max)
    sig = []

    def systems():
        for k, ec in enumerate(eclutches):
            if not isinstance(ec, EClutch):
                raise ParameterError(f"simulate_batch: variant {k} is a {type(ec).__name__}, not an EClutch")
            if not sig:
                sig.append(ec.assembly.signature())
            elif ec.assembly.signature() != sig[0]:
                raise ParameterError(f"simulate_batch: variant {k} has another model structure than variant 0 "
                                     "(coordinates, elements and friction placement must be shared)")
            yield ec.as_system(inputs, rtol=rtol, max_step=h, event_tol=event_tol, jac_every=jac_every)

    # a sequence is checked and stacked at once; an iterator is built chunk by chunk while the chunks
    # before it run (clutchlab.system.simulate_batch)
    source = list(systems()) if hasattr(eclutches, "__len__") else systems()
    res = contract.simulate_batch(source, t_end, sample_times=grid, max_steps=int(max_steps), check=False,
                                  chunk=chunk)
    keys = ["bearing_position_m", "bearing_velocity_m_s", "pressure_Pa", "master_pressure_Pa", "bearing_force_N",
            "bearing_force_clutch_N", "motor_current_A", "motor_voltage_V", "master_position_m", "normal_force_N",
            "torque_Nm", "input_work_J", "dissipated_J", "friction_dissipated_J"]
    if "reference_m" in res.output_columns:
        keys.append("reference_m")
    out = {k: res[k] for k in keys}
    nv = res.states.shape[0]
    counts = res.events["variant"].value_counts() if len(res.events) else pd.Series(dtype=int)
    stats = pd.DataFrame({
        "accepted_steps": res.stats["accepted_steps"], "rejected_steps": res.stats["rejected_steps"],
        "rhs_evaluations": res.stats["rhs_evaluations"],
        "jacobians": res.stats["jacobians"],
        "status": np.asarray(res.status, dtype=np.int64),
        "events": [int(counts.get(v, 0)) for v in range(nv)]})
    return BatchResult(grid, out, stats, res)
