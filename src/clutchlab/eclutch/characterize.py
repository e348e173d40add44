"""Press-rig characterization: from raw load cycles to component characteristics.

Implements the procedure of Haramina et al. [1], Section 4 (Figs. 8-9): the
raw force-displacement records of a clutch component loaded and unloaded
three times on the manual press show a narrow friction hysteresis, "which
can successfully be removed by averaging the recorded curves"; the averages of
the cycles are "used as a final characteristic of the given component".  On
top of it, the finger (lever) stiffness of the diaphragm spring from the
multi-LVDT tests, Eq. (1) (Sections 5.1-5.2), and the equivalent yoke support
of Model 3 (Section 5.3).

Functions
---------
:func:`characterize`
    record -> :class:`CharacterizedCurve` (a :class:`clutchlab.Curve`).
:func:`lever_stiffness`
    records of Fig. 8b/8c -> :class:`LeverStiffness` (Eq. 1).
:func:`yoke_support_equivalent`
    support ring and yoke support spring in series, extrapolated.

References
----------
.. [1] K. Haramina, N. Kranjčević, M. Hoić, J. Deur, A. Tissot, "Modelling of
   E-clutch axial dynamics based on experimentally identified clutch component
   stress-strain characteristics", Trans. FAMENA 48 (2024) 21-35,
   doi:10.21278/TOF.483057923
.. [2] W. S. Cleveland, "Robust locally weighted regression and smoothing
   scatterplots", J. Am. Stat. Assoc. 74 (1979) 829-836 (local linear
   regression).
.. [3] A. Savitzky, M. J. E. Golay, "Smoothing and differentiation of data by
   simplified least squares procedures", Anal. Chem. 36 (1964) 1627-1639.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..curves import Curve, series
from .._limits import check_allocation, short_repr
from ..errors import DataError, IdentificationError, ParameterError
from ..io import Measurement, read_measurement
from ..io.measurements import check_time as _check_time

__all__ = [
    "CharacterizedCurve",
    "LeverStiffness",
    "characterize",
    "lever_stiffness",
    "yoke_support_equivalent",
    "MIN_SAMPLES",
]

#: Fewest samples a press record may have.
MIN_SAMPLES = 50
#: A branch is used only if it covers at least this fraction of the displacement range.
MIN_BRANCH_SPAN = 0.5
#: Direction reversals smaller than this fraction of the displacement range are noise.
REVERSAL_FRACTION = 0.05
#: ... or smaller than this many standard deviations of the LVDT noise.
REVERSAL_SIGMAS = 8.0
#: Smallest Savitzky-Golay window of a branch, as a fraction of the branch's samples.
BRANCH_SMOOTHING = 0.05
#: Radius of the tricube kernel of the local regression, in bandwidths (same standard deviation as a
#: Gaussian of 0.95 bandwidth, hence the same smoothing and curvature bias as before).
KERNEL_RADIUS = 2.5
#: ... widened where needed to reach this many nearest samples.
KERNEL_NEIGHBOURS = 5


# ----------------------------------------------------------------------------- result
@dataclass(frozen=True, eq=False)
class CharacterizedCurve(Curve):
    """Characteristic from press-rig cycles: a :class:`~clutchlab.Curve` with statistics.

    Behaves exactly like a :class:`~clutchlab.Curve` (deflection = recorded
    displacement [m], force [N]); methods that build new curves (``scale``,
    ``shift``, ``linearize``, :func:`~clutchlab.curves.series`, ...) return
    plain curves.

    Attributes
    ----------
    hysteresis_half_width : numpy.ndarray
        Half the difference loading minus unloading force at each deflection
        sample, averaged over the cycles [N] (the friction force).
    cycle_scatter : numpy.ndarray
        Standard deviation over the cycles of the cycle-averaged force at each
        deflection sample [N] (zero for a single cycle).
    n_cycles : int
        Number of load-unload cycles averaged.
    branches : pandas.DataFrame
        Raw samples of the used branches: ``cycle`` (1-based), ``branch``
        (``"loading"``/``"unloading"``), ``time_s``, ``displacement_m``,
        ``force_N`` -- the blue curves of [1], Fig. 9.
    cycle_curves : pandas.DataFrame
        Per cycle on the deflection grid: ``cycle``, ``displacement_m``,
        ``loading_N``, ``unloading_N``, ``force_N`` (their mean, the black
        curves of Fig. 9).
    channel : str
        Displacement channel used as the deflection axis.
    """

    hysteresis_half_width: np.ndarray | None = field(default=None, repr=False)
    cycle_scatter: np.ndarray | None = field(default=None, repr=False)
    n_cycles: int = 0
    branches: pd.DataFrame | None = field(default=None, repr=False)
    cycle_curves: pd.DataFrame | None = field(default=None, repr=False)
    channel: str = "displacement_m"

    def __post_init__(self):
        super().__post_init__()
        n = self.deflection.size
        for label in ("hysteresis_half_width", "cycle_scatter"):
            value = getattr(self, label)
            arr = np.zeros(n) if value is None else np.array(value, dtype=float).ravel()
            if arr.size != n:
                raise DataError(f"curve {self.name!r}: {label} has {arr.size} values for {n} samples")
            arr.setflags(write=False)
            object.__setattr__(self, label, arr)

    def as_curve(self) -> Curve:
        """The characteristic alone, as a plain :class:`~clutchlab.Curve`."""
        return Curve(self.deflection, self.force, kind=self.kind, extrapolation=self.extrapolation, name=self.name)

    def to_frame(self) -> pd.DataFrame:
        """Samples with ``deflection_m``, ``force_N``, ``hysteresis_half_width_N``, ``cycle_scatter_N``."""
        frame = super().to_frame()
        frame["hysteresis_half_width_N"] = self.hysteresis_half_width
        frame["cycle_scatter_N"] = self.cycle_scatter
        return frame

    def __repr__(self) -> str:
        return (super().__repr__()[:-1]
                + f", {self.n_cycles} cycles, hysteresis half-width {np.median(self.hysteresis_half_width):.3g} N"
                + f", cycle scatter {np.max(self.cycle_scatter):.3g} N max)")


# -------------------------------------------------------------------------- internals
def _odd_window(n_wanted: float, n_available: int) -> int:
    w = int(round(n_wanted))
    w = max(w, 5)
    if w % 2 == 0:
        w += 1
    while w > n_available:
        w -= 2
    return w


def _smooth(y: np.ndarray, window: int, order: int = 2) -> np.ndarray:
    """Savitzky-Golay smoothing [3] in time; identity for tiny windows."""
    if window < order + 3 or y.size < window:
        return y
    from scipy.signal import savgol_filter

    return savgol_filter(y, window, order, mode="interp")


def _noise_sigma(x: np.ndarray) -> float:
    """Robust white-noise standard deviation from second differences (MAD)."""
    d2 = x[2:] - 2.0 * x[1:-1] + x[:-2]
    if d2.size == 0:
        return 0.0
    return float(1.4826 * np.median(np.abs(d2 - np.median(d2))) / np.sqrt(6.0))


def _local_linear(x: np.ndarray, y: np.ndarray, grid: np.ndarray, bandwidth: float) -> np.ndarray:
    """Local linear regression [2] of ``y(x)`` at ``grid``; ``y`` may be 2-D (rows).

    Tricube weights ``(1 - |d/h|^3)^3`` as in [2]: compact support, so a sample
    farther than ``h`` from a grid point has no influence on it.  ``h`` is
    ``KERNEL_RADIUS * bandwidth``, widened where needed to reach the
    :data:`KERNEL_NEIGHBOURS` nearest samples (the nearest-neighbour span of [2]).
    A Gaussian kernel, used before, let the sticking samples crowded at a
    turning point leak into grid points several bandwidths away (about 1e-4 of
    the friction force two grid steps inside the turning point).
    """
    d = x[None, :] - grid[:, None]
    ad = np.abs(d)
    k = min(KERNEL_NEIGHBOURS, x.size) - 1
    h = np.maximum(KERNEL_RADIUS * bandwidth, np.partition(ad, k, axis=1)[:, k] * (1.0 + 1e-9))
    u = np.minimum(ad / h[:, None], 1.0)
    w = (1.0 - u ** 3) ** 3
    s0 = w.sum(axis=1)
    s1 = (w * d).sum(axis=1)
    s2 = (w * d * d).sum(axis=1)
    y = np.atleast_2d(y)
    t0 = w @ y.T  # (n_grid, n_quantities)
    t1 = (w * d) @ y.T
    den = s0 * s2 - s1 * s1
    ok = den > 1e-12 * s0 * s0 * h * h
    with np.errstate(divide="ignore", invalid="ignore"):
        ll = (s2[:, None] * t0 - s1[:, None] * t1) / den[:, None]
        nw = t0 / s0[:, None]
    out = np.where(ok[:, None], ll, nw)
    if not np.all(np.isfinite(out)):
        raise IdentificationError("characterize: a grid point has no samples near it (record too sparse)")
    return out.T


def _turning_points(xs: np.ndarray, delta: float) -> list[int]:
    """Alternating extrema of ``xs`` with prominence >= ``delta`` (zig-zag filter)."""
    from scipy.signal import find_peaks

    hi, _ = find_peaks(xs, prominence=delta)
    lo, _ = find_peaks(-xs, prominence=delta)
    marks = sorted([(int(i), 1) for i in hi] + [(int(i), -1) for i in lo])
    out: list[tuple[int, int]] = []
    for i, kind in marks:
        if out and out[-1][1] == kind:
            j = out[-1][0]
            if kind * xs[i] > kind * xs[j]:
                out[-1] = (i, kind)
            continue
        out.append((i, kind))
    return [i for i, _ in out]


@dataclass
class _Cycles:
    grid: np.ndarray            # deflection grid [m]
    loading: np.ndarray         # (n_cycles, n_quantities, n_grid)
    unloading: np.ndarray       # (n_cycles, n_quantities, n_grid)
    branches: pd.DataFrame      # raw samples of the used branches
    label: str


def _load_record(record, channels, name, channel_map=None, sample_rate=None):
    if isinstance(record, (str, Path)):
        label = name or str(record)
    elif isinstance(record, Measurement):
        label = record.source.path or name or "record"  # errors name the file the measurement came from
    elif isinstance(record, pd.DataFrame):
        label = name or "record"
    else:
        raise DataError(f"record must be a pandas.DataFrame or a file path, got {type(record).__name__}")
    # CSV, Parquet or MDF 4; units in the file converted to the ones the column names state; a channel
    # map renames a logger's channels to time_s, force_N, displacement_m (docs/measurements.md)
    # The time column is optional: the characterisation needs only the order of the samples (#33); a record
    # without time gets time_s from sample_rate, or NaN (it only labels the raw branches).
    meas = read_measurement(record, channel_map, required=["force_N", *channels], time=None, name=label)
    frame = meas.frame
    if "time_s" in meas.source.skipped:
        raise DataError(f"{label}: time column 'time_s': {meas.source.skipped['time_s']}")
    if sample_rate is not None:
        number = isinstance(sample_rate, (int, float, np.number)) and not isinstance(sample_rate, bool)
        if not (number and np.isfinite(sample_rate) and sample_rate > 0):
            raise ParameterError(f"sample_rate = {sample_rate!r} Hz: must be a positive number")
    if "time_s" in frame.columns:
        if sample_rate is not None:
            raise ParameterError(f"sample_rate = {sample_rate!r} Hz, but {label} has its own time column time_s")
        _check_time(frame["time_s"].to_numpy(dtype=float), label, "time_s", "row")
    else:
        n = len(frame)
        frame.insert(0, "time_s", np.arange(n) / float(sample_rate) if sample_rate is not None else np.nan)
    if len(frame) < MIN_SAMPLES:
        raise DataError(f"{label}: record too short ({len(frame)} samples, need at least {MIN_SAMPLES})")
    return frame, label


def _cycles(frame: pd.DataFrame, label: str, drive: str, quantities: list[str], n_grid: int) -> _Cycles:
    """Split a record into load cycles and smooth every branch onto a common grid of ``drive``."""
    t = frame["time_s"].to_numpy(dtype=float)
    x = frame[drive].to_numpy(dtype=float)
    n = x.size
    # direction from the smoothed displacement, never from the force (non-monotone for the diaphragm spring)
    xs = _smooth(x, _odd_window(n / 100.0, n))
    span_all = float(np.ptp(xs))
    sigma = _noise_sigma(x)
    delta = max(REVERSAL_FRACTION * span_all, REVERSAL_SIGMAS * sigma)
    if not span_all > delta:
        raise IdentificationError(
            f"{label}: no loading branch in {drive!r} (displacement range {span_all:.3g} m does not exceed "
            f"the noise threshold {delta:.3g} m)")
    bounds = [0, *_turning_points(xs, delta), n - 1]
    segments = []
    for a, b in zip(bounds[:-1], bounds[1:]):
        if b - a < 2:
            continue
        rise = xs[b] - xs[a]
        if abs(rise) < MIN_BRANCH_SPAN * span_all:
            continue
        segments.append((a, b, "loading" if rise > 0 else "unloading"))
    kinds = {s[2] for s in segments}
    if "unloading" not in kinds:
        raise IdentificationError(
            f"{label}: no unloading branch ({drive!r} never decreases over at least "
            f"{MIN_BRANCH_SPAN:.0%} of its range); the friction hysteresis cannot be averaged out")
    if "loading" not in kinds:
        raise IdentificationError(
            f"{label}: no loading branch ({drive!r} never increases over at least {MIN_BRANCH_SPAN:.0%} of its range)")
    pairs = [(s, u) for s, u in zip(segments[:-1], segments[1:]) if s[2] == "loading" and u[2] == "unloading"]
    if not pairs:
        raise IdentificationError(f"{label}: no loading branch is followed by an unloading branch")

    used = [seg for pair in pairs for seg in pair]
    # branch ends = smoothed displacement at the turning points (the extremes of a noisy branch
    # overshoot by a few noise sigmas, and a grid point beyond the data cluster would be extrapolated)
    lo = max(float(min(xs[a], xs[b])) for a, b, _ in used)
    hi = min(float(max(xs[a], xs[b])) for a, b, _ in used)
    if not hi > lo:
        raise IdentificationError(f"{label}: the load cycles share no displacement range")
    grid = np.linspace(lo, hi, n_grid)
    step = grid[1] - grid[0]

    values = np.vstack([frame[q].to_numpy(dtype=float) for q in quantities])
    out = {"loading": [], "unloading": []}
    rows = []
    for c, pair in enumerate(pairs, start=1):
        for a, b, kind in pair:
            xb = x[a:b + 1]
            nb = xb.size
            # samples per grid step at this branch's mean speed; smooth in time over ~0.75 grid step [3]
            per_step = nb * step / max(abs(xs[b] - xs[a]), step)
            # one window for all channels (a linear law stays exactly linear), at least BRANCH_SMOOTHING of
            # the branch, so that the regressor is nearly noise-free where the samples crowd at the turning
            # points (no errors-in-variables flattening there)
            w = max(_odd_window(0.75 * per_step, nb), _odd_window(BRANCH_SMOOTHING * nb, nb))
            xb_s = _smooth(xb, w)
            vb_s = np.vstack([_smooth(v[a:b + 1], w) for v in values])
            spacing = float(np.median(np.abs(np.diff(xb_s)))) if nb > 1 else step
            bandwidth = max(0.5 * step, 1.5 * spacing)
            out[kind].append(_local_linear(xb_s, vb_s, grid, bandwidth))  # [2]
            rows.append(pd.DataFrame({
                "cycle": c, "branch": kind, "time_s": t[a:b + 1], "displacement_m": xb,
                **{q: frame[q].to_numpy(dtype=float)[a:b + 1] for q in quantities},
            }))
    branches = pd.concat(rows, ignore_index=True)
    return _Cycles(grid, np.array(out["loading"]), np.array(out["unloading"]), branches, label)


def _correct_turning_points(load: np.ndarray, unload: np.ndarray, mean: np.ndarray) -> np.ndarray:
    """Replace the loading/unloading mean where one branch is still sticking after a turning point.

    Near the upper turning point the loading branch arrives sliding (elastic
    force + friction) while the unloading branch has just reversed and sticks,
    so their mean is too high by up to the friction; at the lower turning
    point the roles swap.  The sliding half-width is modelled as
    ``mu0 + mu1*|F|`` (Coulomb + load-proportional), fitted on the central
    60 % of the grid; from each end inward, the grid points whose half-width
    falls short of the model by more than 3 residual standard deviations form
    the sticking zone, where the sliding branch minus (plus) the modelled
    half-width is used instead of the mean.
    """
    n_c, n_g = load.shape
    hw = 0.5 * (load - unload)
    central = slice(int(0.2 * n_g), int(np.ceil(0.8 * n_g)))
    f_c = np.abs(mean[:, central]).ravel()
    h_c = hw[:, central].ravel()
    if f_c.size < 4:
        return mean
    A = np.column_stack([np.ones_like(f_c), f_c])
    coef, *_ = np.linalg.lstsq(A, h_c, rcond=None)
    resid = h_c - A @ coef
    sigma = float(np.std(resid))
    out = mean.copy()
    limit = n_g // 4
    for c in range(n_c):
        model = coef[0] + coef[1] * np.abs(mean[c])
        short = hw[c] < model - 3.0 * sigma - 1e-9 * np.abs(mean[c]).max()
        j = n_g - 1
        while j >= n_g - limit and short[j]:
            out[c, j] = load[c, j] - model[j]    # upper turning point: loading branch slides
            j -= 1
        j = 0
        while j < limit and short[j]:
            out[c, j] = unload[c, j] + model[j]  # lower turning point: unloading branch slides
            j += 1
    return out


def _check_sign_convention(load: np.ndarray, unload: np.ndarray, frame: pd.DataFrame, label: str,
                           channel: str) -> None:
    """Refuse a record whose force or displacement has the reversed sign.

    Friction opposes the motion, so at equal deflection the loading force lies
    above the unloading force: the hysteresis half-width is >= 0 for any
    component.  A force that is negative over most of the record is negated
    (the press pushes); with a positive force, a half-width clearly below zero
    over the central part of the travel (median below minus twice its robust
    scatter and 0.1 % of the force span) means the displacement is negated.
    Refused, not corrected:
    which channel to negate is the user's call, and a silently mirrored
    characteristic would be worse than an error.
    """
    force = frame["force_N"].to_numpy(dtype=float)
    if np.median(force) < 0:
        raise DataError(
            f"{label}: force_N is negative over most of the record (median {np.median(force):.4g} N): the press "
            "pushes, so a press record has the compression force positive; negate the column and run again")
    n_g = load.shape[1]
    hw = 0.5 * (load - unload)[:, int(0.2 * n_g):int(np.ceil(0.8 * n_g))].mean(axis=0)
    med = float(np.median(hw))
    scatter = 1.4826 * float(np.median(np.abs(hw - med)))
    span = float(np.ptp(0.5 * (load + unload)))
    if not med < -max(2.0 * scatter, 1e-3 * span):
        return
    raise DataError(
        f"{label}: the unloading force lies above the loading force (hysteresis half-width {med:.3g} N), "
        f"which friction cannot do: the sign of {channel!r} looks reversed (a press record has compression "
        f"force and deflection positive); negate that column and run again")


# ------------------------------------------------------------------------ characterize
def characterize(record, *, channel: str = "displacement_m", n_grid: int = 60, kind: str = "pchip",
                 min_cycles: int = 1, turning_point_correction: bool = True,
                 name: str | None = None, channel_map=None, sample_rate: float | None = None) -> CharacterizedCurve:
    """Component characteristic from a press-rig record ([1], Section 4, Fig. 9).

    The procedure of [1], Section 4: "raw experimental results exhibit a
    relatively narrow hysteresis because of friction between individual
    components, which can successfully be removed by averaging the recorded
    curves.  The averaged values over three repeated experiments or cycles
    are used as a final characteristic of the given component."

    Parameters
    ----------
    record : pandas.DataFrame or path
        Press record with ``force_N`` [N], the displacement ``channel`` [m]
        and optionally ``time_s`` [s]; a CSV file may carry ``#`` comment
        lines and be in any dialect (:mod:`clutchlab.io.dialect`).
    channel : str
        Displacement column used as deflection (``"displacement_m"`` = LVDT 1;
        e.g. ``"displacement2_m"`` for the second LVDT).
    n_grid : int
        Number of deflection samples of the result [-] (>= 5).
    kind : {"pchip", "linear"}
        Interpolation of the returned curve.
    min_cycles : int
        Fewest complete load-unload cycles required [-].
    turning_point_correction : bool
        Replace the loading/unloading mean near the turning points, where one
        branch is still sticking, by the sliding branch minus (plus) the
        modelled friction (Notes, step 4).  ``False`` gives the paper's plain
        average.
    name : str, optional
        Name of the curve (default: the file name or ``"characterized"``).
    channel_map : ChannelMap, mapping, str or Path, optional
        Map from the logger's channel names (and units) to ``time_s``,
        ``force_N`` and ``channel`` (a TOML file or a mapping, see
        :class:`~clutchlab.io.channels.ChannelMap` and docs/measurements.md).
        Without a map the record must use those names; units stated in the
        file (a CSV ``# units:`` line or unit row, Parquet metadata, MDF
        channel units) are converted to SI either way.
    sample_rate : float, optional
        Sample rate [Hz] of a record without time column, for the ``time_s``
        of ``branches``.  The characterisation itself needs only the order of
        the samples, so a record without time is accepted; without
        ``sample_rate`` its branches carry ``time_s = NaN``.

    Returns
    -------
    CharacterizedCurve
        Force [N] vs recorded displacement [m] on ``n_grid`` equidistant
        samples covering the range every used branch shares, with
        ``hysteresis_half_width`` [N], ``cycle_scatter`` [N], ``n_cycles``,
        ``branches`` and ``cycle_curves``.

    Raises
    ------
    DataError
        Missing column, NaN, time not strictly increasing (naming the row),
        fewer than :data:`MIN_SAMPLES` samples; force or displacement of
        reversed sign (the unloading branch above the loading branch, which
        friction cannot produce; refused, not corrected).
    IdentificationError
        No loading or no unloading branch, fewer than ``min_cycles`` cycles.

    Notes
    -----
    Steps (the paper gives only the principle; the details are ours):

    1. Branches from the direction of the displacement -- never from the force,
       which has a maximum for the Almen-László diaphragm spring.  The
       displacement is smoothed (Savitzky-Golay, window ~1 % of the record)
       and its turning points are the extrema with a prominence of at least
       ``max(5 % of the range, 8 sigma)`` (sigma: LVDT noise estimated from
       second differences), so LVDT noise does not create reversals.
       Branches covering less than half the range are ignored; a cycle is a
       loading branch followed by an unloading branch.
    2. Each branch is smoothed in time, force and displacement with the same
       quadratic Savitzky-Golay window (about 0.75 grid step, at least 5 % of
       the branch; a nearly noise-free displacement avoids the
       errors-in-variables flattening where the samples crowd at the turning
       points, and a common window keeps a linear law exactly linear), then
       regressed locally linearly on the displacement grid (tricube kernel
       of [2] with compact support, radius 2.5 bandwidths, bandwidth half a
       grid step or more: a sticking zone at a turning point cannot leak
       beyond it).  The grid ends are the smoothed
       displacements at the turning points.
    3. Per cycle, loading and unloading are averaged at equal displacement:
       the mean removes a friction force that is symmetric on both branches;
       half the difference is the hysteresis half-width.
    4. Turning-point correction (our addition): within about
       ``2*friction/stick stiffness`` after a turning point one branch still
       sticks, and the plain mean is biased towards the arriving branch by up
       to the friction force.  The sliding half-width is modelled as
       ``mu0 + mu1*|F|`` on the central 60 % of the grid; from each end
       inward, points whose half-width falls short of it by more than 3
       residual standard deviations (at most a quarter of the grid per end)
       take the sliding branch -/+ the modelled half-width.  Valid when the
       sticking zones are short compared with the travel.
    5. The cycles are averaged; their standard deviation is the cycle scatter.

    The grid covers the displacement range shared by all used branches; the
    deflection axis is the recorded displacement (not shifted).  The recorded
    displacement includes the rig compliance ([1], Sections 5.3-5.4);
    nothing here removes it.
    """
    if not isinstance(channel, str):
        raise ParameterError(f"channel = {channel!r} must be a column name")
    if isinstance(n_grid, bool) or not isinstance(n_grid, (int, np.integer)) or n_grid < 5:
        raise ParameterError(f"n_grid = {n_grid!r} must be an integer >= 5")
    if kind not in ("pchip", "linear"):
        raise ParameterError(f"kind = {kind!r}, expected 'pchip' or 'linear'")
    if isinstance(min_cycles, bool) or not isinstance(min_cycles, (int, np.integer)) or min_cycles < 1:
        raise ParameterError(f"min_cycles = {min_cycles!r} must be an integer >= 1")
    frame, label = _load_record(record, [channel], None, channel_map, sample_rate)
    # kernel weights of the local linear regression: n_grid x samples of a branch, a few temporaries
    check_allocation(n_grid, 6 * len(frame), f"n_grid = {n_grid} points for {label} ({len(frame)} samples)")
    cyc = _cycles(frame, label, channel, ["force_N"], int(n_grid))
    n_cycles = cyc.loading.shape[0]
    if n_cycles < min_cycles:
        raise IdentificationError(f"{label}: {n_cycles} complete load cycle(s), min_cycles = {min_cycles}")
    load = cyc.loading[:, 0, :]
    unload = cyc.unloading[:, 0, :]
    _check_sign_convention(load, unload, frame, label, channel)
    per_cycle = 0.5 * (load + unload)        # friction removed by averaging, [1] Section 4
    if turning_point_correction:
        per_cycle = _correct_turning_points(load, unload, per_cycle)
    half_width = 0.5 * (load - unload).mean(axis=0)
    force = per_cycle.mean(axis=0)           # average of the cycles, [1] Section 4
    scatter = per_cycle.std(axis=0, ddof=1) if n_cycles > 1 else np.zeros_like(force)
    cycle_curves = pd.concat([
        pd.DataFrame({"cycle": c + 1, "displacement_m": cyc.grid, "loading_N": load[c],
                      "unloading_N": unload[c], "force_N": per_cycle[c]})
        for c in range(n_cycles)], ignore_index=True)
    branches = cyc.branches
    if name is None:
        name = Path(record).stem if isinstance(record, (str, Path)) else "characterized"
    return CharacterizedCurve(cyc.grid, force, kind=kind, extrapolation="linear", name=name,
                              hysteresis_half_width=half_width, cycle_scatter=scatter, n_cycles=n_cycles,
                              branches=branches[["cycle", "branch", "time_s", "displacement_m", "force_N"]],
                              cycle_curves=cycle_curves, channel=channel)


# ---------------------------------------------------------------------- lever stiffness
@dataclass(frozen=True)
class LeverStiffness:
    """Diaphragm-spring finger (lever) stiffness from Eq. (1) of [1].

    Attributes
    ----------
    value : float
        Linearised constant finger stiffness ``k_fl`` [N/m] (least-squares
        slope of force over finger deflection in ``force_range``).
    standard_error : float
        Standard error of ``value`` from the regression residuals [N/m]
        (nominal: the grid points are smoothed, hence correlated, and the
        residuals include the mild nonlinearity that the linearisation drops).
    curve : clutchlab.Curve
        Finger characteristic: finger deflection ``s_b.ds - i_ds*s_pp.ds``
        [m] -> force [N] (mildly nonlinear).
    force_range : tuple of float
        Forces [N] over which ``value`` was fitted.
    points : pandas.DataFrame
        ``force_N``, ``tip_m``, ``support_m``, ``edge_m``, ``s_b_ds_m``,
        ``s_pp_ds_m``, ``finger_deflection_m``, ``fitted`` on the grid.
    reference : str
        Record that supplies force and tip displacement ("b": Model 1,
        Section 5.1; "c": Model 2, Section 5.2).
    """

    value: float
    standard_error: float
    curve: Curve
    force_range: tuple[float, float]
    points: pd.DataFrame = field(repr=False)
    reference: str = "b"

    def report(self) -> str:
        """One-paragraph summary."""
        lo, hi = self.force_range
        return (f"finger (lever) stiffness k_fl = {self.value:.6g} N/m +- {self.standard_error:.3g} N/m "
                f"(Eq. 1 of Haramina et al. 2024, reference record {self.reference!r}, "
                f"fitted over {lo:.4g}..{hi:.4g} N, {int(self.points['fitted'].sum())} points)")

    def __str__(self) -> str:
        return self.report()


def _averaged(record, channels, label, n_grid):
    """Loading/unloading- and cycle-averaged force and channels on the LVDT 1 grid."""
    frame, label = _load_record(record, ["displacement_m", *channels], label)
    cyc = _cycles(frame, label, "displacement_m", ["force_N", *channels], n_grid)
    mean = 0.5 * (cyc.loading + cyc.unloading).mean(axis=0)  # (n_quantities, n_grid)
    return cyc.grid, mean[0], mean[1:], label


def _monotone_channel(force, values, label, what):
    """Channel as a function of force for interpolation (force must increase along the grid)."""
    df = np.diff(force)
    if not (df > 0).all():
        k = int(np.flatnonzero(df <= 0)[0])
        raise IdentificationError(
            f"{label}: averaged force is not increasing with the displacement near {force[k]:.4g} N; "
            f"{what} cannot be matched at equal force (Eq. 1)")
    return force, values


def lever_stiffness(record_b, record_c, lever_ratio: float, *, force_range=None, reference: str = "b",
                    second_channel: str = "displacement2_m", n_grid: int = 60) -> LeverStiffness:
    """Finger (lever) stiffness of the diaphragm spring, Eq. (1) of [1].

    ``k_fl = dF_ds / (ds_b.ds - i_ds * ds_pp.ds)`` ([1], Eq. 1, Section 5.1)
    with ``F_ds = F(b)``, ``s_b.ds = s(b1) - s(b2)`` (tip relative to the
    support) and ``s_pp.ds = s(c2) - s(b2)`` (outer edge relative to the
    support), i.e. the finger bending that is left after the rigid lever
    rotation ``i_ds * s_pp.ds`` is taken out of the tip travel.

    Parameters
    ----------
    record_b : pandas.DataFrame or path
        Test of Fig. 8b: ``displacement_m`` = LVDT 1 at the tips ``s(b1)``,
        ``second_channel`` = LVDT 2 at the yoke support ``s(b2)`` [m].
    record_c : pandas.DataFrame or path
        Test of Fig. 8c: ``displacement_m`` = tips ``s(c1)``,
        ``second_channel`` = LVDT 2 at the pressure-plate edge ``s(c2)`` [m].
    lever_ratio : float
        ``i_ds`` (< 0) [-].
    force_range : (float, float), optional
        Forces [N] over which the constant ``k_fl`` is fitted; default the
        central 10-90 % of the force range both records share.
    reference : {"b", "c"}
        Record supplying ``F_ds`` and the tip displacement: "b" as in Section
        5.1 (Model 1); "c" as Section 5.2 prints it for Model 2 (``F(c)``,
        ``s(c1) - s(b2)``, ``s(c2) - s(b2)``).  The records are generic: the
        support channel always comes from ``record_b``, the edge channel from
        ``record_c``, so other pairings (e.g. a record of Fig. 8a) can be
        passed in those roles.
    second_channel : str
        Column of LVDT 2 in both records.
    n_grid : int
        Grid size of the averaged curves [-].

    Returns
    -------
    LeverStiffness
        ``value`` [N/m], ``standard_error`` [N/m], ``curve`` (finger
        deflection [m] -> force [N]), ``force_range``, ``points``.

    Notes
    -----
    Each record is first averaged over loading/unloading and cycles at equal
    tip displacement (as :func:`characterize`, plain average without the
    turning-point correction: the default fit range leaves the turning points
    out), for the force and LVDT 2 together.  The paper mixes two records "at equal force": the LVDT 2
    channel of the non-reference record is interpolated, as a function of its
    own averaged force, onto the reference record's forces, which requires
    that force to increase with the tip displacement.
    """
    ratio = float(lever_ratio) if isinstance(lever_ratio, (int, float, np.floating, np.integer)) else np.nan
    if not (np.isfinite(ratio) and ratio < 0):
        raise ParameterError(f"lever_ratio = {lever_ratio!r} must be a finite number < 0 (i_ds, [1] Section 3.2)")
    if reference not in ("b", "c"):
        raise ParameterError(f"reference = {reference!r}, expected 'b' or 'c'")
    if isinstance(n_grid, bool) or not isinstance(n_grid, (int, np.integer)) or n_grid < 5:
        raise ParameterError(f"n_grid = {n_grid!r} must be an integer >= 5")
    if not isinstance(second_channel, str):
        raise ParameterError(f"second_channel = {second_channel!r} must be a column name")
    gb, fb, chb, lb = _averaged(record_b, [second_channel], "record_b" if isinstance(record_b, pd.DataFrame) else None, n_grid)
    gc, fc, chc, lc = _averaged(record_c, [second_channel], "record_c" if isinstance(record_c, pd.DataFrame) else None, n_grid)
    support_b, edge_c = chb[0], chc[0]
    if reference == "b":
        force, tip, support = fb, gb, support_b
        fo, vo = _monotone_channel(fc, edge_c, lc, "s(c2)")
        lo_f, hi_f = max(fb.min(), fo[0]), min(fb.max(), fo[-1])
        inside = (force >= lo_f) & (force <= hi_f)
        edge = np.interp(force, fo, vo)  # record c onto record b's forces
    else:
        force, tip, edge = fc, gc, edge_c
        fo, vo = _monotone_channel(fb, support_b, lb, "s(b2)")
        lo_f, hi_f = max(fc.min(), fo[0]), min(fc.max(), fo[-1])
        inside = (force >= lo_f) & (force <= hi_f)
        support = np.interp(force, fo, vo)  # record b onto record c's forces
    if not hi_f > lo_f or inside.sum() < 3:
        raise IdentificationError(f"{lb} and {lc} share no force range")
    s_b_ds = tip - support                   # [1], Eq. 1: s_b.ds = s(b1) - s(b2)
    s_pp_ds = edge - support                 # [1], Eq. 1: s_pp.ds = s(c2) - s(b2)
    finger = s_b_ds - ratio * s_pp_ds        # [1], Eq. 1: denominator
    if force_range is None:
        f_lo, f_hi = lo_f + 0.1 * (hi_f - lo_f), lo_f + 0.9 * (hi_f - lo_f)
    else:
        try:
            f_lo, f_hi = (float(v) for v in force_range)
        except (TypeError, ValueError):
            raise ParameterError(f"force_range = {force_range!r} must be two forces [N]") from None
        if not (np.isfinite(f_lo) and np.isfinite(f_hi) and f_hi > f_lo):
            raise ParameterError(f"force_range = {force_range!r} must be finite and increasing")
    fit = inside & (force >= f_lo) & (force <= f_hi)
    if fit.sum() < 3:
        raise IdentificationError(f"force_range = ({f_lo:.4g}, {f_hi:.4g}) N holds {int(fit.sum())} grid points; need 3")
    d, f = finger[fit], force[fit]
    A = np.column_stack([d - d.mean(), np.ones_like(d)])
    coef, *_ = np.linalg.lstsq(A, f, rcond=None)
    k_fl = float(coef[0])                    # [1], Eq. 1: k_fl = dF_ds / d(finger deflection), linearised
    resid = f - A @ coef
    dof = max(d.size - 2, 1)
    sxx = float(((d - d.mean()) ** 2).sum())
    se = float(np.sqrt((resid ** 2).sum() / dof / sxx)) if sxx > 0 else float("inf")
    if not (np.isfinite(k_fl) and k_fl > 0):
        raise IdentificationError(f"Eq. 1 gives a non-positive finger stiffness {short_repr(k_fl)} N/m; check lever_ratio and channels")

    # finger characteristic: isotonic in force (noise can make the deflection jitter), strictly increasing
    from scipy.optimize import isotonic_regression

    sel = inside
    order = np.argsort(force[sel])
    fs, ds = force[sel][order], finger[sel][order]
    ds_iso = isotonic_regression(ds, increasing=True).x
    uniq, inv = np.unique(ds_iso, return_inverse=True)
    f_mean = np.bincount(inv, weights=fs) / np.bincount(inv)
    if uniq.size < 2:
        raise IdentificationError("the finger deflection does not grow with the force; no finger characteristic")
    curve = Curve(uniq, f_mean, kind="linear", extrapolation="linear", name="diaphragm fingers (Eq. 1)")
    points = pd.DataFrame({"force_N": force, "tip_m": tip, "support_m": support, "edge_m": edge,
                           "s_b_ds_m": s_b_ds, "s_pp_ds_m": s_pp_ds, "finger_deflection_m": finger,
                           "fitted": fit})
    return LeverStiffness(k_fl, se, curve, (float(f_lo), float(f_hi)), points, reference)


# -------------------------------------------------------------------- yoke support (eq.)
def _increasing(curve: Curve, label: str) -> Curve:
    """``curve`` as a plain, strictly increasing curve.

    A stiff part characterized with LVDT noise comparable to its deflection
    can wiggle; its force is then made monotone by isotonic regression
    (pool-adjacent-violators), pooled samples merged.  A curve that is mostly
    decreasing is rejected.
    """
    x, f = curve.deflection, curve.force
    if (np.diff(f) > 0).all():
        return curve.as_curve() if isinstance(curve, CharacterizedCurve) else curve
    from scipy.optimize import isotonic_regression

    level = isotonic_regression(f, increasing=True).x
    uniq, inv = np.unique(level, return_inverse=True)
    if uniq.size < max(2, curve.deflection.size // 2):
        raise ParameterError(
            f"{label}: curve {curve.name!r} is not increasing (force {f[0]:.4g} N at {x[0]:.4g} m to "
            f"{f[-1]:.4g} N at {x[-1]:.4g} m); the series sum needs increasing characteristics")
    xm = np.bincount(inv, weights=x) / np.bincount(inv)
    return Curve(xm, uniq, kind=curve.kind, extrapolation=curve.extrapolation, name=curve.name)


def yoke_support_equivalent(ring: Curve, spring: Curve, *, max_force_N: float | None = None,
                            end_fraction: float = 0.2, name: str = "yoke support (eq.)") -> Curve:
    """Equivalent yoke support of Model 3: support ring and support spring in series.

    [1], Section 5.3: ``k_ys.eq`` is calculated from the yoke support spring
    and the yoke support ring "considered as serially connected mutually
    opposing springs", and "estimated by extrapolating the reconstructed
    curve because the operating range of the clutch is beyond the measurement
    range of the manual press test rig".

    Parameters
    ----------
    ring : clutchlab.Curve
        Yoke support ring, deflection [m] -> force [N] (Section 4.5, Fig. 9g).
    spring : clutchlab.Curve
        Yoke support spring (Section 4.6, Fig. 9h).
    max_force_N : float, optional
        Extend the result up to this force [N] along the end slope.
    end_fraction : float
        Fraction of the top of the series curve's force range over which the
        end slope is fitted (least squares, robust to noise) [-].
    name : str
        Name of the result.

    Returns
    -------
    clutchlab.Curve
        Series curve (deflections add at equal force), extrapolated linearly.

    Notes
    -----
    The figure labels of [1] disagree: Sections 4.5/4.6 call the ring Fig. 9g
    and the spring Fig. 9h, Section 5.3 the opposite.  We follow Section 4 (the
    description of the measurements); the series sum does not depend on it.
    Both curves must increase; a characterized stiff ring whose force
    wiggles with LVDT noise (deflection of a few noise standard deviations
    per grid step) is made monotone by isotonic regression first (fewer grid
    points avoid it).  The stiffening of
    the yoke support that [1] needed for Models 3-4 (Sections 5.3-5.4) is not
    applied here: use ``Curve.scale``.
    """
    parts = []
    for label, c in (("ring", ring), ("spring", spring)):
        if not isinstance(c, Curve):
            raise ParameterError(f"{label} must be a clutchlab.Curve, got {type(c).__name__}")
    if not (0.0 < end_fraction <= 1.0):
        raise ParameterError(f"end_fraction = {end_fraction!r} must be in (0, 1]")
    # the series sum does not depend on a model variant's scalars: building many variants (Monte Carlo, a
    # sweep) computes it once.  Keyed on the curves' contents (curves are immutable; the bundled ones are read
    # anew by every preset) and the arguments
    key = (_curve_key(ring), _curve_key(spring), None if max_force_N is None else float(max_force_N),
           float(end_fraction), str(name))
    cached = _SUPPORT_EQUIVALENTS.get(key)
    if cached is not None:
        return cached
    out = _yoke_support_equivalent(ring, spring, max_force_N, end_fraction, name)
    if len(_SUPPORT_EQUIVALENTS) >= 16:
        _SUPPORT_EQUIVALENTS.pop(next(iter(_SUPPORT_EQUIVALENTS)))
    _SUPPORT_EQUIVALENTS[key] = out
    return out


#: (ring, spring, max_force_N, end_fraction, name) -> the equivalent curve (:func:`yoke_support_equivalent`)
_SUPPORT_EQUIVALENTS: dict = {}


def _curve_key(c: Curve) -> tuple:
    """What a curve's behaviour depends on, as a hashable key (its samples, interpolation, extrapolation)."""
    return (c.deflection.tobytes(), c.force.tobytes(), c.kind, c.extrapolation)


