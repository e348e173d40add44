"""A small reference engine for MSL Rotational networks, written from the MSL equations, not from clutchlab.

The specification is the Modelica Standard Library (4.x) source: ``Interfaces.PartialFriction`` and the
friction elements built on it (``Components.Clutch``, ``Brake``, ``BearingFriction``),
``Components.OneWayClutch``, ``Components.LossyGear`` (Pelchen, Otter and Schweiger 2002),
``Components.IdealGear``, ``Components.ElastoBacklash``, ``Components.SpringDamper`` and the
``Modelica.Blocks.Sources`` signals.  Three elements MSL does not have are written from docs/driveline.md's
equations, for random networks that use them: the torque converter (``converter_torques``, also the law of
``tests/driveline/test_converter.py``), clutchlab's Kelvin-Voigt backlash contact (``backlash(...,
law="kelvin_voigt")``, with its released modes) and the synchroniser.  Nothing here imports clutchlab.

Method: the speeds and angles of the inertias are the states (SciPy ``solve_ivp``, DOP853, rtol 1e-12).
For a fixed set of modes, the accelerations and the constraint torques solve one linear system:
``M a + sum_k lambda_k d_k = F`` (known torques ``F``; a constraint ``k`` acts along ``d_k`` with the
unknown torque ``lambda_k``) and ``c_k . a = 0`` (a stuck friction element, a locked one-way clutch, a
gear's ratio, a locked lossy gear).  Every mode change is a terminal event of ``solve_ivp``; the
integration restarts after it.  At every event and signal break the modes are *settled* as Modelica's
event iteration does (``settle``): free/engaged by the normal force; a stuck element whose torque exceeds
its static limit breaks away (the furthest beyond first); an element sliding at zero speed that would
accelerate against its direction sticks; a lossy gear's quadrant (the sign of ``tau_eta``) follows its
torque.  Sign conventions are MSL's: an element's ``tau`` acts as ``-tau`` on the inertia at flange b
and ``+tau`` on the one at flange a; ``w_rel = w_b - w_a``; a gear's ``tau_a = flange_a.tau`` (the inertia
at flange a receives ``-tau_a``).

Where the suite departs from MSL on purpose (``OneWayClutch``'s ``tau0_max_low``, the release threshold
of a disengaged one-way clutch, ``1e-4 mu0 cgeo fn_max`` in MSL, 0 here by default = the pure freewheel of
the agreed clutchlab semantics) a keyword selects MSL's value.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

FREE, FWD, STUCK, BWD = "free", "forward", "stick", "backward"
#: MSL mode codes (PartialFriction, LossyGear)
MODE_CODE = {FWD: 1.0, STUCK: 0.0, BWD: -1.0, FREE: 2.0}


# ----------------------------------------------------------------------------- signals (Blocks.Sources)
@dataclass
class Sig:
    """A time signal: its value, the times where it jumps or kinks (restarts), and whether its zero
    crossings must be located (a continuous normal force that changes sign, e.g. a sine)."""

    f: callable
    breaks: tuple = ()
    crosses_zero: bool = False

    def __call__(self, t):
        return self.f(t)


def constant(k):
    return Sig(lambda t: k)


def step(height=1.0, offset=0.0, start=0.0):
    """Blocks.Sources.Step: offset + (if time < startTime then 0 else height)."""
    return Sig(lambda t: offset + (0.0 if t < start else height), (start,))


def ramp(height=1.0, duration=1.0, offset=0.0, start=0.0):
    """Blocks.Sources.Ramp."""
    def f(t):
        if t < start:
            return offset
        if t < start + duration:
            return offset + (t - start) * height / duration
        return offset + height
    return Sig(f, (start, start + duration))


def sine(amplitude=1.0, f=1.0, phase=0.0, offset=0.0, start=0.0, crosses_zero=False):
    """Blocks.Sources.Sine: offset + (if time < startTime then 0 else amplitude sin(2 pi f (t - startTime) + phase))."""
    def val(t):
        return offset + (0.0 if t < start else amplitude * math.sin(2.0 * math.pi * f * (t - start) + phase))
    return Sig(val, (start,) if start > 0 else (), crosses_zero)


def pulse(amplitude=1.0, width=0.5, period=1.0, nperiod=-1, offset=0.0, start=0.0, t_end=100.0):
    """Blocks.Sources.Pulse with ``width`` the fraction (MSL: percent) of the period that is on."""
    on = width * period

    def f(t):
        if t < start:
            return offset
        k = math.floor((t - start) / period + 1e-13)
        if nperiod >= 0 and k >= nperiod:
            return offset
        return offset + (amplitude if t - start - k * period < on - 1e-13 * period else 0.0)
    breaks = []
    k = 0
    while start + k * period <= t_end and (nperiod < 0 or k < nperiod):
        breaks += [start + k * period, start + k * period + on]
        k += 1
    return Sig(f, tuple(breaks))


def product(a: Sig, b: Sig):
    """Blocks.Math.Product of two signals."""
    return Sig(lambda t: a(t) * b(t), tuple(a.breaks) + tuple(b.breaks), a.crosses_zero or b.crosses_zero)


def table1d(rows):
    """A characteristic ``[[x, y], ...]`` in |x|: linear segments, MSL's ``LastTwoPoints`` extrapolation."""
    rows = np.atleast_2d(np.asarray(rows, float))
    if len(rows) == 1:
        return lambda x: float(rows[0, 1])
    xs, ys = rows[:, 0], rows[:, 1]

    def f(x):
        x = abs(x)
        i = min(max(np.searchsorted(xs, x) - 1, 0), len(xs) - 2)
        return float(ys[i] + (ys[i + 1] - ys[i]) * (x - xs[i]) / (xs[i + 1] - xs[i]))
    return f


# ----------------------------------------------------------------------------- a torque converter
def converter_capacity(table, s, torque_ratio=True):
    """``(1/K^2, TR)`` of ``table`` at ``0 <= s <= 1``: K and TR linear between rows, held below the first; from the
    last row the capacity falls linearly to 0 at 1."""
    t = np.asarray(table, dtype=float)
    sr, k = t[:, 0], t[:, 1]
    tr = t[:, 2] if torque_ratio else np.ones(len(t))
    if s >= sr[-1]:
        return (1.0 - s) / (1.0 - sr[-1]) / k[-1] ** 2, tr[-1]
    kk = np.interp(s, sr, k)
    return 1.0 / kk ** 2, float(np.interp(s, sr, tr))


