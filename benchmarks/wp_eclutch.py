"""Work-precision: 1 s of E-clutch dynamics (actuator + Model 4, stick-slip friction on, position control:
release 7 mm and re-engage), issue #14 "Speed at the limit".

Solvers, each over rtol = 1e-3 ... 1e-7 (clutchlab also 1e-8):

* clutchlab: the core run (``clutchlab.system.simulate`` of ``EClutch.as_system``, no outputs) and
  ``EClutch.simulate`` with outputs (as ``bench_eclutch_dynamics.py`` times them); Rodas3.
* SciPy ``solve_ivp`` (Radau, BDF, LSODA) with the plain-Python right-hand side ``PythonEClutch`` of
  ``bench_eclutch_dynamics.py`` (massless tip by Newton inside the right-hand side, friction on terminal
  events with restarts, restarts at the input corners), driven by :func:`run_scipy` (the state machine of
  clutchlab's ``update``/``restart``; see there why not ``bench_eclutch_dynamics.run_reference``).  Each run
  is capped at ``--scipy-cap`` seconds of wall time (default 60 s, ``--quick`` 10 s); a capped run is
  reported as such and has no point.
* the compiled peer (``_peer_eclutch.py``): LSODA of ``numbalsoda`` (ODEPACK, switches to BDF when stiff)
  with a numba ``cfunc`` right-hand side and an ``njit`` driver that locates the friction events.

Absolute tolerances: every solver gets the model's default absolute tolerances (``Assembly.atol``: 0.1 um,
0.1 mm/s, 100 Pa, 1 mA, ...), fixed; only rtol varies (clutchlab's passed as ``atol_scale=1``: since issue #30's
eighteenth-session fix ``EClutch`` scales them with rtol below its default unless told otherwise).  (Scaling atol with rtol makes every solver resolve
the seals' stick-slip micro-motions: clutchlab at rtol 1e-6, atol x 1e-3 takes 106,000 steps and 1,003 events.)
The peer integrates the state scaled by those atol (``w = y / atol``) with LSODA's scalar atol 1.

Error: max |F_b - F_b,ref| over 2001 points of [0, 1] s, relative to the peak of F_b,ref (F_b = p_s A_sl, the
bearing force as the rig measures it).  Reference: SciPy Radau on the plain-Python equations at rtol 1e-9
(default atol; 3-8 s), independent of clutchlab's integrator, event handling and code; the peer at rtol
1e-10 is printed as a cross-check.  The seals' stick-slip (tens to hundreds of located events, more the
tighter the tolerance) makes F_b depend on the event sequence: independent solutions agree to about 1e-3 of
peak, not better, so errors below that measure the agreement with the reference's own method (Radau's points
at rtol <= 1e-6: 3e-4), not accuracy.  clutchlab's and the peer's F_b are read at the grid points (clutchlab:
``output_step`` 0.5 ms; the peer: its sub-grid), SciPy's from its dense output.

Run:  python benchmarks/wp_eclutch.py [--quick] [--scipy-cap SECONDS] [--no-scipy]
"""

from __future__ import annotations

import math
import os
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from _wp import Point, Series, machine, plot, ratio_at_matched_error, row, timed  # noqa: E402
from bench_eclutch_dynamics import INPUT, T_END, PythonEClutch  # noqa: E402

import _peer_eclutch as peer  # noqa: E402
from clutchlab import system as contract  # noqa: E402
from clutchlab.eclutch import ClutchModel, EClutch, FrictionParameters  # noqa: E402
from clutchlab.eclutch.dynamics import _as_table  # noqa: E402

GRID = np.linspace(0.0, T_END, 2001)
REF_RTOL = 1e-9


class _Capped(Exception):
    pass


