"""Torque transfer of the EMTC's three friction elements ([1], Sec. 3.2).

Element 1 is the primary (pilot) clutch pressed by the armature with the force
``F_n1``; its torque drives the ball-cam, whose axial force
``F_n2 = lambda/R * (T1 + T3)`` (Eq. 14) presses the secondary (main) clutch,
element 2, and the third friction element, element 3, whose torque also passes
through the ball-cam.  All three act in parallel between the input and the
output shaft (Fig. 10).

References
----------
.. [1] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557,
   doi:10.3390/pr7090557
"""

from __future__ import annotations

import dataclasses

import numba
import numpy as np

from ..errors import ParameterError
from ..params import ParameterSet, quantity

__all__ = [
    "CouplingGeometry",
    "slipping_torques",
    "slipping_capacities",
    "locked_capacities",
    "locked_torques",
    "locked_case",
    "UNLOCK_MARGIN",
]

#: locked -> slipping when ``abs(T_lock) > UNLOCK_MARGIN * T_cap_L`` ([1], Sec. 3.2, Fig. 11)
UNLOCK_MARGIN = 1.02


@dataclasses.dataclass(frozen=True)
class CouplingGeometry(ParameterSet):
    """Friction coefficients and radii of the three friction elements and the ball-cam.

    ``CouplingGeometry(mu_k, mu_s, radius, pairs, cam_ratio, cam_radius)``:

    Parameters
    ----------
    mu_k : (float, float, float)
        Kinetic friction coefficients of the primary clutch, the secondary
        (main) clutch and the third friction element [-].
    mu_s : (float, float, float)
        Static friction coefficients of the same three elements [-] (each
        ``>= mu_k``).
    radius : (float, float, float)
        Effective radii ``R1, R2, R3`` of Eq. 13 [m], where the torque is
        ``2/3 * mu * R_i * F_n * z``.
    pairs : (int, int)
        Friction pairs ``z1, z2`` of the primary and secondary clutch [-].
    cam_ratio : float
        Ball-cam amplification ``lambda`` (Eq. 14) [-].
    cam_radius : float
        Ball-cam working radius ``R`` (Eq. 14) [m].

    Notes
    -----
    Defaults are representative values chosen by clutchlab (the paper gives no
    numbers for the coupling): a pilot clutch of four pairs, a main clutch of
    ten pairs, a single third element, ball-cam with ``lambda = 5`` on
    ``R = 40 mm``.  The per-element values are also available as
    ``mu_k1 .. mu_k3``, ``mu_s1 .. mu_s3``, ``radius1 .. radius3``,
    ``pairs1``, ``pairs2``.
    """

    kind = "coupling"

    mu_k: tuple = quantity((0.12, 0.12, 0.10), "1", "kinetic friction coefficients (primary, secondary, third)",
                           source="representative", positive=True)
    mu_s: tuple = quantity((0.13, 0.13, 0.11), "1", "static friction coefficients (primary, secondary, third)",
                           source="representative", positive=True)
    radius: tuple = quantity((0.065, 0.070, 0.060), "m", "radii R1, R2, R3 of Eq. 13", source="representative",
                             positive=True)
    pairs: tuple = quantity((4, 10), "1", "friction pairs z1, z2 of the primary and secondary clutch",
                            source="representative", positive=True)
    cam_ratio: float = quantity(5.0, "1", "ball-cam amplification lambda (Eq. 14)", source="representative", positive=True)
    cam_radius: float = quantity(0.040, "m", "ball-cam working radius R (Eq. 14)", source="representative", positive=True)

    def check(self) -> None:
        for name, n in (("mu_k", 3), ("mu_s", 3), ("radius", 3), ("pairs", 2)):
            if len(getattr(self, name)) != n:
                raise ParameterError(f"CouplingGeometry.{name} = {getattr(self, name)!r}: expected {n} values")
        for i in (1, 2, 3):
            if getattr(self, f"mu_s{i}") < getattr(self, f"mu_k{i}"):
                raise ParameterError(
                    f"CouplingGeometry.mu_s{i} = {getattr(self, f'mu_s{i}')!r} < mu_k{i} = {getattr(self, f'mu_k{i}')!r}:"
                    " static friction must not be below kinetic friction")
        for k, v in enumerate(self.pairs, start=1):
            if v != int(v):
                raise ParameterError(f"CouplingGeometry.pairs{k} = {v!r}: expected a whole number")
        for mu_name in ("mu_k3", "mu_s3"):
            g = 2.0 * self.cam_ratio * getattr(self, mu_name) * self.radius3 / (3.0 * self.cam_radius)
            if g >= 1.0:
                raise ParameterError(
                    f"CouplingGeometry: 2*lambda*{mu_name}*R3/(3*R) = {g:.4g} >= 1: the ball-cam would self-lock "
                    "(Eqs. 15, 19, 20 need 3R > 2*lambda*mu3*R3)")

    # per-element views ([1] numbers the elements 1: primary, 2: secondary, 3: third)
    mu_k1 = property(lambda self: self.mu_k[0], doc="kinetic coefficient of the primary clutch [-]")
    mu_k2 = property(lambda self: self.mu_k[1], doc="kinetic coefficient of the secondary clutch [-]")
    mu_k3 = property(lambda self: self.mu_k[2], doc="kinetic coefficient of the third element [-]")
    mu_s1 = property(lambda self: self.mu_s[0], doc="static coefficient of the primary clutch [-]")
    mu_s2 = property(lambda self: self.mu_s[1], doc="static coefficient of the secondary clutch [-]")
    mu_s3 = property(lambda self: self.mu_s[2], doc="static coefficient of the third element [-]")
    radius1 = property(lambda self: self.radius[0], doc="radius R1 [m]")
    radius2 = property(lambda self: self.radius[1], doc="radius R2 [m]")
    radius3 = property(lambda self: self.radius[2], doc="radius R3 [m]")
    pairs1 = property(lambda self: int(self.pairs[0]), doc="friction pairs z1 [-]")
    pairs2 = property(lambda self: int(self.pairs[1]), doc="friction pairs z2 [-]")

    def kernel_data(self) -> np.ndarray:
        """Array ``[mu_k1..3, mu_s1..3, R1..3, z1, z2, lambda, R]`` for compiled kernels."""
        return np.array([*self.mu_k, *self.mu_s, *self.radius, float(self.pairs[0]), float(self.pairs[1]),
                         self.cam_ratio, self.cam_radius])