def converter_torques(wp, wt, table, coast=None):
    """A hydrodynamic torque converter's torques on the impeller and the turbine ``(tau_p, tau_t)`` at their speeds
    against the support (the support receives ``-(tau_p + tau_t)``), written from docs/driveline.md's "Torque
    converter" (SAE J643's law made continuous at every pair of speeds), not from clutchlab: driving, ``T_p = w_p
    |w_p| / K(SR)^2`` and ``T_t = TR(SR) T_p`` at ``SR = w_t / w_p``; coasting (``|w_t| > |w_p|``) ``TR = 1`` with
    the coast table's ``K`` at ``w_p / w_t`` (default the drive table's); a driven member turning against its
    driver keeps the stall capacity and brings ``TR`` (or the coast capacity) linearly to the other side's at a
    ratio of -1; from the table's last row to a ratio of 1 the capacity ``1/K^2`` falls linearly to 0."""
    coast = [row[:2] for row in table] if coast is None else coast
    if wp == 0.0 and wt == 0.0:
        return 0.0, 0.0
    if abs(wp) >= abs(wt):
        s = wt / wp
        c0, tr0 = converter_capacity(table, 0.0)
        if s >= 0.0:
            c, tr = converter_capacity(table, s)
        else:   # the turbine turning against the impeller: TR from its stall value to 1 at s = -1
            c, tr = c0, tr0 + (tr0 - 1.0) * s
        tp = c * wp * abs(wp)
        return -tp, tr * tp
    s = wp / wt
    if s >= 0.0:
        c, _ = converter_capacity(coast, s, torque_ratio=False)
    else:   # the coast capacity from its value at 0 to the drive table's at stall, at s = -1
        cc0, _ = converter_capacity(coast, 0.0, torque_ratio=False)
        cd0, _ = converter_capacity(table, 0.0)
        c = cc0 + (cc0 - cd0) * s
    tt = c * wt * abs(wt)
    return tt, -tt


# ----------------------------------------------------------------------------- the network
#: how long switching functions seen at zero where a segment starts stay off [s] (:meth:`Network.simulate`)
REENABLE = 1e-5
#: how far ahead a tie is decided [s] (:meth:`Network.settle`)
LOOK = 1e-7


class Indeterminate(RuntimeError):
    """A statically indeterminate set of constraints in a strict network (:attr:`Network.strict`): the torques the
    constraints carry are not unique, and which split holds decides the next break-away."""


@dataclass
class Element:
    kind: str
    name: str
    a: int | None = None          # body index of flange a (None: the ground)
    b: int | None = None          # body index of flange b
    s: int | None = None          # body index of a gear's support
    p: dict = field(default_factory=dict)


