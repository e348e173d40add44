#!/usr/bin/env python
"""Independent SciPy reference of the E-clutch's clutch alone with friction (bearing motion prescribed).

Model (docs/eclutch_dynamics.md Sec. 2, [1] Figs. 5b, 11; friction law and state machine of Sec. 2
"Friction elements and the stick-slip state machine"):

    element deflections     d_e = d0_e + Gb_e u(t) + sum_j GA_ej q_j
    element forces          f_e = scale_e F_e(d_e)   (F_e: linear or cubic Hermite curve, linear continuation
                                                      outside the samples); a unilateral element: max(f_e, 0)
    generalised forces      F_j = -sum_e GA_ej f_e
    massive coordinates     m_j dv_j/dt = F_j + F_f,j,   dq_j/dt = v_j
    massless coordinates    0 = F_j                      (Newton inside the right-hand side)
    friction                F_c = F_c0 + mu_n |f_normal|,  static limit r_s F_c,  viscous c v
        slipping (s = +-1)  F_f = -s F_c - c v;          event v = 0 -> stick if |F_j| <= r_s F_c, else s = sign F_j
        stuck               v = 0, dv/dt = 0;            event r_s F_c - |F_j| = 0 -> slip with s = sign F_j
    outputs                 F_b = sum_e Gb_e f_e (bearing force of the clutch), F_n = f_(normal element),
                            the node positions q

Only parameter values are taken from clutchlab (the network's linear maps GA, Gb, d0, its element curves,
masses and the friction placement, read from ``ClutchDynamics(...).assembly``) and the initial equilibrium
(``Assembly.initial_state``, a static solve at u(0) with friction off).  The curve law, the forces, the
Newton solve of massless nodes, the friction law and the stick/slip/reversal logic are written here in plain
Python; the integration is ``scipy.integrate.solve_ivp`` (DOP853 by default, rtol 1e-10, atol 1e-13 m and
1e-10 m/s), restarted at every stick, break-away and slip reversal (terminal events located by SciPy on its
dense output) and at every corner of the input table.  Contact changes of unilateral elements and curve
knots are not located (the step control resolves them; the scenarios of the tests have none of the former).

Usage::

    from dynamics_friction_scipy import reference
    r = reference(ClutchModel.preset(0), FrictionParameters(), ([0, .1, .2], [0, 2e-4, 0]), grid)
    r["bearing_force_N"], r["normal_force_N"], r["x"]["pp"], r["events"]
"""

from __future__ import annotations

import bisect
import math
import time as _time

import numpy as np
from scipy.integrate import solve_ivp

STUCK = 0


def _curve(xs, fs, ds, kind, x):
    """Force and slope of a characteristic: linear (kind 0) or cubic Hermite (kind 1), linear outside."""
    n = len(xs)
    if x <= xs[0]:
        s = (fs[1] - fs[0]) / (xs[1] - xs[0]) if kind == 0 else ds[0]
        return fs[0] + s * (x - xs[0]), s
    if x >= xs[-1]:
        s = (fs[-1] - fs[-2]) / (xs[-1] - xs[-2]) if kind == 0 else ds[-1]
        return fs[-1] + s * (x - xs[-1]), s
    lo = bisect.bisect_right(xs, x) - 1
    lo = min(max(lo, 0), n - 2)
    hi = lo + 1
    h = xs[hi] - xs[lo]
    if kind == 0:
        s = (fs[hi] - fs[lo]) / h
        return fs[lo] + s * (x - xs[lo]), s
    t = (x - xs[lo]) / h
    t2, t3 = t * t, t * t * t
    val = ((2 * t3 - 3 * t2 + 1) * fs[lo] + (t3 - 2 * t2 + t) * h * ds[lo] + (-2 * t3 + 3 * t2) * fs[hi]
           + (t3 - t2) * h * ds[hi])
    der = ((6 * t2 - 6 * t) / h * (fs[lo] - fs[hi]) + (3 * t2 - 4 * t + 1) * ds[lo] + (3 * t2 - 2 * t) * ds[hi])
    return val, der


