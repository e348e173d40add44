"""Friction coefficient and drag torque of the EMTC friction elements ([1], Sec. 3.3).

Three friction options: a constant coefficient, a coefficient map
``mu(slip speed, temperature)``, and the LuGre model (Eqs. 22-24) whose
bristle state is advanced in closed form over each step (stable for any step size):
:func:`lugre_advance` at a held slip (a sampled slip history), :func:`lugre_advance_path`
along the slip's path over an integrator step (the drum bench, docs/emtc.md).
The open-clutch drag torque is Eq. 25; Eq. 26 selects drag or friction torque.

References
----------
.. [1] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557,
   doi:10.3390/pr7090557
.. [2] C. Canudas de Wit, H. Olsson, K. J. Astrom, P. Lischinsky, "A new model
   for control of systems with friction", IEEE TAC 40 (1995) 419-425.
"""

from __future__ import annotations

import dataclasses
import math

import numba
import numpy as np

from ..errors import DataError, ParameterError
from ..params import ParameterSet, quantity
from ._lookup import bilinear_many

__all__ = [
    "LuGreParameters",
    "stribeck",
    "lugre_steady_state",
    "lugre_simulate",
    "LuGreResult",
    "FrictionMap",
    "drag_torque",
    "coupling_torque",
]


@dataclasses.dataclass(frozen=True)
class LuGreParameters(ParameterSet):
    """LuGre friction-coefficient parameters ([1], Eqs. 22-24).

    Slip speed is the relative angular speed of the friction surfaces [rad/s],
    so the bristle deflection ``z`` is an angle [rad] and ``sigma0`` is per radian.
    Defaults are representative for a wet paper lining (clutchlab's choice).
    """

    kind = "lugre"

    sigma0: float = quantity(2000.0, "1/rad", "bristle stiffness sigma0", source="representative", positive=True)
    sigma1: float = quantity(5.0, "s/rad", "bristle damping sigma1", source="representative", nonnegative=True)
    sigma2: float = quantity(0.0005, "s/rad", "viscous coefficient sigma2", source="representative", nonnegative=True)
    mu_c: float = quantity(0.11, "1", "Coulomb friction coefficient mu_cl", source="representative", positive=True)
    mu_p: float = quantity(0.13, "1", "peak (static) friction coefficient mu_p", source="representative", positive=True)
    v_s: float = quantity(2.0, "rad/s", "Stribeck slip speed v_s", source="representative", positive=True)

    def check(self) -> None:
        if self.mu_p < self.mu_c:
            raise ParameterError(
                f"LuGreParameters: mu_p = {self.mu_p!r} < mu_c = {self.mu_c!r}: the peak (static) coefficient must "
                "not be below the Coulomb level (Eq. 24: g(v) falls from mu_p to mu_c)")

    def kernel_data(self) -> np.ndarray:
        """``[sigma0, sigma1, sigma2, mu_c, mu_p, v_s]`` for compiled kernels."""
        return np.array([self.sigma0, self.sigma1, self.sigma2, self.mu_c, self.mu_p, self.v_s])


@numba.njit(cache=True, nogil=True)
def stribeck_g(v, p):
    """Stribeck curve ``g(v) = mu_cl + (mu_p - mu_cl) exp(-(v/v_s)^2)`` at one slip speed ([1], Eq. 24).

    Parameters
    ----------
    v : float
        Slip speed [rad/s].
    p : ndarray
        :meth:`LuGreParameters.kernel_data` ``[sigma0, sigma1, sigma2, mu_c, mu_p, v_s]``.

    Returns
    -------
    float
        ``g(v)`` [-], between ``mu_c`` and ``mu_p``.
    """
    return p[3] + (p[4] - p[3]) * math.exp(-((v / p[5]) ** 2))  # [1], Eq. 24


@numba.njit(cache=True, nogil=True)
def _stribeck_many(v, p, out):
    for k in range(v.shape[0]):
        out[k] = stribeck_g(v[k], p)


