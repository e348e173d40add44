"""Virtual manual press rig: synthetic stress-strain records of clutch components.

Haramina et al. [1] (Section 4, Figs. 7-9) characterize every elastic part
of a disassembled clutch on a manually powered spindle press: an S-type force
sensor sits between the spindle and the part, an LVDT parallel to it measures
the displacement, and a second LVDT measures another point of the same part
(or verifies the first).  The operator turns the spindle up and down three
times; the raw curves show a narrow friction hysteresis, which is removed by
averaging (Section 4, text before Fig. 8).

This module produces such records from a known force-deflection law, so that
the characterization procedure (:mod:`clutchlab.eclutch.characterize`) can be
tested against the truth and the paper's remarks on rig compliance
(Sections 5.3-5.4) can be reproduced:

* :func:`simulate_press_test` -- one component, force + LVDT 1 (+ optional
  channels), friction hysteresis, frame compliance, sensor noise;
* :func:`simulate_lever_tests` -- the two multi-LVDT tests of the diaphragm
  spring leaning on the yoke support, Fig. 8b and Fig. 8c, from which Eq. (1)
  computes the finger (lever) stiffness.

All records are synthetic; their ``DataFrame.attrs["provenance"]`` says so.

References
----------
.. [1] K. Haramina, N. Kranjčević, M. Hoić, J. Deur, A. Tissot, "Modelling of
   E-clutch axial dynamics based on experimentally identified clutch component
   stress-strain characteristics", Trans. FAMENA 48 (2024) 21-35,
   doi:10.21278/TOF.483057923
.. [2] M. A. Krasnosel'skii, A. V. Pokrovskii, Systems with Hysteresis,
   Springer 1989 (stop and play operators).
"""

from __future__ import annotations

from typing import Callable, Mapping

import numba
import numpy as np
import pandas as pd

from .._limits import check_number, short_repr
from ..errors import ParameterError, SimulationError

__all__ = ["simulate_press_test", "simulate_lever_tests", "spindle_stroke", "stop_operator"]

#: Fraction of each stroke spent accelerating / decelerating the spindle.
RAMP_FRACTION = 0.15
#: Default sticking stiffness as a multiple of the component's largest tangent stiffness.
STICK_STIFFNESS_FACTOR = 10.0

_CORE_COLUMNS = ("time_s", "force_N", "displacement_m")


# --------------------------------------------------------------------------- helpers
_check_number = check_number  # (the shared check of clutchlab._limits)


