"""Compiled functions called through their addresses (:mod:`clutchlab.numerics.outline`).

The driveline's event iteration, stuck-set repair and invariant check are called this way so that the functions
of the core below the hooks do not link (and compile again) their code.  The call must be the one numba makes:
same result, exceptions reaching the caller's caller; a caller that cannot find the function raises, never calls
through a bad address; and the caller's code does not contain the function.
"""

from __future__ import annotations

import math
import re

import numba
import numpy as np
import pytest
from numba.core import types

from clutchlab.numerics import outline


@numba.njit
def _weighted(x, k, out):
    """A function with an array argument written into, a scalar and a result; raises for a negative ``k``."""
    if k < 0:
        raise ValueError("k must be >= 0")
    s = 0.0
    for i in range(x.shape[0]):
        out[i] = x[i] * k
        s += math.sin(x[i]) * k
    return s


_SIG = (types.float64[::1], types.int64, types.float64[::1])
_weighted_outlined = outline.outlined(_weighted, lambda: _SIG, types.float64)


@numba.njit
def _caller(x, k, out):
    return _weighted_outlined(x, k, out) + 1.0


@numba.njit
def _caller_other_types(x, k, out):
    # a float k is not the outlined signature: an ordinary linked call
    return _weighted_outlined(x, float(k), out) + 1.0


def test_a_call_through_the_address_is_the_call_numba_makes():
    x = np.linspace(0.0, 1.0, 7)
    out = np.zeros(7)
    assert _caller(x, 3, out) == pytest.approx(3.0 * np.sin(x).sum() + 1.0, rel=1e-15)
    np.testing.assert_array_equal(out, 3 * x)
    with pytest.raises(ValueError, match="k must be >= 0"):
        _caller(x, -1, out)


def test_the_caller_does_not_contain_the_function():
    x, out = np.zeros(3), np.zeros(3)
    _caller(x, 1, out)
    ir = next(iter(_caller.inspect_llvm().values()))
    assert outline.RESOLVE_SYMBOL in ir
    defines = re.compile(r"_ZN\w*9_weightedB")   # the function's compiled name: defined, or inlined (its metadata)
    assert not defines.search(ir)   # the outlined function's body is not in its caller
    _caller_other_types(x, 1, out)
    assert defines.search(next(iter(_caller_other_types.inspect_llvm().values())))   # other types: linked


def test_a_caller_that_cannot_find_the_function_raises():
    @numba.njit
    def lost(x, k, out):
        return x[0] * k

    sig = (types.float64[::1], types.int64, types.float64[::1])
    stub = outline.outlined(lost, lambda: sig, types.float64)

    @numba.njit
    def caller(x, k, out):
        return stub(x, k, out)

    x = np.ones(2)
    caller.compile((types.float64[::1], types.int64, types.float64[::1]))
    # the function is no longer known in this process (a cached caller older than the code): a clean error
    outline._ENTRIES.remove(next(e for e in outline._ENTRIES if e.dispatcher is lost))
    with pytest.raises(RuntimeError, match="not available in this process"):
        caller(x, 2, x)
    assert outline._resolve(12345) == 0


