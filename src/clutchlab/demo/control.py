"""Control-design section of ``clutchlab demo``: the E-clutch's position loop designed on its linear models.

The worked design of issue #15 (1), on the bundled E-clutch (Model 4, actuator with seal and spindle
friction), through :mod:`clutchlab.control` only:

1. operating points over the bearing travel (:meth:`clutchlab.eclutch.EClutch.operating_point`, motor
   voltage solved for) and the linear models ``motor_voltage -> bearing_position`` there: Bode diagram
   and pole map (the hydraulic line's resonance, the unstable pole beyond the diaphragm spring's force
   peak);
2. a PI for a 60° phase margin at a 5 Hz crossover, designed at the touch point (where the clamp force
   vanishes) and at every other operating point, scheduled over the measured position;
3. 0.2 mm reference steps of the nonlinear model with the scheduled PI in the loop at 1 kHz
   (:func:`clutchlab.control.loop.closed_loop`), against the linear closed loop's prediction.

and worked design (2), the EMTC's torque tracking on the drum bench with and without the inverse
Preisach feedforward (seed 002, Eqs. 6-7, Fig. 7): the same staircase of torque references, the coupling
slipping throughout, once with the plant's Preisach model inverted by the controller and once with its
hysteresis-free (anhysteretic) characteristic, :meth:`clutchlab.hysteresis.Preisach.anhysteretic`.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pandas as pd

from ..report import Figure, Section, Table, Text

__all__ = ["POSITIONS", "STEP_POSITIONS", "design", "step_runs", "emtc_tracking", "wet_torque_control",
           "demo_section"]

#: wet design: slip speed of the design point [rad/s], torques of the trimmed points [N*m], the design
#: point's torque, crossover [Hz] and phase margin [deg], and the engagement's torque reference
WET_SLIP, WET_TORQUES, WET_DESIGN_TORQUE, WET_CROSSOVER_HZ, WET_MARGIN_DEG = 100.0, (5.0, 10.0, 25.0, 50.0, 100.0), \
    100.0, 8.0, 60.0

#: EMTC torque-reference staircase (times [s], torques [N*m]) and the holds whose last 0.2 s are compared
EMTC_REFERENCE = ((0.0, 0.2, 0.7, 1.2, 1.5, 2.0, 2.2, 2.6, 2.8, 3.2),
                  (0.0, 0.0, 420.0, 420.0, 200.0, 200.0, 350.0, 350.0, 100.0, 100.0))
EMTC_HOLDS = ((1.0, 1.2), (1.8, 2.0), (2.4, 2.6), (3.0, 3.2))

#: operating points of the design and of the schedule [m]
POSITIONS = (1e-3, 2e-3, 3e-3, 4e-3, 5e-3, 6.2e-3, 7e-3, 8e-3)
#: where the steps start [m]
STEP_POSITIONS = (2e-3, 4e-3, 6.2e-3, 8e-3)
#: the design: crossover [Hz], phase margin [deg], controller period [s], step [m]
CROSSOVER_HZ, PHASE_MARGIN_DEG, SAMPLE_TIME, STEP = 5.0, 60.0, 1e-3, 0.2e-3

PROVENANCE = ("Simulated (synthetic) data, not measured: the bundled E-clutch (Model 4 with the default actuator) "
              "trimmed, linearised and run in closed loop by clutchlab.control on the integrator core, the EMTC "
              "on its drum bench with the bundled (synthetic) magnet, and the wet clutch of the paper on its "
              "virtual bench.")


def design(eclutch=None) -> dict:
    """Operating points, linear models and scheduled PI gains over :data:`POSITIONS`.

    Parameters
    ----------
    eclutch : clutchlab.eclutch.EClutch, optional
        Default: the bundled E-clutch.

    Returns
    -------
    dict
        ``points`` (positions [m]), ``ops``, ``models`` (``StateSpace``, motor voltage [V] -> bearing
        position [m]), ``pis`` (:class:`clutchlab.control.design.PI`), ``touch`` (index of the touch point).
    """
    from ..eclutch import EClutch
    from ..control.design import pi_for_phase_margin
    from ..control.linear import linearize

    ec = EClutch() if eclutch is None else eclutch
    ops = [ec.operating_point(x) for x in POSITIONS]
    models = [linearize(op, inputs=["motor_voltage"], outputs=["bearing_position"]) for op in ops]
    pis = [pi_for_phase_margin(g, CROSSOVER_HZ, PHASE_MARGIN_DEG) for g in models]
    return dict(points=np.array(POSITIONS), ops=ops, models=models, pis=pis, touch=POSITIONS.index(6.2e-3))


def step_runs(d: dict, t_end: float = 1.0) -> list[dict]:
    """Reference steps of :data:`STEP` from each of :data:`STEP_POSITIONS`, nonlinear and linear.

    Parameters
    ----------
    d : dict
        From :func:`design`.
    t_end : float
        Length of each run [s].

    Returns
    -------
    list of dict
        Per start: ``position``, ``time_s``, ``nonlinear`` and ``linear`` (normalised responses, 1 = the
        step), overshoots [%], ``settling_s`` (±5 % band; nan if not settled), ``seconds`` (wall time of
        the closed-loop run, in the Python loop).
    """
    import control

    from ..control.design import ScheduledPI
    from ..control.loop import closed_loop

    kp = np.array([p.kp for p in d["pis"]])
    ti = np.array([p.ti for p in d["pis"]])
    out = []
    for x0 in STEP_POSITIONS:
        k = POSITIONS.index(x0)
        op = d["ops"][k]
        lo, hi = op.system.limits["motor_voltage"]
        ctrl = ScheduledPI(d["points"], kp, ti, None, SAMPLE_TIME, lambda t, r=x0 + STEP: r, (lo, hi))
        t = time.perf_counter()
        # compiled=False: the report runs each loop once, and the Python loop's few ms beat the compiled loop's
        # first-use compilation (about 10 s per model; clutchlab.control.loop)
        res = closed_loop(op, ctrl, SAMPLE_TIME, t_end, measure=["bearing_position"], actuate=["motor_voltage"],
                          memory=[op.u[0]], compiled=False)
        seconds = time.perf_counter() - t
        T = res.frame["time_s"].to_numpy()
        y = (res.frame["bearing_position_m"].to_numpy() - x0) / STEP
        cl = control.feedback(control.ss(d["pis"][k].tf()) * d["models"][k], 1)
        lin = np.asarray(control.forced_response(cl, T, np.ones_like(T)).outputs).ravel()
        out.append(dict(position=x0, time_s=T, nonlinear=y, linear=lin, overshoot_nonlinear=100 * (y.max() - 1),
                        overshoot_linear=100 * (lin.max() - 1), settling_nonlinear=_settling(T, y),
                        settling_linear=_settling(T, lin), seconds=seconds, events=len(res.events),
                        saturated=int(res.frame["saturated_1"].sum())))
    return out


def emtc_tracking() -> dict:
    """The EMTC's torque tracking with and without the inverse Preisach feedforward (worked design 2).

    The drum bench (seed 002) with the coupling slipping throughout (drum speed difference 1 m/s,
    throttle 0.3) follows :data:`EMTC_REFERENCE`; the controller inverts either the plant's Preisach model
    (Eqs. 6-7) or its anhysteretic characteristic.

    Returns
    -------
    dict
        ``frames`` (name -> DataFrame of the run), ``holds`` (DataFrame: the mean torque error [N*m] in
        the last 0.2 s of each hold, per controller).
    """
    from ..emtc import simulate_bench
    from ..emtc.bench import BenchScenario
    from ..emtc.magnet import bundled_magnet

    magnet = bundled_magnet()
    scenario = BenchScenario(duration=3.2, speed_difference=1.0, throttle_start=0.3, throttle_end=0.3)
    reference = (np.array(EMTC_REFERENCE[0]), np.array(EMTC_REFERENCE[1]))
    frames, rows = {}, []
    for name, model in (("inverse Preisach", magnet), ("anhysteretic inverse", magnet.anhysteretic())):
        frame = simulate_bench(magnet, scenario, controller_model=model, torque_reference=reference).to_dataframe()
        frames[name] = frame
        t = frame["time_s"].to_numpy()
        err = (frame["coupling_torque_Nm"] - frame["torque_reference_Nm"]).to_numpy()
        for a, b in EMTC_HOLDS:
            sel = (t >= a) & (t <= b)
            rows.append({"controller": name, "hold_from_s": a,
                         "reference_Nm": float(frame["torque_reference_Nm"].to_numpy()[sel].mean()),
                         "torque_error_Nm": float(err[sel].mean()),
                         "min_slip_rad_s": float(np.abs(frame["slip_speed_rad_s"].to_numpy()).min())})
    return {"frames": frames, "holds": pd.DataFrame(rows)}


def _wet_reference(t):
    """Torque reference of the engagement [N*m]: 5 N*m (fill to the kiss point) until 0.3 s, a 50 ms ramp to 100."""
    return 5.0 if t < 0.3 else min(100.0, 5.0 + (t - 0.3) / 0.05 * 95.0)


def wet_torque_control() -> dict:
    """The wet clutch's torque control during an engagement (worked design 3).

    Operating points of the bench slipping at :data:`WET_SLIP` (the drive's speed controller holds the
    slip, the pack temperatures held) at each torque of :data:`WET_TORQUES`: the force each needs is the
    feedforward map (5 N*m: the kiss point, where the fill ends). On the linear model at
    :data:`WET_DESIGN_TORQUE` (force -> measured torque) a PI for :data:`WET_MARGIN_DEG` at
    :data:`WET_CROSSOVER_HZ`. The engagement of the bench protocol (b) (slip ramped from 1500 rpm to 0, no
    force profile: the controller sets the force at 1 kHz) follows :func:`_wet_reference` with the
    feedforward alone, with the PI and conditional integration (only within 10 % of the reference), and
    with the PI integrating always.

    Returns
    -------
    dict
        ``frames`` (name -> closed-loop DataFrame), ``metrics`` (DataFrame: rms and largest torque error
        [N*m] from 0.4 s to 20 ms before lock-up, lock-up time [s]), ``pi`` (the PI), ``feedforward``
        (torques [N*m], forces [N]).
    """
    from ..wet.bench import EngagementProtocol
    from ..wet.engagement import Scenario
    from ..wet.params import WetClutch
    from ..wet.system import engagement_system
    from ..control.design import ScheduledPI, pi_for_phase_margin
    from ..control.linear import linearize
    from ..control.loop import closed_loop
    from ..trim import operating_point

    steady = Scenario(force_time=[0.0, 1.0], force_value=[0.0, 0.0], speed_time=[0.0, 1.0],
                      speed_value=[WET_SLIP, WET_SLIP], duration=5.0, motor="speed", initial_slip_speed=WET_SLIP)
    s = engagement_system(steady)
    temps = {n: float(s.x0[s.state_index(n)]) for n in ("temperature", "fluid_temperature", "housing_temperature",
                                                        "thermistor_temperature")}
    ops, prev = {}, None
    for torque in sorted(WET_TORQUES, reverse=True):  # each point starts from the one above
        start = dict(inputs={"force_reference": 1500.0}, settle=2.0) if prev is None else \
            dict(inputs={"force_reference": prev.u[0]}, guess=prev.x, modes=prev.modes)
        prev = ops[torque] = operating_point(s, states=temps, targets={"clutch_torque": torque},
                                             free_inputs=["force_reference"], t=0.5, **start)
    torques = np.array(sorted(WET_TORQUES))
    forces = np.array([ops[t].u[0] for t in torques])
    G = linearize(ops[WET_DESIGN_TORQUE], inputs=["force_reference"], outputs=["sensor_torque"])
    pi = pi_for_phase_margin(G, WET_CROSSOVER_HZ, WET_MARGIN_DEG)
    protocol = EngagementProtocol().scenario(WetClutch.paper(), "speed")
    engagement = engagement_system(dataclasses.replace(protocol, force_time=np.array([0.0, 1.0]),
                                                       force_value=np.array([0.0, 0.0])))
    frames, rows = {}, []
    ones = np.ones(torques.size)
    for name, kp, band in (("feedforward", 0.0, np.inf), ("feedforward + PI", pi.kp, 0.1),
                           ("feedforward + PI, integrating always", pi.kp, np.inf)):
        ctrl = ScheduledPI(torques, kp * ones, pi.ti * ones, forces, SAMPLE_TIME, _wet_reference, (0.0, 8000.0), band)
        res = closed_loop(engagement, ctrl, SAMPLE_TIME, float(protocol.duration), measure=["sensor_torque"],
                          actuate=["force_reference"], memory=[0.0], reference=_wet_reference, compiled=False)
        frame = res.frame
        lock = res.events.loc[res.events["event"] == "lockup", "time_s"]
        t_lock = float(lock.iloc[0]) if len(lock) else float("nan")
        sel = (frame["time_s"] > 0.4) & (frame["time_s"] < t_lock - 0.02)
        err = (frame["sensor_torque_Nm"] - frame["reference_sensor_torque_Nm"])[sel]
        frames[name] = frame
        rows.append({"controller": name, "rms_error_Nm": float(np.sqrt(np.mean(err ** 2))),
                     "max_error_Nm": float(err.abs().max()), "lockup_s": t_lock})
    return {"frames": frames, "metrics": pd.DataFrame(rows), "pi": pi, "feedforward": (torques, forces)}


def _tracking_figure(frames, reference, tracked, lower, labels, title, ylim=None, lower_ylim=None):
    """Two panels: the tracked signal of each run with the reference, and a second signal of each run.

    ``reference``, ``tracked``: column names; ``lower(frame)`` gives the lower panel's values; ``labels``: the
    two y labels; ``ylim``/``lower_ylim``: optional limits.
    """
    from ..plotting import legend_outside, mark_synthetic, new_figure

    fig, (ax, ax_l) = new_figure(2, 1, width=7.5, height=5.5, sharex=True)
    first = next(iter(frames.values()))
    ax.plot(first["time_s"], first[reference], "k--", label="reference")
    for name, frame in frames.items():
        ax.plot(frame["time_s"], frame[tracked], label=name)
        ax_l.plot(frame["time_s"], lower(frame), label=name)
    ax.set_ylabel(labels[0])
    ax_l.set_ylabel(labels[1])
    if ylim is not None:
        ax.set_ylim(*ylim)
    if lower_ylim is not None:
        ax_l.set_ylim(*lower_ylim)
    ax_l.set_xlabel("time [s]")
    for a in (ax, ax_l):
        a.grid(True, alpha=0.3)
        legend_outside(a)
    fig.suptitle(title)
    mark_synthetic(fig)
    return fig


def _wet_figure(wet):
    return _tracking_figure(wet["frames"], "reference_sensor_torque_Nm", "sensor_torque_Nm",
                            lambda f: f["force_reference_N"] * 1e-3, ("measured torque [N·m]", "force command [kN]"),
                            "Wet clutch: torque control during an engagement", ylim=(0.0, 170.0))


def _emtc_figure(track):
    return _tracking_figure(track["frames"], "torque_reference_Nm", "coupling_torque_Nm",
                            lambda f: f["coupling_torque_Nm"] - f["torque_reference_Nm"],
                            ("coupling torque [N·m]", "torque error [N·m]"),
                            "EMTC: torque tracking with and without hysteresis compensation", lower_ylim=(-60.0, 60.0))


def _settling(T, y, band: float = 0.05) -> float:
    outside = np.flatnonzero(np.abs(y - 1.0) > band)
    if outside.size == 0:
        return 0.0
    return float(T[outside[-1] + 1]) if outside[-1] + 1 < T.size else float("nan")


def _figures(d, runs):
    from ..plotting import legend_outside, mark_synthetic, new_figure
    from ..control.linear import pole_sweep
    from ..control.plots import bode_figure, nyquist_figure, pole_map_figure

    f = np.logspace(-1, np.log10(2000.0), 400)
    chosen = [0, 3, d["touch"], len(POSITIONS) - 1]
    bode = bode_figure([(f"bearing at {POSITIONS[k] * 1e3:g} mm", d["models"][k]) for k in chosen], f,
                       title="E-clutch: motor voltage to bearing position")
    from ..control.linear import linearize

    current = bode_figure([(f"bearing at {POSITIONS[k] * 1e3:g} mm",
                            linearize(d["ops"][k], inputs=["motor_voltage"], outputs=["pressure", "motor_current"]))
                           for k in chosen], f, over="motor_current_A",
                          title="E-clutch: CSC pressure per motor current")
    poles = pole_sweep(list(zip(POSITIONS, d["ops"])), inputs=["motor_voltage"], outputs=["bearing_position"],
                       name="bearing_position_m")
    near = poles[poles["natural_frequency_Hz"] < 150]
    pmap = pole_map_figure(near, "bearing_position_m", scale=1e3, unit="mm",
                           title="E-clutch: poles below 150 Hz over the travel")
    pmap.axes[1].set_ylabel("bearing position [mm]")
    steps, axes = new_figure(len(runs), 1, width=7.5, height=2.0 * len(runs), sharex=True)
    for ax, r in zip(np.atleast_1d(axes), runs):
        ax.plot(r["time_s"], r["nonlinear"], label="nonlinear model, PI at 1 kHz")
        ax.plot(r["time_s"], r["linear"], "--", label="linear prediction")
        ax.set_ylabel("position / step [1]")
        ax.set_title(f"step from {r['position'] * 1e3:g} mm", fontsize=9)
        ax.grid(True, alpha=0.3)
    np.atleast_1d(axes)[-1].set_xlabel("time [s]")
    for ax in np.atleast_1d(axes):
        legend_outside(ax)
    steps.suptitle(f"E-clutch: {STEP * 1e3:g} mm reference steps, scheduled PI")
    import control

    from ..control.linear import loop_margins

    loops = [(f"bearing at {POSITIONS[k] * 1e3:g} mm", control.ss(d["pis"][k].tf()) * d["models"][k])
             for k in chosen]
    nyq = nyquist_figure(loops, np.logspace(-2, np.log10(2000.0), 800),
                         title="E-clutch: open loops L = PI G near the critical point")
    margins = loop_margins(loops)
    for fig in (bode, current, pmap, steps, nyq):
        mark_synthetic(fig)
    return bode, current, pmap, steps, poles, nyq, margins


def demo_section(progress=None) -> Section:
    """The control-design section of ``clutchlab demo`` (see the module docstring).

    Parameters
    ----------
    progress : callable, optional
        Told what is being done (a message string).
    """
    if progress:
        progress("control: E-clutch operating points, linear models and PI design ...")
    d = design()
    runs = step_runs(d)
    bode, current, pmap, steps, poles, nyq, margins = _figures(d, runs)
    line = poles[(poles["pole_imag_1_s"] > 0) & poles["natural_frequency_Hz"].between(50, 90)]
    res_f = line.groupby("bearing_position_m")["natural_frequency_Hz"].first()
    unstable = sorted(set(poles.loc[poles["pole_real_1_s"] > 0, "bearing_position_m"]))
    gains = pd.DataFrame({"bearing_position_mm": np.array(POSITIONS) * 1e3,
                          "motor_voltage_V": [op.u[0] for op in d["ops"]],
                          "kp_V_per_mm": [p.kp * 1e-3 for p in d["pis"]], "ti_s": [p.ti for p in d["pis"]],
                          "line_resonance_Hz": [res_f.get(x, np.nan) for x in POSITIONS]})
    table = pd.DataFrame({"start_mm": [r["position"] * 1e3 for r in runs],
                          "overshoot_linear_pct": [r["overshoot_linear"] for r in runs],
                          "overshoot_nonlinear_pct": [r["overshoot_nonlinear"] for r in runs],
                          "settling_linear_s": [r["settling_linear"] for r in runs],
                          "settling_nonlinear_s": [r["settling_nonlinear"] for r in runs],
                          "friction_events": [r["events"] for r in runs],
                          "run_ms": [1e3 * r["seconds"] for r in runs]})
    worst = float(np.max(np.abs(table["overshoot_linear_pct"] - table["overshoot_nonlinear_pct"])))
    items = [
        Text("The E-clutch paper's purpose is control design (seed 000, summary). Here the bundled E-clutch is "
             "trimmed at bearing positions from 1 to 8 mm (the motor voltage that holds the bearing, the seal and "
             "spindle friction sliding forward), linearised there (python-control StateSpace, motor voltage [V] "
             f"to bearing position [m]), and a PI is designed for a {PHASE_MARGIN_DEG:g} deg phase margin at a "
             f"{CROSSOVER_HZ:g} Hz crossover at each point; the touch point is {POSITIONS[d['touch']] * 1e3:g} mm, "
             "where the clamp force vanishes."),
        Figure("control_eclutch_bode", bode, "Bode diagram of the open-loop actuator at four bearing positions: "
               "the oil column's resonance near 70 Hz and the clutch's undamped internal modes above 200 Hz."),
        Figure("control_eclutch_current_pressure", current, "The CSC pressure per motor current (the "
               "voltage-driven actuator's pressure response over its current response): flat at the spindle's "
               "ratio k_t 2 pi / (lead A_mc) at low frequency; a peak where the current has its anti-resonance, "
               "the motor's rotor inertia reflected through the spindle (about 37 kg at the master piston) on "
               "the clutch's stiffness, at 3.6-5.3 Hz while that stiffness is positive and none beyond the "
               "force peak; then the line's resonance near 70 Hz."),
        Figure("control_eclutch_poles", pmap, "Poles below 150 Hz over the travel (colour: bearing position). "
               f"The line resonance falls from {res_f.iloc[0]:.1f} to {res_f.iloc[-1]:.1f} Hz as the clutch seen "
               "from the bearing softens; beyond the diaphragm spring's force peak a real pole is in the right "
               f"half-plane (at {', '.join(f'{x * 1e3:g}' for x in unstable)} mm): the open loop is unstable there "
               "and the PI stabilises it."),
        Table("control_eclutch_schedule", gains, "Operating points and the scheduled PI (Kp in V/mm, Ti in s) "
              "with the line resonance there", float_format="{:.4g}"),
        Figure("control_eclutch_nyquist", nyq, "Nyquist diagram of the open loops (PI times actuator) at four "
               "positions, near the critical point -1 (negative and positive frequencies). Every loop passes -1 at "
               f"the designed {PHASE_MARGIN_DEG:g} deg; where the actuator is open-loop unstable the curve "
               "encircles -1 once counter-clockwise, which the Nyquist criterion requires for a stable closed "
               "loop."),
        Table("control_eclutch_margins", margins, "Margins of the loops and the Nyquist criterion: P open-loop "
              "right-half-plane poles, N clockwise encirclements of -1, Z closed-loop right-half-plane poles "
              "counted from the closed loop's poles; consistent where Z = N + P", float_format="{:.4g}"),
        Figure("control_eclutch_steps", steps, f"{STEP * 1e3:g} mm reference steps of the nonlinear model with "
               "the gain-scheduled PI sampled at 1 kHz (zero-order hold on the motor voltage), against the "
               "linear closed loop at the start position."),
        Table("control_eclutch_steps", table, "Overshoot and settling (±5 % band) of the steps: linear "
              "prediction and nonlinear model", float_format="{:.4g}"),
        Text(f"The linear models predict the nonlinear overshoot within {worst:.1f} percentage points at every "
             "start position. The settling differs: in the nonlinear model the seals' Coulomb friction sticks "
             "near the target (the friction events in the table) and the integral term has to break it loose, "
             "which no linear model shows."),
    ]
    if progress:
        progress("control: EMTC torque tracking with and without the inverse Preisach model ...")
    track = emtc_tracking()
    holds = track["holds"]
    comp = holds[holds.controller == "inverse Preisach"]["torque_error_Nm"].abs().max()
    plain = holds[holds.controller == "anhysteretic inverse"]["torque_error_Nm"].abs()
    items += [
        Text("Worked design 2, the EMTC on the drum bench (seed 002): its controller turns the torque reference "
             "into a magnet force (Eqs. 13, 15, 11) and the force into a coil current through the inverse of "
             "the Preisach model (Eqs. 6-7, Fig. 7), open loop. Here the reference is a staircase with the "
             "coupling slipping throughout (drum speed difference 1 m/s), once with that inverse and once with "
             "the inverse of the magnet's hysteresis-free characteristic (the mean of its major loop's "
             "branches), as a compensator without a hysteresis model would do."),
        Figure("control_emtc_tracking", _emtc_figure(track), "Coupling torque and its error against the "
               "reference, with the inverse Preisach model and with the anhysteretic inverse."),
        Table("control_emtc_holds", holds, "Mean torque error in the last 0.2 s of each hold", float_format="{:.4g}"),
        Text(f"With the inverse Preisach model the holds are reached to {comp:.2g} N·m; without it the error is "
             f"{plain.min():.1f} to {plain.max():.1f} N·m, positive after a falling reference and negative after "
             "a rising one: the magnet's hysteresis, which the inverse Preisach model removes (the claim of "
             "seed 002)."),
    ]
    if progress:
        progress("control: wet-clutch torque control during an engagement ...")
    wet = wet_torque_control()
    m = wet["metrics"].set_index("controller")
    items += [
        Text("Worked design 3, the wet clutch's torque during an engagement on its bench (protocol b: the slip "
             "ramped from 1500 rpm to zero by the drive): a controller sets the piston force at 1 kHz from the "
             "measured torque. Feedforward: the force of operating points trimmed at 100 rad/s for 5 to "
             f"100 N·m (5 N·m is the kiss point that ends the fill). Feedback: a PI for {WET_MARGIN_DEG:g} deg at "
             f"{WET_CROSSOVER_HZ:g} Hz on the linear model at 100 N·m (Kp = {wet['pi'].kp:.3g} N/(N·m), "
             f"Ti = {1e3 * wet['pi'].ti:.3g} ms), integrating only within 10 % of the reference."),
        Figure("control_wet_torque", _wet_figure(wet), "Measured torque and force command: feedforward alone, "
               "with the PI, and with a PI that integrates during the fill and the ramp too."),
        Table("control_wet_metrics", wet["metrics"], "Torque error from 0.4 s to 20 ms before lock-up",
              float_format="{:.4g}"),
        Text(f"The feedforward alone drifts as the friction coefficient changes with the slip speed and the "
             f"pack heats (rms error {m.loc['feedforward', 'rms_error_Nm']:.1f} N·m); the PI holds the torque "
             f"(rms {m.loc['feedforward + PI', 'rms_error_Nm']:.1f} N·m). Integrating while the piston still "
             f"crosses its clearance and the torque lags its ramp winds the integral up: "
             f"{m.loc['feedforward + PI, integrating always', 'max_error_Nm']:.0f} N·m of overshoot."),
    ]
    params = {"control: design": f"PI for {PHASE_MARGIN_DEG:g} deg phase margin at {CROSSOVER_HZ:g} Hz, sampled at "
                                 f"{SAMPLE_TIME * 1e3:g} ms, scheduled over {len(POSITIONS)} positions; steps of "
                                 f"{STEP * 1e3:g} mm"}
    return Section("Control design: E-clutch position loop, EMTC hysteresis compensation, wet-clutch torque "
                   "(simulated)", items, provenance=PROVENANCE,
                   parameters=params, synthetic=True)
