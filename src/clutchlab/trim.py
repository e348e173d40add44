"""Operating points: the steady state of a system for given inputs, or the inputs that hold given outputs (trim).

Written against the system contract (:func:`clutchlab.system.evaluate`): the right-hand side ``f(t, x, u, m)``
of any model, at fixed modes ``m`` (a hybrid model is trimmed within one mode: stuck or sliding, in contact
or not).  The conditions are

* ``f_i(t, x, u, m) = 0`` for every state ``i`` that must be steady: all states but the *held* ones
  (``states=``, kept at their given values: a slow temperature, a shaft speed set by a bench) and the
  *monitors* (states nothing depends on: energy integrals, a free shaft angle; and states the active mode
  holds still, whose derivative is zero whatever the state: an armature at its stop), which keep their
  values;
  algebraic rows (mass 0) are part of the conditions;
* ``y_k(t, x, u, m) = r_k`` for every target (``targets=``: a state or an output), each paid for by one
  unknown input (``free_inputs=``) or by one held state left free.

They are solved by Newton's method with a central-difference Jacobian in scaled unknowns (each state by
its typical magnitude, ``max(|x|, fd_scale, atol / rtol)``; each input by its range) and a halving line
search; converged when every condition is below ``tol`` times the change one unit of scaled unknowns
makes in it.  A point outside the system's physical range (:attr:`clutchlab.system.System.limits`: the
CSC travel, the supply voltage) is refused, as is a steady state that is not unique in the chosen modes
(a stuck friction element leaves its position free: trim it in a sliding mode).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .errors import ClutchlabError, ParameterError
from .system import Simulation, System, evaluate

__all__ = ["OperatingPoint", "operating_point", "OperatingPointError", "resolve"]


class OperatingPointError(ClutchlabError, ValueError):
    """No steady state with the requested inputs or targets (outside the travel, beyond a limit, not converged)."""


def resolve(system: System, name: str, kinds=("state", "output")) -> tuple[str, int]:
    """Which variable ``name`` (``"bearing_position"`` or its column ``"bearing_position_m"``) is.

    Parameters
    ----------
    system : System
        The system whose variables are searched.
    name : str
        Variable name, with or without its unit suffix, or its signal in a linear model
        (:func:`clutchlab.control.linear.signal_name`: ``clutch1_tau_Nm`` for ``clutch1.tau_Nm``).
    kinds : tuple of str
        Kinds searched in order (``"state"``, ``"output"``, ``"input"``).

    Returns
    -------
    (kind, index)

    Raises
    ------
    ParameterError
        Unknown name (the message lists the known ones).
    """
    tables = {"state": system.states, "output": system.outputs, "input": system.inputs}
    for kind in kinds:
        for i, v in enumerate(tables[kind]):
            if name in (v.name, v.column):
                return kind, i
    for kind in kinds:   # a linear model's signal name (a driveline's clutch1_tau_Nm for clutch1.tau_Nm)
        for i, v in enumerate(tables[kind]):
            if "." in v.column and name == v.column.replace(".", "_"):
                return kind, i
    known = [v.column for kind in kinds for v in tables[kind]]
    raise ParameterError(f"{system.name}: unknown {'/'.join(kinds)} {name!r}; known: {', '.join(known)}")


@dataclasses.dataclass(frozen=True)
class OperatingPoint:
    """A steady state of a system: time, state, held inputs and modes.

    Attributes
    ----------
    system : System
        The system it belongs to.
    t : float
        Time [s] (models with time-dependent profiles are trimmed at this instant).
    x, u : ndarray
        State and held inputs [SI].
    m : ndarray of int
        Modes (the hybrid model's active mode: linearisation keeps it).
    held : tuple of str
        States kept at given values (not required steady).
    monitors : tuple of str
        States nothing depends on (energy integrals), and states the active mode holds still (derivative
        zero whatever the state: the EMTC's armature at its stop): not required steady, kept at their
        values.
    residual : float
        Largest scaled steady-state condition at the solution (see the module docstring).
    iterations : int
        Newton iterations.
    """

    system: System
    t: float
    x: np.ndarray
    u: np.ndarray
    m: np.ndarray
    held: tuple = ()
    monitors: tuple = ()
    residual: float = 0.0
    iterations: int = 0

    @property
    def modes(self) -> dict:
        """Active mode: ``{mode variable: value name}``."""
        s = self.system
        out = {}
        for k, name in enumerate(s.mode_names):
            values = s.mode_values[k] if k < len(s.mode_values) else ()
            v = int(self.m[k])
            out[name] = values[v] if 0 <= v < len(values) else str(v)
        return out

    def values(self) -> dict:
        """States, inputs and outputs at the point, by column name (``bearing_position_m``) [SI]."""
        dx, g, y = evaluate(self.system, self.t, self.x, self.u, self.m)
        s = self.system
        out = {f"state.{c}": float(v) for c, v in zip(s.state_columns, self.x)}
        out.update({f"input.{c}": float(v) for c, v in zip(s.input_columns, self.u)})
        out.update({f"output.{c}": float(v) for c, v in zip(s.output_columns, y)})
        return out

    def value(self, name: str) -> float:
        """One state, output or input at the point [SI] (``"bearing_position"`` or ``"bearing_position_m"``)."""
        kind, i = resolve(self.system, name, ("state", "output", "input"))
        if kind == "state":
            return float(self.x[i])
        if kind == "input":
            return float(self.u[i])
        return float(evaluate(self.system, self.t, self.x, self.u, self.m)[2][i])

    def start(self) -> System:
        """The system started at this point (initial state, held inputs and modes replaced).

        Each call gives the system its own copy of the point's parameter arrays: memories a model keeps
        there (the EMTC magnet's hysteresis memory, a lock-up time) start as they were at the point, and a
        run from one start does not change the next.
        """
        return self.system.variant(params=own_memories(self.system.params), x0=self.x, m0=self.m, u0=self.u)

    def to_dict(self) -> dict:
        """Plain description (JSON): time, modes, every state, input and output with its unit."""
        return {"model": self.system.name, "time_s": float(self.t), "modes": self.modes,
                "held_states": list(self.held), "monitor_states": list(self.monitors),
                "residual_1": float(self.residual), **self.values()}


def _set_modes(system: System, m: np.ndarray, modes: dict | None) -> np.ndarray:
    m = m.copy()
    for name, value in (modes or {}).items():
        if name not in system.mode_names:
            raise ParameterError(f"{system.name}: unknown mode variable {name!r}; known: "
                                 f"{', '.join(system.mode_names)}")
        k = system.mode_names.index(name)
        values = system.mode_values[k]
        if isinstance(value, str):
            if value not in values:
                raise ParameterError(f"{system.name}: mode {name} = {value!r}; expected one of {', '.join(values)}")
            m[k] = values.index(value)
        else:
            m[k] = int(value)
    return m


def state_scale(system: System, x: np.ndarray) -> np.ndarray:
    """Typical magnitude of each state [SI]: ``max(|x|, fd_scale, atol / rtol)`` (scaling and difference steps)."""
    return np.maximum.reduce([np.abs(x), system.fd_scale, system.atol / system.rtol, np.full(x.shape, 1e-300)])


def input_scale(system: System, u: np.ndarray) -> np.ndarray:
    """Typical magnitude of each held input [SI]: half its range in ``limits``, else ``max(|u|, 1)``."""
    scale = np.maximum(np.abs(u), 1.0)
    for i, v in enumerate(system.inputs):
        lim = system.limits.get(v.name)
        if lim is not None and np.isfinite(lim[1] - lim[0]):
            scale[i] = max(abs(u[i]), 0.5 * (lim[1] - lim[0]))
    return scale


def _check_limits(system: System, what: dict, where: str) -> None:
    for name, value in what.items():
        lim = system.limits.get(name)
        if lim is None:
            continue
        lo, hi = lim
        span = hi - lo
        if not (lo - 1e-9 * span <= value <= hi + 1e-9 * span):
            raise OperatingPointError(f"{system.name}: {where} {name} = {value:.6g} is outside its physical range "
                                      f"[{lo:.6g}, {hi:.6g}] (System.limits)")


def own_memories(params):
    """A copy of ``params`` with its own copy of every C-contiguous array (NamedTuples and tuples rebuilt,
    numbers and other arrays shared): the memories a model keeps in its parameters, as they are."""
    if isinstance(params, np.ndarray):
        return params.copy() if params.flags.c_contiguous else params
    if isinstance(params, tuple):
        parts = [own_memories(q) for q in params]
        return type(params)(*parts) if hasattr(params, "_fields") else tuple(parts)
    return params


def _zero_columns(system, t, x, u, m, h):
    """``(monitors, frozen)`` as boolean masks over the states, bit for bit.

    Monitors: states nothing depends on (perturbing them changes no derivative).  Frozen: states the
    active mode holds still -- their derivative is exactly zero at the point and stays so whichever state
    is perturbed (an armature at its stop)."""
    out = np.zeros(x.size, dtype=bool)
    still = evaluate(system, t, x, u, m)[0] == 0.0
    for j in range(x.size):
        xp, xm = x.copy(), x.copy()
        xp[j] += h[j]
        xm[j] -= h[j]
        fp, _, yp = evaluate(system, t, xp, u, m)
        fm, _, ym = evaluate(system, t, xm, u, m)
        # its own row may depend on itself only through a rate it does not feed back (none here)
        others = np.arange(x.size) != j
        out[j] = bool(np.all(fp[others] == fm[others]) and fp[j] == fm[j])
        still &= (fp == 0.0) & (fm == 0.0)
    return out, still


def operating_point(system: System, *, inputs: dict | None = None, states: dict | None = None,
                    targets: dict | None = None, free_inputs=(), free_states=(), modes: dict | None = None,
                    t: float = 0.0, guess=None, settle: float = 0.0, tol: float = 1e-10,
                    max_iterations: int = 60) -> OperatingPoint:
    """Steady state of ``system`` (trim): for given inputs, or the inputs that hold given outputs.

    Parameters
    ----------
    system : System
        Any model's system (its held inputs are the operating inputs: build it with held inputs, e.g.
        ``EClutch().as_system({"voltage": 0.0}, held_input=True)``).
    inputs : dict, optional
        Held input values ``{name: value}`` [SI]; the others keep ``system.u0``.
    states : dict, optional
        States held at given values (not required steady): ``{"omega_f": 120.0}``.
    targets : dict, optional
        Required values of states or outputs ``{"bearing_position": 4e-3}`` [SI].
    free_inputs : sequence of str
        Inputs solved for (one per target, unless ``free_states`` pays for some).
    free_states : sequence of str
        Held states solved for nonetheless (listed in ``states`` as a start value).
    modes : dict, optional
        Mode of a hybrid model ``{mode variable: value name}`` (default: the system's initial modes, or
        those after ``settle``).
    t : float
        Time [s].
    guess : array_like, optional
        Starting state (default: ``system.x0``).
    settle : float
        Simulate this long [s] from the guess with the inputs held before Newton's method (a start near
        a stable steady state; the modes are those reached).
    tol : float
        Convergence bound on the scaled conditions.
    max_iterations : int
        Newton iterations allowed.

    Returns
    -------
    OperatingPoint

    Raises
    ------
    ParameterError
        Unknown names, or as many conditions as unknowns are not given.
    OperatingPointError
        A target or input outside the system's limits; no convergence; a solution outside the limits; a
        steady state that is not unique in the chosen mode.
    """
    inputs, states, targets = dict(inputs or {}), dict(states or {}), dict(targets or {})
    t = float(t)
    if not math.isfinite(t):
        raise ParameterError(f"{system.name}: t = {t!r}: the time of the operating point must be finite [s]")
    if not (math.isfinite(float(settle)) and float(settle) >= 0.0):
        raise ParameterError(f"{system.name}: settle = {settle!r}: must be a time >= 0 [s] (#33: a negative one "
                             "was ignored)")
    u = system.u0.copy()
    for name, value in inputs.items():
        _, i = resolve(system, name, ("input",))
        u[i] = float(value)
    # work on an own copy of the memories a model keeps in its parameters: the settle and Newton's method
    # change them there, not in the caller's system
    system = system.variant(params=own_memories(system.params))
    x = system.x0.copy() if guess is None else np.array(guess, dtype=float).ravel()
    if x.shape != system.x0.shape:
        raise ParameterError(f"{system.name}: guess has {x.size} entries, the system {system.x0.size} states")
    m = _set_modes(system, system.m0, modes)
    held = []
    for name, value in states.items():
        _, i = resolve(system, name, ("state",))
        x[i] = float(value)
        held.append(i)
    tgt = []
    for name, value in targets.items():
        kind, i = resolve(system, name, ("state", "output"))
        tgt.append((kind, i, float(value)))
    _check_limits(system, {system.inputs[i].name: u[i] for i in range(u.size)}, "input")
    _check_limits(system, {(system.states if k == "state" else system.outputs)[i].name: v for k, i, v in tgt},
                  "target")
    _check_limits(system, {system.states[i].name: x[i] for i in held}, "held state")
    fin = [resolve(system, name, ("input",))[1] for name in free_inputs]
    if settle > 0.0:
        sim = Simulation(system.variant(x0=x, m0=m, u0=u), t0=t)
        sim.advance(t + float(settle))
        x, m = sim.x.copy(), _set_modes(system, sim.m, modes)
        for i in held:
            x[i] = states[system.states[i].name] if system.states[i].name in states else \
                states[system.states[i].column]
    xs = state_scale(system, x)
    us = input_scale(system, u)
    target_states = {i for k, i, _ in tgt if k == "state"}
    zero, still = _zero_columns(system, t, x, u, m, 1e-6 * xs)
    monitors = [j for j in range(x.size) if zero[j] and j not in held and j not in target_states]
    frozen = [j for j in range(x.size) if still[j] and not zero[j] and j not in held and j not in target_states]
    monitors += frozen
    freed = [resolve(system, name, ("state",))[1] for name in free_states]
    for j in freed:
        if j not in held:
            raise ParameterError(f"{system.name}: free state {system.states[j].name!r} is not a held state "
                                 "(free_states frees states given in states=)")
    steady = [j for j in range(x.size) if j not in held and j not in monitors]
    unknown_x = steady + freed
    n_unknown = len(unknown_x) + len(fin)
    n_cond = len(steady) + len(tgt)
    if n_unknown != n_cond:
        raise ParameterError(
            f"{system.name}: {n_cond} conditions ({len(steady)} steady states, {len(tgt)} targets) but "
            f"{n_unknown} unknowns ({len(unknown_x)} states, {len(fin)} free inputs): give one free input "
            "(free_inputs=) or freed state (free_states=) per target")
    scale = np.concatenate([xs[unknown_x], us[fin]])
    ix = np.array(unknown_x, dtype=np.int64)
    iu = np.array(fin, dtype=np.int64)
    ts = np.array([max(abs(v), 1e-300) for _, _, v in tgt])

    def point(z):
        xx, uu = x.copy(), u.copy()
        xx[ix] = z[:ix.size] * scale[:ix.size]
        uu[iu] = z[ix.size:] * scale[ix.size:]
        return xx, uu

    def conditions(z, goal):
        xx, uu = point(z)
        dx, _, y = evaluate(system, t, xx, uu, m)
        r = np.empty(n_cond)
        r[:len(steady)] = dx[steady]
        for q, (kind, i, _) in enumerate(tgt):
            r[len(steady) + q] = (xx[i] if kind == "state" else y[i]) - goal[q]
        return r

    def jac(z, goal):
        J = np.empty((n_cond, z.size))
        for j in range(z.size):
            h = 1e-6 * max(1.0, abs(z[j]))
            zp, zm = z.copy(), z.copy()
            zp[j] += h
            zm[j] -= h
            J[:, j] = (conditions(zp, goal) - conditions(zm, goal)) / (2 * h)
        return J

    goal = np.array([v for _, _, v in tgt])
    z = np.concatenate([x[ix] / scale[:ix.size], u[iu] / scale[ix.size:]])
    if n_cond == 0:
        return OperatingPoint(system.variant(params=own_memories(system.params)), t, x, u, m,
                              tuple(system.states[i].name for i in held),
                              tuple(system.states[i].name for i in monitors), 0.0, 0)
    J0 = jac(z, goal)
    weight = np.sum(np.abs(J0), axis=1)
    weight[len(steady):] = np.maximum(weight[len(steady):], 1.0 / ts)  # a target: relative to its value
    weight = np.where(weight > 0, weight, 1.0)

    def norm(r_):
        return float(np.max(np.abs(r_) / weight)) if np.all(np.isfinite(r_)) else np.inf

    def newton(z, goal, iterations):
        r = conditions(z, goal)
        res = norm(r)
        it = 0
        while res > tol and it < iterations:
            it += 1
            J = jac(z, goal)
            if not np.all(np.isfinite(J)):
                break
            try:
                dz = np.linalg.solve(J, -r)
            except np.linalg.LinAlgError:
                dz = np.linalg.lstsq(J, -r, rcond=None)[0]
            lam, z_new, r_new, res_new = 1.0, z, r, res
            for _ in range(30):
                z_new = z + lam * dz
                r_new = conditions(z_new, goal)
                res_new = norm(r_new)
                if res_new < res:
                    break
                lam *= 0.5
            if not res_new < res:
                break
            z, r, res = z_new, r_new, res_new
        return z, r, res, it

    z1, r, res, it = newton(z, goal, max_iterations)
    if not res <= tol and tgt:
        # continuation: solve with the targets at their values at the start (the start's own steady state),
        # then move them towards the goal in steps, each started from the last solution
        start = np.array([(x[i] if kind == "state" else evaluate(system, t, x, u, m)[2][i]) for kind, i, _ in tgt])
        zc, _, resc, total = newton(z, start, max_iterations)
        lam, step = 0.0, 0.1
        while resc <= tol and lam < 1.0 and step > 1e-4 and total < 20 * max_iterations:
            trial = min(1.0, lam + step)
            zt, _, rest, itt = newton(zc, start + trial * (goal - start), 12)
            total += itt
            if rest <= tol:
                zc, lam, step = zt, trial, min(2 * step, 0.5)
            else:
                step *= 0.5
        if lam >= 1.0:
            z1, r, res, it = zc, conditions(zc, goal), norm(conditions(zc, goal)), total
    z = z1
    xx, uu = point(z)
    if not res <= tol:
        worst = int(np.argmax(np.abs(r) / weight)) if r.size else 0
        what = (system.states[steady[worst]].name + " not steady" if worst < len(steady)
                else f"target {list(targets)[worst - len(steady)]} missed")
        raise OperatingPointError(
            f"{system.name}: no steady state found with {_describe(inputs, targets)} in mode "
            f"{_mode_text(system, m)} after {it} Newton iterations (scaled residual {res:.3g}, {what}); "
            "start nearer (guess=, settle=) or choose another mode (modes=)")
    J = jac(z, goal)
    cond = np.linalg.cond(J / weight[:, None]) if J.size else 1.0
    if not cond < 1e12:
        raise OperatingPointError(
            f"{system.name}: the steady state with {_describe(inputs, targets)} is not unique in mode "
            f"{_mode_text(system, m)} (condition number {cond:.3g}): a stuck friction element or a free "
            "integrator leaves a state undetermined; choose a sliding mode (modes=) or hold that state (states=)")
    _, _, y = evaluate(system, t, xx, uu, m)
    _check_limits(system, {v.name: xx[i] for i, v in enumerate(system.states)}, "steady state")
    _check_limits(system, {v.name: uu[i] for i, v in enumerate(system.inputs)}, "input")
    _check_limits(system, {v.name: y[i] for i, v in enumerate(system.outputs)}, "output")
    # the point keeps the memories as they are now (its own copy: later runs of `system` leave them)
    return OperatingPoint(system.variant(params=own_memories(system.params)), t, xx, uu, m.copy(),
                          tuple(system.states[i].name for i in held),
                          tuple(system.states[i].name for i in monitors), res, it)


def _describe(inputs: dict, targets: dict) -> str:
    parts = [f"{k} = {v:.6g}" for k, v in {**inputs, **targets}.items()]
    return ", ".join(parts) if parts else "the system's inputs"


def _mode_text(system: System, m) -> str:
    if not system.mode_names:
        return "(no modes)"
    return "{" + ", ".join(f"{n}: {OperatingPoint(system, 0.0, system.x0, system.u0, m).modes[n]}"
                           for n in system.mode_names) + "}"