def test_prepare_compiles_every_outlined_function_of_the_driveline():
    """``prepare`` compiles every outlined function but the lazy ones (the repair of a stuck set over several null
    directions, a rare path; the laws of a shifted E-clutch and of a friction map read at a heat port's temperature,
    for networks that have one; the invariant check, a debug option) and those of a group (the hooks of a network
    with model components), ``prepare(groups=("coupled",))`` the group's, ``prepare(lazy=True)`` the lazy ones."""
    from clutchlab.driveline import kernel as K

    from clutchlab.driveline import coupled as DC

    from clutchlab.emtc import system as ES

    lazy = [K._repair_space, K._small_solve, K.shifted_curve, K.shifted_liftoff, K.friction_map, K.check_invariants]
    assert [e.dispatcher for e in outline._ENTRIES if e.lazy] == lazy
    coupled = [e.dispatcher for e in outline._ENTRIES if e.group == "coupled"]
    assert coupled == [DC._evaluate, DC._components_rhs, DC.coupled_outputs, DC.coupled_update, DC.coupled_restart,
                       DC.coupled_accept, DC._watch_rates, DC._components_start, DC._components_next_break,
                       DC._keep_rows]
    assert [e.dispatcher for e in outline._ENTRIES if e.group == "emtc"] == [ES._evaluate_into, ES._update,
                                                                             ES._controller]
    assert all(e.group is None for e in outline._ENTRIES if e.dispatcher.py_func.__module__ == K.__name__)
    outline.prepare()
    for fn in (K._repair, K.settle, K.driveline_rhs, K._solve_stuck, K._margin_rates, K._eliminate):
        entry = next(e for e in outline._ENTRIES if e.dispatcher is fn)
        assert entry.sig() in fn.overloads
    outline.prepare(groups=("coupled",))
    for fn in coupled:
        entry = next(e for e in outline._ENTRIES if e.dispatcher is fn)
        assert entry.sig() in fn.overloads
    outline.prepare(lazy=True)
    for fn in lazy:
        entry = next(e for e in outline._ENTRIES if e.dispatcher is fn)
        assert entry.sig() in fn.overloads


_UNCHECKED = r"""
import json
from pathlib import Path
from clutchlab.driveline import coupled as DC, kernel as K
from clutchlab.driveline.description import load_driveline
from clutchlab.emtc import system as S
from clutchlab.hysteresis import kernels as H
load_driveline(Path(r"{examples}") / "driveline_coupled_clutches.toml").driveline.simulate(0.05)
print(json.dumps([len(K.check_invariants.overloads), len(K._repair_space.overloads), len(K._small_solve.overloads),
                  len(K.settle.overloads),
                  len(DC.coupled_update.overloads) + len(DC._components_rhs.overloads) + len(DC._evaluate.overloads)
                  + len(DC._components_start.overloads) + len(DC._components_next_break.overloads)
                  + len(DC._keep_rows.overloads),
                  sum(len(f.overloads) for f in (S.derive_actuator, S.derive_vehicle, S._outside, H.gap_weights,
                                                 H.combine_tables, H.locate))]))
"""


