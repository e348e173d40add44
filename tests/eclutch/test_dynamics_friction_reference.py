"""The clutch alone with friction (R_f.ds, R_f.pp) against an independent trajectory (issue #30).

Reference: ``dynamics_friction_scipy.py`` (this folder), the same equations in plain Python integrated by
SciPy's DOP853 at rtol 1e-10, restarted at every stick, break-away and slip reversal.  Scenario: the bearing
ramped at the 2 mm/s of the documented release-engage cycle (0 -> 0.2 mm in 0.1 s and back for Model 0,
0 -> 0.1 mm in 0.05 s and back for Model 4), long enough for the pressure plate's stick-slip micro-cycles
(~1.07 ms period for Model 0: 367 located events in the reference) and the reversal.

Measured 2026-11-29 (docs/eclutch_dynamics.md, "Accuracy per model"): at the default rtol 1e-5 and the
default absolute tolerances (10 nm, 10 um/s) clutchlab finds the reference's micro-cycles (Model 0: 370
events against 367) and its F_b is within 2.7 % of peak (Model 4: 0.93 %); that is the floor of the absolute
tolerance (the micro-cycles are ~0.7 um, ~3 mm/s).  Below the default rtol the absolute tolerances follow it
(``ClutchDynamics.simulate``'s default ``atol_scale = min(1, rtol / 1e-5)``): the error shrinks to 0.005 %
(Model 0) / 0.045 % (Model 4) at rtol 1e-8 and the event count equals the reference's; fixed absolute
tolerances (``atol_scale=1``) hold it at 2.6 % from rtol 1e-5 to 1e-8.
"""

from __future__ import annotations

import importlib.util
import pathlib

import numpy as np
import pytest

from clutchlab.eclutch import ClutchDynamics, ClutchModel, FrictionParameters

_spec = importlib.util.spec_from_file_location("eclutch_dynamics_friction_scipy",
                                               pathlib.Path(__file__).with_name("dynamics_friction_scipy.py"))
ref_mod = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(ref_mod)

SCENARIOS = {0: ([0.0, 0.1, 0.2], [0.0, 2e-4, 0.0]), 4: ([0.0, 0.05, 0.1], [0.0, 1e-4, 0.0])}
# bounds at the default rtol 1e-5 (default atol), fraction of the reference's peak; measured in the docstring
BOUND_FB = {0: 0.035, 4: 0.015}
BOUND_FN = 1e-3
STICK_SLIP = ("stick", "breakaway", "slip reversal")
_REFS = {}


def _reference(number):
    if number not in _REFS:
        table = SCENARIOS[number]
        grid = np.linspace(table[0][0], table[0][-1], 2001)
        _REFS[number] = (grid, ref_mod.reference(ClutchModel.preset(number), FrictionParameters(), table, grid))
    return _REFS[number]


def _compare(number, friction=None, **options):
    """Errors of clutchlab against the reference: F_b, F_n (fractions of peak), x_pp [m], event counts."""
    grid, ref = _reference(number)
    dyn = ClutchDynamics(ClutchModel.preset(number), FrictionParameters() if friction is None else friction)
    res = dyn.simulate(SCENARIOS[number], output_step=grid[1] - grid[0], **options)
    o = res.outputs_table
    assert len(o) == len(grid) and np.allclose(o.time_s.to_numpy(), grid, atol=1e-12)
    fb, fn = ref["bearing_force_N"], ref["normal_force_N"]
    return {"Fb": np.abs(o.bearing_force_clutch_N.to_numpy() - fb).max() / np.abs(fb).max(),
            "Fn": np.abs(o.normal_force_N.to_numpy() - fn).max() / np.abs(fn).max(),
            "x_pp": np.abs(o.x_pp_m.to_numpy() - ref["x"]["pp"]).max(),
            "events": int(res.events.event.isin(STICK_SLIP).sum()),
            "ref_events": len(ref["events"])}


@pytest.mark.parametrize("number", [0, 4])
def test_reference_has_the_stick_slip_micro_cycles(number):
    # physical, not numerical: the tight independent solution sticks and breaks away every ~1 ms
    _grid, ref = _reference(number)
    kinds = [k for _t, k, _n in ref["events"]]
    assert kinds.count("breakaway") > 50 and kinds.count("stick") > 50


