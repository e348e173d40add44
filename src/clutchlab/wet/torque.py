"""Wet-clutch torque: asperity contact torque plus viscous shear torque.

Shin, Kim and Choi [1], Sec. 2.1, Eqs. 3-6.

References
----------
.. [1] S. Shin, D.-H. Kim, S. B. Choi, "Apparatus for identification of
   frictional and thermal characteristics of a wet clutch" (KAIST).
"""

from __future__ import annotations

import numpy as np

__all__ = ["asperity_torque", "viscous_torque", "clutch_torque"]


def _out(x):
    return float(x) if np.ndim(x) == 0 else x


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
    return _out(float(r_eff) * float(n_c) * np.asarray(mu_f, dtype=float) * np.asarray(contact_force, dtype=float))  # [1], Eq. 4


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
    return _out(float(r_eff) * float(n_c) * np.asarray(viscosity, dtype=float) * float(friction_area)
                * np.asarray(slip_velocity, dtype=float) / np.asarray(mean_film, dtype=float))  # [1], Eq. 5


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
    tc = asperity_torque(r_eff, n_c, mu_f, contact_force) * np.sign(v)
    tv = viscous_torque(r_eff, n_c, viscosity, friction_area, v, mean_film)
    return _out(tc + tv)  # [1], Eq. 3 / Eq. 6
