"""Describe a one-dimensional driveline network in Python and run it on the integrator core.

::

    from clutchlab.driveline import Driveline, Signal

    d = Driveline("test_friction")
    d.inertia("inertia", J=1.0)
    d.torque("torque", "inertia", Signal.sine(amplitude=10.0, frequency=1.0))
    d.bearing_friction("bearing_friction", "inertia", torque=1.0)
    result = d.simulate(1.1, output_step=1e-3)
    result.events            # time_s, event (stick / forward / backward / free), element

Every component has a unique name; flanges are named by their inertia (``None`` or ``"ground"`` is the
fixed ground).  Quantities are SI (kg m^2, N m/rad, N m s/rad, N, rad/s, N m).  The friction semantics
are those of the Modelica Standard Library (MSL 4.x, :mod:`clutchlab.driveline.kernel`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._limits import check_number
from ..errors import ParameterError
from ..system import System, register_model, simulate as _simulate
from . import kernel as K

__all__ = ["Driveline", "Signal", "GROUND"]

GROUND = "ground"


def _finite(component, name, value, *, positive=False, nonneg=False):
    return check_number(f"{component}: {name}", value, positive=positive, nonnegative=nonneg)


@dataclass(frozen=True)
class Signal:
    """A time signal as in ``Modelica.Blocks.Sources``: constant, step, ramp, sine or a table.

    Build with the class methods; a plain number is a constant.

    Parameters
    ----------
    row : tuple
        The kind (``kernel.SIG_*``) and its parameters.
    points : tuple
        The breakpoints of a table signal: times, then values.
    """

    row: tuple
    points: tuple = ()

    @classmethod
    def constant(cls, value: float) -> "Signal":
        """``value`` at all times."""
        return cls((K.SIG_CONST, _finite("signal", "value", value)))

    @classmethod
    def step(cls, height: float = 1.0, start: float = 0.0, offset: float = 0.0) -> "Signal":
        """``offset`` before ``start`` [s], ``offset + height`` from it (MSL ``Step``)."""
        return cls((K.SIG_STEP, _finite("step", "height", height), _finite("step", "start", start),
                    _finite("step", "offset", offset)))

    @classmethod
    def ramp(cls, height: float, duration: float, start: float = 0.0, offset: float = 0.0) -> "Signal":
        """Linear from ``offset`` at ``start`` to ``offset + height`` after ``duration`` [s] (MSL ``Ramp``)."""
        return cls((K.SIG_RAMP, _finite("ramp", "height", height), _finite("ramp", "duration", duration, positive=True),
                    _finite("ramp", "start", start), _finite("ramp", "offset", offset)))

    @classmethod
    def sine(cls, amplitude: float, frequency: float, phase: float = 0.0, offset: float = 0.0,
             start: float = 0.0) -> "Signal":
        """``offset + amplitude sin(2 pi f (t - start) + phase)`` from ``start`` [s], ``offset`` before (MSL ``Sine``)."""
        return cls((K.SIG_SINE, _finite("sine", "amplitude", amplitude), _finite("sine", "frequency", frequency, nonneg=True),
                    _finite("sine", "phase", phase), _finite("sine", "offset", offset), _finite("sine", "start", start)))

    @classmethod
    def table(cls, times, values) -> "Signal":
        """Piecewise linear through ``(times [s], values)``, held beyond the ends."""
        t = np.asarray(times, dtype=float).ravel()
        v = np.asarray(values, dtype=float).ravel()
        if t.size < 1 or t.size != v.size or not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
            raise ParameterError(f"table signal: times and values need the same non-zero length and finite values "
                                 f"({t.size} times, {v.size} values)")
        if t.size > 1 and np.any(np.diff(t) <= 0):
            raise ParameterError("table signal: times must be strictly increasing")
        return cls((K.SIG_TABLE,), tuple(t) + tuple(v))

    def describe(self, unit: str = "") -> str:
        """One line for people: ``sine 10 N m at 5 Hz``, ``step to 1 at 0.4 s`` (``unit``: of the values)."""
        k, *a = self.row
        u = f" {unit}" if unit else ""
        if k == K.SIG_CONST:
            return f"{a[0]:g}{u}"
        if k == K.SIG_STEP:
            return f"step from {a[2]:g} to {a[2] + a[0]:g}{u} at {a[1]:g} s"
        if k == K.SIG_RAMP:
            return f"ramp from {a[3]:g} to {a[3] + a[0]:g}{u} over {a[2]:g} s from {a[1]:g} s"
        if k == K.SIG_SINE:
            off = f"{a[3]:g} + " if a[3] else ""
            return f"{off}{a[0]:g}{u} sine at {a[1]:g} Hz, phase {a[2]:g} rad" + (f", from {a[4]:g} s" if a[4] else "")
        n = len(self.points) // 2
        return f"table of {n} points from {self.points[0]:g} to {self.points[n - 1]:g} s"

    @classmethod
    def of(cls, value, what: str) -> "Signal":
        """``value`` as a signal: a :class:`Signal` as it is, a number as a constant."""
        if isinstance(value, Signal):
            return value
        if isinstance(value, (int, float, np.floating)) and not isinstance(value, bool):
            return cls.constant(value)
        raise ParameterError(f"{what} = {value!r}: expected a number or a Signal")


@dataclass
class _Element:
    kind: int
    name: str
    a: str | None
    b: str | None
    coef: tuple = (0.0, 0.0, 0.0)
    law: int = 0
    signal: Signal | None = None
    table: tuple = ()   # friction characteristic: speeds [rad/s], then values


class Driveline:
    """A driveline network: inertias, spring-dampers, torque sources and friction elements.

    Parameters
    ----------
    name : str
        Name of the model (shown in results and errors).
    """

    def __init__(self, name: str = "driveline"):
        self.name = str(name)
        self._inertias: dict = {}
        self._elements: list = []

    # ---- components
    def _new_name(self, name):
        if not isinstance(name, str) or not name or not name.replace("_", "").isalnum():
            raise ParameterError(f"{self.name}: component name {name!r} must be letters, digits and underscores")
        if name == GROUND or name in self._inertias or any(e.name == name for e in self._elements):
            raise ParameterError(f"{self.name}: component name {name!r} is used twice")
        return name

    def _flange(self, component, which, flange):
        if flange is None or flange == GROUND:
            return None
        if flange not in self._inertias:
            known = ", ".join(self._inertias) or "none"
            raise ParameterError(f"{component}: {which} = {flange!r} is not an inertia of {self.name!r} "
                                 f"(inertias: {known}; 'ground' for the fixed ground)")
        return flange

    def _two(self, name, a, b):
        a = self._flange(name, "flange a", a)
        b = self._flange(name, "flange b", b)
        if a == b:
            raise ParameterError(f"{name}: both flanges are {a or GROUND!r} (an element needs two different flanges)")
        return a, b

    def inertia(self, name: str, J: float, w0: float = 0.0, phi0: float = 0.0) -> "Driveline":
        """A rigid inertia ``J`` [kg m^2] starting at angle ``phi0`` [rad] and speed ``w0`` [rad/s]."""
        name = self._new_name(name)
        self._inertias[name] = (_finite(name, "J", J, positive=True), _finite(name, "w0", w0),
                                _finite(name, "phi0", phi0))
        return self

    def spring_damper(self, name: str, a, b, c: float = 0.0, d: float = 0.0, phi_rel0: float = 0.0) -> "Driveline":
        """Spring ``c`` [N m/rad] and damper ``d`` [N m s/rad] in parallel between flanges a and b
        (``tau = c (phi_b - phi_a - phi_rel0) + d (w_b - w_a)``)."""
        name = self._new_name(name)
        a, b = self._two(name, a, b)
        self._elements.append(_Element(K.K_SPRING, name, a, b, (_finite(name, "c", c, nonneg=True),
                                                                 _finite(name, "d", d, nonneg=True),
                                                                 _finite(name, "phi_rel0", phi_rel0))))
        return self

    def torque(self, name: str, flange, signal, support=None) -> "Driveline":
        """A torque source [N m] accelerating ``flange`` (its reaction on ``support``, default the ground)."""
        name = self._new_name(name)
        b = self._flange(name, "flange", flange)
        if b is None:
            raise ParameterError(f"{name}: a torque source needs an inertia as its flange, not the ground")
        a = self._flange(name, "support", support)
        if a == b:
            raise ParameterError(f"{name}: flange and support are both {a!r}")
        self._elements.append(_Element(K.K_SOURCE, name, a, b, signal=Signal.of(signal, f"{name}: torque")))
        return self

    def _friction(self, name, a, b, law, table, peak, fn_max=1.0, cgeo=1.0, normal=None):
        peak = _finite(name, "peak", peak)
        if peak < 1.0:
            raise ParameterError(f"{name}: peak = {peak!r} must be >= 1 (static limit = peak x sliding torque at rest)")
        coef = (_finite(name, "fn_max", fn_max, nonneg=True), _finite(name, "cgeo", cgeo, nonneg=True), peak)
        sig = None if normal is None else Signal.of(normal, f"{name}: normal")
        self._elements.append(_Element(K.K_FRICTION, name, a, b, coef, law, sig, table))
        return self

    @staticmethod
    def _characteristic(name, what, value):
        """A constant or a table ``[[w, value], ...]`` (w >= 0 increasing) as (speeds, values)."""
        if isinstance(value, (int, float, np.floating)) and not isinstance(value, bool):
            return (0.0, _finite(name, what, value, nonneg=True))
        arr = np.asarray(value, dtype=float)
        if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 1 or not np.all(np.isfinite(arr)):
            raise ParameterError(f"{name}: {what} must be a number or a table of rows [w_rad_s, value]")
        if arr[0, 0] != 0.0 or np.any(np.diff(arr[:, 0]) <= 0) or np.any(arr[:, 1] < 0):
            raise ParameterError(f"{name}: {what} table must start at w = 0, increase in w and be >= 0")
        return tuple(arr[:, 0]) + tuple(arr[:, 1])

    def clutch(self, name: str, a, b, fn_max: float, mu=0.5, peak: float = 1.0, cgeo: float = 1.0,
               normal=1.0) -> "Driveline":
        """A clutch between flanges a and b (MSL ``Clutch``): sliding torque ``cgeo fn mu(|w_rel|)``,
        ``fn = fn_max * normal(t)`` [N] (free when ``<= 0``), static limit ``peak`` times the sliding
        torque at rest.  ``mu``: a number or a table ``[[w_rad_s, mu], ...]``."""
        name = self._new_name(name)
        a, b = self._two(name, a, b)
        return self._friction(name, a, b, K.LAW_CLUTCH, self._characteristic(name, "mu", mu), peak, fn_max, cgeo,
                              normal)

    def brake(self, name: str, flange, fn_max: float, mu=0.5, peak: float = 1.0, cgeo: float = 1.0,
              normal=1.0, support=None) -> "Driveline":
        """A brake between ``flange`` and ``support`` (default the ground), as :meth:`clutch` (MSL ``Brake``)."""
        name = self._new_name(name)
        a, b = self._two(name, support, flange)
        return self._friction(name, a, b, K.LAW_CLUTCH, self._characteristic(name, "mu", mu), peak, fn_max, cgeo,
                              normal)

    def bearing_friction(self, name: str, flange, torque=1.0, peak: float = 1.0, support=None) -> "Driveline":
        """Bearing friction of ``flange`` against ``support`` (default the ground; MSL ``BearingFriction``):
        sliding torque ``torque`` [N m], a number or a table ``[[w_rad_s, N m], ...]``; never free."""
        name = self._new_name(name)
        a, b = self._two(name, support, flange)
        return self._friction(name, a, b, K.LAW_TABLE, self._characteristic(name, "torque", torque), peak)

    # ---- the system
    def describe(self) -> str:
        """A text schematic: the inertias, then every element between its flanges (``ground`` for none)."""
        fric = self.friction_names
        lines = [f"{self.name}: {len(self._inertias)} inertias, {len(self._elements)} elements "
                 f"({len(fric)} friction)"]
        for name, (J, w0, phi0) in self._inertias.items():
            lines.append(f"  [{name}]  J = {J:g} kg m^2, w0 = {w0:g} rad/s, phi0 = {phi0:g} rad")
        for e in self._elements:
            a, b = e.a or GROUND, e.b or GROUND
            if e.kind == K.K_SOURCE:
                lines.append(f"  {a} --({e.name}: torque {e.signal.describe('N m')})--> [{b}]")
                continue
            if e.kind == K.K_SPRING:
                what = f"spring-damper c = {e.coef[0]:g} N m/rad, d = {e.coef[1]:g} N m s/rad"
            else:
                n = len(e.table) // 2
                char = f"{e.table[n]:g}" if n == 1 else f"table of {n} points"
                if e.law == K.LAW_TABLE:
                    what = f"bearing friction {char} N m, peak {e.coef[2]:g}"
                else:
                    normal = "" if e.signal is None else f", normal {e.signal.describe()}"
                    what = f"friction fn_max = {e.coef[0]:g} N, mu {char}, peak {e.coef[2]:g}{normal}"
            lines.append(f"  [{a}] --({e.name}: {what})-- [{b}]")
        return "\n".join(lines)

    @property
    def friction_names(self) -> tuple:
        return tuple(e.name for e in self._elements if e.kind == K.K_FRICTION)

    def pack(self) -> K.DrivelineParams:
        """The packed parameters (:class:`~clutchlab.driveline.kernel.DrivelineParams`)."""
        if not self._inertias:
            raise ParameterError(f"{self.name}: no inertia")
        index = {n: i for i, n in enumerate(self._inertias)}
        signals, data = [], []
        elem = np.zeros((len(self._elements), 8), dtype=np.int64)
        coef = np.zeros((len(self._elements), 3))

        def add_signal(sig):
            row = list(sig.row)
            if row[0] == K.SIG_TABLE:
                n = len(sig.points) // 2
                row = [K.SIG_TABLE, float(len(data)), float(n)]
                data.extend(sig.points)
            signals.append(row + [0.0] * (7 - len(row)))
            return len(signals) - 1

        for r, e in enumerate(self._elements):
            elem[r, K.E_KIND] = e.kind
            elem[r, K.E_A] = -1 if e.a is None else index[e.a]
            elem[r, K.E_B] = -1 if e.b is None else index[e.b]
            elem[r, K.E_LAW] = e.law
            elem[r, K.E_SIGNAL] = -1 if e.signal is None else add_signal(e.signal)
            if e.table:
                elem[r, K.E_TABLE] = len(data)
                elem[r, K.E_TABLE_N] = len(e.table) // 2
                data.extend(e.table)
            coef[r] = e.coef
        fric = np.array([r for r, e in enumerate(self._elements) if e.kind == K.K_FRICTION], dtype=np.int64)
        n, ne, nf = len(index), len(self._elements), fric.size
        work = np.zeros(K.work_size(n, nf, ne))
        inertia = np.array([v[0] for v in self._inertias.values()])
        x0 = self.initial_state()
        work[-1] = 0.5 * float(np.sum(inertia * x0[n:2 * n] ** 2)) + self._spring_energy(x0, index)
        return K.DrivelineParams(inertia, elem, coef, np.array(signals, dtype=float).reshape(-1, 7),
                                 np.array(data, dtype=float), fric, work, np.zeros(max(nf, 1), dtype=np.int64))

    def _spring_energy(self, x0, index):
        e_sum = 0.0
        for e in self._elements:
            if e.kind == K.K_SPRING:
                pa = 0.0 if e.a is None else x0[index[e.a]]
                pb = 0.0 if e.b is None else x0[index[e.b]]
                e_sum += 0.5 * e.coef[0] * (pb - pa - e.coef[2]) ** 2
        return e_sum

    def initial_state(self) -> np.ndarray:
        """Angles, speeds, then the energy states (zero)."""
        n = len(self._inertias)
        x = np.zeros(2 * n + len(self._elements))
        for i, (J, w0, phi0) in enumerate(self._inertias.values()):
            x[i] = phi0
            x[n + i] = w0
        return x

    def _initial_modes(self, p, x0):
        n = len(self._inertias)
        m = np.empty(p.fric.size, dtype=np.int64)
        for k, r in enumerate(p.fric):
            e = p.elem[r]
            w_rel = (0.0 if e[K.E_B] < 0 else x0[n + e[K.E_B]]) - (0.0 if e[K.E_A] < 0 else x0[n + e[K.E_A]])
            free = e[K.E_LAW] != K.LAW_TABLE and K.normal_force(p, r, 0.0) <= 0.0
            m[k] = K.FREE if free else K.FORWARD if w_rel > 0 else K.BACKWARD if w_rel < 0 else K.STUCK
        return m

    def variables(self):
        """States and outputs as ``(name, unit, description)`` (column ``<component>.<quantity>_<unit>``)."""
        states = [(f"{i}.phi", "rad", f"angle of {i}") for i in self._inertias]
        states += [(f"{i}.w", "rad_s", f"speed of {i}") for i in self._inertias]
        outputs = []
        for e in self._elements:
            if e.kind == K.K_SOURCE:
                states.append((f"{e.name}.work", "J", f"work of the source {e.name}"))
                outputs.append((f"{e.name}.tau", "Nm", f"torque of the source {e.name} on its flange"))
            else:
                states.append((f"{e.name}.dissipated", "J", f"energy dissipated in {e.name}"))
                outputs.append((f"{e.name}.tau", "Nm", f"torque of {e.name} (on flange b: -tau)"))
                outputs.append((f"{e.name}.w_rel", "rad_s", f"relative speed of {e.name}, flange b minus flange a"))
        for name in self.friction_names:
            outputs.append((f"{name}.mode", "1", f"mode of {name}: 1 forward, 0 stuck, -1 backward, 2 free (MSL)"))
            outputs.append((f"{name}.fn", "N", f"normal force of {name}"))
        outputs += [("kinetic_energy", "J", "kinetic energy of the inertias"),
                    ("spring_energy", "J", "energy stored in the springs"),
                    ("input_work", "J", "work of the sources since the start"),
                    ("dissipated_energy", "J", "energy dissipated since the start"),
                    ("energy_error", "J", "input work - dissipated - change of the stored energy")]
        return tuple(states), tuple(outputs)

    def system(self, rtol: float = 1e-8) -> System:
        """The :class:`~clutchlab.system.System` of this network (Dormand-Prince 5(4), events to 1e-12 s)."""
        p = self.pack()
        x0 = self.initial_state()
        states, outputs = self.variables()
        fric = self.friction_names
        switching = tuple((f"{f}.{what}", d) for f in fric
                          for what, d in (("stick", -1), ("breakaway", -1), ("normal", 0)))
        n = len(self._inertias)
        scale = np.concatenate([np.full(n, 1.0), np.full(n, 1.0), np.full(len(self._elements), 1.0)])

        def element_name(code, element, _names=fric):
            return _names[element] if 0 <= element < len(_names) else ""

        # the switching functions follow the sources: a step holds at most an eighth of a sine's period, so a
        # stuck element whose torque swings past its limit and back within one step is not stepped over
        freqs = [e.signal.row[2] for e in self._elements if e.signal is not None and e.signal.row[0] == K.SIG_SINE]
        max_step = min((0.125 / f for f in freqs if f > 0), default=math.inf)
        return System(name=self.name, params=p, states=states, outputs=outputs, inputs=(), x0=x0,
                      m0=self._initial_modes(p, x0), atol=float(rtol) * scale, switching=switching,
                      events=K.EVENTS, mode_names=fric, mode_values=tuple(K.MODE_VALUES for _ in fric),
                      method="dopri", rtol=float(rtol), max_step=max_step, event_tol=1e-12,
                      element_name=element_name)

    def simulate(self, t_end: float, *, rtol: float = 1e-8, atol=None, max_step: float | None = None,
                 output_step: float | None = None, sample_times=None):
        """Run the network from its initial state to ``t_end`` [s]; a :class:`~clutchlab.SimulationResult`."""
        return _simulate(self.system(rtol), t_end, atol=atol, max_step=max_step, output_step=output_step,
                         sample_times=sample_times)


def _example_system(rtol: float = 1e-8) -> System:
    """The registered factory: ModelicaTest's TestFriction bearing row (a default to run through the contract)."""
    d = Driveline("driveline")
    d.inertia("inertia", J=1.0)
    d.torque("torque", "inertia", Signal.sine(10.0, 1.0))
    d.bearing_friction("bearing_friction", "inertia", torque=1.0)
    return d.system(rtol)


register_model("driveline", _example_system)
