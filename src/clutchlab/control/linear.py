"""Linear models of any system at an operating point (python-control ``StateSpace``).

For a system ``M x' = f(t, x, u, m)``, ``y = h(t, x, u, m)`` (:mod:`clutchlab.system`; ``M`` diagonal, 0 on
algebraic rows such as the E-clutch's massless finger tip) at an operating point ``(t, x0, u0, m)``:

* ``A_full = df/dx`` from the model's analytic Jacobian hook where it has one, else central differences
  (step ``6e-6`` times the state's typical magnitude, :func:`clutchlab.trim.state_scale`);
  ``B = df/du``, ``C = dh/dx``, ``D = dh/du`` by central differences; the modes stay fixed, so a hybrid model
  is linearised within its active mode (stuck or sliding, in contact or not), and that mode is part of the
  result;
* differential rows are divided by their mass, algebraic rows ``a`` are eliminated
  (``A = A_dd - A_da A_aa^-1 A_ad``, likewise ``B``, ``C``, ``D``): index-1 DAEs only;
* states that no other kept state and no requested output reads are dropped, repeatedly (energy
  integrals, see :mod:`clutchlab.trim`; the E-clutch's massless-tip velocity): they are
  unobservable, so the input-output behaviour is unchanged (``keep_monitors=True`` keeps them); so are
  states the active mode holds still (a zero row in ``A`` and ``B``: the EMTC's armature at its stop),
  which stay at their operating values whatever the inputs do.

The result is a ``control.StateSpace`` whose signal names carry their unit (``bearing_position_m``,
``motor_voltage_V``); its ``operating_point`` attribute holds the :class:`OperatingPoint` and ``mode`` the
active mode by name.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..errors import ParameterError
from ..system import System, evaluate
from ..trim import OperatingPoint, input_scale, resolve, state_scale

__all__ = ["jacobians", "reduced_matrices", "Reduced", "linearize", "nonlinear_iosystem", "frequency_table",
           "pole_sweep", "loop_margins", "write_linear_model", "signal_name"]

#: relative step of the central differences (about the cube root of the machine epsilon)
FD_STEP = 6e-6


def _signals(system: System, names, kinds, default):
    if names is None:
        names = default
    if isinstance(names, str):
        names = [names]
    return [resolve(system, n, kinds) for n in names]


def _directions(system: System, directions) -> dict:
    """``{("state"|"input", index): +1.0 | -1.0}`` from ``{name: "rising" | "falling"}``."""
    out = {}
    if directions is not None and not isinstance(directions, dict):
        raise ParameterError(f"{system.name}: directions = {directions!r}: expected a mapping "
                             "{name: 'rising' | 'falling'} of the states or inputs with a direction")
    for name, d in (directions or {}).items():
        if d not in ("rising", "falling"):
            raise ParameterError(f"{system.name}: direction of {name!r} = {d!r}: expected 'rising' or 'falling'")
        out[resolve(system, name, ("state", "input"))] = 1.0 if d == "rising" else -1.0
    return out


def jacobians(system: System, op: OperatingPoint, inputs=None, outputs=None, directions=None):
    """The full Jacobians of a system at an operating point (before eliminating algebraic rows).

    Parameters
    ----------
    system : System
        The system (normally ``op.system``).
    op : OperatingPoint
        Where: time, state, inputs and modes.
    inputs : sequence of str, optional
        Held inputs (default: all).
    outputs : sequence of str, optional
        States or outputs (default: all outputs).
    directions : dict, optional
        ``{state or input: "rising" | "falling"}``: one-sided differences in that direction for those
        columns (a hysteretic element's branch: the EMTC magnet's force rises along its ascending branch
        and falls along a descending one, with other slopes); central differences otherwise.

    Returns
    -------
    dict
        ``A`` (n x n), ``B`` (n x p), ``C`` (q x n), ``D`` (q x p) [SI per SI], ``analytic`` (bool: the
        model's own ``df/dx``), and the resolved ``inputs``/``outputs`` as ``(kind, index)`` lists.
    """
    from ..numerics.core import evaluate_jacobian

    ins = _signals(system, inputs, ("input",), [v.name for v in system.inputs])
    outs = _signals(system, outputs, ("state", "output"), [v.name for v in system.outputs])
    t, x, u, m = op.t, op.x.copy(), op.u.copy(), op.m.copy()
    n, q = x.size, len(outs)
    xs = state_scale(system, x)
    us = input_scale(system, u)

    def pick(xx, y):
        return np.array([xx[i] if kind == "state" else y[i] for kind, i in outs])

    sides = _directions(system, directions)
    f0, _, y0 = evaluate(system, t, x, u, m)
    y0 = pick(x, y0)

    def slopes(vec, kind, j, h):
        """d(rhs)/d and d(outputs)/d component ``j`` of ``vec`` (x or u): central, or one-sided (directions)."""
        side = sides.get((kind, j))
        out = []
        for sign in ((1.0, -1.0) if side is None else (side,)):
            v = vec.copy()
            v[j] += sign * h
            xx, uu = (v, u) if vec is x else (x, v)
            f, _, y = evaluate(system, t, xx, uu, m)
            out.append((f, pick(xx, y)))
        if side is None:
            (fp, yp), (fm, ym) = out
            return (fp - fm) / (2 * h), (yp - ym) / (2 * h), False
        (f1, y1), = out
        return (f1 - f0) / (side * h), (y1 - y0) / (side * h), True

    A = np.zeros((n, n))
    C = np.zeros((q, n))
    analytic = bool(evaluate_jacobian(system.params, float(t), x, u, m, A))
    for j in range(n):
        a, c, one_sided = slopes(x, "state", j, FD_STEP * xs[j])
        if not analytic or one_sided:
            A[:, j] = a
        C[:, j] = c
    B = np.zeros((n, len(ins)))
    D = np.zeros((q, len(ins)))
    for k, (_, j) in enumerate(ins):
        B[:, k], D[:, k], _ = slopes(u, "input", j, FD_STEP * us[j])
    for name, M in (("A", A), ("B", B), ("C", C), ("D", D)):
        if not np.all(np.isfinite(M)):
            raise ParameterError(f"{system.name}: the Jacobian {name} is not finite at this operating point "
                                 f"(mode {op.modes})")
    return {"A": A, "B": B, "C": C, "D": D, "analytic": analytic, "inputs": ins, "outputs": outs}


def signal_name(column: str) -> str:
    """The python-control signal name of a result column: the column with ``.`` written ``_``
    (``clutch1.tau_Nm`` -> ``clutch1_tau_Nm``).  python-control refuses ``.`` in a signal name (it reads
    ``sys.signal`` as a subsystem's signal in ``interconnect``); the other models' columns have none and keep
    their names.  A linear model maps its signals back in its ``columns`` attribute."""
    return str(column).replace(".", "_")


class Reduced(NamedTuple):
    """A system's linear matrices at an operating point within its active mode, its algebraic rows eliminated and
    its unread states dropped (:func:`reduced_matrices`): ``x' = A x + B u``, ``y = C x + D u`` [SI per SI] over
    the kept ``states``, ``inputs`` and ``outputs`` (:class:`~clutchlab.system.Variable`)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    states: list
    inputs: list
    outputs: list
    operating_point: OperatingPoint
    analytic: bool


def reduced_matrices(system: System, op: OperatingPoint | None = None, inputs=None, outputs=None, *,
                     directions: dict | None = None, keep_monitors: bool = False) -> Reduced:
    """The matrices :func:`linearize` builds its ``StateSpace`` from (the module docstring: the differential rows
    divided by their mass, the algebraic rows eliminated, unread and frozen states dropped), as plain arrays with
    their variables: also for a system without inputs, which a python-control model cannot hold."""
    if isinstance(system, OperatingPoint):
        system, op = system.system, system
    if op is None:
        op = OperatingPoint(system, 0.0, system.x0.copy(), system.u0.copy(), system.m0.copy())
    if op.system is not system and op.x.shape != system.x0.shape:
        raise ParameterError(f"{system.name}: the operating point belongs to another system ({op.system.name})")
    jac = jacobians(system, op, inputs, outputs, directions)
    A, B, C, D = jac["A"], jac["B"], jac["C"], jac["D"]
    mass = system.mass
    alg = np.flatnonzero(mass == 0.0)
    dif = np.flatnonzero(mass != 0.0)
    if alg.size:
        Aaa = A[np.ix_(alg, alg)]
        try:
            lu_a = np.linalg.solve(Aaa, np.hstack([A[np.ix_(alg, dif)], B[alg]]))
        except np.linalg.LinAlgError:
            raise ParameterError(f"{system.name}: the algebraic equations ({', '.join(system.states[i].name for i in alg)}) "
                                 "are singular at this operating point: not an index-1 system") from None
        Xa, Ba = lu_a[:, :dif.size], lu_a[:, dif.size:]
        A_ = A[np.ix_(dif, dif)] - A[np.ix_(dif, alg)] @ Xa
        B_ = B[dif] - A[np.ix_(dif, alg)] @ Ba
        C_ = C[:, dif] - C[:, alg] @ Xa
        D_ = D - C[:, alg] @ Ba
    else:
        A_, B_, C_, D_ = A, B, C, D
    md = mass[dif]
    A_ = A_ / md[:, None]
    B_ = B_ / md[:, None]
    keep = np.ones(dif.size, dtype=bool)
    changed = not keep_monitors
    while changed:  # a state no kept state and no output reads: unobservable, dropped (then look again);
        changed = False  # a state the mode holds still (zero row, no input): constant, dropped as well
        for k in np.flatnonzero(keep):
            others = keep & (np.arange(dif.size) != k)
            unread = np.all(A_[others, k] == 0.0) and np.all(C_[:, k] == 0.0)
            frozen = np.all(A_[k, keep] == 0.0) and np.all(B_[k] == 0.0)
            if unread or frozen:
                keep[k] = False
                changed = True
    A_, B_, C_ = A_[np.ix_(keep, keep)], B_[keep], C_[:, keep]
    state_vars = [system.states[i] for i in dif[keep]]
    in_vars = [system.inputs[j] for _, j in jac["inputs"]]
    out_vars = [(system.states if kind == "state" else system.outputs)[i] for kind, i in jac["outputs"]]
    return Reduced(A_, B_, C_, D_, state_vars, in_vars, out_vars, op, bool(jac["analytic"]))


def linearize(system: System, op: OperatingPoint | None = None, inputs=None, outputs=None, *,
              directions: dict | None = None, keep_monitors: bool = False, name: str | None = None):
    """Linear model of ``system`` at ``op`` within its active mode, as a python-control ``StateSpace``.

    Parameters
    ----------
    system : System or OperatingPoint
        The system; an :class:`OperatingPoint` alone stands for its system and itself.
    op : OperatingPoint, optional
        Where to linearise (default: the system's initial state, inputs and modes at t = 0).
    inputs : sequence of str, optional
        Held inputs of the model (default: all), names with or without unit.
    outputs : sequence of str, optional
        States or outputs (default: all outputs).
    directions : dict, optional
        ``{state or input: "rising" | "falling"}``: linearise a hysteretic element along one branch
        (:func:`jacobians`), e.g. ``{"i2": "rising"}`` for the EMTC magnet driven up.  Without it the
        slopes are central differences: on a hysteresis branch point, the mean of the rising and falling
        slopes.
    keep_monitors : bool
        Keep states that no other state and no requested output reads (unobservable poles) and states the
        mode holds still (poles at zero that no input reaches).
    name : str, optional
        Name of the ``StateSpace`` (default: the system's name and the mode).

    Returns
    -------
    control.StateSpace
        Signals named by column (``bearing_position_m``; a driveline's ``clutch1.tau_Nm`` as
        ``clutch1_tau_Nm``: :func:`signal_name`); attributes ``operating_point``, ``mode``
        (``{mode variable: value}``), ``directions`` (the branches asked for), ``units``
        (``{signal: unit}``) and ``columns`` (``{signal: result column}``).

    Raises
    ------
    ParameterError
        Unknown names, a system without the requested inputs or without any (python-control cannot hold a model
        with outputs and no inputs: :func:`reduced_matrices` and :func:`clutchlab.control.judder_modes` take one),
        an algebraic block that is singular.
    """
    import control

    if isinstance(system, OperatingPoint):
        system, op = system.system, system
    reduced = reduced_matrices(system, op, inputs, outputs, directions=directions, keep_monitors=keep_monitors)
    A_, B_, C_, D_ = reduced.A, reduced.B, reduced.C, reduced.D
    state_vars, in_vars, out_vars, op = reduced.states, reduced.inputs, reduced.outputs, reduced.operating_point
    if not in_vars and out_vars:
        # (python-control 0.10 stores an empty D as 0 x 0 and then refuses it: name the cause, not its shape)
        raise ParameterError(f"{system.name}: a linear model needs at least one input (the system has "
                             f"{'none' if not system.inputs else 'none asked for'}); its poles and modes without "
                             "inputs: clutchlab.control.judder_modes")
    mode = op.modes
    label = name or system.name
    columns = {}
    for v in (*state_vars, *in_vars, *out_vars):
        sig = signal_name(v.column)
        if columns.get(sig, v.column) != v.column:
            raise ParameterError(f"{system.name}: {columns[sig]!r} and {v.column!r} would both be the signal {sig!r} "
                                 "of the linear model (rename a component)")
        columns[sig] = v.column
    sys = control.ss(A_, B_, C_, D_, states=[signal_name(v.column) for v in state_vars],
                     inputs=[signal_name(v.column) for v in in_vars], outputs=[signal_name(v.column) for v in out_vars],
                     name=label)
    sys.operating_point = op
    sys.mode = mode
    sys.directions = dict(directions or {})
    sys.units = {signal_name(v.column): v.unit for v in (*state_vars, *in_vars, *out_vars)}
    sys.columns = columns
    sys.analytic_jacobian = reduced.analytic
    return sys


def nonlinear_iosystem(system: System, op: OperatingPoint | None = None, outputs=None, *, name: str | None = None):
    """The model as a python-control ``NonlinearIOSystem`` (for python-control's own tools).

    The update and output functions evaluate the model's right-hand side and outputs through the
    contract at fixed modes (those of ``op``, else the system's initial modes): python-control's
    ``input_output_response``, ``find_operating_point`` and ``linearize`` then see one mode of the hybrid
    model, without its events. For simulation use :func:`clutchlab.system.simulate` (events, compiled).

    Parameters
    ----------
    system : System
        A model with a unit mass matrix (no algebraic rows: python-control integrates ODEs only).
    op : OperatingPoint, optional
        Gives the modes (default: ``system.m0``).
    outputs : sequence of str, optional
        States or outputs (default: all outputs).
    name : str, optional
        Name of the I/O system.

    Returns
    -------
    control.NonlinearIOSystem
        States, inputs and outputs named by column (``bearing_position_m``).

    Raises
    ------
    ParameterError
        A system with algebraic rows (mass 0).
    """
    import control

    if np.any(system.mass != 1.0):
        raise ParameterError(f"{system.name}: a mass matrix other than the identity (algebraic rows) cannot be "
                             "a python-control NonlinearIOSystem; use linearize() for its linear model")
    m = (op.m if op is not None else system.m0).copy()
    outs = _signals(system, outputs, ("state", "output"), [v.name for v in system.outputs])

    def update(t, x, u, params):
        return evaluate(system, t, np.asarray(x, float), np.atleast_1d(np.asarray(u, float)), m)[0]

    def output(t, x, u, params):
        x = np.asarray(x, float)
        y = evaluate(system, t, x, np.atleast_1d(np.asarray(u, float)), m)[2]
        return np.array([x[i] if kind == "state" else y[i] for kind, i in outs])

    return control.nlsys(update, output, states=[signal_name(c) for c in system.state_columns],
                         inputs=[signal_name(c) for c in system.input_columns],
                         outputs=[signal_name((system.states if k == "state" else system.outputs)[i].column)
                                  for k, i in outs],
                         name=name or system.name)


def frequency_table(sys, frequencies_hz, *, over: str | None = None) -> "pandas.DataFrame":  # noqa: F821
    """Magnitude and phase of every input-output pair of a linear model (a Bode table).

    Parameters
    ----------
    sys : control.StateSpace or control.TransferFunction
        The linear model (e.g. from :func:`linearize`).
    frequencies_hz : array_like
        Frequencies [Hz].
    over : str, optional
        An output of ``sys`` (e.g. ``"motor_current_A"``): every other output's response is divided by
        this one's, for the model's single input (pressure per motor current from the voltage-driven
        actuator: how the pressure follows the current, with the line and the clutch in between).

    Returns
    -------
    pandas.DataFrame
        ``frequency_Hz``, then per pair ``gain_<out>__<in>`` (output unit per input unit; with ``over``
        the pairs are ``<out>__<over>``), ``gain_dB_<out>__<in>`` and ``phase_deg_<out>__<in>`` (unwrapped:
        continuous over the frequencies, the first one's phase in [-270, 90) degrees).
    """
    import pandas as pd

    f = np.asarray(frequencies_hz, dtype=float)
    if f.ndim != 1 or f.size == 0 or not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ParameterError("frequencies_hz must be a non-empty vector of positive frequencies [Hz]")
    w = 2 * np.pi * f
    resp = sys(1j * w) if sys.ninputs * sys.noutputs > 1 else np.reshape(sys(1j * w), (1, 1, -1))
    resp = np.reshape(resp, (sys.noutputs, sys.ninputs, -1))
    outs, ins = list(sys.output_labels), list(sys.input_labels)
    if over is not None:
        over = over if over in outs else signal_name(over)   # (a result column: clutch1.tau_Nm)
        if over not in outs:
            raise ParameterError(f"over = {over!r} is not an output of the model ({', '.join(outs)})")
        if sys.ninputs != 1:
            raise ParameterError(f"over = {over!r} needs a model with one input, not {sys.ninputs}")
        k = outs.index(over)
        keep = [i for i in range(len(outs)) if i != k]
        resp = resp[keep] / resp[k][None]
        outs, ins = [outs[i] for i in keep], [over]
    cols = {"frequency_Hz": f}
    for i, o in enumerate(outs):
        for j, n in enumerate(ins):
            g = resp[i, j]
            cols[f"gain_{o}__{n}"] = np.abs(g)
            cols[f"gain_dB_{o}__{n}"] = 20 * np.log10(np.maximum(np.abs(g), 1e-300))
            # continuous, its first point in [-270, 90) deg: a lag of an integrator chain or a sign reads as one
            # (-180, not +180), a lead up to a differentiator's +90 as one
            phase = np.degrees(np.unwrap(np.angle(g)))
            cols[f"phase_deg_{o}__{n}"] = phase - 360.0 * np.floor((phase[0] + 270.0) / 360.0)
    return pd.DataFrame(cols)


def pole_sweep(points, inputs=None, outputs=None, *, directions: dict | None = None,
               name: str = "value") -> "pandas.DataFrame":  # noqa: F821
    """Poles of the linear models at a series of operating points (a pole map over an operating range).

    Parameters
    ----------
    points : sequence of (float, OperatingPoint)
        The swept value (e.g. the bearing position [m]) and the operating point there.
    inputs, outputs : sequence of str, optional
        As :func:`linearize`.
    directions : dict, optional
        Hysteresis branches, as :func:`linearize`.
    name : str
        Column name of the swept value (with its unit, ``bearing_position_m``).

    Returns
    -------
    pandas.DataFrame
        One row per pole: ``name``, ``pole_real_1_s``, ``pole_imag_1_s`` [1/s], ``natural_frequency_Hz``,
        ``damping_1``.
    """
    import pandas as pd

    rows = []
    for value, op in points:
        A = reduced_matrices(op, inputs=inputs, outputs=outputs, directions=directions).A   # (also without inputs)
        for p in np.linalg.eigvals(A) if A.size else []:
            wn = abs(p)
            rows.append({name: float(value), "pole_real_1_s": float(p.real), "pole_imag_1_s": float(p.imag),
                         "natural_frequency_Hz": wn / (2 * np.pi),
                         "damping_1": float(-p.real / wn) if wn > 0 else 1.0})
    return pd.DataFrame(rows)


def loop_margins(loops) -> "pandas.DataFrame":  # noqa: F821
    """Stability margins and the Nyquist criterion of open loops ``L = C G`` (SISO), one row per loop.

    Parameters
    ----------
    loops : sequence of (str, control.LTI)
        Label and open-loop transfer (e.g. ``control.ss(pi.tf()) * G``; negative feedback around it).

    Returns
    -------
    pandas.DataFrame
        ``loop``; ``gain_margin_dB`` (inf: none), ``phase_crossover_Hz`` (where the phase is -180°);
        ``phase_margin_deg``, ``crossover_Hz`` (where ``|L| = 1``); ``stability_margin_1`` (the least
        ``|1 + L(jw)|``, the distance of the Nyquist curve from -1); ``open_loop_rhp_poles_1`` (P);
        ``encirclements_1`` (N, clockwise encirclements of -1 by the Nyquist curve, python-control's
        ``nyquist_response``); ``closed_loop_rhp_poles_1`` (Z, counted from the closed loop's poles) and
        ``nyquist_consistent_1`` (1 if Z = N + P: the two counts agree).
    """
    import control
    import pandas as pd

    rows = []
    for label, L in loops:
        if L.ninputs != 1 or L.noutputs != 1:
            raise ParameterError(f"loop {label!r}: {L.ninputs} inputs and {L.noutputs} outputs; a loop has one each")
        gm, pm, sm, w_pc, w_gc, _ = control.stability_margins(L)
        # (a pole on the imaginary axis, an integrator, is passed on the right by the Nyquist contour: not counted)
        poles, cl = L.poles(), control.feedback(L, 1).poles()
        p = int(np.sum(np.real(poles) > 1e-9 * np.maximum(1.0, np.abs(poles))))
        z = int(np.sum(np.real(cl) > 1e-9 * np.maximum(1.0, np.abs(cl))))
        n = int(control.nyquist_response(L, warn_encirclements=False, warn_nyquist=False).count)
        rows.append({"loop": label, "gain_margin_dB": 20 * np.log10(gm) if np.isfinite(gm) and gm > 0 else np.inf,
                     "phase_crossover_Hz": w_pc / (2 * np.pi), "phase_margin_deg": pm,
                     "crossover_Hz": w_gc / (2 * np.pi), "stability_margin_1": sm, "open_loop_rhp_poles_1": p,
                     "encirclements_1": n, "closed_loop_rhp_poles_1": z, "nyquist_consistent_1": int(z == n + p)})
    return pd.DataFrame(rows)


def write_linear_model(sys, path, *, force: bool = False) -> Path:
    """Write a linear model's matrices with their names and units: JSON (``.json``) or CSV (``.csv``).

    Parameters
    ----------
    sys : control.StateSpace
        From :func:`linearize` (its operating point and mode are written too).
    path : str or Path
        ``*.json``: one document (matrices, names, units, operating point, mode); ``*.csv``: one table,
        rows ``A``/``B``/``C``/``D`` with their row and column names.
    force : bool
        Replace an existing file.

    Returns
    -------
    Path
    """
    from ..io.files import atomic_write_text, check_writable

    path = Path(path)
    check_writable(path, force)
    units = getattr(sys, "units", {})
    states, ins, outs = list(sys.state_labels), list(sys.input_labels), list(sys.output_labels)
    if path.suffix.lower() == ".json":
        op = getattr(sys, "operating_point", None)
        doc = {"name": sys.name, "states": states, "inputs": ins, "outputs": outs, "units": units,
               "columns": getattr(sys, "columns", {}),
               "mode": getattr(sys, "mode", {}), "directions": getattr(sys, "directions", {}), "A": np.asarray(sys.A).tolist(), "B": np.asarray(sys.B).tolist(),
               "C": np.asarray(sys.C).tolist(), "D": np.asarray(sys.D).tolist(),
               "operating_point": op.to_dict() if op is not None else None}
        atomic_write_text(path, json.dumps(doc, indent=1), overwrite=force)
    elif path.suffix.lower() == ".csv":
        lines = ["matrix,row,column,value"]
        for mname, M, rows, cols in (("A", sys.A, states, states), ("B", sys.B, states, ins),
                                     ("C", sys.C, outs, states), ("D", sys.D, outs, ins)):
            M = np.asarray(M)
            for i, r in enumerate(rows):
                for j, c in enumerate(cols):
                    lines.append(f"{mname},{r},{c},{float(M[i, j])!r}")
        atomic_write_text(path, "\n".join(lines) + "\n", overwrite=force)
    else:
        raise ParameterError(f"{path}: write a linear model as .json or .csv, not {path.suffix!r}")
    return path
