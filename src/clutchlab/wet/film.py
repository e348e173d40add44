"""Clutch geometry, fluid film and asperity contact of a wet multi-plate clutch.

Pure, vectorised functions in SI units implementing Section 2 of Shin, Kim and
Choi [1]: the torque effective radius and mean slip speed (the paper numbers
them (1) and (2) a second time in Sec. 2.1; clutchlab calls them Eq. (1') and
(2')), the nominal separation from the piston position (Eq. 1) and the
Patir-Cheng mean film thickness (Eq. 2).  The engagement model adds the
Greenwood-Williamson asperity contact pressure [3] and the Reynolds
squeeze-film force between annular plates [2, 4] on which the engagement
model of Deur et al. [4] is built.

Each equation is written once, as a scalar compiled function with its
docstring (``*_scalar``), called by the engagement model's hooks
(:mod:`clutchlab.wet.system`).  The vectorised public functions evaluate the
same function: arithmetic ones run its Python body on NumPy arrays
(``.py_func``, broadcasting), the branching Eq. 2 runs it in a small compiled
loop.

References
----------
.. [1] S. Shin, D.-H. Kim, S. B. Choi, "Apparatus for identification of
   frictional and thermal characteristics of a wet clutch", Int. J. Automotive
   Technology (KAIST preprint).
.. [2] N. Patir, H. S. Cheng, "Application of average flow model to lubrication
   between rough sliding surfaces", J. Lubrication Technol. 101 (1979) 220-229,
   doi:10.1115/1.3453329
.. [3] J. A. Greenwood, J. B. P. Williamson, "Contact of nominally flat
   surfaces", Proc. R. Soc. Lond. A 295 (1966) 300-319, doi:10.1098/rspa.1966.0242
.. [4] J. Deur, J. Petric, J. Asgari, D. Hrovat, "Modeling of wet clutch
   engagement including a thorough experimental validation", SAE Trans. (2005)
   1013-1028, doi:10.4271/2005-01-0877
"""

from __future__ import annotations

import math
from functools import lru_cache

import numba
import numpy as np
from numba.extending import overload

from ..errors import ParameterError

__all__ = [
    "effective_radius",
    "slip_velocity",
    "nominal_separation",
    "mean_film_thickness",
    "gw_integral",
    "asperity_contact_pressure",
    "squeeze_film_coefficient",
    "squeeze_film_force",
    "gw_pressure_scale",
    "gw_pressure_scale_scalar",
    "effective_radius_scalar",
    "squeeze_film_coefficient_scalar",
]

_SQRT2 = math.sqrt(2.0)
_SQRT2PI = math.sqrt(2.0 * math.pi)


def _positive(name, value):
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise ParameterError(f"{name} = {value!r}: must be finite and > 0")
    return arr


def effective_radius(r_outer, r_inner):
    """Torque effective radius of an annular friction face.

    Shin et al. [1], Sec. 2.1, Eq. (1') (printed as a second "(1)"):
    ``R_eff = 2/3 (R_o^3 - R_i^3) / (R_o^2 - R_i^2)`` -- the radius at which a
    uniform pressure's friction force acts.  With Table 1 (R_o = 83.15 mm,
    R_i = 71.74 mm) this gives 0.077585 m, Table 1's 0.07758 m; the arithmetic
    mean radius (0.077445 m) does not.

    Parameters
    ----------
    r_outer : array_like
        Outer radius of the clutch disk R_o [m].
    r_inner : array_like
        Inner radius R_i [m], ``0 <= r_inner < r_outer``.

    Returns
    -------
    numpy.ndarray or float
        Effective radius R_eff [m].

    Notes
    -----
    Assumes uniform contact pressure over the face (constant-pressure rather
    than constant-wear hypothesis).
    """
    ro = _positive("r_outer", r_outer)
    ri = np.asarray(r_inner, dtype=float)
    if not np.all(np.isfinite(ri)) or np.any(ri < 0) or np.any(ri >= ro):
        raise ParameterError(f"r_inner = {r_inner!r}: must satisfy 0 <= r_inner < r_outer = {r_outer!r}")
    if ri.ndim == 0 and np.ndim(ro) == 0:   # (the compiled form: the number the wet model's start derives)
        return float(effective_radius_scalar(float(ro), float(ri)))   # [1], Eq. (1')
    return np.asarray(effective_radius_scalar.py_func(ro, ri))


@numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def effective_radius_scalar(r_outer, r_inner):
    """``R_eff = 2/3 (R_o^3 - R_i^3) / (R_o^2 - R_i^2)`` [m] (Shin et al. [1], Eq. (1')), compiled scalar form: the
    wet model's compiled start derives its effective radius with it (:func:`effective_radius` checks its
    arguments, ``0 <= R_i < R_o`` [m]).  Uniform contact pressure over the face."""
    return 2.0 / 3.0 * (r_outer ** 3 - r_inner ** 3) / (r_outer ** 2 - r_inner ** 2)  # [1], Eq. (1')


def slip_velocity(slip_speed, r_eff):
    """Mean slip velocity of the friction faces, ``v = R_eff * dw`` ([1], Eq. (2')).

    Parameters
    ----------
    slip_speed : array_like
        Clutch rotational slip speed [rad/s].
    r_eff : float
        Torque effective radius [m].

    Returns
    -------
    numpy.ndarray or float
        Slip velocity v [m/s].
    """
    out = np.asarray(slip_velocity_scalar.py_func(np.asarray(slip_speed, dtype=float), np.asarray(r_eff, dtype=float)))
    return float(out) if out.ndim == 0 else out


@numba.njit(cache=True, nogil=True, inline="always")
def slip_velocity_scalar(slip_speed, r_eff):
    """Mean slip velocity ``v = R_eff * dw`` [m/s] (Shin et al. [1], Eq. (2')), compiled scalar form.

    Parameters
    ----------
    slip_speed : float
        Clutch slip speed dw [rad/s].
    r_eff : float
        Torque effective radius [m].
    """
    return r_eff * slip_speed  # [1], Eq. (2')


def nominal_separation(piston_position, piston_h0, n_c):
    """Nominal separation between lining and core disk from the piston position.

    Shin et al. [1], Eq. 1: ``h = (x_{p,h0} - x_p) / N_c``; the piston stroke is
    shared equally by the ``N_c`` friction interfaces.

    Parameters
    ----------
    piston_position : array_like
        Piston position x_p [m], positive towards the clutch pack.
    piston_h0 : float
        Piston position x_{p,h0} at which h = 0 [m].
    n_c : int
        Number of clutches N_c [-].

    Returns
    -------
    numpy.ndarray or float
        Nominal separation h [m] (negative once asperities are compressed).
    """
    if not (isinstance(n_c, (int, np.integer)) or float(n_c).is_integer()) or n_c < 1:
        raise ParameterError(f"n_c = {n_c!r}: must be a positive whole number")
    out = np.asarray(separation_scalar.py_func(np.asarray(piston_position, dtype=float), float(piston_h0), float(n_c)))
    return float(out) if out.ndim == 0 else out


@numba.njit(cache=True, nogil=True, inline="always")
def separation_scalar(piston_position, piston_h0, n_c):
    """Nominal separation ``h = (x_{p,h0} - x_p) / N_c`` [m] (Shin et al. [1], Eq. 1), compiled scalar form.

    Parameters
    ----------
    piston_position : float
        Piston position x_p [m], positive towards the pack.
    piston_h0 : float
        Piston position at zero separation [m].
    n_c : float
        Number of clutches N_c [-]; the stroke is shared equally by the interfaces.
    """
    return (piston_h0 - piston_position) / n_c  # [1], Eq. 1


