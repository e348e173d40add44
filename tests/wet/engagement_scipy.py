"""An independent solution of the wet-clutch engagement: the equations written out again in Python, solved by SciPy.

Nothing of clutchlab's integrator or compiled model is used: the paper's equations (Shin et al. Eqs. 1-8,
Deur et al.'s squeeze film and piston, ``docs/wet.md``) are written here from the documentation, the
Greenwood-Williamson integral F_3/2 is evaluated exactly (parabolic cylinder function, where the model uses
a cubic-Hermite table accurate to about 1e-7 relative), and ``scipy.integrate.solve_ivp`` (DOP853) runs
piecewise: restarted at every corner of the force and slip-speed references and at every mode change, each
located by a SciPy event:

* the piston leaving its stop (its free speed rising through zero) and reaching it again (x_p falling through 0);
* film contact (h falling through 0);
* lock-up (the slip speed reaching zero: stick if the drive torque is within the static capacity
  ``R_eff N_c mu_f(0, T) F_c``, else the slip reverses) and break-away (the drive torque leaving the capacity).

Both drives: the inertia dynamometer (``motor="free"``, SAE No. 2) and the speed-controlled bench motor (PI with
back-calculation anti-windup, torque limit and power limit).  The drive's torque and power limits and the
heater's thermostat limits are clipped inside the right-hand side here too (at rtol 1e-12 the kinks cost
DOP853 a few rejected steps, not accuracy).

``tests/wet/test_engagement_core.py`` keeps its own events-only version of the free-inertia case (written
first); this module adds the motor and the states on a grid.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import special
from scipy.integrate import solve_ivp

#: states of the reference, in this order
STATES = ("x_p", "actuator_force", "slip_speed", "integral", "temperature", "fluid_temperature",
          "housing_temperature", "friction_work")
X, FA, W, INTEG, T, TF, TH, EF = range(8)


def _f32(t):
    """Greenwood-Williamson integral F_3/2(t) = int_t^inf (s - t)^1.5 phi(s) ds, exactly (Gaussian phi)."""
    return special.gamma(2.5) / math.sqrt(2 * math.pi) * math.exp(-0.25 * t * t) * special.pbdv(-2.5, t)[0]


def _pwl(t, tt, vv):
    return float(np.interp(t, tt, vv))


def solve(scen, clutch, bench, law, t_end=None, grid=(), rtol=1e-12):
    """Solve one engagement; returns ``(events, states)``.

    Parameters
    ----------
    scen : clutchlab.wet.Scenario
        Profiles, drive (``motor``), initial speed and temperatures.
    clutch, bench : WetClutch, Bench
        Parameters (read field by field, as documented in ``docs/wet.md``).
    law : ParametricFriction or FrictionMap
        mu_f = mu0 + mu_t (T - T_ref) + mu_e exp(-|v| / v_s), not below 0; or a two-dimensional friction map,
        bilinear in (|v|, T) between its nodes and held beyond them, read here from its grids and values with
        ``np.interp`` (not the package's kernel).  With a map, every segment also ends where ``|v|`` or ``T``
        reaches a node (the map's slope jumps there), and the run goes on from it.
    t_end : float, optional
        End time [s] (default: the scenario's duration).
    grid : array_like
        Times [s] at which to return the states (from the dense output of the segment holding each).
    rtol : float
        DOP853's relative tolerance (absolute tolerances 1e-3 of it times each state's scale).

    Returns
    -------
    events : list of (float, str)
        ``leave`` (piston off its stop), ``stop``, ``contact``, ``lockup``, ``reversal``, ``breakaway``.
    states : ndarray, shape (len(grid), 8)
        :data:`STATES` at ``grid``.
    """
    t_end = scen.duration if t_end is None else t_end
    is_map = hasattr(law, "speed_grid")
    if is_map:
        gv, gt = np.asarray(law.speed_grid, float), np.asarray(law.temperature_grid, float)
        vals = np.asarray(law.values, float)
        if vals.ndim != 2 or getattr(law, "force_grid", None) is not None and np.size(law.force_grid) > 1:
            raise ValueError("engagement_scipy: a two-dimensional friction map only")
    nc, sig, area, reff = clutch.n_c, clutch.sigma, clutch.friction_area, clutch.r_eff
    mu1, mu2, mu3, mu4 = clutch.viscosity
    coef = 4.0 / 3.0 * clutch.contact_modulus * clutch.asperity_density * math.sqrt(clutch.asperity_radius) * sig**1.5
    ksq = clutch.squeeze_flow_factor * 1.5 * math.pi * (
        clutch.r_outer**4 - clutch.r_inner**4 - (clutch.r_outer**2 - clutch.r_inner**2) ** 2
        / math.log(clutch.r_outer / clutch.r_inner))
    vmax = bench.actuator_speed_max
    free_motor = scen.motor == "free"
    setpoint = scen.setpoint_c
    ft, fv = np.asarray(scen.force_time, float), np.asarray(scen.force_value, float)
    st, sv = np.asarray(scen.speed_time, float), np.asarray(scen.speed_value, float)

    def terms(t, y, mode, at_stop):
        """(dy, free piston speed, drive torque, static capacity) in ``mode`` (+1, -1 sliding; 0 stuck)."""
        x, fa, w, integ, temp, tf, th = y[:7]
        h = (clutch.piston_h0 - x) / nc                                                # [1] Eq. 1
        s = h / sig
        hbar = sig * (0.5 * s * math.erfc(-s / math.sqrt(2)) + math.exp(-0.5 * s * s) / math.sqrt(2 * math.pi))
        muv = mu1 * math.exp(mu2 * temp) + mu3 * math.exp(mu4 * temp)                 # [1] Eq. 7
        fc = area * coef * _f32(s)                                                      # Greenwood-Williamson
        v = reff * w
        v_abs = mode * v if mode else abs(v)
        if is_map:
            row = [float(np.interp(v_abs, gv, vals[j])) for j in range(len(gt))]
            muf = float(np.interp(temp, gt, row))
        else:
            muf = max(law.mu0 + law.mu_t * (temp - law.t_ref) + law.mu_e * math.exp(-v_abs / law.v_s), 0.0)
        cap = reff * nc * muf * fc                                                      # [1] Eq. 4
        if free_motor:
            td, dint = 0.0, 0.0
        else:
            e = _pwl(t, st, sv) - w
            cmd = bench.speed_kp * e + integ
            lim = bench.drive_torque_max
            if abs(w) * lim > bench.motor_power_max:
                lim = bench.motor_power_max / abs(w)
            td = min(max(cmd, -lim), lim)
            dint = bench.speed_ki * e + bench.speed_ki / bench.speed_kp * (td - cmd)
        if mode:
            tau = mode * cap + reff * nc * muv * area * v / hbar                      # [1] Eqs. 3-6
            wdot = (td - tau) / bench.total_inertia
        else:
            tau, wdot = td, 0.0
        pf = tau * w if mode else 0.0
        c_film = ksq * muv / (nc * hbar**3)                                            # Reynolds, N_c in series
        v_free = vmax * math.tanh((fa - clutch.spring_preload - clutch.spring_stiffness * x - fc) / (c_film * vmax))
        q1, q2 = clutch.k1 * (temp - tf), clutch.k2 * (temp - th)
        qh = min(max(bench.heater_gain * (setpoint - tf), 0.0), bench.heater_power_max)
        qfh = bench.fluid_housing_conductance * (tf - th)
        fref = min(_pwl(t, ft, fv), bench.actuator_force_max)
        dy = [0.0 if at_stop else v_free, (fref - fa) / bench.actuator_time_constant, wdot, dint,
              (pf - q1 - q2) / clutch.heat_capacity,                                   # [1] Eq. 8
              (q1 + qh - bench.reservoir_cooling * (tf - bench.ambient_temperature) - qfh)
              / bench.reservoir_heat_capacity,
              (q2 + qfh - bench.housing_cooling * (th - bench.ambient_temperature)) / bench.housing_heat_capacity,
              pf]
        return dy, v_free, td, cap

    y = np.zeros(8)
    y[FA] = _pwl(0.0, ft, fv)
    y[W] = scen.initial_slip_speed
    y[T], y[TF], y[TH] = scen.initial_temperature_c, scen.fluid_temperature_c, scen.housing_temperature_c
    scale = np.array([clutch.piston_h0, 1e4, 100.0, 100.0, 10.0, 10.0, 10.0, 1e3])
    atol = 1e-3 * rtol * scale
    mode = 1 if y[W] > 0 else (-1 if y[W] < 0 else 0)
    at_stop, open_film = True, True
    corners = sorted({float(c) for c in np.concatenate([ft, [] if free_motor else st]) if 0.0 < c < t_end})
    corners.append(t_end)
    events, pieces = [], []
    t = 0.0
    for t_seg in corners:
        while t < t_seg:
            def leave(tt, yy):
                return terms(tt, yy, mode, True)[1]

            def stop(tt, yy):
                return yy[X]

            def contact(tt, yy):
                return clutch.piston_h0 - yy[X]

            def lock(tt, yy):
                return mode * yy[W]

            def breakaway(tt, yy):
                _, _, td, cap = terms(tt, yy, 0, at_stop)
                return abs(td) - cap

            leave.direction, stop.direction, contact.direction, lock.direction, breakaway.direction = 1, -1, -1, -1, 1
            watched = [e for e, on in ((leave, at_stop), (stop, not at_stop), (contact, open_film),
                                       (lock, mode != 0), (breakaway, mode == 0)) if on]
            nodes = []
            if is_map and mode != 0:   # (a map's nodes while sliding; not the one the segment starts on)
                for node in gv:
                    if abs(abs(reff * y[W]) - node) > 1e-12 * (1.0 + node):
                        nodes.append(lambda tt, yy, node=node: abs(reff * yy[W]) - node)
                for node in gt:
                    if abs(y[T] - node) > 1e-12 * (1.0 + abs(node)):
                        nodes.append(lambda tt, yy, node=node: yy[T] - node)
            watched = watched + nodes
            for e in watched:
                e.terminal = True
            sol = solve_ivp(lambda tt, yy: terms(tt, yy, mode, at_stop)[0], (t, t_seg), y, method="DOP853",
                            rtol=rtol, atol=atol, events=watched, dense_output=True, max_step=0.01)
            if sol.status < 0:
                raise RuntimeError(sol.message)
            pieces.append((t, float(sol.t[-1]), sol.sol))
            t, y = float(sol.t[-1]), sol.y[:, -1].copy()
            if sol.status != 1:
                t = t_seg
                continue
            for ev, times in zip(watched, sol.t_events):
                if not (len(times) and times[-1] == t):
                    continue
                if ev in nodes:   # (a node of the map: the segment ends there, nothing changes)
                    continue
                if ev is leave:
                    at_stop = False
                    events.append((t, "leave"))
                elif ev is stop:
                    y[X] = 0.0
                    at_stop = True
                    events.append((t, "stop"))
                elif ev is contact:
                    open_film = False
                    events.append((t, "contact"))
                elif ev is lock:
                    y[W] = 0.0
                    _, _, td, cap = terms(t, y, 0, at_stop)
                    if abs(td) <= cap:
                        mode = 0
                        events.append((t, "lockup"))
                    else:
                        mode = -mode
                        events.append((t, "reversal"))
                else:
                    _, _, td, _ = terms(t, y, 0, at_stop)
                    mode = 1 if td > 0 else -1
                    events.append((t, "breakaway"))
    grid = np.asarray(grid, dtype=float)
    out = np.empty((grid.size, 8))
    starts = np.array([p[0] for p in pieces])
    for i, tg in enumerate(grid):
        k = max(int(np.searchsorted(starts, tg, side="right")) - 1, 0)
        while k + 1 < len(pieces) and tg > pieces[k][1]:
            k += 1
        out[i] = pieces[k][2](tg)
    return events, out
