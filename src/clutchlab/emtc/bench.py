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
from ..params.base import load_toml
from ..result import SimulationResult
from ..system import sample_grid
from . import system as S
from .params import ActuatorParameters, BenchScenario, TorqueMap, VehicleParameters, _default
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


@dataclasses.dataclass(repr=False)
class BenchResult(SimulationResult):
    """Result of :func:`simulate_bench`: the :class:`clutchlab.SimulationResult` of the ``emtc_bench`` model, recorded
    at the controller samples, with the bench's tables.

    Every field of a :class:`~clutchlab.SimulationResult` is the core's run (``states``, ``outputs`` and ``modes``
    arrays with their unit-suffixed columns, ``stats``, ``status``); ``events`` adds to its ``time_s``, ``event``
    (:data:`EVENT_KEYS`: ``lockup``, ``unlock``, ...) and ``element`` the ``description`` and the
    ``armature_mode`` and ``coupling_mode`` after the event (names).

    Parameters
    ----------
    controller_log : numpy.ndarray or callable, optional
        ``(samples, 4)``: command [A], reference [N*m], throttle [-] and feasible (1/0) computed by the
        controller at each sample (see :meth:`from_result`), or a zero-argument callable returning it, called
        when the controller columns are first read (:func:`simulate_bench` runs the controller's last sample
        only then).

    Attributes
    ----------
    kernel_states, kernel_outputs : pandas.DataFrame
        The states (``omega_f, omega_r`` [rad/s], ``theta`` [rad], ``x`` [m], ``xdot`` [m/s], ``i1, i2`` [A]) and
        outputs (magnet force, clamp forces, element torques, lock torque, capacity, integer mode codes of
        :data:`MODE_NAMES` and :data:`ARMATURE_MODE_NAMES`, the controller's columns) by the kernel's names, from
        which :meth:`to_dataframe` names them as docs/nomenclature.md does.
    coupling_modes : pandas.Series
        The coupling mode's name at every sample.
    n_steps : int
        Accepted integration steps.

    Notes
    -----
    :meth:`to_dataframe` is the table to keep and to write: every column
    named with its unit suffix and modes as names (docs/nomenclature.md).
    The controller columns (``current_command``, ``torque_reference``,
    ``throttle``, ``command_feasible``) of row ``k`` are those the controller
    computed at sample ``k`` (the command applied from there on); the run's
    own outputs report at each sample the command held up to it.
    """

    controller_log: object = dataclasses.field(default=None, repr=False)

    def __post_init__(self):
        self._cache = {}

    @classmethod
    def from_result(cls, result, controller_log=None) -> "BenchResult":
        """The bench result of a drum-bench :class:`clutchlab.SimulationResult`.

        Parameters
        ----------
        result : clutchlab.SimulationResult
            A run of the ``emtc_bench`` model (:func:`clutchlab.emtc.simulate`).
        controller_log : numpy.ndarray, optional
            ``(samples, 4)``: command [A], reference [N*m], throttle [-], feasible (1/0) computed at each
            sample (:func:`clutchlab.emtc.system.controller_log`); without it the held values the result reports are used.
        """
        kw = SimulationResult.fields_of(result)
        kw["time"] = np.asarray(result.time, dtype=float).copy()
        kw["events"] = lambda: _bench_events(result)
        return cls(**kw, controller_log=controller_log)

    @property
    def result(self) -> "BenchResult":
        """The run itself (a :class:`BenchResult` is a :class:`~clutchlab.SimulationResult`; kept for code that
        read the run from here)."""
        return self

    @property
    def n_steps(self) -> int:
        return int(self.stats.get("accepted_steps", 0))

    @property
    def _log(self):
        """The controller log (built from its callable on first read)."""
        if callable(self.controller_log):
            self.controller_log = self.controller_log()
        return self.controller_log

    def __getstate__(self):
        self._log  # noqa: B018  (no callable in the state)
        return super().__getstate__()

    @property
    def kernel_states(self) -> pd.DataFrame:
        if "states" not in self._cache:
            x = self.states
            self._cache["states"] = pd.DataFrame({c: x[:, q] for q, c in enumerate(_STATE_COLS)})
        return self._cache["states"]

    @property
    def kernel_outputs(self) -> pd.DataFrame:
        if "outputs" not in self._cache:
            cols = {c: np.asarray(self[name], float) for c, name in _AUX_COLS}
            cols["locked_case"] = cols["locked_case"].astype(int)
            log = self._log
            if log is not None and log.shape[0] == self.time.size:
                cmd, tref, thr, ok = log[:, 0], log[:, 1], log[:, 2], log[:, 3] > 0.5
            else:
                cmd, tref = self["current_command_A"], self["torque_reference_Nm"]
                thr, ok = self["throttle_1"], self["command_feasible_1"] > 0.5
            cols.update({
                "armature_mode": self.modes[:, 0].astype(int),
                "coupling_mode": self.modes[:, 1].astype(int),
                "current_command": np.asarray(cmd, float),
                "torque_reference": np.asarray(tref, float),
                "throttle": np.asarray(thr, float),
                "command_feasible": np.asarray(ok, bool),
                "slip_speed": np.asarray(self["slip_speed_rad_s"], float),
                "airgap": np.asarray(self["airgap_m"], float),
            })
            self._cache["outputs"] = pd.DataFrame(cols)
        return self._cache["outputs"]

    @property
    def coupling_modes(self) -> pd.Series:
        """Coupling mode name at every sample."""
        return self.kernel_outputs["coupling_mode"].map(MODE_NAMES)

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
        frame = pd.concat([pd.DataFrame({"time": self.time}), self.kernel_states, self.kernel_outputs], axis=1)
        frame["armature_mode"] = frame["armature_mode"].map(ARMATURE_MODE_NAMES)
        frame["coupling_mode"] = frame["coupling_mode"].map(MODE_NAMES)
        frame["locked_case"] = frame["locked_case"].map(lambda c: LOCKED_CASE_NAMES.get(int(c), ""))
        return frame.rename(columns=COLUMN_NAMES)


