"""Measured characteristics: force as a function of deflection, given by samples.

A :class:`Curve` is what a press rig measures for one clutch component (the
stress-strain curves of Haramina et al. 2024, Fig. 9): deflection samples
[m] and the force [N] at each.  It interpolates piecewise-linearly or with a
monotone cubic (Fritsch-Carlson / PCHIP), extrapolates by a stated policy,
and composes: series (deflections add at equal force), parallel (forces add
at equal deflection), scaling of the stiffness and a shift by a pre-strain.

The same evaluation is available inside compiled kernels through
:func:`curve_eval` (numba), fed with :meth:`Curve.kernel_data`.

References
----------
.. [1] K. Haramina, N. Kranjčević, M. Hoić, J. Deur, A. Tissot, "Modelling of
   E-clutch axial dynamics based on experimentally identified clutch component
   stress-strain characteristics", Trans. FAMENA 48 (2024) 21-35,
   doi:10.21278/TOF.483057923
.. [2] F. N. Fritsch, R. E. Carlson, "Monotone piecewise cubic interpolation",
   SIAM J. Numer. Anal. 17 (1980) 238-246.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from numba import uintp as _u

from ._limits import short_repr
from .errors import DataError, ParameterError
from .numerics.interp import segment_range

__all__ = ["Curve", "series", "parallel", "curve_eval", "curve_eval_range", "curve_eval_segment", "KIND_CODES",
           "EXTRAPOLATION_CODES"]

KIND_CODES = {"linear": 0, "pchip": 1}
EXTRAPOLATION_CODES = {"linear": 0, "error": 1}


def _pchip_slopes(x: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Node derivatives of the Fritsch-Carlson monotone cubic (SciPy's PCHIP inside, secants at the ends)."""
    from scipy.interpolate import PchipInterpolator

    if x.size == 2:
        s = (f[1] - f[0]) / (x[1] - x[0])
        return np.array([s, s])
    d = PchipInterpolator(x, f).derivative()(x)
    # end derivatives = end-segment secants: keeps the Fritsch-Carlson monotonicity
    # conditions (alpha, beta <= 3) and gives a C1 linear extrapolation that never
    # has the zero slope SciPy's one-sided end formula may produce
    d[0] = (f[1] - f[0]) / (x[1] - x[0])
    d[-1] = (f[-1] - f[-2]) / (x[-1] - x[-2])
    return d


@numba.njit(cache=True, nogil=True)
def curve_eval(xs, fs, ds, kind, extrap, x):
    """Evaluate a sampled curve and its slope at a scalar ``x`` (compiled).

    Parameters
    ----------
    xs, fs, ds : 1-D float arrays
        Deflection samples [m], forces [N] and node slopes [N/m] (slopes are
        used for ``kind == 1`` only).
    kind : int
        0 piecewise linear, 1 monotone cubic Hermite.
    extrap : int
        0 linear extrapolation with the end slope, 1 NaN outside the samples.
    x : float
        Deflection [m].

    Returns
    -------
    (force, stiffness) : (float, float)
        Force [N] and slope dF/dx [N/m].
    """
    return curve_eval_range(xs, fs, ds, 0, xs.shape[0], kind, extrap, x)


@numba.njit(cache=True, nogil=True, forceinline=True)
def curve_eval_range(xs, fs, ds, start, stop, kind, extrap, x):
    """:func:`curve_eval` of the curve held in ``xs[start:stop]`` (``fs``, ``ds`` alike) of packed arrays.

    Indexing into the packed arrays of a network's curves instead of slicing them saves building an array
    structure per look-up.  Arguments and result as :func:`curve_eval`; ``start``, ``stop``: the curve's
    samples (non-negative: they are read as unsigned indices, without numba's wrap-around test).
    """
    val, der, _seg = curve_eval_segment(xs, fs, ds, start, stop, kind, extrap, x, -1)
    return val, der


