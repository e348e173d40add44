"""Virtual wet-clutch test bench of Shin, Kim and Choi [1], Fig. 4, and its protocols.

The bench is the engagement model of :mod:`clutchlab.wet.engagement` with
the rig's drive (speed-controlled 32 kW motor through the 1:2 gear, inertia,
torque sensor), force-controlled linear actuator with load cell, encoder,
thermistor with its lag, oil reservoir with 2 kW heater and natural cooling,
and the housing.  Its records carry the measured channels with sensor noise
(fixed seed), as a real bench would produce them.

Protocols
---------
(a) :class:`MapProtocol` -- the friction-map experiment of Sec. 4 / Fig. 13:
    constant pressing force applied at standstill (steady film), spin-up to a
    constant slip held for ``hold_time`` while the surface heats, then a slow
    linear decrease of the slip (and with it the temperature) over
    ``decay_time``.
(b) :class:`EngagementProtocol` with ``motor="speed"`` -- the engagement of
    Fig. 14: force raised over 0.2 s, motor torque controlled so the slip
    follows a smoothed ramp-down reference.
(c) the same engagement with ``motor="free"`` -- an SAE No. 2 inertia
    dynamometer: no motor torque, the clutch only decelerates the inertia.

References
----------
.. [1] S. Shin, D.-H. Kim, S. B. Choi, "Apparatus for identification of
   frictional and thermal characteristics of a wet clutch" (KAIST).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pandas as pd

from ..errors import DataError, ParameterError
from ..io import read_measurement, write_measurement
from ..params import ParameterSet, load_toml, quantity
from ..system import register_model
from . import system as W
from .engagement import EngagementResult, Scenario, simulate_engagement
from .friction import ParametricFriction
from .params import Bench, WetClutch
from .thermal import steady_state_temperature

__all__ = [
    "MapProtocol",
    "EngagementProtocol",
    "BenchRun",
    "RECORD_COLUMNS",
    "run_protocol",
    "measure",
    "read_bench_record",
    "write_bench_record",
    "load_protocol",
    "smoothed_ramp",
    "protocol_system",
]

#: channels of a bench record (CSV header), SI units, temperatures in degC
RECORD_COLUMNS = ("time_s", "slip_speed_rad_s", "torque_Nm", "force_N", "piston_position_m", "temperature_C",
                  "fluid_temperature_C", "housing_temperature_C")

_P300 = 300e3 * WetClutch().friction_area  # 300 kPa on the friction area, Sec. 4


def _pack_equilibrium(clutch: WetClutch, fluid_c: float, housing_c: float) -> float:
    # Eq. 8 with no friction power (thermal.steady_state_temperature); the oil's temperature without conductances
    if not clutch.k1 + clutch.k2 > 0:
        return fluid_c
    return float(steady_state_temperature(0.0, fluid_c, housing_c, clutch.k1, clutch.k2))


@dataclasses.dataclass(frozen=True)
class MapProtocol(ParameterSet):
    """Protocol (a): friction-map experiment of Sec. 4 (Fig. 13)."""

    kind: ClassVar[str] = "protocol"

    force: float = quantity(_P300, "N", "constant pressing force", source="Sec. 4: 300 kPa on the friction area",
                            positive=True)
    slip_speed: float = quantity(300 * math.pi / 30, "rad/s", "constant slip in the first section",
                                 source="Sec. 4: 300 rpm", positive=True)
    preload_time: float = quantity(3.0, "s", "force applied at standstill before rotation (film settles)",
                                   source="clutchlab", positive=True)
    spin_up_time: float = quantity(0.5, "s", "ramp from standstill to the slip speed", source="clutchlab", positive=True)
    hold_time: float = quantity(10.0, "s", "constant-slip section", source="Sec. 4", positive=True)
    decay_time: float = quantity(20.0, "s", "slow decrease of slip and temperature", source="Sec. 4", positive=True)
    final_slip_fraction: float = quantity(0.02, "1", "slip at the end of the decay / slip speed", source="clutchlab",
                                          bounds=(0.0, 1.0))
    fluid_temperature: float = quantity(85.0, "degC", "reservoir temperature (heater set point)",
                                        source="Sec. 4: test started at 85 degC")
    housing_temperature: float = quantity(65.0, "degC", "housing temperature at the start",
                                          source="clutchlab (differs from the fluid, Sec. 2.3)")

    def scenario(self, clutch: WetClutch) -> Scenario:
        """Reference profiles and initial conditions for the bench."""
        t1 = self.preload_time
        t2 = t1 + self.spin_up_time
        t3 = t2 + self.hold_time
        t4 = t3 + self.decay_time
        w = self.slip_speed
        return Scenario(
            force_time=[0.0, 0.2], force_value=[0.0, self.force],
            speed_time=[0.0, t1, t2, t3, t4], speed_value=[0.0, 0.0, w, w, w * self.final_slip_fraction],
            duration=t4, motor="speed", initial_slip_speed=0.0,
            initial_temperature_c=_pack_equilibrium(clutch, self.fluid_temperature, self.housing_temperature),
            fluid_temperature_c=self.fluid_temperature, housing_temperature_c=self.housing_temperature)


def smoothed_ramp(time, start, duration, initial, final=0.0):
    """Smoothed ramp from ``initial`` to ``final`` (cubic smoothstep, C1) [same unit as initial].

    Parameters
    ----------
    time : float or array_like
        Times [s] at which to evaluate the ramp.
    start : float
        Start of the ramp [s] (``initial`` before it).
    duration : float
        Length of the ramp [s] (``final`` after ``start + duration``).
    initial, final : float
        Values before and after the ramp.
    """
    s = np.clip((np.asarray(time, dtype=float) - start) / duration, 0.0, 1.0)
    return initial + (final - initial) * (3.0 * s**2 - 2.0 * s**3)


@dataclasses.dataclass(frozen=True)
class EngagementProtocol(ParameterSet):
    """Protocols (b) and (c): engagement of Fig. 14 on the bench or on an inertia dynamometer."""

    kind: ClassVar[str] = "protocol"

    force: float = quantity(3000.0, "N", "pressing force after the rise", source="clutchlab", positive=True)
    force_delay: float = quantity(0.05, "s", "time before the force rise starts", source="clutchlab", nonnegative=True)
    force_rise_time: float = quantity(0.2, "s", "force raised over", source="Sec. 4 (Fig. 14)", positive=True)
    initial_slip_speed: float = quantity(1500 * math.pi / 30, "rad/s", "slip speed at the start", source="clutchlab",
                                         positive=True)
    ramp_start: float = quantity(0.15, "s", "start of the slip ramp-down reference", source="clutchlab",
                                 nonnegative=True)
    ramp_time: float = quantity(0.7, "s", "duration of the smoothed ramp-down", source="clutchlab", positive=True)
    duration: float = quantity(1.2, "s", "simulated time", source="Sec. 4: about 1 s", positive=True)
    fluid_temperature: float = quantity(80.0, "degC", "reservoir temperature", source="clutchlab")
    housing_temperature: float = quantity(70.0, "degC", "housing temperature", source="clutchlab")

    def scenario(self, clutch: WetClutch, motor: str = "speed") -> Scenario:
        """Profiles for the bench (``motor="speed"``) or the inertia dynamometer (``"free"``)."""
        t_r = np.linspace(self.ramp_start, self.ramp_start + self.ramp_time, 41)
        st = np.concatenate([[0.0], t_r]) if self.ramp_start > 0 else t_r
        sv = smoothed_ramp(st, self.ramp_start, self.ramp_time, self.initial_slip_speed)
        ft = [0.0, self.force_delay, self.force_delay + self.force_rise_time] if self.force_delay > 0 else \
            [0.0, self.force_rise_time]
        fv = [0.0, 0.0, self.force] if self.force_delay > 0 else [0.0, self.force]
        return Scenario(
            force_time=ft, force_value=fv, speed_time=st, speed_value=sv, duration=self.duration, motor=motor,
            initial_slip_speed=self.initial_slip_speed,
            initial_temperature_c=_pack_equilibrium(clutch, self.fluid_temperature, self.housing_temperature),
            fluid_temperature_c=self.fluid_temperature, housing_temperature_c=self.housing_temperature)


@dataclass
class BenchRun:
    """A protocol run: the simulation (truth) and the measured record with noise.

    Attributes
    ----------
    protocol : ParameterSet
        The protocol that was run; ``protocol_type`` names it (map, engagement, inertia).
    result : EngagementResult
        The noise-free simulation (the truth).
    record : pandas.DataFrame
        Measured channels with sensor noise, as the bench writes them.
    clutch, bench : WetClutch, Bench
        Parameters of the clutch and the bench used.
    friction : object
        The true friction law of the run.
    seed : int
        Seed of the sensor noise.
    """

    protocol: ParameterSet
    protocol_type: str
    result: EngagementResult
    record: pd.DataFrame
    clutch: WetClutch
    bench: Bench
    friction: object
    seed: int = 0

    def header(self) -> str:
        """Comment block for the CSV file (marks the data synthetic)."""
        lines = [
            f"synthetic: clutchlab virtual wet-clutch bench (Shin, Kim, Choi, Fig. 4), protocol {self.protocol_type}",
            "synthetic: not measured data; generated by clutchlab.wet.bench with sensor noise, seed "
            f"{self.seed}, sampled at {self.bench.sample_rate:g} Hz",
            "protocol: " + ", ".join(f"{k}={v}" for k, v in self.protocol.to_dict(with_units=True).items()),
        ]
        if isinstance(self.friction, ParametricFriction):
            lines.append("true friction law: " + ", ".join(f"{k}={v:.6g}" for k, v in self.friction.to_dict().items()))
        lines.append(f"true k1={self.clutch.k1:.6g} W/K, k2={self.clutch.k2:.6g} W/K")
        return "\n".join(lines)


def measure(result: EngagementResult, bench: Bench, seed: int | None = None) -> pd.DataFrame:
    """Turn a simulation into a measured bench record with sensor noise.

    Torque from the torque sensor (clutch torque plus the shaft inertia
    term), slip from the encoder, force from the load cell, piston position,
    thermistor temperature (lagged state) and the fluid and housing sensors,
    each with Gaussian noise of the bench's standard deviations.

    Parameters
    ----------
    result : EngagementResult
        Simulation with outputs.
    bench : Bench
        Noise levels (standard deviations) and default seed.
    seed : int, optional
        Seed of the noise generator (default ``bench.seed``).

    Returns
    -------
    pandas.DataFrame
        The record channels :data:`RECORD_COLUMNS`.
    """
    rng = np.random.default_rng(bench.seed if seed is None else seed)
    n = result.time.size

    def noisy(x, s):
        return x + (rng.normal(0.0, s, n) if s > 0 else 0.0)

    return pd.DataFrame({
        "time_s": result.time,
        "slip_speed_rad_s": noisy(result.state("slip_speed_rad_s"), bench.noise_speed),
        "torque_Nm": noisy(result.output("sensor_torque_Nm"), bench.noise_torque),
        "force_N": noisy(result.output("load_cell_force_N"), bench.noise_force),
        "piston_position_m": noisy(result.state("piston_position_m"), bench.noise_position),
        "temperature_C": noisy(result.state("thermistor_temperature_C"), bench.noise_temperature),
        "fluid_temperature_C": noisy(result.state("fluid_temperature_C"), bench.noise_fluid_temperature),
        "housing_temperature_C": noisy(result.state("housing_temperature_C"), bench.noise_fluid_temperature),
    })


PROTOCOL_TYPES = ("friction_map", "engagement", "inertia_dynamometer")


def run_protocol(protocol, clutch: WetClutch | None = None, bench: Bench | None = None, friction=None, *,
                 protocol_type: str | None = None, seed: int | None = None, rtol: float = 1e-7, atol=None,
                 max_step: float = 0.01, output_step: float | None = None,
                 fixed_step: float | None = None) -> BenchRun:
    """Run a protocol on the virtual bench and return truth and noisy record.

    Parameters
    ----------
    protocol : MapProtocol or EngagementProtocol
        What to run.
    clutch : WetClutch, optional
        Clutch in the rig (default Table 1).
    bench : Bench, optional
        Rig (default ``Bench()``); its ``sample_rate`` sets the record rate.
    friction : ParametricFriction or FrictionMap, optional
        The clutch's true friction law (default
        :meth:`ParametricFriction.bench_truth`).
    protocol_type : {"friction_map", "engagement", "inertia_dynamometer"}, optional
        Needed for an :class:`EngagementProtocol` (default "engagement").
    seed : int, optional
        Noise seed (default ``bench.seed``).
    rtol, atol, max_step : optional
        Step control of the run (:func:`~clutchlab.wet.engagement.simulate_engagement`).
    output_step : float, optional
        Record interval [s] instead of the bench's ``sample_rate``.
    fixed_step : float, optional
        Fixed-step (real-time, HIL frame) mode with this step [s]
        (:func:`~clutchlab.wet.engagement.simulate_engagement`).  None
        (default): step-size control.
    """
    clutch = WetClutch.paper() if clutch is None else clutch
    bench = Bench() if bench is None else bench
    friction = ParametricFriction.bench_truth() if friction is None else friction
    if isinstance(protocol, MapProtocol):
        ptype = "friction_map"
        scen = protocol.scenario(clutch)
    elif isinstance(protocol, EngagementProtocol):
        ptype = protocol_type or "engagement"
        if ptype not in ("engagement", "inertia_dynamometer"):
            raise ParameterError(f"protocol_type = {ptype!r}: expected 'engagement' or 'inertia_dynamometer'")
        scen = protocol.scenario(clutch, motor="speed" if ptype == "engagement" else "free")
    else:
        raise ParameterError(f"protocol = {protocol!r}: expected a MapProtocol or an EngagementProtocol")
    res = simulate_engagement(clutch, scen, bench=bench, friction=friction,
                              sample_rate=bench.sample_rate if output_step is None else None, rtol=rtol, atol=atol,
                              max_step=max_step, output_step=output_step, fixed_step=fixed_step)
    seed = bench.seed if seed is None else int(seed)
    return BenchRun(protocol, ptype, res, measure(res, bench, seed), clutch, bench, friction, seed)


def write_bench_record(run_or_frame, path, *, overwrite: bool = False, header: str | None = None,
                       every: int = 1):
    """Write a bench record (CSV, Parquet or MDF 4 by the suffix; ``#`` header marks it synthetic), atomically.

    Written through :func:`clutchlab.io.write_measurement`: the units of the
    channels go into the file (a ``# units:`` line in CSV).

    Parameters
    ----------
    run_or_frame : BenchRun or pandas.DataFrame
        A protocol run (its header says what generated it) or a record.
    path : str or Path
        File to write (``.csv``, ``.parquet`` or ``.mf4``).
    overwrite : bool
        Replace an existing file.
    header : str, optional
        Comment lines (default: the run's header, or a synthetic-data note).
    every : int
        Keep every n-th sample (to make small example files).
    """
    if isinstance(run_or_frame, BenchRun):
        frame = run_or_frame.record
        header = run_or_frame.header() if header is None else header
    else:
        frame = run_or_frame
    if not isinstance(every, int) or every < 1:
        raise ParameterError(f"every = {every!r}: must be a positive whole number")
    if every > 1 and header:
        header = header + f"\nstored: every {every}th sample"

    missing = [c for c in RECORD_COLUMNS if c not in frame.columns]
    if missing:
        raise DataError(f"bench record lacks column {missing[0]!r}")
    return write_measurement(frame.loc[:, list(RECORD_COLUMNS)].iloc[::every].reset_index(drop=True), path,
                             overwrite=overwrite, comment=header or "synthetic: clutchlab virtual bench")


def read_bench_record(path, channel_map=None, *, rate: float | None = None) -> pd.DataFrame:
    """Read a bench record (CSV, Parquet or MDF 4) and validate its channels.

    Read through :func:`clutchlab.io.read_measurement`: ``#`` comment lines of
    a CSV are skipped, units stored in the file are converted to the ones the
    column names state, a logger's channel names are mapped by
    ``channel_map``.

    Parameters
    ----------
    path : str, Path or pandas.DataFrame
        Record with the channels ``time_s, slip_speed_rad_s, torque_Nm,
        force_N, piston_position_m, temperature_C, fluid_temperature_C,
        housing_temperature_C`` (SI, temperatures in degC), or a file whose
        channels ``channel_map`` maps onto them.
    channel_map : ChannelMap, mapping or TOML path, optional
        Logger channel names and units -> the names above
        (:class:`clutchlab.io.ChannelMap`).
    rate : float, optional
        Resample onto a uniform time base [Hz] (channels logged at different
        rates are otherwise put onto the fastest channel's timestamps).

    Returns
    -------
    pandas.DataFrame
        The eight channels as float columns.

    Raises
    ------
    DataError
        Missing file or column, NaN or non-numeric value (naming the file,
        the column and the row), time not strictly increasing, fewer than 10
        samples.
    """
    frame = read_measurement(path, channel_map, required=RECORD_COLUMNS, rate=rate).frame
    label = str(path) if not isinstance(path, pd.DataFrame) else "record"
    t = frame["time_s"].to_numpy()
    if t.size < 10:
        raise DataError(f"{label}: needs at least 10 samples, has {t.size}")
    return frame.loc[:, list(RECORD_COLUMNS)].reset_index(drop=True)


def load_protocol(path):
    """Read a protocol TOML file.

    The file has a ``[protocol]`` table with ``type`` (``"friction_map"``,
    ``"engagement"`` or ``"inertia_dynamometer"``) and the protocol's fields
    (values may carry units: ``force = "1.7 kN"``, ``slip_speed = "300 rpm"``),
    and optional ``[wet]`` (clutch), ``[bench]`` and ``[friction]`` (true
    friction law) tables overriding the defaults.

    Parameters
    ----------
    path : str or Path
        Protocol TOML file.

    Returns
    -------
    (protocol, protocol_type, clutch, bench, friction)
    """
    data = load_toml(path)
    src = str(path)
    unknown = [k for k in data if k not in ("protocol", "wet", "bench", "friction")]
    if unknown:
        raise ParameterError(f"{src}: unknown table [{unknown[0]}] (known: protocol, wet, bench, friction)")
    if "protocol" not in data or not isinstance(data["protocol"], dict):
        raise ParameterError(f"{src}: missing [protocol] table")
    table = dict(data["protocol"])
    ptype = table.pop("type", None)
    if ptype not in PROTOCOL_TYPES:
        raise ParameterError(f"{src}: [protocol] type = {ptype!r}: expected one of {', '.join(PROTOCOL_TYPES)}")
    cls = MapProtocol if ptype == "friction_map" else EngagementProtocol
    protocol = cls.from_dict(table, source=src)
    clutch = WetClutch.from_dict(data.get("wet", {}), source=src)
    bench = Bench.from_dict(data.get("bench", {}), source=src)
    friction = ParametricFriction.from_dict(data["friction"], source=src, base=ParametricFriction.bench_truth()) \
        if "friction" in data else ParametricFriction.bench_truth()
    return protocol, ptype, clutch, bench, friction


def protocol_system(protocol: EngagementProtocol | None = None, *, clutch: WetClutch | None = None,
                    bench: Bench | None = None, friction=None, motor: str = "speed", rtol: float = 1e-7):
    """The :class:`~clutchlab.system.System` of a bench protocol's engagement (the model ``"wet"``).

    Parameters
    ----------
    protocol : EngagementProtocol, optional
        Default ``EngagementProtocol()`` (protocol (b), Sec. 4, Fig. 14).
    clutch : WetClutch, optional
        Default :meth:`WetClutch.paper`.
    bench : Bench, optional
        Default ``Bench()``.
    friction : ParametricFriction or FrictionMap, optional
        Default :meth:`ParametricFriction.bench_truth`.
    motor : {"speed", "free"}
        The bench's speed-controlled motor or the inertia dynamometer.
    rtol : float
        The system's default relative tolerance.

    Returns
    -------
    System
        :func:`clutchlab.wet.system.engagement_system` of the protocol's scenario.
    """
    clutch = WetClutch.paper() if clutch is None else clutch
    scenario = (EngagementProtocol() if protocol is None else protocol).scenario(clutch, motor)
    return W.engagement_system(scenario, clutch=clutch, bench=bench, friction=friction, rtol=rtol)


register_model("wet", protocol_system)