@pytest.mark.parametrize("number", [0, 4])
def test_clutch_with_friction_follows_the_reference_at_the_default_rtol(number):
    e = _compare(number)
    assert e["Fb"] < BOUND_FB[number], e
    assert e["Fn"] < BOUND_FN, e
    assert e["x_pp"] < 6e-7, e
    # the micro-cycles are found: the event count within 2 % of the reference's
    assert abs(e["events"] - e["ref_events"]) <= max(2, 0.02 * e["ref_events"]), e


@pytest.mark.parametrize("number", [0, 4])
def test_clutch_with_friction_error_shrinks_with_the_tolerance(number):
    # the default absolute tolerances follow rtol below its default (atol_scale = rtol / 1e-5): the error shrinks
    # to the reference, events and all
    default = _compare(number)
    errors = {rtol: _compare(number, rtol=rtol) for rtol in (1e-6, 1e-7, 1e-8)}
    # fixed absolute tolerances (atol_scale=1) hold the stick-slip phase, and the error, at their floor
    fixed = _compare(number, rtol=1e-8, atol_scale=1.0)
    assert fixed["Fb"] > 5.0 * errors[1e-8]["Fb"], (fixed, errors)
    assert fixed["Fb"] < 1.05 * default["Fb"], (default, fixed)
    assert errors[1e-6]["Fb"] < default["Fb"], errors
    assert errors[1e-8]["Fb"] < 0.1 * errors[1e-6]["Fb"], errors
    assert errors[1e-8]["Fb"] < 1e-3 and errors[1e-8]["Fn"] < 5e-5 and errors[1e-8]["x_pp"] < 5e-8, errors
    assert all(e["events"] == e["ref_events"] for e in (errors[1e-7], errors[1e-8])), errors


@pytest.mark.parametrize("number", [0, 4])
def test_loose_tolerances_keep_the_micro_cycles(number):
    # the step after a stick or break-away starts afresh (update returns RESTART): before, the first step
    # after a break-away kept the stuck phase's trial length, longer than a cycle, whose L-stable stages damped
    # the ringing unseen; the plate then slid smoothly (Model 0: 3 events of 367 at rtol 1e-3, 103 at 1e-4)
    for rtol in (1e-3, 1e-4):
        e = _compare(number, rtol=rtol)
        assert e["events"] > 0.5 * e["ref_events"], (rtol, e)
        assert e["Fb"] < 2.0 * BOUND_FB[number], (rtol, e)


def test_the_full_cycle_has_the_reference_s_micro_cycles_at_the_default_rtol():
    # the documented cycle (0 -> 8 mm -> 0 in 8 s, Model 0): the reference has 13,953 stick-slip events
    # (dynamics_friction_scipy.reference, 35 s on the 2-core machine, measured 2026-11-29: too long to run
    # here); clutchlab had 1,227 at the default rtol before the step restart, 14,064 after
    res = ClutchDynamics(ClutchModel.preset(0), FrictionParameters()).simulate(([0.0, 4.0, 8.0], [0.0, 8e-3, 0.0]))
    n = int(res.events.event.isin(STICK_SLIP).sum())
    assert abs(n - 13_953) < 0.02 * 13_953, n


@pytest.mark.parametrize("friction", [
    FrictionParameters.off(),
    FrictionParameters(diaphragm_coefficient=0.033),  # R_f.ds 10 % high
    FrictionParameters(static_ratio=1.3),  # break-away limit 4 % high
    FrictionParameters(pressure_plate_force=20.0),  # R_f.pp doubled
], ids=["friction off", "mu_ds +10%", "r_s 1.3", "F_pp x2"])
def test_the_comparison_detects_a_wrong_friction_model(friction):
    # at the tight tolerance of the convergence test every wrong model is far outside its bound
    e = _compare(0, friction, rtol=1e-8, atol_scale=1e-3)
    assert e["Fb"] > 0.01, e  # bound 1e-3; the right model: 5e-5
    # at the default tolerance only an error above the absolute tolerance's floor shows (2.7 % of peak):
    # friction off does (6.2 %); a friction coefficient 10 % off does not (3.0 %, measured 2026-11-29)
    if friction == FrictionParameters.off():
        e = _compare(0, friction)
        assert e["Fb"] > BOUND_FB[0] and abs(e["events"] - e["ref_events"]) > 0.02 * e["ref_events"], e
