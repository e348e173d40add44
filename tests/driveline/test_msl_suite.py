"""The MSL suite: every friction, clutch, brake, one-way clutch, gear and backlash example of
``Modelica.Mechanics.Rotational.Examples`` and ``ModelicaTest.Rotational`` that a clutchlab network can
hold, as TOML (``tests/driveline/msl/*.toml``), against an independent solution written from the MSL
equations (``tests/driveline/msl/reference.py``: SciPy DOP853 at rtol 1e-12, restarted at every event,
the networks transcribed separately in ``msl/models.py``).

Criteria (issue #30): every stick/slip/roll event within 1e-6 s; every signal (speeds, angles, element
torques, dissipated energies, source work, a lossy gear's mode) within 2e-3 of its range (MSL's own
regression tube), torques away from their jumps; the energy balance ``energy_error_J`` within 1e-6 of the
energy that flowed.  ``msl/README.md`` lists the examples left out and why.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pytest

from clutchlab.driveline.description import load_driveline

from .msl.models import MODELS
from .msl.reference import collapse

HERE = Path(__file__).parent / "msl"
NAMES = sorted(MODELS)
EVENT_TOL = 1e-6            # [s]
SIGNAL_TOL = 2e-3           # of the signal's range
MODES = ("stick", "forward", "backward", "free")
#: events not compared: LossyGearDemo2 before 0.2 s (a stuck bearing on the flange of a locked gear: the
#: split of the holding torque is not unique, MSL's system is singular there; see its TOML header)
COMPARE_AFTER = {"lossy_gear_demo2": 0.2}
#: statically indeterminate groups: elements that hold one shaft together (a stuck bearing on the flange of a stuck
#: lossy gear).  While the shaft is at rest the split of the holding torque between them, and so which of them
#: MSL labels "stuck", is not unique (MSL's LossyGearDemo2 documentation: "no unique solution"); clutchlab keeps
#: every member stuck with a split within all limits, the reference a least-squares split that may leave one
#: "sliding" at zero speed.  For such a group the events compared are the instants the shaft starts or stops
#: (the motion, which is unique), and its members' torques and modes are compared only while the shaft moves.
INDETERMINATE = {"lossy_gear_demo2": ("Inertia1.w_rad_s", ("bearingFriction", "gear"))}


def _motion_events(times, speed_t, speed_w, after):
    """The instants among ``times`` (> ``after``) at which a shaft with speed samples ``(speed_t, speed_w)``
    starts or stops: at rest (|w| < 1e-7 of its range) just before and moving just after, or the reverse.  Times
    within 1e-9 s of each other are one instant (the members of a group that slips when its last feasible split
    closes may be released a few 1e-11 s apart: LossyGearDemo2's bearing friction 5.6e-11 s before its gear)."""
    span = max(np.ptp(speed_w), 1e-9)
    out = []
    instants = []
    for t in sorted(set(times)):
        if not instants or t - instants[-1] > 1e-9:
            instants.append(t)
    for t in instants:
        if t <= after:
            continue
        before = abs(np.interp(t - 2e-3, speed_t, speed_w)) < 1e-7 * span
        later = abs(np.interp(t + 2e-3, speed_t, speed_w)) < 1e-7 * span
        if before != later:
            out.append((t, "start" if before else "stop"))
    return out


def _grid(t_end, dt):
    return np.linspace(0.0, t_end, int(round(t_end / dt)) + 1)


@functools.lru_cache(maxsize=None)
def reference(name):
    build, t_end, dt = MODELS[name]
    return build().simulate(t_end, _grid(t_end, dt))


@functools.lru_cache(maxsize=None)
def clutchlab_run(name):
    f = load_driveline(HERE / f"{name}.toml")
    _, t_end, dt = MODELS[name]
    assert f.t_end == pytest.approx(t_end) and f.output_step == pytest.approx(dt), "TOML and models.py disagree"
    return f.driveline.simulate(f.t_end, rtol=f.rtol, output_step=f.output_step)


def _kinds(name):
    """Element name -> kind in the reference network."""
    return {e.name: e.kind for e in MODELS[name][0]().elements}


def _events_of(rows, name):
    """(t, element, mode) of the friction elements, one-way clutches and lossy gears after t = 0 (one-way
    clutches: stick/forward only; the ideal gears have no events)."""
    kinds = _kinds(name)
    after = COMPARE_AFTER.get(name, 1e-9)
    out = []
    for t, element, event in rows:
        kind = kinds.get(element)
        if t <= after or event not in MODES or kind not in ("friction", "one_way", "lossy_gear"):
            continue
        if kind in ("one_way", "lossy_gear") and event == "free":
            continue
        out.append((float(t), element, event))
    # several elements changing mode at one instant: in element order (their order in time is not defined)
    return _drop_touches(collapse(sorted(out, key=lambda e: (round(e[0], 7), e[1], e[2]))))


def _drop_touches(events, width=1e-5):
    """Drop a stick that the same element undoes within ``width`` [s] (a relative speed that touches zero
    tangentially, a double root, e.g. OneWayClutch's at 1.5 s where its drive torque and its clutch's pulse end
    together: whether the integration error puts the touch a few 1e-9 rad/s below zero, a stick of a few
    microseconds, or above, none, is not a decision of the model)."""
    out = []
    skip = set()
    for i, (t, el, ev) in enumerate(events):
        if i in skip:
            continue
        if ev == "stick":
            nxt = next((j for j in range(i + 1, len(events)) if events[j][1] == el), None)
            if nxt is not None and events[nxt][0] - t < width and events[nxt][2] != "stick":
                prev = next((e[2] for e in reversed(events[:i]) if e[1] == el), None)
                if prev == events[nxt][2]:
                    skip.add(nxt)
                    continue
        out.append((t, el, ev))
    return out


@pytest.mark.parametrize("name", NAMES)
def test_events_match_the_msl_reference(name):
    """Every mode change (element, mode entered) in order, at the reference's time within 1e-6 s."""
    ref = _events_of(reference(name).events, name)
    ev = clutchlab_run(name).events
    got = _events_of(zip(ev["time_s"], ev["element"], ev["event"]), name)
    if name in INDETERMINATE:
        col, group = INDETERMINATE[name]
        after = COMPARE_AFTER.get(name, 1e-9)
        df = clutchlab_run(name).to_dataframe()
        rr = reference(name)
        got_m = _motion_events([e[0] for e in got if e[1] in group], df["time_s"].to_numpy(), df[col].to_numpy(),
                               after)
        ref_m = _motion_events([e[0] for e in ref if e[1] in group], rr.time, rr.columns[col], after)
        assert [m for _, m in got_m] == [m for _, m in ref_m] and len(got_m) >= 2, (got_m, ref_m)
        assert max(abs(a[0] - b[0]) for a, b in zip(got_m, ref_m)) <= EVENT_TOL, (got_m, ref_m)
        got = [e for e in got if e[1] not in group]
        ref = [e for e in ref if e[1] not in group]
    lines = [f"{'clutchlab':>34} | reference"]
    for i in range(max(len(got), len(ref))):
        g = "%.9f %s %s" % got[i] if i < len(got) else ""
        r = "%.9f %s %s" % ref[i] if i < len(ref) else ""
        lines.append(f"{g:>34} | {r}")
    table = "\n".join(lines)
    assert [e[1:] for e in got] == [e[1:] for e in ref], f"{name}: the events differ\n{table}"
    dt = max((abs(g[0] - r[0]) for g, r in zip(got, ref)), default=0.0)
    assert dt <= EVENT_TOL, f"{name}: event times differ by up to {dt:.3g} s\n{table}"


def _compared_columns(name, ref):
    kinds = _kinds(name)
    cols = []
    for col in ref.columns:
        element, quantity = col.split(".", 1)
        if quantity == "dissipated_J" and kinds.get(element) in ("spring_damper", "backlash"):
            continue   # a separating backlash's spring energy: counted differently on purpose (docs/driveline.md)
        cols.append(col)
    return cols


@pytest.mark.parametrize("name", NAMES)
def test_signals_match_the_msl_reference(name):
    """Speeds, angles, torques, dissipated energies, source work and lossy-gear modes within 2e-3 of each
    signal's range (torques and modes not within 2e-5 s of a reference event or break, where they jump)."""
    ref = reference(name)
    df = clutchlab_run(name).to_dataframe()
    t = ref.time
    jumps = np.array(sorted({e[0] for e in ref.log} | set(ref.breaks)))
    near = np.zeros(len(t), bool)
    for tj in jumps:
        near |= np.abs(t - tj) < 2e-5
    missing = [c for c in _compared_columns(name, ref) if c not in df.columns]
    assert not missing, f"{name}: clutchlab lacks the columns {missing}"
    worst = []
    for col in _compared_columns(name, ref):
        r = ref.columns[col]
        g = np.interp(t, df["time_s"].to_numpy(), df[col].to_numpy())
        mask = ~near if col.endswith(("tau_Nm", "mode_1")) else np.ones(len(t), bool)
        if name in INDETERMINATE and col.split(".")[0] in INDETERMINATE[name][1] and col.endswith(("tau_Nm", "mode_1")):
            w = ref.columns[INDETERMINATE[name][0]]
            mask &= np.abs(w) > 1e-7 * np.ptp(w)    # the split is not unique while the shaft is at rest
        span = max(np.ptp(r), 1e-3)
        err = np.max(np.abs(g - r)[mask]) / span
        worst.append((err, col))
    worst.sort(reverse=True)
    bad = [(c, e) for e, c in worst if e > SIGNAL_TOL]
    assert not bad, f"{name}: signals beyond {SIGNAL_TOL} of their range: " + ", ".join(
        f"{c} {e:.3g}" for c, e in bad)


@pytest.mark.parametrize("name", NAMES)
def test_energy_balance_closes(name):
    """``energy_error_J`` within 1e-6 of the energy that flowed (input work, initial kinetic energy)."""
    df = clutchlab_run(name).to_dataframe()
    scale = max(np.abs(df["input_work_J"]).max(), df["kinetic_energy_J"].max(), 1.0)
    err = np.abs(df["energy_error_J"]).max()
    assert err <= 1e-6 * scale, f"{name}: energy balance error {err:.3g} J against {scale:.3g} J"
