"""One result type for every simulation: :class:`SimulationResult`."""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from .numerics.status import Status

__all__ = ["SimulationResult", "BuiltOnFirstAccess"]


class BuiltOnFirstAccess:
    """Descriptor of a dataclass field that may be given as a zero-argument callable.

    Declared as the field's default (``events: pd.DataFrame = BuiltOnFirstAccess()``), it keeps the
    field required.  The callable is called (once) when the field is first read, so a run
    whose events nobody reads does not pay for building a DataFrame (about
    0.2 ms with pandas; a batch of 10,000 variants would otherwise build
    10,000 of them).  A value that is not callable is stored as it is.
    """

    def __set_name__(self, owner, name):
        self.slot = "_built_" + name

    def __get__(self, obj, owner=None):
        if obj is None:
            raise AttributeError(self.slot)  # no class-level default: the field stays required
        value = obj.__dict__[self.slot]
        if callable(value):
            value = value()
            obj.__dict__[self.slot] = value
        return value

    def __set__(self, obj, value):
        obj.__dict__[self.slot] = value

    def stored(self, obj):
        """What ``obj`` holds in this field: the value, or the callable not called yet."""
        return obj.__dict__[self.slot]


@dataclasses.dataclass
class SimulationResult:
    """Time series, modes and named events of one run (or a stacked batch of runs).

    Attributes
    ----------
    time : ndarray
        Sample times [s], shape ``(n,)``.
    states : ndarray
        States [SI], shape ``(n, n_x)`` (batch: ``(n_v, n, n_x)``), columns ``state_columns``.
    outputs : ndarray
        Outputs [SI], shape ``(n, n_y)`` (batch: ``(n_v, n, n_y)``), columns ``output_columns``;
        NaN if outputs were not requested.
    modes : ndarray of int
        Mode vector per sample, shape ``(n, n_m)`` (batch: ``(n_v, n, n_m)``); ``mode_names``
        names the mode variables and ``mode_values`` the values of each.
    events : pandas.DataFrame
        One row per event: ``time_s``, ``event`` (a name such as ``lockup``), ``element``
        (the element it concerns, empty for none); a batch adds ``variant``.  The constructor
        also takes a zero-argument callable returning the frame, called on first access.
    status : Status or ndarray of Status codes
        How the run ended (batch: one code per variant).
    state_columns, output_columns : tuple of str
        Column names with their unit suffix (``piston_position_m``).
    stats : dict
        Accepted and rejected steps, right-hand-side and Jacobian evaluations.
    model : str
        Name of the model that produced it.
    """

    time: np.ndarray
    states: np.ndarray
    outputs: np.ndarray
    modes: np.ndarray
    events: pd.DataFrame = BuiltOnFirstAccess()
    status: object
    state_columns: tuple
    output_columns: tuple
    mode_names: tuple = ()
    mode_values: tuple = ()
    stats: dict = dataclasses.field(default_factory=dict)
    model: str = ""

    def __getstate__(self):
        self.events  # noqa: B018  (build the events before pickling: no callable in the state)
        return self.__dict__

    @classmethod
    def fields_of(cls, result: "SimulationResult") -> dict:
        """The fields of ``result`` as keyword arguments of a subclass's constructor (a model's entry point returns
        its own subclass, :class:`clutchlab.wet.EngagementResult`, ..., built from the core's run with them).  The
        events stay unbuilt where they were (their callable is passed on)."""
        kw = {f.name: getattr(result, f.name) for f in dataclasses.fields(SimulationResult) if f.name != "events"}
        kw["events"] = SimulationResult.__dict__["events"].stored(result)
        return kw

    @property
    def batch(self) -> bool:
        """True for a stacked batch (leading variant axis)."""
        return self.states.ndim == 3

    @property
    def ok(self) -> bool:
        """True if every run reached its end time (or a terminal event)."""
        if self.batch:
            return bool(np.all([Status(int(s)).ok for s in np.ravel(self.status)]))
        return Status(int(self.status)).ok

    def _column(self, name: str):
        for cols, arr in ((self.state_columns, self.states), (self.output_columns, self.outputs)):
            if name in cols:
                return arr[..., cols.index(name)]
        stems = {c.rsplit("_", 1)[0]: c for c in self.state_columns + self.output_columns}
        for cols, arr in ((self.state_columns, self.states), (self.output_columns, self.outputs)):
            for i, c in enumerate(cols):
                if name == c or (name in stems and stems[name] == c):
                    return arr[..., i]
        raise KeyError(f"{name!r}: not a state or output of {self.model or 'this result'} "
                       f"(states: {', '.join(self.state_columns)}; outputs: {', '.join(self.output_columns)})")

    def __getitem__(self, name: str) -> np.ndarray:
        """One state or output trace by its column name (``result["clutch_torque_Nm"]``)."""
        return self._column(name)

    def mode(self, name: str | None = None) -> np.ndarray:
        """Mode names per sample of one mode variable (the first by default)."""
        i = 0 if name is None else self.mode_names.index(name)
        values = np.asarray(self.mode_values[i], dtype=object)
        return values[self.modes[..., i]]

    def to_dataframe(self, variant: int | None = None) -> pd.DataFrame:
        """Samples as a DataFrame: ``time_s``, states, outputs (unit-suffixed columns) and modes.

        For a batch, ``variant`` selects one run; without it the runs are stacked with a
        ``variant`` column.
        """
        if self.batch:
            if variant is not None:
                return self._frame(self.states[variant], self.outputs[variant], self.modes[variant])
            frames = []
            for v in range(self.states.shape[0]):
                f = self._frame(self.states[v], self.outputs[v], self.modes[v])
                f.insert(0, "variant", v)
                frames.append(f)
            return pd.concat(frames, ignore_index=True)
        return self._frame(self.states, self.outputs, self.modes)

    def _frame(self, states, outputs, modes) -> pd.DataFrame:
        data = {"time_s": self.time}
        for i, c in enumerate(self.state_columns):
            data[c] = states[:, i]
        for i, c in enumerate(self.output_columns):
            if c not in data:
                data[c] = outputs[:, i]
        for i, name in enumerate(self.mode_names):
            values = np.asarray(self.mode_values[i], dtype=object)
            data[name] = values[modes[:, i]]
        return pd.DataFrame(data)

    def __repr__(self) -> str:
        shape = f"{self.states.shape[0]} variants x " if self.batch else ""
        return (f"{type(self).__name__}(model={self.model!r}, {shape}{self.time.size} samples, "
                f"{len(self.state_columns)} states, {len(self.output_columns)} outputs, "
                f"{len(self.events)} events, status={self.status if self.batch else Status(int(self.status)).name})")