@numba.njit(cache=True, nogil=True)
def lugre_advance(z, v, h, p):
    """Bristle state after ``h`` seconds at constant slip speed ``v`` (exact solution of [1], Eq. 23).

    ``dz/dt = v - sigma0 |v| / g(v) z`` is linear in ``z`` for constant ``v``:
    ``z(h) = z_ss + (z - z_ss) exp(-sigma0 |v| h / g(v))`` with
    ``z_ss = g(v) sgn(v) / sigma0``; unconditionally stable and bounded.

    Parameters
    ----------
    z : float
        Bristle deflection at the start [rad].
    v : float
        Slip speed held over the interval [rad/s].
    h : float
        Interval [s]; ``h <= 0`` (or ``v = 0``) returns ``z`` unchanged.
    p : ndarray
        :meth:`LuGreParameters.kernel_data`.
    """
    if v == 0.0 or h <= 0.0:
        return z
    g = stribeck_g(v, p)
    zss = g / p[0] * (1.0 if v > 0.0 else -1.0)
    return zss + (z - zss) * math.exp(-p[0] * abs(v) * h / g)


@numba.njit(cache=True, nogil=True)
def _lugre_path(z, v0, v1, a0, h, p):
    """:func:`lugre_advance_path` over an interval in which the slip keeps one sign (``v0 * v1 >= 0``)."""
    s = 1.0 if v0 + v1 > 0.0 else -1.0
    vm = 0.5 * (v0 + v1)
    am = p[0] * abs(vm) / stribeck_g(vm, p) * h  # lambda h at the middle speed
    # the speed at which lambda and z_ss' are held: the centre of the kernel exp(-lambda (h - s)) that weighs the
    # forcing over the interval: the middle where the bristles are slow, the end where they are fast
    back = 0.5 - am / 12.0 if am < 1e-3 else 1.0 / am - 1.0 / math.expm1(am)
    ve = v1 - back * (v1 - v0)
    lam = p[0] * abs(ve) / stribeck_g(ve, p)  # relaxation rate of Eq. 23 [1/s]
    a = lam * h
    decay = math.exp(-a)
    # the forcing int_0^h exp(-lambda (h - s)) dv/ds ds for dv/ds linear from a0 to a1 = 2 (v1 - v0)/h - a0 (the
    # quadratic path): a1 phi - (a1 - a0) psi, phi = (1 - e^-a)/lambda, psi = (1 - e^-a (1 + a))/(lambda^2 h)
    if a < 1e-4:
        phi_h = 1.0 - 0.5 * a + a * a / 6.0          # phi / h
        psi_h = 0.5 - a / 3.0 + a * a / 8.0          # psi / h
    else:
        phi_h = -math.expm1(-a) / a
        psi_h = (-math.expm1(-a) - a * decay) / (a * a)
    dv = v1 - v0
    forcing = 2.0 * dv * (phi_h - psi_h) + a0 * h * (2.0 * psi_h - phi_h)
    dg = -2.0 * (p[4] - p[3]) * ve / (p[5] * p[5]) * math.exp(-((ve / p[5]) ** 2))  # g'(v) of Eq. 24
    z0 = s * stribeck_g(v0, p) / p[0]
    z1 = s * stribeck_g(v1, p) / p[0]
    # w = z - z_ss(v) obeys dw/dt = -lambda(v) w - z_ss'(v) dv/dt; lambda and z_ss' held at ve
    return z1 + (z - z0) * decay - s * dg / p[0] * forcing


@numba.njit(cache=True, nogil=True)
def lugre_advance_path(z, v0, v1, a0, h, p):
    """Bristle state after ``h`` seconds of a slip speed moving from ``v0`` to ``v1`` ([1], Eq. 23).

    The slip follows the quadratic path that starts with the slope ``a0`` (the slip acceleration at the start,
    [rad/s^2]) and ends at ``v1``.  Eq. 23 is written for the deviation from the steady state,
    ``w = z - z_ss(v)`` with ``z_ss = g(v) sgn(v) / sigma0``: while the slip keeps its sign it reads
    ``dw/dt = -lambda(v) w - z_ss'(v) dv/dt`` with ``lambda = sigma0 |v| / g(v)``, solved exactly with
    ``lambda`` and ``z_ss'`` held at one speed: the centre of the kernel ``exp(-lambda (h - s))`` that weighs
    the forcing, which is the middle speed where the bristles are slow (``lambda h`` small: second order in
    ``h``) and the end speed where they are fast (``1/lambda`` is 30 us at 2 rad/s).  There the result is the
    steady state at ``v1`` plus the bristles' lag behind the slip's acceleration *at the end*, which Eq. 22's
    damping ``sigma1 dz/dt`` multiplies by ``sigma1 lambda`` (about 2e5): a path with the acceleration of the
    interval's secant (a straight ramp) would put the lag half a step behind, an error first order in the step
    that no error estimate of the integrator sees (docs/emtc.md); an update at a held mid-interval slip
    (:func:`lugre_advance`) leaves ``z`` on the steady state of the middle speed, a far larger one.  A slip that
    changes sign within the interval is advanced along a straight ramp to its zero and on from there.
    ``h <= 0`` returns ``z``.

    Parameters
    ----------
    z : float
        Bristle deflection at the start [rad].
    v0, v1 : float
        Slip speed at the start and the end of the interval [rad/s].
    a0 : float
        Slip acceleration at the start [rad/s^2].
    h : float
        Interval [s].
    p : ndarray
        :meth:`LuGreParameters.kernel_data`.

    Returns
    -------
    float
        Bristle deflection at the end [rad].
    """
    if h <= 0.0:
        return z
    if v0 == 0.0 and v1 == 0.0:
        return z  # Eq. 23: dz/dt = 0 at zero slip
    if v0 * v1 >= 0.0:
        return _lugre_path(z, v0, v1, a0, h, p)
    h0 = h * v0 / (v0 - v1)  # the slip's zero (on the straight ramp)
    ramp = (v1 - v0) / h
    return _lugre_path(_lugre_path(z, v0, 0.0, ramp, h0, p), 0.0, v1, ramp, h - h0, p)