class ClutchAlone:
    """The clutch's axial network with friction, bearing position prescribed, in plain Python."""

    def __init__(self, model, friction, table):
        from clutchlab.eclutch import ClutchDynamics  # parameter values only

        s = ClutchDynamics(model, friction).assembly
        self.node_names = list(s.asm["independent"])
        self.GA = np.asarray(s.asm["GA"], dtype=float)
        self.Gb = np.asarray(s.asm["Gb"], dtype=float)
        self.d0 = np.asarray(s.asm["d0"], dtype=float)
        self.curves = []
        for e in range(len(s.element_names)):
            lo, hi = s.offsets[e], s.offsets[e + 1]
            self.curves.append((s.cx[lo:hi].tolist(), s.cf[lo:hi].tolist(), s.cd[lo:hi].tolist(), int(s.kinds[e]),
                                float(s.scale[e]), bool(s.unilateral[e])))
        nz = s.nz
        self.nq = nz - 2
        self.mass = [float(s.mass[2 + i]) for i in range(self.nq)]
        self.massive = [i for i in range(self.nq) if self.mass[i] > 0.0]
        self.massless = [i for i in range(self.nq) if self.mass[i] == 0.0]
        self.fric = {}
        for i in range(self.nq):
            j = 2 + i
            if s.fr_on[j]:
                self.fric[i] = (float(s.fr_c0[j]), float(s.fr_mun[j]), int(s.fr_nidx[j]), float(s.fr_rs[j]))
        self.visc = [float(s.fr_c[2 + i]) for i in range(self.nq)]
        self.normal_element = int(s.normal_element)
        self.tin = [float(t) for t in table[0]]
        self.vin = [float(v) for v in table[1]]
        y0, _modes = s.initial_state(self.vin[0])
        self.q0 = [float(y0[2 + i]) for i in range(self.nq)]
        self.q_guess = list(self.q0)

    # ------------------------------------------------------------------ equations
    def u(self, t):
        """The prescribed bearing position [m]: linear between the table's points, held outside."""
        return float(np.interp(t, self.tin, self.vin))

    def element_forces(self, u, q):
        d = self.d0 + self.Gb * u + self.GA @ np.asarray(q)
        f = np.empty(len(d))
        k = np.empty(len(d))
        for e, (xs, fs, ds, kind, scale, uni) in enumerate(self.curves):
            fe, ke = _curve(xs, fs, ds, kind, d[e])
            fe, ke = scale * fe, scale * ke
            if uni and fe <= 0.0:
                fe, ke = 0.0, 0.0
            f[e], k[e] = fe, ke
        return f, k

    def solve_massless(self, u, q):
        """Newton on the massless coordinates, 0 = -(GA^T f)_j (to 1e-9 N)."""
        if not self.massless:
            return q
        idx = self.massless
        for _ in range(60):
            f, k = self.element_forces(u, q)
            r = -(self.GA[:, idx].T @ f)
            if np.max(np.abs(r)) < 1e-9:
                break
            J = -(self.GA[:, idx].T * k) @ self.GA[:, idx]
            dq = np.linalg.solve(J, r)
            for a, i in enumerate(idx):
                q[i] -= dq[a]
        return q

    def forces(self, t, y):
        """Element forces and generalised forces F_j at the ODE state y = (q_massive, v_massive)."""
        m = len(self.massive)
        q = list(self.q_guess)
        for a, i in enumerate(self.massive):
            q[i] = y[a]
        u = self.u(t)
        q = self.solve_massless(u, q)
        self.q_guess = q
        f, _k = self.element_forces(u, q)
        F = -(self.GA.T @ f)
        return q, f, F, y[m:]

    def level(self, i, f):
        c0, mun, nidx, _rs = self.fric[i]
        return c0 + (mun * abs(f[nidx]) if nidx >= 0 else 0.0)

    def rhs(self, t, y, modes):
        q, f, F, v = self.forces(t, y)
        m = len(self.massive)
        dy = np.zeros(2 * m)
        for a, i in enumerate(self.massive):
            if i in self.fric and modes[i] == STUCK:
                continue
            ff = -self.visc[i] * v[a]
            if i in self.fric:
                ff -= modes[i] * self.level(i, f)
            dy[a] = v[a]
            dy[m + a] = (F[i] + ff) / self.mass[i]
        return dy

    def switching(self, t, y, modes, i):
        a = self.massive.index(i)
        if modes[i] == STUCK:
            _q, f, F, _v = self.forces(t, y)
            return self.fric[i][3] * self.level(i, f) - abs(F[i])
        return y[len(self.massive) + a]

    def outputs(self, t, y):
        q, f, _F, _v = self.forces(t, y)
        return float(self.Gb @ f), float(f[self.normal_element]), q


