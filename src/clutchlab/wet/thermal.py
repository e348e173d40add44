"""Lumped thermal model of the clutch pack.

Shin, Kim and Choi [1], Sec. 2.3, Eq. 8: the whole pack (steel cores and
linings) is one lumped mass of uniform temperature heated by the friction
power and cooled by convection to the oil (k1) and conduction to the
housing (k2).

References
----------
.. [1] S. Shin, D.-H. Kim, S. B. Choi, "Apparatus for identification of
   frictional and thermal characteristics of a wet clutch" (KAIST).
.. [2] Y. Yang, R. C. Lam, Y. F. Chen, H. Yabe, "Modeling of heat transfer and
   fluid hydrodynamics for a multidisc wet clutch", SAE Trans. (1995) 1674-1688.
"""

from __future__ import annotations

import numba
import numpy as np

from ..errors import ParameterError

__all__ = [
    "pack_heat_capacity", "pack_heat_capacity_scalar",
    "heat_balance",
    "thermal_time_constant",
    "steady_state_temperature",
    "temperature_step_response",
]


def _out(x):
    return float(x) if np.ndim(x) == 0 else x


@numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def pack_heat_capacity_scalar(n_c, m_lining, cp_lining, m_core, cp_core):
    """Heat capacity ``{(m c_p)_lining + (m c_p)_core} N_c`` of the pack [J/K] ([1], Eq. 8, left side), compiled:
    the equation itself (:func:`pack_heat_capacity` checks its result; the wet model's compiled ``start`` derives
    its pack's heat capacity with it, so a native FMU's host may set the masses and heat capacities).

    Parameters: ``n_c`` clutches [-], ``m_lining``, ``m_core`` the masses of one lining and one core disk [kg],
    ``cp_lining``, ``cp_core`` their specific heat capacities [J/(kg*K)].  Assumes a lumped pack (one temperature).
    """
    return (m_lining * cp_lining + m_core * cp_core) * n_c  # [1], Eq. 8


def pack_heat_capacity(n_c, m_lining, cp_lining, m_core, cp_core):
    """Heat capacity ``{(m c_p)_lining + (m c_p)_core} N_c`` of the pack [J/K] ([1], Eq. 8, left side).

    Parameters
    ----------
    n_c : int
        Number of clutches [-].
    m_lining, m_core : float
        Mass of one lining and one core disk [kg].
    cp_lining, cp_core : float
        Their specific heat capacities [J/(kg*K)].
    """
    c = pack_heat_capacity_scalar(float(n_c), float(m_lining), float(cp_lining), float(m_core), float(cp_core))
    if not c > 0:
        raise ParameterError(f"pack heat capacity = {c!r}: masses and heat capacities must be > 0")
    return c


def heat_balance(temperature_c, friction_power, fluid_temperature_c, housing_temperature_c, heat_capacity, k1, k2):
    """Rate of change of the pack temperature from the heat balance.

    Shin et al. [1], Eq. 8:
    ``C dT/dt = tau dw - k1 (T - T_fluid) - k2 (T - T_housing)``.

    Parameters
    ----------
    temperature_c : array_like
        Mean friction-surface (pack) temperature T [degC].
    friction_power : array_like
        Friction power ``tau * dw`` [W] (>= 0 while slipping).
    fluid_temperature_c, housing_temperature_c : array_like
        Oil reservoir and housing temperatures [degC].
    heat_capacity : float
        Pack heat capacity C [J/K] (:func:`pack_heat_capacity`).
    k1, k2 : float
        Generalised conductances to the oil and to the housing [W/K].

    Returns
    -------
    numpy.ndarray or float
        dT/dt [K/s].

    Notes
    -----
    Uniform pack temperature (thin steel cores, single-sided linings, after
    Yang et al. [2]); all friction heat enters the pack.
    """
    return _out(heat_balance_scalar.py_func(
        np.asarray(temperature_c, dtype=float), np.asarray(friction_power, dtype=float),
        np.asarray(fluid_temperature_c, dtype=float), np.asarray(housing_temperature_c, dtype=float),
        float(heat_capacity), k1, k2))  # [1], Eq. 8