@numba.njit(cache=True, nogil=True, forceinline=True)
def curve_eval_segment(xs, fs, ds, start, stop, kind, extrap, x, hint):
    """:func:`curve_eval_range` starting the search at segment ``hint``; also returns the segment used.

    The one implementation of the curve law (:func:`curve_eval` and :func:`curve_eval_range` call it).  A
    right-hand side evaluates each curve close to where it did last time: checking the segment of the
    previous look-up first (``hint``, an index into ``xs``; -1: none) spares the binary search and its
    unpredictable branches.  The segment is the one the binary search finds (``xs[lo] <= x < xs[lo + 1]``),
    so the result does not depend on the hint.

    Returns
    -------
    (force, stiffness, segment) : (float, float, int)
        Force [N], slope dF/dx [N/m] and the segment's first sample (-1 outside the samples).
    """
    first = _u(start)
    last = _u(stop - 1)
    if x <= xs[first] or x >= xs[last]:
        if x < xs[first] or x > xs[last]:
            if extrap == 1:
                return np.nan, np.nan, -1
        if x <= xs[first]:
            if kind == 0:
                s = (fs[first + _u(1)] - fs[first]) / (xs[first + _u(1)] - xs[first])
            else:
                s = ds[first]
            return fs[first] + s * (x - xs[first]), s, -1
        if kind == 0:
            s = (fs[last] - fs[last - _u(1)]) / (xs[last] - xs[last - _u(1)])
        else:
            s = ds[last]
        return fs[last] + s * (x - xs[last]), s, -1
    if start <= hint < stop - 1 and xs[_u(hint)] <= x < xs[_u(hint + 1)]:
        k = hint
    else:
        k = segment_range(xs, start, stop, x)  # segment xs[lo] <= x < xs[lo+1], binary search
    lo = _u(k)
    hi = lo + _u(1)
    h = xs[hi] - xs[lo]
    if kind == 0:
        s = (fs[hi] - fs[lo]) / h
        return fs[lo] + s * (x - xs[lo]), s, k
    inv_h = 1.0 / h  # (one division: the position in the segment and the derivative's two 1/h terms)
    t = (x - xs[lo]) * inv_h
    t2 = t * t
    t3 = t2 * t
    h00 = 2.0 * t3 - 3.0 * t2 + 1.0
    h10 = t3 - 2.0 * t2 + t
    h01 = -2.0 * t3 + 3.0 * t2
    h11 = t3 - t2
    val = h00 * fs[lo] + h10 * h * ds[lo] + h01 * fs[hi] + h11 * h * ds[hi]
    dh00 = (6.0 * t2 - 6.0 * t) * inv_h  # (dh01 = -dh00)
    dh10 = 3.0 * t2 - 4.0 * t + 1.0
    dh11 = 3.0 * t2 - 2.0 * t
    der = dh00 * (fs[lo] - fs[hi]) + dh10 * ds[lo] + dh11 * ds[hi]
    return val, der, k


@numba.njit(cache=True, nogil=True)
def curve_inverse(xs, fs, ds, fz, sign, g, out):
    """Deflections at which a strictly monotone cubic Hermite curve reaches given forces (compiled).

    The inverse of :func:`curve_eval` (``kind == 1``) inside the sampled range: a safeguarded Newton
    iteration in the segment that brackets each force (the cubic is monotone there), from the secant's
    root, bisecting whenever a step leaves the bracket; stops when a step is below a few units in the last
    place of ``|x|`` plus the sampled span (a looser step bound left force errors of 1e-7 N on curves of
    1e8 N/m), or at a zero residual.

    Parameters
    ----------
    xs, fs, ds : 1-D float arrays
        Deflection samples [m], forces [N] and node slopes [N/m].
    fz : 1-D float array
        ``sign * fs``, increasing [N].
    sign : float
        +1 for an increasing curve, -1 for a decreasing one.
    g : 1-D float array
        ``sign * force`` for each force wanted [N].
    out : 1-D float array
        Written: the deflections [m] (forces outside the samples get the end segments' root; the caller
        replaces them by the end slopes' extrapolation).
    """
    n = xs.shape[0]
    span = xs[n - 1] - xs[0]
    for k in range(g.shape[0]):
        gk = g[k]
        i = np.searchsorted(fz, gk, side="right") - 1
        i = min(max(i, 0), n - 2)
        lo = xs[i]
        hi = xs[i + 1]
        x = lo + (gk - fz[i]) * (hi - lo) / (fz[i + 1] - fz[i])
        for _ in range(60):
            val, der = curve_eval(xs, fs, ds, 1, 0, x)
            r = val * sign - gk
            if r == 0.0:
                break
            if r < 0:
                lo = x
            elif r > 0:
                hi = x
            step = r / (der * sign) if der != 0 else 0.0
            xn = x - step
            if xn <= lo or xn >= hi or not np.isfinite(xn):
                xn = 0.5 * (lo + hi)
            done = abs(xn - x) <= 4.0 * 2.220446049250313e-16 * (abs(x) + span)
            x = xn
            if done:
                break
        out[k] = x