def _yoke_support_equivalent(ring, spring, max_force_N, end_fraction, name):
    """:func:`yoke_support_equivalent` without its memory of earlier requests."""
    parts = [_increasing(c, label) for label, c in (("ring", ring), ("spring", spring))]
    eq = series(*parts, name=name)  # [1], Section 5.3: springs in series
    if max_force_N is None:
        return eq
    fmax = float(max_force_N)
    top = float(eq.force[-1])
    if not np.isfinite(fmax):
        raise ParameterError(f"max_force_N = {max_force_N!r} is not finite")
    if fmax <= top:
        return eq
    f0 = float(eq.force[0])
    sel = eq.force >= top - end_fraction * (top - f0)
    if sel.sum() < 2:
        sel = np.zeros(eq.force.size, bool)
        sel[-2:] = True
    compliance = np.polyfit(eq.force[sel], eq.deflection[sel], 1)[0]  # end slope dx/dF [m/N]
    if not compliance > 0:
        raise IdentificationError(f"{name}: the end slope is not positive; cannot extrapolate")
    n_ext = 8
    f_new = np.linspace(top, fmax, n_ext + 1)[1:]
    x_new = eq.deflection[-1] + (f_new - top) * compliance  # [1], Section 5.3: extrapolation
    return Curve(np.concatenate([eq.deflection, x_new]), np.concatenate([eq.force, f_new]),
                 kind=eq.kind, extrapolation="linear", name=name)
