"""Work-precision of the wet-clutch engagement: clutchlab against SciPy and against a compiled peer (issue #14).

Run: ``python benchmarks/wp_wet.py [--quick] [--no-check]`` (needs the ``bench`` extra: numbalsoda, built with
gfortran).  About 35 s (``--quick``: 15 s), of which about 11 s is the peer's first run (numbalsoda's import
compiles its own drivers, and numba cannot cache the peer's driver, which calls a ctypes function).

Model: the 1 s engagement of ``bench_wet.py`` (protocol (b) on the bench: force rise, speed-controlled slip
ramp-down, the piston leaving its stop, film contact, lock-up, stick), 12 states, samples at 1 kHz.

* clutchlab: the public API, ``simulate_engagement`` with all 18 outputs at the samples (as ``bench_wet.py``
  times it), and the core run alone, ``clutchlab.system.simulate(..., outputs=False)`` on a system built
  beforehand (states at the samples only).  Dormand-Prince 5(4), events on the dense output, steps end on
  the reference profiles' corners, largest step 10 ms.
* SciPy: ``solve_ivp`` with the Python right-hand side of ``_python_wet.py`` (``make_python_model``),
  restarted at the lock-up / break-away events and, like clutchlab and the peer, at the piston leaving
  and reaching its stop (terminal event functions; ``solve_scipy``), largest step 10 ms, ``t_eval`` = the
  samples: RK45, DOP853, LSODA, Radau, BDF.  "Best SciPy" at an error level is the cheapest of these that
  reaches it.
* Compiled peer: numbalsoda's LSODA with a ``numba.cfunc`` right-hand side, driven from ``numba.njit`` code
  that locates the events itself (``_peer_wet.py``: samples checked for sign changes, Illinois refinement
  with short ``lsoda`` calls, restart in the new mode; one ``lsoda`` call spans at most 0.1 s, tuned: a
  single call to the end was 1.5-1.7x slower, 0.05 s and 0.02 s no faster).
* Tolerances: rtol 1e-3 ... 1e-8; absolute tolerances clutchlab's for every solver,
  ``clutchlab.wet.system.absolute_tolerance(clutch, rtol)`` = ``min(rtol, 1e-7)`` times each state's typical
  magnitude (SciPy: that array; the peer integrates the states divided by those magnitudes with the scalar
  ``atol = min(rtol, 1e-7)``, the same thing).
* Error (relative, worst case): ``max_k |w(t_k) - w_ref(t_k)| / w_0 + |t_lock - t_lock,ref| / t_end`` -- the
  slip-speed error over the 1,001 samples relative to the speed range (the initial slip speed, 157 rad/s)
  plus the lock-up time error relative to the run's 1 s.  Reference: SciPy DOP853 at rtol 1e-11 (atol as
  above at 1e-11) with the Python right-hand side -- independent of clutchlab's integrator and of the peer;
  its own error is printed: against DOP853 at rtol 1e-12 and against clutchlab at rtol 1e-10 (measured
  3.7e-10 and 1.6e-10 since issue #14).  The compiled solvers also run at rtol 1e-9 and 1e-10, so that
  both reach the tight error levels.
* All three integrate the same equations: the friction law reads |v| by the slip mode (smooth through zero
  slip within a mode, as clutchlab's model does since issue #14; with |v| itself every solver stepped across
  a kink in the step that ends past the lock-up, and the lock-up error was erratic: 1.2e-6 s at rtol 1e-8).

Times are medians (min-max) of repeated runs after a warm-up run of every solver (compilation, caches);
clutchlab's speed-ups are at matched error: the cheapest run of the other solver(s) that is at least as
accurate (``_wp.ratio_at_matched_error``).  Writes ``benchmarks/wp_wet.png``.
"""

from __future__ import annotations

import argparse
import datetime
import math
import os
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import _peer_wet as peer_mod  # noqa: E402
import _wp  # noqa: E402
from _python_wet import make_python_model  # noqa: E402