@numba.njit(cache=True, nogil=True)
def lugre_mu(z, v, p):
    """Friction coefficient ``sigma0 z + sigma1 dz/dt + sigma2 v`` ([1], Eqs. 22-23).

    Parameters
    ----------
    z : float
        Bristle deflection [rad].
    v : float
        Slip speed [rad/s].
    p : ndarray
        :meth:`LuGreParameters.kernel_data`.

    Returns
    -------
    float
        Friction coefficient [-] (signed like the slip).
    """
    zdot = v - p[0] * abs(v) / stribeck_g(v, p) * z  # [1], Eq. 23
    return p[0] * z + p[1] * zdot + p[2] * v  # [1], Eq. 22


@numba.njit(cache=True, nogil=True)
def _lugre_run(t, v, p, z0, mu, z):
    zc = z0
    z[0] = zc
    mu[0] = lugre_mu(zc, v[0], p)
    for i in range(1, t.shape[0]):
        h = t[i] - t[i - 1]
        zc = lugre_advance(zc, 0.5 * (v[i] + v[i - 1]), h, p)
        z[i] = zc
        mu[i] = lugre_mu(zc, v[i], p)


def stribeck(slip_speed, params: LuGreParameters):
    """Stribeck curve ``g(v) = mu_cl + (mu_p - mu_cl) exp(-(v/v_s)^2)`` ([1], Eq. 24).

    Parameters
    ----------
    slip_speed : array_like
        Relative speed of the friction surfaces [rad/s].
    params : LuGreParameters

    Returns
    -------
    numpy.ndarray or float
        ``g(v)`` [-].
    """
    v = np.asarray(slip_speed, dtype=float)
    out = np.empty(v.shape)
    _stribeck_many(np.ascontiguousarray(v).ravel(), params.kernel_data(), out.reshape(-1))  # [1], Eq. 24
    return float(out) if out.ndim == 0 else out


def lugre_steady_state(slip_speed, params: LuGreParameters):
    """Steady-state LuGre coefficient ``g(v) sgn(v) + sigma2 v`` ([1], Eqs. 22-24 with dz/dt = 0).

    Parameters
    ----------
    slip_speed : array_like
        Slip speed v [rad/s].
    params : LuGreParameters
        sigma0, sigma1, sigma2 and the Stribeck curve g(v).

    Returns
    -------
    (mu, z) : friction coefficient [-] and bristle deflection [rad].
    """
    v = np.asarray(slip_speed, dtype=float)
    g = stribeck(v, params)
    z = g * np.sign(v) / params.sigma0  # [1], Eq. 23 with dz/dt = 0
    return params.sigma0 * z + params.sigma2 * v, z


@dataclasses.dataclass
class LuGreResult:
    """LuGre response: ``time`` [s], ``slip_speed`` [rad/s], ``mu`` [-], ``z`` [rad]."""

    time: np.ndarray
    slip_speed: np.ndarray
    mu: np.ndarray
    z: np.ndarray

    def to_dataframe(self):
        import pandas as pd

        return pd.DataFrame({"time": self.time, "slip_speed": self.slip_speed, "mu": self.mu, "z": self.z})