def _bench_events(result) -> pd.DataFrame:
    """The run's named events with their description and the modes after each (names): the modes after an event
    follow from the event alone (Fig. 11; the armature stops)."""
    e = result.events
    keys = [str(k) for k in e["event"]]
    names = [_DESCRIPTIONS[_EVENTS.index(k)] for k in keys]
    arm, cpl = (int(v) for v in result.modes[0, :2]) if len(result.time) else (0, 0)
    arm_after, cpl_after = [], []
    for k in keys:
        arm, cpl = _AFTER[k](arm, cpl)
        arm_after.append(ARMATURE_MODE_NAMES[arm])
        cpl_after.append(MODE_NAMES[cpl])
    return pd.DataFrame({"time_s": e["time_s"].to_numpy(dtype=float), "event": keys,
                         "element": list(e["element"]), "description": names, "armature_mode": arm_after,
                         "coupling_mode": cpl_after})


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


def simulate_bench(magnet, scenario: BenchScenario | None = None, *, vehicle: VehicleParameters | None = None,
                   actuator: ActuatorParameters | None = None, coupling: CouplingGeometry | None = None,
                   torque_map: TorqueMap | None = None, controller_model=None, friction_map=None, lugre=None,
                   torque_reference=None, rtol=1e-6, atol=None, max_step: float | None = None,
                   output_step: float | None = None, max_steps=2_000_000,
                   fixed_step: float | None = None) -> BenchResult:
    """Simulate the vehicle with EMTC on the drum bench ([1], Eqs. 8-31, Figs. 11, 15-17).

    A thin layer over :func:`clutchlab.emtc.simulate` (the ``emtc_bench`` model run by the integrator
    core), kept for existing code: the result is recorded at every controller sample up to the last one
    at or before ``scenario.duration`` (or every ``output_step``) and viewed as a :class:`BenchResult`.

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
    max_step : float, optional
        Largest step [s] (default: none besides the controller samples).
    output_step : float, optional
        Sample interval of the result [s] up to ``scenario.duration`` (default: the controller samples,
        ``scenario.sample_time``); off the controller samples the controller columns are the outputs held
        between samples.
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
    scenario = scenario or _default(BenchScenario)
    given = (actuator, coupling, torque_map, controller_model, friction_map, lugre, torque_reference)
    if all(g is None for g in given):
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
    if output_step is not None:
        samples = sample_grid(0.0, float(scenario.duration), output_step)

    def build(cap):
        opts = options if cap is None else dataclasses.replace(options, memory_capacity=cap)
        return S.bench_system(magnet, scenario, vehicle, opts, n_samples=n)

    system, res = S.run(build, float(samples[-1]), rtol=rtol, atol=atol, max_step=max_step,
                        sample_times=samples, max_steps=int(max_steps), fixed_step=fixed_step)
    params, t_last, x_last, u0 = system.params, float(samples[-1]), res.stats["final_state"].copy(), system.u0

    def controller_log():
        # the controller also runs at the last sample (its break never comes: the run ends there); done when
        # the controller columns are first read (the run's own memories wait for it)
        S.run_controller(params, t_last, x_last, u0)
        return S.controller_log(params)

    return BenchResult.from_result(res, controller_log)


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
