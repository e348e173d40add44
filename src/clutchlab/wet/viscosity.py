"""Dynamic viscosity of automatic transmission fluid (ATF) versus temperature.

Shin, Kim and Choi [1], Sec. 2.2, Eq. 7: a sum of two exponentials fitted to
measured ATF viscosity; Table 1 gives the parameters for ATF SP-4 RR.

References
----------
.. [1] S. Shin, D.-H. Kim, S. B. Choi, "Apparatus for identification of
   frictional and thermal characteristics of a wet clutch" (KAIST).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from .._limits import short_repr
from ..errors import DataError, IdentificationError

__all__ = ["atf_viscosity", "fit_viscosity", "ViscosityFit"]


def atf_viscosity(temperature_c, mu1, mu2, mu3, mu4):
    """ATF dynamic viscosity ``mu_v(T) = mu1 exp(mu2 T) + mu3 exp(mu4 T)``.

    Shin et al. [1], Eq. 7.

    Parameters
    ----------
    temperature_c : array_like
        Fluid temperature T [degC] (the exponents multiply degrees Celsius).
    mu1, mu3 : float
        Viscosity parameters [Pa*s] (Table 1: 150.2 and 58.15 mPa*s).
    mu2, mu4 : float
        Exponents [1/K] (Table 1: -0.07838 and -0.02184).

    Returns
    -------
    numpy.ndarray or float
        Dynamic viscosity [Pa*s].

    Notes
    -----
    The paper gives mu1, mu3 in mPa*s; clutchlab uses Pa*s.  T is read in
    degC: with Table 1 this gives 30.8 mPa*s at 40 degC and 6.6 mPa*s at
    100 degC, the range of an ATF (in kelvin the exponentials would vanish).
    """
    t = np.asarray(temperature_c, dtype=float)
    # the one implementation of Eq. 7 (the compiled model calls the same function), on arrays
    out = np.asarray(viscosity_scalar.py_func(t, mu1, mu2, mu3, mu4))
    return float(out) if out.ndim == 0 else out


@numba.njit(cache=True, nogil=True, inline="always")
def viscosity_scalar(temperature_c, mu1, mu2, mu3, mu4):
    """ATF dynamic viscosity ``mu1 exp(mu2 T) + mu3 exp(mu4 T)`` [Pa*s] (Shin et al. [1], Eq. 7).

    The compiled scalar form used by the engagement model; :func:`atf_viscosity`
    evaluates the same function body on arrays.

    Parameters
    ----------
    temperature_c : float
        Fluid temperature T [degC].
    mu1, mu3 : float
        Viscosity parameters [Pa*s].
    mu2, mu4 : float
        Exponents [1/K].

    Returns
    -------
    float
        Dynamic viscosity [Pa*s].
    """
    return mu1 * np.exp(mu2 * temperature_c) + mu3 * np.exp(mu4 * temperature_c)  # [1], Eq. 7


@dataclass(frozen=True)
class ViscosityFit:
    """Result of :func:`fit_viscosity`.

    Attributes
    ----------
    params : tuple of float
        (mu1 [Pa*s], mu2 [1/K], mu3 [Pa*s], mu4 [1/K]).
    stderr : tuple of float
        Standard errors of the parameters (same units).
    rms_relative_error : float
        RMS of ``(model - data) / data`` [-].
    n_samples : int
    """

    params: tuple
    stderr: tuple
    rms_relative_error: float
    n_samples: int

    def __call__(self, temperature_c):
        """Evaluate the fitted law [Pa*s]."""
        return atf_viscosity(temperature_c, *self.params)

    def report(self) -> str:
        """One-paragraph summary."""
        names = ("mu1 [Pa*s]", "mu2 [1/K]", "mu3 [Pa*s]", "mu4 [1/K]")
        rows = [f"  {n:<12} {v: .6g} +/- {s:.2g}" for n, v, s in zip(names, self.params, self.stderr)]
        return "ATF viscosity fit (Eq. 7), {} samples, rms rel. error {:.3g}\n".format(
            self.n_samples, self.rms_relative_error) + "\n".join(rows)


def fit_viscosity(temperature_c, viscosity) -> ViscosityFit:
    """Fit the two-exponential law of Eq. 7 to (temperature, viscosity) samples.

    Shin et al. [1], Sec. 2.2 ("fitted as the sum of two exponential
    functions").  Least squares on the relative error (log residuals), started
    from a physics-based guess: the slow exponential from a log-linear fit to
    the hottest half, the fast one from the remainder at the coldest points.

    Parameters
    ----------
    temperature_c : array_like
        Temperatures [degC], at least 5 distinct values.
    viscosity : array_like
        Measured dynamic viscosity [Pa*s], > 0.

    Returns
    -------
    ViscosityFit

    Raises
    ------
    DataError
        Mismatched lengths, non-finite or non-positive viscosity, too few points.
    IdentificationError
        If the optimiser fails.
    """
    from scipy.optimize import least_squares

    t = np.asarray(temperature_c, dtype=float).ravel()
    mu = np.asarray(viscosity, dtype=float).ravel()
    if t.shape != mu.shape:
        raise DataError(f"temperature_c has {t.size} samples but viscosity has {mu.size}")
    if not np.all(np.isfinite(t)) or not np.all(np.isfinite(mu)):
        raise DataError("temperature_c/viscosity: non-finite sample")
    if np.any(mu <= 0):
        raise DataError(f"viscosity: non-positive value {short_repr(mu[mu <= 0][0])} [Pa*s]")
    if np.unique(t).size < 5:
        raise DataError(f"fit_viscosity needs at least 5 distinct temperatures, got {np.unique(t).size}")
    order = np.argsort(t)
    t, mu = t[order], mu[order]
    hot = t >= np.median(t)
    b4, a4 = np.polyfit(t[hot], np.log(mu[hot]), 1)
    slow = np.exp(a4 + b4 * t)
    rest = mu - slow
    cold = (~hot) & (rest > 0)
    if cold.sum() >= 2:
        b2, a2 = np.polyfit(t[cold], np.log(rest[cold]), 1)
        if b2 >= b4:
            b2 = 3.0 * b4
    else:
        b2, a2 = 3.0 * b4, math.log(max(mu[0] * 0.5, 1e-12)) - 3.0 * b4 * t[0]
    x0 = np.array([a2, b2, a4, b4])

    def resid(p):  # log residuals of Eq. 7 with log-amplitudes as unknowns
        return np.log(atf_viscosity(t, np.exp(p[0]), p[1], np.exp(p[2]), p[3])) - np.log(mu)

    sol = least_squares(resid, x0, method="lm", x_scale="jac")
    if not sol.success:
        raise IdentificationError(f"fit_viscosity: optimiser failed ({sol.message})")
    p = sol.x
    params = np.array([math.exp(p[0]), p[1], math.exp(p[2]), p[3]])
    if params[1] > params[3]:  # order: fast exponential first, as in Table 1
        params = params[[2, 3, 0, 1]]
        p = p[[2, 3, 0, 1]]
    dof = max(t.size - 4, 1)
    s2 = float(sol.fun @ sol.fun) / dof
    jac = sol.jac
    try:
        cov = np.linalg.inv(jac.T @ jac) * s2
        se_log = np.sqrt(np.clip(np.diag(cov), 0, None))
    except np.linalg.LinAlgError:
        se_log = np.full(4, np.nan)
    if not np.array_equal(p, sol.x):
        se_log = se_log[[2, 3, 0, 1]]
    stderr = (params[0] * se_log[0], se_log[1], params[2] * se_log[2], se_log[3])
    model = atf_viscosity(t, *params)
    rms = float(np.sqrt(np.mean(((model - mu) / mu) ** 2)))
    return ViscosityFit(tuple(float(v) for v in params), tuple(float(v) for v in stderr), rms, int(t.size))
