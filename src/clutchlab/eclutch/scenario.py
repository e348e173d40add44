"""E-clutch simulation scenarios: a TOML file that says what to simulate.

A scenario names the clutch model, the input (motor voltage, bearing-position
reference, clutch-pedal signal, or a prescribed bearing motion for the clutch
alone), the run length and any parameter overrides::

    [scenario]
    model = 4                     # axial Model 0-4 of Haramina et al. (2024)
    t_end = "1.2 s"
    output_step = "1 ms"          # optional: uniform output grid
    rtol = 1e-3                   # optional
    friction = true               # clutch friction elements R_f.ds, R_f.pp (default true)

    [input]
    kind = "pedal"                # "voltage" [V], "bearing_reference" [m], "pedal" [0-1], "bearing_position" [m]
    time_s = [0.0, 0.1, 0.3, 0.8, 1.0]
    value = [0, 0, 1, 1, 0]       # quantities may carry units: ["0 mm", "8 mm"]
    release_travel = "8 mm"       # pedal only

    [eclutch]                     # EClutchParameters overrides (clutch)
    [eclutch_actuator]            # ActuatorParameters overrides
    [eclutch_friction]            # FrictionParameters overrides
    [offsets]                     # wear and thermal expansion (Sec. 7 future work iii)
    wear = "0.2 mm"
    temperature_rise = "60 K"

Every value is converted to SI once here; errors name the file, the table and
key, and the value.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from .._limits import check_allocation, short_repr
from ..errors import ParameterError
from ..params import load_toml
from ..system import register_model
from ..units import to_si
from .actuator import ActuatorParameters
from .dynamics import (ClutchDynamics, DynamicsResult, EClutch, FrictionParameters, _as_table,
                       apply_wear_and_expansion, pedal_reference)
from .models import MODEL_NUMBERS, ClutchModel, EClutchParameters

__all__ = ["Scenario", "load_scenario", "scenario_from_dict", "run_scenario", "scenario_system", "simulate",
           "INPUT_KINDS"]

INPUT_KINDS = {"voltage": "V", "bearing_reference": "m", "pedal": "1", "bearing_position": "m"}
_TABLES = ("scenario", "input", "eclutch", "eclutch_actuator", "eclutch_friction", "offsets")


@dataclasses.dataclass(frozen=True)
class Scenario:
    """A parsed scenario (SI units).

    Attributes
    ----------
    model : int
        Axial model number (0-4).
    t_end : float
        Simulated time [s].
    input_kind : str
        One of :data:`INPUT_KINDS`.
    time_s, value : ndarray
        Input table (value in V, m, or pedal fraction).
    release_travel : float
        Bearing travel of a fully pressed pedal [m].
    clutch, actuator, friction : parameter sets
    wear_m, temperature_rise_k : float
        Offsets of the characteristics.
    output_step : float or None
        Output grid [s].
    rtol : float
        Relative tolerance.
    source : str
        File it came from.
    """

    model: int = 4
    t_end: float = 1.0
    input_kind: str = "pedal"
    time_s: np.ndarray = dataclasses.field(default_factory=lambda: np.array([0.0, 0.1, 0.3, 0.7, 0.9]))
    value: np.ndarray = dataclasses.field(default_factory=lambda: np.array([0.0, 0.0, 1.0, 1.0, 0.0]))
    release_travel: float = 8e-3
    clutch: EClutchParameters = dataclasses.field(default_factory=EClutchParameters)
    actuator: ActuatorParameters = dataclasses.field(default_factory=ActuatorParameters)
    friction: FrictionParameters = dataclasses.field(default_factory=FrictionParameters)
    wear_m: float = 0.0
    temperature_rise_k: float = 0.0
    output_step: float | None = None
    rtol: float = 1e-3
    source: str = "defaults"

    def clutch_model(self) -> ClutchModel:
        """The clutch model with the scenario's parameters and offsets."""
        model = ClutchModel.preset(self.model, self.clutch)
        if self.wear_m or self.temperature_rise_k:
            model = apply_wear_and_expansion(model, wear_m=self.wear_m, temperature_rise_k=self.temperature_rise_k)
        return model

    def input_table(self) -> tuple[np.ndarray, np.ndarray]:
        """Input table in the simulator's units (pedal converted to a bearing reference)."""
        if self.input_kind == "pedal":
            return self.time_s, pedal_reference(self.value, self.release_travel)
        return self.time_s, self.value