@numba.njit(cache=True, nogil=True)
def curve_inverse_one(xs, fs, ds, kind, extrap, force):
    """Deflection [m] at which a strictly monotone sampled curve reaches ``force`` [N] (compiled; one value).

    :meth:`Curve.inverse` for one force, for compiled callers (the E-clutch's start derives pre-strains with it,
    :func:`clutchlab.eclutch.system.derive_clutch`): inside the samples the linear segment's root or the
    cubic's (:func:`curve_inverse`), outside them the end slopes' extrapolation.  Returns NaN where the curve is
    not strictly monotone, the force is not finite, or the force lies outside the samples of a curve whose
    ``extrapolation`` is ``"error"`` (``extrap`` 1), where :meth:`Curve.inverse` raises.
    """
    n = xs.shape[0]
    up = True
    down = True
    for i in range(n - 1):
        if not fs[i + 1] > fs[i]:
            up = False
        if not fs[i + 1] < fs[i]:
            down = False
    if not (up or down) or not np.isfinite(force):
        return np.nan
    sign = 1.0 if up else -1.0
    g = force * sign
    f0 = fs[0] * sign
    f1 = fs[n - 1] * sign
    if extrap == 1 and (g < f0 - 1e-9 * max(1.0, abs(f0)) or g > f1 + 1e-9 * max(1.0, abs(f1))):
        return np.nan
    if kind == 0:
        s0 = (fs[1] * sign - f0) / (xs[1] - xs[0])
        s1 = (f1 - fs[n - 2] * sign) / (xs[n - 1] - xs[n - 2])
    else:
        s0 = ds[0] * sign
        s1 = ds[n - 1] * sign
    if g < f0:
        return xs[0] + (g - f0) / s0
    if g > f1:
        return xs[n - 1] + (g - f1) / s1
    if kind == 0:
        i = n - 2
        for j in range(n - 1):
            if fs[j + 1] * sign > g:
                i = j
                break
        return xs[i] + (g - fs[i] * sign) * (xs[i + 1] - xs[i]) / (fs[i + 1] * sign - fs[i] * sign)
    fz = np.empty(n)
    for i in range(n):
        fz[i] = fs[i] * sign
    gv = np.empty(1)
    gv[0] = g
    out = np.empty(1)
    curve_inverse(xs, fs, ds, fz, sign, gv, out)
    return out[0]


def _eval_numpy(xs, fs, ds, kind, x):
    """Vectorised twin of :func:`curve_eval` without the extrapolation check."""
    x = np.asarray(x, dtype=float)
    n = xs.size
    i = np.clip(np.searchsorted(xs, x, side="right") - 1, 0, n - 2)
    h = xs[i + 1] - xs[i]
    t = (x - xs[i]) / h
    if kind == 0:
        s = (fs[i + 1] - fs[i]) / h
        val = fs[i] + s * (x - xs[i])
        der = s
        s0 = (fs[1] - fs[0]) / (xs[1] - xs[0])
        s1 = (fs[-1] - fs[-2]) / (xs[-1] - xs[-2])
    else:
        t2 = t * t
        t3 = t2 * t
        val = ((2 * t3 - 3 * t2 + 1) * fs[i] + (t3 - 2 * t2 + t) * h * ds[i]
               + (-2 * t3 + 3 * t2) * fs[i + 1] + (t3 - t2) * h * ds[i + 1])
        der = ((6 * t2 - 6 * t) / h * fs[i] + (3 * t2 - 4 * t + 1) * ds[i]
               + (-6 * t2 + 6 * t) / h * fs[i + 1] + (3 * t2 - 2 * t) * ds[i + 1])
        s0, s1 = ds[0], ds[-1]
    below = x < xs[0]
    above = x > xs[-1]
    val = np.where(below, fs[0] + s0 * (x - xs[0]), val)
    val = np.where(above, fs[-1] + s1 * (x - xs[-1]), val)
    der = np.where(below, s0, np.where(above, s1, der))
    return val, der