def mean_film_thickness(h, sigma):
    """Average fluid film thickness for Gaussian roughness (Patir and Cheng).

    Shin et al. [1], Eq. 2 (from Patir and Cheng [2]):
    ``h_bar = h/2 [1 + erf(h / (sqrt(2) sigma))] + sigma/sqrt(2 pi) exp(-(h/(sqrt(2) sigma))^2)``,
    i.e. ``h_bar = sigma [t Phi(t) + phi(t)]`` with ``t = h/sigma``.

    Parameters
    ----------
    h : array_like
        Nominal separation [m]; any sign.
    sigma : float
        RMS roughness of the friction material [m], > 0.

    Returns
    -------
    numpy.ndarray or float
        Mean film thickness h_bar [m], > 0 for every finite h.

    Notes
    -----
    Evaluated by :func:`film_scalar` (the function the engagement model
    uses), written with ``erfc`` so that it stays accurate and positive for
    ``h << 0`` (the printed form cancels catastrophically):
    ``1 + erf(x) = erfc(-x)``; for ``t < -8`` the Mills-ratio series
    ``phi(t) (1/t^2 - 3/t^4 + 15/t^6 - 105/t^8 + 945/t^10)`` is used.  Limits:
    ``h >> sigma -> h``; ``h = 0 -> sigma/sqrt(2 pi)``; ``h << 0 -> 0+``.
    """
    s = float(_positive("sigma", sigma))
    hh = np.asarray(h, dtype=float)
    if not np.all(np.isfinite(hh / s)):
        raise ParameterError(f"h = {h!r}: must be finite")
    out = np.empty(hh.shape)
    _film_loop(np.ascontiguousarray(hh).ravel(), s, out.reshape(-1))
    return float(out) if out.ndim == 0 else out


@numba.njit(cache=True, nogil=True, inline="always", error_model="numpy")
def film_scalar(h, sigma):
    """Patir-Cheng mean film thickness h_bar [m] (Shin et al. [1], Eq. 2 from [2]), compiled scalar form.

    ``h_bar = sigma [t Phi(t) + phi(t)]`` with ``t = h / sigma`` -- the printed
    ``h/2 [1 + erf(h/(sqrt2 sigma))] + sigma/sqrt(2 pi) exp(-h^2/(2 sigma^2))``
    written with ``erfc`` (``1 + erf(x) = erfc(-x)``) and, for ``t < -8``, the
    Mills-ratio series, so that it stays positive and accurate for ``h << 0``.

    Parameters
    ----------
    h : float
        Nominal separation [m] (Eq. 1), any sign.
    sigma : float
        RMS roughness [m], > 0.

    Returns
    -------
    float
        h_bar [m], > 0.

    Notes
    -----
    Gaussian roughness, flow factors of [2] not modelled.
    """
    t = h / sigma
    if t >= -8.0:
        # [1], Eq. 2 as sigma * (t Phi(t) + phi(t)), Phi(t) = erfc(-t/sqrt2)/2
        return sigma * (0.5 * t * math.erfc(-t / 1.4142135623730951) + math.exp(-0.5 * t * t) / 2.5066282746310002)
    u = 1.0 / (t * t)
    phi = math.exp(-0.5 * t * t) / 2.5066282746310002
    # asymptotic tail phi(t) (1/t^2 - 3/t^4 + 15/t^6 - 105/t^8 + 945/t^10)
    return sigma * phi * u * (1.0 - 3.0 * u + 15.0 * u * u - 105.0 * u * u * u + 945.0 * u * u * u * u)


@numba.njit(cache=True, nogil=True, inline="always")
def _film_loop(h, sigma, out):
    """:func:`film_scalar` over a flat array (the vectorised :func:`mean_film_thickness`)."""
    for i in range(h.shape[0]):
        out[i] = film_scalar(h[i], sigma)


def gw_integral(t, order=1.5):
    """Greenwood-Williamson integral ``F_n(t) = int_t^inf (s - t)^n phi(s) ds`` [-].

    Greenwood and Williamson [3], Eq. 11 with a Gaussian summit-height density
    ``phi``; evaluated in closed form through the parabolic cylinder function,
    ``F_n(t) = Gamma(n+1)/sqrt(2 pi) exp(-t^2/4) D_{-n-1}(t)``.

    Parameters
    ----------
    t : array_like
        Standardised separation h/sigma [-].
    order : float
        n (1.5 for the load, 1 for the contact area, 0.5 for the stiffness).

    Returns
    -------
    numpy.ndarray or float
        F_n(t) [-]; ``F_1.5(0) = 0.43002``.
    """
    from scipy import special   # (here: scipy.special takes a quarter of a second to import)

    t = np.asarray(t, dtype=float)
    d = special.pbdv(-order - 1.0, t)[0]
    out = special.gamma(order + 1.0) / _SQRT2PI * np.exp(-0.25 * t * t) * d
    return float(out) if out.ndim == 0 else out


