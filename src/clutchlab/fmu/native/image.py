"""A co-simulation's compiled session as data: the image a native FMU copies into each instance.

A :class:`~clutchlab.system.Simulation` runs a model through one compiled entry, ``session(table, t_end,
what)`` (:mod:`clutchlab.numerics.session`), whose only argument of substance is the session's *table*: the
addresses of the model's ``advance`` and ``evaluate_outputs``, then every argument of theirs (parameters,
state, modes, inputs, solver state, options, event log, buffers) in the layout of numba's data model, each
array as its native structure whose data pointer points into the array's memory.

:func:`session_image` copies that table and the memory of every array it points into one byte string, the
*image*: the table first, then the arrays' memory in blocks (arrays that share memory share a block), and
lists the *relocations*, the table's slots that hold a pointer into a block.  An instance of a native FMU
copies the image into memory of its own and writes into each relocation slot the address of its own copy
of that block -- nothing else of the image depends on where it lies -- and the two function slots take the
addresses of the compiled functions linked into the FMU's library.  Where a variable lives (an input in
``u``, an output in the report ``r``, the time in the solver state) is an offset into the image.

:func:`parameter_map` finds where each FMU parameter (or input) lands in the image, by building the model
again with it changed (the co-simulation class builds it from the component declarations or parameter
sets): one whose every changed number is ``a * value + b`` (most are copies, ``a = 1, b = 0``) or
``a / value + b`` (a time constant kept as a rate) is written by the native FMU itself.  One that changes the
image in any other way (a table rebuilt, the arrays' sizes, a number two parameters share) is fixed at
export, and a writable one's range ends where its law stops holding (:func:`law_holds`, searched by
:func:`accepted_range` as the values the model refuses are).  The words the model's compiled ``start`` derives from the
initial state or from several parameters (:attr:`clutchlab.system.System.decided_at_start`: a driveline's start
modes and the stored energy its energy balance starts from; the wet clutch's heat capacity, the E-clutch's
compliances) are no parameter's target: the FMU runs ``start`` again after a host set start values (before the
run, :mod:`clutchlab.fmu.native`), so an initial speed, a mass or a line diameter is a copy.  (Whether ``start``
derives there what the model's build derives is not checked here, where the start words are left out: the tests
compare the FMU's runs with clutchlab's at parameters a host set.)  Words that differ between two builds of the same values
are memory the model never initialised and are ignored; a last build with every writable parameter changed
at once must equal what the FMU writes; where the model refuses such a combination (a check across
parameters), the parameters of the smallest refused set are fixed.

With ``exchange=True``, :func:`session_image` gives the image of the model-exchange session
(:mod:`clutchlab.numerics.exchange`): the same arguments with buffers for the derivatives, the switching
functions and the outputs in place of the integrator's.
"""

from __future__ import annotations

import ctypes
import dataclasses
import math

import numpy as np

from ...errors import ClutchlabError

__all__ = ["Image", "session_image", "parameter_map", "ParameterMap", "law_holds", "NativeExportError", "LOG_CAPACITY",
           "word_indices"]

#: events a native FMU's session log holds (the FMU reports no events; an overflow is only counted)
LOG_CAPACITY = 16

#: the session's arguments whose contents the FMU never reads before the compiled code writes them (buffers
#: and the event log): copied as zeros, so that the image does not depend on uninitialised memory
_SCRATCH = ("log", "ts", "rt", "rx", "rm", "ry", "y", "r")

_ALIGN = 16


class NativeExportError(ClutchlabError):
    """A model cannot become a native FMU (its session has a form the image does not know, a compiler is
    missing, a compilation failed); the message says which and what to do."""


