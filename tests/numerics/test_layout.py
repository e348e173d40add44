"""Index constants generated from declarations (:mod:`clutchlab.numerics.layout`), and the modules that use them
written without a hand-written index: every module-level integer constant of theirs comes from a declaration."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

import clutchlab
from clutchlab.numerics.layout import indices, slots

ROOT = Path(clutchlab.__file__).parent

#: the modules whose layouts are generated: the three models, the driveline's kernel and its blocks, the core's
#: solver state, the session's report kinds, the sampled controllers' and the wet friction laws' kinds
GENERATED = ("wet/system.py", "emtc/system.py", "eclutch/system.py", "driveline/kernel.py", "driveline/wet.py",
             "driveline/emtc.py", "driveline/block.py", "numerics/core.py", "numerics/session.py",
             "numerics/sampled.py", "wet/friction.py", "numerics/rosenbrock.py", "numerics/exchange.py",
             "numerics/status.py", "numerics/calls.py", "fmu/native/__init__.py", "system.py", "emtc/bench.py")
#: integers in them that are numbers, not positions (name: why)
NOT_INDICES = {
    "ERR_PLANT_MEMORY": "a model error code (negative: the hooks' convention)",
    "ERR_CONTROLLER_MEMORY": "a model error code",
    "ERROR_STRIDE": "the spacing of the couplings' error codes",
    "INV_BASE": "the base of the driveline's invariant error codes",
    "SPACE_SLOTS": "a capacity: the stuck-set repair's warm starts kept",
    "TERMINAL": "a code a model's update returns (0 is go on, negative an error)",
    "RESTART": "a code a model's update returns",
    "WAYPOINT_ALWAYS": "a switching function's crossing direction (the core's codes: +-1, +-2, +-3, 4, 5)",
    "ADVANCE": "a bit of a session call's request",
    "OUTPUTS": "a bit of a session call's request",
    "ALGEBRAIC_FAILED": "a model error code of the model exchange",
    "NEWTON_ITERATIONS": "a count: the algebraic rows' Newton iterations",
    "REFINE_MAX": "a count: the stuck set's refinements at most",
    "ACTIVE_STEPS": "a count: the split search's simplex and active-set steps per variable and bound at most",
    "ENUMERATED_DIMENSIONS": "a dimension: the split search enumerates up to it",
    "ORDER_EST": "a number: the local order of Rodas3's error estimate",
    "CHUNK_ROWS": "a capacity: rows of a recorded chunk",
    "FIRST_CHUNK_ROWS": "a capacity: rows of the first recorded chunk",
    "EVENT_CAPACITY": "a capacity: events recorded",
    "_CHECKED_GRIDS_SIZE": "a capacity: output grids remembered as checked",
    "_PIPELINE_RESERVE": "a capacity: a pipeline's reserve of rows",
}


def test_indices_follow_the_declaration_by_name():
    decl = (("x", "m", "position"), ("v", "m_s", "speed"), ("a", "m_s2", "acceleration"))
    assert indices(decl, "v") == 1
    assert indices(decl, "a", "x") == (2, 0)
    assert indices(("p", "q"), "q") == 1
    with pytest.raises(KeyError, match="'w' is not declared.*x, v, a"):
        indices(decl, "w")
    with pytest.raises(ValueError, match="names x twice"):
        indices((("x",), ("x",)), "x")


def test_bits_are_one_flag_per_entry():
    from clutchlab.numerics import calls, exchange
    from clutchlab.numerics.layout import bits

    assert bits(("a", "b", "c"), "c") == 4 and bits(("a", "b", "c"), "b", "a") == (2, 1)
    with pytest.raises(KeyError, match="'d' is not declared"):
        bits(("a", "b"), "d")
    flags = [getattr(exchange, "ME_" + n.upper()) for n in exchange.ME_REQUESTS]
    assert flags == [1 << k for k in range(len(flags))]
    assert (calls.ADVANCE, calls.OUTPUTS) == (1, 2)


def test_slots_are_consecutive_and_sum_to_the_total():
    s = slots(("x", 12), ("dx", 12), ("g", 5), ("none", 0), ("y", 3))
    assert s.of("x", "dx", "g", "none", "y") == (0, 12, 24, 29, 29)
    assert s["y"] == 29 and s.total == 32 and s.size["g"] == 5
    with pytest.raises(KeyError, match="no slot 'z'"):
        s["z"]
    for bad in ((("x", 1), ("x", 2)), (("x", -1),), (("x", 1.0),), (("x", True),)):
        with pytest.raises(ValueError):
            slots(*bad)


@pytest.mark.parametrize("module, declaration, prefix", [
    ("clutchlab.wet.system", "STATES", "S_"), ("clutchlab.wet.system", "OUTPUTS", "O_"),
    ("clutchlab.wet.system", "SWITCHING", "G_"), ("clutchlab.wet.system", "EVENTS", "EV_"),
    ("clutchlab.emtc.system", "EVENTS", "EV_"), ("clutchlab.emtc.system", "AUX", "AUX_"),
    ("clutchlab.emtc.system", "TABLES", "L_"), ("clutchlab.eclutch.system", "ACTUATOR_VECTOR", "P_"),
    ("clutchlab.eclutch.system", "EVENTS", "EV_"), ("clutchlab.eclutch.system", "WORK_ROWS", "W_"),
    ("clutchlab.driveline.kernel", "EVENTS", "EV_"), ("clutchlab.driveline.kernel", "ELEM_COLUMNS", "E_"),
    ("clutchlab.driveline.kernel", "SIGNAL_KINDS", "SIG_"), ("clutchlab.driveline.kernel", "ELEMENT_KINDS", "K_"),
    ("clutchlab.numerics.core", "SOLVER_FLOATS", "SF_"), ("clutchlab.numerics.core", "SOLVER_INTS", "SI_"),
    ("clutchlab.numerics.calls", "REPORT_KINDS", "REPORT_"), ("clutchlab.wet.friction", "FRICTION_KINDS", "KIND_"),
    ("clutchlab.numerics.status", "STATUSES", "="), ("clutchlab.numerics.rosenbrock", "ROW_KINDS", "="),
    ("clutchlab.fmu.native", "ROLES", "=_"),
])
def test_each_declared_entry_has_exactly_one_constant(module, declaration, prefix):
    """The constants of a declaration are a permutation of its positions (none missing, none twice)."""
    mod = importlib.import_module(module)
    if prefix.startswith("="):   # an enumeration whose constants are its names (SUCCESS, KEEP, _PARAMETER, ...)
        values = sorted(getattr(mod, prefix[1:] + e.upper()) for e in getattr(mod, declaration))
    else:
        values = sorted(v for k, v in vars(mod).items() if k.startswith(prefix) and k.isupper() and type(v) is int)
    assert values == list(range(len(getattr(mod, declaration))))


def test_the_block_layouts_are_their_models_declarations():
    from clutchlab.driveline import emtc as DE, wet as DW
    from clutchlab.emtc import system as S
    from clutchlab.wet import system as W

    for block, model in ((DW, W), (DE, S)):
        n_x, n_g, n_u, n_y = len(model.STATES), len(model.SWITCHING), len(model.INPUTS), len(model.OUTPUTS)
        assert (block.B_X, block.B_DX, block.B_G, block.B_U, block.B_Y, block.N_BUF) == (
            0, n_x, 2 * n_x, 2 * n_x + n_g, 2 * n_x + n_g + n_u, 2 * n_x + n_g + n_u + n_y)
        assert (block.F_K, block.F_ROW, block.F_X, block.F_G, block.F_M, block.F_EV, block.F_EL) == tuple(range(7))
    assert (DW.F_U, DW.N_CONF) == (7, 8)
    assert (DE.F_PORT, DE.N_CONF) == (7, 7 + DE.N_PORT)
    assert W.N_WORK == 2 + W.N_OUT + W.N_STATE + W.N_SWITCH + 2


def _hand_written(path: Path, root: Path = ROOT) -> list:
    """Module-level assignments of integer literals (alone, in a tuple, or ``range(n)``) to upper-case names."""
    found = []
    for node in ast.parse(path.read_text(encoding="utf-8"), str(path)).body:
        if not isinstance(node, (ast.Assign, ast.AnnAssign)):
            continue
        targets = node.targets if isinstance(node, ast.Assign) else [node.target]
        names = [n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name) and n.id.isupper()]
        value = node.value
        literal = (isinstance(value, ast.Constant) and type(value.value) is int) or (
            isinstance(value, ast.UnaryOp) and isinstance(value.operand, ast.Constant)
            and type(value.operand.value) is int) or (
            isinstance(value, ast.Call) and isinstance(value.func, ast.Name) and value.func.id == "range")
        if isinstance(value, ast.Tuple):
            literal = any(isinstance(e, ast.Constant) and type(e.value) is int for e in value.elts)
        if isinstance(value, ast.BinOp):   # an offset computed by hand: NAME + 6
            literal = any(isinstance(n, ast.Constant) and type(n.value) is int for n in ast.walk(value))
        if literal:
            found += [f"{path.relative_to(root)}:{node.lineno} {n}" for n in names if n not in NOT_INDICES]
        # names unpacked from the declaration itself (``indices(D, *D)``, ``S.of(*S.offset)``): a renamed or
        # reordered entry would rename or move the constants with it instead of being refused
        unpacked = isinstance(value, ast.Call) and any(isinstance(a, ast.Starred) for a in value.args) and (
            (isinstance(value.func, ast.Name) and value.func.id == "indices")
            or (isinstance(value.func, ast.Attribute) and value.func.attr == "of"))
        if unpacked:
            found += [f"{path.relative_to(root)}:{node.lineno} {n} (names unpacked)" for n in names]
    return found


@pytest.mark.parametrize("relative", GENERATED)
def test_no_hand_written_index_in_the_generated_modules(relative):
    assert _hand_written(ROOT / relative) == []


def test_the_check_sees_a_hand_written_index(tmp_path):
    f = tmp_path / "m.py"
    f.write_text("A, B = range(2)\nC = 3\nD = (0, 1)\nE = A + 6\nF = -1\nG = len(())\nH = 1e-6\nI = X.of('a')\n"
                 "J, K = indices(Q, *Q)\nL, M = X.of(*X.offset)\nN, O = indices(Q, 'n', 'o')\n")
    assert [s.split()[1] for s in _hand_written(f, tmp_path)] == ["A", "B", "C", "D", "E", "F", "J", "K", "L", "M"]


def test_the_eclutch_outputs_are_its_declaration():
    """The E-clutch's outputs hook writes each output at its declared position: the named head (:data:`OUTPUTS`),
    the input of the input mode, then the elements' forces (the names the system publishes, in that order)."""
    from clutchlab import system as contract
    from clutchlab.eclutch import system as E

    assert set(E.INPUT_OUTPUTS) == set(E.INPUT_MODES)
    assert (E.Y_INPUT, E.Y_ELEMENTS) == (len(E.OUTPUTS), len(E.OUTPUTS) + 1)
    system = contract.MODELS["eclutch"]()
    for name, *_ in E.OUTPUTS:
        assert system.output_index(name) == E.indices(E.OUTPUTS, name)
    _dx, _g, y = contract.evaluate(system)
    assert y[E.Y_BEARING_FORCE_CLUTCH] == y[system.output_index("bearing_force_clutch")]
    names = [v.name for v in system.outputs]
    assert names[E.Y_INPUT] in [spec[0] for spec in E.INPUT_OUTPUTS.values()]
