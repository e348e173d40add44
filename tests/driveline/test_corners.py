"""The corners of a law over the speed are waypoints: a friction table's rows, a bearing friction table's, a loss
table's speed rows, an engine map's speed and throttle nodes and its idle controller's clip (issue #30, "accuracy that
follows the tolerance").

A table is linear between its rows, so its slope jumps at each row, and the law's torque with it.  A step that spans
such a corner is a step of a right-hand side that is not smooth, where the error estimate no longer bounds the error:
until the sixty-second session the error against the reference engine (``msl/reference.py``: MSL's equations written
again, DOP853 at rtol 1e-12) did not follow the tolerance there (below, "before").  Each corner now has a waypoint
(``kernel.friction_row``, ``kernel.gear_row``, ``kernel.engine_corners``: zero at each corner, of alternating sign, so
a step ends just past it), as a torque converter's corners have since the sixtieth session (``test_converter.py``).
The engine's reference is a piecewise SciPy solution of its equations written again (:func:`_piecewise_solution`).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples, pinned

from clutchlab.driveline import Driveline, Signal
from clutchlab.driveline import kernel as K

from .msl import reference as R
from .msl.translate import kinematics_hold, to_reference


def _clutch_table():
    """A clutch sliding from 20 rad/s to lock-up across three inner rows of its table (at 12, 7 and 3 rad/s), then
    held stuck by a spring to the ground."""
    d = Driveline("a clutch table")
    d.inertia("J0", 1.0, w0=20.0).inertia("J1", 2.0, w0=0.0)
    d.clutch("c", "J0", "J1", fn_max=100.0, mu=[[0.0, 0.3], [3.0, 0.5], [7.0, 0.25], [12.0, 0.4], [30.0, 0.45]])
    d.spring_damper("k", "J1", "ground", c=5.0, d=0.3)
    return d, ["J0.w_rad_s", "J1.w_rad_s"]


def _bearing_table():
    """An inertia under a sine against a bearing friction table: it breaks away, slides both ways across the rows at
    2 and 5 rad/s and sticks, again and again."""
    d = Driveline("a bearing friction table")
    d.inertia("J0", 0.5, w0=0.0)
    d.torque("src", "J0", Signal.sine(amplitude=20.0, frequency=0.7))
    d.bearing_friction("bf", "J0", torque=[[0.0, 2.0], [2.0, 3.0], [5.0, 1.0], [10.0, 4.0]])
    return d, ["J0.w_rad_s"]


def _loss_table():
    """A lossy gear driven from rest, rolling across its loss table's rows at 5 and 12 rad/s of |w_a|."""
    d = Driveline("a loss table")
    d.inertia("J0", 0.5, w0=0.0).inertia("J1", 2.0, w0=0.0)
    d.torque("src", "J0", 8.0)
    d.gear("g", "J0", "J1", 2.0, loss_table=[[0.0, 0.9, 0.8, 0.1, 0.1], [5.0, 0.6, 0.6, 0.3, 0.3],
                                             [12.0, 0.95, 0.9, 0.0, 0.0], [20.0, 0.7, 0.7, 0.5, 0.5]])
    d.spring_damper("k", "J1", "ground", c=0.0, d=0.5)
    return d, ["J0.w_rad_s", "J1.w_rad_s"]


@pytest.mark.parametrize("build, factor", [(_clutch_table, 10.0), (_bearing_table, 10.0), (_loss_table, 1.0)],
                         ids=["clutch", "bearing", "gear"])
