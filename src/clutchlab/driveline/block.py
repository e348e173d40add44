"""The rows of a model component in a driveline block, laid out from the component's declaration.

A block (:mod:`clutchlab.driveline.wet`, :mod:`clutchlab.driveline.emtc`) holds one row per component of its kind
in two arrays: a configuration row (int64: where the component sits in the network and the whole system) and a
buffer row (float64: its model's states, derivatives, switching values, inputs and outputs at an evaluation).
Their offsets are generated here (:func:`clutchlab.numerics.layout.slots`) from the model's declared states,
switching functions, inputs and outputs, so a block writes no index by hand.
"""

from __future__ import annotations

from ..numerics.layout import Slots, slots

__all__ = ["CONF_HEAD", "conf_slots", "buffer_slots"]

#: what every component's configuration row starts with, one integer each: its friction index in the network, its
#: element row, the offsets of its states, switching functions and modes in the whole system's, the number of the
#: network's events and the index of its first named element (events name ``<name>``, ``<name>.<part>``)
CONF_HEAD = ("friction", "row", "states", "switching", "modes", "events", "element")


def conf_slots(*ports) -> Slots:
    """A component's configuration row: :data:`CONF_HEAD`, then its ports (``(name, count)`` pairs: the network
    signal each reads, -1 for none)."""
    return slots(*((name, 1) for name in CONF_HEAD), *ports)


def buffer_slots(states, switching, inputs, outputs) -> Slots:
    """A component's buffer row from its model's declarations: its states (the flange speeds replaced by the
    network's), their derivatives, its switching values, its model's inputs (its ports' values at the evaluation's
    time, zero for the others) and its outputs."""
    return slots(("states", len(states)), ("derivative", len(states)), ("switching", len(switching)),
                 ("inputs", len(inputs)), ("outputs", len(outputs)))