from clutchlab.system import simulate  # noqa: E402
from clutchlab.wet import Bench, ParametricFriction, WetClutch, simulate_engagement  # noqa: E402
from clutchlab.wet import system as W  # noqa: E402
from clutchlab.wet.bench import EngagementProtocol  # noqa: E402

RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
QUICK_RTOLS = (1e-3, 1e-5, 1e-7)
#: the compiled solvers (clutchlab and the peer) only, beyond RTOLS: the tight error levels
COMPILED_EXTRA = (1e-9, 1e-10)
SCIPY_METHODS = ("RK45", "DOP853", "LSODA", "Radau", "BDF")
REF_RTOL = 1e-11
MAX_STEP = 0.01
PEER_WINDOW = 0.1
#: a SciPy run slower than this [s] is timed once more only
SLOW = 2.0


def setup():
    clutch = WetClutch.paper()
    bench = Bench()
    truth = ParametricFriction.bench_truth()
    scen = EngagementProtocol(duration=1.0).scenario(clutch, "speed")
    grid = np.arange(int(round(scen.duration * 1000.0)) + 1) / 1000.0
    return clutch, bench, truth, scen, grid


# ---------------------------------------------------------------- SciPy (Python right-hand side)
def solve_scipy(terms, x0, t_end, grid, method, rtol, atol):
    """``bench_wet.solve_reference`` with a choice of method and tolerances, and the piston's stop located
    too: states at ``grid``, lock-up time, right-hand-side evaluations.

    The mode logic of ``solve_reference`` (lock-up, slip reversal, break-away: terminal events, restart),
    plus clutchlab's piston modes: on its stop the piston's rate is zero and the event is the free piston
    speed rising through zero; free, the event is the position falling through zero.  (With only the
    reference's clip of the rate inside the right-hand side, Radau and BDF return a wrong solution: the
    finite-difference Jacobian at t = 0, across the clip, has d(x_p')/dx_p of about -1e9 /s, and their
    simplified Newton iteration, never re-evaluating it, "converges" with the piston left on its stop.)
    """
    y = np.array(x0, dtype=float)
    t = 0.0
    mode = "slip+" if y[2] > 0 else ("slip-" if y[2] < 0 else "stick")
    at_stop = y[0] <= 0.0
    ys = []
    lock = math.nan
    nfev = 0
    while t < t_end - 1e-12:
        def f(tt, yy, mode=mode, at_stop=at_stop):
            dy = terms(tt, yy, mode)[0]
            if at_stop:
                dy[0] = 0.0
            return dy

        if mode == "stick":
            def ev(tt, yy):
                _, td, cap = terms(tt, yy, "stick")
                return abs(td) - cap
            ev.direction = 1
        else:
            sd = 1.0 if mode == "slip+" else -1.0

            def ev(tt, yy, sd=sd):
                return sd * yy[2]
            ev.direction = -1
        ev.terminal = True
        if at_stop:
            def evp(tt, yy, mode=mode):
                # the free piston speed: the reference's rate just off the stop (its clip acts at x_p <= 0)
                y2 = np.array(yy, dtype=float)
                y2[0] = 1e-300
                return terms(tt, y2, mode)[0][0]
            evp.direction = 1
        else:
            def evp(tt, yy):
                return yy[0]
            evp.direction = -1
        evp.terminal = True
        te = grid[(grid >= t) & (grid <= t_end)]
        sol = solve_ivp(f, (t, t_end), y, method=method, rtol=rtol, atol=atol, t_eval=te, events=(ev, evp),
                        max_step=MAX_STEP)
        nfev += sol.nfev
        if sol.status < 0:
            raise RuntimeError(f"solve_ivp {method} rtol {rtol:g}: {sol.message}")
        ys.append(sol.y.T)
        if sol.status == 1:
            k = min((i for i in (0, 1) if sol.t_events[i].size), key=lambda i: sol.t_events[i][0])
            t = float(sol.t_events[k][0])
            y = sol.y_events[k][0].copy()
            if k == 1:
                if at_stop:
                    at_stop = False
                else:
                    y[0] = 0.0
                    y2 = y.copy()
                    y2[0] = 1e-300
                    at_stop = not terms(t, y2, mode)[0][0] > 0.0
            elif mode == "stick":
                _, td, _ = terms(t, y, "stick")
                mode = "slip+" if td > 0 else "slip-"
            else:
                y[2] = 0.0
                _, td, cap = terms(t, y, "stick")
                if abs(td) <= cap:
                    mode = "stick"
                    if math.isnan(lock):
                        lock = t
                else:
                    mode = "slip-" if mode == "slip+" else "slip+"
            t = t + 1e-12
        else:
            t = t_end
    states = np.vstack(ys)
    if states.shape[0] != grid.size:
        raise RuntimeError(f"solve_ivp {method}: {states.shape[0]} samples, expected {grid.size}")
    return states, lock, nfev