def test_a_step_ends_at_each_row_of_a_table_so_the_error_follows_the_tolerance(build, factor):
    """The largest error over 1,001 samples in 2 s, in units of the speeds' range, against the reference engine, is
    within ``factor`` rtol at rtol 1e-7 and 1e-9 (10 for the friction tables, whose elements slide to lock-up and
    break away again; 1 for the rolling gear).  Measured (sixty-second session) before / now:

    ========  ============================  ============================
    network   rtol 1e-7                     rtol 1e-9
    ========  ============================  ============================
    clutch    3.2e-6 / 1.2e-7               2.9e-8 / 1.9e-9
    bearing   1.0e-5 / 1.1e-7               4.0e-8 / 1.9e-9
    gear      4.8e-7 / 3.5e-9               1.5e-9 / 3.5e-11
    ========  ============================  ============================
    """
    d, cols = build()
    times = np.linspace(0.0, 2.0, 1001)
    ref = to_reference(d).simulate(2.0, times, max_step=1e-4)
    want = np.column_stack([ref.columns[c] for c in cols])
    span = max(1.0, float(np.max(np.ptp(want, axis=0))))
    err = {}
    for rtol in (1e-7, 1e-9):
        got = d.simulate(2.0, rtol=rtol, sample_times=times).to_dataframe()[cols].to_numpy()
        err[rtol] = float(np.max(np.abs(got - want))) / span
    assert err[1e-7] <= factor * 1e-7 and err[1e-9] <= factor * 1e-9, err


def _corners_of_friction_table(rows):
    """The speeds where a friction table's sliding torque has a corner, from docs/driveline.md ("Friction tables"):
    the first row where it is above 0 (held below it), the inner rows, and where the extrapolation beyond the last two
    rows reaches 0 (held there)."""
    xs = [r[0] for r in rows]
    ys = [r[1] for r in rows]
    out = ([xs[0]] if xs[0] > 0.0 else []) + xs[1:-1]
    if ys[-1] < ys[-2]:
        out.append(xs[-1] + ys[-1] * (xs[-1] - xs[-2]) / (ys[-2] - ys[-1]))
    return out


@st.composite
def _friction_tables(draw, from_zero=True):
    """Rows ``[w, value]``: from ``w = 0`` (a friction table must start there), or (``from_zero`` False, a loss
    table's speed rows) maybe above it."""
    n = draw(st.integers(2, 6))
    gaps = draw(st.lists(st.floats(0.05, 20.0), min_size=n, max_size=n))
    first = 0.0 if from_zero else draw(st.sampled_from([0.0, 1.0])) * gaps[0]
    xs = list(first + np.cumsum([0.0] + gaps[1:]))
    ys = draw(st.lists(st.floats(0.0, 1.0), min_size=n, max_size=n))
    return [[float(x), float(y)] for x, y in zip(xs, ys)]


def _check_waypoint(f, corners, top):
    """``f`` changes sign at each corner and keeps it between two (and from 0 to the first, beyond the last); within
    1e-9 of zero at a corner; bounded by 1."""
    ring = [0.0] + corners + [top]
    for a, b in zip(ring, ring[1:]):
        inner = [f(a + q * (b - a)) for q in (0.01, 0.25, 0.5, 0.75, 0.99)]
        assert all(v > 0 for v in inner) or all(v < 0 for v in inner), (a, b, inner)
        assert all(abs(v) <= 1.0 for v in inner)
    for c, (a, b) in zip(corners, zip(ring, ring[2:])):
        eps = 1e-6 * min(c - a, b - c)
        assert f(c - eps) * f(c + eps) < 0, c
        assert abs(f(c)) <= 1e-9, (c, f(c))


@settings(max_examples=examples(40), deadline=None)
@given(rows=_friction_tables())
def test_a_friction_tables_waypoint_passes_zero_at_every_corner_and_nowhere_else(rows):
    """``kernel.friction_row`` over ``|w_rel|`` for a drawn table (a clutch's ``mu``, the last two rows rising or
    falling) against the corners written from the table's own rule (:func:`_corners_of_friction_table`);
    a table of no corner (a constant, two rows from 0 rising) is 1 everywhere."""
    corners = _corners_of_friction_table(rows)
    assume(all(b - a > 1e-6 for a, b in zip([0.0] + corners, corners)))
    d = Driveline("table").inertia("J0", 1.0).clutch("c", "J0", "ground", fn_max=10.0, mu=rows)
    p = d.pack()
    r = int(p.fric[0])

    def f(s):
        return K.friction_row(p, r, s)

    top = 2.0 * (corners[-1] if corners else rows[-1][0]) + 1.0
    if not corners:
        assert all(f(s) == 1.0 for s in np.linspace(0.0, top, 7))
        return
    _check_waypoint(f, corners, top)