def _number_list(raw, unit, where):
    if not isinstance(raw, list) or not raw:
        raise ParameterError(f"{where} = {short_repr(raw)}: expected a non-empty list")
    return np.array([to_si(v, unit, name=f"{where}[{i}]") for i, v in enumerate(raw)], dtype=float)


def load_scenario(path) -> Scenario:
    """Read a scenario TOML file (see the module documentation for the format).

    Parameters
    ----------
    path : str or Path
        Scenario TOML file; errors name it with the table, key and value at fault.
    """
    return scenario_from_dict(load_toml(path), source=str(path))


def scenario_from_dict(data: dict, source: str = "scenario") -> Scenario:
    """A :class:`Scenario` from the tables of a scenario file.

    Parameters
    ----------
    data : dict
        Tables as read from TOML (keys starting with ``_`` are ignored).
    source : str
        Name of the file, used in error messages.
    """
    src = source
    data = {k: v for k, v in data.items() if not k.startswith("_")}
    unknown = [k for k in data if k not in _TABLES]
    if unknown:
        raise ParameterError(f"{src}: unknown table [{short_repr(unknown[0])}] (known: {', '.join(_TABLES)})")
    for name, table in data.items():
        if not isinstance(table, dict):
            raise ParameterError(f"{src}: {name} = {short_repr(table)}: expected a table [{name}]")
    sc = dict(data.get("scenario", {}))
    known = {"model", "t_end", "output_step", "rtol", "friction"}
    for k in sc:
        if k not in known:
            raise ParameterError(f"{src}: [scenario] unknown key {short_repr(k)} (known: {', '.join(sorted(known))})")
    model = sc.get("model", 4)
    if isinstance(model, bool) or not isinstance(model, int) or model not in MODEL_NUMBERS:
        raise ParameterError(f"{src}: [scenario] model = {short_repr(model)}: expected one of 0, 1, 2, 3, 4")
    t_end = to_si(sc.get("t_end", 1.0), "s", name="[scenario] t_end", source=src)
    if t_end <= 0:
        raise ParameterError(f"{src}: [scenario] t_end = {sc.get('t_end')!r} must be > 0")
    output_step = None
    if "output_step" in sc:
        output_step = to_si(sc["output_step"], "s", name="[scenario] output_step", source=src)
        if not 0 < output_step <= t_end:
            raise ParameterError(f"{src}: [scenario] output_step = {sc['output_step']!r} must be in (0, t_end]")
        check_allocation(t_end / output_step + 1, 1, f"{src}: [scenario] t_end = {short_repr(sc.get('t_end'))} "
                                                     f"at output_step = {short_repr(sc['output_step'])}")
    rtol = to_si(sc.get("rtol", 1e-3), "1", name="[scenario] rtol", source=src)
    use_friction = sc.get("friction", True)
    if not isinstance(use_friction, bool):
        raise ParameterError(f"{src}: [scenario] friction = {short_repr(use_friction)}: expected true or false")
    inp = dict(data.get("input", {}))
    kind = inp.pop("kind", "pedal")
    if not isinstance(kind, str) or kind not in INPUT_KINDS:
        raise ParameterError(f"{src}: [input] kind = {short_repr(kind)}: expected one of {', '.join(INPUT_KINDS)}")
    release_travel = to_si(inp.pop("release_travel", 8e-3), "m", name="[input] release_travel", source=src)
    file_input = "file" in inp
    if file_input:
        from ..io import read_table

        name = inp.pop("file")
        if not isinstance(name, str) or not name.strip():
            raise ParameterError(f"{src}: [input] file = {short_repr(name)}: expected the path of a CSV file")
        f = Path(src).parent / name
        frame = read_table(f, ["time_s", "value"], name=f"{src}: [input] file {str(f)!r}")
        t = frame["time_s"].to_numpy(float)
        v = frame["value"].to_numpy(float)
    else:
        if "time_s" not in inp or "value" not in inp:
            raise ParameterError(f"{src}: [input] needs 'time_s' and 'value' lists (or 'file')")
        try:
            t = _number_list(inp.pop("time_s"), "s", "[input] time_s")
            v = _number_list(inp.pop("value"), INPUT_KINDS[kind], "[input] value")
        except ParameterError as exc:
            raise ParameterError(f"{src}: {exc}") from None
    if inp:
        raise ParameterError(f"{src}: [input] unknown key {short_repr(next(iter(inp)))}")
    if kind == "pedal":
        bad = np.flatnonzero(~((v >= 0.0) & (v <= 1.0)))  # NaN too
        if bad.size:
            where = f"{f}: row {int(bad[0])} value" if file_input else f"[input] value[{int(bad[0])}]"
            raise ParameterError(f"{src}: {where} = {float(v[bad[0]])!r}: a pedal position must lie in 0..1 "
                                 "(0 released, 1 pressed down)")
        if not 0.0 < release_travel < float("inf"):
            raise ParameterError(f"{src}: [input] release_travel = {release_travel!r} m: must be finite and > 0")
    if t.size != v.size:
        raise ParameterError(f"{src}: [input] time_s has {t.size} values but value has {v.size}")
    if t.size > 1 and np.any(np.diff(t) <= 0):
        i = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
        raise ParameterError(f"{src}: [input] time_s must increase strictly (entry {i}: {t[i]!r} s)")
    offsets = dict(data.get("offsets", {}))
    wear = to_si(offsets.pop("wear", 0.0), "m", name="[offsets] wear", source=src)
    rise = to_si(offsets.pop("temperature_rise", 0.0), "K", name="[offsets] temperature_rise", source=src)
    if offsets:
        raise ParameterError(f"{src}: [offsets] unknown key {short_repr(next(iter(offsets)))} "
                             "(known: wear, temperature_rise)")
    if wear < 0:
        raise ParameterError(f"{src}: [offsets] wear = {wear!r} m must be >= 0")
    clutch = EClutchParameters.from_dict(data.get("eclutch", {}), source=src)
    actuator = ActuatorParameters.from_dict(data.get("eclutch_actuator", {}), source=src)
    friction = FrictionParameters.from_dict(data.get("eclutch_friction", {}), source=src) if use_friction \
        else FrictionParameters.off()
    if "eclutch_actuator" not in data or "csc_preload" not in data.get("eclutch_actuator", {}):
        actuator = actuator.replace(csc_preload=clutch.bearing_preload)
    lo, hi = actuator.slave_min, actuator.slave_max
    if kind == "bearing_reference":   # (the actuator's position reference: inside its travel, #33)
        bad = np.flatnonzero((v < lo) | (v > hi))
        if bad.size:
            where = f"{f}: row {int(bad[0])} value" if file_input else f"[input] value[{int(bad[0])}]"
            raise ParameterError(f"{src}: {where} = {float(v[bad[0]]):g} m is outside the CSC travel [{lo:g}, {hi:g}] m "
                                 "([eclutch_actuator] slave_min, slave_max)")
    if kind == "pedal" and release_travel > hi:
        raise ParameterError(f"{src}: [input] release_travel = {release_travel:g} m is beyond the CSC travel "
                             f"{hi:g} m ([eclutch_actuator] slave_max)")
    return Scenario(model=model, t_end=t_end, input_kind=kind, time_s=t, value=v, release_travel=release_travel,
                    clutch=clutch, actuator=actuator, friction=friction, wear_m=wear, temperature_rise_k=rise,
                    output_step=output_step, rtol=rtol, source=src)


