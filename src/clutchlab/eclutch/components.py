"""Component laws of the virtual clutch (the "truth" behind the synthetic data).

The measurements of Haramina et al. [1] are not public, so clutchlab ships a
virtual clutch whose components follow documented textbook laws.  These
functions are the ground truth of the virtual press rig (raw records of the
eight component tests of [1], Fig. 8 a-h) and of the virtual full-clutch rig
(bearing force and torque vs bearing position, [1] Fig. 12).  They are
*representative* of a passenger-car single-plate dry clutch, not measured.

All functions are pure and vectorised; deflections in m, forces in N.

References
----------
.. [1] K. Haramina et al., Trans. FAMENA 48 (2024) 21-35, doi:10.21278/TOF.483057923
.. [2] J. O. Almen, A. László, "The uniform-section disk spring", Trans. ASME
   58 (1936) 305-314.
.. [3] N. Cappetti, M. Pisaturo, A. Senatore, "Modelling the cushion spring
   characteristic to enhance the automated dry-clutch performance", Proc.
   IMechE D 226 (2012) 1472-1482.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "almen_laszlo",
    "progressive_exponential",
    "progressive_quadratic",
    "hertz_contact",
    "linear_spring",
]


def almen_laszlo(deflection, stiffness, cone_height, thickness):
    r"""Almen-László disk-spring force referred to the load point.

    .. math:: F(s) = k\,s\,\frac{(h - s)(h - s/2) + t^2}{h^2 + t^2}

    Parameters
    ----------
    deflection : array_like
        Deflection ``s`` from the free (unloaded) cone [m].
    stiffness : float
        Initial stiffness ``k = dF/ds`` at ``s = 0`` [N/m].
    cone_height : float
        Free cone height ``h`` referred to the load point [m].
    thickness : float
        Equivalent sheet thickness ``t`` referred to the load point [m].

    Returns
    -------
    force : ndarray
        Force [N].

    Notes
    -----
    This is the Almen-László law [2] with its geometry constant folded into
    ``k`` so that ``k`` is the initial stiffness.  For ``h/t > sqrt(2)`` the
    curve has a maximum and a minimum inside the travel (degressive diaphragm
    spring, [1] Fig. 9a); for ``h/t`` below it is monotone (yoke support
    spring, [1] Fig. 9h).
    """
    s = np.asarray(deflection, dtype=float)
    h, t = cone_height, thickness
    return stiffness * s * ((h - s) * (h - 0.5 * s) + t * t) / (h * h + t * t)


def progressive_exponential(deflection, force_scale, rate):
    r"""Progressive (stiffening) spring ``F = a (exp(b s) - 1)``, zero for ``s <= 0``.

    Used for the woven cushion spring of the friction plate ([1] Fig. 9d,
    [3]): soft at first contact, stiff when flattened.

    Parameters
    ----------
    deflection : array_like
        Compression ``s`` [m].
    force_scale : float
        ``a`` [N]; the initial stiffness is ``a*b`` [N/m].
    rate : float
        ``b`` [1/m].

    Returns
    -------
    force : ndarray
        Force [N] (0 where the spring is not in contact).
    """
    s = np.asarray(deflection, dtype=float)
    return np.where(s > 0.0, force_scale * np.expm1(rate * np.maximum(s, 0.0)), 0.0)


def progressive_quadratic(deflection, stiffness, length):
    r"""Mildly progressive spring ``F = k s (1 + s/L)`` for ``s > 0`` (zero otherwise).

    Used for the pressure plate with its wear-compensation mechanism
    ([1] Fig. 9f) and the yoke support spring ([1] Fig. 9h).

    Parameters
    ----------
    deflection : array_like
        Compression ``s`` [m].
    stiffness : float
        Initial stiffness ``k`` [N/m].
    length : float
        Stiffening length ``L`` [m] (stiffness doubles-plus at ``s = L/2``).

    Returns
    -------
    force : ndarray
        Force [N].
    """
    s = np.asarray(deflection, dtype=float)
    sp = np.maximum(s, 0.0)
    return stiffness * sp * (1.0 + sp / length)


def hertz_contact(deflection, coefficient):
    r"""Hertzian line/ring contact ``F = c s^{3/2}`` for ``s > 0``.

    Used for the solid yoke support ring ([1] Fig. 9g): non-linear at first
    contact, nearly linear (and very stiff) at the pre-strain it works at.

    Parameters
    ----------
    deflection : array_like
        Compression ``s`` [m].
    coefficient : float
        ``c`` [N/m^1.5].

    Returns
    -------
    force : ndarray
        Force [N].
    """
    s = np.maximum(np.asarray(deflection, dtype=float), 0.0)
    return coefficient * s ** 1.5


def linear_spring(deflection, stiffness, preload=0.0):
    """Linear spring ``F = preload + k s`` (return leaf springs, [1] Fig. 9e).

    Parameters
    ----------
    deflection : array_like
        Deflection [m].
    stiffness : float
        ``k`` [N/m].
    preload : float
        Force at zero deflection [N].

    Returns
    -------
    force : ndarray
        Force [N].
    """
    return preload + stiffness * np.asarray(deflection, dtype=float)
