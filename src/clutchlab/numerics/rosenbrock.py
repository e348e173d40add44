"""Rodas3: a stiffly accurate, L-stable Rosenbrock method for stiff ODEs and index-1 DAEs.

The E-clutch actuator couples a hydraulic line (sub-millisecond pressure
modes), a servomotor and a clutch whose stiffest component (the Model 4 yoke
support, ``k_ys.eq x 20``) vibrates at tens of kHz: an explicit method such as
Dormand-Prince would be held to micro-second steps by stability alone.  A
Rosenbrock (linearly implicit Runge-Kutta) method solves one linear system
per stage with the matrix ``M/(h gamma) - J`` and stays stable on the stiff
modes; because it is *stiffly accurate* it also integrates the algebraic
equations of massless nodes (mass-matrix rows equal to zero, index 1).

The method is Rodas3 of Sandu et al. [1] (4 stages, order 3, embedded order 2,
three new function evaluations per step) in the transformed form of Hairer &
Wanner [2], Sec. VI.4::

    (M/(h gamma) - J) K_i = f(t + alpha_i h, y + sum_j a_ij K_j)
                            + M sum_j (c_ij / h) K_j + h gamma_i df/dt
    y_new = y + sum_i m_i K_i,       error = K_4

Subsystem kernels call the cached helpers here (and the error norm of
:mod:`clutchlab.numerics.dopri`) (numba cannot cache a kernel
that receives another compiled function, so each subsystem writes its own
loop around its own right-hand side).

References
----------
.. [1] A. Sandu, J. G. Verwer, J. G. Blom, E. J. Spee, G. R. Carmichael,
   F. A. Potra, "Benchmarking stiff ODE solvers for atmospheric chemistry
   problems II: Rosenbrock solvers", Atmos. Environ. 31 (1997) 3459-3472.
.. [2] E. Hairer, G. Wanner, Solving Ordinary Differential Equations II, 2nd
   ed., Springer 1996, Sec. VI.4 (Rosenbrock methods, DAEs of index 1).
"""

from __future__ import annotations

import math

import numba

__all__ = ["GAMMA", "lu_factor", "lu_solve", "rodas_next_step"]

#: diagonal coefficient gamma of Rodas3
GAMMA = 0.5
# a_ij (stage arguments): a21 = 0, a31 = 2, a32 = 0, a41 = 2, a42 = 0, a43 = 1
A31, A41, A43 = 2.0, 2.0, 1.0
# c_ij (stage couplings)
C21, C31, C32, C41, C42, C43 = 4.0, 1.0, -1.0, 1.0, -1.0, -8.0 / 3.0
# gamma_i (time-derivative weights) and alpha_i (stage times)
GAMMA1, GAMMA2 = 0.5, 1.5
ALPHA3, ALPHA4 = 1.0, 1.0
# solution weights m = (2, 0, 1, 1): y_new = Y4 + K4 (stiffly accurate); error estimate e = (0, 0, 0, 1)
ORDER_EST = 3  # local order of the error estimate (min(3, 2) + 1)

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 6.0


@numba.njit(cache=True, nogil=True)
def lu_factor(a, piv):
    """In-place LU factorisation with partial pivoting of a small dense matrix.

    Returns False if the matrix is singular to working precision.
    """
    n = a.shape[0]
    for k in range(n):
        p = k
        amax = abs(a[k, k])
        for i in range(k + 1, n):
            v = abs(a[i, k])
            if v > amax:
                amax = v
                p = i
        piv[k] = p
        if amax == 0.0 or not math.isfinite(amax):
            return False
        if p != k:
            for j in range(n):
                tmp = a[k, j]
                a[k, j] = a[p, j]
                a[p, j] = tmp
        inv = 1.0 / a[k, k]
        for i in range(k + 1, n):
            a[i, k] *= inv
            lik = a[i, k]
            if lik != 0.0:
                for j in range(k + 1, n):
                    a[i, j] -= lik * a[k, j]
    return True


@numba.njit(cache=True, nogil=True)
def lu_solve(lu, piv, b):
    """Solve ``A x = b`` in place (``b`` becomes ``x``) from :func:`lu_factor` output."""
    n = lu.shape[0]
    for k in range(n):
        p = piv[k]
        if p != k:
            tmp = b[k]
            b[k] = b[p]
            b[p] = tmp
    for i in range(n):
        s = b[i]
        for j in range(i):
            s -= lu[i, j] * b[j]
        b[i] = s
    for i in range(n - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, n):
            s -= lu[i, j] * b[j]
        b[i] = s / lu[i, i]


@numba.njit(cache=True, nogil=True)
def rodas_next_step(h, err_norm, rejected_before):
    """New step size from the error norm (order-3 estimate; Hairer & Wanner II.4)."""
    if err_norm == 0.0 or not math.isfinite(err_norm):
        factor = MAX_FACTOR if err_norm == 0.0 else MIN_FACTOR
    else:
        factor = SAFETY * err_norm ** (-1.0 / ORDER_EST)
    factor = min(MAX_FACTOR, max(MIN_FACTOR, factor))
    if rejected_before and factor > 1.0:
        factor = 1.0
    return h * factor