def lugre_simulate(time, slip_speed, params: LuGreParameters, z0: float = 0.0) -> LuGreResult:
    """Friction coefficient of the LuGre model for a slip-speed history ([1], Eqs. 22-24).

    The bristle state is advanced exactly between samples with the slip speed
    held at the mid-interval value (see :func:`lugre_advance`), so any sample
    spacing is stable and ``|z| <= max(|z0|, mu_p/sigma0)`` holds.

    Parameters
    ----------
    time : array_like
        Strictly increasing sample times [s].
    slip_speed : array_like
        Slip speed at each sample [rad/s].
    params : LuGreParameters
    z0 : float
        Initial bristle deflection [rad].
    """
    t = np.asarray(time, dtype=float)
    v = np.asarray(slip_speed, dtype=float)
    if t.shape != v.shape or t.ndim != 1 or t.size < 1:
        raise DataError("lugre_simulate: time and slip_speed must be 1-D arrays of equal length")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
        raise DataError("lugre_simulate: time or slip_speed has non-finite values")
    if np.any(np.diff(t) <= 0):
        raise DataError("lugre_simulate: time must be strictly increasing")
    mu = np.empty(t.size)
    z = np.empty(t.size)
    _lugre_run(t, v, params.kernel_data(), float(z0), mu, z)
    return LuGreResult(t, v, mu, z)


class FrictionMap:
    """Kinetic friction coefficient as a table ``mu(slip speed, temperature)``.

    Bilinear interpolation, clamped at the table edges; symmetric in the sign
    of the slip speed (the table is given for ``|slip speed|``).

    Parameters
    ----------
    slip_speed : array_like
        Strictly increasing ``|slip speed|`` grid [rad/s] (>= 0).
    temperature_c : array_like
        Strictly increasing temperature grid [degC].
    mu : array_like, shape (len(slip_speed), len(temperature_c))
        Coefficients [-] (> 0).
    """

    def __init__(self, slip_speed, temperature_c, mu):
        v = np.asarray(slip_speed, dtype=float)
        tc = np.asarray(temperature_c, dtype=float)
        m = np.asarray(mu, dtype=float)
        for name, arr in (("slip_speed", v), ("temperature_c", tc)):
            if arr.ndim != 1 or arr.size < 2:
                raise DataError(f"FrictionMap.{name}: need a 1-D grid of at least two values")
            if not np.all(np.isfinite(arr)) or np.any(np.diff(arr) <= 0):
                raise DataError(f"FrictionMap.{name}: must be finite and strictly increasing")
        if np.any(v < 0):
            raise DataError("FrictionMap.slip_speed: the grid is for |slip speed| and must be >= 0")
        if m.shape != (v.size, tc.size):
            raise DataError(f"FrictionMap.mu: shape {m.shape}, expected {(v.size, tc.size)}")
        if not np.all(np.isfinite(m)) or np.any(m <= 0):
            raise DataError("FrictionMap.mu: coefficients must be finite and > 0")
        self.slip_speed, self.temperature_c, self.mu = v, tc, m

    def __call__(self, slip_speed, temperature_c):
        """Coefficient at the given slip speed [rad/s] and temperature [degC] (broadcasting)."""
        v, tc = np.broadcast_arrays(np.abs(np.asarray(slip_speed, float)), np.asarray(temperature_c, float))
        out = np.empty(v.size)
        bilinear_many(self.slip_speed, self.temperature_c, self.mu, np.ascontiguousarray(v).ravel(),
                      np.ascontiguousarray(tc).ravel(), out)  # the table look-up of the bench model's hooks
        return out.reshape(v.shape) if v.ndim else float(out[0])