def asperity_contact_pressure(h, sigma, asperity_radius, asperity_density, contact_modulus):
    """Nominal asperity contact pressure of a rough lining on a smooth plate.

    Greenwood and Williamson [3] (Hertzian spherical asperity tips of radius
    beta, Gaussian heights), as used for the wet-clutch contact by Deur et al.
    [4]: ``p_c = 4/3 E' eta sqrt(beta) sigma^{3/2} F_{3/2}(h/sigma)``.

    Parameters
    ----------
    h : array_like
        Nominal separation [m].
    sigma : float
        RMS roughness [m] (used for the summit heights).
    asperity_radius : float
        Asperity tip radius beta [m].
    asperity_density : float
        Number of asperities per unit nominal area eta [1/m^2].
    contact_modulus : float
        Composite elastic modulus E' [Pa].

    Returns
    -------
    numpy.ndarray or float
        Contact pressure p_c [Pa], > 0 and decreasing in h.

    Notes
    -----
    Elastic asperities, no interaction between them, summit-height standard
    deviation taken equal to the surface RMS roughness sigma.  ``F_{3/2}`` is
    evaluated exactly (parabolic cylinder function); the engagement model
    uses the same equation in :func:`asperity_force_scalar` with ``F_{3/2}``
    from the cubic-Hermite table :func:`gw_table` (agreement 1e-7 relative
    for ``-12 <= h/sigma <= 8``).
    """
    s = float(_positive("sigma", sigma))
    coef = gw_pressure_scale(s, asperity_radius, asperity_density, contact_modulus)
    return coef * gw_integral(np.asarray(h, dtype=float) / s, 1.5)  # [3], Eq. 11


def gw_pressure_scale(sigma, asperity_radius, asperity_density, contact_modulus):
    """Pressure scale ``4/3 E' eta sqrt(beta) sigma^{3/2}`` of the GW model [Pa] (:func:`gw_pressure_scale_scalar`,
    its arguments checked > 0)."""
    b = float(_positive("asperity_radius", asperity_radius))
    e = float(_positive("asperity_density", asperity_density))
    m = float(_positive("contact_modulus", contact_modulus))
    return gw_pressure_scale_scalar(float(sigma), b, e, m)


@numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def gw_pressure_scale_scalar(sigma, asperity_radius, asperity_density, contact_modulus):
    """Pressure scale ``4/3 E' eta sqrt(beta) sigma^{3/2}`` of the Greenwood-Williamson contact [Pa] ([3], Eq. 11,
    the prefactor of ``F_{3/2}(h / sigma)``), compiled: the wet model's compiled ``start`` derives it with this.

    Parameters: ``sigma`` RMS roughness [m], ``asperity_radius`` beta [m], ``asperity_density`` eta [1/m^2],
    ``contact_modulus`` E' [Pa].  Assumes Gaussian asperity heights and Hertzian tips of one radius.
    """
    return 4.0 / 3.0 * contact_modulus * asperity_density * math.sqrt(asperity_radius) * sigma ** 1.5  # [3], Eq. 11


@lru_cache(maxsize=1)
def gw_table(t_min: float = -12.0, t_max: float = 8.0, n: int = 2001):
    """Tabulated ``F_{3/2}`` and its derivative ``-1.5 F_{1/2}`` for compiled kernels.

    Returns ``(t0, dt, values, derivatives)``; kernels interpolate with a
    cubic Hermite (error < 1e-9 relative for the default spacing 0.01).
    """
    t = np.linspace(t_min, t_max, n)
    values = gw_integral(t, 1.5)
    ders = -1.5 * gw_integral(t, 0.5)  # dF_n/dt = -n F_{n-1}
    values.setflags(write=False)
    ders.setflags(write=False)
    return float(t[0]), float(t[1] - t[0]), values, ders


