"""Control design: operating points, linear models, fixed-step runs, controllers in the loop.

Everything here is written against the system contract (:mod:`clutchlab.system`): it works for every
model (E-clutch, wet clutch, EMTC bench, driveline networks) and for a user's own.

* :func:`operating_point` -- steady state of a system for given inputs, or the inputs that hold given
  outputs (trim), within the system's physical limits;
* :func:`linearize` -- a python-control ``StateSpace`` with named states, inputs and outputs (their
  unit in the name, ``bearing_position_m``), within the active mode of a hybrid model;
  :func:`nonlinear_iosystem` -- the model as a python-control ``NonlinearIOSystem`` (one mode);
* :func:`frequency_table`, :func:`pole_sweep` -- frequency responses and poles over an operating range;
* :func:`judder_modes`, :func:`friction_damping`, :func:`oscillation` -- judder: the oscillating modes in the
  active mode, the damping a sliding clutch adds to them (negative where its friction falls with the slip speed),
  and the oscillation in a band of a run or a measurement;
  :func:`loop_margins` -- gain, phase and stability margins of loops, checked by the Nyquist criterion;
* :func:`shift_quality` -- the phases and quality metrics of a clutch-to-clutch gear shift (times, acceleration
  dip, jerk, vibration dose value, lock-up slip rate, engine flare, the clutches' heat) in a run or a rig's record;
* :func:`closed_loop` -- a discrete controller (python-control or a function) in the loop with any model;
  :class:`AmtController` -- an automated manual transmission's controller (TCU): a gear command carried out by the
  shift sequence, waiting on the synchronisers; :class:`DctController` -- a dual-clutch transmission's: power
  shifts, the off-going clutch released where the on-coming one has taken the torque over;
* :func:`pi_for_phase_margin`, :class:`ScheduledPI` -- a PI for a phase margin, gain scheduling;
* :func:`time_steps`, :func:`fixed_step_error` -- fixed-step (HIL frame) runs: wall time per frame and
  the error against the adaptive solution (``simulate(..., fixed_step=1e-3)`` runs the core's fixed-step
  mode).

python-control (``control`` on PyPI) is imported when a linear model is built, not with this package.
"""

from __future__ import annotations

import importlib

__all__ = ["OperatingPoint", "operating_point", "linearize", "nonlinear_iosystem", "jacobians", "frequency_table", "pole_sweep",
           "loop_margins", "write_linear_model", "OperatingPointError", "closed_loop", "ClosedLoopResult", "PI",
           "pi_for_phase_margin", "ScheduledPI", "time_steps", "fixed_step_error", "judder_modes", "JudderModes",
           "judder_timeline", "friction_damping", "oscillation", "Oscillation", "reduced_matrices", "shift_quality",
           "ShiftQuality", "AmtController", "AmtGear", "DctController", "DctGear"]

_WHERE = {
    "OperatingPoint": "clutchlab.trim",
    "operating_point": "clutchlab.trim",
    "OperatingPointError": "clutchlab.trim",
    "linearize": "clutchlab.control.linear",
    "jacobians": "clutchlab.control.linear",
    "nonlinear_iosystem": "clutchlab.control.linear",
    "frequency_table": "clutchlab.control.linear",
    "pole_sweep": "clutchlab.control.linear",
    "loop_margins": "clutchlab.control.linear",
    "write_linear_model": "clutchlab.control.linear",
    "reduced_matrices": "clutchlab.control.linear",
    "judder_modes": "clutchlab.control.judder",
    "JudderModes": "clutchlab.control.judder",
    "judder_timeline": "clutchlab.control.judder",
    "friction_damping": "clutchlab.control.judder",
    "oscillation": "clutchlab.control.judder",
    "Oscillation": "clutchlab.control.judder",
    "shift_quality": "clutchlab.driveline.shift",
    "ShiftQuality": "clutchlab.driveline.shift",
    "AmtController": "clutchlab.control.tcu",
    "AmtGear": "clutchlab.control.tcu",
    "DctController": "clutchlab.control.dct",
    "DctGear": "clutchlab.control.dct",
    "closed_loop": "clutchlab.control.loop",
    "ClosedLoopResult": "clutchlab.control.loop",
    "PI": "clutchlab.control.design",
    "pi_for_phase_margin": "clutchlab.control.design",
    "ScheduledPI": "clutchlab.control.design",
    "time_steps": "clutchlab.control.realtime",
    "fixed_step_error": "clutchlab.control.realtime",
}


def __getattr__(name):
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'clutchlab.control' has no attribute {name!r}")
    return getattr(importlib.import_module(module), name)


def __dir__():
    return sorted(list(globals()) + list(_WHERE))
