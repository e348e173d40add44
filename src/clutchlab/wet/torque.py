"""Wet-clutch torque: asperity contact torque plus viscous shear torque.

Shin, Kim and Choi [1], Sec. 2.1, Eqs. 3-6.  Each equation is one scalar
compiled function (``*_scalar``) that the engagement model calls; the
vectorised public functions evaluate the same function bodies on NumPy
arrays (``.py_func``), so every equation is written once.

References
----------
.. [1] S. Shin, D.-H. Kim, S. B. Choi, "Apparatus for identification of
   frictional and thermal characteristics of a wet clutch" (KAIST).
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["asperity_torque", "viscous_torque", "clutch_torque"]


def _out(x):
    return float(x) if np.ndim(x) == 0 else x


@numba.njit(cache=True, nogil=True, inline="always")
def asperity_torque_scalar(r_eff, n_c, mu_f, contact_force):
    """Asperity contact torque magnitude ``tau_c = R_eff N_c mu_f F_c`` [N*m] ([1], Eq. 4), compiled scalar form.

    Parameters
    ----------
    r_eff : float
        Torque effective radius [m].
    n_c : float
        Number of clutches [-].
    mu_f : float
        Asperity friction coefficient [-].
    contact_force : float
        Asperity force F_c [N].

    Notes
    -----
    At zero slip this is the static torque capacity of the pack.
    """
    return r_eff * n_c * mu_f * contact_force  # [1], Eq. 4


@numba.njit(cache=True, nogil=True, inline="always")
def viscous_torque_scalar(r_eff, n_c, viscosity, friction_area, slip_velocity, mean_film):
    """Viscous shear torque ``tau_v = R_eff N_c mu_v A_f v / h_bar`` [N*m] ([1], Eq. 5), compiled scalar form.

    Parameters
    ----------
    r_eff : float
        Torque effective radius [m].
    n_c : float
        Number of clutches [-].
    viscosity : float
        Dynamic viscosity mu_v [Pa*s] (Eq. 7).
    friction_area : float
        Friction area of one face A_f [m^2].
    slip_velocity : float
        Mean slip velocity v [m/s] (Eq. (2')).
    mean_film : float
        Mean film thickness h_bar [m] (Eq. 2).

    Notes
    -----
    Couette flow in the mean film, shear stress evaluated at R_eff.
    """
    return r_eff * n_c * viscosity * friction_area * slip_velocity / mean_film  # [1], Eq. 5


@numba.njit(cache=True, nogil=True, inline="always")
def clutch_torque_scalar(r_eff, n_c, mu_f, contact_force, viscosity, friction_area, slip_velocity, mean_film,
                         direction):
    """Total clutch torque ``tau = tau_c + tau_v`` [N*m] ([1], Eqs. 3 and 6), compiled scalar form.

    Parameters
    ----------
    r_eff, n_c, mu_f, contact_force : float
        As :func:`asperity_torque_scalar`.
    viscosity, friction_area, slip_velocity, mean_film : float
        As :func:`viscous_torque_scalar`.
    direction : float
        Sliding direction (+1, -1; 0 without slip): the contact torque opposes
        the slip.  The engagement model passes the direction of its slip
        mode, so the torque stays smooth within a step; :func:`clutch_torque`
        passes ``sign(v)``.
    """
    tc = direction * asperity_torque_scalar(r_eff, n_c, mu_f, contact_force)  # [1], Eq. 4
    return tc + viscous_torque_scalar(r_eff, n_c, viscosity, friction_area, slip_velocity, mean_film)  # Eqs. 3, 6


def asperity_torque(r_eff, n_c, mu_f, contact_force):
    """Asperity contact torque ``tau_c = R_eff N_c mu_f F_c`` ([1], Eq. 4).

    Parameters
    ----------
    r_eff : float
        Torque effective radius [m].
    n_c : int
        Number of clutches N_c [-] (friction interfaces carrying F_c in series).
    mu_f : array_like
        Asperity friction coefficient [-].
    contact_force : array_like
        Force carried by the asperities F_c [N].

    Returns
    -------
    numpy.ndarray or float
        tau_c [N*m], magnitude (acts against the slip).
    """
    return _out(asperity_torque_scalar.py_func(float(r_eff), float(n_c), np.asarray(mu_f, dtype=float),
                                               np.asarray(contact_force, dtype=float)))  # [1], Eq. 4


def viscous_torque(r_eff, n_c, viscosity, friction_area, slip_velocity, mean_film):
    """Viscous shear torque ``tau_v = R_eff N_c mu_v A_f v / h_bar`` ([1], Eq. 5).

    Parameters
    ----------
    r_eff : float
        Torque effective radius [m].
    n_c : int
        Number of clutches [-].
    viscosity : array_like
        Dynamic viscosity mu_v [Pa*s] (Eq. 7).
    friction_area : float
        Nominal friction area of one face A_f [m^2].
    slip_velocity : array_like
        Mean slip velocity v = R_eff dw [m/s] (Eq. (2')).
    mean_film : array_like
        Mean film thickness h_bar [m] (Eq. 2).

    Returns
    -------
    numpy.ndarray or float
        tau_v [N*m], with the sign of v.

    Notes
    -----
    Couette flow in the mean film; the shear stress is evaluated at R_eff.
    """
    return _out(viscous_torque_scalar.py_func(float(r_eff), float(n_c), np.asarray(viscosity, dtype=float),
                                              float(friction_area), np.asarray(slip_velocity, dtype=float),
                                              np.asarray(mean_film, dtype=float)))  # [1], Eq. 5


def clutch_torque(r_eff, n_c, mu_f, contact_force, viscosity, friction_area, slip_velocity, mean_film):
    """Total clutch torque ``tau = R_eff N_c (mu_f F_c sgn v + mu_v A_f v / h_bar)`` ([1], Eqs. 3 and 6).

    Parameters
    ----------
    r_eff : float
        Torque effective radius [m].
    n_c : int
        Number of clutches [-].
    mu_f : array_like
        Asperity friction coefficient [-].
    contact_force : array_like
        Asperity force F_c [N].
    viscosity : array_like
        Dynamic viscosity mu_v [Pa*s].
    friction_area : float
        Friction area of one face A_f [m^2].
    slip_velocity : array_like
        Mean slip velocity v [m/s].
    mean_film : array_like
        Mean film thickness h_bar [m].

    Returns
    -------
    numpy.ndarray or float
        tau [N*m], with the sign of the slip velocity (Eq. 6 written for v > 0;
        the contact part opposes the slip for either sign).
    """
    v = np.asarray(slip_velocity, dtype=float)
    return _out(clutch_torque_scalar.py_func(float(r_eff), float(n_c), np.asarray(mu_f, dtype=float),
                                             np.asarray(contact_force, dtype=float),
                                             np.asarray(viscosity, dtype=float), float(friction_area), v,
                                             np.asarray(mean_film, dtype=float), np.sign(v)))  # [1], Eqs. 3, 6