def _gw_constants():
    """``(t0, dt, values, derivatives, n)`` of :func:`gw_table`: the table the compiled model uses
    (:func:`asperity_force_scalar`), as constants of its code -- a fixed approximation of a special function, not a
    parameter of the model.  Computed where a kernel that reads it is compiled (its overload below), not when
    clutchlab is imported: the table needs ``scipy.special``, a quarter of a second to import, and a cached kernel
    carries the numbers in its code."""
    t0, dt, values, ders = gw_table()
    return t0, dt, values, ders, values.shape[0]


@overload(_gw_constants)
def _gw_constants_compiled():
    t0, dt, values, ders, n = _gw_constants()

    def impl():   # (the arrays are closure constants: numba freezes them into the code)
        return t0, dt, values, ders, n

    return impl


@numba.njit(cache=True, nogil=True, inline="always", error_model="numpy")
def gw_scalar(t, t0, dt, values, ders):
    """Compiled cubic-Hermite lookup of ``F_{3/2}(t)`` in a :func:`gw_table`.

    Parameters
    ----------
    t : float
        Standardised separation h/sigma [-].
    t0, dt : float
        First node and spacing of the table [-].
    values, ders : ndarray
        ``F_{3/2}`` and its derivative at the nodes.

    Notes
    -----
    Zero beyond the last node, linear extrapolation before the first.
    """
    return gw_lookup(t, t0, dt, values, 0, ders, 0, values.shape[0])


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def gw_lookup(t, t0, dt, values, vstart, ders, dstart, n):
    """:func:`gw_scalar` on a table stored inside larger arrays: nodes at ``values[vstart:vstart + n]``
    and derivatives at ``ders[dstart:dstart + n]`` (the engagement model keeps its tables in one array).

    Parameters
    ----------
    t, t0, dt
        As :func:`gw_scalar`.
    values, ders : ndarray
        Arrays holding the node values and derivatives.
    vstart, dstart : int
        Index of the first node in each.
    n : int
        Number of nodes.
    """
    x = (t - t0) / dt
    if x >= n - 1:
        return 0.0
    if x < 0.0:
        return values[vstart] + ders[dstart] * (t - t0)
    i = int(x)
    th = x - i
    t2 = th * th
    t3 = t2 * th
    return ((2.0 * t3 - 3.0 * t2 + 1.0) * values[vstart + i] + (t3 - 2.0 * t2 + th) * dt * ders[dstart + i]
            + (-2.0 * t3 + 3.0 * t2) * values[vstart + i + 1] + (t3 - t2) * dt * ders[dstart + i + 1])


@numba.njit(cache=True, nogil=True, _nrt=False)  # (no reference counting: see clutchlab.wet.system._HOOK)
def asperity_force_scalar(h, sigma, area, pressure_scale):
    """Greenwood-Williamson asperity contact force ``F_c = A_f p_c(h)`` [N], compiled scalar form.

    Greenwood and Williamson [3], Eq. 11, as used by Deur et al. [4]:
    ``p_c = 4/3 E' eta sqrt(beta) sigma^{3/2} F_{3/2}(h/sigma)``, with
    ``F_{3/2}`` from the cubic-Hermite table of :func:`gw_table` (constants of the compiled code,
    :func:`_gw_constants`).

    Parameters
    ----------
    h : float
        Nominal separation [m] (Eq. 1).
    sigma : float
        RMS roughness [m].
    area : float
        Nominal friction area of one face A_f [m^2].
    pressure_scale : float
        ``4/3 E' eta sqrt(beta) sigma^{3/2}`` [Pa] (:func:`gw_pressure_scale`).

    Returns
    -------
    float
        F_c [N], carried by each of the interfaces in series.

    Notes
    -----
    Assumptions as :func:`asperity_contact_pressure`.
    """
    t0, dt, values, ders, n = _gw_constants()
    return area * pressure_scale * gw_lookup(h / sigma, t0, dt, values, 0, ders, 0, n)  # [3], Eq. 11