# ----------------------------------------------------------------- compiled core
@numba.njit(cache=True, nogil=True, error_model="numpy")
def _slipping(fn1, dw, g, mu1, mu2, mu3, out):
    """Torques of the three elements in slipping mode with given kinetic coefficients ([1], Eqs. 13-15).

    ``fn1``: primary-clutch normal force [N]; ``dw``: slip speed [rad/s] (only its sign is used);
    ``g``: :meth:`CouplingGeometry.kernel_data`; ``mu1..mu3``: kinetic coefficients [-];
    ``out[0:3]`` receives ``(T1, T2, T3)`` [N*m].  Used by :func:`slipping_torques`, by the bench
    model's right-hand side and, with ``fn1 = dw = 1``, by its controller (the gain ``T_c/F_n1``).
    """
    lam, rc = g[11], g[12]
    sgn = 1.0 if dw > 0.0 else (-1.0 if dw < 0.0 else 0.0)
    t1 = 2.0 / 3.0 * mu1 * g[6] * fn1 * g[9] * sgn  # [1], Eq. 15 (first line)
    den = 3.0 * rc - 2.0 * lam * mu3 * g[8]
    out[0] = t1
    out[1] = 2.0 * lam * mu2 * g[7] * g[10] / den * t1  # [1], Eq. 15 (second line)
    out[2] = 2.0 * lam * mu3 * g[8] / den * t1  # [1], Eq. 15 (third line)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _locked_coefficients(fn1, g):
    """(c1, a2, a3): T_cap_l1 = c1, T_cap_l2 = a2*(T1+T3), T_cap_l3 = a3*(T1+T3) (Eq. 18 with Eq. 14)."""
    lam_r = g[11] / g[12]
    c1 = 2.0 / 3.0 * g[3] * g[6] * g[9] * fn1  # [1], Eq. 18, T_cap_l1
    a2 = 2.0 / 3.0 * g[4] * g[7] * g[10] * lam_r  # [1], Eq. 18 with F_n2 = lambda/R (T_l1 + T_l3)
    a3 = 2.0 / 3.0 * g[5] * g[8] * lam_r
    return c1, a2, a3


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _locked_capacity(fn1, g):
    """Locked-mode capacity ``T_cap_L = c1 (1 + a2) / (1 - a3)`` with every element saturated ([1], Eq. 21).

    ``fn1`` is the primary-clutch normal force [N], ``g`` :meth:`CouplingGeometry.kernel_data` (the static
    coefficients ``mu_s``); returns [N*m].  Used by the locked split and by the bench model's hooks.
    """
    c1, a2, a3 = _locked_coefficients(fn1, g)
    return c1 * (1.0 + a2) / (1.0 - a3)  # [1], Eq. 21


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _cam_force(t1, t3, g):
    """Ball-cam axial force ``F_n2 = lambda/R (T1 + T3)`` on the secondary clutch and third element ([1], Eq. 14).

    ``t1``, ``t3``: torques of the primary clutch and the third element [N*m]; ``g``:
    :meth:`CouplingGeometry.kernel_data`; returns the force magnitude [N].
    """
    return g[11] / g[12] * abs(t1 + t3)  # [1], Eq. 14


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _locked(fn1, t_lock, g, margin, out):
    """Locked-mode split (Eqs. 18-21) by equal sharing with saturation.

    Returns the saturated-set code (bit 0: element 1, bit 1: element 2, bit
    2: element 3), or -1 if ``|t_lock| > margin * T_cap_L`` (the coupling slips).
    ``out[0:3]`` receives the torques, ``out[3:6]`` the three capacities for the split.
    """
    c1, a2, a3 = _locked_coefficients(fn1, g)
    sgn = 1.0 if t_lock >= 0.0 else -1.0
    t = abs(t_lock)
    total_cap = _locked_capacity(fn1, g)  # [1], Eq. 21 with every element saturated
    if t > total_cap * (1.0 + 1e-12):
        if t > margin * total_cap * (1.0 + 1e-12) or total_cap <= 0.0:
            return -1
        # inside the unlock margin every element carries its capacity scaled up to t (continuous at T_cap_L)
        s = t / total_cap
        out[0] = sgn * c1 * s
        out[2] = sgn * c1 * a3 / (1.0 - a3) * s
        out[1] = sgn * c1 * a2 / (1.0 - a3) * s
        out[3] = c1
        out[5] = c1 * a3 / (1.0 - a3)
        out[4] = c1 * a2 / (1.0 - a3)
        return 7
    t = min(t, total_cap)
    tol = 1e-11 * (t + total_cap) + 1e-300
    # try the saturated sets in order of size; the first consistent one is the split
    order = (0, 1, 4, 2, 5, 3, 6, 7)
    for code in order:
        s1 = code & 1
        s2 = (code >> 1) & 1
        s3 = (code >> 2) & 1
        # unknowns T1, T2, T3, share s; equations solved in closed form per set
        if code == 0:
            x1 = t / 3.0  # [1], Eq. 18
            x2 = x1
            x3 = x1
            sh = x1
        elif code == 4:  # element 3 saturated: [1], Eq. 19
            x3 = a3 * t / (2.0 - a3)
            x1 = (t - x3) / 2.0
            x2 = x1
            sh = x1
        elif code == 1:  # element 1 saturated (mirrored case of Eq. 19)
            x1 = c1
            x2 = (t - c1) / 2.0
            x3 = x2
            sh = x2
        elif code == 5:  # elements 1 and 3 saturated: [1], Eq. 20
            x1 = c1
            x3 = a3 * c1 / (1.0 - a3)
            x2 = t - x1 - x3
            sh = x2
        elif code == 2:  # element 2 saturated: T2 = a2 (T1 + T3), T1 = T3 = s
            sh = t / (2.0 + 2.0 * a2)
            x1 = sh
            x3 = sh
            x2 = 2.0 * a2 * sh
        elif code == 3:  # elements 1 and 2 saturated, element 3 shares the rest
            x1 = c1
            # T2 = a2 (c1 + T3), T3 = t - c1 - T2
            x3 = (t - c1 - a2 * c1) / (1.0 + a2)
            x2 = a2 * (c1 + x3)
            sh = x3
        elif code == 6:  # elements 2 and 3 saturated, element 1 shares the rest
            # T3 = a3 (T1 + T3), T2 = a2 (T1 + T3), T1 + T2 + T3 = t
            x1 = t * (1.0 - a3) / (1.0 + a2)
            x3 = a3 / (1.0 - a3) * x1
            x2 = a2 / (1.0 - a3) * x1
            sh = x1
        else:
            x1 = c1
            x3 = a3 * c1 / (1.0 - a3)
            x2 = a2 * c1 / (1.0 - a3)
            sh = 0.0
        k3 = a3 * (x1 + x3)
        k2 = a2 * (x1 + x3)
        cap = (c1, k2, k3)
        x = (x1, x2, x3)
        sat = (s1, s2, s3)
        ok = True
        for e in range(3):
            if x[e] < -tol:
                ok = False
            if sat[e] == 1:
                if code != 7 and cap[e] > sh + tol:
                    ok = False
            elif x[e] > cap[e] + tol:
                ok = False
        if code == 7 and abs(x1 + x2 + x3 - t) > tol:
            ok = False
        if ok:
            out[0] = sgn * x1
            out[1] = sgn * x2
            out[2] = sgn * x3
            out[3] = c1
            out[4] = k2
            out[5] = k3
            return code
    return -1