def run_scenario(scenario: Scenario, progress=None, *, rtol: float | None = None, atol=None,
                 max_step: float | None = None, output_step: float | None = None,
                 fixed_step: float | None = None) -> DynamicsResult:
    """Simulate a scenario: the E-clutch (actuator + clutch), or the clutch alone for ``bearing_position``.

    Parameters
    ----------
    scenario : Scenario
        What to simulate (:func:`load_scenario`).
    progress : callable, optional
        Called with a message string as the run proceeds.
    rtol, output_step : float, optional
        Relative tolerance and sample interval [s] (default: the scenario's).
    atol : float or array_like, optional
        Absolute tolerances per state (default: the model's, :meth:`EClutch.simulate`).
    max_step : float, optional
        Largest step [s] (default: the model's).
    fixed_step : float, optional
        Fixed-step (real-time, HIL frame) mode with this step [s] (:meth:`EClutch.simulate`); the
        scenario's ``rtol`` is then unused.  None (default): step-size control.
    """
    if progress:
        progress(f"building Model {scenario.model} and the actuator ...")
    model = scenario.clutch_model()
    t, v = scenario.input_table()
    if progress:
        frames = "" if fixed_step is None else f" in fixed steps of {fixed_step:g} s"
        progress(f"simulating {scenario.t_end:g} s ({scenario.input_kind} input){frames} ...")
    options = dict(rtol=scenario.rtol if rtol is None else rtol, atol=atol, max_step=max_step,
                   output_step=scenario.output_step if output_step is None else output_step, fixed_step=fixed_step)
    if scenario.input_kind == "bearing_position":
        return ClutchDynamics(model, scenario.friction).simulate((t, v), scenario.t_end, **options)
    key = "voltage" if scenario.input_kind == "voltage" else "bearing_reference"
    ec = EClutch(scenario.actuator, model, scenario.friction)
    return ec.simulate({key: (t, v)}, scenario.t_end, **options)