# ---------------------------------------------------------------- error
def error_of(w, lock, ref):
    """(error, slip part, lock-up part): the measure of the module docstring."""
    ew = float(np.max(np.abs(w - ref["w"]))) / ref["w_range"]
    et = abs(lock - ref["lock"]) / ref["t_end"] if math.isfinite(lock) else math.inf
    return ew + et, ew, et


def reference(terms, x0, scen, grid, clutch, bench, truth, check=True):
    t0 = time.perf_counter()
    states, lock, nfev = solve_scipy(terms, x0, scen.duration, grid, "DOP853", REF_RTOL,
                                     W.absolute_tolerance(clutch, REF_RTOL))
    ref = {"w": states[:, W.S_W], "lock": lock, "w_range": float(scen.initial_slip_speed),
           "t_end": float(scen.duration)}
    print(f"reference: SciPy DOP853 rtol {REF_RTOL:g}, {nfev} evaluations, {time.perf_counter() - t0:.1f} s; "
          f"lock-up at {lock:.9f} s")
    if check:
        s2, l2, _ = solve_scipy(terms, x0, scen.duration, grid, "DOP853", REF_RTOL / 10,
                                W.absolute_tolerance(clutch, REF_RTOL / 10))
        e2 = error_of(s2[:, W.S_W], l2, ref)[0]
        res = simulate_engagement(clutch, scen, bench=bench, friction=truth, rtol=1e-10, outputs=False)
        e3 = error_of(res.state("slip_speed_rad_s"), res.lockup_time, ref)[0]
        print(f"  its error: {e2:.1e} from DOP853 at rtol {REF_RTOL / 10:g}; {e3:.1e} from clutchlab at rtol 1e-10")
    return ref


# ---------------------------------------------------------------- the solvers
def run_clutchlab_api(clutch, bench, truth, scen, rtols, repeat, ref):
    s = _wp.Series("clutchlab simulate_engagement (all outputs)")
    for rtol in rtols:
        def go():
            return simulate_engagement(clutch, scen, bench=bench, friction=truth, rtol=rtol)
        go()
        times, res = _wp.timed(go, repeat)
        e, ew, et = error_of(res.state("slip_speed_rad_s"), res.lockup_time, ref)
        s.points.append(_wp.Point(rtol, e, times, f"slip {ew:.1e} lock {et:.1e}, {res.n_steps} steps"))
    return s


def run_clutchlab_core(clutch, bench, truth, scen, grid, rtols, repeat, ref):
    s = _wp.Series("clutchlab core run (states only)")
    for rtol in rtols:
        def build():
            return W.engagement_system(scen, clutch=clutch, bench=bench, friction=truth, rtol=rtol)
        simulate(build(), scen.duration, sample_times=grid, outputs=False, max_step=MAX_STEP)
        systems = [build() for _ in range(repeat)]  # fresh per-run buffers (lock-up time) each
        times, res = [], None
        for sysm in systems:
            t0 = time.perf_counter()
            res = simulate(sysm, scen.duration, sample_times=grid, outputs=False, max_step=MAX_STEP)
            times.append(time.perf_counter() - t0)
        lock = W.lockup_time(systems[-1].params)
        e, ew, et = error_of(res.states[:, W.S_W], lock, ref)
        s.points.append(_wp.Point(rtol, e, times, f"slip {ew:.1e} lock {et:.1e}, "
                                                  f"{res.stats['accepted_steps']} steps"))
    return s