@dataclass(frozen=True, eq=False)
class Curve:
    """Force-deflection characteristic given by samples.

    Parameters
    ----------
    deflection : array_like
        Strictly increasing deflection samples [m] (at least 2).
    force : array_like
        Force at each sample [N].
    kind : {"linear", "pchip"}
        Piecewise-linear or monotone-cubic (Fritsch-Carlson) interpolation.
        The cubic preserves the monotonicity of the data between samples and
        reproduces an Almen-László maximum without overshoot.
    extrapolation : {"linear", "error"}
        Outside the samples, continue with the end slope ("linear") or raise
        :class:`~clutchlab.errors.ParameterError` ("error"; compiled kernels
        get NaN).
    name : str
        Label used in errors and plots.

    Examples
    --------
    >>> import clutchlab
    >>> c = clutchlab.Curve([0.0, 1e-3, 2e-3], [0.0, 100.0, 300.0])
    >>> float(c(1.5e-3))
    200.0
    >>> float(c.inverse(100.0))
    0.001
    """

    deflection: np.ndarray
    force: np.ndarray
    kind: str = "linear"
    extrapolation: str = "linear"
    name: str = "curve"

    def __post_init__(self):
        try:
            x = np.array(self.deflection, dtype=float).ravel()
            f = np.array(self.force, dtype=float).ravel()
        except (TypeError, ValueError) as exc:
            raise DataError(f"curve {self.name!r}: samples are not numeric ({exc})") from None
        if x.size != f.size:
            raise DataError(f"curve {self.name!r}: {x.size} deflection samples but {f.size} force samples")
        if x.size < 2:
            raise DataError(f"curve {self.name!r}: needs at least 2 samples, got {x.size}")
        for label, arr in (("deflection", x), ("force", f)):
            bad = ~np.isfinite(arr)
            if bad.any():
                k = int(np.flatnonzero(bad)[0])
                raise DataError(f"curve {self.name!r}: {label}[{k}] = {short_repr(arr[k])} is not finite")
        dx = np.diff(x)
        if (dx <= 0).any():
            k = int(np.flatnonzero(dx <= 0)[0])
            raise DataError(
                f"curve {self.name!r}: deflection must be strictly increasing, but "
                f"deflection[{k + 1}] = {short_repr(x[k + 1])} <= deflection[{k}] = {short_repr(x[k])}"
            )
        if self.kind not in KIND_CODES:
            raise ParameterError(f"curve {self.name!r}: kind = {self.kind!r}, expected one of {sorted(KIND_CODES)}")
        if self.extrapolation not in EXTRAPOLATION_CODES:
            raise ParameterError(
                f"curve {self.name!r}: extrapolation = {self.extrapolation!r}, expected one of {sorted(EXTRAPOLATION_CODES)}"
            )
        x.setflags(write=False)
        f.setflags(write=False)
        object.__setattr__(self, "deflection", x)
        object.__setattr__(self, "force", f)
        if self.kind == "pchip":
            d = _pchip_slopes(x, f)
        else:
            d = np.empty(x.size)
            d[:-1] = np.diff(f) / dx
            d[-1] = d[-2]
        d.setflags(write=False)
        object.__setattr__(self, "_slopes", d)

    # ------------------------------------------------------------- constructors
    @classmethod
    def linear(cls, stiffness: float, force_at_zero: float = 0.0, span: tuple[float, float] = (0.0, 1e-3),
               name: str = "linear") -> "Curve":
        """A linear spring ``F = force_at_zero + stiffness * x`` [N/m, N], extrapolated linearly."""
        lo, hi = span
        if not np.isfinite(stiffness):
            raise ParameterError(f"curve {name!r}: stiffness = {short_repr(stiffness)} is not finite")
        return cls([lo, hi], [force_at_zero + stiffness * lo, force_at_zero + stiffness * hi], name=name)

    @classmethod
    def from_function(cls, func, deflection, kind: str = "pchip", extrapolation: str = "linear", name: str = "curve"):
        """Sample ``func(deflection) -> force`` on the given grid."""
        deflection = np.asarray(deflection, dtype=float)
        return cls(deflection, np.asarray(func(deflection), dtype=float), kind=kind, extrapolation=extrapolation, name=name)

    # ---------------------------------------------------------------- evaluation
    @property
    def span(self) -> tuple[float, float]:
        """Measured deflection range (first, last sample) [m]."""
        return float(self.deflection[0]), float(self.deflection[-1])

    def _check_range(self, x):
        if self.extrapolation == "error":
            x = np.asarray(x, dtype=float)
            lo, hi = self.span
            bad = (x < lo - 1e-15) | (x > hi + 1e-15) | ~np.isfinite(x)
            if np.any(bad):
                v = np.asarray(x)[bad].ravel()[0]
                raise ParameterError(
                    f"curve {self.name!r}: deflection {short_repr(v)} m outside the measured range [{short_repr(lo)}, {short_repr(hi)}] "
                    "and extrapolation='error'"
                )

    def __call__(self, x):
        """Force [N] at deflection ``x`` [m] (vectorised)."""
        self._check_range(x)
        val, _ = _eval_numpy(self.deflection, self.force, self._slopes, KIND_CODES[self.kind], x)
        return val if np.ndim(x) else float(val)

    def stiffness(self, x):
        """Tangent stiffness dF/dx [N/m] at deflection ``x`` [m] (vectorised)."""
        self._check_range(x)
        _, der = _eval_numpy(self.deflection, self.force, self._slopes, KIND_CODES[self.kind], x)
        return der if np.ndim(x) else float(der)

    def kernel_data(self):
        """Arrays and codes for :func:`curve_eval`: ``(xs, fs, ds, kind, extrap)``."""
        return (np.ascontiguousarray(self.deflection), np.ascontiguousarray(self.force),
                np.ascontiguousarray(self._slopes), KIND_CODES[self.kind], EXTRAPOLATION_CODES[self.extrapolation])

    # ------------------------------------------------------------------ algebra
    def _replace(self, deflection=None, force=None, **kw) -> "Curve":
        return Curve(self.deflection if deflection is None else deflection,
                     self.force if force is None else force,
                     kind=kw.get("kind", self.kind), extrapolation=kw.get("extrapolation", self.extrapolation),
                     name=kw.get("name", self.name))

    def scale(self, factor: float) -> "Curve":
        """Scale the stiffness: force multiplied by ``factor`` at every deflection.

        Model 4 of [1] scales the yoke-support characteristic by 20 and the
        diaphragm spring by 1.3 (Section 5.4).
        """
        if not (np.isfinite(factor) and factor > 0):
            raise ParameterError(f"curve {self.name!r}: scale factor = {short_repr(factor)} must be finite and > 0")
        return self._replace(force=self.force * factor, name=f"{self.name}*{factor:g}")

    def shift(self, prestrain: float) -> "Curve":
        """Curve seen from a pre-strained state: ``g(x) = f(x + prestrain)``.

        A component mounted with a pre-strain ``prestrain`` [m] (its deflection
        in the assembled clutch) has force ``g(0) = f(prestrain)`` there.
        """
        if not np.isfinite(prestrain):
            raise ParameterError(f"curve {self.name!r}: prestrain = {short_repr(prestrain)} is not finite")
        return self._replace(deflection=self.deflection - prestrain)

    def is_monotone(self) -> bool:
        """True if the force is strictly increasing or strictly decreasing in the samples."""
        df = np.diff(self.force)
        return bool((df > 0).all() or (df < 0).all())

    def _monotone_sign(self) -> int:
        df = np.diff(self.force)
        if (df > 0).all():
            return 1
        if (df < 0).all():
            return -1
        k = int(np.flatnonzero(np.diff(np.sign(df)) != 0)[0]) + 1 if np.any(np.diff(np.sign(df)) != 0) else int(np.flatnonzero(df == 0)[0])
        raise ParameterError(
            f"curve {self.name!r} is not monotone (force turns near deflection {short_repr(self.deflection[k])} m); "
            "it has no inverse"
        )

    def inverse(self, force):
        """Deflection [m] at which the curve reaches ``force`` [N] (vectorised).

        Defined only for strictly monotone curves; outside the sampled forces
        the end slopes are used (or an error is raised with
        ``extrapolation='error'``).
        """
        sign = self._monotone_sign()
        f = np.asarray(force, dtype=float)
        if not np.all(np.isfinite(f)):
            raise ParameterError(f"curve {self.name!r}: inverse of a non-finite force")
        xs, fs, ds = self.deflection, self.force, self._slopes
        fz = fs * sign
        g = f * sign
        if self.extrapolation == "error":
            bad = (g < fz[0] - 1e-9 * max(1.0, abs(fz[0]))) | (g > fz[-1] + 1e-9 * max(1.0, abs(fz[-1])))
            if np.any(bad):
                raise ParameterError(
                    f"curve {self.name!r}: force {short_repr(np.atleast_1d(f)[np.atleast_1d(bad)][0])} N outside the measured "
                    f"range [{short_repr(min(fs[0], fs[-1]))}, {short_repr(max(fs[0], fs[-1]))}] and extrapolation='error'"
                )
        if self.kind == "linear":
            i = np.clip(np.searchsorted(fz, g, side="right") - 1, 0, xs.size - 2)
            x = xs[i] + (g - fz[i]) * (xs[i + 1] - xs[i]) / (fz[i + 1] - fz[i])
        else:
            # safeguarded Newton inside the bracketing segment (the cubic is monotone there), compiled
            gv = np.ascontiguousarray(np.ravel(g), dtype=float)
            out = np.empty(gv.size)
            curve_inverse(xs, fs, ds, np.ascontiguousarray(fz, dtype=float), float(sign), gv, out)
            x = out.reshape(np.shape(g))
            s0, s1 = ds[0] * sign, ds[-1] * sign
            x = np.where(g < fz[0], xs[0] + (g - fz[0]) / s0, x)
            x = np.where(g > fz[-1], xs[-1] + (g - fz[-1]) / s1, x)
        if self.kind == "linear":
            s0 = (fz[1] - fz[0]) / (xs[1] - xs[0])
            s1 = (fz[-1] - fz[-2]) / (xs[-1] - xs[-2])
            x = np.where(g < fz[0], xs[0] + (g - fz[0]) / s0, x)
            x = np.where(g > fz[-1], xs[-1] + (g - fz[-1]) / s1, x)
        return x if np.ndim(force) else float(x)

    def linearize(self, lower: float, upper: float, npoints: int = 201) -> "Curve":
        """Least-squares straight line through the curve over ``[lower, upper]`` [m].

        Used for the diaphragm lever stiffness k_fl, which [1] (Section 5.1)
        finds mildly varying and replaces by a constant.  The result is a
        two-sample linear :class:`Curve` extrapolated linearly; its slope is
        ``result.stiffness(0.0)``.
        """
        if not (np.isfinite(lower) and np.isfinite(upper) and upper > lower):
            raise ParameterError(f"curve {self.name!r}: linearize range [{short_repr(lower)}, {short_repr(upper)}] is empty or not finite")
        x = np.linspace(lower, upper, npoints)
        k, c = np.polyfit(x, self(x), 1)
        return Curve([lower, upper], [c + k * lower, c + k * upper], name=f"{self.name} (linearised)")

    def to_frame(self):
        """Samples as a DataFrame with columns ``deflection_m``, ``force_N``."""
        import pandas as pd

        return pd.DataFrame({"deflection_m": self.deflection, "force_N": self.force})

    def __repr__(self) -> str:
        lo, hi = self.span
        return (f"Curve({self.name!r}, {self.deflection.size} samples, deflection {lo:.4g}..{hi:.4g} m, "
                f"force {self.force.min():.4g}..{self.force.max():.4g} N, kind={self.kind!r}, "
                f"extrapolation={self.extrapolation!r})")