def run_scipy(ec: EClutch, method: str, rtol: float, cap: float = math.inf):
    """solve_ivp on ``PythonEClutch``: F_b on ``GRID`` (dense output), RHS count, events.

    The state machine is clutchlab's (``update``/``restart`` of ``clutchlab.eclutch.system``): at a slip-end
    event the coordinate sticks if ``r_s F_c >= |F|`` else turns round; at a break-away it slips in the
    direction of its force.  ``bench_eclutch_dynamics.run_reference`` instead sets v = 0 and lets the restart
    check decide, which loops for ever at t = 0.923632 s with friction on (Radau, rtol 1e-3): the edge ring's
    slip-end event fires again at every restart (zero-length segments).
    """
    tin, vin = _as_table(INPUT["bearing_reference"], "bearing_reference")
    py = PythonEClutch(ec, tin, vin)
    s = ec.assembly
    y_full, modes = s.initial_state(ec.rest_position)
    modes = modes.tolist()
    nz = s.nz
    py.q_alg = [y_full[2 + j] for j in range(nz - 2)]
    massive = py.massive
    m = len(massive)
    y = [y_full[j] for j in massive] + [y_full[nz + j] for j in massive] + list(y_full[2 * nz: 2 * nz + 5])
    atol = np.array([s.atol[j] for j in massive] + [s.atol[nz + j] for j in massive]
                    + list(s.atol[2 * nz: 2 * nz + 5]))
    fr_idx = [j for j in range(nz) if s.fr_on[j]]
    rs = py.fr[6]
    breaks = [b for b in tin if 0.0 < b < T_END] + [T_END]
    fb = np.full(GRID.shape, np.nan)
    fb[0] = y[2 * m + 2] * ec.actuator.slave_area
    n_rhs = 0
    n_ev = 0
    deadline = time.perf_counter() + cap

    def fun(t, yy):
        nonlocal n_rhs
        n_rhs += 1
        if n_rhs % 256 == 0 and time.perf_counter() > deadline:
            raise _Capped
        return py.rhs(t, yy, modes)

    t0 = 0.0
    for t_stop in breaks:
        while t0 < t_stop - 1e-12:
            evs = []
            for k, j in enumerate(fr_idx):
                def ev(t, yy, k=k):
                    return py.event_values(t, yy, modes)[k]
                ev.terminal = True
                ev.direction = -1.0 if modes[j] == 2 else -float(np.sign(modes[j]))
                evs.append(ev)
            z, v, Fz, fn, _ = py.forces(t0, y, modes)  # restart: modes consistent with the forces
            for j in fr_idx:
                i = massive.index(j)
                if modes[j] == 2:
                    if abs(Fz[j]) > rs[j] * fn[j]:
                        modes[j] = 1 if Fz[j] > 0 else -1
                        y[m + i] = 0.0
                elif y[m + i] == 0.0:
                    sgn = 1.0 if modes[j] > 0 else -1.0
                    if (Fz[j] - sgn * fn[j]) * sgn < 0.0:
                        modes[j] = 2 if abs(Fz[j]) <= rs[j] * fn[j] else (1 if Fz[j] > 0 else -1)
            try:
                sol = solve_ivp(fun, (t0, t_stop), y, method=method, rtol=rtol, atol=atol, events=evs,
                                dense_output=True)
            except _Capped:
                return None, n_rhs, n_ev
            if sol.status < 0:
                raise RuntimeError(sol.message)
            t1 = float(sol.t[-1])
            sel = (GRID > t0) & (GRID <= t1)
            if sel.any():
                fb[sel] = sol.sol(GRID[sel])[2 * m + 2] * ec.actuator.slave_area
            y = sol.y[:, -1].tolist()
            t0 = t1
            if sol.status == 1:
                z, v, Fz, fn, _ = py.forces(t0, y, modes)
                for k, j in enumerate(fr_idx):
                    if len(sol.t_events[k]):
                        n_ev += 1
                        i = massive.index(j)
                        y[m + i] = 0.0
                        if modes[j] == 2 or rs[j] * fn[j] - abs(Fz[j]) < 0.0:  # break-away or turn round
                            modes[j] = 1 if Fz[j] > 0 else -1
                        else:
                            modes[j] = 2  # stick
            py.q_alg = py.unpack(y)[2]
    return fb, n_rhs, n_ev