class Network:
    """Inertias joined by MSL Rotational elements (build it with the methods, then :meth:`simulate`)."""

    def __init__(self, strict=False):
        self.names, self.J, self.w0, self.phi0 = [], [], [], []
        self.elements: list[Element] = []
        #: a statically indeterminate set of constraints holds while some split of its torques holds
        #: (:meth:`_holding_split`) instead of taking the least-squares split, which decides break-aways by its
        #: choice (MSL's equations are singular there); :class:`Indeterminate` where that cannot be written
        self.strict = strict
        self.margin = None
        self._memo = None

    # bodies and elements ---------------------------------------------------------------
    def inertia(self, name, J, w0=0.0, phi0=0.0):
        self.names.append(name)
        self.J.append(float(J))
        self.w0.append(float(w0))
        self.phi0.append(float(phi0))
        return self

    def _i(self, name):
        return None if name in (None, "ground") else self.names.index(name)

    def _add(self, kind, name, a=None, b=None, s=None, **p):
        self.elements.append(Element(kind, name, self._i(a), self._i(b), self._i(s), p))
        return self

    def torque(self, name, flange, signal: Sig, support=None):
        """Sources.Torque: ``flange`` gets +tau, ``support`` -tau."""
        return self._add("torque", name, a=support, b=flange, u=signal)

    def quadratic_torque(self, name, flange, tau_nominal, w_nominal, torque_direction=True):
        """Sources.QuadraticSpeedDependentTorque: the flange gets tau = tau_nominal (w/w_nominal)^2 (with
        TorqueDirection; else signed by w)."""
        def law(w):
            q = tau_nominal * (w / w_nominal) ** 2
            return q if torque_direction or w >= 0.0 else -q
        return self._add("torque", name, b=flange, u=None, law=law)

    def planetary(self, name, sun, carrier, ring, ratio):
        """IdealPlanetary: (1 + ratio) w_carrier = w_sun + ratio w_ring; tau the sun flange's (MSL sun.tau)."""
        self._add("planetary", name, a=sun, b=ring, s=carrier, ratio=ratio)
        return self

    def spring_damper(self, name, a, b, c=0.0, d=0.0, phi_rel0=0.0):
        """SpringDamper (Damper: c = 0): tau = c (phi_rel - phi_rel0) + d w_rel."""
        return self._add("spring_damper", name, a, b, c=c, d=d, phi_rel0=phi_rel0)

    def backlash(self, name, a, b, c, d, b_gap, phi_rel0=0.0, law="msl"):
        """ElastoBacklash (b > bEps), its damping law limited so the contact never pulls (``law="msl"``); or
        clutchlab's documented contact (``law="kelvin_voigt"``, docs/driveline.md "Backlash and nonlinear
        springs"; not MSL's): in contact tau = c delta + d w_rel (delta the deflection beyond the edge), the
        contact ends where that torque would pull, into the gap at the edge or *released* beyond it (no torque,
        the spring relaxing through its damper) until the torque would push again or delta returns to zero."""
        kind = "backlash" if law == "msl" else "kv_backlash"
        return self._add(kind, name, a, b, c=c, d=d, bmax=b_gap / 2.0, phi_rel0=phi_rel0)

    def torque_converter(self, name, a, b, table, coast=None, support=None):
        """A hydrodynamic torque converter, impeller on ``a``, turbine on ``b``, the stator's reaction on
        ``support`` (:func:`converter_torques`; MSL has no converter)."""
        return self._add("converter", name, a, b, support, table=table, coast=coast)

    def clutch(self, name, a, b, fn_max, normal: Sig, mu=0.5, peak=1.0, cgeo=1.0):
        """Clutch: tau0 = mu(0) cgeo fn, fn = fn_max f_normalized, free if fn <= 0."""
        mu_f = table1d(mu if isinstance(mu, (list, tuple)) else [[0.0, mu]])
        return self._add("friction", name, a, b, slide=lambda w, t: cgeo * fn_max * normal(t) * mu_f(w),
                         free=lambda t: fn_max * normal(t) <= 0.0, peak=peak, normal=normal)

    def brake(self, name, flange, fn_max, normal: Sig, mu=0.5, peak=1.0, cgeo=1.0, support=None):
        """Brake: a clutch between the support (flange a here) and the flange."""
        return self.clutch(name, support, flange, fn_max, normal, mu, peak, cgeo)

    def synchronizer(self, name, a, b, force: Sig, cone_radius, dog_capacity, mu=0.1, cone_angle=math.radians(6.5),
                     cones=1, side="positive"):
        """A synchroniser (docs/driveline.md "Synchronisers and the automated manual transmission", not MSL): a
        friction element whose cone slides with ``cones mu F R_c / sin(alpha)`` under the shift force ``F``
        (``-force`` with ``side="negative"``), free while ``F <= 0``, and stuck holds up to the dogs' capacity
        (never less than the cone's torque)."""
        sign = 1.0 if side == "positive" else -1.0
        cgeo = cones * cone_radius / math.sin(cone_angle)
        shift = Sig(lambda t: sign * force(t), force.breaks, force.crosses_zero)
        return self._add("friction", name, a, b, slide=lambda w, t: mu * cgeo * shift(t),
                         free=lambda t: shift(t) <= 0.0,
                         peak=1.0, normal=shift, limit=lambda t: max(dog_capacity, mu * cgeo * shift(t)))

    def bearing_friction(self, name, flange, tau_pos=1.0, peak=1.0, support=None):
        """BearingFriction: tau = tau_pos(|w|), never free."""
        tf = table1d(tau_pos if isinstance(tau_pos, (list, tuple)) else [[0.0, tau_pos]])
        return self._add("friction", name, support, flange, slide=lambda w, t: tf(w), free=lambda t: False,
                         peak=peak, normal=None)

    def one_way_clutch(self, name, a, b, fn_max=0.0, normal: Sig | None = None, mu=0.5, peak=1.0, cgeo=1.0,
                       msl_tau0_max_low=False):
        """OneWayClutch: free wheel (w_rel >= 0) in parallel with a clutch acting against overrunning.
        Locked it holds any negative torque and up to tau0_max = peak2 tau0 (engaged) or tau0_max_low
        (disengaged: MSL 1e-4 mu0 cgeo fn_max; 0 unless ``msl_tau0_max_low``); overrunning it carries
        mu cgeo fn (0 while disengaged)."""
        normal = normal or constant(0.0)
        low = 1e-4 * mu * cgeo * fn_max if msl_tau0_max_low else 0.0
        peak2 = max(peak, 1.0 + 1e-4)
        return self._add("one_way", name, a, b, fn=lambda t: fn_max * normal(t), mu=mu, cgeo=cgeo, peak2=peak2,
                         low=low, normal=normal)

    def gear(self, name, a, b, ratio, support=None, loss_table=None):
        """IdealGear (no ``loss_table``) or LossyGear (rows [w, eta_mf1, eta_mf2, tau_bf1, tau_bf2])."""
        # (ideal only if exactly [0, 1, 1, 0, 0], MSL's isEqual to eps: np.allclose took an efficiency of 0.99999)
        if loss_table is None or np.array_equal(np.asarray(loss_table, float), [[0.0, 1.0, 1.0, 0.0, 0.0]]):
            return self._add("gear", name, a, b, support, ratio=ratio)
        lt = np.atleast_2d(np.asarray(loss_table, float))
        cols = [table1d(np.c_[lt[:, 0], lt[:, j]]) for j in range(1, 5)]
        return self._add("lossy_gear", name, a, b, support, ratio=ratio, cols=cols)

    # the equations ---------------------------------------------------------------------
    @property
    def n(self):
        return len(self.J)

    def _e(self, i, v=1.0):
        e = np.zeros(self.n)
        if i is not None:
            e[i] = v
        return e

    def _rel(self, el, y):
        """w_rel = w_b - w_a and phi_rel (angles are states n..2n)."""
        n = self.n
        wa = 0.0 if el.a is None else y[el.a]
        wb = 0.0 if el.b is None else y[el.b]
        pa = 0.0 if el.a is None else y[n + el.a]
        pb = 0.0 if el.b is None else y[n + el.b]
        return wb - wa, pb - pa

    def _gear_w(self, el, y):
        ws = 0.0 if el.s is None else y[el.s]
        wa = (0.0 if el.a is None else y[el.a]) - ws
        return wa

    @staticmethod
    def _loss(el, wa):
        """eta_mf1, eta_mf2, tau_bf1, tau_bf2 and tau_bf_a at |w_a| (LossyGear)."""
        e1, e2, b1, b2 = (c(wa) for c in el.p["cols"])
        b1, b2 = abs(b1), abs(b2)
        if abs(e1 - 1.0) < 1e-15 and abs(e2 - 1.0) < 1e-15:
            bfa = b1 / 2.0
        else:
            bfa = (b1 - b2) / (e1 - 1.0 / e2)
        return e1, e2, b1, b2, bfa

    @staticmethod
    def _quadrant(el, mode, q, wa):
        """(k, m) of tau_b = -ratio (k tau_a - m) for the rolling quadrants of LossyGear."""
        e1, e2, b1, b2, _ = Network._loss(el, wa)
        if mode == FWD:
            return (e1, b1) if q > 0 else (1.0 / e2, b2)     # quadrant1, quadrant2
        return (1.0 / e2, -b2) if q > 0 else (e1, -b1)      # quadrant4, quadrant3

    @staticmethod
    def backlash_tau(p, phi_rel, w_rel):
        """ElastoBacklash (MSL 4.x, b > bEps): tau and the loss power."""
        diff = phi_rel - p["phi_rel0"]
        if diff > p["bmax"]:
            tc, td = p["c"] * (diff - p["bmax"]), p["d"] * w_rel
            return (0.0, 0.0) if tc + td <= 0 else (tc + min(tc, td), min(tc, td) * w_rel)
        if diff < -p["bmax"]:
            tc, td = p["c"] * (diff + p["bmax"]), p["d"] * w_rel
            return (0.0, 0.0) if tc + td >= 0 else (tc + max(tc, td), max(tc, td) * w_rel)
        return 0.0, 0.0

    def solve(self, t, y, modes, split=True):
        """Accelerations and every element's torque for fixed modes.  Returns (a, out) with out[name] a
        dict: tau (MSL's element torque; a gear's tau_a), power (its loss or, for a source, its power).
        ``split=False``: an indeterminate stuck set's torques as any split (the accelerations, the same for every
        split, are what the integration needs; :meth:`_holding_split` solves a linear program).  The last split
        solved is kept for the same time, state and modes (the event functions ask for it in turn)."""
        key = None
        if split and self.strict:
            key = (float(t), np.asarray(y[:2 * self.n], float).tobytes(), tuple(sorted(modes.items())))
            if self._memo is not None and self._memo[0] == key:
                self.margin = self._memo[2]
                return self._memo[1]
        result = self._solve(t, y, modes, split)
        if key is not None:
            self._memo = (key, result, self.margin)
        return result

    def _solve(self, t, y, modes, split):
        n = self.n
        M = np.diag(self.J)
        F = np.zeros(n)
        D, C, owner = [], [], []          # constraint force directions, constraint rows, (element, slot)
        out = {}
        for el in self.elements:
            m = modes.get(el.name)
            if el.kind == "torque":
                wb = y[el.b] - (0.0 if el.a is None else y[el.a])
                u = el.p["u"](t) if el.p.get("u") is not None else el.p["law"](wb)
                F += self._e(el.b, u) - self._e(el.a, u)
                out[el.name] = {"tau": u, "power": u * wb}
            elif el.kind in ("spring_damper", "backlash"):
                w_rel, phi_rel = self._rel(el, y)
                if el.kind == "spring_damper":
                    tau = el.p["c"] * (phi_rel - el.p["phi_rel0"]) + el.p["d"] * w_rel
                    loss = el.p["d"] * w_rel * w_rel
                else:
                    tau, loss = self.backlash_tau(el.p, phi_rel, w_rel)
                F += self._e(el.a, tau) - self._e(el.b, tau)
                out[el.name] = {"tau": tau, "power": loss}
            elif el.kind == "kv_backlash":
                w_rel, phi_rel = self._rel(el, y)
                diff = phi_rel - el.p["phi_rel0"]
                tau, loss = 0.0, 0.0
                if m in ("upper", "lower"):
                    delta = diff - el.p["bmax"] if m == "upper" else diff + el.p["bmax"]
                    tau = el.p["c"] * delta + el.p["d"] * w_rel
                    loss = el.p["d"] * w_rel * w_rel
                elif m in ("upper_released", "lower_released"):
                    delta = diff - el.p["bmax"] if m == "upper_released" else diff + el.p["bmax"]
                    loss = -el.p["c"] * delta * w_rel      # the deflected spring relaxes through its damper
                F += self._e(el.a, tau) - self._e(el.b, tau)
                out[el.name] = {"tau": tau, "power": loss}
            elif el.kind == "converter":
                ws = 0.0 if el.s is None else y[el.s]
                wp = (0.0 if el.a is None else y[el.a]) - ws
                wt = (0.0 if el.b is None else y[el.b]) - ws
                ta, tb = converter_torques(wp, wt, el.p["table"], el.p["coast"])
                F += self._e(el.a, ta) + self._e(el.b, tb) - self._e(el.s, ta + tb)
                out[el.name] = {"tau": ta, "tau_b": tb, "power": -(ta * wp + tb * wt)}
            elif el.kind in ("friction", "one_way"):
                w_rel, _ = self._rel(el, y)
                cvec = self._e(el.b) - self._e(el.a)
                if m == STUCK:
                    D.append(cvec)
                    C.append(cvec)
                    owner.append((el.name, 0))
                    out[el.name] = {"tau": None}
                    continue
                if el.kind == "friction":
                    tau = 0.0 if m == FREE else (1.0 if m == FWD else -1.0) * el.p["slide"](w_rel, t)
                else:
                    fn = el.p["fn"](t)
                    tau = 0.0 if fn <= 0 else el.p["mu"] * el.p["cgeo"] * fn
                F += self._e(el.a, tau) - self._e(el.b, tau)
                out[el.name] = {"tau": tau}
            elif el.kind == "planetary":   # sun + ratio ring - (1 + ratio) carrier = 0, workless
                r = el.p["ratio"]
                cvec = self._e(el.a) + self._e(el.b, r) - self._e(el.s, 1.0 + r)
                D.append(cvec)
                C.append(cvec)
                owner.append((el.name, 0))
                out[el.name] = {"tau": None}
            elif el.kind == "gear":
                r = el.p["ratio"]
                cvec = self._e(el.a) - self._e(el.b, r) + self._e(el.s, r - 1.0)
                D.append(cvec)
                C.append(cvec)
                owner.append((el.name, 0))
                out[el.name] = {"tau": None}
            elif el.kind == "lossy_gear":
                r = el.p["ratio"]
                cvec = self._e(el.a) - self._e(el.b, r) + self._e(el.s, r - 1.0)
                if m == STUCK:   # locked: both flanges held against the support, tau_a and tau_b free
                    for slot, i in ((0, el.a), (1, el.b)):
                        row = self._e(i) - self._e(el.s)
                        D.append(row)
                        C.append(row)
                        owner.append((el.name, slot))
                    out[el.name] = {"tau": None, "tau_b": None}
                    continue
                k, mm = self._quadrant(el, m, modes[el.name + ".q"], self._gear_w(el, y))
                D.append(self._e(el.a) - self._e(el.b, r * k) + self._e(el.s, r * k - 1.0))
                C.append(cvec)
                owner.append((el.name, 0))
                F += r * mm * (self._e(el.s) - self._e(el.b))
                out[el.name] = {"tau": None, "k": k, "m": mm}
        nc = len(C)
        A = np.zeros((n + nc, n + nc))
        A[:n, :n] = M
        rhs = np.zeros(n + nc)
        rhs[:n] = F
        for j in range(nc):
            A[:n, n + j] = D[j]
            A[n + j, :n] = C[j]
        self.margin = None
        deficient = self.strict and nc and np.linalg.matrix_rank(np.array(C), tol=1e-9) < nc
        if deficient and split:
            x = self._holding_split(t, A, rhs, np.array(D), owner, modes)
        elif deficient:
            x = np.linalg.lstsq(A, rhs, rcond=None)[0]
        else:
            try:
                x = np.linalg.solve(A, rhs)
            except np.linalg.LinAlgError:
                # constraints that hold the same motion twice (a stuck bearing on the flange of a locked gear):
                # the torques are not unique (MSL: a singular system); take the least-squares split
                x = np.linalg.lstsq(A, rhs, rcond=None)[0]
        acc = x[:n]
        for j, (name, slot) in enumerate(owner):
            out[name]["tau" if slot == 0 else "tau_b"] = float(x[n + j])
        # derived quantities of gears and friction elements
        for el in self.elements:
            o = out[el.name]
            if el.kind in ("friction", "one_way"):
                w_rel, _ = self._rel(el, y)
                o["power"] = o["tau"] * w_rel
                o["w_rel"] = w_rel
                o["a_rel"] = (0.0 if el.b is None else acc[el.b]) - (0.0 if el.a is None else acc[el.a])
            elif el.kind in ("gear", "lossy_gear"):
                r, ta = el.p["ratio"], o["tau"]
                wa = self._gear_w(el, y)
                aa = (0.0 if el.a is None else acc[el.a]) - (0.0 if el.s is None else acc[el.s])
                if el.kind == "gear":
                    o.update(tau_b=-r * ta, loss=0.0)
                elif modes[el.name] == STUCK:
                    o["loss"] = ta + o["tau_b"] / r           # tauLoss = sa while locked
                else:
                    o["tau_b"] = -r * (o["k"] * ta - o["m"])
                    o["loss"] = ta + o["tau_b"] / r
                o.update(w_a=wa, a_a=aa, power=o["loss"] * wa)
        return acc, out

    def _holding_split(self, t, A, rhs, D, owner, modes):
        """The accelerations and constraint torques of a statically indeterminate stuck set (a strict network):
        the accelerations are unique, the torques ``lambda0 + N z`` over the null space ``N`` of the constraint
        directions.  Of those splits, the one farthest inside every stuck friction element's and locked one-way
        clutch's limit: the linear program ``min s`` over ``(z, s)`` with each ``|tau_k| - limit_k <= s`` (a
        one-way clutch's ``tau_k - limit_k <= s``: it holds any torque the other way).  ``self.margin`` is its
        ``s``: the set holds while some split holds (``s <= 0``), and the element whose excess is ``s`` breaks
        away first where none does (:meth:`settle`, the furthest beyond its limit).  Rigid-body Coulomb friction's
        reading where MSL's equations are singular; written here with SciPy's ``linprog``, not from clutchlab.
        Raises :class:`Indeterminate` where a locked lossy gear's torques move along the null space (its band is
        not convex in them)."""
        from scipy.linalg import null_space
        from scipy.optimize import linprog

        n = len(self.J)
        x = np.linalg.lstsq(A, rhs, rcond=None)[0]
        lam0 = x[n:]
        N = null_space(D.T, rcond=1e-10)
        k = N.shape[1]
        by_name = {e.name: e for e in self.elements}
        rows, bounds = [], []
        for j, (name, _slot) in enumerate(owner):
            el = by_name[name]
            if el.kind == "lossy_gear" and np.abs(N[j]).max(initial=0.0) > 1e-12:
                raise Indeterminate(f"t = {t!r}: a locked lossy gear {name} in an indeterminate stuck set")
            if el.kind in ("friction", "one_way") and modes.get(name) == STUCK:
                lim = self._limit(el, t)
                rows.append(np.r_[N[j], -1.0])
                bounds.append(lim - lam0[j])
                if el.kind == "friction":
                    rows.append(np.r_[-N[j], -1.0])
                    bounds.append(lim + lam0[j])
        if not rows or k == 0:
            return x
        big = 1e9
        res = linprog(np.r_[np.zeros(k), 1.0], A_ub=np.array(rows), b_ub=np.array(bounds),
                      bounds=[(-big, big)] * k + [(-big, big)], method="highs")
        if res.status != 0:
            raise Indeterminate(f"t = {t!r}: the split's linear program failed ({res.message})")
        x = x.copy()
        x[n:] = lam0 + N @ res.x[:k]
        self.margin = float(res.x[k])
        return x

    def _split_margin(self, t, y, modes):
        """The indeterminate stuck set's margin (:meth:`_holding_split`), -1 where the set is determinate."""
        self.solve(t, y, modes)
        return -1.0 if self.margin is None else self.margin

    # events ------------------------------------------------------------------------------
    def _limit(self, el, t):
        """Static limit of a stuck friction element (peak tau0) or a locked one-way clutch (tau0_max)."""
        if el.kind == "friction":
            if "limit" in el.p:          # a synchroniser's dogs
                return el.p["limit"](t)
            return el.p["peak"] * el.p["slide"](0.0, t)
        fn = el.p["fn"](t)
        return el.p["low"] if fn <= 0 else el.p["peak2"] * el.p["mu"] * el.p["cgeo"] * fn

    def _gear_bounds(self, el, ta):
        """LossyGear's tauLossMax_p and tauLossMin_m (values at w = 0) for the locked torque tau_a."""
        e1, e2, b1, b2, bfa = self._loss(el, 0.0)
        lmax = (1 - e1) * ta + b1 if ta - bfa > 0 else (1 - 1 / e2) * ta + b2
        lmin = (1 - 1 / e2) * ta - b2 if ta + bfa > 0 else (1 - e1) * ta - b1
        return lmax, lmin

    def _event_functions(self, modes):
        """(function, direction, tag) per switching condition of the present modes."""
        evs = []

        def add(fun, direction, tag):
            evs.append((fun, direction, tag))

        if self.strict:     # an indeterminate stuck set stops holding where no split holds
            add(lambda t, y: self._split_margin(t, y, modes), 1.0, ("stuck set", "no split holds"))

        for el in self.elements:
            m = modes.get(el.name)
            if el.kind in ("friction", "one_way"):
                if m in (FWD, BWD):
                    add(lambda t, y, el=el: self._rel(el, y)[0], -1.0 if m == FWD else 1.0, (el.name, "zero"))
                elif m == STUCK:
                    add(lambda t, y, el=el: self.solve(t, y, modes)[1][el.name]["tau"] - self._limit(el, t), 1.0,
                        (el.name, "break+"))
                    if el.kind == "friction":
                        add(lambda t, y, el=el: -self.solve(t, y, modes)[1][el.name]["tau"] - self._limit(el, t),
                            1.0, (el.name, "break-"))
                nrm = el.p.get("normal")
                if nrm is not None and nrm.crosses_zero:
                    add(lambda t, y, nrm=nrm: nrm(t), 0.0, (el.name, "normal"))
            elif el.kind == "lossy_gear":
                if m in (FWD, BWD):
                    add(lambda t, y, el=el: self._gear_w(el, y), -1.0 if m == FWD else 1.0, (el.name, "zero"))

                    def tau_eta(t, y, el=el, m=m):
                        o = self.solve(t, y, modes)[1][el.name]
                        bfa = self._loss(el, o["w_a"])[4]
                        return o["tau"] - bfa if m == FWD else o["tau"] + bfa
                    add(tau_eta, 0.0, (el.name, "quadrant"))
                else:
                    def up(t, y, el=el):
                        o = self.solve(t, y, modes)[1][el.name]
                        return o["loss"] - self._gear_bounds(el, o["tau"])[0]

                    def down(t, y, el=el):
                        o = self.solve(t, y, modes)[1][el.name]
                        return o["loss"] - self._gear_bounds(el, o["tau"])[1]
                    add(up, 1.0, (el.name, "break+"))
                    add(down, -1.0, (el.name, "break-"))
            elif el.kind == "backlash":
                p = el.p

                def edge(t, y, el=el, s=1.0):
                    return self._rel(el, y)[1] - el.p["phi_rel0"] - s * el.p["bmax"]

                def kinks(t, y, el=el, which=0):
                    w_rel, phi_rel = self._rel(el, y)
                    diff = phi_rel - el.p["phi_rel0"]
                    edge_ = el.p["bmax"] if diff > 0 else -el.p["bmax"]
                    tc, td = el.p["c"] * (diff - edge_), el.p["d"] * w_rel
                    return tc + td if which == 0 else tc - td
                add(edge, 0.0, (el.name, "kink"))
                add(lambda t, y, el=el: edge(t, y, el, -1.0), 0.0, (el.name, "kink"))
                if p["d"] > 0:
                    add(kinks, 0.0, (el.name, "kink"))
                    add(lambda t, y, el=el: kinks(t, y, el, 1), 0.0, (el.name, "kink"))
            elif el.kind == "kv_backlash":
                def rel(t, y, el=el, edge=1.0):
                    w_rel, phi_rel = self._rel(el, y)
                    return phi_rel - el.p["phi_rel0"] - edge * el.p["bmax"], w_rel

                def push(t, y, el=el, edge=1.0):
                    delta, w_rel = rel(t, y, el, edge)
                    return el.p["c"] * delta + el.p["d"] * w_rel
                if m == "gap":
                    add(lambda t, y, el=el: rel(t, y, el, 1.0)[0], 1.0, (el.name, "contact+"))
                    add(lambda t, y, el=el: rel(t, y, el, -1.0)[0], -1.0, (el.name, "contact-"))
                else:
                    s = 1.0 if m.startswith("upper") else -1.0
                    if m in ("upper", "lower"):       # the contact torque would pull: separate
                        add(lambda t, y, el=el, s=s: push(t, y, el, s), -s, (el.name, "separate"))
                    else:                             # released: pushes again, or back at the edge
                        add(lambda t, y, el=el, s=s: push(t, y, el, s), s, (el.name, "push"))
                        add(lambda t, y, el=el, s=s: rel(t, y, el, s)[0], -s, (el.name, "into_gap"))
        return evs

    def _backlash_event(self, el, what, t, y, modes):
        """The new mode of Kelvin-Voigt backlash ``el`` at its event ``what``."""
        if what in ("contact+", "contact-"):
            return "upper" if what == "contact+" else "lower"
        if what == "into_gap":
            return "gap"
        up = modes[el.name].startswith("upper")
        if what == "push":
            return "upper" if up else "lower"
        # separate: at the edge into the gap, beyond it released
        _w, phi_rel = self._rel(el, y)
        delta = phi_rel - el.p["phi_rel0"] - (1.0 if up else -1.0) * el.p["bmax"]
        if abs(delta) <= 1e-12 * max(1.0, el.p["bmax"]):
            return "gap"
        return "upper_released" if up else "lower_released"

    # mode logic --------------------------------------------------------------------------
    def _initial_modes(self, t, y):
        modes = {}
        for el in self.elements:
            if el.kind == "friction":
                w_rel = self._rel(el, y)[0]
                modes[el.name] = FREE if el.p["free"](t) else (FWD if w_rel > 0 else BWD if w_rel < 0 else STUCK)
            elif el.kind == "one_way":
                w_rel = self._rel(el, y)[0]
                if w_rel < 0:
                    raise ValueError(f"{el.name}: w_rel < 0 at the start (MSL: not physically possible)")
                modes[el.name] = FWD if w_rel > 0 else STUCK
            elif el.kind == "lossy_gear":
                wa = self._gear_w(el, y)
                modes[el.name] = FWD if wa > 0 else BWD if wa < 0 else STUCK
                modes[el.name + ".q"] = 1.0
            elif el.kind == "kv_backlash":
                diff = self._rel(el, y)[1] - el.p["phi_rel0"]
                bmax = el.p["bmax"]
                modes[el.name] = "upper" if diff > bmax else "lower" if diff < -bmax else "gap"
        return modes

    def settle(self, t, y, modes, log, tol=1e-10, eps=1e-9):
        """Modelica's event iteration at time t (state fixed): apply one change at a time until none
        applies.  Appends (t, element, new mode) to ``log`` for every change.

        A tie (a load exactly at its limit, an element at zero speed with zero relative acceleration: a network
        at rest whose sources start from zero, a spring that starts to wind up) is decided by the same quantity
        :data:`LOOK` seconds later, one explicit Euler step on (the sources' next values and the state's motion),
        so a load growing from zero breaks away the way it grows."""
        def scale(x):
            return tol * max(1.0, abs(x))

        def setm(name, m):
            if modes[name] != m:
                modes[name] = m
                log.append((t, name, m))

        for _ in range(200):
            for el in self.elements:       # free / engaged (PartialFriction: mode = Free if free)
                if el.kind != "friction":
                    continue
                w_rel = self._rel(el, y)[0]
                if el.p["free"](t + 1e-10):      # just after the instant (a sine's zero crossing)
                    setm(el.name, FREE)
                elif modes[el.name] == FREE:
                    setm(el.name, FWD if w_rel > eps else BWD if w_rel < -eps else STUCK)
            acc, out = self.solve(t, y, modes)
            ahead = None

            def later(name, key):
                nonlocal ahead
                if ahead is None:   # one explicit Euler step: the sources' next values and the state's motion
                    n = self.n
                    y_next = np.array(y, float)
                    y_next[:n] += LOOK * acc
                    y_next[n:2 * n] += LOOK * np.asarray(y[:n], float)
                    ahead = self.solve(t + LOOK, y_next, modes)[1]
                return ahead[name][key]
            worst, excess = None, 0.0
            ties = []
            for el in self.elements:       # break-away: the furthest beyond its limit first
                m, o = modes.get(el.name), out[el.name]
                if el.kind in ("friction", "one_way") and m == STUCK:
                    lim = self._limit(el, t)
                    for direction, x in ((FWD, o["tau"] - lim), (BWD, -o["tau"] - lim)):
                        if direction == BWD and el.kind == "one_way":
                            continue
                        if abs(x) <= scale(lim):
                            ties.append((el, direction, lim))
                        if x > scale(lim) and x > excess:
                            worst, excess = (el.name, direction), x
                elif el.kind == "lossy_gear" and m == STUCK:
                    lmax, lmin = self._gear_bounds(el, o["tau"])
                    for direction, x in ((FWD, o["loss"] - lmax), (BWD, lmin - o["loss"])):
                        if x > scale(o["tau"]) and x > excess:
                            worst, excess = (el.name, direction), x
            if worst is None:              # a tie: the way the load goes
                for el, direction, lim in ties:
                    tau, lim_later = later(el.name, "tau"), self._limit(el, t + LOOK)
                    x = tau - lim_later if direction == FWD else -tau - lim_later
                    if x > scale(lim) and x > excess:
                        worst, excess = (el.name, direction), x
            if worst is not None:
                setm(*worst)
                el = next(e for e in self.elements if e.name == worst[0])
                if el.kind == "lossy_gear":    # startForward/startBackward: tau_eta = tau_a -/+ tau_bf_a
                    bfa = self._loss(el, 0.0)[4]
                    ta = out[el.name]["tau"]
                    modes[el.name + ".q"] = 1.0 if (ta - bfa if worst[1] == FWD else ta + bfa) >= 0 else -1.0
                continue
            change = None
            for el in self.elements:       # sliding at zero speed against its direction: stuck
                m, o = modes.get(el.name), out[el.name]
                if el.kind in ("friction", "one_way") and m in (FWD, BWD):
                    s = 1.0 if m == FWD else -1.0
                    if s * o["w_rel"] < -eps:
                        raise RuntimeError(f"t = {t!r}: {el.name} slides against its mode (a crossing missed)")
                    if abs(o["w_rel"]) >= eps:
                        continue
                    a_rel = o["a_rel"]
                    if abs(a_rel) <= scale(a_rel):   # a tie: the way it accelerates next
                        a_rel = later(el.name, "a_rel")
                    if s * a_rel < -scale(o["a_rel"]):
                        change = (el.name, STUCK)
                        break
                if el.kind == "lossy_gear" and m in (FWD, BWD):
                    s = 1.0 if m == FWD else -1.0
                    if abs(o["w_a"]) < eps and s * o["a_a"] < -scale(o["a_a"]):
                        change = (el.name, STUCK)
                        break
                    bfa = self._loss(el, o["w_a"])[4]
                    eta = o["tau"] - bfa if m == FWD else o["tau"] + bfa
                    q = modes[el.name + ".q"]
                    tie = abs(eta) <= scale(o["tau"]) and abs(o["w_a"]) < eps
                    if tie:
                        # a tie as it leaves rest (tau_eta = 0 to rounding: startForward/startBackward's ">= 0" took
                        # quadrant 1 or 4 whichever flange drives): the way tau_eta goes, LOOK later in this quadrant.
                        # (A gear with tau_bf1 = tau_bf2, so tau_bf_a = 0, breaking away forward under a sine on flange
                        # b from rest: tau_a is 0 there, the gear ran in quadrant 1, a driving, at 1.8 times the
                        # acceleration of quadrant 2; the sixty-second session's random table networks)
                        ta_later = later(el.name, "tau")
                        eta = ta_later - bfa if m == FWD else ta_later + bfa
                    if (eta >= 0) != (q > 0) and (abs(eta) > scale(o["tau"]) or (tie and eta != 0.0)):
                        modes[el.name + ".q"] = -q
                        change = ("quadrant", None)
                        break
            if change is None:
                return modes
            if change[0] != "quadrant":
                setm(*change)
        raise RuntimeError(f"mode iteration did not converge at t = {t!r}")

    # the run -----------------------------------------------------------------------------
    def simulate(self, t_end, t_out, rtol=1e-12, atol=1e-12, max_step=1e-3, breaks=(), partial=False):
        """Integrate to ``t_end``; return a :class:`Result` sampled at ``t_out``.  ``max_step`` bounds the
        step so that no switching function crosses zero and back within one step (a locked network has
        no error to limit it).  ``partial``: a strict network that meets a statically indeterminate set of
        constraints (:class:`Indeterminate`) ends the run there, its result's ``reached`` the time it got to
        (``t_end`` for a whole run)."""
        n = self.n
        sources = [e for e in self.elements if e.kind == "torque"]
        lossy = [e for e in self.elements if e.kind in ("friction", "one_way", "lossy_gear", "spring_damper",
                                                        "backlash", "kv_backlash", "converter")]
        ny = 2 * n + len(sources) + len(lossy)
        y = np.zeros(ny)
        y[:n] = self.w0
        y[n:2 * n] = self.phi0
        t = 0.0
        tb = set(breaks)
        for el in self.elements:
            for key in ("u", "normal"):
                if el.p.get(key) is not None:
                    tb.update(el.p[key].breaks)
        tb = sorted(x for x in tb if 0.0 < x < t_end) + [t_end]
        modes = self._initial_modes(t, y)
        log = []
        self.settle(t, y, modes, log)
        initial = dict(modes)
        segments = []                # (t0, t1, sol, modes)

        def rhs_for(md):
            def rhs(tt, yy):
                acc, out = self.solve(tt, yy, md, split=False)
                dy = np.zeros(ny)
                dy[:n] = acc
                dy[n:2 * n] = yy[:n]
                for j, e in enumerate(sources):
                    dy[2 * n + j] = out[e.name]["power"]
                for j, e in enumerate(lossy):
                    dy[2 * n + len(sources) + j] = out[e.name]["power"]
                return dy
            return rhs

        disabled = set()
        quiet = 0                    # short segments in a row that ended with no event
        reached = t_end
        try:
            while t < t_end:
                t_stop = min(x for x in tb if x > t)
                if disabled:
                    # functions seen at zero where this segment starts are off only for a short segment: the run
                    # ends it, settles and takes them back (a normal force's sine that takes a clutch out at one
                    # zero must engage it at the next).  One that stays at zero (a free wheel at rest with nothing
                    # driving it) is seen again at every start: the segments double, up to 1 ms (a crossing
                    # missed meanwhile is the settle's error, "slides against its mode")
                    t_stop = min(t_stop, t + min(REENABLE * 2.0 ** quiet, 1e-3))
                md = dict(modes)
                evs = [e for e in self._event_functions(md) if e[2] not in disabled]
                funs = []
                for fun, direction, _tag in evs:
                    def g(tt, yy, fun=fun):
                        return fun(tt, yy[:2 * n])
                    g.terminal, g.direction = True, direction
                    funs.append(g)
                sol = solve_ivp(rhs_for(md), (t, t_stop), y, method="DOP853", rtol=rtol, atol=atol,
                                max_step=max_step, events=funs, dense_output=True)
                if sol.status < 0:
                    raise RuntimeError(sol.message)
                te, ye = sol.t[-1], sol.y[:, -1].copy()
                segments.append((t, te, sol.sol, md))
                if sol.status == 1:
                    hits = [evs[i][2] for i in range(len(evs)) if len(sol.t_events[i])
                            and abs(sol.t_events[i][-1] - te) <= 1e-13]
                    if any(tag[1] == "zero" for tag in hits):
                        # an element on the same motion reaches zero speed at the same instant (a bearing on a
                        # lossy gear's shaft): its root may be dropped as later by an ulp, or land an ulp past
                        # zero, with the processor's rounding; it is stuck too (the settle releases it if its
                        # torque is beyond its limit)
                        hits += [tag for (fun, _d, tag) in evs if tag[1] == "zero" and tag not in hits
                                 and abs(fun(te, ye[:2 * n])) < 1e-12]
                    at_start = te - t < 1e-12
                    for tag in hits:
                        name, what = tag
                        if at_start:
                            # a function at zero where its segment starts: the crossing the settle at this
                            # instant has just decided (it sticks an element released at zero speed that would
                            # accelerate against its direction, breaks a tie the way the load goes, flips a
                            # quadrant whose sign disagrees), seen again; applied once more it would undo that
                            # decision (a gear run in the quadrant its tau_eta has just left, an element released
                            # at zero speed stuck again).  Off for a short segment (:data:`REENABLE`).
                            disabled.add(tag)
                            continue
                        if what in ("kink", "normal"):
                            continue
                        if what == "zero":
                            modes[name] = STUCK
                            log.append((te, name, STUCK))
                        elif what in ("break+", "break-"):
                            modes[name] = FWD if what == "break+" else BWD
                            log.append((te, name, modes[name]))
                            el = next(e for e in self.elements if e.name == name)
                            if el.kind == "lossy_gear":
                                o = self.solve(te, ye[:2 * n], md)[1][name]
                                bfa = self._loss(el, 0.0)[4]
                                eta = o["tau"] - bfa if modes[name] == FWD else o["tau"] + bfa
                                modes[name + ".q"] = 1.0 if eta >= 0 else -1.0
                        elif what == "quadrant":
                            modes[name + ".q"] = -modes[name + ".q"]
                        elif what in ("contact+", "contact-", "separate", "push", "into_gap"):
                            el = next(e for e in self.elements if e.name == name)
                            modes[name] = self._backlash_event(el, what, te, ye[:2 * n], modes)
                            log.append((te, name, modes[name]))
                    if not at_start:
                        disabled = set()
                        quiet = 0
                    self.settle(te, ye[:2 * n], modes, log)
                else:
                    quiet = quiet + 1 if disabled else 0
                    disabled = set()
                    if te < t_end:
                        self.settle(te, ye[:2 * n], modes, log)
                t, y = te, ye
        except Indeterminate:
            if not partial or not segments:
                raise
            reached = segments[-1][1]   # (the samples after it hold that segment's end: not a result)
        res = Result(self, segments, log, initial, np.asarray(t_out, float), sources, lossy)
        res.reached = reached
        return res