@numba.njit(cache=True, nogil=True, inline="always")
def heat_balance_scalar(temperature_c, friction_power, fluid_temperature_c, housing_temperature_c, heat_capacity,
                        k1, k2):
    """Pack temperature rate ``dT/dt`` [K/s] of Eq. 8 (Shin et al. [1]), compiled scalar form.

    ``C dT/dt = tau dw - k1 (T - T_fluid) - k2 (T - T_housing)``; the
    engagement model calls it, :func:`heat_balance` evaluates the same
    function body on arrays.

    Parameters
    ----------
    temperature_c : float
        Pack temperature T [degC].
    friction_power : float
        Friction power ``tau * dw`` [W].
    fluid_temperature_c, housing_temperature_c : float
        Oil and housing temperatures [degC].
    heat_capacity : float
        Pack heat capacity C [J/K].
    k1, k2 : float
        Conductances to the oil and to the housing [W/K].
    """
    q = friction_power - k1 * (temperature_c - fluid_temperature_c) - k2 * (temperature_c - housing_temperature_c)
    return q / heat_capacity  # [1], Eq. 8


def thermal_time_constant(heat_capacity, k1, k2):
    """Time constant ``C / (k1 + k2)`` of Eq. 8 with fixed surroundings [s].

    With Table 1: 348.2 J/K / 162.14 W/K = 2.148 s.

    Parameters
    ----------
    heat_capacity : float
        Pack heat capacity C [J/K].
    k1, k2 : float
        Conductances to the oil and to the housing [W/K].
    """
    if not (k1 + k2) > 0:
        raise ParameterError(f"k1 + k2 = {k1 + k2!r}: must be > 0 for a finite time constant")
    return float(heat_capacity) / (float(k1) + float(k2))


def steady_state_temperature(friction_power, fluid_temperature_c, housing_temperature_c, k1, k2):
    """Steady state of Eq. 8: ``T = (P + k1 T_fluid + k2 T_housing) / (k1 + k2)`` [degC].

    Parameters
    ----------
    friction_power : array_like
        Constant friction power [W].
    fluid_temperature_c, housing_temperature_c : array_like
        Oil and housing temperatures [degC].
    k1, k2 : float
        Conductances [W/K].
    """
    if not (k1 + k2) > 0:
        raise ParameterError(f"k1 + k2 = {k1 + k2!r}: must be > 0")
    return _out((np.asarray(friction_power, dtype=float) + k1 * np.asarray(fluid_temperature_c, dtype=float)
                 + k2 * np.asarray(housing_temperature_c, dtype=float)) / (k1 + k2))


def temperature_step_response(time, initial_temperature_c, friction_power, fluid_temperature_c,
                              housing_temperature_c, heat_capacity, k1, k2):
    """Closed-form solution of Eq. 8 for constant power and surroundings [degC].

    ``T(t) = T_inf + (T_0 - T_inf) exp(-t / tau)`` with the steady state
    ``T_inf`` of :func:`steady_state_temperature` and ``tau = C/(k1 + k2)``.

    Parameters
    ----------
    time : array_like
        Time since the step [s].
    initial_temperature_c : float
        Pack temperature at t = 0 [degC].
    friction_power : float
        Constant friction power [W].
    fluid_temperature_c, housing_temperature_c : float
        Constant oil and housing temperatures [degC].
    heat_capacity : float
        Pack heat capacity C [J/K].
    k1, k2 : float
        Conductances [W/K].
    """
    tau = thermal_time_constant(heat_capacity, k1, k2)
    t_inf = steady_state_temperature(friction_power, fluid_temperature_c, housing_temperature_c, k1, k2)
    return _out(t_inf + (initial_temperature_c - t_inf) * np.exp(-np.asarray(time, dtype=float) / tau))