def reference(model, friction, table, grid, *, method="DOP853", rtol=1e-10, atol_x=1e-13, atol_v=1e-10,
              max_events=200_000):
    """Integrate the clutch alone with friction; outputs on ``grid`` (times in [table start, table end]).

    Returns a dict: ``bearing_force_N``, ``normal_force_N`` (arrays on ``grid``), ``x`` (node name -> array),
    ``events`` (list of (time, kind, node)), ``n_rhs``, ``seconds``.
    """
    c = ClutchAlone(model, friction, table)
    grid = np.asarray(grid, dtype=float)
    m = len(c.massive)
    modes = {i: STUCK for i in c.fric}  # at rest, as clutchlab starts (Assembly.initial_state)
    y = np.array([c.q0[i] for i in c.massive] + [0.0] * m)
    atol = np.array([atol_x] * m + [atol_v] * m)
    t0 = c.tin[0]
    t_end = c.tin[-1]
    breaks = [b for b in c.tin if t0 < b < t_end] + [t_end]
    segments = []  # (t_start, t_end, dense solution, modes)
    events = []
    n_rhs = 0
    start = _time.perf_counter()

    def consistent(t, y):
        """Modes consistent with the forces at a restart: a stuck coordinate beyond its limit breaks away."""
        changed = True
        while changed:
            changed = False
            _q, f, F, _v = c.forces(t, y)
            for i in c.fric:
                if modes[i] == STUCK and abs(F[i]) > c.fric[i][3] * c.level(i, f):
                    modes[i] = 1 if F[i] > 0 else -1
                    events.append((t, "breakaway", c.node_names[i]))
                    changed = True

    consistent(t0, y)
    for t_stop in breaks:
        while t0 < t_stop:
            frozen = dict(modes)
            evs = []
            for i in c.fric:
                def ev(t, yy, i=i):
                    return c.switching(t, yy, frozen, i)
                ev.terminal = True
                ev.direction = -1.0 if frozen[i] == STUCK else -float(frozen[i])
                evs.append((i, ev))
            sol = solve_ivp(lambda t, yy: c.rhs(t, yy, frozen), (t0, t_stop), y, method=method, rtol=rtol,
                            atol=atol, events=[e for _i, e in evs] or None, dense_output=True)
            if sol.status < 0:
                raise RuntimeError(f"solve_ivp failed at t = {sol.t[-1]}: {sol.message}")
            n_rhs += sol.nfev
            t1 = float(sol.t[-1])
            y = sol.y[:, -1].copy()
            segments.append((t0, t1, sol.sol, frozen))
            if sol.status == 1:
                # the earliest terminal event ends the segment: apply the state machine there
                hit = [(float(te[0]), k) for k, te in enumerate(sol.t_events) if len(te)]
                t1, k = min(hit)
                i = evs[k][0]
                a = c.massive.index(i)
                _q, f, F, _v = c.forces(t1, y)
                if frozen[i] == STUCK:
                    modes[i] = 1 if F[i] > 0 else -1
                    events.append((t1, "breakaway", c.node_names[i]))
                else:
                    y[m + a] = 0.0
                    if abs(F[i]) <= c.fric[i][3] * c.level(i, f):
                        modes[i] = STUCK
                        events.append((t1, "stick", c.node_names[i]))
                    else:
                        modes[i] = 1 if F[i] > 0 else -1
                        events.append((t1, "slip_reversal", c.node_names[i]))
                consistent(t1, y)
                if len(events) > max_events:
                    raise RuntimeError("too many events")
            t0 = t1
    # outputs on the grid, from the segment that holds each time (the later one at an event)
    fb = np.full(grid.shape, np.nan)
    fn = np.full(grid.shape, np.nan)
    xs = {name: np.full(grid.shape, np.nan) for name in c.node_names}
    starts = [sg[0] for sg in segments]
    c.q_guess = list(c.q0)
    for g, t in enumerate(grid):
        k = max(bisect.bisect_right(starts, t) - 1, 0)
        _ta, _tb, dense, _modes = segments[k]
        yy = dense(t)
        fb[g], fn[g], q = c.outputs(t, yy)
        for i, name in enumerate(c.node_names):
            xs[name][g] = q[i]
    return {"bearing_force_N": fb, "normal_force_N": fn, "x": xs, "events": events, "n_rhs": n_rhs,
            "seconds": _time.perf_counter() - start, "segments": len(segments)}


if __name__ == "__main__":
    from clutchlab.eclutch import ClutchModel, FrictionParameters

    table = ([0.0, 0.1, 0.2], [0.0, 2e-4, 0.0])
    r = reference(ClutchModel.preset(0), FrictionParameters(), table, np.linspace(0.0, 0.2, 2001))
    kinds = {}
    for _t, kind, _n in r["events"]:
        kinds[kind] = kinds.get(kind, 0) + 1
    print(f"{len(r['events'])} events {kinds}, {r['n_rhs']} rhs, {r['seconds']:.1f} s, "
          f"peak F_b {np.max(np.abs(r['bearing_force_N'])):.1f} N")