@settings(max_examples=examples(20), deadline=None)
@given(rows=_friction_tables(from_zero=False))
def test_a_loss_tables_waypoint_passes_zero_at_every_speed_row_and_nowhere_else(rows):
    """``kernel.gear_row`` over ``|w_a|`` for a drawn loss table's speed rows: a corner at its first row where it is
    above 0 and at each inner row (the law beyond the last row is the extrapolation of the last two)."""
    xs = [r[0] for r in rows]
    corners = ([xs[0]] if xs[0] > 0.0 else []) + xs[1:-1]
    table = [[x, 0.9, 0.8, 0.1, 0.2] for x in xs]
    d = Driveline("loss").inertia("J0", 1.0).inertia("J1", 1.0).gear("g", "J0", "J1", 2.0, loss_table=table)
    p = d.pack()
    r = int(p.lossy[0])

    def f(s):
        return K.gear_row(p, r, s)

    if not corners:
        assert all(f(s) == 1.0 for s in np.linspace(0.0, 2.0 * xs[-1] + 1.0, 7))
        return
    _check_waypoint(f, corners, 2.0 * corners[-1] + 1.0)


def test_the_rows_are_waypoints_that_change_no_mode():
    """The clutch of :func:`_clutch_table` crosses its rows at 12, 7 and 3 rad/s of slip and only locks up: its one
    event is ``stick``, and a step ends just past each row (the core locates a waypoint to 1 % of its step: the slip
    at a step's end, every accepted step recorded, within 0.002 rad/s below each, 1e-4 of its range; measured 5.8e-4,
    1.5e-4 and 3.0e-4 rad/s.  Before, the nearest step end below 12 rad/s was 0.021 rad/s away, by chance)."""
    d, _cols = _clutch_table()
    r = d.simulate(1.0, rtol=1e-8)
    ev = r.events
    assert list(ev["event"]) == ["stick"] and list(ev["element"]) == ["c"]
    df = r.to_dataframe()
    slip = (df["J0.w_rad_s"] - df["J1.w_rad_s"]).to_numpy()
    for row in (12.0, 7.0, 3.0):
        below = row - slip
        assert np.any((below >= 0.0) & (below <= 0.002)), (row, np.sort(np.abs(below))[:3])


def test_a_friction_maps_waypoint_passes_zero_at_its_speed_nodes():
    """A brake reading a friction map ``mu(v, T)`` (:class:`clutchlab.wet.friction.FrictionMap`, bilinear, held
    beyond its nodes) at radius 0.1 m: ``kernel.friction_row`` passes zero at each slip-velocity node over the radius
    (held below the first, 0.5 m/s, and beyond the last), and nowhere else."""
    from clutchlab.wet.friction import FrictionMap

    v = [0.5, 2.0, 6.0, 20.0]
    values = np.array([[0.12, 0.14, 0.11, 0.13], [0.10, 0.12, 0.10, 0.12]])
    d = (Driveline("map").inertia("J", 0.5, w0=100.0)
         .brake("brake", "J", fn_max=200.0, mu=FrictionMap(v, [40.0, 120.0], values), radius=0.1, temperature=80.0))
    p = d.pack()
    r = int(p.fric[0])

    def f(s):
        return K.friction_row(p, r, s)

    _check_waypoint(f, [vi / 0.1 for vi in v], 2.0 * v[-1] / 0.1)


