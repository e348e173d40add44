"""Shift quality: the phases and the metrics of a clutch-to-clutch gear shift (a dual-clutch or planetary automatic
transmission's power shift), from a run or from a rig's record.

A power upshift hands the drive from the off-going clutch to the on-coming one in two phases:

* the **torque phase**: the on-coming clutch, slipping, takes up the torque while the off-going one, still stuck,
  lets go of it; the engine keeps its speed and the output torque sags towards the higher gear's (the torque
  hole);
* the **inertia phase**: the off-going clutch carries nothing, the on-coming one slides and pulls the engine
  down to the new gear's speed; it ends when the on-coming clutch locks, and the step of its friction torque
  there (the slip's rate at lock-up times the inertia it stops) is the lock-up shock.

A power-on downshift runs the phases the other way round (the off-going clutch slips first so the engine can
speed up, then the on-coming one takes the torque); so does a coast upshift (the engine's drag slows it once the
off-going clutch slips), while a coast downshift runs them as a power-on upshift does.  A shift's direction (up or
down: the engine's speed over the output's falls or rises) and its sequence (torque phase first or inertia phase
first) are therefore two things, :attr:`ShiftQuality.order` and :attr:`ShiftQuality.sequence`.

An automated manual transmission (AMT) shifts with the drive **interrupted**: the engine's torque is taken down and
the clutch opens (the release), the off-going gear's sleeve is pulled out, the on-coming gear's synchroniser pulls
the input shaft onto the new gear's speed and its dogs engage (the synchronisation), and the clutch closes again
(the closing) while the engine's torque comes back.  The vehicle coasts through the torque interruption.

The seeds do not treat shifts; the metrics are the ones shift calibration uses (the vehicle's longitudinal
acceleration, its jerk and vibration dose value, the phases' times, the engine's flare and the off-going clutch's
tie-up, and the clutches' heat), each defined below from sampled columns only, so a simulated run and a rig's record
are measured by the same code (docs/control.md, "Shift quality").

* :func:`shift_quality` -- the phases and metrics of one shift: :class:`ShiftQuality`.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..errors import ParameterError

__all__ = ["ShiftQuality", "shift_quality", "METRICS", "INTERRUPTED_METRICS", "metric_names", "sample_interval",
           "SHIFT_FIELDS"]

#: the metrics of what the driver feels, the same for every kind of shift (name, unit, description), as
#: :data:`METRICS`
_RIDE = (
    ("acceleration_before_{a}", "{a}", "the output's acceleration at the start (mean over the pre-window)"),
    ("acceleration_dip_{a}", "{a}", "the torque hole: the acceleration at the start less its least value during "
                                    "the shift"),
    ("acceleration_peak_to_peak_{a}", "{a}", "the largest less the least acceleration from the start to the end of "
                                             "the settling window"),
    ("jerk_peak_{j}", "{j}", "the largest |d a/dt| from the start to the end of the settling window"),
    ("vdv_{v}", "{v}", "vibration dose value of the acceleration's change from its value at the start, "
                       "(integral of (a - a_before)^4 dt)^(1/4) over the shift and the settling window "
                       "(ISO 2631-1's form, without its frequency weighting)"),
)

#: the metrics of :class:`ShiftQuality` (name, unit, description); ``{a}`` is the unit of the acceleration
#: (``m_s2`` with a radius, else ``rad_s2``), ``{j}`` of the jerk, ``{v}`` of the vibration dose value
METRICS = (
    ("shift_time_s", "s", "from the shift's start to its end (the later of the hand-over and the lock-up)"),
    ("torque_phase_s", "s", "both clutches carry torque: from the start to the hand-over (torque phase first), "
                            "from the lock-up to the hand-over (inertia phase first; 0 where the off-going clutch "
                            "let go before the lock-up)"),
    ("inertia_phase_s", "s", "the on-coming clutch slides alone: from the hand-over to the lock-up (torque phase "
                             "first), from the start to the lock-up (inertia phase first)"),
    *_RIDE,
    ("lockup_slip_rate_rad_s2", "rad_s2", "|d w_rel / dt| of the on-coming clutch over the last sample interval "
                                          "in which it slides before it locks (the lock-up shock's cause)"),
    ("flare_rad_s", "rad_s", "the off-going clutch's largest slip the way it drove before the start, during the "
                             "shift: the engine running ahead of the old gear (an off-going clutch released too "
                             "early where the torque phase comes first; the inertia phase where it comes first)"),
    ("tie_up_Nm", "Nm", "the largest torque the off-going clutch carries against the way it carried the drive "
                        "before the start (it brakes the engine against the on-coming one): released too late"),
    ("offgoing_energy_J", "J", "heat of the off-going clutch during the shift, integral of |tau w_rel| dt"),
    ("oncoming_energy_J", "J", "heat of the on-coming clutch during the shift, integral of |tau w_rel| dt"),
    ("offgoing_peak_power_W", "W", "largest |tau w_rel| of the off-going clutch during the shift"),
    ("oncoming_peak_power_W", "W", "largest |tau w_rel| of the on-coming clutch during the shift"),
)


#: the metrics of an interrupted (AMT) shift (:func:`shift_quality` with a ``clutch``), as :data:`METRICS`
INTERRUPTED_METRICS = (
    ("shift_time_s", "s", "from the shift's start to the clutch's lock-up after the new gear is in"),
    ("release_time_s", "s", "from the start to the clutch carrying nothing (the engine's torque taken down, the "
                            "clutch opened)"),
    ("neutral_time_s", "s", "from the clutch's opening to the on-coming synchroniser's cone taking up torque "
                            "(the off-going sleeve pulled out, the on-coming one pushed in)"),
    ("synchronisation_time_s", "s", "the on-coming synchroniser's cone slides: from its first torque to its dogs' "
                                    "engagement (its slip within the threshold from there to the end)"),
    ("closing_time_s", "s", "from the dogs' engagement to the clutch's lock-up"),
    ("torque_interruption_s", "s", "the clutch carries nothing: from its opening to its first torque after the "
                                   "dogs' engagement"),
    *_RIDE,
    ("lockup_slip_rate_rad_s2", "rad_s2", "|d w_rel / dt| of the clutch over the last sample interval in which it "
                                          "slides before it locks (the lock-up shock's cause)"),
    ("pull_out_torque_Nm", "Nm", "the largest torque the off-going synchroniser carries from the clutch's opening "
                                 "to its release (the load its sleeve is pulled out against)"),
    ("synchroniser_energy_J", "J", "heat of the on-coming synchroniser's cone, integral of |tau w_rel| dt"),
    ("synchroniser_peak_power_W", "W", "largest |tau w_rel| of the on-coming synchroniser's cone"),
    ("clutch_energy_J", "J", "heat of the clutch during the shift, integral of |tau w_rel| dt"),
    ("clutch_peak_power_W", "W", "largest |tau w_rel| of the clutch during the shift"),
)


#: the keys of a driveline file's ``[shift]`` table (the shift its network makes, for ``clutchlab control shift`` and
#: the sweep's ``shift.<metric>`` outputs): key -> SI unit of a quantity, or None for a name of the network
SHIFT_FIELDS = {"offgoing": None, "oncoming": None, "output": None, "engine": None, "clutch": None, "radius": "m",
                "threshold": "1", "settle": "s", "pre": "s", "start": "s"}


def metric_names(vehicle: bool, interrupted: bool = False) -> dict:
    """The metrics' names (:data:`METRICS`; ``interrupted``: an AMT shift's, :data:`INTERRUPTED_METRICS`) -> their
    units, with the acceleration in m/s^2 (``vehicle``: a radius given, or the vehicle's speed as the output) or in
    rad/s^2."""
    a, j, v = ("m_s2", "m_s3", "m_s1_75") if vehicle else ("rad_s2", "rad_s3", "rad_s1_75")
    return {name.format(a=a, j=j, v=v): unit.format(a=a, j=j, v=v)
            for name, unit, _ in (INTERRUPTED_METRICS if interrupted else METRICS)}


@dataclasses.dataclass(frozen=True)
class ShiftQuality:
    """The phases and metrics of one shift (:func:`shift_quality`).

    Attributes
    ----------
    start_s, handover_s, lockup_s, end_s : float
        The shift's start, the off-going clutch's hand-over (its torque below the threshold), the on-coming
        clutch's lock-up (its slip within the threshold from there to the end of the record) and the end
        (the later of the two) [s].  An interrupted shift's (``kind == "interrupted"``): the start, the clutch's
        opening, the on-coming synchroniser's dogs engaging and the clutch's lock-up.
    order : str
        ``"upshift"`` or ``"downshift"``: the engine's speed over the output's falls or rises from the start to the
        end (read where there is an ``engine`` column and the two differ).  A power shift without one is named by
        its sequence as a power-on shift would be: ``"upshift"`` where the torque phase comes first, else
        ``"downshift"`` (a coast shift's is then the other way round); an interrupted shift's is ``"shift"``.
    metrics : dict
        Name (with its unit's suffix, :data:`METRICS`) -> value.
    columns : dict
        The columns read: ``output``, ``offgoing``, ``oncoming``, ``engine``.
    trace : pandas.DataFrame
        The samples the metrics were read from: ``time_s``, the acceleration and the jerk (their units' suffixes
        as the metrics'), the two clutches' ``|tau|`` [N m], ``|w_rel|`` [rad/s] and ``|tau w_rel|`` [W] (an
        interrupted shift's: the two synchronisers', and the clutch's as ``clutch_*``), and the engine's speed where
        there is one (:func:`clutchlab.control.plots.shift_figure` draws them).
    kind : str
        ``"power"`` (a clutch-to-clutch shift) or ``"interrupted"`` (an AMT's, through its clutch and
        synchronisers).
    sequence : str
        A power shift's phases in their order: ``"torque_first"`` (the hand-over before the lock-up, the on-coming
        clutch carrying torque by then: a power-on upshift, a coast downshift) or ``"inertia_first"`` (a power-on
        downshift, a coast upshift, also one whose off-going clutch lets go before the on-coming one takes anything
        up); ``""`` for an interrupted shift.
    """

    start_s: float
    handover_s: float
    lockup_s: float
    end_s: float
    order: str
    metrics: dict
    columns: dict
    trace: object = dataclasses.field(default=None, repr=False, compare=False)
    kind: str = "power"
    sequence: str = ""

    def to_dict(self) -> dict:
        """Everything as plain numbers and strings (JSON; NaN as None)."""
        def plain(v):
            return None if isinstance(v, float) and not math.isfinite(v) else v

        return {"kind": self.kind, "start_s": self.start_s, "handover_s": self.handover_s,
                "lockup_s": self.lockup_s, "end_s": self.end_s, "order": self.order, "sequence": self.sequence,
                "columns": dict(self.columns),
                "metrics": {k: plain(float(v)) for k, v in self.metrics.items()}}

    def table(self):
        """The metrics as a DataFrame: ``metric``, ``value``, ``unit``, ``description``."""
        import pandas as pd

        units, docs = self._described()
        return pd.DataFrame({"metric": list(self.metrics), "value": [float(v) for v in self.metrics.values()],
                             "unit": [units[k] for k in self.metrics], "description": [docs[k] for k in self.metrics]})

    def _described(self):
        interrupted = self.kind == "interrupted"
        units = metric_names("acceleration_dip_m_s2" in self.metrics, interrupted)
        return units, dict(zip(units, (doc for _, _, doc in (INTERRUPTED_METRICS if interrupted else METRICS))))

    def __str__(self) -> str:
        units, _ = self._described()
        if self.kind == "interrupted":
            head = (f"{self.order} (interrupted) from {self.start_s:.4f} s: clutch open at {self.handover_s:.4f} s, "
                    f"gear in at {self.lockup_s:.4f} s, clutch locked at {self.end_s:.4f} s")
        else:
            first = {"torque_first": " (torque phase first)", "inertia_first": " (inertia phase first)"}
            head = (f"{self.order}{first.get(self.sequence, '')} from {self.start_s:.4f} s: hand-over at "
                    f"{self.handover_s:.4f} s, lock-up at {self.lockup_s:.4f} s")
        rows = [f"  {k:<34s} {v:>12.5g} {units[k]}" for k, v in self.metrics.items()]
        return "\n".join([head, *rows])


def sample_interval(t, what: str) -> float:
    """The constant interval [s] of the sample times ``t`` (within 1e-6 of their median spacing); else a
    :class:`~clutchlab.errors.ParameterError` naming ``what`` (a record's filters and differences need it)."""
    dt = np.diff(t)
    h = float(np.median(dt))
    if not h > 0 or np.max(np.abs(dt - h)) > 1e-6 * h:
        raise ParameterError(f"{what}: time_s must be sampled at a constant interval (from {dt.min():g} to "
                             f"{dt.max():g} s); resample it first")
    return h


def _trapezoid(y, x) -> float:
    """The trapezoid rule's integral of samples ``y`` over ``x`` (0 for fewer than two)."""
    return float(np.sum((y[1:] + y[:-1]) * np.diff(x)) / 2.0) if len(x) > 1 else 0.0


def _column(frame, name: str, suffix: str, what: str, label: str) -> str:
    """The column of ``name``: itself if it is one, else ``<name>.<suffix>`` (``label``: the source, for the
    message)."""
    if name in frame.columns:
        return name
    col = f"{name}.{suffix}"
    if col not in frame.columns:
        raise ParameterError(f"{label}: {what} {name!r}: no column {name!r} or {col!r} (columns: "
                             f"{', '.join(map(str, frame.columns))})")
    return col


def shift_quality(frame, *, offgoing: str, oncoming: str, output: str, engine: str | None = None,
                  clutch: str | None = None, radius: float | None = None, start: float | None = None,
                  threshold: float = 0.02, settle: float = 0.3, pre: float = 0.05,
                  filter_Hz: float | None = None) -> ShiftQuality:
    """The phases and the quality metrics of one gear shift in a run or a rig's record: a clutch-to-clutch (power)
    shift, or with ``clutch`` an automated manual transmission's (interrupted) shift.

    Parameters
    ----------
    frame : pandas.DataFrame, SimulationResult, Measurement, str or Path
        Samples with ``time_s`` at a constant interval: a run (its ``to_dataframe()``), a record read by
        :func:`clutchlab.io.read_measurement` (a rig's CSV, Parquet, MDF 4 or CAN log through a channel map into
        clutchlab's names and SI units, resampled with its ``rate``), or such a file whose channels already carry
        the names below (read without a map).
    offgoing, oncoming : str
        The two clutches (with ``clutch``: the off-going and the on-coming gear's synchronisers): their columns
        ``<name>.tau_Nm`` (friction torque [N m]) and ``<name>.w_rel_rad_s`` (slip speed [rad/s]) are read, in one
        sign convention: a sliding clutch's torque has its slip's sign (clutchlab's and the Modelica library's;
        where a rig's logger differs, negate one of the two columns of its record first), which the flare and the
        tie-up read.
    output : str
        The output shaft's (or the wheels') speed: a column, or an inertia whose ``<name>.w_rad_s`` is read; or the
        vehicle's speed, a column whose name ends in ``_m_s`` [m/s] (a rig's or a CAN log's), whose derivative is
        the acceleration in m/s^2 without a ``radius``.
    engine : str, optional
        The engine's (the transmission input's) speed, drawn by :func:`clutchlab.control.plots.shift_figure`: a
        column or an inertia.  An interrupted shift's order (up or down) is read from it.
    clutch : str, optional
        An AMT's clutch (its ``<name>.tau_Nm`` and ``<name>.w_rel_rad_s``): the shift is then an interrupted one,
        measured by :data:`INTERRUPTED_METRICS` (see Notes).
    radius : float, optional
        [m] the vehicle's travel per radian of ``output`` (the tyre's rolling radius over the axle ratio behind
        it): the acceleration in m/s^2, the jerk in m/s^3; without it, the output's angular acceleration.
    start : float, optional
        [s] the shift's start; default: the first sample at which the on-coming clutch carries more than
        ``threshold`` of the largest torque of the two clutches, or the off-going clutch, stuck before, slides
        by more than ``threshold`` of the largest slip of the two, whichever comes first.  An interrupted shift's
        default is the clutch's opening: give the start (the shift's command) to count the engine's torque
        reduction before it in the release time and the acceleration's dip.
    threshold : float
        Fraction (0, 0.5) of the largest torque, and of the largest slip, below which a clutch counts as carrying
        nothing, and as locked.
    settle : float
        [s] the acceleration, jerk and dose value are read up to this long after the shift's end (the lock-up
        shock rings in the driveline's first mode).
    pre : float
        [s] the acceleration before the shift is the mean over this long before its start.
    filter_Hz : float, optional
        A rig's acceleration is noisy: the output's speed is low-pass filtered at this frequency (fourth-order
        Butterworth, forwards and backwards: no phase shift) before it is differentiated.  None: no filter (a
        simulated run).

    Returns
    -------
    ShiftQuality

    Notes
    -----
    The acceleration is the output speed's central difference (``numpy.gradient``, second order), times
    ``radius``; the jerk the acceleration's.  The energies and peak powers integrate ``|tau w_rel|`` of the two
    clutches by the trapezoid rule over ``[start, end]``, which equals the clutch's dissipated energy to the
    sampling's error.  The phases are found from the columns alone (no events), as on a rig: the hand-over is the
    first sample from the start on at which the off-going clutch carries at most the threshold, the lock-up the
    first sample from which the on-coming clutch's slip stays within the threshold to the end of the record: each
    is off its instant (the start late, the hand-over and the lock-up early) by at most the threshold's share of
    its ramp (the threshold times the largest slip over the slip's rate at lock-up, for the lock-up) plus one
    sample.  A simulated run's columns are exact: a smaller threshold (``1e-4``) puts the instants on the events.
    The acceleration, jerk and dose value are read to the end of the settling window or of the record,
    whichever comes first.

    An interrupted shift's phases, read the same way: the on-coming synchroniser's engagement is the first sample
    from which its slip stays within the threshold of its largest slip to the end; the clutch's opening the first
    sample from which it carries at most the threshold of its largest torque up to that engagement; its cone's first
    torque the first sample after the opening at which it carries more than the threshold of its largest torque
    before that engagement (the cone's, not the dogs'); the off-going synchroniser's release the first sample after
    the opening at which it slides beyond the threshold; the clutch's lock-up (the shift's end) the first sample
    after the engagement from which its slip stays within the threshold to the end.
    """
    from ..io.files import read_table

    label = "shift_quality"
    if hasattr(frame, "source") and hasattr(frame, "frame"):   # a Measurement: its file in the messages
        label = str(frame.source.path or label)
        frame = frame.frame
    elif hasattr(frame, "to_dataframe"):
        frame = frame.to_dataframe()
    elif not hasattr(frame, "columns"):   # a file: its path in the messages
        from ..io import read_measurement

        label = str(frame)
        frame = read_measurement(frame).frame
    head = frame
    cols = {"output": _column(head, output, "w_rad_s", "output", label),
            "offgoing": offgoing, "oncoming": oncoming,
            "engine": None if engine is None else _column(head, engine, "w_rad_s", "engine", label)}
    if clutch is not None:
        cols["clutch"] = clutch
    frictions = (offgoing, oncoming) + (() if clutch is None else (clutch,))
    need = ["time_s", cols["output"]] + [f"{c}.{q}" for c in frictions for q in ("tau_Nm", "w_rel_rad_s")]
    need += [cols["engine"]] if cols["engine"] else []
    for c in need:
        if c not in head.columns:
            raise ParameterError(f"{label}: no column {c!r} (columns: {', '.join(map(str, head.columns))})")
    df = read_table(head, need, name=label)
    if not 0.0 < threshold < 0.5:
        raise ParameterError(f"shift_quality: threshold = {threshold!r} must lie in (0, 0.5)")
    for name, value in (("settle", settle), ("pre", pre)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0.0):
            raise ParameterError(f"shift_quality: {name} = {value!r} s must be finite and >= 0")
    if radius is not None and not (math.isfinite(radius) and radius > 0.0):
        raise ParameterError(f"shift_quality: radius = {radius!r} m must be finite and > 0")
    linear = cols["output"].endswith("_m_s")   # (the vehicle's speed [m/s]: its derivative is in m/s^2 already)
    if linear and radius is not None:
        raise ParameterError(f"shift_quality: output {cols['output']!r} is a speed in m/s: give no radius")
    t = df["time_s"].to_numpy(float)
    if t.size < 8:
        raise ParameterError(f"shift_quality: needs at least 8 samples (got {t.size})")
    h = sample_interval(t, label)
    if start is not None and not (isinstance(start, (int, float)) and t[0] <= start < t[-1]):
        raise ParameterError(f"shift_quality: start = {start!r} s is outside the record [{t[0]:g}, {t[-1]:g}] s")
    signed_off = df[f"{offgoing}.tau_Nm"].to_numpy(float)
    tau_off, tau_on = np.abs(signed_off), np.abs(df[f"{oncoming}.tau_Nm"].to_numpy(float))
    w_off, w_on = (np.abs(df[f"{c}.w_rel_rad_s"].to_numpy(float)) for c in (offgoing, oncoming))

    def first(mask, frm=0, what=""):
        idx = np.flatnonzero(mask[frm:])
        if idx.size == 0:
            raise ParameterError(f"shift_quality: {what} within the record (to {t[-1]:g} s)")
        return frm + int(idx[0])

    def locks(w, w_thr, name, frm=0):
        """The first sample from which the slip ``w`` stays within ``w_thr`` to the end (not before ``frm``)."""
        moving = np.flatnonzero(w > w_thr)
        i = int(moving[-1]) + 1 if moving.size else 0
        if i >= len(t):
            raise ParameterError(f"shift_quality: {name} does not lock within the record (its slip is "
                                 f"{w[-1]:g} rad/s at {t[-1]:g} s)")
        return max(i, frm)

    def at(s0):
        return int(np.searchsorted(t, s0 - 1e-12 * max(1.0, abs(s0))))

    def direction(i_from, i_to):
        """``"upshift"`` or ``"downshift"``: the engine's speed over the output's falls or rises from sample
        ``i_from`` to ``i_to``; None without an engine column, or where the two ratios cannot be told apart."""
        if cols["engine"] is None:
            return None
        rows = [i_from, i_to]
        with np.errstate(divide="ignore", invalid="ignore"):
            r0, r1 = np.abs(df[cols["engine"]].to_numpy(float)[rows] / df[cols["output"]].to_numpy(float)[rows])
        if not (math.isfinite(r0) and math.isfinite(r1)) or r0 == r1:
            return None
        return "upshift" if r1 < r0 else "downshift"

    if clutch is not None:
        tau_c, w_c = (np.abs(df[f"{clutch}.{q}"].to_numpy(float)) for q in ("tau_Nm", "w_rel_rad_s"))
        if not tau_c.max() > 0.0:
            raise ParameterError(f"shift_quality: the clutch {clutch} carries no torque")
        c_thr, cw_thr = threshold * tau_c.max(), threshold * w_c.max()
        i_in = locks(w_on, threshold * w_on.max(), oncoming, at(start) if start is not None else 0)
        # the clutch's opening: from it to the dogs' engagement the clutch carries nothing (a torque passing zero
        # as the engine's torque is taken down is no opening)
        carried = np.flatnonzero(tau_c[:i_in + 1] > c_thr)
        if not carried.size:
            raise ParameterError(f"shift_quality: the clutch {clutch} carries nothing before {oncoming} engages at "
                                 f"{t[i_in]:g} s")
        i_open = int(carried[-1]) + 1
        if i_open > i_in:
            raise ParameterError(f"shift_quality: the clutch {clutch} carries torque when {oncoming} engages at "
                                 f"{t[i_in]:g} s: no interrupted shift")
        i0 = at(start) if start is not None else i_open
        if i0 > i_open:
            raise ParameterError(f"shift_quality: start = {start!r} s is after the clutch {clutch} opens at "
                                 f"{t[i_open]:g} s")
        cone = tau_on[i_open:i_in + 1]
        if not cone.size or not cone.max() > 0.0:
            raise ParameterError(f"shift_quality: the synchroniser {oncoming} carries no torque between the clutch's "
                                 f"opening at {t[i_open]:g} s and its engagement at {t[i_in]:g} s")
        i_sync = first(tau_on > threshold * cone.max(), i_open, f"{oncoming} never takes up torque")
        i_sync = min(i_sync, i_in)
        off_w = threshold * max(w_off.max(), w_on.max())
        i_free = first(w_off > off_w, i_open, f"the synchroniser {offgoing} is never released after the clutch's "
                                              f"opening at {t[i_open]:g} s")
        i_end = locks(w_c, cw_thr, f"the clutch {clutch}", i_in)
        i_back = first(tau_c > c_thr, i_in, f"the clutch {clutch} never carries torque again after {t[i_in]:g} s")
        ts, th, tl, te = t[i0], t[i_open], t[i_in], t[i_end]
        order = direction(i0, i_end) or "shift"
    else:
        t_ref = max(tau_off.max(), tau_on.max())
        w_ref = max(w_off.max(), w_on.max())
        if not t_ref > 0.0:
            raise ParameterError(f"shift_quality: neither {offgoing} nor {oncoming} carries any torque")
        t_thr, w_thr = threshold * t_ref, threshold * w_ref
        if start is None:
            i_on = first(tau_on > t_thr,
                         what=f"{oncoming} never carries more than {threshold:g} of the largest torque")
            stuck = np.flatnonzero(w_off <= w_thr)
            i_slip = len(t)
            if stuck.size:
                slid = np.flatnonzero(w_off[stuck[0]:] > w_thr)
                i_slip = stuck[0] + int(slid[0]) if slid.size else len(t)
            i0 = min(i_on, i_slip)
        else:
            i0 = at(start)
        i_hand = first(tau_off <= t_thr, i0, f"{offgoing} never lets go of its torque after {t[i0]:g} s")
        i_lock = locks(w_on, w_thr, oncoming, i0)
        i_end = max(i_hand, i_lock)
        # the sequence: torque phase first where the off-going clutch hands its torque over before the on-coming one
        # locks *and* the on-coming one carries torque by then (it took the torque over); an off-going clutch that
        # lets go with nothing taking over (a coast upshift easing it open: the drag then slows the engine) runs the
        # inertia phase first, the on-coming clutch taking the torque up only as it locks
        torque_first = i_hand <= i_lock and bool(np.max(tau_on[i0:i_hand + 1]) > t_thr)
        order = direction(i0, i_end) or ("upshift" if torque_first else "downshift")
        ts, th, tl, te = t[i0], t[i_hand], t[i_lock], t[i_end]

    speed = df[cols["output"]].to_numpy(float)
    if filter_Hz is not None:
        from scipy import signal

        nyquist = 0.5 / h
        if not (math.isfinite(filter_Hz) and 0.0 < filter_Hz < nyquist):
            raise ParameterError(f"shift_quality: filter_Hz = {filter_Hz!r} must lie in (0, {nyquist:g}) Hz, the "
                                 f"Nyquist frequency of the samples")
        speed = signal.sosfiltfilt(signal.butter(4, filter_Hz, fs=1.0 / h, output="sos"), speed)
    scale = 1.0 if radius is None else float(radius)
    acc = np.gradient(speed, t) * scale
    jerk = np.gradient(acc, t)
    before = (t >= ts - pre - 1e-12) & (t <= ts + 1e-12)
    a0 = float(np.mean(acc[before]))
    shift = slice(i0, i_end + 1)
    window = (t >= ts - 1e-12) & (t <= te + settle + 1e-12)
    tw = t[window]
    dev4 = (acc[window] - a0) ** 4
    vdv = _trapezoid(dev4, tw) ** 0.25
    p_off = tau_off * w_off
    p_on = tau_on * w_on
    a, j, v = ("m_s2", "m_s3", "m_s1_75") if radius is not None or linear else ("rad_s2", "rad_s3", "rad_s1_75")
    ride = {
        f"acceleration_before_{a}": a0,
        f"acceleration_dip_{a}": a0 - float(np.min(acc[shift])),
        f"acceleration_peak_to_peak_{a}": float(np.ptp(acc[window])),
        f"jerk_peak_{j}": float(np.max(np.abs(jerk[window]))),
        f"vdv_{v}": vdv,
    }

    def slip_rate(w, i_lock):
        # (the last interval both of whose ends slide: the lock-up may fall inside the one after it)
        return abs(float((w[i_lock - 2] - w[i_lock - 1]) / h)) if i_lock >= 2 else math.nan

    import pandas as pd

    trace = pd.DataFrame({"time_s": t, f"acceleration_{a}": acc, f"jerk_{j}": jerk,
                          "offgoing_torque_Nm": tau_off, "oncoming_torque_Nm": tau_on,
                          "offgoing_slip_rad_s": w_off, "oncoming_slip_rad_s": w_on,
                          "offgoing_power_W": p_off, "oncoming_power_W": p_on})
    if clutch is not None:
        p_c = tau_c * w_c
        values = {
            "shift_time_s": te - ts,
            "release_time_s": th - ts,
            "neutral_time_s": t[i_sync] - th,
            "synchronisation_time_s": tl - t[i_sync],
            "closing_time_s": te - tl,
            "torque_interruption_s": t[i_back] - th,
            **ride,
            "lockup_slip_rate_rad_s2": slip_rate(w_c, i_end),
            "pull_out_torque_Nm": float(np.max(tau_off[i_open:i_free + 1])),
            "synchroniser_energy_J": _trapezoid(p_on[shift], t[shift]),
            "synchroniser_peak_power_W": float(np.max(p_on[shift])),
            "clutch_energy_J": _trapezoid(p_c[shift], t[shift]),
            "clutch_peak_power_W": float(np.max(p_c[shift])),
        }
        trace["clutch_torque_Nm"] = tau_c
        trace["clutch_slip_rad_s"] = w_c
        trace["clutch_power_W"] = p_c
    else:
        # the off-going clutch's drive before the start: the sign of its torque at its largest over the pre-window
        pre_off = signed_off[before]
        way = float(np.sign(pre_off[np.argmax(np.abs(pre_off))])) if pre_off.size else 0.0
        tie_up = max(0.0, float(np.max(-way * signed_off[shift]))) if way != 0.0 else 0.0
        # (a sliding clutch's torque has its slip's sign: slipping the way its torque drove, the driving side runs
        # ahead)
        slip_off = df[f"{offgoing}.w_rel_rad_s"].to_numpy(float)
        flare = max(0.0, float(np.max(way * slip_off[shift]))) if way != 0.0 else 0.0
        values = {
            "shift_time_s": te - ts,
            "torque_phase_s": (th - ts) if torque_first else max(0.0, th - tl),
            "inertia_phase_s": (tl - th) if torque_first else (tl - ts),
            **ride,
            "lockup_slip_rate_rad_s2": slip_rate(w_on, i_lock),
            "flare_rad_s": flare,
            "tie_up_Nm": tie_up,
            "offgoing_energy_J": _trapezoid(p_off[shift], t[shift]),
            "oncoming_energy_J": _trapezoid(p_on[shift], t[shift]),
            "offgoing_peak_power_W": float(np.max(p_off[shift])),
            "oncoming_peak_power_W": float(np.max(p_on[shift])),
        }
    if cols["engine"] is not None:
        trace["engine_speed_rad_s"] = df[cols["engine"]].to_numpy(float)
    return ShiftQuality(float(ts), float(th), float(tl), float(te), order,
                        {k: float(v) for k, v in values.items()}, cols, trace,
                        "power" if clutch is None else "interrupted",
                        "" if clutch is not None else ("torque_first" if torque_first else "inertia_first"))
