"""Dormand-Prince 5(4) pieces for compiled adaptive integrators.

The tableau is that of Dormand & Prince (1980) as used by SciPy's ``RK45``;
the error estimate is ``h * sum(E_i k_i)`` with the FSAL stage k7.  Subsystem
kernels compute the stages with their own right-hand side and call
:func:`error_norm`, :func:`next_step`, :func:`dense_hermite` (cubic Hermite
dense output) and :func:`dense_correction` (its fourth-order term for this pair [3]).

References
----------
.. [1] J. R. Dormand, P. J. Prince, "A family of embedded Runge-Kutta
   formulae", J. Comput. Appl. Math. 6 (1980) 19-26.
.. [2] E. Hairer, S. P. Nørsett, G. Wanner, Solving Ordinary Differential
   Equations I, 2nd ed., Springer 1993, Sec. II.4 (step size control), II.6 (dense output).
.. [3] L. F. Shampine, "Some practical Runge-Kutta formulas", Math. Comp. 46 (1986) 135-150
   (the continuous extension of order 4; coefficients as in Hairer's ``dopri5.f``).
"""

from __future__ import annotations

import math

import numba

C2, C3, C4, C5 = 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0
A21 = 1.0 / 5.0
A31, A32 = 3.0 / 40.0, 9.0 / 40.0
A41, A42, A43 = 44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0
A51, A52, A53, A54 = 19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0
A61, A62, A63, A64, A65 = 9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0
B1, B3, B4, B5, B6 = 35.0 / 384.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0
# error coefficients: b - b_hat (5th minus 4th order), SciPy RK45 "E"
E1, E3, E4, E5, E6, E7 = -71.0 / 57600.0, 71.0 / 16695.0, -71.0 / 1920.0, 17253.0 / 339200.0, -22.0 / 525.0, 1.0 / 40.0

# dense output of order 4 (Shampine 1986, as in Hairer's DOPRI5 ``CONTD5``): the cubic Hermite interpolant
# plus theta^2 (1 - theta)^2 times ``h * sum(D_i k_i)`` (:func:`dense_correction`)
D1, D3, D4 = -12715105075.0 / 11282082432.0, 87487479700.0 / 32700410799.0, -10690763975.0 / 1880347072.0
D5, D6, D7 = 701980252875.0 / 199316789632.0, -1453857185.0 / 822651844.0, 69997945.0 / 29380423.0

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0


@numba.njit(cache=True, nogil=True, forceinline=True)
def error_norm(err, y_old, y_new, rtol, atol):
    """RMS norm of the local error scaled by ``atol + rtol*max(|y_old|, |y_new|)`` (atol per state)."""
    s = 0.0
    n = err.shape[0]
    for i in range(n):
        sc = atol[i] + rtol * max(abs(y_old[i]), abs(y_new[i]))
        r = err[i] / sc
        s += r * r
    return math.sqrt(s / n)


@numba.njit(cache=True, nogil=True, forceinline=True)
def next_step(h, err_norm, accepted_previous_rejected):
    """New step size from the error norm (order-5 controller, Hairer & Wanner II.4)."""
    if err_norm == 0.0:
        factor = MAX_FACTOR
    else:
        factor = SAFETY * err_norm ** (-0.2)
    if err_norm < 1.0:
        factor = min(MAX_FACTOR, factor)
        if accepted_previous_rejected:
            factor = min(1.0, factor)
    else:
        factor = max(MIN_FACTOR, factor)
    return h * factor


@numba.njit(cache=True, nogil=True)
def dense_hermite(theta, h, y0, f0, y1, f1, out):
    """Cubic Hermite interpolant between two accepted points at ``t0 + theta*h``."""
    t2 = theta * theta
    t3 = t2 * theta
    h00 = 2.0 * t3 - 3.0 * t2 + 1.0
    h10 = t3 - 2.0 * t2 + theta
    h01 = -2.0 * t3 + 3.0 * t2
    h11 = t3 - t2
    for i in range(y0.shape[0]):
        out[i] = h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i]