def _combined_kind(curves) -> str:
    """All cubic: cubic; otherwise linear (keeps the kinks of linear parts exactly)."""
    return "pchip" if all(c.kind == "pchip" for c in curves) else "linear"


def _combined_extrap(curves) -> str:
    return "error" if any(c.extrapolation == "error" for c in curves) else "linear"


def _adaptive_samples(func, breakpoints: np.ndarray, lo: float, hi: float, rtol: float, interpolate,
                      max_rounds: int = 30):
    """Sample ``func`` on [lo, hi] from the breakpoints, bisecting every interval in which the final
    interpolant ``interpolate(t, y, t_query)`` misses ``func`` by more than ``rtol`` of its range at
    one third or two thirds of the interval."""
    t = np.unique(np.concatenate([breakpoints[(breakpoints > lo) & (breakpoints < hi)], [lo, hi]]))
    tol_t = 1e-9 * max(abs(lo), abs(hi), 1e-300)
    t = t[np.concatenate([[True], np.diff(t) > tol_t])]
    y = func(t)
    for _ in range(max_rounds):
        mid = 0.5 * (t[:-1] + t[1:])
        ym = func(mid)
        # probe at 1/3 and 2/3 of each interval: a midpoint alone can be met by chance (symmetric cubics)
        probes = np.concatenate([t[:-1] + (t[1:] - t[:-1]) / 3.0, t[:-1] + 2.0 * (t[1:] - t[:-1]) / 3.0])
        yp = func(probes)
        scale = max(np.ptp(np.concatenate([y, ym, yp])), 1e-300)
        miss = np.abs(yp - interpolate(t, y, probes)) > rtol * scale
        bad = miss[: t.size - 1] | miss[t.size - 1:]
        bad &= np.diff(t) > 4 * tol_t
        if not bad.any():
            break
        t = np.concatenate([t, mid[bad]])
        y = np.concatenate([y, ym[bad]])
        order = np.argsort(t)
        t, y = t[order], y[order]
    return t, y