def run_scipy(terms, x0, scen, grid, clutch, method, rtols, repeat, ref):
    s = _wp.Series(f"SciPy {method} (Python RHS)")
    for rtol in rtols:
        atol = W.absolute_tolerance(clutch, rtol)

        def go():
            return solve_scipy(terms, x0, scen.duration, grid, method, rtol, atol)
        try:
            t0 = time.perf_counter()
            go()  # warm-up (and a run too slow to repeat much)
            first = time.perf_counter() - t0
            times, (states, lock, nfev) = _wp.timed(go, 1 if first > SLOW else repeat)
        except Exception as exc:  # noqa: BLE001 (a method that fails is reported, not fatal)
            print(f"  SciPy {method} rtol {rtol:g}: failed ({exc})")
            continue
        e, ew, et = error_of(states[:, W.S_W], lock, ref)
        s.points.append(_wp.Point(rtol, e, times, f"slip {ew:.1e} lock {et:.1e}, {nfev} evaluations"))
    return s


def run_peer(clutch, bench, truth, scen, grid, rtols, repeat, ref):
    s = _wp.Series("compiled peer: numbalsoda LSODA + numba RHS")
    t0 = time.perf_counter()
    pr = peer_mod.Peer(clutch, bench, scen, truth, grid=grid)
    pr.solve(1e-6, window=PEER_WINDOW)
    print(f"compiled peer: first run (numbalsoda import and the driver's compilation; the driver calls a "
          f"ctypes function and numba cannot cache it) {time.perf_counter() - t0:.1f} s")
    for rtol in rtols:
        def go():
            return pr.solve(rtol, window=PEER_WINDOW)
        go()
        times, out = _wp.timed(go, repeat)
        lock = pr.lockup_time()
        e, ew, et = error_of(out[:, W.S_W], lock, ref)
        s.points.append(_wp.Point(rtol, e, times, f"slip {ew:.1e} lock {et:.1e}, {int(pr.stats[0])} lsoda calls"))
    return s


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="rtol 1e-3, 1e-5, 1e-7, fewer repeats (under a minute)")
    ap.add_argument("--no-check", action="store_true", help="skip the reference's own error estimate")
    args = ap.parse_args(argv)
    rtols = QUICK_RTOLS if args.quick else RTOLS
    rep_fast, rep_scipy = (5, 1) if args.quick else (21, 5)
    cl_rtols = rtols if args.quick else rtols + COMPILED_EXTRA
    methods = ("RK45", "DOP853", "LSODA", "Radau") if args.quick else SCIPY_METHODS

    t_start = time.perf_counter()
    print(f"machine: {_wp.machine()}")
    print(f"date: {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC; repeats {rep_fast} "
          f"(clutchlab, peer), {rep_scipy} (SciPy; 1 where a run takes over {SLOW:g} s)")
    clutch, bench, truth, scen, grid = setup()
    terms = make_python_model(clutch, bench, scen, truth)
    x0 = W.initial_state(scen)
    t0 = time.perf_counter()
    simulate_engagement(clutch, scen, bench=bench, friction=truth, rtol=1e-6)
    print(f"clutchlab: first run (numba cache load or compilation) {time.perf_counter() - t0:.1f} s")
    ref = reference(terms, x0, scen, grid, clutch, bench, truth, check=not (args.quick or args.no_check))

    series = [run_clutchlab_api(clutch, bench, truth, scen, cl_rtols, rep_fast, ref),
              run_clutchlab_core(clutch, bench, truth, scen, grid, cl_rtols, rep_fast, ref),
              run_peer(clutch, bench, truth, scen, grid, cl_rtols, rep_fast, ref)]
    scipy_series = [run_scipy(terms, x0, scen, grid, clutch, m, rtols, rep_scipy, ref) for m in methods]
    t_end = float(scen.duration)

    print("\nerror = max |slip-speed error| / 157 rad/s + |lock-up time error| / 1 s, against SciPy DOP853 rtol 1e-11")
    short = dict(zip([s.label for s in series], ("clutchlab API", "clutchlab core", "peer (numbalsoda LSODA)")))
    for s in series + scipy_series:
        for p in s.points:
            print(_wp.row(short.get(s.label, s.label.split(" (")[0]), p, t_end))

    best = _wp.Series("best SciPy", [p for s in scipy_series for p in s.points])
    labels = {id(p): s.label.split(" (")[0] for s in scipy_series for p in s.points}
    api, core, peer = series
    print("\nclutchlab's speed-up at matched error (the other's cheapest run at least as accurate):")
    for cl in (api, core):
        print(cl.label)
        r_best = _wp.ratio_at_matched_error(cl, best)
        r_peer = _wp.ratio_at_matched_error(cl, peer)
        for p, (e, rb), (_, rp) in zip(cl.points, r_best, r_peer):
            rb_s = f"{rb:7.1f}x" if rb else "    n/a"
            rp_s = f"{rp:6.2f}x" if rp else "   n/a"
            print(f"  rtol {p.rtol:.0e}  error {e:8.1e}  {p.median * 1e3:7.3f} ms   vs best SciPy {rb_s}   "
                  f"vs compiled peer {rp_s}")

    print("\nat fixed error levels, the cheapest run that reaches each (median ms; n/a: none did):")
    head = ("error <=", "clutchlab API", "clutchlab core", "best SciPy", "compiled peer")
    print(f"  {head[0]:>9s} {head[1]:>14s} {head[2]:>15s} {head[3]:>24s} {head[4]:>14s}")
    for level in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8):
        cells = []
        for s in (api, core, best, peer):
            c = _wp.cheapest_at(s, level)
            c = None if c is None else c[1]
            txt = "n/a" if c is None else f"{c.median * 1e3:.3f}"
            if s is best and c is not None:
                txt += f" ({labels[id(c)]})"
            cells.append(txt)
        print(f"  {level:9.0e} {cells[0]:>14s} {cells[1]:>15s} {cells[2]:>24s} {cells[3]:>14s}")

    print("\nissue #14 at each error level (cheapest run reaching it; ratio = the other's median / clutchlab's):")
    for level in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8):
        c_api, c_core = _wp.cheapest_at(api, level), _wp.cheapest_at(core, level)
        c_peer, c_best = _wp.cheapest_at(peer, level), _wp.cheapest_at(best, level)
        if c_api is None:
            print(f"  {level:7.0e}: clutchlab does not reach it")
            continue
        parts = [f"clutchlab API {c_api[1].median * 1e3:.3f} ms (rtol {c_api[1].rtol:.0e})"]
        if c_peer is not None:
            parts.append(f"peer {c_peer[1].median * 1e3:.3f} ms: API {c_peer[1].median / c_api[1].median:.2f}x faster")
        else:
            parts.append("peer does not reach it")
        if c_best is not None:
            parts.append(f"best SciPy ({labels[id(c_best[1])]}) {c_best[1].median * 1e3:.1f} ms: "
                         f"{c_best[1].median / c_core[1].median:.0f}x the core run, "
                         f"{c_best[1].median / c_api[1].median:.0f}x the API")
        else:
            parts.append("no SciPy method reaches it")
        print(f"  {level:7.0e}: " + "; ".join(parts))

    _wp.plot(series + scipy_series, HERE / "wp_wet.png",
             "wet-clutch engagement, 1 s (protocol b), states at 1 kHz", "error (relative, see wp_wet.py)")
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"load at the end: {load:.2f}; total {time.perf_counter() - t_start:.0f} s")


if __name__ == "__main__":
    main()
