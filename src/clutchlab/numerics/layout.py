"""Index constants generated from a declaration, never written by hand.

A model declares its states, outputs, inputs, modes, switching functions, events and work memories once, as tuples
whose entries start with a name (:mod:`clutchlab.component`'s contract); its compiled code reads them through
integer constants (numba folds a module's integers into the machine code).  These make those constants from the
declaration, at import:

* :func:`indices` -- the position of each named entry of a declaration
  (``S_W = indices(STATES, "slip_speed")``): reordering the declaration moves the constant with its entry, and a
  renamed or removed entry is refused at import, never silently read from another row;
* :func:`bits` -- one bit per named entry (a request made of flags: ``1 << indices(...)``);
* :func:`slots` -- consecutive named slots of a flat array from ``(name, size)`` pairs (a driveline block's buffer:
  its states, their derivatives, switching values, inputs, outputs; a model's work memory): each offset is the
  sum of the sizes before it, and :attr:`Slots.total` the array's length.

Everything here is plain Python ``int``; nothing is compiled.
"""

from __future__ import annotations

__all__ = ["indices", "bits", "slots", "Slots"]


def _names(declaration) -> list:
    out = []
    for entry in declaration:
        name = entry if isinstance(entry, str) else entry[0]
        if not isinstance(name, str) or not name:
            raise TypeError(f"declaration entry {entry!r}: its first item must be a name")
        out.append(name)
    twice = sorted({n for n in out if out.count(n) > 1})
    if twice:
        raise ValueError(f"a declaration names {', '.join(twice)} twice")
    return out


def indices(declaration, *names: str):
    """Positions of ``names`` in ``declaration`` (a tuple of names, or of tuples whose first item is a name).

    One name gives an ``int``, several a tuple of them in the order asked.  A name that is not declared raises
    :class:`KeyError` naming it and the declared ones.

    >>> indices((("x", "m"), ("v", "m_s")), "v", "x")
    (1, 0)
    """
    known = _names(declaration)
    where = {n: i for i, n in enumerate(known)}
    out = []
    for n in names:
        if n not in where:
            raise KeyError(f"{n!r} is not declared (declared: {', '.join(known)})")
        out.append(where[n])
    return out[0] if len(out) == 1 else tuple(out)


def bits(declaration, *names: str):
    """The flag ``1 << position`` of each of ``names`` in ``declaration`` (as :func:`indices`: one name gives an
    ``int``, several a tuple).

    >>> bits(("derivatives", "accept", "event"), "event", "derivatives")
    (4, 1)
    """
    at = indices(declaration, *names)
    return 1 << at if isinstance(at, int) else tuple(1 << a for a in at)


class Slots:
    """Consecutive named slots of a flat array (:func:`slots`): ``slots[name]`` is a slot's offset,
    :meth:`of` several, :attr:`size` each one's length and :attr:`total` the array's."""

    __slots__ = ("offset", "size", "total")

    def __init__(self, offset: dict, size: dict, total: int):
        self.offset, self.size, self.total = offset, size, total

    def __getitem__(self, name: str) -> int:
        if name not in self.offset:
            raise KeyError(f"no slot {name!r} (slots: {', '.join(self.offset)})")
        return self.offset[name]

    def of(self, *names: str) -> tuple:
        """The offsets of ``names``, in that order."""
        return tuple(self[n] for n in names)

    def __repr__(self) -> str:
        inner = ", ".join(f"{n}={o}+{self.size[n]}" for n, o in self.offset.items())
        return f"Slots({inner}; total={self.total})"


def slots(*pairs) -> Slots:
    """Consecutive slots of a flat array from ``(name, size)`` pairs, in that order.

    Each slot's offset is the sum of the sizes before it; sizes are integers >= 0 and each name appears once.

    >>> s = slots(("x", 12), ("dx", 12), ("g", 5))
    >>> s["dx"], s.of("x", "g"), s.total
    (12, (0, 24), 29)
    """
    offset, size, at = {}, {}, 0
    for pair in pairs:
        name, n = pair
        if not isinstance(name, str) or not name:
            raise TypeError(f"slot {pair!r}: its first item must be a name")
        if name in offset:
            raise ValueError(f"slot {name!r} given twice")
        if not isinstance(n, int) or isinstance(n, bool) or n < 0:
            raise ValueError(f"slot {name!r}: size {n!r} must be an integer >= 0")
        offset[name], size[name] = at, n
        at += n
    return Slots(offset, size, at)