def series(*curves: Curve, name: str = "series", rtol: float = 1e-6) -> Curve:
    """Springs in series: deflections add at equal force.

    Each curve must be strictly increasing (invertible).  The result is
    sampled at the union of the components' sample forces, bisected where the
    result's own interpolant misses the exact sum by more than ``rtol`` of the
    deflection range, over the union of their force ranges, each
    component extrapolating by its own policy; with ``extrapolation='error'``
    on any component, only the common range is used.  Two linear springs give
    ``1/k = 1/k1 + 1/k2``.  ``name`` labels the result.
    """
    if len(curves) < 1:
        raise ParameterError("series() needs at least one curve")
    for c in curves:
        if c._monotone_sign() != 1:
            raise ParameterError(f"series(): curve {c.name!r} must have force increasing with deflection")
    extrap = _combined_extrap(curves)
    if extrap == "error":
        lo = max(c.force[0] for c in curves)
        hi = min(c.force[-1] for c in curves)
    else:
        lo = min(c.force[0] for c in curves)
        hi = max(c.force[-1] for c in curves)
    if not hi > lo:
        raise ParameterError("series(): the curves share no force range")
    kind = _combined_kind(curves)

    def interpolate(f, x, f_query):  # the result's own interpolant, read as deflection(force)
        return Curve(x, f, kind=kind).inverse(f_query) if np.all(np.diff(x) > 0) else np.full(f_query.shape, np.inf)

    grid, x = _adaptive_samples(lambda f: sum(c.inverse(f) for c in curves),
                                np.concatenate([c.force for c in curves]), lo, hi, rtol, interpolate)
    keep = np.concatenate([[True], np.diff(x) > 1e-12 * (np.abs(x).max() + 1e-300)])
    x, grid = x[keep], grid[keep]
    return Curve(x, grid, kind=kind, extrapolation=extrap, name=name)


def parallel(*curves: Curve, name: str = "parallel", rtol: float = 1e-6) -> Curve:
    """Springs in parallel: forces add at equal deflection.

    Sampled at the union of the components' deflection samples (bisected
    until the result's interpolant is within ``rtol`` of the force range; ``name``
    labels the result) over the union (or, with ``extrapolation='error'``, the
    intersection) of their spans.
    """
    if len(curves) < 1:
        raise ParameterError("parallel() needs at least one curve")
    extrap = _combined_extrap(curves)
    if extrap == "error":
        lo = max(c.span[0] for c in curves)
        hi = min(c.span[1] for c in curves)
    else:
        lo = min(c.span[0] for c in curves)
        hi = max(c.span[1] for c in curves)
    if not hi > lo:
        raise ParameterError("parallel(): the curves share no deflection range")
    kind = _combined_kind(curves)
    grid, f = _adaptive_samples(lambda x: sum(c(x) for c in curves),
                                np.concatenate([c.deflection for c in curves]), lo, hi, rtol,
                                lambda x, y, xq: Curve(x, y, kind=kind)(xq))
    return Curve(grid, f, kind=kind, extrapolation=extrap, name=name)