def _check_int(name: str, value, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ParameterError(f"{name} = {value!r} must be an integer")
    if value < minimum:
        raise ParameterError(f"{name} = {value!r} must be >= {minimum}")
    return int(value)


def _call_law(law: Callable, x: np.ndarray, what: str) -> np.ndarray:
    if not callable(law):
        raise ParameterError(f"{what} = {law!r} is not callable")
    try:
        out = np.asarray(law(x), dtype=float)
    except Exception as exc:  # a user callable can fail in any way
        raise SimulationError(f"{what} failed on an array of {x.size} values: {exc}") from exc
    if out.shape != x.shape:
        if out.size == x.size:
            out = out.reshape(x.shape)
        elif out.size == 1:
            out = np.full(x.shape, float(out.ravel()[0]))
        else:
            raise SimulationError(f"{what} returned shape {out.shape} for input shape {x.shape}")
    bad = ~np.isfinite(out)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise SimulationError(f"{what} returned {short_repr(out[k])} at input {short_repr(x[k])}")
    return out


def spindle_stroke(u):
    """Normalised position of one smooth spindle stroke.

    Parameters
    ----------
    u : array_like
        Normalised time within the stroke, 0..1 [-].

    Returns
    -------
    numpy.ndarray
        Position 0..1 [-]: constant speed in the middle, ``sin**2`` velocity
        ramps over the first and last :data:`RAMP_FRACTION` of the stroke, so
        the turning points are smooth (zero velocity, finite acceleration), as
        with an operator turning a hand wheel.
    """
    u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
    r = RAMP_FRACTION
    head = u / 2.0 - r / (2.0 * np.pi) * np.sin(np.pi * u / r)
    w = 1.0 - u
    tail = (1.0 - r) - (w / 2.0 - r / (2.0 * np.pi) * np.sin(np.pi * w / r))
    mid = r / 2.0 + (u - r)
    p = np.where(u < r, head, np.where(u > 1.0 - r, tail, mid))
    return p / (1.0 - r)


@numba.njit(cache=True, nogil=True)
def _stop_kernel(x, zmax, stiffness, z0):
    n = x.shape[0]
    z = np.empty(n)
    zi = z0
    for i in range(n):
        if i > 0:
            zi += stiffness * (x[i] - x[i - 1])
        lim = zmax[i]
        if zi > lim:
            zi = lim
        elif zi < -lim:
            zi = -lim
        z[i] = zi
    return z


def stop_operator(x, limit, stiffness: float, z0: float = 0.0) -> np.ndarray:
    """Quasi-static Coulomb friction with compliant sticking (stop operator [2]).

    ``z_i = clip(z_{i-1} + stiffness * (x_i - x_{i-1}), -limit_i, +limit_i)``:
    while the contact sticks, the friction force grows with the tangential
    stiffness; once it reaches the Coulomb limit it slides at ``+-limit``.

    Parameters
    ----------
    x : array_like
        Deflection history [m].
    limit : array_like or float
        Coulomb friction limit at each sample [N] (>= 0).
    stiffness : float
        Sticking (pre-sliding) stiffness [N/m].
    z0 : float
        Initial friction force [N].

    Returns
    -------
    numpy.ndarray
        Friction force [N]; positive while the deflection increases.
    """
    x = np.ascontiguousarray(x, dtype=float)
    lim = np.ascontiguousarray(np.broadcast_to(np.asarray(limit, dtype=float), x.shape))
    return _stop_kernel(x, lim, float(stiffness), float(z0))


# ----------------------------------------------------------------------- press test
def simulate_press_test(
    law: Callable,
    travel_m: float,
    *,
    cycles: int = 3,
    samples_per_stroke: int = 400,
    rate_m_s: float = 2e-3,
    start_m: float = 0.0,
    rig_compliance_m_per_N: float = 0.0,
    friction_N: float = 20.0,
    friction_rel: float = 0.02,
    stick_stiffness_N_per_m: float | None = None,
    force_noise_N: float = 3.0,
    lvdt_noise_m: float = 3e-6,
    seed: int = 0,
    extra: Mapping[str, Callable] | None = None,
) -> pd.DataFrame:
    """Record of a component loaded and unloaded on the manual press rig.

    Virtual version of the spindle press of [1], Section 4 (Fig. 7): the
    spindle drives the true component deflection ``x`` smoothly from
    ``start_m`` to ``start_m + travel_m`` and back, ``cycles`` times; the
    force sensor records the elastic force plus the friction between the
    components; LVDT 1, parallel to the force sensor, records the deflection
    plus the deformation of the compliant press frame and fixtures.

    Parameters
    ----------
    law : callable
        ``law(x) -> force``: elastic force [N] of the component at true
        deflection ``x`` [m] (numpy array in, array out).  May be non-monotone
        (the Almen-László diaphragm spring has a force maximum in the travel).
    travel_m : float
        Stroke of the spindle [m] (> 0).
    cycles : int
        Number of load-unload cycles (the paper records three) [-].
    samples_per_stroke : int
        Samples per loading or unloading stroke [-] (>= 10).
    rate_m_s : float
        Spindle speed in the constant-speed part of a stroke [m/s].
    start_m : float
        Deflection at the start and at each lower turning point [m] (a
        pre-load position).
    rig_compliance_m_per_N : float
        Compliance of the press frame and fixtures seen by LVDT 1 [m/N].
        [1], Sections 5.3-5.4 blame it for the unrealistically low stiffness
        measured on stiff parts.
    friction_N, friction_rel : float
        Coulomb friction limit ``friction_N + friction_rel * |law(x)|`` [N],
        [-] between the components.
    stick_stiffness_N_per_m : float, optional
        Tangential stiffness of the sticking contact [N/m]; the sticking
        segments after each turning point are ``2*limit/stick_stiffness`` long.
        Default: :data:`STICK_STIFFNESS_FACTOR` times the largest tangent
        stiffness of ``law`` over the stroke (at least 1e5 N/m), so the
        sticking segments stay steep for soft and stiff parts alike.
    force_noise_N : float
        Standard deviation of the white force-sensor noise [N].
    lvdt_noise_m : float
        Standard deviation of the white noise of every LVDT channel [m].
    seed : int
        Seed of the :func:`numpy.random.default_rng` generator.
    extra : mapping of str to callable, optional
        Further displacement channels: ``{"displacement2_m": f}`` with
        ``f(x, force) -> displacement`` [m], called with the true deflection
        [m] and the noise-free recorded force (elastic + friction) [N]; LVDT
        noise is added to each.

    Returns
    -------
    pandas.DataFrame
        Columns ``time_s`` [s], ``force_N`` [N], ``displacement_m`` [m] and the
        ``extra`` channels; ``attrs["provenance"]`` describes the synthetic
        origin and the settings.

    Notes
    -----
    Friction (a modelling choice; [1] only reports "a relatively narrow
    hysteresis because of friction between individual components", Section 4)
    is the stop operator :func:`stop_operator` with limit
    ``friction_N + friction_rel*|law(x)|``: the loading branch is
    ``law + limit``, the unloading branch ``law - limit``, joined by steep
    sticking segments at the turning points.  The component is assumed to stay
    in contact with the spindle (no lift-off when the unloading force would
    become negative).

    LVDT 1 records ``x + rig_compliance_m_per_N * force``: the frame
    compliance lies inside the LVDT's measuring loop, so a linear spring of
    stiffness ``k`` appears to have ``1/(1/k + c)``.

    Each stroke lasts ``travel_m / (rate_m_s * (1 - RAMP_FRACTION))`` with
    ``sin**2`` velocity ramps (:func:`spindle_stroke`).
    """
    travel = _check_number("travel_m", travel_m, positive=True)
    cycles = _check_int("cycles", cycles, 1)
    sps = _check_int("samples_per_stroke", samples_per_stroke, 10)
    rate = _check_number("rate_m_s", rate_m_s, positive=True)
    start = _check_number("start_m", start_m)
    comp = _check_number("rig_compliance_m_per_N", rig_compliance_m_per_N, nonnegative=True)
    fric0 = _check_number("friction_N", friction_N, nonnegative=True)
    fric_rel = _check_number("friction_rel", friction_rel, nonnegative=True)
    kst = (None if stick_stiffness_N_per_m is None
           else _check_number("stick_stiffness_N_per_m", stick_stiffness_N_per_m, positive=True))
    f_noise = _check_number("force_noise_N", force_noise_N, nonnegative=True)
    x_noise = _check_number("lvdt_noise_m", lvdt_noise_m, nonnegative=True)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise ParameterError(f"seed = {seed!r} must be an integer")
    extra = {} if extra is None else dict(extra)
    for key, func in extra.items():
        if not isinstance(key, str) or key in _CORE_COLUMNS:
            raise ParameterError(f"extra channel name {key!r} must be a string other than {_CORE_COLUMNS}")
        if not callable(func):
            raise ParameterError(f"extra channel {key!r}: {func!r} is not callable")

    # spindle motion: 2*cycles strokes, smooth turning points
    n = 2 * cycles * sps + 1
    k = np.arange(n)
    stroke = k // sps
    p = spindle_stroke((k % sps) / sps)
    p = np.where(stroke % 2 == 0, p, 1.0 - p)
    p[-1] = 0.0
    x = start + travel * p
    stroke_time = travel / (rate * (1.0 - RAMP_FRACTION))
    t = k * (stroke_time / sps)

    f_el = _call_law(law, x, "law")
    if kst is None:
        dx = np.diff(x)
        moving = dx != 0
        k_max = float(np.max(np.abs(np.diff(f_el)[moving] / dx[moving])))
        kst = max(STICK_STIFFNESS_FACTOR * k_max, 1e5)
    limit = fric0 + fric_rel * np.abs(f_el)
    z = stop_operator(x, limit, kst)
    force = f_el + z  # recorded force: elastic + friction (stop operator)

    rng = np.random.default_rng(int(seed))
    data = {
        "time_s": t,
        "force_N": force + f_noise * rng.standard_normal(n),
        "displacement_m": x + comp * force + x_noise * rng.standard_normal(n),
    }
    for key, func in extra.items():
        d = _call_law(lambda xx, f=func: f(xx, force), x, f"extra channel {key!r}")
        data[key] = d + x_noise * rng.standard_normal(n)
    frame = pd.DataFrame(data)
    frame.attrs["provenance"] = (
        "synthetic: clutchlab virtual manual press rig (clutchlab.eclutch.pressrig.simulate_press_test), "
        f"travel {travel:g} m from {start:g} m, {cycles} cycles, rate {rate:g} m/s, "
        f"friction {fric0:g} N + {fric_rel:g}*|F|, stick stiffness {kst:g} N/m, "
        f"rig compliance {comp:g} m/N, noise {f_noise:g} N / {x_noise:g} m, seed {int(seed)}"
    )
    return frame


# ----------------------------------------------------------------------- lever tests
def _tip_force_law(lever_ratio, finger_law, rotation_law, support_law, lo, hi):
    """Force at the finger tips as a function of the tip position (numerical inverse)."""

    def tip(force):
        return (_call_law(support_law, force, "support_law")
                + lever_ratio * _call_law(rotation_law, force, "rotation_law")
                + _call_law(finger_law, force, "finger_law"))

    zero = np.zeros(1)
    s0 = float(tip(zero)[0])
    if s0 > lo + 1e-9 * (hi - lo):  # tolerance: the laws' inverses at zero force carry round-off
        raise ParameterError(
            f"start_m = {lo!r} m is below the unloaded tip position {s0!r} m of the lever test")
    f_hi = 1.0
    for _ in range(80):
        s_hi = float(tip(np.array([f_hi]))[0])
        if s_hi >= hi:
            break
        if s_hi < s0:
            raise SimulationError(
                f"lever test: tip displacement is not increasing with force (at F = {f_hi:.6g} N the tip is at "
                f"{s_hi!r} m, below {s0!r} m at F = 0; check the signs: rotation_law must oppose the tips, "
                "lever_ratio < 0)")
        f_hi *= 2.0
    else:
        raise SimulationError("lever test: the tip never reaches start_m + travel_m (laws too soft?)")
    forces = np.linspace(0.0, f_hi, 4001)
    s = tip(forces)
    ds = np.diff(s)
    if (ds <= 0).any():
        j = int(np.flatnonzero(ds <= 0)[0])
        raise SimulationError(
            f"lever test: tip displacement is not increasing with force near F = {forces[j]:.6g} N "
            "(check the signs: rotation_law must oppose the tips, lever_ratio < 0)")

    def law(x):
        return np.interp(x, s, forces)

    return law


def simulate_lever_tests(*, lever_ratio: float, finger_law: Callable, rotation_law: Callable,
                         support_law: Callable, travel_m: float, **press_kwargs):
    """The two multi-LVDT diaphragm-spring tests of [1], Fig. 8b and Fig. 8c.

    The diaphragm spring leans on the yoke support and is pushed at the finger
    tips (where the release bearing acts) by the press spindle.  LVDT 1
    measures the tips in both tests; LVDT 2 measures the support point (test
    b) or the outer, pressure-plate edge (test c) ([1], Section 4.1).

    Parameters
    ----------
    lever_ratio : float
        Diaphragm spring lever ratio ``i_ds`` (< 0, [1] Section 3.2) [-].
    finger_law : callable
        ``finger_law(F)`` -> finger bending deflection [m] at tip force ``F``
        [N], i.e. ``F / k_fl(F)``.
    rotation_law : callable
        ``rotation_law(F)`` -> displacement ``e`` [m] of the outer edge
        relative to the support; opposite in sign to the tips (negative for a
        positive force, since ``i_ds < 0``).
    support_law : callable
        ``support_law(F)`` -> deflection of the support point [m] (support
        ring / yoke support compliance).
    travel_m : float
        Tip stroke of the spindle [m].
    **press_kwargs
        Passed to :func:`simulate_press_test` (``cycles``, ``rate_m_s``,
        ``start_m``, ``rig_compliance_m_per_N``, friction, noise, ``seed``);
        record c uses ``seed + 1``.  ``extra`` is not accepted.

    Returns
    -------
    (record_b, record_c) : (pandas.DataFrame, pandas.DataFrame)
        Both with ``time_s``, ``force_N``, ``displacement_m`` (LVDT 1, tips,
        ``s(b1)`` / ``s(c1)``) and ``displacement2_m`` (LVDT 2: support
        ``s(b2)`` in record b, pressure-plate edge ``s(c2)`` in record c) [s,
        N, m].

    Notes
    -----
    Kinematics of the virtual test (our model; [1] gives only the
    measurement, Section 4.1, and its use in Eq. (1), Section 5.1): at tip
    force ``F``

    * support point: ``s_sup = support_law(F)``
    * outer edge: ``s_pp = s_sup + e``, ``e = rotation_law(F)``
    * tips: ``s_tip = s_sup + i_ds*e + finger_law(F)``

    so that Eq. (1), ``(s_tip - s_sup) - i_ds*(s_pp - s_sup) = F/k_fl``,
    returns exactly the finger characteristic.  The spindle drives the tip
    position; the elastic force is the numerical inverse of ``s_tip(F)``
    (tabulated on 4001 forces), which must be increasing.  LVDT 2 follows the
    elastic force (it does not see the friction at the spindle, nor the
    frame compliance, which only LVDT 1 -- parallel to the force sensor --
    sees).
    """
    ratio = _check_number("lever_ratio", lever_ratio)
    if not ratio < 0:
        raise ParameterError(f"lever_ratio = {lever_ratio!r} must be < 0 (i_ds < 0 in [1], Section 3.2)")
    if "extra" in press_kwargs:
        raise ParameterError("simulate_lever_tests: 'extra' is not accepted; the LVDT 2 channels are built in")
    travel = _check_number("travel_m", travel_m, positive=True)
    start = _check_number("start_m", press_kwargs.get("start_m", 0.0))
    seed = press_kwargs.pop("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise ParameterError(f"seed = {seed!r} must be an integer")
    law = _tip_force_law(ratio, finger_law, rotation_law, support_law, start, start + travel)

    def support(x, _force):
        return _call_law(support_law, law(x), "support_law")

    def edge(x, _force):
        f = law(x)
        return _call_law(support_law, f, "support_law") + _call_law(rotation_law, f, "rotation_law")

    record_b = simulate_press_test(law, travel, seed=int(seed), extra={"displacement2_m": support}, **press_kwargs)
    record_c = simulate_press_test(law, travel, seed=int(seed) + 1, extra={"displacement2_m": edge}, **press_kwargs)
    record_b.attrs["provenance"] += "; lever test Fig. 8b of Haramina et al. 2024 (LVDT 2 at the support)"
    record_c.attrs["provenance"] += "; lever test Fig. 8c of Haramina et al. 2024 (LVDT 2 at the pressure-plate edge)"
    return record_b, record_c
