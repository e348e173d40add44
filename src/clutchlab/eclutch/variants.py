"""Describe a clutch model variant in a TOML file, without writing code.

A variant either starts from one of the paper's Models 0-4 (``base = N``) and
replaces or adds nodes and elements by name (a replaced element keeps the
pre-strain, and a replaced spring its ``b`` node, ``scale``, ``unilateral``
and ``gain``, of the one it replaces unless given; the bearing is then zeroed
again at ``bearing_preload``, default the parameters' 80 N, unless the
variant gives the bearing's ``prestrain``), or lists a whole network.
To replace a component's characteristic and keep every model assembled
around it, prefer ``[eclutch.curves]`` in a parameter file
(:meth:`~clutchlab.eclutch.ComponentCurves.replace`, docs/eclutch.md).
Quantities may carry units; curves come from CSV files (columns
``deflection_m``, ``force_N``) relative to the TOML file, or are linear
(``stiffness``)::

    [network]
    name = "Model 2 + compliant support"
    base = 2                       # start from Model 2 (bundled parameters)
    r_eff = "102.6 mm"             # optional, default from the parameters
    mu = 0.27

    [[network.nodes]]
    name = "support"
    mass = "0.3 kg"

    [[network.levers]]             # replaces the lever of Model 2 (same name)
    name = "lever"
    tip = "tip"
    edge = "edge"
    pivot = "support"
    ratio = -4.0
    stiffness = "1.18 MN/m"

    [[network.springs]]
    name = "support"
    a = "ground"
    b = "support"
    stiffness = "60 MN/m"          # or: curve = "support.csv"
    prestrain = "0.1 mm"
"""

from __future__ import annotations

from pathlib import Path

from ..curves import Curve
from ..errors import DataError, ParameterError
from ..io import read_table
from ..params import load_toml
from ..units import to_si
from .models import ClutchModel, EClutchParameters, build_model
from .network import AxialNetwork, Lever, Node, Spring, zero_input

__all__ = ["load_variant"]

_NODE_KEYS = {"name", "mass"}
_SPRING_KEYS = {"name", "a", "b", "curve", "stiffness", "prestrain", "scale", "unilateral", "gain"}
_LEVER_KEYS = {"name", "tip", "edge", "pivot", "ratio", "stiffness", "prestrain"}
_TOP_KEYS = {"name", "base", "bearing_preload", "input", "normal_force", "r_eff", "mu", "nodes", "springs", "levers"}


def _check_keys(where: str, table: dict, allowed: set, required: set):
    if not isinstance(table, dict):
        raise ParameterError(f"{where}: expected a table, got {table!r}")
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise ParameterError(f"{where}: unknown key {unknown[0]!r} (allowed: {', '.join(sorted(allowed))})")
    missing = sorted(required - set(table))
    if missing:
        raise ParameterError(f"{where}: missing key {missing[0]!r}")


def _curve(where: str, table: dict, folder: Path) -> Curve:
    if ("curve" in table) == ("stiffness" in table):
        raise ParameterError(f"{where}: give exactly one of 'curve' (CSV file) or 'stiffness'")
    if "stiffness" in table:
        k = to_si(table["stiffness"], "N/m", name=f"{where}.stiffness")
        return Curve.linear(k, name=table["name"])
    path = folder / str(table["curve"])
    try:
        frame = read_table(path, ["deflection_m", "force_N"])
    except DataError as exc:
        raise ParameterError(f"{where}.curve: {exc}") from None
    return Curve(frame["deflection_m"].to_numpy(), frame["force_N"].to_numpy(), kind="pchip", name=table["name"])