def test_a_run_without_the_check_does_not_compile_it():
    """A run without ``check_invariants`` neither compiles nor loads the check, one whose stuck sets never lose
    their split along several null directions neither the repair over them (nor its small solves), and a plain
    network none of the hooks of a network with model components, nor any EMTC function (its empty EMTC block's
    types come from ``params_template``; packed from a magnet, they compiled the magnet's tables and the start's
    derivations) (a fresh process)."""
    import json
    import subprocess
    import sys
    from pathlib import Path

    examples = Path(__file__).resolve().parents[2] / "examples"
    proc = subprocess.run([sys.executable, "-c", _UNCHECKED.format(examples=examples)], capture_output=True,
                          text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert json.loads(proc.stdout.strip().splitlines()[-1]) == [0, 0, 0, 1, 0, 0]


_LOOP = r"""
import json, sys
sys.path.insert(0, r"{support}")
from driveline_networks import indeterminate_loop
from clutchlab.driveline import kernel as K

before = len(K._repair_space.overloads)
res = indeterminate_loop().simulate(1.0, output_step=2e-3, rtol=1e-8)
ev = [[float(t), str(el), str(e)] for t, el, e in zip(res.events.time_s, res.events.element, res.events.event)]
from clutchlab.numerics import outline
sigs = {{fn.__name__: [sig == next(e for e in outline._ENTRIES if e.dispatcher is fn).sig() for sig in fn.overloads]
        for fn in (K._repair_space, K._small_solve, K._eliminate)}}
print(json.dumps([before, len(K._repair_space.overloads), ev, sigs]))
"""


def test_a_rare_path_is_compiled_at_its_first_call_and_gives_the_same_run():
    """``_repair_space`` is outlined lazily: a fresh process whose network needs it (the rigid loop of
    ``test_a_statically_indeterminate_loop_holds_while_any_split_holds``, seven stuck members on four inertias)
    compiles or loads it from inside the running kernel, at its first call (:func:`outline._resolve`), and the run
    is the one this process makes with it prepared ahead."""
    import json
    import subprocess
    import sys
    from pathlib import Path

    from driveline_networks import indeterminate_loop

    support = Path(__file__).resolve().parents[1] / "_support"
    proc = subprocess.run([sys.executable, "-c", _LOOP.format(support=support)], capture_output=True, text=True,
                          timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    before, after, events, sigs = json.loads(proc.stdout.strip().splitlines()[-1])
    assert (before, after) == (0, 1)
    # (the repair's own calls, compiled at its first call, go through the outlined signatures too)
    assert sigs == {"_repair_space": [True], "_small_solve": [True], "_eliminate": [True]}, sigs
    outline.prepare(lazy=True)
    res = indeterminate_loop().simulate(1.0, output_step=2e-3, rtol=1e-8)
    here = [[float(t), str(el), str(e)] for t, el, e in zip(res.events.time_s, res.events.element, res.events.event)]
    assert [e[1:] for e in events] == [e[1:] for e in here] and any(e[1] == "loop" for e in here)
    assert max(abs(a[0] - b[0]) for a, b in zip(events, here)) < 1e-9


_NETWORKS = r"""
import json
from pathlib import Path
from clutchlab.driveline import kernel as K
from clutchlab.driveline.description import load_driveline
from clutchlab.numerics import outline
for name in ("coupled_clutches", "wet_sae2", "emtc_awd", "eclutch_launch"):
    load_driveline(Path(r"{examples}") / f"driveline_{{name}}.toml").driveline.simulate(0.05, check_invariants=True)
from clutchlab.driveline import coupled as DC
out = {{}}
for fn in (K.settle, K._solve_stuck, K._repair, K.check_invariants, K.driveline_rhs, K._margin_rates, DC._evaluate,
           DC._components_rhs, DC.coupled_outputs, DC.coupled_update, DC.coupled_restart, DC.coupled_accept,
           DC._components_start, DC._components_next_break, DC._keep_rows):
    entry = next(e for e in outline._ENTRIES if e.dispatcher is fn)
    out[fn.__name__] = [sig == entry.sig() for sig in fn.overloads]
print(json.dumps(out))
"""


def test_the_example_networks_call_the_driveline_through_the_outlined_signatures():
    """Plain, wet and EMTC networks call the outlined functions with the very types they are outlined for (the
    network's right-hand side at events too, through the core's ``rhs_event`` hook; a network with model components
    its hooks and its components' evaluation at events, :mod:`clutchlab.driveline.coupled`): a
    signature drift (a new field of the parameter structure, another log type) would link them again silently,
    compiled once more in every function of the core.  (A fresh process: tests here call kernel functions directly.)"""
    import json
    import subprocess
    import sys
    from pathlib import Path

    examples = Path(__file__).resolve().parents[2] / "examples"
    proc = subprocess.run([sys.executable, "-c", _NETWORKS.format(examples=examples)], capture_output=True,
                          text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    names = ("settle", "_solve_stuck", "_repair", "check_invariants", "driveline_rhs", "_margin_rates", "_evaluate",
             "_components_rhs", "coupled_outputs", "coupled_update", "coupled_restart", "coupled_accept",
             "_components_start", "_components_next_break", "_keep_rows")
    assert out == {name: [True] for name in names}, out


_BENCH = r"""
import json
from clutchlab.emtc import system as S
from clutchlab.emtc.bench import BenchScenario, simulate_bench
from clutchlab.emtc.magnet import bundled_magnet
from clutchlab.numerics import outline
model = bundled_magnet()
res = simulate_bench(model, BenchScenario(duration=0.3), controller_model=model)
out = {{}}
for fn in (S._evaluate_into, S._update, S._controller):
    entry = next(e for e in outline._ENTRIES if e.dispatcher is fn)
    out[fn.__name__] = [sig == entry.sig() for sig in fn.overloads]
print(json.dumps([out, len(res.events.time_s)]))
"""


def test_the_emtc_bench_calls_its_hooks_through_the_outlined_signatures():
    """The EMTC's evaluation at a point, its event update and its controller sample run through their addresses, with
    the very types they are outlined for (:mod:`clutchlab.emtc.system`): each compiled once, for that signature only.  A signature drift (a
    new field of :class:`~clutchlab.emtc.system.EmtcParams` the template lacks) would compile a second, linked copy
    into every function of the core that calls the hook.  (A fresh process, running only the bench.)"""
    import json
    import subprocess
    import sys

    proc = subprocess.run([sys.executable, "-c", _BENCH.format()], capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out, events = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out == {"_evaluate_into": [True], "_update": [True], "_controller": [True]}, out
    assert events > 0   # (the run had events: its update hook ran)


def _fresh_llvm(fn, sig) -> str:
    """The LLVM text of ``fn`` compiled for ``sig`` afresh (not from numba's cache, whose code is not kept to be
    read)."""
    fresh = numba.njit(fn.py_func)
    fresh.compile(sig)
    return fresh.inspect_llvm(sig)


def test_the_emtc_hooks_do_not_contain_the_outlined_functions():
    """The EMTC's registered update hook and its evaluation at a point, compiled for the hooks' signature, call the
    update and the right-hand side through their addresses: their code holds neither the update's memory commit nor
    the right-hand side (which would be compiled again into every function of the core that calls them)."""
    from clutchlab.emtc import system as S
    from clutchlab.numerics import dispatch

    assert dispatch._MODELS[S.EmtcParams]["update"] is S._update_hook
    bodies = re.compile(r"_ZN\w*(4_rhs|7_commit|7_switch)B")   # compiled names: defined, declared or inlined
    for fn, sig in ((S._update_hook, S._hook_args(types.int64, S._log_type())), (S._evaluate, S._hook_args()),
                    (S._update, S._hook_args(types.int64, S._log_type()))):
        ir = _fresh_llvm(fn, sig)
        if fn is S._update:   # the update itself holds them: the pattern finds what it looks for
            assert bodies.search(ir)
        else:
            assert outline.RESOLVE_SYMBOL in ir and not bodies.search(ir), fn.__name__


def test_the_emtc_restart_calls_its_controller_through_its_address():
    """The EMTC's restart hook (a run's start, each break: linked into several functions of the core) calls the
    controller sample through its address: its code holds none of the controller's force and inverse (Eqs. 11-15,
    6-7), which the controller's own code does hold.  One compiled copy of the controller gives every caller the same
    command to the last bit; linked copies, optimised with fast-math flags each in its caller, need not (a 1-ulp
    difference between a co-simulation stepping across sample instants and one stepping on them, once in CI)."""
    from clutchlab.emtc import system as S

    bodies = re.compile(r"_ZN\w*(22commanded_magnet_force|15invert_combined)B")
    for fn, sig in ((S._restart, S._hook_args(S._log_type())), (S._controller, S._controller_args())):
        ir = _fresh_llvm(fn, sig)
        if fn is S._controller:   # the controller itself holds them: the pattern finds what it looks for
            assert bodies.search(ir)
        else:
            assert outline.RESOLVE_SYMBOL in ir and not bodies.search(ir)


def test_the_emtc_template_has_the_type_of_a_packed_bench():
    """The signatures of the EMTC's outlined hooks come from :func:`~clutchlab.emtc.system.params_template`: its numba
    type must be that of the parameters of a bench as packed for a run, with a friction map and with LuGre."""
    from clutchlab.emtc import system as S
    from clutchlab.emtc.friction import LuGreParameters
    from clutchlab.emtc.magnet import bundled_magnet

    template = numba.typeof(S.params_template())
    magnet = bundled_magnet()
    for options in (None, S.BenchOptions(lugre=LuGreParameters()), S.BenchOptions(coil_drive="current")):
        for cosimulation in (False, True):
            packed = S.pack_parameters(magnet, options=options, cosimulation=cosimulation, n_samples=3)
            assert numba.typeof(packed) == template