def _as_scenario(scenario) -> Scenario:
    if scenario is None:
        return Scenario()
    if isinstance(scenario, Scenario):
        return scenario
    if isinstance(scenario, (str, Path)):
        return load_scenario(scenario)
    if isinstance(scenario, Mapping):
        keys = set(scenario)
        if len(keys) == 1 and keys <= {"voltage", "bearing_reference", "bearing_position"}:
            # an input table: the default E-clutch (Model 4, friction on) driven by it
            (kind, value), = scenario.items()
            t, v = _as_table(value, kind)
            return Scenario(input_kind=kind, time_s=t, value=v, t_end=float(t[-1]) if t[-1] > 0 else 1.0,
                            source=f"{kind} input")
        return scenario_from_dict(dict(scenario), source=str(scenario.get("_source", "scenario")))
    raise ParameterError(f"scenario: expected a Scenario, a scenario file or an input mapping, "
                         f"got {type(scenario).__name__}")


def scenario_system(scenario=None, **options):
    """The :class:`~clutchlab.system.System` of a scenario (what :func:`simulate` runs; the model ``"eclutch"``).

    Parameters
    ----------
    scenario : Scenario, str, Path, dict or None
        A :class:`Scenario`, a scenario TOML file, its parsed tables, an input mapping
        (``{"voltage": table}``, ``{"bearing_reference": table}``, ``{"bearing_position": table}``: the
        default E-clutch, Model 4 with friction) or None for the default scenario.
    **options
        Run defaults for the system (``max_step``, ``event_tol``, ``jac_every``, ``atol_scale``).
    """
    sc = _as_scenario(scenario)
    model = sc.clutch_model()
    t, v = sc.input_table()
    options.setdefault("rtol", sc.rtol)
    if sc.input_kind == "bearing_position":
        return ClutchDynamics(model, sc.friction).as_system((t, v), **options)
    key = "voltage" if sc.input_kind == "voltage" else "bearing_reference"
    return EClutch(sc.actuator, model, sc.friction).as_system({key: (t, v)}, **options)


def simulate(scenario=None, t_end: float | None = None, *, rtol: float | None = None, atol=None,
             max_step: float | None = None, output_step: float | None = None, fixed_step: float | None = None):
    """Simulate an E-clutch scenario with the integrator core: the uniform entry point.

    Parameters
    ----------
    scenario : Scenario, str, Path, dict or None
        What to simulate: a :class:`Scenario`, a scenario TOML file (:func:`load_scenario`), its parsed
        tables, an input mapping (``{"voltage": (times, volts)}``, ``{"bearing_reference": (times, m)}`` or
        ``{"bearing_position": (times, m)}`` for the clutch alone; the default E-clutch, Model 4 with
        friction), or None for the default scenario (pedal press and release).
    t_end : float, optional
        End time [s] (default: the scenario's).
    rtol : float, optional
        Relative tolerance (default: the scenario's, 1e-3).
    atol : float or array_like, optional
        Absolute tolerance per state in the state's unit (default: 0.1 um, 0.1 mm/s, 100 Pa, 1 mA, ...).
    max_step : float, optional
        Largest step [s] (default 0.01).
    output_step : float, optional
        Sample interval of the result [s] (dense output; default: the scenario's, else every accepted step).
    fixed_step : float, optional
        Fixed-step (real-time, HIL frame) mode with this step [s] (:func:`clutchlab.system.simulate`); None
        (default): step-size control.

    Returns
    -------
    SimulationResult
        States, outputs (``bearing_force_N``, ``torque_Nm``, ``motor_current_A``, ...), friction modes and
        named events (``stick``, ``breakaway``, ``slip_reversal``, ``contact_open``, ``stop_hit``,
        ``cavitation_start``, ...) with the element they concern.
    """
    from ..system import simulate as run

    sc = _as_scenario(scenario)
    t_end = sc.t_end if t_end is None else float(t_end)
    if not (isinstance(t_end, (int, float)) and math.isfinite(t_end) and t_end > 0):
        raise ParameterError(f"t_end = {t_end!r} s must be finite and > 0")
    system = scenario_system(sc)
    step = sc.output_step if output_step is None else output_step
    return run(system, t_end, rtol=rtol, atol=atol, max_step=max_step, output_step=step, max_steps=500_000,
               fixed_step=fixed_step)


register_model("eclutch", scenario_system)