def load_variant(path, params: EClutchParameters | None = None) -> ClutchModel:
    """Build a :class:`ClutchModel` from a TOML network description (see module docstring).

    Parameters
    ----------
    path : str or Path
        TOML file with a ``[network]`` table.
    params : EClutchParameters, optional
        Parameters of the base model (default: bundled defaults).

    Raises
    ------
    ParameterError
        Unknown or missing keys, wrong units, unknown nodes, bad values --
        naming the file, the entry and the key.
    """
    path = Path(path)
    data = load_toml(path)
    if "network" not in data:
        raise ParameterError(f"{path}: no [network] table")
    top = data["network"]
    src = str(path)
    _check_keys(f"{src}: [network]", top, _TOP_KEYS, set())
    params = params or EClutchParameters()
    preload = to_si(top.get("bearing_preload", params.bearing_preload), "N", name="network.bearing_preload", source=src)
    if "base" in top:
        base = build_model(top["base"], params)
    else:
        base = None
    nodes = []
    for k, entry in enumerate(top.get("nodes", [])):
        where = f"{src}: network.nodes[{k}]"
        _check_keys(where, entry, _NODE_KEYS, {"name"})
        nodes.append(Node(str(entry["name"]), to_si(entry.get("mass", 0.0), "kg", name=f"{where}.mass")))
    def replaced(entry):
        """The element of the base model that ``entry`` replaces (None if it adds one)."""
        if base is not None and entry["name"] in {e.name for e in base.elements}:
            return base.element(entry["name"])
        return None

    def prestrain(where, entry):
        # a replaced element keeps the pre-strain of the element it replaces unless one is given
        if "prestrain" in entry:
            return to_si(entry["prestrain"], "m", name=f"{where}.prestrain")
        old = replaced(entry)
        return old.prestrain if old is not None else 0.0

    def inherited(entry, key, default):
        # ... and its other settings: Model 4's diaphragm keeps b = "support" and its x1.3 scale
        old = replaced(entry)
        return getattr(old, key) if isinstance(old, Spring) and key not in entry else entry.get(key, default)

    elements = []
    for k, entry in enumerate(top.get("springs", [])):
        where = f"{src}: network.springs[{k}]"
        _check_keys(where, entry, _SPRING_KEYS, {"name", "a"})
        elements.append(Spring(
            str(entry["name"]), str(entry["a"]), _curve(where, entry, path.parent),
            b=str(inherited(entry, "b", "ground")),
            prestrain=prestrain(where, entry),
            scale=to_si(inherited(entry, "scale", 1.0), "1", name=f"{where}.scale"),
            unilateral=bool(inherited(entry, "unilateral", False)),
            gain=to_si(inherited(entry, "gain", 1.0), "1", name=f"{where}.gain")))
    for k, entry in enumerate(top.get("levers", [])):
        where = f"{src}: network.levers[{k}]"
        _check_keys(where, entry, _LEVER_KEYS, {"name", "tip", "edge", "ratio"})
        stiffness = entry.get("stiffness")
        elements.append(Lever(
            str(entry["name"]), str(entry["tip"]), str(entry["edge"]), to_si(entry["ratio"], "1", name=f"{where}.ratio"),
            pivot=str(entry.get("pivot", "ground")),
            stiffness=None if stiffness is None else to_si(stiffness, "N/m", name=f"{where}.stiffness"),
            prestrain=prestrain(where, entry)))
    name = str(top.get("name", path.stem))
    try:
        if base is not None:
            existing = {e.name for e in base.elements}
            replace = {e.name: e for e in elements if e.name in existing}
            added = tuple(e for e in elements if e.name not in existing)
            known_nodes = {n.name for n in base.nodes}
            dup = [n.name for n in nodes if n.name in known_nodes]
            if dup:
                raise ParameterError(f"node {dup[0]!r} already exists in Model {top['base']}")
            network = base.modified(nodes=tuple(nodes), replace=replace, add=added, name=name)
            explicit = {str(e["name"]) for e in top.get("springs", []) if "prestrain" in e}
            if "bearing" not in explicit:
                # the replaced elements change the engaged state: zero the bearing contact again at the
                # CSC preload, as build_model does (bearing position 0 = engaged clutch, bearing at preload)
                network = zero_input(network, "bearing", preload)
        else:
            network = AxialNetwork(tuple(nodes), tuple(elements), input=str(top.get("input", "bearing")),
                                   normal_force=str(top.get("normal_force", "cushion")), name=name)
    except ParameterError as exc:
        raise ParameterError(f"{src}: {exc}") from None
    r_eff = to_si(top.get("r_eff", params.r_eff), "m", name="network.r_eff", source=src)
    mu = to_si(top.get("mu", params.mu), "1", name="network.mu", source=src)
    return ClutchModel(network, r_eff=r_eff, mu=mu)