@dataclasses.dataclass
class Image:
    """The session of one co-simulation as bytes (module docstring).

    Attributes
    ----------
    data : bytes
        The table (``table_bytes`` long), then the blocks; the scratch arrays are zeros.
    table_bytes : int
    relocations : list of (int, int)
        ``(slot, target)``: the 8 bytes at offset ``slot`` hold the address of the image's byte ``target``.
    function_slots : tuple of int
        Offsets of the addresses of ``advance`` and ``evaluate_outputs``.
    method : str
        The core's method of the session (``"dopri"`` or ``"rodas"``): which compiled functions it calls.
    args : tuple
        The session's arguments (the objects the image was copied from).
    """

    data: bytes
    table_bytes: int
    relocations: list
    function_slots: tuple
    method: str
    args: tuple
    _where: dict = dataclasses.field(repr=False, default_factory=dict)
    _blocks: list = dataclasses.field(repr=False, default_factory=list)
    pointer_slots: frozenset = frozenset()
    #: ``(module, outputs_module, args)``: the compiled entry modules of the session and its arguments
    entry_modules: tuple = ()
    #: the names of ``args`` (:data:`clutchlab.numerics.session.FIELDS` or ``exchange.FIELDS``)
    names: tuple = ()
    #: indices of the words the model's ``start`` writes from the initial state (the system's
    #: ``decided_at_start``): the FMU decides them again, so they are no parameter's target
    start_words: frozenset = frozenset()

    def arg(self, name: str):
        """The session's argument ``name`` (``"x"``, ``"u"``, ``"r"``, ...)."""
        return self.args[self.names.index(name)]

    def offset(self, array: np.ndarray, index: int = 0) -> int:
        """Image offset of element ``index`` of ``array`` (one of the session's arrays, C-contiguous)."""
        address = array.__array_interface__["data"][0] + index * array.itemsize
        for start, end, at in self._blocks:
            if start <= address < end or (start == address == end):
                return at + (address - start)
        raise NativeExportError(f"an array of {array.nbytes} bytes is not part of the session's image")

    def same_layout(self, other: "Image") -> bool:
        """Whether ``other`` has the same size, relocations and method (so its numbers can be compared)."""
        return (len(self.data) == len(other.data) and self.relocations == other.relocations
                and self.method == other.method)


def _arrays(value, out: list) -> None:
    if isinstance(value, np.ndarray):
        out.append(value)
    elif isinstance(value, tuple):
        for v in value:
            _arrays(v, out)


def session_arguments(simulation):
    """``(module, outputs_module, args, method)`` of a :class:`~clutchlab.system.Simulation`'s packed session
    (:meth:`~clutchlab.system.Simulation.session`), with its event log replaced by a short one
    (:data:`LOG_CAPACITY`)."""
    return simulation.session(LOG_CAPACITY)


#: the model-exchange session's arguments whose contents the FMU never reads before the compiled code writes them
_EXCHANGE_SCRATCH = ("log", "dx", "g0", "g1", "out", "y", "r", "jac", "sub", "piv", "xp", "fp", "gp", "dls")