def collapse(log):
    """One event per element and instant: the mode it ends in (MSL passes through Stuck on a reversal
    within one event iteration); changes that return to the mode before the instant are dropped."""
    out = []
    i = 0
    while i < len(log):
        t, name, _ = log[i]
        same = [e for e in log if abs(e[0] - t) < 1e-12 and e[1] == name]
        before = None
        for e in reversed([e for e in log[:i] if e[1] == name]):
            before = e[2]
            break
        last = same[-1][2]
        if last != before and (t, name) not in [(o[0], o[1]) for o in out]:
            out.append((t, name, last))
        i += 1
    return out


class Result:
    """Samples of a reference run: ``columns`` (clutchlab's names: ``J.w_rad_s``, ``J.phi_rad``,
    ``E.tau_Nm`` in clutchlab's element convention, ``E.dissipated_J``, ``S.work_J``, ``G.mode_1``),
    ``events`` [(t, element, mode)] after t = 0 (collapsed per instant), ``initial`` modes."""

    def __init__(self, net, segments, log, initial, t_out, sources, lossy):
        self.events = collapse([e for e in log if e[0] > 0.0])
        self.log = log
        self.initial = initial
        self.time = t_out
        n = net.n
        cols = {f"{nm}.{q}": np.zeros(len(t_out)) for nm in net.names for q in ("w_rad_s", "phi_rad")}
        for el in net.elements:
            if el.kind != "torque":
                cols[f"{el.name}.tau_Nm"] = np.zeros(len(t_out))
            if el.kind == "lossy_gear":
                cols[f"{el.name}.mode_1"] = np.zeros(len(t_out))
        for e in sources:
            cols[f"{e.name}.work_J"] = np.zeros(len(t_out))
        for e in lossy:
            cols[f"{e.name}.dissipated_J"] = np.zeros(len(t_out))
        seg = 0
        for k, tk in enumerate(t_out):
            while seg < len(segments) - 1 and tk > segments[seg][1]:
                seg += 1
            t0, t1, dense, md = segments[seg]
            yk = dense(min(max(tk, t0), t1))
            for i, nm in enumerate(net.names):
                cols[f"{nm}.w_rad_s"][k] = yk[i]
                cols[f"{nm}.phi_rad"][k] = yk[n + i]
            _, out = net.solve(tk, yk[:2 * n], md)
            for el in net.elements:
                if el.kind == "torque":
                    continue
                tau = out[el.name]["tau"]
                # clutchlab reports a gear's torque ON flange a (the inertia there receives -tau_a)
                cols[f"{el.name}.tau_Nm"][k] = -tau if el.kind in ("gear", "lossy_gear", "planetary") else tau
                if el.kind == "lossy_gear":
                    cols[f"{el.name}.mode_1"][k] = MODE_CODE[md[el.name]]
            for j, e in enumerate(sources):
                cols[f"{e.name}.work_J"][k] = yk[2 * n + j]
            for j, e in enumerate(lossy):
                cols[f"{e.name}.dissipated_J"][k] = yk[2 * n + len(sources) + j]
        self.columns = cols
        self.breaks = sorted({s[1] for s in segments})