# ----------------------------------------------------------------- public API
def _fn1_check(fn1):
    f = np.asarray(fn1, dtype=float)
    if not np.all(np.isfinite(f)):
        raise ParameterError(f"fn1 = {fn1!r}: not finite")
    if np.any(f < 0):
        raise ParameterError(f"fn1 = {fn1!r}: the primary clutch force must be >= 0 [N]")
    return float(f) if f.ndim == 0 else f


def slipping_torques(fn1, slip_speed, geometry: CouplingGeometry):
    """Kinetic torques of the three elements in slipping mode ([1], Eqs. 13-15).

    Parameters
    ----------
    fn1 : float
        Compression force of the primary clutch [N] (>= 0).
    slip_speed : float
        ``delta_omega = omega_f - omega_r`` [rad/s]; only its sign is used.
    geometry : CouplingGeometry

    Returns
    -------
    (T1, T2, T3) : tuple of float
        Torques from the input to the output shaft [N*m], signed like ``slip_speed``.

    Notes
    -----
    Eq. 15 follows from Eq. 13 with ``F_n2 = lambda/R (T_k1 + T_k3)`` (Eq. 14):
    ``T_k2 = 2 lambda mu_k2 R2 z2 / (3R - 2 lambda mu_k3 R3) T_k1`` and
    ``T_k3 = 2 lambda mu_k3 R3 / (3R - 2 lambda mu_k3 R3) T_k1``.
    """
    fn1 = _fn1_check(fn1)
    if not np.isfinite(slip_speed):
        raise ParameterError(f"slip_speed = {slip_speed!r}: not finite")
    g = geometry.kernel_data()
    out = np.zeros(3)
    _slipping(float(fn1), float(slip_speed), g, g[0], g[1], g[2], out)
    return float(out[0]), float(out[1]), float(out[2])


