"""AWD vehicle with the EMTC on a drum test bench ([1], Secs. 3.1 and 4).

Parameter sets (frozen, unit-annotated, TOML load/save), the torque reference
map of Eq. 31, and :func:`simulate_bench`, a thin layer over the model of
:mod:`clutchlab.emtc.system` (run by the integrator core) that returns the
per-sample view :class:`BenchResult` of a :class:`clutchlab.SimulationResult`.

Schematic (coupling shaft side, speeds at the coupling)::

    T_trans*i0 --> [front axle + wheels J_wf] --(i_f)--> omega_f [J_sf] ==EMTC==> omega_r [J_sr] --(i_r)--> [rear axle J_wr]
                          |  tyre force on drum                         T_c                                 | tyre force on drum
                    front drums (speed v_df)                                                          rear drums (speed v_dr)

References
----------
.. [1] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557,
   doi:10.3390/pr7090557
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from .._limits import check_allocation, short_repr
from ..errors import ParameterError
from ..params import ParameterSet, quantity
from ..params.base import load_toml
from ._lookup import bilinear
from .friction import drag_torque
from .torque import LOCKED_CASE_NAMES, CouplingGeometry

__all__ = [
    "ActuatorParameters",
    "VehicleParameters",
    "BenchScenario",
    "TorqueMap",
    "BenchResult",
    "simulate_bench",
    "load_scenario",
    "EVENT_NAMES",
    "EVENT_KEYS",
    "MODE_NAMES",
    "ARMATURE_MODE_NAMES",
    "COLUMN_NAMES",
]

#: event codes (``kind``) of :attr:`BenchResult.events`: the index of the event in :data:`EVENT_KEYS`
_EVENTS = ("armature_rest", "armature_contact", "armature_leave_rest", "armature_leave_contact", "lockup",
           "slip_reversal", "unlock")
_DESCRIPTIONS = ("armature at rest stop", "armature contacts primary clutch (engaged)", "armature leaves rest stop",
                 "armature leaves primary clutch (open)", "lock-up (slip speed zero, capacity covers T_lock)",
                 "slip reversal (capacity below T_lock)", "unlock (|T_lock| > 1.02 T_cap)")
EVENT_NAMES = dict(enumerate(_DESCRIPTIONS))
#: short name of each event kind, as in the ``event`` column of :attr:`BenchResult.events`
EVENT_KEYS = dict(enumerate(_EVENTS))
MODE_NAMES = {0: "open", 1: "slipping", 2: "locked"}
#: armature modes of the kernel: at the rest stop, free, pressing the primary clutch
ARMATURE_MODE_NAMES = {0: "rest", 1: "free", 2: "contact"}

#: kernel names of :attr:`BenchResult.states` / :attr:`BenchResult.outputs` -> columns of
#: :meth:`BenchResult.to_dataframe` (docs/nomenclature.md, "EMTC drum-bench results")
COLUMN_NAMES = {
    "time": "time_s",
    "omega_f": "omega_f_rad_s", "omega_r": "omega_r_rad_s", "theta": "theta_rad",
    "x": "x_armature_m", "xdot": "v_armature_m_s", "i1": "i1_A", "i2": "i2_A",
    "magnet_force": "magnet_force_N", "fn1": "fn1_N", "t1": "t1_Nm", "t2": "t2_Nm", "t3": "t3_Nm",
    "t_coupling": "coupling_torque_Nm", "t_lock_eq29": "lock_torque_Nm", "t_trans": "transmission_torque_Nm",
    "capacity_locked": "capacity_locked_Nm", "locked_case": "locked_case", "fn2": "fn2_N",
    "engine_torque": "engine_torque_Nm", "armature_mode": "armature_mode", "coupling_mode": "coupling_mode",
    "current_command": "current_command_A", "torque_reference": "torque_reference_Nm", "throttle": "throttle_1",
    "command_feasible": "command_feasible", "slip_speed": "slip_speed_rad_s", "airgap": "airgap_m",
}


@dataclasses.dataclass(frozen=True)
class ActuatorParameters(ParameterSet):
    """Electromagnetic actuator: armature, return spring and coil current control ([1], Eqs. 8-12, Fig. 15).

    Values are representative (clutchlab's choice; the paper gives none).
    """

    kind = "actuator"

    mass: float = quantity(0.15, "kg", "armature mass m0 (Eq. 8)", source="representative", positive=True)
    stiffness: float = quantity(4.0e4, "N/m", "return spring stiffness K_spring (Eq. 9)", source="representative", positive=True)
    preload: float = quantity(50.0, "N", "spring preload F_k0 (Eq. 9)", source="representative", nonnegative=True)
    damping: float = quantity(100.0, "N*s/m", "spring damping c_spring (Eq. 8)", source="representative", nonnegative=True)
    free_travel: float = quantity(0.5e-3, "m", "free travel sigma of the primary clutch (Eq. 9)", source="representative", positive=True)
    airgap_open: float = quantity(1.2e-3, "m", "airgap d at x = 0 (Eq. 12)", source="representative", positive=True)
    tau1: float = quantity(0.010, "s", "first current-control lag tau1 (Fig. 15)", source="representative", positive=True)
    tau2: float = quantity(0.004, "s", "second current-control lag tau2 (Fig. 15)", source="representative", positive=True)

    def check(self) -> None:
        if not self.airgap_open > self.free_travel:
            raise ParameterError(
                f"ActuatorParameters: airgap_open = {self.airgap_open!r} m must exceed free_travel = "
                f"{self.free_travel!r} m (Eq. 12: d > sigma)")

    def kernel_data(self) -> np.ndarray:
        """Array ``[mass, stiffness, preload, damping, free_travel, airgap_open, tau1, tau2]`` (SI)."""
        return np.array([self.mass, self.stiffness, self.preload, self.damping, self.free_travel,
                         self.airgap_open, self.tau1, self.tau2])


@dataclasses.dataclass(frozen=True)
class VehicleParameters(ParameterSet):
    """AWD vehicle on the drum bench; Table 1 of [1] plus representative inertias, tyre and bench data."""

    kind = "vehicle"

    mass: float = quantity(2162.0, "kg", "curb weight", source="[1] Table 1", positive=True)
    cg_to_front: float = quantity(1.1043, "m", "centre of mass to front axle", source="[1] Table 1", positive=True)
    cg_to_rear: float = quantity(1.5957, "m", "centre of mass to rear axle", source="[1] Table 1", positive=True)
    cg_height: float = quantity(0.670, "m", "height of the centre of mass", source="[1] Table 1", positive=True)
    wheelbase: float = quantity(2.700, "m", "wheel base", source="[1] Table 1", positive=True)
    gear_ratios: tuple = quantity((4.044, 2.371, 1.556, 1.159, 0.852, 0.672), "1", "transmission gear ratios 1st-6th",
                                  source="[1] Table 1", positive=True)
    reverse_ratio: float = quantity(3.19, "1", "reverse gear ratio", source="[1] Table 1", positive=True)
    front_final_drive: float = quantity(3.75, "1", "front main retarder ratio i0", source="[1] Table 1", positive=True)
    rear_final_drive: float = quantity(2.533, "1", "rear main retarder ratio i_r = i_f (Eq. 28)", source="[1] Table 1", positive=True)
    engine_power: float = quantity(125e3, "W", "engine power", source="[1] Table 1", positive=True)
    engine_torque_max: float = quantity(250.0, "N*m", "engine torque limit", source="representative", positive=True)
    tyre_radius: float = quantity(0.3622, "m", "tyre radius of 225/65R17 (0.5*17 in + 0.65*225 mm)", source="[1] Table 1", positive=True)
    inertia_front_axle: float = quantity(3.5, "kg*m^2", "front axle and wheels J_wf (Eq. 27)", source="representative", positive=True)
    inertia_rear_axle: float = quantity(3.3, "kg*m^2", "rear axle and wheels J_wr (Eq. 27)", source="representative", positive=True)
    inertia_input_shaft: float = quantity(0.05, "kg*m^2", "EMTC input shaft J_sf (Eq. 27)", source="representative", positive=True)
    inertia_output_shaft: float = quantity(0.02, "kg*m^2", "EMTC output shaft J_sr (Eq. 27)", source="representative", positive=True)
    tyre_slip_stiffness: float = quantity(1.0e5, "N", "longitudinal slip stiffness per wheel on the drum", source="representative", positive=True)
    slip_speed_floor: float = quantity(1.0, "m/s", "speed floor of the slip definition", source="representative", positive=True)
    rolling_resistance: float = quantity(0.012, "1", "rolling-resistance coefficient on the drums", source="representative", nonnegative=True)
    torsen_stiffness: float = quantity(2000.0, "N*m/rad", "Torsen equivalent stiffness K_s (Eq. 30)", source="representative", nonnegative=True)
    torsen_damping: float = quantity(30.0, "N*m*s/rad", "Torsen equivalent damping D_s (Eq. 30)", source="representative", nonnegative=True)
    drag_pairs: int = quantity(15, "1", "fluid gaps N of the open coupling (Eq. 25)", source="representative", nonnegative=True)
    oil_viscosity: float = quantity(0.02, "Pa*s", "dynamic viscosity of the coupling fluid (Eq. 25)", source="representative", positive=True)
    plate_clearance: float = quantity(0.2e-3, "m", "axial clearance h between discs (Eq. 25)", source="representative", positive=True)
    plate_outer_radius: float = quantity(0.075, "m", "outer radius R_o of the wetted plates (Eq. 25)", source="representative", positive=True)
    plate_inner_radius: float = quantity(0.055, "m", "inner radius R_1 of the wetted plates (Eq. 25)", source="representative", nonnegative=True)

    def check(self) -> None:
        if abs(self.cg_to_front + self.cg_to_rear - self.wheelbase) > 1e-3:
            raise ParameterError(
                f"VehicleParameters: cg_to_front + cg_to_rear = {self.cg_to_front + self.cg_to_rear:.4f} m "
                f"differs from wheelbase = {self.wheelbase:.4f} m")
        if not self.plate_inner_radius < self.plate_outer_radius:
            raise ParameterError("VehicleParameters: plate_inner_radius must be < plate_outer_radius")
        ratios = self.gear_ratios
        if len(ratios) == 0 or any(not r > 0 for r in ratios):
            raise ParameterError(f"VehicleParameters: gear_ratios = {list(ratios)!r}: needs one ratio > 0 per gear, "
                                 "from 1st to top gear")
        if any(not a > b for a, b in zip(ratios, ratios[1:])):
            raise ParameterError(
                f"VehicleParameters: gear_ratios = {list(ratios)!r}: must fall strictly from 1st to top gear")

    def axle_loads(self) -> tuple[float, float]:
        """Static front and rear axle loads [N]."""
        w = self.mass * 9.80665
        return w * self.cg_to_rear / self.wheelbase, w * self.cg_to_front / self.wheelbase

    def drag_coefficient(self) -> float:
        """``T_drag / omega`` of Eq. 25 [N*m*s/rad]."""
        return drag_torque(self.drag_pairs, self.oil_viscosity, 1.0, self.plate_clearance, self.plate_outer_radius,
                           self.plate_inner_radius)


@dataclasses.dataclass(frozen=True)
class BenchScenario(ParameterSet):
    """A drum-bench experiment: drum speeds, throttle ramp, gear ([1], Sec. 4, Figs. 16-17)."""

    kind = "scenario"

    duration: float = quantity(4.0, "s", "simulated time", positive=True)
    gear: int = quantity(2, "1", "engaged gear (1-6)", bounds=(1, 6))
    drum_speed: float = quantity(8.0, "m/s", "front drum surface speed", nonnegative=True)
    speed_difference: float = quantity(0.3, "m/s", "front minus rear drum speed", bounds=(-5.0, 5.0))
    throttle_start: float = quantity(0.1, "1", "throttle at t = 0", bounds=(0.0, 1.0))
    throttle_end: float = quantity(0.6, "1", "throttle at the end of the ramp", bounds=(0.0, 1.0))
    ramp_start: float = quantity(0.5, "s", "throttle ramp start", nonnegative=True)
    ramp_end: float = quantity(3.5, "s", "throttle ramp end", nonnegative=True)
    drum_load_front: float = quantity(0.0, "N*m", "extra drum resistance torque, front axle", nonnegative=True)
    drum_load_rear: float = quantity(0.0, "N*m", "extra drum resistance torque, rear axle", nonnegative=True)
    temperature_c: float = quantity(60.0, "degC", "coupling temperature (friction map)", bounds=(-40.0, 200.0))
    sample_time: float = quantity(0.002, "s", "controller and output sample time", positive=True)

    def check(self) -> None:
        if self.ramp_end < self.ramp_start:
            raise ParameterError("BenchScenario: ramp_end must not be before ramp_start")
        if self.sample_time > self.duration:
            raise ParameterError("BenchScenario: sample_time longer than duration")


class TorqueMap:
    """Torque reference ``T_cal = f(throttle, v_x)`` of the EMTC controller ([1], Eq. 31).

    Bilinear in throttle [-] and vehicle speed [m/s], clamped at the edges.
    The default is representative: more torque to the rear at high throttle
    and low speed, fading with speed.
    """

    def __init__(self, throttle=None, speed=None, torque=None):
        if throttle is None:
            throttle = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
            speed = np.array([0.0, 5.0, 10.0, 20.0, 40.0])
            torque = np.outer([0.0, 150.0, 300.0, 450.0, 550.0], [1.0, 0.9, 0.8, 0.5, 0.2])
        self.throttle = np.asarray(throttle, float)
        self.speed = np.asarray(speed, float)
        self.torque = np.asarray(torque, float)
        for name, g in (("throttle", self.throttle), ("speed", self.speed)):
            if g.ndim != 1 or g.size < 2 or np.any(np.diff(g) <= 0) or not np.all(np.isfinite(g)):
                raise ParameterError(f"TorqueMap.{name}: need a strictly increasing grid of at least two values")
        if self.torque.shape != (self.throttle.size, self.speed.size) or not np.all(np.isfinite(self.torque)):
            raise ParameterError(f"TorqueMap.torque: expected finite values of shape {(self.throttle.size, self.speed.size)}")

    def __call__(self, throttle, speed):
        """``T_cal`` [N*m] at throttle [-] and vehicle speed [m/s]."""
        return float(bilinear(self.throttle, self.speed, self.torque, float(throttle), float(speed)))


class BenchResult:
    """Result of :func:`simulate_bench`: a per-sample view of a :class:`clutchlab.SimulationResult`.

    Parameters
    ----------
    result : clutchlab.SimulationResult
        A run of the ``emtc_bench`` model recorded at the controller samples.
    controller_log : numpy.ndarray or callable, optional
        ``(samples, 4)``: command [A], reference [N*m], throttle [-] and feasible (1/0) computed by the
        controller at each sample (see :meth:`from_result`), or a zero-argument callable returning it, called
        when the controller columns are first read (:func:`simulate_bench` runs the controller's last sample
        only then).

    Attributes
    ----------
    result : clutchlab.SimulationResult
        The run as every model returns it: unit-suffixed states and outputs, modes and named events.
    time : numpy.ndarray
        Sample times [s] (the controller samples).
    states : pandas.DataFrame
        Kernel names, kept for existing code: ``omega_f, omega_r`` [rad/s],
        ``theta`` [rad], ``x`` [m], ``xdot`` [m/s], ``i1, i2`` [A].
    outputs : pandas.DataFrame
        Kernel names, kept for existing code: magnet force, clamp forces,
        element torques, lock torque, capacity, integer mode codes
        (:data:`MODE_NAMES`, :data:`ARMATURE_MODE_NAMES`), commands.
    events : pandas.DataFrame
        ``time_s``, ``event`` (:data:`EVENT_KEYS`: ``lockup``, ``unlock``,
        ...), ``description``, ``armature_mode`` and ``coupling_mode`` after
        the event (names); the former ``time``, ``kind`` (integer code) and
        ``name`` (= ``description``) columns are kept for existing code.
    n_steps : int
        Accepted integration steps.

    Notes
    -----
    :meth:`to_dataframe` is the table to keep and to write: every column
    named with its unit suffix and modes as names (docs/nomenclature.md).
    The controller columns (``current_command``, ``torque_reference``,
    ``throttle``, ``command_feasible``) of row ``k`` are those the controller
    computed at sample ``k`` (the command applied from there on); the
    :attr:`result` reports at each sample the command held up to it.
    """

    def __init__(self, result, controller_log=None):
        self.result = result
        self._log_source = controller_log
        self.n_steps = int(result.stats.get("accepted_steps", 0))
        self.time = np.asarray(result.time, dtype=float).copy()
        self._cache = {}

    @classmethod
    def from_result(cls, result, controller_log=None) -> "BenchResult":
        """The per-sample view of a drum-bench :class:`clutchlab.SimulationResult`.

        Parameters
        ----------
        result : clutchlab.SimulationResult
            A run of the ``emtc_bench`` model (:func:`clutchlab.emtc.simulate`).
        controller_log : numpy.ndarray, optional
            ``(samples, 4)``: command [A], reference [N*m], throttle [-], feasible (1/0) computed at each
            sample (:func:`clutchlab.emtc.system.controller_log`); without it the held values the result reports are used.
        """
        return cls(result, controller_log)

    @property
    def _log(self):
        """The controller log (built from its callable on first read)."""
        if callable(self._log_source):
            self._log_source = self._log_source()
        return self._log_source

    def __getstate__(self):
        state = dict(self.__dict__)
        state["_log_source"] = self._log  # (no callable in the state)
        return state

    def _out(self, name):
        return self.result[name]

    @property
    def states(self) -> pd.DataFrame:
        if "states" not in self._cache:
            x = self.result.states
            self._cache["states"] = pd.DataFrame({c: x[:, q] for q, c in enumerate(_STATE_COLS)})
        return self._cache["states"]

    @property
    def outputs(self) -> pd.DataFrame:
        if "outputs" not in self._cache:
            r = self.result
            cols = {c: np.asarray(r[name], float) for c, name in _AUX_COLS}
            cols["locked_case"] = cols["locked_case"].astype(int)
            log = self._log
            if log is not None and log.shape[0] == self.time.size:
                cmd, tref, thr, ok = log[:, 0], log[:, 1], log[:, 2], log[:, 3] > 0.5
            else:
                cmd, tref = r["current_command_A"], r["torque_reference_Nm"]
                thr, ok = r["throttle_1"], r["command_feasible_1"] > 0.5
            cols.update({
                "armature_mode": r.modes[:, 0].astype(int),
                "coupling_mode": r.modes[:, 1].astype(int),
                "current_command": np.asarray(cmd, float),
                "torque_reference": np.asarray(tref, float),
                "throttle": np.asarray(thr, float),
                "command_feasible": np.asarray(ok, bool),
                "slip_speed": np.asarray(r["slip_speed_rad_s"], float),
                "airgap": np.asarray(r["airgap_m"], float),
            })
            self._cache["outputs"] = pd.DataFrame(cols)
        return self._cache["outputs"]

    @property
    def events(self) -> pd.DataFrame:
        if "events" not in self._cache:
            e = self.result.events
            keys = [str(k) for k in e["event"]]
            kinds = np.array([_EVENTS.index(k) for k in keys], dtype=int)
            names = [_DESCRIPTIONS[k] for k in kinds]
            # the modes after each event follow from the event alone (Fig. 11; the armature stops)
            arm, cpl = (int(v) for v in self.result.modes[0, :2]) if len(self.time) else (0, 0)
            arm_after, cpl_after = [], []
            for k in keys:
                arm, cpl = _AFTER[k](arm, cpl)
                arm_after.append(ARMATURE_MODE_NAMES[arm])
                cpl_after.append(MODE_NAMES[cpl])
            t = e["time_s"].to_numpy(dtype=float)
            self._cache["events"] = pd.DataFrame({
                "time_s": t, "event": keys, "description": names, "armature_mode": arm_after,
                "coupling_mode": cpl_after, "time": t, "kind": kinds, "name": names})
        return self._cache["events"]

    @property
    def modes(self) -> pd.Series:
        """Coupling mode name at every sample."""
        return self.outputs["coupling_mode"].map(MODE_NAMES)

    def to_dataframe(self) -> pd.DataFrame:
        """One table with time, states and outputs, in the names and units of docs/nomenclature.md.

        Returns
        -------
        pandas.DataFrame
            Columns :data:`COLUMN_NAMES` (``time_s``, ``omega_f_rad_s``,
            ``coupling_torque_Nm``, ``slip_speed_rad_s``, ...), all SI;
            ``armature_mode`` (``rest``/``free``/``contact``),
            ``coupling_mode`` (``open``/``slipping``/``locked``) and
            ``locked_case`` (the case of Fig. 12, ``""`` unless locked) as names.
        """
        frame = pd.concat([pd.DataFrame({"time": self.time}), self.states, self.outputs], axis=1)
        frame["armature_mode"] = frame["armature_mode"].map(ARMATURE_MODE_NAMES)
        frame["coupling_mode"] = frame["coupling_mode"].map(MODE_NAMES)
        frame["locked_case"] = frame["locked_case"].map(lambda c: LOCKED_CASE_NAMES.get(int(c), ""))
        return frame.rename(columns=COLUMN_NAMES)


_STATE_COLS = ["omega_f", "omega_r", "theta", "x", "xdot", "i1", "i2"]
#: kernel names of the outputs and the SimulationResult columns they come from
_AUX_COLS = [("magnet_force", "magnet_force_N"), ("fn1", "fn1_N"), ("t1", "t1_Nm"), ("t2", "t2_Nm"),
             ("t3", "t3_Nm"), ("t_coupling", "coupling_torque_Nm"), ("t_lock_eq29", "lock_torque_Nm"),
             ("t_trans", "transmission_torque_Nm"), ("capacity_locked", "capacity_locked_Nm"),
             ("locked_case", "locked_case_1"), ("fn2", "fn2_N"), ("engine_torque", "engine_torque_Nm")]
#: (armature mode, coupling mode) after each event
_AFTER = {
    "armature_rest": lambda a, c: (0, c),
    "armature_contact": lambda a, c: (2, 1),
    "armature_leave_rest": lambda a, c: (1, c),
    "armature_leave_contact": lambda a, c: (1, 0),
    "lockup": lambda a, c: (a, 2),
    "slip_reversal": lambda a, c: (a, 1),
    "unlock": lambda a, c: (a, 1),
}


_DEFAULTS: dict = {}
_NONE7 = (None,) * 7
_SYSTEM = None


def _system_module():
    """:mod:`clutchlab.emtc.system` (imported on first use: it imports this module; an import statement in a
    function costs about 1.5 us a call)."""
    global _SYSTEM
    if _SYSTEM is None:
        from . import system

        _SYSTEM = system
    return _SYSTEM


def _default(cls):
    """Shared default instance (parameter sets are frozen; the map is never modified)."""
    if cls not in _DEFAULTS:
        _DEFAULTS[cls] = cls()
    return _DEFAULTS[cls]


def simulate_bench(magnet, scenario: BenchScenario | None = None, *, vehicle: VehicleParameters | None = None,
                   actuator: ActuatorParameters | None = None, coupling: CouplingGeometry | None = None,
                   torque_map: TorqueMap | None = None, controller_model=None, friction_map=None, lugre=None,
                   torque_reference=None, rtol=1e-6, atol=None, max_steps=2_000_000,
                   fixed_step: float | None = None) -> BenchResult:
    """Simulate the vehicle with EMTC on the drum bench ([1], Eqs. 8-31, Figs. 11, 15-17).

    A thin layer over :func:`clutchlab.emtc.simulate` (the ``emtc_bench`` model run by the integrator
    core), kept for existing code: the result is recorded at every controller sample up to the last one
    at or before ``scenario.duration`` and viewed as a :class:`BenchResult`.

    Parameters
    ----------
    magnet : clutchlab.hysteresis.Preisach
        Magnet force [N] vs coil current [A] (and airgap [m]) of the plant.
    scenario : BenchScenario
        Drum speeds, throttle ramp, gear, sample time.
    vehicle, actuator, coupling : parameter sets
        Defaults: Table 1 of [1] and representative values.
    torque_map : TorqueMap
        Reference map of Eq. 31 (default :class:`TorqueMap`).
    controller_model : Preisach, optional
        Model used by the open-loop compensation (Fig. 7); default ``magnet``.
    friction_map : clutchlab.emtc.FrictionMap, optional
        Kinetic coefficient ``mu(|slip|, temperature)`` for all three elements
        (default: the constant coefficients of ``coupling``).
    lugre : clutchlab.emtc.LuGreParameters, optional
        LuGre friction (Eqs. 22-24) for the three elements in slipping mode
        instead of the constant kinetic coefficients; the bristle state is
        committed once per accepted step with the exact update of Eq. 23.
        The static coefficients of the locked mode are then ``mu_p`` for all
        three elements (LuGre's breakaway level), and the bristles start at
        full deflection after an unlock.
    torque_reference : (times, torques), optional
        Replaces the map of Eq. 31 by a prescribed reference [s], [N*m].
    rtol, atol : float
        Integrator tolerances (atol per state; default: ``clutchlab.emtc.system.absolute_tolerance(rtol)``,
        scaled to each state and shrinking with ``rtol`` below its default 1e-6).
    max_steps : int
        Accepted steps after which the run stops with :class:`SimulationError`.
    fixed_step : float, optional
        Fixed-step (real-time, HIL frame) mode with this step [s]: Rodas3 steps on the grid
        ``k * fixed_step``, the controller samples and mode changes inside a step at its end
        (:func:`clutchlab.system.simulate`; ``rtol`` and ``atol`` are then unused).  None (default):
        step-size control.

    Returns
    -------
    BenchResult

    Notes
    -----
    The controller samples at ``scenario.sample_time``: it reads ``T_cal``,
    converts it to the primary-clutch force with the slipping-mode gain of
    Eq. 15, adds spring preload and travel (Eq. 11) and commands the current
    from the inverse Preisach model at the engaged airgap ``d - sigma``
    (Eqs. 6-7).  The current follows through the two lags of Fig. 15.
    """
    S = _system_module()
    scenario = scenario or _default(BenchScenario)
    given = (actuator, coupling, torque_map, controller_model, friction_map, lugre, torque_reference)
    if given == _NONE7:
        options = _default(S.BenchOptions)
    else:
        options = S.BenchOptions(actuator=actuator, coupling=coupling, torque_map=torque_map,
                                 controller_model=controller_model, friction_map=friction_map, lugre=lugre,
                                 torque_reference=torque_reference)
    # output rows plus the event buffer (20 events of 4 values per output row, as before)
    check_allocation(scenario.duration / scenario.sample_time + 1, 26 + 80,
                     f"duration = {scenario.duration!r} s at sample_time = {scenario.sample_time!r} s")
    n = int(round(scenario.duration / scenario.sample_time)) + 1
    samples = np.arange(n) * scenario.sample_time

    def build(cap):
        opts = options if cap is None else dataclasses.replace(options, memory_capacity=cap)
        return S.bench_system(magnet, scenario, vehicle, opts, n_samples=n)

    system, res = S.run(build, float(samples[-1]), rtol=float(rtol), atol=atol, sample_times=samples,
                        max_steps=int(max_steps), fixed_step=fixed_step)
    params, t_last, x_last, u0 = system.params, float(samples[-1]), res.stats["final_state"].copy(), system.u0

    def controller_log():
        # the controller also runs at the last sample (its break never comes: the run ends there); done when
        # the controller columns are first read (the run's own memories wait for it)
        S.run_controller(params, t_last, x_last, u0)
        return S.controller_log(params)

    return BenchResult(res, controller_log)


def load_scenario(path):
    """Read a scenario TOML with optional tables ``[scenario]``, ``[vehicle]``, ``[actuator]``, ``[coupling]``.

    Returns
    -------
    dict
        ``scenario``, ``vehicle``, ``actuator``, ``coupling`` parameter sets
        and ``magnet`` (path of a Preisach model JSON or None, relative to the file).
    """
    from pathlib import Path

    data = load_toml(path)
    known = {"scenario", "vehicle", "actuator", "coupling", "magnet"}
    unknown = set(data) - known
    if unknown:
        raise ParameterError(f"{path}: unknown table(s) {short_repr(sorted(unknown))} (known: {sorted(known)})")
    out = {
        "scenario": BenchScenario.from_dict(data.get("scenario", {}), source=str(path)),
        "vehicle": VehicleParameters.from_dict(data.get("vehicle", {}), source=str(path)),
        "actuator": ActuatorParameters.from_dict(data.get("actuator", {}), source=str(path)),
        "coupling": CouplingGeometry.from_dict(data.get("coupling", {}), source=str(path)),
        "magnet": None,
    }
    if out["scenario"].gear > len(out["vehicle"].gear_ratios):
        raise ParameterError(f"{path}: [scenario] gear = {out['scenario'].gear}: the vehicle has gears 1 to "
                             f"{len(out['vehicle'].gear_ratios)} ([vehicle] gear_ratios)")
    mag = data.get("magnet", {})
    if mag:
        if not isinstance(mag, dict) or set(mag) - {"model"}:
            raise ParameterError(f"{path}: [magnet] takes only model = 'path/to/model.json', got {short_repr(mag)}")
        if not isinstance(mag.get("model"), str) or not mag["model"].strip():
            raise ParameterError(f"{path}: [magnet] model = {short_repr(mag.get('model'))}: expected the path of "
                                 "a Preisach model JSON file")
        out["magnet"] = (Path(path).parent / mag["model"]).resolve()
    return out