def session_image(simulation, exchange: bool = False) -> Image:
    """The image of a :class:`~clutchlab.system.Simulation`'s session (module docstring); ``exchange``: of its
    model-exchange session (:mod:`clutchlab.numerics.exchange`: the same parameters, state, modes, inputs,
    solver state, options and log, with buffers for the derivatives, the switching functions and the
    outputs), called through the model's ``model_exchange`` entry.

    Raises
    ------
    NativeExportError
        The session's table has a layout this does not know, or points outside its arrays.
    """
    from ...numerics import exchange as X, session as S

    module, outputs_module, args, method = session_arguments(simulation)
    names, scratch_names = S.FIELDS, _SCRATCH
    if exchange:
        p, x, m, u, sf, si, opt, log = args[:8]
        args = (p, x, m, u, sf, si, opt, log, np.zeros(x.size), np.zeros(opt.gdir.size), np.zeros(opt.gdir.size),
                np.zeros(2), args[14], args[15], args[16], *X.workspace(opt.mass, opt.gdir.size))
        names, scratch_names = X.FIELDS, _EXCHANGE_SCRATCH
    args_ty = module.session.typeof_pyval(args)
    layout = S.table_layout(args_ty)
    if layout is None:
        raise NativeExportError(f"{simulation.system.name}: its session's arguments have a type the native "
                                f"FMU's image does not know ({args_ty})")
    nbytes, fields, flat = layout
    values = [0, 0]
    flat(args, values)
    arrays = []
    _arrays(args, arrays)
    scratch = []
    for name, value in zip(names, args):
        if name in scratch_names:
            _arrays(value, scratch)
    # blocks: the arrays' memory, merged where it overlaps, in the order the arguments first name them (not by
    # address: two builds of one model then give the same image)
    spans = sorted((a.__array_interface__["data"][0], a.__array_interface__["data"][0] + a.nbytes, k)
                   for k, a in enumerate(arrays))
    merged = []
    for start, end, k in spans:
        if merged and start < merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], end)
            merged[-1][2] = min(merged[-1][2], k)
        else:
            merged.append([start, end, k])
    merged.sort(key=lambda b: b[2])
    at = -(-nbytes // _ALIGN) * _ALIGN
    blocks = []
    for start, end, _ in merged:
        blocks.append((start, end, at))
        at += -(-max(end - start, 1) // _ALIGN) * _ALIGN
    data = bytearray(at)
    for start, end, off in blocks:
        if end > start:
            data[off:off + end - start] = ctypes.string_at(start, end - start)
    image = Image(b"", nbytes, [], (fields[0][0], fields[1][0]), "exchange" if exchange else method,
                  args, {}, blocks)
    image.names = names
    for a in scratch:   # zeros, not whatever the buffers held
        if a.nbytes:
            off = image.offset(a)
            data[off:off + a.nbytes] = bytes(a.nbytes)
    for a in arrays:   # a record's padding (after a bool field) as zeros: memory numpy never writes
        if a.dtype.fields and a.nbytes and a.flags.c_contiguous:
            _zero_padding(data, image.offset(a), a)
    import struct

    table = bytearray(nbytes)
    relocations = []
    for (offset, code), value in zip(fields, values):
        struct.pack_into("=" + code, table, offset, value)
        if code == "Q" and value and offset not in image.function_slots:
            for start, end, off in blocks:
                if start <= value <= end:
                    relocations.append((offset, off + value - start))
                    struct.pack_into("=Q", table, offset, 0)
                    break
            else:
                raise NativeExportError(f"{simulation.system.name}: its session's table points outside its "
                                        "arrays (a pointer the native FMU cannot relocate)")
    for slot in image.function_slots:
        struct.pack_into("=Q", table, slot, 0)
    data[:nbytes] = table
    image.data = bytes(data)
    image.relocations = relocations
    image.entry_modules = (module, outputs_module, args)
    image.pointer_slots = frozenset([s for s, _ in relocations] + list(image.function_slots))
    image.start_words = frozenset(word_indices(image, simulation.system.decided_at_start))
    return image


def word_indices(image: Image, decided) -> list:
    """Word indices of the slices ``decided`` (``(path, start, stop)``, as
    :attr:`clutchlab.system.System.decided_at_start`) in ``image``."""
    out = []
    for where, start, stop in decided:
        head, *path = where.split(".")
        if head in ("m", "x") and not path:
            value = image.arg(head)
        elif head == "params" and path:
            value = image.arg("p")
            for name in path:   # (a field of a record array: its column, a strided view)
                names = value.dtype.names if isinstance(value, np.ndarray) else None
                value = value[name] if names and name in names else getattr(value, name)
        else:
            raise NativeExportError(f"decided_at_start: {where!r}: expected 'm', 'x' or 'params.<field>[.<field>...]'")
        array = value.reshape(-1)
        for k in range(*slice(start, stop).indices(array.size)):
            out.append(image.offset(array[k:], 0) // 8)
    return out


def _zero_padding(data: bytearray, at: int, a: np.ndarray) -> None:
    """Zero the bytes of the records of ``a`` (copied to ``data[at:]``) that no field covers."""
    covered = np.zeros(a.dtype.itemsize, dtype=bool)
    for field in a.dtype.fields.values():
        dt, offset = field[0], field[1]
        covered[offset:offset + dt.itemsize] = True
    if covered.all():
        return
    view = np.frombuffer(memoryview(data)[at:at + a.nbytes], dtype=np.uint8).reshape(-1, a.dtype.itemsize)
    view[:, ~covered] = 0


def _words(image: Image) -> np.ndarray:
    n = len(image.data) // 8
    return np.frombuffer(image.data[:n * 8], dtype=np.uint64)


def _trials(variable) -> list:
    """Values of a parameter to build the model with, beside its start: inside its range, whole numbers for a
    whole-number start, in order of preference."""
    v = float(variable.start)
    lo, hi = variable.minimum, variable.maximum
    # one value above the start and one below, relative to it: a law that changes at the start (a tolerance
    # whose absolute tolerances follow it only below its default, min(1, rtol / default)) is seen as not affine
    # and fixed; two values on one side (v * 1.25 + 0.125 and v * 0.8 + 0.0625 for rtol = 1e-3) saw a line
    cand = ([v * 1.25, v * 0.8, v * 2.0, v * 0.5, v * 1.5, v * 0.75] if v != 0.0 else []) \
        + [v + 1.0, v - 1.0, v + 0.5, v - 0.5, v + 0.125, v - 0.0625]
    if float(v).is_integer():
        # whole numbers (a count the model refuses fractions of), the relative ones first: trials one apart from a
        # large start saw a curve as a line (the E-clutch's k_fl_model2 of 1175810 N/m: 2.7e-5 off at 1.02 times
        # it) and fitted a line's slope to 1e-12 only (actuator.ki, clutch.asperity_density)
        cand = [float(round(v * 1.25)), float(round(v * 0.8)), v + 1.0, v - 1.0, v + 2.0, v - 2.0] + cand
    out = []
    for c in cand:
        if c == v or not math.isfinite(c) or c in out:
            continue
        if lo is not None and c < lo or hi is not None and c > hi or variable.positive and c <= 0.0:
            continue
        out.append(c)
    return out


@dataclasses.dataclass(frozen=True)
class Target:
    """Where a parameter lands in the image: the float64 at ``offset`` is ``a * value + b`` (``reciprocal``:
    ``a / value + b``, a time constant stored as its rate)."""

    offset: int
    a: float
    b: float
    reciprocal: bool = False
    #: written only until initialisation ends (an input's start value of a state)
    initial: bool = False
    #: a number two parameters share as a product (an absolute tolerance ``rtol`` times a length): the float64 is
    #: ``a * value * value of partner`` (``b`` 0); ``partner_start``, the partner's start
    partner: str | None = None
    partner_start: float = 0.0

    def value(self, v: float, values: dict | None = None) -> float:
        """The number the FMU writes for the value ``v`` (``values``: the other parameters' values by name, a
        product's partner at its start where it is not there)."""
        if self.partner is not None:
            return self.a * v * (values or {}).get(self.partner, self.partner_start)
        if self.a == 1.0 and self.b == 0.0 and not self.reciprocal:
            return v
        return (self.a / v if self.reciprocal else self.a * v) + self.b


def _fit(v0, v1, v2, y0, y1, y2):
    """The :class:`Target` law (without its offset) that maps the three values to the three numbers, or None."""
    scale = max(abs(y0), abs(y1), abs(y2), 1e-300)
    if y0 == v0 and y1 == v1 and y2 == v2:
        return (1.0, 0.0, False)
    for reciprocal in (False, True):
        if reciprocal and 0.0 in (v0, v1, v2):
            continue
        f = (lambda v: 1.0 / v) if reciprocal else (lambda v: v)
        a = (y1 - y0) / (f(v1) - f(v0))
        b = y0 - a * f(v0)
        if abs(a * f(v2) + b - y2) <= 1e-13 * scale and abs(a * f(v1) + b - y1) <= 1e-13 * scale:
            # a proportion whose offset is the fit's rounding (1.5e-16 for 1e-8 ki): without it, so that the number
            # stays right near zero (relative to it), where the offset would dominate
            if f(v0) != 0.0 and abs(b) <= 1e-12 * scale:
                a0 = y0 / f(v0)
                if all(abs(a0 * f(v) - y) <= 1e-13 * scale for v, y in ((v1, y1), (v2, y2))):
                    return (a0, 0.0, reciprocal)
            return (a, b, reciprocal)
    return None


def parameter_map(variables, base: Image, build, label: str = "model", one_sided: bool = False) -> dict:
    """Where each of ``variables`` (parameters, or inputs) lands in the image ``base`` (module docstring).

    Parameters
    ----------
    variables : sequence of clutchlab.fmu.cosim.Variable
        A co-simulation class's parameters or inputs (their ``start``, ranges and names).
    base : Image
        The image with every variable at its start.
    build : callable
        ``build(values) -> Image``: the image with the variables named in ``values`` changed (the others at
        their start), or None if the model refuses the values.
    label : str
        For messages.
    one_sided : bool
        Where the law changes at the start (a line on each side), take the one below it: for
        parameters, whose range the exporter then ends at the start on the other side (:func:`law_holds`); not
        for inputs, which have no such range.

    Returns
    -------
    dict
        Name -> tuple of :class:`Target` (an empty tuple: the variable changes nothing), or None where it
        changes the image in a way the FMU cannot repeat (fixed at export).
    """
    w0 = _words(base)
    again = build({})
    if again is None or not base.same_layout(again):
        raise NativeExportError(f"{label}: two builds of the same model differ in layout")
    noise = w0 != _words(again)
    # (what the model's start decides from the initial state, again in the FMU: no parameter's target)
    noise[np.fromiter(base.start_words, dtype=np.int64, count=len(base.start_words))] = True
    skip = np.zeros_like(noise)
    for slot in base.pointer_slots:
        skip[slot // 8] = True
    out = ParameterMap()
    out.trial = {}
    sided = set()   # (found on one side of the start only)
    for var in variables:
        v0 = float(var.start)
        images = []
        for trial in _trials(var):
            img = build({var.name: trial})
            if img is not None and base.same_layout(img):
                images.append((trial, img))
            if len(images) == 2:
                break
        out[var.name] = None
        # the two trials around the start; where the law changes there (an absolute tolerance that follows rtol
        # only below the model's default), the two below it: the range then ends at the start above (law_holds,
        # searched by accepted_range)
        targets = _law(w0, noise, skip, v0, images[0], images[1]) if len(images) >= 2 else None
        if targets is not None:
            out[var.name] = targets
            out.trial[var.name] = images[0][0]
        elif one_sided:
            # a kink at the start: a line on each side (each side's two trials and the start follow one), the one
            # below taken (a tolerance a host tightens); a law that holds on neither side stays fixed
            # (trials a tenth or more from the start: one apart from a large whole number shows no curve)
            far = [c for c in _trials(var) if abs(c - v0) >= 0.1 * abs(v0)]
            below, above = [], []
            for side, values in ((below, [c for c in far if c < v0]), (above, [c for c in far if c > v0])):
                for c in values:
                    img = build({var.name: c})
                    if img is not None and base.same_layout(img):
                        side.append((c, img))
                    if len(side) == 2:
                        break
            if len(below) == 2 and len(above) == 2:
                lower = _law(w0, noise, skip, v0, *below)
                if lower is not None and _law(w0, noise, skip, v0, *above) is not None:
                    out[var.name] = lower
                    out.trial[var.name] = below[0][0]
                    sided.add(var.name)
    # a number two parameters change (a sum, a product of two) cannot be written by either
    # while the other may change too: the first in declaration order stays writable (the others fixed at their
    # start, it alone changes that number, as it was found to), the others are fixed; one whose law holds on
    # both sides of its start before one that has a law below it only (the E-clutch's actuator.ki before its rtol,
    # whose tolerance of the controller's integral both change)
    owners = {}
    for name, targets in out.items():
        for t in targets or ():
            owners.setdefault(t.offset, []).append(name)
    starts = {var.name: float(var.start) for var in variables}
    for offset, names in owners.items():
        if len(names) == 2 and _product(base, build, w0, noise, skip, out, offset, names, starts):
            continue
        for name in sorted(names, key=lambda n: n in sided)[1:]:
            out[name] = None
    out.ignore = noise | skip
    return _checked_jointly(variables, base, build, out, noise | skip)


def _product(base, build, w0, noise, skip, out, offset, names, starts) -> bool:
    """Whether the word at ``offset``, which both parameters ``names`` change in proportion (``a v``, no offset), is
    their product ``c v1 v2`` (an absolute tolerance ``rtol`` times a length): checked by a build with both at their
    trial values; then both targets there become the product's (:attr:`Target.partner`) and True."""
    n1, n2 = names
    if out.get(n1) is None or out.get(n2) is None:
        return False
    t1 = next(t for t in out[n1] if t.offset == offset)
    t2 = next(t for t in out[n2] if t.offset == offset)
    v1, v2 = starts[n1], starts[n2]
    if t1.b != 0.0 or t2.b != 0.0 or t1.reciprocal or t2.reciprocal or t1.partner or t2.partner or 0.0 in (v1, v2):
        return False
    c = t1.a / v2
    if abs(c - t2.a / v1) > 1e-12 * abs(c):
        return False
    trial = {n1: out.trial[n1], n2: out.trial[n2]}
    img = build(trial)
    if img is None or not base.same_layout(img):
        return False
    got = float(_words(img).view(np.float64)[offset // 8])
    want = c * trial[n1] * trial[n2]
    if not abs(want - got) <= WORD_RTOL * abs(got):
        return False
    out[n1] = tuple(dataclasses.replace(t, a=c, partner=n2, partner_start=v2) if t.offset == offset else t
                    for t in out[n1])
    out[n2] = tuple(dataclasses.replace(t, a=c, partner=n1, partner_start=v1) if t.offset == offset else t
                    for t in out[n2])
    return True


def _law(w0: np.ndarray, noise: np.ndarray, skip: np.ndarray, v0: float, trial1, trial2):
    """The targets of a parameter from the images of two trials ``(value, image)`` beside the start's words ``w0``
    (a tuple of :class:`Target`, empty if it changes nothing), or None if a changed word follows no law."""
    (v1, i1), (v2, i2) = trial1, trial2
    w1, w2 = _words(i1), _words(i2)
    # (a word that differs between two builds of the same values is memory the model never initialised:
    # not a target, and no reason to refuse one)
    changed = ((w1 != w0) | (w2 != w0)) & ~noise
    if np.any(changed & skip):
        return None
    targets = []
    f0, f1, f2 = w0.view(np.float64), w1.view(np.float64), w2.view(np.float64)
    for k in np.flatnonzero(changed):
        y0, y1, y2 = float(f0[k]), float(f1[k]), float(f2[k])
        if not all(math.isfinite(y) and (y == 0.0 or abs(y) >= 2.2250738585072014e-308) for y in (y0, y1, y2)):
            return None   # (not a float: an integer, a flag)
        law = _fit(v0, v1, v2, y0, y1, y2)
        if law is None:
            return None
        targets.append(Target(int(k) * 8, *law))
    return tuple(targets)


class ParameterMap(dict):
    """:func:`parameter_map`'s result: name -> tuple of :class:`Target` or None (fixed at export); ``ignore``, the
    words a comparison of two images leaves out (memory the model never initialised, pointers, the words its
    ``start`` decides); ``trial``, name -> the value a writable one's law was found at first (the joint build's)."""

    ignore: np.ndarray
    trial: dict


def law_holds(base: Image, where: ParameterMap, img: Image, values: dict) -> bool:
    """Whether ``img`` (the model built with ``values``) holds what the FMU writes into ``base`` for them: the
    laws :func:`parameter_map` found near the start still hold there (a law that changes beyond, such as an
    absolute tolerance with a floor, does not: the FMU's range of the parameter ends before it)."""
    if not base.same_layout(img):
        return False
    return bool(np.all(_same_words(_apply(base, where, values), img, base, _written(where, values), where.ignore)))


#: how far a number the FMU writes may lie from the model's own (relative): the rounding of a law ``a v + b`` fitted
#: near the start grows with the distance from it (the EMTC's axle loads, ``a vehicle.mass``, fitted with ``b`` =
#: 1.8e-9 N for 0, were 1.2e-13 off at 0.83 times the start); a thousandth of the 1e-9 a co-simulation is checked to
WORD_RTOL = 1e-12


def _same_words(expected: np.ndarray, img: "Image", base: "Image", written: np.ndarray, ignore: np.ndarray) -> np.ndarray:
    """Where the image ``img`` holds what the FMU would write (``expected``, float64 words): equal, or equal to
    :data:`WORD_RTOL`, or unchanged from ``base`` where no target writes, or a word to ignore."""
    got = _words(img).view(np.float64)
    with np.errstate(invalid="ignore", over="ignore"):
        return ((expected == got) | (np.abs(expected - got) <= WORD_RTOL * np.abs(got))
                | (_words(img) == _words(base)) & ~np.isin(np.arange(got.size), written) | ignore)


def accepted_range(accepts, start: float, lo=None, hi=None, positive: bool = False, whole: bool = False,
                   reach: float = 2.0 ** 40, iterations: int = 48) -> tuple:
    """The interval around ``start`` in which the model accepts a parameter, within its declared range.

    A model may refuse values its declared range allows (a check in the model's own code: the E-clutch's
    ``actuator.slave_min`` must be < 0 though its range is [-100, 100]); a native FMU cannot run that check,
    so it takes the interval found here as the variable's ``min``/``max``.  On each side the distance from
    ``start`` doubles (from ``|start| / 2``, or 1/2 where ``start`` is 0) until the model refuses the value
    or the declared bound (else ``reach`` times the first distance) is passed; between the last accepted and
    the first refused value, bisection (``iterations`` halvings, whole numbers for ``whole``) finds the
    bound, and the last accepted value is returned.  A side whose far end (the declared bound, or ``reach``
    first distances away) the model takes costs one build: the values a model refuses are taken to lie
    beyond a threshold (its checks compare a value with a limit).

    Parameters
    ----------
    accepts : callable
        ``accepts(value) -> bool``: the model built with the parameter at ``value`` (the others at their start).
    start, lo, hi : float
        The start value (accepted) and the declared bounds (None: none).
    positive : bool
        The declared range excludes 0 and below.

    Returns
    -------
    (low, high) : tuple
        The accepted interval's ends (None where the declared side has no bound and nothing was refused
        within ``reach``).
    """
    v0 = float(start)
    base = abs(v0) / 2.0 if v0 != 0.0 else 0.5
    if whole:
        base = max(1.0, math.floor(base))
    out = []
    for sign, bound in ((-1.0, lo), (1.0, hi)):
        if positive and sign < 0 and (bound is None or bound < 0.0):
            bound = 0.0
        # the far end first: a side the model takes to its bound (or to reach) costs one build (refusals lie
        # beyond a threshold: checks compare a value with a limit)
        far = v0 + sign * base * reach if bound is None else bound
        if far != v0 and not (positive and far <= 0.0) and accepts(far):
            out.append(bound)
            continue
        good, bad, d = v0, None, base
        while d <= base * reach:
            value = v0 + sign * d
            if bound is not None and (value < bound if sign < 0 else value > bound):
                value = bound
            if positive and value <= 0.0 or value == good:
                break
            if accepts(value):
                good = value
                if value == bound:
                    break
            else:
                bad = value
                break
            d *= 2.0
        if bad is None:   # (nothing refused up to the declared bound, or within reach: the declared side)
            out.append(bound)
            continue
        for _ in range(iterations):
            mid = 0.5 * (good + bad)
            if whole:
                mid = math.floor(mid) if sign > 0 else math.ceil(mid)
            if mid == good or mid == bad:
                break
            if accepts(mid):
                good = mid
            else:
                bad = mid
        out.append(good)
    return out[0], out[1]


def _apply(image: Image, where: dict, values: dict) -> np.ndarray:
    """The image's numbers with ``values`` written as a native FMU writes them (float64 words)."""
    words = _words(image).view(np.float64).copy()
    for name, v in values.items():
        for t in where[name] or ():
            words[t.offset // 8] = t.value(v, values)
    return words


def _written(where: dict, values: dict) -> np.ndarray:
    """Word indices the targets of the parameters in ``values`` write."""
    return np.array(sorted({t.offset // 8 for name in values for t in where[name] or ()}), dtype=np.int64)


def _joint_values(variables, names, where) -> dict:
    """The joint build's values of the variables ``names``: the trial values their laws were found at first."""
    changed = {}
    for var in variables:
        if var.name in names:
            trial = where.trial.get(var.name)
            if trial is None:
                trials = _trials(var)
                trial = trials[0] if trials else None
            if trial is not None:
                changed[var.name] = trial
    return changed


def _checked_jointly(variables, base: Image, build, where: dict, ignore: np.ndarray) -> dict:
    """Build the model with every writable parameter changed at once and compare with the image the FMU would
    write; a parameter whose numbers differ is fixed (repeated until they agree).  ``ignore``: the words that
    differ between two builds of the same values, and the pointers.  Where the model refuses the combination
    (a check across parameters: the E-clutch's preload balance, a travel's two ends), the smallest refused
    set is found by delta debugging (Zeller's ddmin) and its members are fixed: a host could otherwise write a
    combination the model refuses, which the FMU cannot check."""
    names = [var.name for var in variables if where.get(var.name)]
    _check_set(variables, base, build, where, ignore, names)
    return where


def _refused(variables, base, build, names, where) -> bool:
    img = build(_joint_values(variables, set(names), where))
    return img is None or not base.same_layout(img)


def _minimal_refused(variables, base, build, names, where) -> list:
    """A smallest subset of ``names`` (refused together) that the model still refuses (ddmin on the
    complements)."""
    s, n = list(names), 2
    while len(s) >= 2:
        size = -(-len(s) // n)
        chunks = [s[i:i + size] for i in range(0, len(s), size)]
        for chunk in chunks:
            rest = [x for x in s if x not in chunk]
            if rest and _refused(variables, base, build, rest, where):
                s, n = rest, max(n - 1, 2)
                break
        else:
            if n >= len(s):
                break
            n = min(len(s), 2 * n)
    return s


def _check_set(variables, base, build, where, ignore, names) -> None:
    for _ in range(2 * len(names) + 1):
        names = [n for n in names if where.get(n)]
        if not names:
            return
        changed = _joint_values(variables, set(names), where)
        if not changed:
            return
        img = build(changed)
        if img is None or not base.same_layout(img):
            for name in _minimal_refused(variables, base, build, names, where):
                where[name] = None
            continue
        same = _same_words(_apply(base, where, changed), img, base, _written(where, changed), ignore)
        bad = set(np.flatnonzero(~same).tolist())
        if not bad:
            return
        # (no two writable parameters write one word: parameter_map left the first of them writable)
        offenders = [name for name in changed if any(t.offset // 8 in bad for t in where[name])]
        if not offenders:   # (a number no target writes changed: nothing can be trusted)
            offenders = list(changed)
        for name in offenders:
            where[name] = None
    for name in names:   # (not settled within the rounds: nothing unverified stays writable)
        where[name] = None