def slipping_capacities(fn1, slip_speed, geometry: CouplingGeometry):
    """Slipping-mode capacities ``T_cap_Si = mu_si/mu_ki * T_ki`` and their sum ([1], Eqs. 16-17).

    Parameters
    ----------
    fn1 : float
        Normal force on the primary clutch F_n1 [N] (>= 0).
    slip_speed : float
        Slip speed of the coupling [rad/s]; only its sign is used (a zero slip counts as positive).
    geometry : CouplingGeometry
        Friction coefficients, radii, pairs and ball-cam data.

    Returns
    -------
    (caps, total) : (tuple of three float, float)
        Per-element capacities and ``T_cap_S`` [N*m] (magnitudes).
    """
    t = slipping_torques(fn1, slip_speed if slip_speed != 0 else 1.0, geometry)
    ratios = (geometry.mu_s1 / geometry.mu_k1, geometry.mu_s2 / geometry.mu_k2, geometry.mu_s3 / geometry.mu_k3)
    caps = tuple(abs(r * x) for r, x in zip(ratios, t))  # [1], Eq. 16
    return caps, float(sum(caps))  # [1], Eq. 17


def locked_capacities(fn1, geometry: CouplingGeometry):
    """Static capacities when every element is saturated ([1], Eqs. 18, 20, 21).

    Parameters
    ----------
    fn1 : float
        Normal force on the primary clutch F_n1 [N] (>= 0).
    geometry : CouplingGeometry
        Friction coefficients, radii, pairs and ball-cam data.

    Returns
    -------
    (caps, total) : (tuple of three float, float)
        ``T_cap_l1 = 2/3 mu_s1 R1 z1 F_n1``, ``T_cap_l3 = 2 lambda mu_s3 R3/(3R - 2 lambda mu_s3 R3) T_cap_l1``,
        ``T_cap_l2 = 2 lambda mu_s2 R2 z2/(3R - 2 lambda mu_s3 R3) T_cap_l1`` and ``T_cap_L`` [N*m].
    """
    fn1 = _fn1_check(fn1)
    c1, a2, a3 = _locked_coefficients(float(fn1), geometry.kernel_data())
    caps = (c1, c1 * a2 / (1.0 - a3), c1 * a3 / (1.0 - a3))
    return caps, float(sum(caps))