@numba.njit(cache=True, nogil=True, forceinline=True)
def dense_correction(h, k1, k3, k4, k5, k6, k7, out):
    """The fourth-order term of the Dormand-Prince dense output of a step of length ``h`` [3].

    The interpolant is ``dense_hermite(...) + theta**2 * (1 - theta)**2 * out``: order 4 in the
    step, where the cubic Hermite interpolant alone is order 3 (measured on the wet engagement:
    samples between 1 ms steps 1e-7 rad/s off at rtol 1e-11 with Hermite alone).
    """
    for i in range(k1.shape[0]):
        out[i] = h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i])


@numba.njit(cache=True, nogil=True)
def initial_step(y0, f0, rtol, atol, t_span, order):
    """First guess of the starting step, ``h0 = 0.01 d0 / d1`` (the first half of Hairer & Wanner's rule [2],
    ``dopri5.f``'s ``hinit``; 1e-6 s when the state or its derivative is about zero), at most ``|t_span|``.

    ``d0`` and ``d1`` are the RMS norms of the state and of its derivative scaled by ``atol + rtol |y0|``.  The
    caller evaluates the right-hand side at ``y0 + h0 f0`` and completes the rule with :func:`starting_step`;
    the guess alone can lie below the resolution of the time (a state of 4e-12 against a derivative of 4 at
    rtol 1e-9 gives 1e-14 s: docs/driveline.md "Open", #30).  ``order`` is unused (kept for the callers).
    """
    d0 = 0.0
    d1 = 0.0
    n = y0.shape[0]
    for i in range(n):
        sc = atol[i] + rtol * abs(y0[i])
        d0 += (y0[i] / sc) ** 2
        d1 += (f0[i] / sc) ** 2
    d0 = math.sqrt(d0 / max(n, 1))
    d1 = math.sqrt(d1 / max(n, 1))
    if d0 < 1e-5 or d1 < 1e-5:
        h = 1e-6
    else:
        h = 0.01 * d0 / d1
    return min(h, abs(t_span))


@numba.njit(cache=True, nogil=True)
def starting_step(h0, y0, f0, f1, rtol, atol, t_span, order, h_min):
    """The starting step of Hairer & Wanner's rule [2] (``dopri5.f``'s ``hinit``, SciPy's
    ``select_initial_step``), from the first guess ``h0`` of :func:`initial_step` and the derivative ``f1``
    at ``y0 + h0 f0``.

    With ``d1`` the scaled norm of ``f0`` and ``d2 = |f1 - f0| / h0`` that of the second derivative,
    ``h1 = (0.01 / max(d1, d2)) ** (1 / (order + 1))`` (``order`` that of the error estimate: 4 for
    Dormand-Prince 5(4)), or ``max(1e-6, 1e-3 h0)`` when both vanish; the step is ``min(100 h0, h1)``, further
    capped at a tenth of ``t_span`` and at 10 ms (the core's own caps, kept from before).

    The growth limit ``100 h0`` is raised to ``h_min`` (0 gives the rule as published): the guess falls to
    1e-17 s and below when a state lies a little above the rule's "zero" (``d0`` >= 1e-5, far below its
    tolerance) while its derivative is large, under the core's resolution of the time; ``h1`` still bounds the
    step by the second derivative, and the error control rejects a step too long.
    """
    d1 = 0.0
    d2 = 0.0
    n = y0.shape[0]
    for i in range(n):
        sc = atol[i] + rtol * abs(y0[i])
        d1 += (f0[i] / sc) ** 2
        d2 += ((f1[i] - f0[i]) / sc) ** 2
    d1 = math.sqrt(d1 / max(n, 1))
    d2 = math.sqrt(d2 / max(n, 1)) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1.0))
    return min(max(100.0 * h0, h_min), h1, abs(t_span) / 10.0, 1e-2)