def _rows(draw, lo, hi, n):
    """``n`` rows ``[w, value]`` from w = 0 at random speeds up to about 30 rad/s, the last two rising (a friction
    table the reference compares: its MSL extrapolation never falls below 0)."""
    ws = np.cumsum([0.0] + draw(st.lists(st.floats(1.0, 10.0), min_size=n - 1, max_size=n - 1)))
    vs = draw(st.lists(st.floats(lo, hi), min_size=n, max_size=n))
    vs[-1] = max(vs[-1], vs[-2])
    return [[float(w), float(v)] for w, v in zip(ws, vs)]


@st.composite
def table_networks(draw):
    """A chain of 2-4 inertias (the first at up to 25 rad/s), each link a clutch with a friction table of 3-5 rows (a
    normal force on a sine or held), a loss-table gear of three speed rows (its efficiencies and bearing friction
    flat beyond the second, so that no extrapolation is clamped), or a spring-damper; sine torques; maybe a bearing
    friction table on the first inertia."""
    n = draw(st.integers(2, 4))
    d = Driveline("table network")
    for i in range(n):
        if i == 0:   # (the others at rest, or at the speed their gears give them)
            d.inertia(f"J{i}", J=draw(st.floats(0.05, 2.0)), w0=draw(st.floats(-25.0, 25.0)))
        else:
            d.inertia(f"J{i}", J=draw(st.floats(0.05, 2.0)))
    for i in range(n - 1):
        kind = draw(st.sampled_from(["clutch", "gear", "spring"]))
        a, b = f"J{i}", f"J{i + 1}"
        if kind == "clutch":
            d.clutch(f"c{i}", a, b, fn_max=draw(st.floats(1.0, 100.0)), mu=_rows(draw, 0.05, 0.6, draw(st.integers(3, 5))),
                     peak=draw(st.floats(1.0, 1.5)),
                     normal=draw(st.sampled_from([1.0, Signal.sine(1.0, 1.5, phase=1.0)])))
        elif kind == "gear":
            e1 = draw(st.lists(st.floats(0.5, 1.0), min_size=2, max_size=2))
            e2 = draw(st.lists(st.floats(0.5, 0.999), min_size=2, max_size=2))
            bf = draw(st.lists(st.floats(0.0, 1.0), min_size=2, max_size=2))
            w1 = draw(st.floats(2.0, 12.0))
            d.gear(f"g{i}", a, b, ratio=draw(st.floats(0.5, 3.0)) * draw(st.sampled_from([-1.0, 1.0])),
                   loss_table=[[0.0, e1[0], e2[0], bf[0], bf[0]], [w1, e1[1], e2[1], bf[1], bf[1]],
                               [w1 + 10.0, e1[1], e2[1], bf[1], bf[1]]])
        else:
            d.spring_damper(f"k{i}", a, b, c=draw(st.floats(0.0, 200.0)), d=draw(st.floats(0.05, 2.0)))
    for i in range(n):
        if draw(st.booleans()):
            d.torque(f"T{i}", f"J{i}", Signal.sine(draw(st.floats(1.0, 30.0)), draw(st.floats(0.2, 3.0)),
                                                  phase=draw(st.floats(0.0, 6.0))))
    if draw(st.booleans()):
        d.bearing_friction("bf", "J0", torque=_rows(draw, 0.1, 3.0, draw(st.integers(3, 4))))
    return d