def locked_torques(fn1, t_lock, geometry: CouplingGeometry, *, margin: float = 1.0):
    """Static torques of the three elements in locked mode ([1], Eqs. 18-21).

    The three elements share ``t_lock`` equally until one reaches its static
    capacity; a saturated element carries its capacity and the others share
    the rest equally.  The capacities of elements 2 and 3 grow with the
    ball-cam force ``F_n2 = lambda/R (T_l1 + T_l3)``.  This reproduces case
    (a) Eq. 18, (b) Eq. 19, (c) Eq. 20 of Fig. 12 and the mirrored case in
    which the primary clutch saturates first.

    Parameters
    ----------
    fn1 : float
        Compression force of the primary clutch [N] (>= 0).
    t_lock : float
        Torque the locked coupling must transfer [N*m] (signed).
    geometry : CouplingGeometry
    margin : float
        Allowance above ``T_cap_L`` before the coupling slips (the mode logic
        uses 1.02, [1] Sec. 3.2); within it every element carries its capacity
        scaled up to ``t_lock``.

    Returns
    -------
    (T1, T2, T3) or None
        Torques [N*m] summing to ``t_lock`` (Eq. 21), or ``None`` if
        ``|t_lock| > margin * T_cap_L`` (the coupling slips).
    """
    fn1 = _fn1_check(fn1)
    if not np.isfinite(t_lock):
        raise ParameterError(f"t_lock = {t_lock!r}: not finite")
    if not margin >= 1.0:
        raise ParameterError(f"margin = {margin!r}: must be >= 1")
    out = np.zeros(6)
    code = _locked(float(fn1), float(t_lock), geometry.kernel_data(), float(margin), out)
    if code < 0:
        return None
    return float(out[0]), float(out[1]), float(out[2])


#: distribution cases of the locked coupling ([1], Fig. 12) by kernel code
LOCKED_CASE_NAMES = _CASE_NAMES = {
    0: "a: equal split (Eq. 18)",
    4: "b: third element saturated (Eq. 19)",
    1: "b': primary clutch saturated (mirrored Eq. 19)",
    5: "c: primary and third saturated (Eq. 20)",
    2: "secondary saturated",
    3: "primary and secondary saturated",
    6: "secondary and third saturated",
    7: "all saturated (at capacity)",
}


def locked_case(fn1, t_lock, geometry: CouplingGeometry) -> str | None:
    """Name of the distribution case of Fig. 12 for the lock torque ``t_lock`` [N*m] (None if the coupling slips).

    ``fn1`` is the primary-clutch normal force [N] and ``geometry`` the :class:`CouplingGeometry`.
    """
    out = np.zeros(6)
    code = _locked(float(_fn1_check(fn1)), float(t_lock), geometry.kernel_data(), 1.0, out)
    return None if code < 0 else _CASE_NAMES[int(code)]