def drag_torque(n_pairs, viscosity, slip_speed, clearance, r_outer, r_inner):
    """Viscous drag torque of an open wet clutch ([1], Eq. 25).

    ``T_drag = N pi omega mu / (2 h) (R_o^4 - R_i^4)``: laminar Couette shear
    of the fluid film in each of the ``N`` gaps.

    Parameters
    ----------
    n_pairs : int
        Number of friction pairs (fluid gaps) N (>= 0).
    viscosity : float
        Dynamic viscosity of the fluid [Pa*s] (> 0).
    slip_speed : array_like
        Relative speed of the discs [rad/s] (signed; the torque has its sign).
    clearance : float
        Axial clearance h between consecutive discs [m] (> 0).
    r_outer, r_inner : float
        Outer and inner radius of the wetted annulus [m], ``0 <= r_inner < r_outer``.

    Returns
    -------
    numpy.ndarray or float
        Drag torque [N*m].
    """
    if isinstance(n_pairs, bool) or not float(n_pairs) == int(n_pairs) or n_pairs < 0:
        raise ParameterError(f"n_pairs = {n_pairs!r}: must be a whole number >= 0")
    for name, val in (("viscosity", viscosity), ("clearance", clearance), ("r_outer", r_outer)):
        if not (np.isfinite(val) and val > 0):
            raise ParameterError(f"{name} = {val!r}: must be finite and > 0")
    if not (np.isfinite(r_inner) and 0 <= r_inner < r_outer):
        raise ParameterError(f"r_inner = {r_inner!r}: must satisfy 0 <= r_inner < r_outer = {r_outer!r}")
    w = np.asarray(slip_speed, dtype=float)
    if not np.all(np.isfinite(w)):
        raise ParameterError("slip_speed: not finite")
    out = np.empty(w.shape)
    _drag_many(float(n_pairs), float(viscosity), np.ascontiguousarray(w).ravel(), float(clearance), float(r_outer),
               float(r_inner), out.reshape(-1))  # [1], Eq. 25
    return float(out) if out.ndim == 0 else out


@numba.njit(cache=True, nogil=True)
def drag_torque_scalar(n_pairs, viscosity, slip_speed, clearance, r_outer, r_inner):
    """Viscous drag torque of the open coupling at one slip speed ([1], Eq. 25).

    ``T_drag = N pi omega mu / (2 h) (R_o^4 - R_i^4)``: laminar Couette shear of the fluid film in each
    of the ``N`` gaps.  Used by :func:`drag_torque` and by the bench model's hooks.

    Parameters
    ----------
    n_pairs : float
        Fluid gaps N [-].
    viscosity : float
        Dynamic viscosity of the fluid [Pa*s].
    slip_speed : float
        Relative speed of the discs [rad/s] (the torque has its sign).
    clearance : float
        Axial clearance h between consecutive discs [m].
    r_outer, r_inner : float
        Outer and inner radius of the wetted annulus [m].

    Returns
    -------
    float
        Drag torque [N*m].
    """
    return n_pairs * math.pi * slip_speed * viscosity / (2.0 * clearance) * (r_outer**4 - r_inner**4)  # [1], Eq. 25


@numba.njit(cache=True, nogil=True)
def _drag_many(n_pairs, viscosity, w, clearance, r_outer, r_inner, out):
    for k in range(w.shape[0]):
        out[k] = drag_torque_scalar(n_pairs, viscosity, w[k], clearance, r_outer, r_inner)


@numba.njit(cache=True, nogil=True)
def coupling_torque_scalar(engaged, t_drag, t_friction):
    """Torque the EMTC transfers at one instant: drag when open, friction when engaged ([1], Eq. 26).

    Parameters
    ----------
    engaged : bool
        ``eta``: True when the primary clutch is pressed.
    t_drag, t_friction : float
        Drag torque (Eq. 25) and friction torque (Eqs. 15/17 slipping, Eqs. 21/30 locked) [N*m].
    """
    return t_friction if engaged else t_drag  # [1], Eq. 26


@numba.njit(cache=True, nogil=True)
def _coupling_many(engaged, t_drag, t_friction, out):
    for k in range(out.shape[0]):
        out[k] = coupling_torque_scalar(engaged[k], t_drag[k], t_friction[k])


def coupling_torque(engaged, t_drag, t_friction):
    """Torque the EMTC transfers: drag when open, friction when engaged ([1], Eq. 26).

    Parameters
    ----------
    engaged : bool or array_like of bool
        ``eta``: True when the primary clutch is pressed (``F_n1 > 0``).
    t_drag, t_friction : array_like
        Drag torque (Eq. 25) and friction torque (Eqs. 15/21) [N*m].

    Returns
    -------
    numpy.ndarray
        Transferred torque [N*m], broadcast over the three arguments.
    """
    e, d, f = np.broadcast_arrays(np.asarray(engaged, dtype=bool), np.asarray(t_drag, dtype=float),
                                  np.asarray(t_friction, dtype=float))
    out = np.empty(e.shape)
    _coupling_many(np.ascontiguousarray(e).ravel(), np.ascontiguousarray(d).ravel(), np.ascontiguousarray(f).ravel(),
                   out.reshape(-1))  # [1], Eq. 26
    return out