@settings(max_examples=examples(6), deadline=None, derandomize=pinned(),
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(table_networks())
def test_random_networks_of_tables_follow_the_reference_and_keep_the_invariants(d):
    """A random network of friction tables, loss tables and a bearing friction table, run with its invariants checked
    (``check_invariants``), has the reference engine's speeds within 1e-6 of their range at rtol 1e-10 (where the
    reference can decide: a statically indeterminate stuck set or a lossy gear without a consistent quadrant ends
    its comparison, as in ``test_reference_networks.py``)."""
    net = to_reference(d)
    assert net is not None and kinematics_hold(net)
    times = np.linspace(0.0, 1.0, 201)
    try:
        ref = net.simulate(1.0, times, max_step=2e-4, partial=True)
    except (R.Indeterminate, np.linalg.LinAlgError):
        assume(False)
    except RuntimeError as exc:
        assume("did not converge" not in str(exc))
        raise
    df = d.simulate(1.0, rtol=1e-10, sample_times=times, check_invariants=True).to_dataframe()
    kept = times <= ref.reached
    assume(kept.sum() > 10)
    cols = [f"{i.name}.w_rad_s" for i in d.inertias]
    span = max(max(np.ptp(ref.columns[c][kept]) for c in cols), 1e-3)
    err = max(np.abs(df[c].to_numpy()[kept] - ref.columns[c][kept]).max() for c in cols) / span
    assert err < 1e-6, (err, d.describe())


def _piecewise_solution(f, y0, t_end, corners, times):
    """An independent solution of ``dy/dt = f(t, y)`` sampled at ``times``: SciPy's DOP853 at rtol 1e-13, ended at
    every zero of a function of ``corners`` (each ``g(t, y)``: a corner of the right-hand side) and started again
    1e-10 s past it, so that no step spans a corner."""
    from scipy.integrate import solve_ivp

    events = []
    for g in corners:
        def ev(t, y, g=g):
            return g(t, y)
        ev.terminal = True
        events.append(ev)
    pieces = []
    t, y = 0.0, np.asarray(y0, dtype=float)
    while t < t_end:
        sol = solve_ivp(f, (t, t_end), y, method="DOP853", rtol=1e-13, atol=1e-12, events=events, dense_output=True)
        pieces.append((t, sol.t[-1], sol.sol))
        t, y = sol.t[-1], sol.y[:, -1]
        if sol.status == 1 and t < t_end:   # (past the corner without looking for events: it is the one just found)
            nudge = solve_ivp(f, (t, min(t_end, t + 1e-10)), y, method="DOP853", rtol=1e-13, atol=1e-12)
            t, y = nudge.t[-1], nudge.y[:, -1]
    out = np.empty((len(times), len(y0)))
    for i, ti in enumerate(times):
        a, b, s = next(q for q in pieces if q[0] <= ti <= q[1] + 1e-12)
        out[i] = s(min(max(ti, a), b))
    return out


def _engine_on_a_curve():
    """An engine on a six-row full-load curve (its throttle at 1), from 80 rad/s against a damper (0.4 N m s):
    ``J dw/dt = T(w) - d w``, its speed crossing the rows at 100, 200, 300 and 400 rad/s."""
    rows = [[0.0, 100.0], [100.0, 160.0], [200.0, 190.0], [300.0, 170.0], [400.0, 120.0], [600.0, 0.0]]
    J, dmp = 0.3, 0.4
    d = (Driveline("engine").inertia("crank", J, w0=80.0).engine("eng", "crank", rows)
         .spring_damper("load", "crank", "ground", c=0.0, d=dmp))
    ws, ts = np.array(rows).T

    def f(t, y):
        return [(np.interp(y[0], ws, ts) - dmp * y[0]) / J]
    corners = [lambda t, y, c=c: y[0] - c for c in ws]
    return d, f, [80.0], corners


def _engine_at_idle():
    """An engine on a map of three throttles (0, 0.4, 1) whose throttle ramps from 0 to 1 in 2 s, with its idle
    controller (80 rad/s, k_p 2, k_i 20, 30 N m at most) against a damper and a load of 40 N m from 0.3 s: the
    controller saturates at 30 N m, then the throttle takes over and it lets go (its clip's edges at 30 and 0 N m),
    the throttle crossing 0.4.  ``J dw/dt = map(w, thr) + T_idle - d w - T_load``, ``dI/dt = k_i e + (k_i/k_p)
    (T_idle - k_p e - I)``, ``e = 80 - w``, ``T_idle = clip(k_p e + I, 0, 30)``."""
    ws = np.array([0.0, 150.0, 400.0])
    th = np.array([0.0, 0.4, 1.0])
    tq = np.array([[-5.0, 40.0, 90.0], [-10.0, 60.0, 150.0], [-20.0, 30.0, 120.0]])
    J, dmp, kp, ki, top = 0.2, 0.05, 2.0, 20.0, 30.0
    d = (Driveline("idle").inertia("crank", J, w0=80.0)
         .engine("eng", "crank", (ws, th, tq), throttle=Signal.ramp(1.0, 2.0, start=0.5), idle_speed=80.0,
                 idle_kp=kp, idle_ki=ki, idle_torque_max=top)
         .spring_damper("load", "crank", "ground", c=0.0, d=dmp)
         .torque("brake", "crank", Signal.step(-40.0, 0.3)))

    def thr(t):
        return min(max((t - 0.5) / 2.0, 0.0), 1.0)

    def tmap(w, u):
        w = min(max(w, ws[0]), ws[-1])
        u = min(max(u, th[0]), th[-1])
        i = min(np.searchsorted(ws, w, side="right") - 1, len(ws) - 2)
        j = min(np.searchsorted(th, u, side="right") - 1, len(th) - 2)
        a = (w - ws[i]) / (ws[i + 1] - ws[i])
        b = (u - th[j]) / (th[j + 1] - th[j])
        return ((1 - a) * ((1 - b) * tq[i, j] + b * tq[i, j + 1]) + a * ((1 - b) * tq[i + 1, j] + b * tq[i + 1, j + 1]))

    def f(t, y):
        w, integral = y
        e = 80.0 - w
        cmd = kp * e + integral
        out = min(max(cmd, 0.0), top)
        load = 40.0 if t >= 0.3 else 0.0
        return [(tmap(w, thr(t)) + out - dmp * w - load) / J, ki * e + (ki / kp) * (out - cmd)]
    corners = ([lambda t, y, c=c: y[0] - c for c in ws] + [lambda t, y, c=c: thr(t) - c for c in (0.4,)]
               + [lambda t, y: kp * (80.0 - y[0]) + y[1], lambda t, y: kp * (80.0 - y[0]) + y[1] - top]
               + [lambda t, y: t - 0.3, lambda t, y: t - 0.5, lambda t, y: t - 2.5])
    # (the idle controller starts at rest at its set speed: I = 0 where w = 80, and the map's drag at throttle 0 is
    # what it holds: its integral from the network's own start, read back from clutchlab's initial state)
    return d, f, None, corners


@pytest.mark.parametrize("build", [_engine_on_a_curve, _engine_at_idle], ids=["curve", "idle"])
def test_an_engines_map_and_idle_clip_are_waypoints_so_the_error_follows_the_tolerance(build):
    """The engine's speed against the independent piecewise solution (:func:`_piecewise_solution`, the engine's
    equations of docs/driveline.md written again) over 3 s, in units of its range, within 10 rtol at rtol 1e-7 and
    1e-9.  Measured (sixty-second session) before / now: the curve 1.0e-5 / 4.3e-8 at 1e-7, 2.0e-7 / 3.5e-9 at 1e-9
    (6.4e-5 / 4.0e-7 at 1e-6); at idle 1.6e-6 / 3.4e-8 and 4.2e-8 / 9.4e-10 (2.4e-5 / 1.9e-7 at 1e-6)."""
    d, f, y0, corners = build()
    if y0 is None:
        x0 = d.initial_state()
        n = len(d.inertias)
        y0 = [float(x0[n]), float(x0[2 * n + len(d.elements)])]
    times = np.linspace(0.0, 3.0, 601)
    want = _piecewise_solution(f, y0, 3.0, corners, times)[:, 0]
    span = float(np.ptp(want))
    err = {}
    for rtol in (1e-7, 1e-9):
        got = d.simulate(3.0, rtol=rtol, sample_times=times).to_dataframe()["crank.w_rad_s"].to_numpy()
        err[rtol] = float(np.max(np.abs(got - want))) / span
    assert err[1e-7] <= 1e-6 and err[1e-9] <= 1e-8, err


def test_a_fade_tables_rows_are_waypoints_so_the_error_follows_the_tolerance():
    """A brake (``cgeo fn mu = 0.1 x 1000 N x 0.4``) stopping an inertia (0.5 kg m^2) from 120 rad/s heats an
    insulated thermal mass (40 J/K) from 20 to 110 degC, its friction fading with that temperature (``mu_temperature``
    rows at 20, 40, 60 and 90 degC): ``J dw/dt = -T0 f(T)``, ``C dT/dt = T0 f(T) w`` until it stops.  Its speed
    against the independent piecewise solution (a corner at each row, the stop) within 10 rtol of its range at rtol
    1e-7 and 1e-9: a step ends at each row (``kernel.friction_temperature_row``, a factor of the element's ``row``
    function).  Measured (sixty-second session) before / now: 2.8e-6 / 1.8e-8 at 1e-7, 3.2e-8 / 2.1e-10 at 1e-9
    (2.4e-5 / 4.7e-7 at 1e-6)."""
    J, C, tq0 = 0.5, 40.0, 0.1 * 1000.0 * 0.4
    fade = [[20.0, 1.0], [40.0, 0.7], [60.0, 0.9], [90.0, 0.5]]
    d = (Driveline("fade").inertia("J", J, w0=120.0)
         .brake("brake", "J", fn_max=1000.0, mu=0.4, cgeo=0.1, mu_temperature=fade)
         .thermal_mass("disc", C, T0=20.0, heat_from=["brake"]))
    ts, fs = np.array(fade).T

    def f(t, y):
        w, temp = y
        if w <= 0.0:
            return [0.0, 0.0]
        tq = tq0 * np.interp(temp, ts, fs)
        return [-tq / J, tq * w / C]
    corners = [lambda t, y, c=c: y[1] - c for c in ts[1:]] + [lambda t, y: y[0]]
    times = np.linspace(0.0, 3.0, 601)
    want = _piecewise_solution(f, [120.0, 20.0], 3.0, corners, times)
    assert abs(want[-1, 0]) <= 1e-9 and want[-1, 1] > 90.0   # (it stops, past every row)
    err = {}
    for rtol in (1e-7, 1e-9):
        df = d.simulate(3.0, rtol=rtol, sample_times=times).to_dataframe()
        err[rtol] = float(np.max(np.abs(df["J.w_rad_s"].to_numpy() - want[:, 0]))) / 120.0
    assert err[1e-7] <= 1e-6 and err[1e-9] <= 1e-8, err


@settings(max_examples=examples(40), deadline=None)
@given(gaps=st.lists(st.floats(0.05, 50.0), min_size=1, max_size=6), first=st.floats(-100.0, 100.0))
def test_a_grids_waypoint_passes_zero_at_every_node_and_nowhere_else(gaps, first):
    """``kernel.grid_waypoint`` (an engine map's speed and throttle nodes, a fade table's and a friction map's
    temperature rows: linear between nodes, held beyond both ends, so every node is a corner) over a signed variable:
    zero at each node, of one sign between two nodes and beyond the ends, alternating; 1 for a grid of one node."""
    nodes = list(first + np.cumsum([0.0] + gaps))
    data = np.array([7.0] + nodes + [7.0])   # (the grid at an offset, between other data)

    def f(s):
        return K.grid_waypoint(data, 1, len(nodes), s)

    span = nodes[-1] - nodes[0]
    ring = [nodes[0] - span - 1.0] + nodes + [nodes[-1] + span + 1.0]
    for a, b in zip(ring, ring[1:]):
        inner = [f(a + q * (b - a)) for q in (0.01, 0.25, 0.5, 0.75, 0.99)]
        assert all(v > 0 for v in inner) or all(v < 0 for v in inner), (a, b, inner)
        assert all(abs(v) <= 1.0 for v in inner)
    for a, c, b in zip(ring, ring[1:-1], ring[2:]):
        eps = 1e-6 * min(c - a, b - c)
        assert f(c - eps) * f(c + eps) < 0, c
        assert abs(f(c)) <= 1e-9
    assert K.grid_waypoint(data, 1, 1, nodes[0] + 1.0) == 1.0


def test_a_gear_leaving_rest_driven_from_flange_b_rolls_as_flange_b_drives():
    """The draw (the draws profile's seed 2 of the random table networks) that found a tie in the reference engine: a
    gear (ratio -1.41) with a loss table whose bearing friction is the same in both quadrants (``tau_bf1 = tau_bf2``,
    so ``tau_bf_a = 0``) between two inertias at rest, a sine on flange b's.  Each time the sine's torque passes the
    bearing friction the gear leaves rest with ``tau_a = 0``, and MSL's ``startForward``'s ``tau_eta >= 0`` picked
    quadrant 1 (flange a drives) in the reference, where flange b drives it: forward, the reference's speeds were 1.8
    times clutchlab's (its acceleration ``r (T - r tau_bf2)/(J_b + r^2 J_a/eta_mf2)`` with ``eta_mf1`` in place of
    ``1/eta_mf2``), while backward both picked the right one (which quadrant the tie took was a rounding: with the
    numbers rounded to two digits both are right).  The reference now decides that tie the way ``tau_eta``
    goes; clutchlab's speeds agree with it to 1e-6 of their range, and its acceleration in the forward phase is
    quadrant 2's closed form."""
    # (the draw's numbers, to the last digit: whether the reference's tie took the wrong quadrant was a rounding)
    r, ja, jb = -1.408553761482606, 1.5365402065424285, 1.1386297173961137
    eta = bf = 0.6583083515657432
    table = [[0.0, eta, eta, bf, bf], [2.0, 0.5, 0.5, 0.0, 0.0], [12.0, 0.5, 0.5, 0.0, 0.0]]
    sine = Signal.sine(1.0, 1.408553761482606, phase=4.983287655362938)
    d = (Driveline("quadrant").inertia("J0", ja).inertia("J1", jb).gear("g0", "J0", "J1", r, loss_table=table)
         .torque("T1", "J1", sine))
    times = np.linspace(0.0, 1.0, 2001)
    ref = to_reference(d).simulate(1.0, times, max_step=2e-4)
    df = d.simulate(1.0, rtol=1e-10, sample_times=times).to_dataframe()
    span = float(np.ptp(ref.columns["J0.w_rad_s"]))
    err = max(float(np.max(np.abs(df[c].to_numpy() - ref.columns[c]))) for c in ("J0.w_rad_s", "J1.w_rad_s"))
    assert err <= 1e-6 * span, (err, span)
    forward = (df["g0.mode_1"].to_numpy() == 1.0) & (df["J0.w_rad_s"].to_numpy() > 0.0)
    assert forward.sum() > 20
    w_a = df["J0.w_rad_s"].to_numpy()
    acc = np.gradient(w_a, times)
    k = np.flatnonzero(forward)[len(np.flatnonzero(forward)) // 4]   # (early in the phase: flange b drives)
    e2 = eta + (0.5 - eta) * w_a[k] / 2.0
    b2 = bf * (1.0 - w_a[k] / 2.0)
    want = r * (sine.value_and_rate(times[k])[0] - r * b2) / (jb + r * r * ja / e2)   # (a_a = r a_b)
    assert acc[k] == pytest.approx(want, rel=1e-4)
