"""The wet clutch's engagement equations (the right-hand side of :mod:`clutchlab.wet.system`) transcribed to plain
Python: the SciPy reference of ``bench_wet.py`` and ``wp_wet.py``, written apart from the compiled model."""

from __future__ import annotations

import bisect
import math

from clutchlab.wet import system as W
from clutchlab.wet.film import gw_table


def make_python_model(clutch, bench, scen, friction):
    """The engagement equations of clutchlab.wet.system (the model's rhs), transcribed to plain Python."""
    c = W.pack_parameters(clutch, bench, scen, friction).constants[0]
    p = {name: c[name].item() for name in c.dtype.names}
    g0, gdt, gv, gd = gw_table()
    gv = gv.tolist()
    gd = gd.tolist()
    ft, fv = scen.force_time.tolist(), scen.force_value.tolist()
    st, sv = scen.speed_time.tolist(), scen.speed_value.tolist()
    law = friction

    def pwl(t, tt, vv):
        if t <= tt[0]:
            return vv[0]
        if t >= tt[-1]:
            return vv[-1]
        i = bisect.bisect_right(tt, t) - 1
        return vv[i] + (t - tt[i]) / (tt[i + 1] - tt[i]) * (vv[i + 1] - vv[i])

    def gw(t):
        x = (t - g0) / gdt
        n = len(gv)
        if x >= n - 1:
            return 0.0
        if x < 0:
            return gv[0] + gd[0] * (t - g0)
        i = int(x)
        th = x - i
        t2, t3 = th * th, th * th * th
        return ((2 * t3 - 3 * t2 + 1) * gv[i] + (t3 - 2 * t2 + th) * gdt * gd[i]
                + (-2 * t3 + 3 * t2) * gv[i + 1] + (t3 - t2) * gdt * gd[i + 1])

    def film(h, s):
        t = h / s
        if t >= -8.0:
            return s * (0.5 * t * math.erfc(-t / math.sqrt(2)) + math.exp(-0.5 * t * t) / math.sqrt(2 * math.pi))
        u = 1 / (t * t)
        return s * math.exp(-0.5 * t * t) / math.sqrt(2 * math.pi) * u * (1 - 3 * u + 15 * u * u - 105 * u**3 + 945 * u**4)

    def terms(t, y, mode):
        nc = p["n_c"]
        x, fa, w, integ, temp, tf, th = y[0], y[1], y[2], y[3], y[4], y[5], y[6]
        h = (p["piston_h0"] - x) / nc
        hbar = film(h, p["sigma"])
        muv = p["mu_v1"] * math.exp(p["mu_v2"] * temp) + p["mu_v3"] * math.exp(p["mu_v4"] * temp)
        fc = p["friction_area"] * p["gw_scale"] * gw(h / p["sigma"])
        v = p["r_eff"] * w
        # |v| as the sliding direction of the mode gives it (clutchlab's model): smooth through v = 0 in a
        # slip mode, so that a step ending past a lock-up sees no kink
        v_abs = v if mode == "slip+" else (-v if mode == "slip-" else abs(v))
        muf = max(law.mu0 + law.mu_t * (temp - law.t_ref) + law.mu_e * math.exp(-v_abs / law.v_s), 0.0)
        cap = p["r_eff"] * nc * muf * fc
        wref = pwl(t, st, sv)
        fref = min(pwl(t, ft, fv), p["actuator_force_max"])
        e = wref - w
        tcmd = p["speed_kp"] * e + integ
        tlim = p["drive_torque_max"]
        if abs(w) * tlim > p["motor_power_max"]:
            tlim = p["motor_power_max"] / abs(w)
        td = min(max(tcmd, -tlim), tlim)
        dint = p["speed_ki"] * e + p["speed_ki"] / p["speed_kp"] * (td - tcmd)
        if mode == "stick":
            tau, wdot, pf = td, 0.0, 0.0
        else:
            sgn = 1.0 if mode == "slip+" else -1.0
            tau = sgn * cap + p["r_eff"] * nc * muv * p["friction_area"] * v / hbar
            wdot = (td - tau) / p["total_inertia"]
            pf = tau * w
        fnet = fa - p["spring_preload"] - p["spring_stiffness"] * x - fc
        csq = p["squeeze_coefficient"] * muv / (nc * hbar**3)
        xdot = p["actuator_speed_max"] * math.tanh(fnet / (csq * p["actuator_speed_max"]))
        if x <= 0 and xdot < 0:
            xdot = 0.0
        qk1 = p["k1"] * (temp - tf)
        qk2 = p["k2"] * (temp - th)
        qh = min(max(p["heater_gain"] * (p["heater_setpoint"] - tf), 0.0), p["heater_power_max"])
        qfh = p["fluid_housing_conductance"] * (tf - th)
        dy = [xdot, (fref - fa) / p["actuator_time_constant"], wdot, dint, (pf - qk1 - qk2) / p["heat_capacity"],
              (qk1 + qh - p["reservoir_cooling"] * (tf - p["ambient_temperature"]) - qfh) / p["reservoir_heat_capacity"],
              (qk2 + qfh - p["housing_cooling"] * (th - p["ambient_temperature"])) / p["housing_heat_capacity"],
              (temp - y[7]) / p["thermistor_time_constant"], pf, qk1, qk2, td * w]
        return dy, td, cap

    return terms