def main(quick: bool = False, scipy_cap: float | None = None, with_scipy: bool = True):
    print("Work-precision: E-clutch dynamics, 1 s, position control (release 7 mm, re-engage), Model 4, "
          "friction on")
    print("machine:", machine())
    print(time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()))
    ec = EClutch(clutch=ClutchModel.preset(4), friction=FrictionParameters())
    tin, vin = _as_table(INPUT["bearing_reference"], "bearing_reference")
    rtols = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7]
    cl_rtols = rtols + [1e-8]
    rep_cl = 5 if quick else 11
    rep_peer = 1 if quick else 3
    cap = scipy_cap if scipy_cap is not None else (10.0 if quick else 60.0)

    # reference: SciPy Radau on the Python equations at rtol 1e-9 (atol the defaults)
    t0 = time.perf_counter()
    fb_ref, n_rhs, n_ev = run_scipy(ec, "Radau", REF_RTOL)
    peak = np.abs(fb_ref).max()
    print(f"reference: SciPy Radau (Python RHS) rtol {REF_RTOL:g}, default atol: {time.perf_counter() - t0:.1f} s, "
          f"{n_rhs} RHS, {n_ev} events; peak F_b {peak:.1f} N")
    t0 = time.perf_counter()
    data = peer.pack(ec, tin, vin)
    peer.simulate(ec, tin, vin, T_END, 1e-3, data=data)  # compile the driver
    print(f"peer compiled/loaded in {time.perf_counter() - t0:.1f} s")
    T, FB, n_ev, ok = peer.simulate(ec, tin, vin, T_END, 1e-10, data=data)
    print(f"cross-check: peer at rtol 1e-10 differs from the reference by "
          f"{np.abs(np.interp(GRID, T, FB) - fb_ref).max() / peak:.1e} of peak ({n_ev} events)")

    def err(fb):
        return float(np.abs(fb - fb_ref).max() / peak)

    # clutchlab
    ec.simulate(INPUT, T_END)  # compile / load cache
    core, sim = Series("clutchlab core run (Rodas3)"), Series("clutchlab EClutch.simulate")
    for r in cl_rtols:
        system = ec.as_system(INPUT, rtol=r, atol_scale=1.0)
        n = rep_cl if r >= 1e-7 else max(3, rep_cl // 3)
        tk, out = timed(lambda: contract.simulate(system, T_END, outputs=False, max_steps=2_000_000), n)
        ts, res = timed(lambda: ec.simulate(INPUT, T_END, rtol=r, output_step=GRID[1], max_steps=2_000_000,
                                                 atol_scale=1.0), n)
        e = err(np.interp(GRID, res.outputs_table.time_s, res.outputs_table.bearing_force_N))
        note = f"{out.stats['accepted_steps']} steps, {len(out.events)} events"
        core.points.append(Point(r, e, tk, note))
        sim.points.append(Point(r, e, ts))

    # the compiled peer
    pe = Series("peer: numbalsoda LSODA, numba cfunc")
    for r in rtols:
        tp, (T, FB, n_ev, ok) = timed(lambda: peer.simulate(ec, tin, vin, T_END, r, data=data), rep_peer)
        pe.points.append(Point(r, err(np.interp(GRID, T, FB)), tp, f"{n_ev} events" + ("" if ok else " FAILED")))

    # SciPy
    sci = []
    if with_scipy:
        for method in ("Radau", "BDF", "LSODA"):
            srs = Series(f"SciPy {method}, Python RHS")
            for r in rtols:
                t0 = time.perf_counter()
                fb, n_rhs, n_ev = run_scipy(ec, method, r, cap)
                dt = time.perf_counter() - t0
                if fb is None:
                    print(f"  SciPy {method} rtol {r:.0e}: not finished within {cap:.0f} s ({n_rhs} RHS), "
                          "tighter tolerances skipped", flush=True)
                    break
                srs.points.append(Point(r, err(fb), [dt], f"{n_rhs} RHS, {n_ev} events, 1 run"))
                print(row(srs.label, srs.points[-1], T_END), flush=True)
            sci.append(srs)

    print("\nrows (median of the runs, min-max):")
    for s in [core, sim, pe] + sci:
        for p in s.points:
            print(row(s.label, p, T_END))
    best = Series("best SciPy")
    for s in sci:
        best.points.extend(s.points)
    print("\nclutchlab (core run / EClutch.simulate) at matched error: time of the cheapest point of the other "
          "solver at least as accurate, over clutchlab's")
    for label, other in (("peer", pe), ("best SciPy", best)):
        for cl in (core, sim):
            rs = ratio_at_matched_error(cl, other)
            txt = ", ".join(f"{e:.1e}: " + (f"{q:.0f}x" if q is not None else "never as accurate") for e, q in rs)
            print(f"  vs {label:10s} ({cl.label}): {txt}")
    plot([core, sim, pe] + sci, os.path.join(os.path.dirname(os.path.abspath(__file__)), "wp_eclutch.png"),
         "E-clutch dynamics 1 s, Model 4, friction on", "max |F_b error| / peak F_b (ref: SciPy Radau rtol 1e-9)")


if __name__ == "__main__":
    cap_arg = None
    if "--scipy-cap" in sys.argv:
        cap_arg = float(sys.argv[sys.argv.index("--scipy-cap") + 1])
    main(quick="--quick" in sys.argv, scipy_cap=cap_arg, with_scipy="--no-scipy" not in sys.argv)