@numba.njit(cache=True, nogil=True)
def squeeze_film_force_scalar(coefficient, viscosity, dh_dt, mean_film):
    """Reynolds squeeze-film force ``F_h = K mu_v (-dh/dt) / h_bar^3`` [N], compiled scalar form.

    Rigid parallel annulus with the Patir-Cheng mean film in place of the
    smooth gap [2, 4] (see :func:`squeeze_film_force`).

    Parameters
    ----------
    coefficient : float
        Geometric factor K [m^4] (:func:`squeeze_film_coefficient`, times a
        groove/flow factor where the model has one).
    viscosity : float
        Dynamic viscosity mu_v [Pa*s] (Eq. 7).
    dh_dt : float
        Rate of change of the nominal separation [m/s] (negative when closing).
    mean_film : float
        Mean film thickness h_bar [m] (Eq. 2).

    Returns
    -------
    float
        Force pushing the plates apart [N] (negative: suction; no cavitation).
    """
    return coefficient * viscosity * (-dh_dt) / (mean_film * mean_film * mean_film)


def squeeze_film_coefficient(r_outer, r_inner):
    """Geometric factor K of the Reynolds squeeze film between annular plates [m^4].

    ``W = K mu (-dh/dt) / h^3`` with
    ``K = 3 pi / 2 [R_o^4 - R_i^4 - (R_o^2 - R_i^2)^2 / ln(R_o/R_i)]``
    (rigid parallel annulus, ambient pressure at both rims), the film
    equation at the heart of Deur et al. [4].

    Parameters
    ----------
    r_outer, r_inner : float
        Outer and inner radius of the friction face [m].

    Returns
    -------
    float
        K [m^4].
    """
    ro = float(_positive("r_outer", r_outer))
    ri = float(_positive("r_inner", r_inner))
    if ri >= ro:
        raise ParameterError(f"r_inner = {ri!r}: must be < r_outer = {ro!r}")
    return squeeze_film_coefficient_scalar(ro, ri)


@numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def squeeze_film_coefficient_scalar(r_outer, r_inner):
    """``K = 3 pi / 2 [R_o^4 - R_i^4 - (R_o^2 - R_i^2)^2 / ln(R_o/R_i)]`` [m^4] of the Reynolds squeeze film between
    rigid parallel annular plates (Deur et al. [4]), compiled scalar form: the wet model's compiled start derives
    its squeeze coefficient with it (:func:`squeeze_film_coefficient` checks ``0 < R_i < R_o`` [m])."""
    return 1.5 * math.pi * (r_outer ** 4 - r_inner ** 4 - (r_outer ** 2 - r_inner ** 2) ** 2
                            / math.log(r_outer / r_inner))


def squeeze_film_force(mean_film, dh_dt, viscosity, r_outer, r_inner):
    """Hydrodynamic squeeze-film force of one friction interface [N].

    Reynolds equation for an annulus with the Patir-Cheng mean film h_bar in
    place of the smooth-surface gap (flow factors taken as 1) [2, 4]:
    ``F_h = K mu_v (-dh/dt) / h_bar^3``.

    Parameters
    ----------
    mean_film : array_like
        Mean film thickness h_bar [m] (Eq. 2).
    dh_dt : array_like
        Rate of change of the nominal separation [m/s] (negative when closing).
    viscosity : array_like
        Dynamic viscosity mu_v [Pa*s] (Eq. 7).
    r_outer, r_inner : float
        Radii of the friction face [m].

    Returns
    -------
    numpy.ndarray or float
        Force pushing the plates apart [N]; negative (suction) when opening,
        cavitation is not modelled.
    """
    k = squeeze_film_coefficient(r_outer, r_inner)
    hb = _positive("mean_film", mean_film)
    out = squeeze_film_force_scalar.py_func(k, np.asarray(viscosity, dtype=float), np.asarray(dh_dt, dtype=float), hb)
    return float(out) if np.ndim(out) == 0 else out
