"""Native FMUs (:mod:`clutchlab.fmu.native`, issue #32): the model's compiled code with an FMI 2.0 (and 3.0)
layer, run with no Python, numba or clutchlab in the host.

Checked against the Python co-simulation of the same class (``ContractCoSimulation``, the same compiled
functions run through numba) at the same communication points, in FMPy in a virtual environment without
clutchlab, numba and llvmlite (and with them refused by an import hook there as well), and in a small C host
(``native_host.c``) with no Python in the process: two instances in two threads, 10,000 instantiate/free
cycles with flat memory, rollback through ``fmi2Get/SetFMUstate`` and serialisation, refused values with their
messages, 100 fresh processes ending with exit code 0, the model-exchange loop on linux64 and win64.  The FMI
3.0 co-simulation FMU in FMPy's FMI 3.0 slave.
"""

import json
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest

from clutchlab.cli import main
from clutchlab.errors import ParameterError
from clutchlab.fmu.driveline import DrivelineCoSimulation
from clutchlab.fmu.native import NativeExportError, export_native_fmu, native_identifier
from clutchlab.fmu.native.image import accepted_range
from driveline_networks import INPUTS_TOML

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "driveline_coupled_clutches.toml"
#: a one-way clutch whose flange b (J2) overruns flange a (J1) at the start; J1's drive catches J2 up at t = 1 s
FREEWHEEL_TOML = """
[driveline]
name = "freewheel"

[inertia.J1]
J = "1 kg m^2"
w0 = "2 rad/s"

[inertia.J2]
J = "0.5 kg m^2"
w0 = "3 rad/s"

[one_way_clutch.f]
a = "J1"
b = "J2"

[torque.drive]
flange = "J1"
torque = "1 N m"
"""
HERE = Path(__file__).resolve().parent
HEADERS = HERE.parents[1] / "src" / "clutchlab" / "fmu" / "shim"

pytestmark = pytest.mark.skipif(not (sys.platform.startswith("linux") and shutil.which("cc") and shutil.which("c++")),
                                reason="native FMUs are built on Linux x86-64 with a C and a C++ compiler")


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The native FMUs of the coupled clutches, of a network with inputs and of a freewheel, and their classes."""
    folder = tmp_path_factory.mktemp("native")
    (folder / "inputs.toml").write_text(INPUTS_TOML)
    out = {}
    (folder / "freewheel.toml").write_text(FREEWHEEL_TOML)
    for key, desc in (("cc", EXAMPLE), ("inputs", folder / "inputs.toml"), ("freewheel", folder / "freewheel.toml")):
        cls = DrivelineCoSimulation.for_description(desc)
        lines = []
        path = export_native_fmu(cls, folder / f"{key}.fmu", platforms=["linux64"], report=lines.append)
        out[key] = (path, cls, lines)
    return out


@pytest.fixture(scope="module")
def native_model(tmp_path_factory):
    """``native_model(model)`` -> (path, export report lines) of the native FMU of ``"wet"``, ``"emtc"`` or
    ``"eclutch"``'s co-simulation, exported once per module (each export links the model's compiled code)."""
    from clutchlab.fmu.cosim import load_cosimulation

    folder = tmp_path_factory.mktemp("native_models")
    cache = {}

    def build(model):
        if model not in cache:
            lines = []
            path = export_native_fmu(load_cosimulation(model), folder / f"{model}.fmu", platforms=["linux64"],
                                     report=lines.append)
            cache[model] = (path, lines)
        return cache[model]

    return build


def _variables(path):
    root = ET.fromstring(zipfile.ZipFile(path).read("modelDescription.xml"))
    return root, {sv.get("name"): sv for sv in root.iter("ScalarVariable")}


def _python_run(cls, n, dt, start=None, inputs=None):
    """The Python co-simulation's outputs at 0, dt, ..., n dt (inputs: name -> array of n + 1 held values)."""
    sim = cls(**(start or {}))
    names = [v.name for v in cls.outputs]
    inputs = inputs or {}

    def held(k):
        return {name: float(values[k]) for name, values in inputs.items()}

    rows = [sim.initial_outputs(held(0))]
    for k in range(n):   # (FMPy's communication points: t_k = k dt, a step of t_(k+1) - t_k)
        rows.append(sim.do_step(k * dt, (k + 1) * dt - k * dt, held(k)))
    return {name: np.array([r[name] for r in rows]) for name in names}


def _close(native, python, name, floor=1e-12):
    scale = max(float(np.max(np.abs(python))), 1e-300)
    np.testing.assert_allclose(native, python, rtol=0, atol=1e-9 * scale + floor, err_msg=name)


#: the head of every host script: clutchlab, numba, llvmlite and pythonfmu refused by an import hook
_REFUSE_IMPORTS = r"""
import importlib.abc, json, sys
class Refuse(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in ("clutchlab", "numba", "llvmlite", "pythonfmu"):
            raise ImportError(f"{name} is not importable in this host")
        return None
sys.meta_path.insert(0, Refuse())
"""


_FMPY_WITHOUT_CLUTCHLAB = _REFUSE_IMPORTS + r"""import numpy as np
import fmpy
from fmpy.validation import validate_fmu
spec = json.load(open(sys.argv[1]))
problems = validate_fmu(spec["path"])
assert not problems, problems
table = None
if spec["inputs"]:
    names = list(spec["inputs"])
    table = np.zeros(spec["n"] + 1, dtype=[("time", float)] + [(k, float) for k in names])
    table["time"] = np.arange(spec["n"] + 1) * spec["dt"]
    for k in names:
        table[k] = spec["inputs"][k]
options = {"relative_tolerance": spec["rtol"]} if spec["fmi_type"] == "ModelExchange" else {"step_size": spec["dt"]}
res = fmpy.simulate_fmu(spec["path"], stop_time=spec["n"] * spec["dt"], output_interval=spec["dt"],
                        start_values=spec["start"], input=table, fmi_type=spec["fmi_type"], **options)
if spec["fmi_type"] == "ModelExchange":   # (the rows at the communication points: after an event there)
    res = res[np.searchsorted(res["time"], np.arange(spec["n"] + 1) * spec["dt"] + 1e-12, side="right") - 1]
loaded = sorted(m for m in sys.modules if m.split(".")[0] in ("clutchlab", "numba", "llvmlite"))
assert not loaded, loaded
np.savez(spec["result"], **{k: res[k] for k in res.dtype.names})
"""


_ISOLATED = []


def _isolated_python():
    """The interpreter of a virtual environment without clutchlab, numba, llvmlite and pythonfmu (made once per
    process, offline): a venv with no site packages of its own but a ``.pth`` naming a folder of links to
    every top-level entry of this environment's site packages except those four (and except ``.pth`` files,
    so an editable clutchlab is not reachable either)."""
    if not _ISOLATED:
        import atexit
        import os
        import tempfile
        import venv

        import fmpy

        root = Path(tempfile.mkdtemp(prefix="clutchlab_fmpy_venv_"))
        atexit.register(shutil.rmtree, root, True)
        venv.create(root / "venv", with_pip=False, symlinks=os.name != "nt")
        python = root / "venv" / ("Scripts/python.exe" if os.name == "nt" else "bin/python")
        site = Path(subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                                   capture_output=True, text=True, check=True).stdout.strip())
        deps = root / "deps"
        deps.mkdir()
        here = Path(fmpy.__file__).resolve().parents[1]
        refused = {"clutchlab", "numba", "llvmlite", "pythonfmu"}
        for entry in here.iterdir():
            top = entry.name.split("-")[0].split(".")[0].lower()
            if top in refused or entry.suffix == ".pth" or entry.name.startswith("__editable__"):
                continue
            (deps / entry.name).symlink_to(entry)
        (site / "host_packages.pth").write_text(str(deps) + "\n")
        probe = subprocess.run([str(python), "-c", "import importlib.util as u, fmpy; print(*(u.find_spec(m) is None "
                                "for m in ('clutchlab', 'numba', 'llvmlite')))"], capture_output=True, text=True)
        assert probe.returncode == 0 and probe.stdout.split() == ["True"] * 3, (probe.stdout, probe.stderr)
        _ISOLATED.append(python)
    return _ISOLATED[0]


def _fmpy_run(tmp_path, path, n, dt, start=None, inputs=None, fmi_type="CoSimulation", rtol=1e-9):
    script = tmp_path / "host.py"
    script.write_text(_FMPY_WITHOUT_CLUTCHLAB)
    spec = tmp_path / "spec.json"
    result = tmp_path / "result.npz"
    spec.write_text(json.dumps({"path": str(path), "n": n, "dt": dt, "start": start or {}, "result": str(result),
                                "fmi_type": fmi_type, "rtol": rtol,
                                "inputs": {k: list(map(float, v)) for k, v in (inputs or {}).items()}}))
    proc = subprocess.run([str(_isolated_python()), str(script), str(spec)], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return dict(np.load(result))


def test_native_fmu_of_a_driveline_in_fmpy_without_clutchlab_equals_the_python_cosimulation(built, tmp_path):
    path, cls, lines = built["cc"]
    assert lines == ["native FMU Clutchlab_coupled_clutches (linux64; FMI 2.0 co-simulation and model exchange): 0 inputs, "
                     "30 outputs, 28 parameters (1 fixed at export)"]
    # (each clutch's mu_scale is a factor of its own in the kernel, not multiplied into its mu: both writable; until
    # the thirty-ninth session the two shared one number and mu_scale was fixed at export)
    _, svs = _variables(path)
    assert [svs[f"clutch{i}.mu_scale"].get("causality") for i in (1, 2, 3)] == ["parameter"] * 3
    assert [svs[f"clutch{i}.mu"].get("causality") for i in (1, 2, 3)] == ["parameter"] * 3
    assert [n for n, sv in svs.items() if sv.get("variability") == "constant"] == ["solver.fixed_step"]
    names = zipfile.ZipFile(path).namelist()
    assert sorted(names) == ["binaries/linux64/Clutchlab_coupled_clutches.so", "modelDescription.xml"]
    n, dt = 1200, 1e-3
    start = {"clutch1.fn_max": 25.0, "J2.J": 2.0, "clutch2.mu": 0.4, "clutch2.mu_scale": 1.3, "clutch3.mu_scale": 0.7}
    native = _fmpy_run(tmp_path, path, n, dt, start)
    python = _python_run(cls, n, dt, start)
    for name in python:
        _close(native[name], python[name], name)
    # (mu and its factor set together: the clutch slides with their product, as clutchlab's own run built so)
    product = _python_run(cls, n, dt, {"clutch1.fn_max": 25.0, "J2.J": 2.0, "clutch2.mu": 0.52, "clutch3.mu": 0.35})
    for name in python:
        np.testing.assert_allclose(python[name], product[name], rtol=1e-6, atol=1e-9, err_msg=name)
    # and the parameters changed the run (so the FMU did write them)
    default = _python_run(cls, n, dt)
    assert np.max(np.abs(default["J2.w"] - python["J2.w"])) > 1e-2


#: initial speeds a host sets that change the mode the run starts from and the stored energy (the example starts
#: with J1 at 10 rad/s and the others at rest: clutch1 sliding backward, w_b - w_a = -10 rad/s; clutch2 and clutch3
#: free until their forces rise): J1 at rest and J2 at 3 rad/s put clutch1 forward
_SPEEDS = {"J1.w0": 0.0, "J2.w0": 3.0, "J4.w0": -2.0}


def test_a_host_sets_the_initial_speeds_and_the_fmu_decides_the_start_modes_again(built, tmp_path):
    """The initial speeds are parameters of the native FMU (not fixed at export): each is a copy into the state, and
    the FMU runs the network's ``start`` again before the run (the modes it starts from, from the signs of the
    relative speeds, and the stored energy its energy balance starts from).  Set by a host, co-simulation equals
    clutchlab's own run built with those speeds (at t = 0 too: the modes and the energy balance), and model
    exchange under CVode agrees within the tolerance."""
    path, cls, _ = built["cc"]
    _, svs = _variables(path)
    for i in (1, 2, 3, 4):
        assert svs[f"J{i}.w0"].get("causality") == "parameter", i
        assert svs[f"J{i}.w0"].get("variability") == "fixed", i
    n, dt = 600, 1e-3
    native = _fmpy_run(tmp_path, path, n, dt, _SPEEDS)
    python = _python_run(cls, n, dt, _SPEEDS)
    for name in python:
        _close(native[name], python[name], name)
    default = _python_run(cls, n, dt)
    codes = {name: (python[name][0], default[name][0]) for name in ("clutch1.mode", "clutch2.mode", "clutch3.mode")}
    assert codes == {"clutch1.mode": (1.0, -1.0), "clutch2.mode": (2.0, 2.0), "clutch3.mode": (2.0, 2.0)}, codes
    # (the energy balance starts from the stored energy of the speeds the host set: 6.5 J, not the file's 50 J)
    assert native["kinetic_energy"][0] == pytest.approx(0.5 * 1.0 * 3.0 ** 2 + 0.5 * 1.0 * 2.0 ** 2)
    assert abs(native["energy_error"][0]) < 1e-12
    assert np.max(np.abs(native["energy_error"])) < 1e-6 * np.max(np.abs(native["kinetic_energy"]))
    (tmp_path / "me").mkdir()
    me = _fmpy_run(tmp_path / "me", path, n, dt, _SPEEDS, fmi_type="ModelExchange", rtol=1e-9)
    same = np.all([me[f"clutch{i}.mode"] == python[f"clutch{i}.mode"] for i in (1, 2, 3)], axis=0)
    assert same[0] and same.sum() >= n - 10
    for name in ("J1.w", "J2.w", "J3.w", "J4.w", "clutch1.tau"):
        scale = float(np.max(np.abs(python[name])))
        np.testing.assert_allclose(me[name][same], python[name][same], rtol=0, atol=2e-5 * scale, err_msg=name)


def test_a_parameter_s_range_ends_where_its_law_stops_holding(built, host, unpacked):
    """The FMU writes ``a * value + b`` found near the start; its range ends where the model builds something else
    (``image.law_holds``, searched as the accepted range is): the coupled clutches' absolute tolerances follow
    ``rtol`` down to a floor of 1e-12, so ``rtol``'s ``min`` is 1e-12 (it was the declared 100 eps, and a host's
    rtol of 1e-13 got absolute tolerances of 1e-13, not clutchlab's 1e-12), and a host's 1e-13 is refused."""
    path, _, _ = built["cc"]
    _, svs = _variables(path)
    low = float(svs["rtol"].find("Real").get("min"))
    assert 1e-12 <= low <= 1.001e-12, low
    lib, guid, vr, _ = unpacked
    status, text = _host(host, lib, guid, "refuse", vr["rtol"], "1e-13").stdout.split(" ", 1)
    assert int(status) == 3 and re.search(r"rtol = 1e-13 \[1\] is outside its range", text), text


_START_VALUES_HOST = _REFUSE_IMPORTS + r"""from ctypes import byref
from fmpy import calloc, extract, free, read_model_description
from fmpy.logging import addLoggerProxy
from fmpy.fmi2 import (FMU2Model, FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)
spec = json.load(open(sys.argv[1]))
md = read_model_description(spec["path"])
vr = {v.name: v.valueReference for v in md.modelVariables}
folder = extract(spec["path"])
out = []
for kind, cls, ident in (("cs", FMU2Slave, md.coSimulation.modelIdentifier),
                         ("me", FMU2Model, md.modelExchange.modelIdentifier)):
    for k, values in enumerate(spec["cases"]):
        messages = []
        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2CallbackLoggerTYPE(lambda env, name, status, category, message:
                                                  messages.append(message.decode()))
        callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(byref(callbacks))   # (FMPy's C proxy formats the logger's variadic arguments)
        fmu = cls(guid=md.guid, unzipDirectory=folder, modelIdentifier=ident, instanceName=f"{kind}{k}")
        fmu.instantiate(callbacks=callbacks)
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.setReal([vr[n] for n in values], list(values.values()))
        try:
            fmu.exitInitializationMode()
        except Exception:
            out.append([kind, "refused", messages[-1] if messages else "no message"])
        else:
            names = spec["outputs"]
            out.append([kind, "ok", dict(zip(names, fmu.getReal([vr[n] for n in names])))])
        fmu.freeInstance()
loaded = sorted(m for m in sys.modules if m.split(".")[0] in ("clutchlab", "numba", "llvmlite"))
assert not loaded, loaded
json.dump(out, open(spec["result"], "w"))
"""


def _start_values(tmp_path, path, cases, names):
    """``[kind, "ok" | "refused", outputs | message]`` of each case of start values set in FMPy (without clutchlab)
    before ``fmi2ExitInitializationMode``, in co-simulation, then in model exchange (:data:`_START_VALUES_HOST`)."""
    script, spec, result = tmp_path / "host.py", tmp_path / "spec.json", tmp_path / "result.json"
    script.write_text(_START_VALUES_HOST)
    spec.write_text(json.dumps({"path": str(path), "cases": cases, "outputs": names, "result": str(result)}))
    proc = subprocess.run([str(_isolated_python()), str(script), str(spec)], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(result.read_text())


def test_a_one_way_clutch_a_host_starts_backward_is_refused_and_the_speeds_are_not_cut_by_ranges(built, tmp_path):
    """A one-way clutch never slides backward (MSL ``OneWayClutch``), so no run starts with its flange b slower than
    its flange a.  The network's compiled ``start`` refuses that state (a model error with the element's name), so
    the FMU refuses speeds a host sets that way at ``fmi2ExitInitializationMode``, in co-simulation and in model
    exchange, with the message clutchlab gives.  And the initial speeds carry no ranges cut where one meets the
    other's start value: before, J1.w0 had ``max`` 3 rad/s (J2's start) and J2.w0 ``min`` 2 rad/s, so J1 = 5,
    J2 = 6 rad/s (a valid start) was refused and J1 = 2.8, J2 = 2.2 rad/s (backward) ran."""
    path, cls, _ = built["freewheel"]
    _, svs = _variables(path)
    for name in ("J1.w0", "J2.w0"):
        real = svs[name].find("Real")
        assert svs[name].get("causality") == "parameter" and real.get("min") is None and real.get("max") is None
    with pytest.raises(ParameterError, match=r"f: a one-way clutch cannot start with flange b slower than flange a "
                                             r"\(it never slides backward\): w_b - w_a = -0\.6 rad/s"):
        cls(**{"J1.w0": 2.8, "J2.w0": 2.2})
    names = [v.name for v in cls.outputs]
    cases = [{"J1.w0": 2.8, "J2.w0": 2.2}, {"J1.w0": 5.0, "J2.w0": 6.0}, {"J2.w0": 1.0}]
    got = _start_values(tmp_path, path, cases, names)
    assert [(kind, what) for kind, what, _ in got] == [("cs", "refused"), ("cs", "ok"), ("cs", "refused"),
                                                      ("me", "refused"), ("me", "ok"), ("me", "refused")]
    for kind, what, detail in got:
        if what == "refused":
            assert re.search(r"^freewheel: f: a one-way clutch cannot start with flange b slower than "
                             r"flange a \(it never slides backward\) \(at t = 0 s\)", detail), detail
        else:   # (the start clutchlab's own co-simulation reports with those speeds: f overrunning, J1 at 5 rad/s)
            python = cls(**cases[1]).initial_outputs({})
            assert detail["f.mode"] == python["f.mode"] == 1.0 and detail["J1.w"] == 5.0
            for name in names:
                assert detail[name] == pytest.approx(python[name], rel=1e-12, abs=1e-12), name


def test_network_inputs_are_fmu_inputs(built, tmp_path):
    path, cls, _ = built["inputs"]
    root, svs = _variables(path)
    assert svs["load"].get("causality") == "input" and svs["load"].find("Real").get("unit") == "N.m"
    assert svs["load"].find("Real").get("start") == "2.0"
    n, dt = 400, 2.5e-3
    k = np.arange(n + 1)
    inputs = {"load": 2.0 + 3.0 * (k * dt > 0.4), "press": np.clip(k * dt, 0.0, 1.0)}
    native = _fmpy_run(tmp_path, path, n, dt, inputs=inputs)
    python = _python_run(cls, n, dt, inputs=inputs)
    for name in python:
        _close(native[name], python[name], name)


#: an engine driving a shaft through the E-clutch with its actuator, its bearing reference a network input
PEDAL_TOML = """
[driveline]
name = "pedal"

[input.pedal]
start = "8 mm"
description = "bearing position reference"

[inertia.engine]
J = "0.2 kg m^2"
w0 = "150 rad/s"

[inertia.shaft]
J = "0.5 kg m^2"

[torque.drive]
flange = "engine"
torque = "20 N m"

[eclutch.clutch]
a = "engine"
b = "shaft"
position = { input = "pedal" }
actuator = true
pre_roll = "0.2 s"

[bearing_friction.load]
flange = "shaft"
torque = "5 N m"

[simulation]
rtol = 1e-6
"""


def test_the_eclutch_pedal_is_an_input_of_the_native_fmu(tmp_path):
    """The E-clutch with its actuator in the network (issue #32: its bearing reference an FMU input): the native FMU
    (Rodas3 inside, the actuator's states among the network's) takes the pedal as an input in metres and gives the
    numbers of the Python co-simulation of the same network, with the pedal moved at the communication points, in
    FMPy without clutchlab."""
    (tmp_path / "pedal.toml").write_text(PEDAL_TOML)
    cls = DrivelineCoSimulation.for_description(tmp_path / "pedal.toml")
    lines = []
    path = export_native_fmu(cls, tmp_path / "pedal.fmu", platforms=["linux64"], report=lines.append)
    _, svs = _variables(path)
    pedal = svs["pedal"]
    assert pedal.get("causality") == "input" and pedal.find("Real").get("unit") == "m"
    assert float(pedal.find("Real").get("start")) == pytest.approx(8e-3)
    assert svs["clutch.normal_force"].get("causality") == "output"
    n, dt = 60, 1e-2
    k = np.arange(n + 1)
    inputs = {"pedal": np.clip(8e-3 - 1e-4 * np.maximum(k - 10, 0), 2e-3, 8e-3)}
    native = _fmpy_run(tmp_path, path, n, dt, inputs=inputs)
    python = _python_run(cls, n, dt, inputs=inputs)
    assert python["clutch.normal_force"][-1] > 1000.0   # the pedal closed the clutch
    for name in python:
        _close(native[name], python[name], name)
    # model exchange: FMPy's CVode integrates the network and the actuator (its massless tip solved inside the FMU),
    # locating the actuator's stick/slip and the clutch's from the event indicators.  Over the engagement, every
    # millisecond, as the E-clutch's own FMU is compared (test_native_fmu_of_the_eclutch), the pedal held at 3 mm
    # from the start.  (Ramped at 0.1 m/s, CVode at rtol 1e-8 stops at its 500 steps per output interval at the
    # ramp's start, as the E-clutch's own FMU does at 1e-10: FMPy's staircase of a continuous input, docs/fmu.md)
    root, svs = _variables(path)
    assert root.find("ModelExchange") is not None and "der(clutch.actuator.x_tip)" not in svs
    assert "der(clutch.actuator.bearing_position)" in svs and "der(engine.w)" in svs
    n, dt = 200, 1e-3
    inputs = {"pedal": np.full(n + 1, 3e-3)}
    me = _fmpy_run(tmp_path, path, n, dt, inputs=inputs, fmi_type="ModelExchange", rtol=1e-10)
    tight = _python_run(cls, n, dt, {"rtol": 1e-10}, inputs=inputs)
    assert tight["clutch.normal_force"][-1] > 1000.0
    # (over the first 150 ms: from 180 ms on the actuator's bearing sticks and slips in micro-cycles whose branches
    # change with the tolerance in both integrators, 3e-3 of the clamp force, as in the E-clutch's own FMU)
    for name in ("engine.w", "shaft.w", "clutch.normal_force", "clutch.tau", "clutch.actuator.bearing_position"):
        scale = float(np.max(np.abs(tight[name])))
        np.testing.assert_allclose(me[name][:151], tight[name][:151], rtol=0, atol=1e-4 * scale, err_msg=name)


_FMI3_HOST = r"""
import json, sys
import numpy as np
from fmpy import read_model_description, extract
from fmpy.fmi3 import FMU3Slave
spec = json.load(open(sys.argv[1]))
md = read_model_description(spec["path"])
vr = {v.name: v.valueReference for v in md.modelVariables}
messages = []
fmu = FMU3Slave(guid=md.guid, unzipDirectory=extract(spec["path"]), modelIdentifier=md.coSimulation.modelIdentifier,
                instanceName="a")
fmu.instantiate(logMessage=lambda env, status, category, message: messages.append(message.decode()))
fmu.enterInitializationMode(startTime=0.0)
fmu.exitInitializationMode()
fmu.reset()   # (and once more from the start)
fmu.enterInitializationMode(startTime=0.0)
fmu.exitInitializationMode()
out = [vr[k] for k in spec["outputs"]]
rows = [fmu.getFloat64(out)]
for k in range(spec["n"]):
    fmu.doStep(currentCommunicationPoint=k * spec["dt"], communicationStepSize=spec["dt"])
    rows.append(fmu.getFloat64(out))
    if k == spec["n"] // 2:
        state = fmu.getFMUState()
again = []
fmu.setFMUState(state)   # rollback: the second half again from the state taken at its start
for k in range(spec["n"] // 2 + 1, spec["n"]):
    fmu.doStep(currentCommunicationPoint=k * spec["dt"], communicationStepSize=spec["dt"])
    again.append(fmu.getFloat64(out))
time = fmu.getFloat64([vr["time"]])[0]
refused = []
for call in (lambda: fmu.setFloat64([vr[spec["input"]]], [float("nan")]),
             lambda: fmu.setFloat64([vr["time"]], [1.0]),
             lambda: fmu.getFloat64([len(md.modelVariables) + 7])):
    try:
        call()
        refused.append("accepted")
    except Exception:
        refused.append(messages[-1] if messages else "no message")
fmu.terminate()
fmu.freeInstance()
json.dump({"rows": rows, "again": again, "time": time, "refused": refused}, open(spec["result"], "w"))
"""


def test_fmi3_cosimulation_from_the_same_library(built, tmp_path):
    """``fmi_version="3.0"``: an FMI 3.0 co-simulation FMU of the same network, whose ``fmi3*`` functions adapt
    onto the ``fmi2*`` ones of the same library, in FMPy without clutchlab: valid, the numbers of
    the Python run with parameters and inputs set, ``fmi3Reset``, rollback through ``fmi3Get/SetFMUState``,
    refused values (a NaN input, a write to time, an unknown value reference) with their messages through FMI
    3.0's log callback; the win64 library in ``binaries/x86_64-windows``."""
    _, cls, _ = built["inputs"]
    lines = []
    platforms = ["linux64"] + (["win64"] if not _wine() else [])
    path = export_native_fmu(cls, tmp_path / "n3.fmu", platforms=platforms, report=lines.append, fmi_version="3.0")
    assert lines[0].startswith(f"native FMU Clutchlab_inputs ({', '.join(platforms)}; FMI 3.0 co-simulation)")
    root = ET.fromstring(zipfile.ZipFile(path).read("modelDescription.xml"))
    assert root.get("fmiVersion") == "3.0" and root.get("instantiationToken").startswith("{")
    assert root.find("ModelExchange") is None and root.find("CoSimulation").get("hasEventMode") == "false"
    variables = {v.get("name"): v for v in root.find("ModelVariables")}
    assert variables["time"].get("causality") == "independent"
    assert variables["load"].get("causality") == "input" and variables["load"].get("unit") == "N.m"
    names = zipfile.ZipFile(path).namelist()
    assert "binaries/x86_64-linux/Clutchlab_inputs.so" in names
    if "win64" in platforms:
        assert "binaries/x86_64-windows/Clutchlab_inputs.dll" in names
    # (FMPy validates it and simulates it with parameters and inputs, as the FMI 2.0 one)
    n, dt = 400, 2.5e-3
    k = np.arange(n + 1)
    inputs = {"load": 2.0 + 3.0 * (k * dt > 0.4), "press": np.clip(k * dt, 0.0, 1.0)}
    parameter = next(v.name for v in cls.parameters if v.name.endswith(".J"))
    start = {parameter: 2.0}
    native = _fmpy_run(tmp_path, path, n, dt, start, inputs=inputs)
    python = _python_run(cls, n, dt, start, inputs=inputs)
    for name in python:
        _close(native[name], python[name], name)
    # rollback and refused values through FMPy's FMI 3.0 slave, no clutchlab in the process
    outputs = [v.name for v in cls.outputs][:4]
    script, spec, result = tmp_path / "fmi3.py", tmp_path / "fmi3.json", tmp_path / "fmi3_result.json"
    script.write_text(_FMI3_HOST)
    spec.write_text(json.dumps({"path": str(path), "n": 200, "dt": 1e-3, "outputs": outputs, "result": str(result),
                                "input": "load"}))
    proc = subprocess.run([str(_isolated_python()), str(script), str(spec)], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    got = json.loads(result.read_text())
    rows = np.array(got["rows"])
    python = _python_run(cls, 200, 1e-3)
    for j, name in enumerate(outputs):
        _close(rows[:, j], python[name], name)
    np.testing.assert_array_equal(np.array(got["again"]), rows[102:])
    assert got["time"] == pytest.approx(0.2, abs=1e-15)
    assert "not a finite number" in got["refused"][0]
    assert "independent variable" in got["refused"][1]
    assert "no variable with value reference" in got["refused"][2]


def test_model_description_from_the_declarations(built):
    path, cls, _ = built["cc"]
    root, svs = _variables(path)
    assert root.get("modelName") == "coupled_clutches" and root.find("CoSimulation").get("modelIdentifier") == \
        native_identifier("coupled_clutches") == "Clutchlab_coupled_clutches"
    cs = root.find("CoSimulation")
    assert cs.get("canGetAndSetFMUstate") == "true" and cs.get("canSerializeFMUstate") == "true"
    assert cs.get("canBeInstantiatedOnlyOncePerProcess") == "false"
    mu = svs["clutch1.mu"]
    assert (mu.get("causality"), mu.get("variability")) == ("parameter", "fixed")
    assert mu.find("Real").get("min") == "0.0" and mu.find("Real").get("max") == "2.0"
    # what chooses the integrator (a step of the fixed-step mode or step-size control): fixed at export, said in the
    # description; a factor on a friction coefficient and an initial speed are parameters (the FMU decides the
    # start modes again)
    fixed = svs["solver.fixed_step"]
    assert (fixed.get("causality"), fixed.get("variability")) == ("local", "constant")
    assert svs["clutch1.mu_scale"].get("causality") == "parameter"
    w0 = svs["J1.w0"]
    assert (w0.get("causality"), w0.get("variability")) == ("parameter", "fixed")
    assert svs["J1.w"].get("causality") == "output" and svs["J1.w"].find("Real").get("unit") == "rad/s"
    units = {u.get("name") for u in root.iter("Unit")}
    assert {"rad/s", "N.m", "kg.m2"} <= units
    outputs = [int(u.get("index")) for u in root.find("ModelStructure/Outputs")]
    assert len(outputs) == len(cls.outputs)


@pytest.fixture(scope="module")
def host(tmp_path_factory):
    """The C host (``native_host.c``), built with the system compiler."""
    out = tmp_path_factory.mktemp("host") / "native_host"
    proc = subprocess.run(["cc", "-O1", "-std=c99", "-D_POSIX_C_SOURCE=200809L", f"-I{HEADERS}",
                           str(HERE / "native_host.c"), "-o", str(out), "-ldl", "-lpthread", "-lm"],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return out


@pytest.fixture(scope="module")
def unpacked(built, tmp_path_factory):
    path, cls, _ = built["cc"]
    folder = tmp_path_factory.mktemp("unpacked")
    with zipfile.ZipFile(path) as z:
        z.extractall(folder)
    root, svs = _variables(path)
    lib = folder / "binaries" / "linux64" / "Clutchlab_coupled_clutches.so"
    return lib, root.get("guid"), {name: int(sv.get("valueReference")) for name, sv in svs.items()}, cls


def _host(host, *args, check=True):
    proc = subprocess.run([str(host), *map(str, args)], capture_output=True, text=True, timeout=600)
    if check:
        assert proc.returncode == 0, (proc.returncode, proc.stderr)
    return proc


def test_a_c_host_without_python_two_instances_in_threads(host, unpacked):
    lib, guid, vr, cls = unpacked
    out = ["J1.w", "J4.w", "clutch1.tau", "clutch3.dissipated", "energy_error"]
    n, dt = 1000, 1e-3
    proc = _host(host, lib, guid, "run", n, dt, vr["clutch1.fn_max"], 25.0, *[vr[o] for o in out])
    values = np.loadtxt(proc.stdout.splitlines())
    python = _python_run(cls, n, dt, {"clutch1.fn_max": 25.0})
    for j, name in enumerate(out):
        _close(values[:, j], python[name], name)
    assert _host(host, lib, guid, "maps").stdout.strip() == "0"   # no libpython, no numba in the process
    deps = subprocess.run(["ldd", str(lib)], capture_output=True, text=True).stdout
    assert "python" not in deps and "stdc++" not in deps, deps


def test_rollback_and_serialised_states(host, unpacked):
    lib, guid, vr, _ = unpacked
    a, b, c = map(float, _host(host, lib, guid, "state", 2e-3, vr["J1.w"]).stdout.split())
    assert a == b == c and a != 0.0


def test_instantiate_free_keeps_memory_flat_and_fresh_processes_exit_cleanly(host, unpacked):
    lib, guid, _, _ = unpacked
    first, last = map(int, _host(host, lib, guid, "cycles", 10_000).stdout.split())
    assert last - first < 2048, (first, last)   # kB over 9,000 cycles: no leak per instance
    codes = [_host(host, lib, guid, "cycles", 3, check=False).returncode for _ in range(100)]
    assert codes == [0] * 100


@pytest.mark.parametrize("name, value, message", [
    ("clutch1.mu", "3.0", r"clutch1\.mu = 3 \[1\] is outside its range \[0, 2\]"),
    ("clutch1.fn_max", "nan", r"clutch1\.fn_max = nan is not a finite number"),
    ("J1.J", "-1", r"J1\.J = -1 \[kg\.m2\] is outside its range \(0, inf\]"),
    ("solver.fixed_step", "0.001", r"solver\.fixed_step is fixed at export and cannot be set"),
    ("clutch1.mu_scale", "2.5", r"clutch1\.mu_scale = 2\.5 \[1\] is outside its range \[0, 2\]"),
    ("J1.w", "5", r"J1\.w is an output and cannot be set"),
])
def test_bad_values_return_fmi2error_with_a_message(host, unpacked, name, value, message):
    lib, guid, vr, _ = unpacked
    status, text = _host(host, lib, guid, "refuse", vr[name], value).stdout.split(" ", 1)
    assert int(status) == 3 and re.search(message, text), text   # fmi2Error


def test_misuse_returns_fmi2error_and_the_instance_goes_on(host, unpacked):
    """An unknown FMU type (NULL from fmi2Instantiate), a step not starting at the model's time, of zero or NaN length,
    an unknown value reference: refused with a message; a valid step afterwards still works; a handle that is not
    an instance of the FMU (zeroed memory) is refused by the instances' magic number, and not freed."""
    lib, guid, _, _ = unpacked
    lines = _host(host, lib, guid, "misuse").stdout.splitlines()
    assert lines[0] == "me 1"
    statuses = {line.split(" ", 2)[0]: (int(line.split(" ", 2)[1]), line.split(" ", 2)[2]) for line in lines[1:]}
    assert statuses["late"][0] == 3 and "the step starts at 0.5 s but the model is at 0 s" in statuses["late"][1]
    assert statuses["zero"][0] == 3 and "expected a finite step > 0" in statuses["zero"][1]
    assert statuses["nan"][0] == 3 and "expected a finite step > 0" in statuses["nan"][1]
    assert statuses["vr"][0] == 3 and "no variable with value reference 99999" in statuses["vr"][1]
    assert statuses["valid"][0] == 0
    assert statuses["foreign"][0] == 3 and statuses["foreign_get"][0] == 3   # (a handle that is no instance)


def test_a_wrong_guid_is_refused_and_a_null_instance_does_not_crash(host, unpacked):
    lib, guid, _, _ = unpacked
    # (the host goes on with the NULL instance: every function returns fmi2Error, none crashes)
    status, text = _host(host, lib, "{not-this-one}", "refuse", 0, "1").stdout.split(" ", 1)
    assert int(status) == 3 and f"GUID {{not-this-one}} does not match this FMU's {guid}" in text


def test_export_fmu_command_builds_a_native_fmu_by_default(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["export-fmu", "driveline", str(EXAMPLE)]) == 0
    captured = capsys.readouterr()
    assert captured.out.strip() == "driveline_coupled_clutches.fmu"
    assert "native FMU Clutchlab_coupled_clutches (linux64" in captured.err
    names = zipfile.ZipFile(tmp_path / "driveline_coupled_clutches.fmu").namelist()
    assert "binaries/linux64/Clutchlab_coupled_clutches.so" in names and not any("resources" in n for n in names)
    with pytest.raises(NativeExportError, match="system contract"):
        export_native_fmu(object, tmp_path / "x.fmu")
    assert main(["export-fmu", "driveline", str(EXAMPLE), "-o", "cc3.fmu", "--fmi-version", "3.0",
                 "--platform", "linux64"]) == 0
    captured = capsys.readouterr()
    assert "(linux64; FMI 3.0 co-simulation)" in captured.err
    assert "binaries/x86_64-linux/Clutchlab_coupled_clutches.so" in zipfile.ZipFile(tmp_path / "cc3.fmu").namelist()
    assert b'fmiVersion="3.0"' in zipfile.ZipFile(tmp_path / "cc3.fmu").read("modelDescription.xml")
    assert main(["export-fmu", "driveline", str(EXAMPLE), "-o", "p3.fmu", "--fmi-version", "3.0",
                 "--backend", "python"]) != 0
    assert "FMI 3.0 is built by the native backend only" in capsys.readouterr().err
    with pytest.raises(ParameterError, match="fmi_version '4.0'"):
        export_native_fmu(DrivelineCoSimulation.for_description(EXAMPLE), tmp_path / "y.fmu", fmi_version="4.0")


_TWICE_THEN_SIDE_BY_SIDE = r"""
import json, sys
import fmpy
from fmpy.fmi2 import FMU2Slave
path, output, dt, n = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4])
runs = [fmpy.simulate_fmu(path, stop_time=n * dt, step_size=dt, output_interval=dt, output=[output])[output].tolist()
        for _ in range(2)]
md = fmpy.read_model_description(path)
vr = next(v.valueReference for v in md.modelVariables if v.name == output)
slaves = [FMU2Slave(guid=md.guid, unzipDirectory=fmpy.extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName=f"instance{i}") for i in range(2)]
for s in slaves:
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
together = [[s.getReal([vr])[0]] for s in slaves]
for k in range(n):   # (side by side: each step of one instance between two of the other's)
    for s, values in zip(slaves, together):
        s.doStep(k * dt, (k + 1) * dt - k * dt)
        values.append(s.getReal([vr])[0])
for s in slaves:
    s.terminate()
    s.freeInstance()   # (FMPy's freeInstance also unloads the library)
print(json.dumps({"runs": runs, "together": together}))
"""


@pytest.mark.parametrize("model, output", [("driveline", "clutch1.tau"), ("wet", "clutch_torque"),
                                           ("emtc", "coupling_torque"), ("eclutch", "clutch_torque")])
def test_a_python_host_runs_each_native_fmu_twice_then_two_side_by_side_and_exits_cleanly(
        tmp_path, built, native_model, model, output):
    """Issue #33's host protocol (the pythonfmu FMU aborted at exit in 15 of 80 such processes): FMPy, in a
    virtual environment without clutchlab, runs the FMU twice with ``simulate_fmu``, then two instances side by
    side; every process exits with code 0, the two runs are equal bit for bit, the two instances equal each
    other and the Python co-simulation.  3 processes per model in CI (``examples``: 60 in the thorough
    profile)."""
    from clutchlab.fmu.cosim import load_cosimulation
    from hypothesis_budget import examples

    path, cls = (built["cc"][0], built["cc"][1]) if model == "driveline" else (native_model(model)[0],
                                                                             load_cosimulation(model))
    n, dt = 5, 0.01
    python = _python_run(cls, n, dt)[output]
    assert np.max(np.abs(python)) > 0.0
    script = tmp_path / "host.py"
    script.write_text(_TWICE_THEN_SIDE_BY_SIDE)
    for _ in range(examples(3)):
        proc = subprocess.run([str(_isolated_python()), str(script), str(path), output, str(dt), str(n)],
                              capture_output=True, text=True, timeout=300, cwd=tmp_path)
        assert proc.returncode == 0, (proc.returncode, proc.stderr[-2000:])
        out = json.loads(proc.stdout.strip().splitlines()[-1])
        assert out["runs"][0] == out["runs"][1]   # a fresh instance of the same model: the same run, bit for bit
        assert out["together"][0] == out["together"][1]
        _close(np.array(out["together"][0]), python, output)
        # (simulate_fmu's own communication points may differ from k dt by a rounding)
        np.testing.assert_allclose(out["runs"][0], python, rtol=1e-8, atol=1e-12 * np.max(np.abs(python)))


def test_native_fmu_of_the_emtc_with_its_inputs(tmp_path, host, native_model):
    """The EMTC's co-simulation (a ContractCoSimulation of the model's own System) as a native FMU: its four
    inputs driven by a host, equal to the Python co-simulation."""
    from clutchlab.fmu.emtc import EmtcCoSimulation

    path, lines = native_model("emtc")
    assert lines[0].startswith("native FMU ClutchlabEmtc (linux64; FMI 2.0 co-simulation and model exchange): 4 inputs, "
                               "18 outputs")
    n, dt = 150, 0.01
    k = np.arange(n + 1)
    # (drum speeds other than their start values: the shafts start free rolling on them, as in clutchlab's run)
    inputs = {"torque_request": np.where(k * dt > 0.3, 400.0, 0.0), "throttle": np.full(n + 1, 0.3),
              "drum_speed_front": np.full(n + 1, 9.0), "drum_speed_rear": 8.6 - 0.5 * (k * dt > 0.9)}
    native = _fmpy_run(tmp_path, path, n, dt, inputs=inputs)
    python = _python_run(EmtcCoSimulation, n, dt, inputs=inputs)
    for name in python:
        _close(native[name], python[name], name)
    assert np.max(python["coupling_torque"]) > 100.0   # (the request went through)
    # parameters a host sets (the coupling's kinetic friction, the armature's spring, the vehicle's mass)
    root, svs = _variables(path)
    start = {"coupling.mu_k[1]": 0.09, "actuator.stiffness": 1.1 * float(svs["actuator.stiffness"].find("Real")
                                                                        .get("start")), "vehicle.mass": 1900.0,
             "solver.rtol": 1e-8}
    assert all(svs[name].get("causality") == "parameter" for name in start)
    # its absolute tolerances follow rtol only below the model's default (a line on each side of its start, 1e-6):
    # a host tightens it (the law below, 1e-8 here), and cannot loosen it past the start
    assert float(svs["solver.rtol"].find("Real").get("max")) == pytest.approx(1e-6, rel=1e-9)
    native = _fmpy_run(tmp_path, path, n, dt, start, inputs=inputs)
    changed = _python_run(EmtcCoSimulation, n, dt, start, inputs=inputs)
    for name in changed:
        _close(native[name], changed[name], name)
    assert np.max(np.abs(changed["coupling_torque"] - python["coupling_torque"])) > 1.0
    # a request that reverses with a shrinking amplitude at every sample fills the magnets' memories (more than
    # the Python co-simulation's 64 turning points: it replays with 256); the native FMU, which cannot grow
    # them at run time, starts with 1024 (EmtcCoSimulation.for_native) and gives the same run
    assert EmtcCoSimulation.for_native()().bench_options.memory_capacity == 1024
    reversing = dict(inputs, torque_request=300.0 + 250.0 * (-1.0) ** k * (1.0 - k / n))
    native = _fmpy_run(tmp_path, path, n, dt, inputs=reversing)
    python = _python_run(EmtcCoSimulation, n, dt, inputs=reversing)
    for name in python:
        _close(native[name], python[name], name)
    # a count the model takes only whole (friction pairs) is refused as a fraction, as the model refuses it
    with zipfile.ZipFile(path) as z:
        z.extractall(tmp_path / "fmu")
    root, svs = _variables(path)
    lib = tmp_path / "fmu" / "binaries" / "linux64" / "ClutchlabEmtc.so"
    assert svs["coupling.pairs[1]"].get("causality") == "parameter"
    for value, expected in (("2.5", "coupling.pairs[1] = 2.5 is not a whole number"), ("2", None),
                            ("1.5", "throttle = 1.5 [1] is outside its range [0, 1]")):
        name = "throttle" if value == "1.5" else "coupling.pairs[1]"
        status, text = _host(host, lib, root.get("guid"), "refuse", int(svs[name].get("valueReference")),
                             value).stdout.split(" ", 1)
        assert (int(status), expected is None or expected in text) == ((0, True) if expected is None else (3, True)), text


def test_the_emtc_s_vehicle_and_actuator_are_derived_by_its_start_in_the_fmu(tmp_path, native_model):
    """The EMTC's geometry, inertias, axle ratio, gear and airgaps were fixed at export (12 parameters): what the
    model derives from them (the axle loads, ``J_F``, ``J_R`` and the lock torque's shares of Eq. 29, the gear's
    ratio, the controller's table at the engaged airgap, the shafts' speeds on the drums) is a product, a quotient
    or a table of several.  The compiled start derives them now (``emtc.system.emtc_start``), so a host sets them
    and the run equals clutchlab's built with them; a combination no run can start from (a wheel base that is not
    the sum of its lever arms, a free travel beyond the airgap, airgaps outside the magnet's calibration) is
    refused at ``fmi2ExitInitializationMode`` with its message, as clutchlab refuses it."""
    from clutchlab.fmu.emtc import EmtcCoSimulation

    path, lines = native_model("emtc")
    assert "55 parameters (1 fixed at export)" in lines[0], lines[0]
    root, svs = _variables(path)
    assert [n for n, sv in svs.items() if sv.get("variability") == "constant"] == ["solver.fixed_step"]
    start = {"vehicle.cg_to_front": 1.2, "vehicle.cg_to_rear": 1.7, "vehicle.wheelbase": 2.9,
             "vehicle.rear_final_drive": 2.8, "vehicle.inertia_front_axle": 4.0, "vehicle.inertia_rear_axle": 2.9,
             "vehicle.inertia_input_shaft": 0.06, "vehicle.inertia_output_shaft": 0.03,
             "actuator.free_travel": 0.45e-3, "actuator.airgap_open": 1.0e-3, "scenario.gear": 3.0}
    assert all(svs[name].get("causality") == "parameter" for name in start)
    n, dt = 150, 0.01
    k = np.arange(n + 1)
    inputs = {"torque_request": np.where(k * dt > 0.3, 400.0, 0.0), "throttle": np.full(n + 1, 0.3),
              "drum_speed_front": np.full(n + 1, 9.0), "drum_speed_rear": 8.6 - 0.5 * (k * dt > 0.9)}
    native = _fmpy_run(tmp_path, path, n, dt, start, inputs=inputs)
    changed = _python_run(EmtcCoSimulation, n, dt, start, inputs=inputs)
    for name in changed:
        _close(native[name], changed[name], name)
    plain = _python_run(EmtcCoSimulation, n, dt, inputs=inputs)
    # (the shafts start free rolling on the drums through the new axle ratio: 9 m/s / 0.3622 m * 2.8)
    assert native["front_shaft_speed"][0] == pytest.approx(9.0 / 0.3622 * 2.8, rel=1e-15)
    for name in ("front_shaft_speed", "coupling_torque", "lock_torque"):
        assert np.max(np.abs(changed[name] - plain[name])) > 1e-3 * np.max(np.abs(plain[name])), name
    # refused by clutchlab (with the values) and by the FMU's start (with its message)
    with pytest.raises(ParameterError, match="cg_to_front \\+ cg_to_rear = 2.7000 m differs from wheelbase = 2.9000"):
        EmtcCoSimulation(**{"vehicle.wheelbase": 2.9})
    # (a fractional gear is refused already by fmi2SetReal, as a fractional count of friction pairs)
    cases = [{"vehicle.wheelbase": 2.9}, {"actuator.free_travel": 1.3e-3}, {"actuator.airgap_open": 1.6e-3}, start]
    names = [v.name for v in EmtcCoSimulation.outputs]
    got = _start_values(tmp_path, path, cases, names)
    expected = ["cg_to_front + vehicle.cg_to_rear must equal vehicle.wheelbase",
                "airgap_open must exceed actuator.free_travel",
                "must lie within the magnet's calibration airgaps", None]
    assert [(kind, what) for kind, what, _ in got] == [(kind, "refused" if e else "ok")
                                                      for kind in ("cs", "me") for e in expected]
    python = EmtcCoSimulation(**start).initial_outputs({})
    for (kind, what, detail), message in zip(got, expected * 2):
        if message:
            assert message in detail and "(at t = 0 s)" in detail, detail
        else:   # (the start clutchlab's own co-simulation reports: in model exchange too, the states the start set;
            # there the controller's first sample, a time event at t = 0, is taken at the end of initialisation
            # already, so its current command is the sample's, not the co-simulation's 0 before it)
            for name in names:
                if kind == "cs" or name != "current_command":
                    assert detail[name] == pytest.approx(python[name], rel=1e-12, abs=1e-12), (kind, name)


def test_the_emtc_native_fmu_snaps_a_step_end_onto_the_controller_s_sample(tmp_path, native_model):
    """A communication point within 1e-9 of a period of a controller sample counts as that sample, in the native
    FMU as in the Python co-simulation (``CoSimulation.step_grid_parameter``, ``cosim.snap_to_grid``; the C layer
    reads the parameter's current value).  Steps of 2 ms (1 + 1e-12): every step ends 4e-15 s to 4e-13 s after a
    sample instant (``scenario.sample_time`` 2 ms), and the request changes at every step, so a sample taken at the
    end of a step rather than the start of the next reads another request.  The native FMU equals the Python run;
    the same FMU without the grid does not (the test can fail)."""
    from clutchlab.fmu.emtc import EmtcCoSimulation
    from clutchlab.fmu.cosim import snap_to_grid

    assert snap_to_grid(0.004 * (1 + 1e-12), 0.002) == 2 * 0.002 and snap_to_grid(0.0041, 0.002) == 0.0041
    path, _ = native_model("emtc")
    n, dt = 100, 0.002 * (1.0 + 1e-12)
    k = np.arange(n + 1)
    inputs = {"torque_request": np.where(k % 2 == 0, 150.0, 350.0) * (k * dt > 0.02), "throttle": np.full(n + 1, 0.3),
              "drum_speed_front": np.full(n + 1, 9.0), "drum_speed_rear": np.full(n + 1, 8.6)}
    python = _python_run(EmtcCoSimulation, n, dt, inputs=inputs)
    native = _fmpy_run(tmp_path, path, n, dt, inputs=inputs)
    for name in python:
        _close(native[name], python[name], name)

    class WithoutGrid(EmtcCoSimulation):
        step_grid_parameter = None

    plain = export_native_fmu(WithoutGrid, tmp_path / "plain.fmu", platforms=["linux64"])
    off = _fmpy_run(tmp_path, plain, n, dt, inputs=inputs)
    assert np.max(np.abs(off["coupling_torque"] - python["coupling_torque"])) > 1e-6 * np.max(
        np.abs(python["coupling_torque"])), "the grid made no difference: the test cannot fail"


def _wine():
    """``wine`` and the MinGW-w64 compiler, or the reason the win64 test cannot run here."""
    missing = [tool for tool in ("x86_64-w64-mingw32-gcc", "x86_64-w64-mingw32-g++", "wine") if not shutil.which(tool)]
    return missing


@pytest.mark.skipif(bool(_wine()), reason=f"win64 needs MinGW-w64 and wine (missing here: {', '.join(_wine())}; "
                                          "tools/setup-tests installs them as root)")
def test_the_win64_binary_under_wine_gives_the_same_numbers(tmp_path, host):
    """The same network cross-built for win64 (COFF object from the same LLVM modules, linked by MinGW-w64),
    loaded by a Windows host built with MinGW-w64 and run under wine64: the numbers of the Python run in
    co-simulation; in model exchange (the host's own explicit Euler loop with the event indicators and time
    events) the numbers of the same host with the linux64 binary, and the Python run's within the Euler
    steps' error."""
    cls = DrivelineCoSimulation.for_description(EXAMPLE)
    path = export_native_fmu(cls, tmp_path / "cc.fmu", platforms=["linux64", "win64"])
    with zipfile.ZipFile(path) as z:
        z.extractall(tmp_path / "fmu")
        assert "binaries/win64/Clutchlab_coupled_clutches.dll" in z.namelist()
    dll = tmp_path / "fmu" / "binaries" / "win64" / "Clutchlab_coupled_clutches.dll"
    imports = subprocess.run(["x86_64-w64-mingw32-objdump", "-p", str(dll)], capture_output=True, text=True).stdout
    assert sorted(set(re.findall(r"DLL Name: (\S+)", imports))) == ["KERNEL32.dll", "msvcrt.dll"]
    exe = tmp_path / "host.exe"
    proc = subprocess.run(["x86_64-w64-mingw32-gcc", "-O1", "-std=c99", f"-I{HEADERS}", str(HERE / "native_host.c"),
                           "-o", str(exe), "-static", "-lpthread"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    root, svs = _variables(path)
    vr = {name: int(sv.get("valueReference")) for name, sv in svs.items()}
    out = ["J1.w", "J4.w", "clutch1.tau", "clutch3.dissipated"]
    n, dt = 600, 1e-3
    env = {**__import__("os").environ, "WINEDEBUG": "-all", "WINEPREFIX": str(tmp_path / "wineprefix")}
    run = subprocess.run(["wine", str(exe), str(dll), root.get("guid"), "run", str(n), str(dt), str(vr["clutch1.fn_max"]),
                          "25", *[str(vr[o]) for o in out]], capture_output=True, text=True, timeout=600, env=env)
    assert run.returncode == 0, run.stderr[-2000:]
    rows = [line.split() for line in run.stdout.splitlines() if re.match(r"^[-0-9.e+ ]+$", line.strip())]
    values = np.array(rows, dtype=float)
    python = _python_run(cls, n, dt, {"clutch1.fn_max": 25.0})
    for j, name in enumerate(out):
        _close(values[:, j], python[name], name)
    state = subprocess.run(["wine", str(exe), str(dll), root.get("guid"), "state", "2e-3", str(vr["J1.w"])],
                           capture_output=True, text=True, timeout=600, env=env)
    a, b, c = map(float, state.stdout.split()[-3:])
    assert a == b == c and a != 0.0
    # model exchange
    nx = sum(name.startswith("der(") for name in svs)
    nz = int(root.get("numberOfEventIndicators"))
    args = ["me", n, dt, 1e-5, nx, nz, *[vr[o] for o in out]]
    me_win = subprocess.run(["wine", str(exe), str(dll), root.get("guid"), *map(str, args)], capture_output=True,
                            text=True, timeout=600, env=env)
    assert me_win.returncode == 0, me_win.stderr[-2000:]
    rows = [line.split() for line in me_win.stdout.splitlines() if re.match(r"^[-0-9.e+ ]+$", line.strip())]
    windows = np.array(rows, dtype=float)
    linux = np.loadtxt(_host(host, tmp_path / "fmu" / "binaries" / "linux64" / "Clutchlab_coupled_clutches.so",
                             root.get("guid"), *args).stdout.splitlines())
    assert windows.shape == linux.shape == (n + 1, len(out))
    python = _python_run(cls, n, dt)
    for j, name in enumerate(out):
        scale = float(np.max(np.abs(python[name])))
        _close(windows[:, j], linux[:, j], name)
        np.testing.assert_allclose(linux[:, j], python[name], rtol=0, atol=2e-3 * scale, err_msg=name)


def test_native_fmu_of_the_eclutch(tmp_path, host, native_model):
    """The E-clutch (Rodas3 with its stick/slip friction) as a native FMU: equal to the Python co-simulation
    in FMPy with a held reference, and in the C host.  (With a reference that steps, FMPy's own timing of the
    input changes its value by a rounding, and the E-clutch's 120 friction events amplify a change of one ulp
    in one step's reference to 1e-8 of the bearing position: the run is compared where the input is exact.)"""
    from clutchlab.fmu.eclutch import EClutchCoSimulation

    path, lines = native_model("eclutch")
    assert lines[0].startswith("native FMU ClutchlabEclutch (linux64; FMI 2.0 co-simulation and model exchange): 2 inputs, "
                               "9 outputs")
    root, svs = _variables(path)
    assert root.find("ModelExchange") is not None and root.find("CoSimulation") is not None
    # its massless tip is an algebraic state (a zero in the mass matrix): solved inside, not one of the host's
    # states; the others carry their nominal (the model's atol / rtol: 0.1 mm for a position)
    assert "state.x_tip" in svs and "der(state.x_tip)" not in svs
    derivatives = [name for name in svs if name.startswith("der(")]
    assert len(derivatives) == 19
    assert float(svs["bearing_position"].find("Real").get("nominal")) == pytest.approx(1e-4)
    n, dt = 500, 1e-3
    inputs = {"bearing_reference": np.full(n + 1, 2e-3)}
    native = _fmpy_run(tmp_path, path, n, dt, inputs=inputs)
    python = _python_run(EClutchCoSimulation, n, dt, inputs=inputs)
    for name in python:
        _close(native[name], python[name], name)
    assert np.ptp(python["bearing_position"]) > 1e-3   # (the actuator moved)
    # a stiffness the model turns into its curves and its pre-strains: writable since the start derives the
    # pre-strains (test_the_eclutch_s_clutch_is_derived_by_its_start_in_the_fmu); before, trials one newton per metre
    # apart from its 1175810 N/m had taken the pre-strains' curve for a line
    assert svs["clutch.k_fl_model2"].get("causality") == "parameter"
    # a gain is a proportion down to 0+ (at 0 the model switches its integrator off: refused)
    ki = svs["actuator.ki"].find("Real")
    assert 0.0 < float(ki.get("min")) < 1e-9 and svs["actuator.ki"].get("causality") == "parameter"
    # parameters a host sets (found writable by rebuilding the model, and checked jointly): the controller's
    # gains, the motor's resistance, the clutch's friction coefficient and the seals' static ratio
    start = {"actuator.kp": 2500.0, "actuator.resistance": 0.25, "clutch.mu": 0.3, "friction.static_ratio": 1.3}
    # and the hydraulics (line, fluid, hose, volumes, snifting port) and the spindle and piston, from which the
    # compiled start derives the compliances, the line's inertance and resistance, the snifting edge, the spindle
    # ratio and the equivalent mass again in the FMU (derive_actuator):
    # fixed at export before (a product or a quotient of two parameters, a sum two of them share)
    assert "59 parameters (5 fixed at export)" in lines[0], lines[0]
    start.update({"actuator.line_diameter": 4e-3, "actuator.bulk_modulus": 3e8, "actuator.hose_compliance": 4e-13,
                  "actuator.fluid_viscosity": 0.012, "actuator.slave_volume": 8e-6, "actuator.snifting_width": 4e-4,
                  "actuator.lead": 5e-3, "actuator.master_mass": 0.12})
    assert all(svs[name].get("causality") == "parameter" for name in start)
    # (its atol follow it only below the default, a line on each side: a host tightens it, max = the default; the
    # controller's integral's tolerance is a voltage, no longer 1e-9 ki, a number the gain and rtol both changed)
    assert svs["rtol"].get("causality") == "parameter"
    assert float(svs["rtol"].find("Real").get("max")) == pytest.approx(1e-3, rel=1e-9)
    assert sum(sv.get("causality") == "parameter" for sv in svs.values()) >= 30
    # a bound the model's own code sets beyond its declared range (the CSC's lower travel limit must be < 0,
    # declared [-100, 100]) is the FMU variable's max, found at export by bisection
    slave_min = svs["actuator.slave_min"].find("Real")
    assert float(slave_min.get("min")) == -100.0 and -1e-12 < float(slave_min.get("max")) < 0.0
    native = _fmpy_run(tmp_path, path, n, dt, start, inputs=inputs)
    changed = _python_run(EClutchCoSimulation, n, dt, start, inputs=inputs)
    for name in changed:
        _close(native[name], changed[name], name)
    assert np.max(np.abs(changed["clutch_torque"] - python["clutch_torque"])) > 1.0
    with zipfile.ZipFile(path) as z:
        z.extractall(tmp_path / "fmu")
    root, svs = _variables(path)
    vr = {name: int(sv.get("valueReference")) for name, sv in svs.items()}
    lib = tmp_path / "fmu" / "binaries" / "linux64" / "ClutchlabEclutch.so"
    values = np.loadtxt(_host(host, lib, root.get("guid"), "run", n, dt, -1, 0, vr["bearing_position"],
                              vr["clutch_torque"]).stdout.splitlines())
    held = _python_run(EClutchCoSimulation, n, dt)   # (the reference at its start value, 5 mm)
    for j, name in enumerate(["bearing_position", "clutch_torque"]):
        _close(values[:, j], held[name], name)
    # model exchange: CVode integrates the 19 differential states, the FMU solves the tip's force balance at
    # every evaluation.  Compared over the engagement (250 ms): after it the clutch's stick-slip micro-cycles
    # take branches that change with the tolerance in both integrators (docs/fmu.md)
    n = 250
    me = _fmpy_run(tmp_path, path, n, dt, fmi_type="ModelExchange", rtol=1e-10)
    tight = _python_run(EClutchCoSimulation, n, dt, {"rtol": 1e-10})
    for name in tight:
        scale = float(np.max(np.abs(tight[name])))
        np.testing.assert_allclose(me[name], tight[name], rtol=0, atol=1e-6 * scale, err_msg=name)


def test_the_eclutch_s_clutch_is_derived_by_its_start_in_the_fmu(tmp_path, native_model):
    """The E-clutch's lever ratio, pre-strains, stiffnesses, scales and preloads and its master bore were fixed at
    export (12 parameters): the model builds its network from them in Python (Model 0's bearing zeroed at the
    preload, the engaged state's loads, the pre-strains of the compliances Models 1-4 add, Model 4's bearing zeroed
    again, the CSC's rest position and the static state there), and the bore's area multiplies the spindle's loss in
    the master seal's friction.  The compiled start of a co-simulation derives them again
    (``eclutch.system.derive_clutch``, ``start_at_rest``, ``derive_actuator``), so a host sets them and the run
    equals clutchlab's built with them; a combination no run can start from (a preload no bearing pre-strain
    reaches, a CSC preload with no rest position, a master volume below the swept one, a snifting port beyond the
    stroke) is refused at ``fmi2ExitInitializationMode`` with its message, as clutchlab refuses it."""
    from clutchlab.fmu.eclutch import EClutchCoSimulation

    path, lines = native_model("eclutch")
    root, svs = _variables(path)
    # (what stays fixed: the structure -- model, control mode, friction switch, fixed step -- and the force up to
    # which the yoke support's measured curve is extrapolated, from which its table is built)
    assert [n for n, sv in svs.items() if sv.get("variability") == "constant"] == [
        "model", "control_mode", "friction_on", "solver.fixed_step", "clutch.support_max_force"]
    start = {"clutch.lever_ratio": -4.2, "clutch.diaphragm_prestrain": 4.4e-3, "clutch.cushion_prestrain": 0.72e-3,
             "clutch.return_prestrain": 8.1e-3, "clutch.bearing_stiffness": 9e6, "clutch.k_fl_model2": 1.25e6,
             "clutch.support_scale": 18.0, "clutch.diaphragm_scale": 1.25, "clutch.bearing_preload": 85.0,
             "actuator.csc_preload": 95.0, "actuator.master_diameter": 0.017, "actuator.spindle_efficiency": 0.8,
             "rtol": 5e-4}
    assert all(svs[name].get("causality") == "parameter" for name in start)
    n, dt = 300, 1e-3
    inputs = {"bearing_reference": np.full(n + 1, 2e-3)}
    native = _fmpy_run(tmp_path, path, n, dt, start, inputs=inputs)
    changed = _python_run(EClutchCoSimulation, n, dt, start, inputs=inputs)
    for name in changed:
        _close(native[name], changed[name], name)
    plain = _python_run(EClutchCoSimulation, n, dt, inputs=inputs)
    # (the CSC's preload above the clutch's: the bearing rests 10 N / (k_pre + the clutch's stiffness) released)
    rest = EClutchCoSimulation(**start).eclutch.rest_position
    assert native["bearing_position"][0] == pytest.approx(rest, rel=1e-12) and rest > 1e-6
    assert plain["bearing_position"][0] == 0.0
    for name in ("normal_force", "clutch_torque", "master_pressure"):
        assert np.max(np.abs(changed[name] - plain[name])) > 1e-3 * np.max(np.abs(plain[name])), name
    # refused by clutchlab and by the FMU's start (with its message)
    cases = [{"clutch.bearing_preload": 900.0, "actuator.csc_preload": 10.0},
             {"clutch.cushion_prestrain": 0.0137, "clutch.bearing_preload": 900.0},
             {"actuator.master_volume": 1e-7}, {"actuator.snifting_port": 0.0399}, start]
    expected = ["with actuator.csc_preload the CSC finds no rest position within its travel",
                "bearing cannot be zeroed at clutch.bearing_preload",
                "master_volume is smaller than the volume the master piston sweeps",
                "must be below actuator.master_stroke", None]
    for case, message in zip(cases, expected):
        if message:
            with pytest.raises(ParameterError):
                EClutchCoSimulation(**case)
    names = [v.name for v in EClutchCoSimulation.outputs]
    got = _start_values(tmp_path, path, cases, names)
    assert [(kind, what) for kind, what, _ in got] == [(kind, "refused" if e else "ok")
                                                      for kind in ("cs", "me") for e in expected]
    python = EClutchCoSimulation(**start).initial_outputs({})
    for (kind, what, detail), message in zip(got, expected * 2):
        if message:
            assert message in detail and "(at t = 0 s)" in detail, detail
        else:
            for name in ("bearing_position", "normal_force", "clutch_torque"):
                assert detail[name] == pytest.approx(python[name], rel=1e-12, abs=1e-15), (kind, name)


def test_native_fmu_of_the_wet_bench_whose_actuator_starts_at_its_reference(tmp_path, native_model):
    """The wet clutch on its bench: its run starts at the first inputs (the actuator force at its reference),
    which the native FMU repeats (an input's target in the state is written until initialisation ends);
    the bench's limits are the inputs' ranges."""
    from clutchlab.fmu.wet import WetCoSimulation

    path, lines = native_model("wet")
    assert lines[0].startswith("native FMU ClutchlabWet (linux64; FMI 2.0 co-simulation and model exchange): 2 inputs, "
                               "24 outputs")
    root, svs = _variables(path)
    # (the inputs' ranges follow the parameters: no max in the description, the FMU checks the model's numbers)
    force = svs["force_reference"].find("Real")
    assert force.get("min") == "0.0" and force.get("max") is None
    assert "bench.actuator_force_max" in svs["force_reference"].get("description")
    # the initial slip speed decides the slip direction the run starts in (a mode the wet bench's builder
    # decides): the FMU takes it > 0 only, where its law holds (a host's -1 rad/s had started slipping forward)
    slip = float(svs["scenario.initial_slip_speed"].find("Real").get("min"))
    assert 0.0 < slip < 1e-9
    n, dt = 400, 1e-3
    k = np.arange(n + 1)
    inputs = {"force_reference": np.where(k * dt > 0.05, 3000.0, 1000.0), "slip_speed_reference": np.full(n + 1, 150.0)}
    native = _fmpy_run(tmp_path, path, n, dt, inputs=inputs)
    python = _python_run(WetCoSimulation, n, dt, inputs=inputs)
    for name in python:
        _close(native[name], python[name], name)
    assert native["actuator_force"][0] == 1000.0   # (started at the reference, not at 0)
    # parameters a host sets: the friction law's coefficients, the bench's speed controller, the start temperature
    start = {"clutch.mu_v1": 1.1 * float(svs["clutch.mu_v1"].find("Real").get("start")), "bench.speed_kp":
             1.3 * float(svs["bench.speed_kp"].find("Real").get("start")), "scenario.initial_temperature": 90.0}
    assert all(svs[name].get("causality") == "parameter" for name in start)
    native = _fmpy_run(tmp_path, path, n, dt, start, inputs=inputs)
    changed = _python_run(WetCoSimulation, n, dt, start, inputs=inputs)
    for name in changed:
        _close(native[name], changed[name], name)
    assert np.max(np.abs(changed["clutch_torque"] - python["clutch_torque"])) > 1e-3 * np.max(np.abs(python["clutch_torque"]))
    # the pack's masses and heat capacities, the asperities' roughness and the plate's radii, from which the
    # model's compiled start derives its heat capacity (Eq. 8), Greenwood-Williamson scale (Eq. 11), effective
    # radius (Eq. 1') and squeeze coefficient again in the FMU (wet_start): they were fixed at export (a product of
    # two parameters, a power law); the run equals clutchlab's built with them.  (The radii only outward: the
    # friction area is the whole annulus at the start)
    assert "50 parameters (2 fixed at export)" in lines[0], lines[0]
    assert sorted(n for n, sv in svs.items() if sv.get("variability") == "constant") == [
        "scenario.free_inertia", "solver.fixed_step"]
    pack = {"clutch.m_core": 1.3, "clutch.cp_lining": 0.8, "clutch.sigma": 1.2, "clutch.contact_modulus": 0.7,
            "clutch.asperity_radius": 1.5, "clutch.asperity_density": 0.9, "clutch.r_outer": 1.05,
            "clutch.r_inner": 0.97}
    start = {name: factor * float(svs[name].find("Real").get("start")) for name, factor in pack.items()}
    assert all(svs[name].get("causality") == "parameter" for name in start)
    native = _fmpy_run(tmp_path, path, n, dt, start, inputs=inputs)
    changed = _python_run(WetCoSimulation, n, dt, start, inputs=inputs)
    for name in changed:
        _close(native[name], changed[name], name)
    for name in ("temperature", "clutch_torque"):   # (the parameters changed the run: the FMU derived with them)
        column = next(k for k in python if k.startswith(name))
        assert np.max(np.abs(changed[column] - python[column])) > 1e-4 * np.max(np.abs(python[column])), column
    # the bench's drive: its gear and the shaft's and motor's inertias and limits, from which the model's start
    # derives the drive at the clutch shaft (total_inertia = shaft + motor gear^2, the torque limit motor x gear, the
    # speed limit motor / gear: wet_start's derive_drive in a co-simulation); they were fixed at export (a number
    # two parameters share, the gear squared), and the slip-speed reference's range followed the gear at export only
    drive = {"bench.gear_ratio": 2.5, "bench.shaft_inertia": 0.05, "bench.motor_inertia": 0.1,
             "bench.motor_torque_max": 60.0, "bench.motor_speed_max": 700.0}
    assert all(svs[name].get("causality") == "parameter" for name in drive)
    (tmp_path / "drive").mkdir()
    native = _fmpy_run(tmp_path / "drive", path, n, dt, drive, inputs=inputs)
    changed = _python_run(WetCoSimulation, n, dt, drive, inputs=inputs)
    for name in changed:
        _close(native[name], changed[name], name)
    assert np.max(np.abs(changed["drive_torque"] - python["drive_torque"])) > 1e-2 * np.max(np.abs(python["drive_torque"]))
    # the inputs' ranges follow the limits the host set, checked once the parameters are fixed (at the end of
    # initialisation): 400 rad/s is beyond the file's drive (6000 rpm / 2 = 314 rad/s) and within a 1:1 gear's
    cases = [{"bench.gear_ratio": 1.0, "slip_speed_reference": 400.0}, {"slip_speed_reference": 400.0},
             {"bench.actuator_force_max": 8000.0, "force_reference": 9000.0}]
    got = _start_values(tmp_path, path, cases, ["slip_speed"])
    for kind in ("cs", "me"):
        results = [r for r in got if r[0] == kind]
        assert results[0][1] == "ok", results[0]
        assert results[1][1] == "refused" and re.search(r"slip_speed_reference = 400 \[rad/s\] is outside its range "
                                                        r"\[-314\.159\d+, 314\.159\d+\] \(bench\.motor_speed_max / "
                                                        r"bench\.gear_ratio\)", results[1][2]), results[1]
        assert results[2][1] == "refused" and re.search(r"force_reference = 9000 \[N\] is outside its range \[0, "
                                                        r"8000\]", results[2][2]), results[2]
    WetCoSimulation(**{"bench.gear_ratio": 1.0}).input_vector({"force_reference": 0.0, "slip_speed_reference": 400.0})
    # the tolerance below its default 1e-7 and the piston's travel, whose product is the piston position's absolute
    # tolerance (wet.system.absolute_tolerance): a number two parameters share as a product, which the FMU writes
    # from both (image.Target.partner); before, solver.rtol was fixed at export
    rtol = svs["solver.rtol"].find("Real")
    assert float(rtol.get("max")) == pytest.approx(1e-7, rel=1e-9) and float(rtol.get("min")) < 1e-10
    tight = {"solver.rtol": 1e-9, "clutch.piston_h0": 0.015}
    (tmp_path / "tight").mkdir()
    native = _fmpy_run(tmp_path / "tight", path, n, dt, tight, inputs=inputs)
    changed = _python_run(WetCoSimulation, n, dt, tight, inputs=inputs)
    for name in changed:
        _close(native[name], changed[name], name)
    assert WetCoSimulation(**tight).simulation.options.atol[0] == pytest.approx(1e-9 * 0.015, rel=1e-12)
    with pytest.raises(ParameterError, match="exceeds the bench's speed limit 314.159"):
        WetCoSimulation().input_vector({"force_reference": 0.0, "slip_speed_reference": 400.0})


# ------------------------------------------------------------------------------------------ model exchange
def test_model_exchange_of_a_driveline_under_fmpys_cvode(built, tmp_path):
    """The same FMU for model exchange: FMPy's CVode integrates the network, locating the clutches' stick/slip
    from the event indicators and the normal forces' steps as time events; the speeds equal clutchlab's own run
    within the tolerance, and every mode change happens at clutchlab's instant (to 1 ms)."""
    path, cls, _ = built["cc"]
    root, svs = _variables(path)
    assert root.find("ModelExchange").get("modelIdentifier") == "Clutchlab_coupled_clutches"
    assert int(root.get("numberOfEventIndicators")) > 0
    assert svs["der(J1.w)"].find("Real").get("derivative") == str(int(svs["J1.w"].get("valueReference")) + 1)
    n, dt = 1500, 1e-3
    me = _fmpy_run(tmp_path, path, n, dt, fmi_type="ModelExchange", rtol=1e-9)
    python = _python_run(cls, n, dt)
    # (a sample at an event's instant may show either side of it: compared where the modes agree)
    same = np.all([me[f"clutch{i}.mode"] == python[f"clutch{i}.mode"] for i in (1, 2, 3)], axis=0)
    assert same.sum() >= n - 10
    for name in ("J1.w", "J2.w", "J3.w", "J4.w", "clutch2.tau", "clutch1.dissipated"):
        scale = float(np.max(np.abs(python[name])))
        np.testing.assert_allclose(me[name][same], python[name][same], rtol=0, atol=2e-5 * scale, err_msg=name)
    for name in ("clutch1.mode", "clutch2.mode", "clutch3.mode"):
        changes = {k: (np.flatnonzero(np.diff(r[name]))) for k, r in (("me", me), ("py", python))}
        assert len(changes["me"]) == len(changes["py"]) >= 2, (name, changes)
        assert np.all(np.abs(changes["me"] - changes["py"]) <= 1), (name, changes)


@pytest.mark.parametrize("model", ["emtc", "wet"])
def test_model_exchange_of_each_model_agrees_with_its_cosimulation(tmp_path, model, native_model):
    """The EMTC's and the wet bench's native FMUs for model exchange (CVode at rtol 1e-9) against the Python
    co-simulation at rtol 1e-8.  (The E-clutch's, with its algebraic state: test_native_fmu_of_the_eclutch.)"""
    from clutchlab.fmu.cosim import load_cosimulation

    cls = load_cosimulation(model)
    path, _ = native_model(model)
    n, dt = {"emtc": (100, 0.01), "wet": (300, 1e-3)}[model]
    rtol_name = next(v.name for v in cls.parameters if v.name in ("rtol", "solver.rtol"))
    me = _fmpy_run(tmp_path, path, n, dt, fmi_type="ModelExchange", rtol=1e-9)
    python = _python_run(cls, n, dt, {rtol_name: 1e-8})
    checked = 0
    for name in python:
        scale = float(np.max(np.abs(python[name])))
        if scale < 1e-12:
            continue
        np.testing.assert_allclose(me[name], python[name], rtol=0, atol=1e-4 * scale, err_msg=name)
        checked += 1
    assert checked >= 6


@pytest.mark.parametrize("example", ["driveline_test_friction", "driveline_wet_sae2", "driveline_emtc_awd",
                                     "driveline_eclutch_launch", "driveline_torque_converter",
                                     "driveline_amt_upshift"])
def test_every_example_network_exports_and_equals_clutchlab(tmp_path, example):
    """Every example network (one-way clutches and bearing friction, the wet clutch's and the EMTC's grafts, the
    E-clutch with its actuator, a torque converter with its lock-up clutch and a thermal mass, an AMT's clutch and
    synchronisers) as a native FMU, run
    in FMPy without clutchlab against the Python
    co-simulation; and for model exchange under CVode."""
    cls = DrivelineCoSimulation.for_description(EXAMPLE.parent / f"{example}.toml")
    lines = []
    path = export_native_fmu(cls, tmp_path / "n.fmu", platforms=["linux64"], report=lines.append)
    root, svs = _variables(path)
    mass = cls().simulation.system.options().mass
    assert root.find("ModelExchange") is not None and "co-simulation and model exchange" in lines[0]
    assert sum(name.startswith("der(") for name in svs) == np.count_nonzero(mass)
    stop, _ = cls.experiment
    n = 200
    dt = min(stop, 1.0) / n
    native = _fmpy_run(tmp_path, path, n, dt)
    python = _python_run(cls, n, dt)
    energy = max(float(np.max(np.abs(python[k]))) for k in ("input_work", "kinetic_energy"))
    for name in python:   # (the energy balance's residual is a rounding of the energies: judged against them)
        _close(native[name], python[name], name, floor=1e-12 * energy if name == "energy_error" else 1e-12)
    me = _fmpy_run(tmp_path, path, n, dt, fmi_type="ModelExchange", rtol=1e-9)
    tight = _python_run(cls, n, dt, {"rtol": 1e-9})
    speeds = [name for name in tight if name.endswith(".w") and np.max(np.abs(tight[name])) > 1e-9]
    assert speeds
    for name in speeds:
        scale = float(np.max(np.abs(tight[name])))
        np.testing.assert_allclose(me[name], tight[name], rtol=0, atol=1e-4 * scale, err_msg=name)
    if example == "driveline_emtc_awd":
        _a_host_sets_the_vehicle_s_initial_speed(tmp_path, path, cls, n, dt)
        _a_host_sets_the_coupling_s_own_parameters(tmp_path, path, cls, n, dt, lines[0])
    if example == "driveline_wet_sae2":
        _a_host_sets_the_wet_clutch_s_own_parameters(tmp_path, path, cls, n, dt, lines[0])
    if example == "driveline_torque_converter":   # a looser converter, set by the host: the FMU writes its K's factor
        python, base = _a_host_sets(tmp_path, path, cls, n, dt, energy, "converter.k_scale", 1.15)
        assert python["converter.tau"][0] == pytest.approx(base["converter.tau"][0] / 1.15 ** 2, rel=1e-12)   # stall
    if example == "driveline_amt_upshift":   # a larger cone on 2nd's synchroniser, set by the host
        python, base = _a_host_sets(tmp_path, path, cls, n, dt, energy, "s2.cone_radius", 0.06)

        def engaged(run):   # the first sample from mid-run on at which 2nd's slip is gone
            w = np.abs(run["s2.w_rel"])
            return n // 2 + int(np.flatnonzero(w[n // 2:] <= 1e-9 * w.max())[0])

        # the cone's torque grows with its radius: 2nd's synchroniser engages sooner
        assert engaged(python) < engaged(base)


def test_an_amt_controller_drives_the_native_fmu_s_inputs_as_it_drives_the_network(tmp_path):
    """The AMT with its engine torque, clutch factor and shift fork as network inputs
    (``examples/driveline_amt_tcu.toml``) as a native FMU: the three are FMI inputs.  The inputs clutchlab's AMT
    controller (its ``[tcu]`` table) set in the loop through the upshift, held by FMPy over the same 1 ms
    communication steps (a TCU in a host), give the FMU the closed loop's run: the synchronisers' modes sample for
    sample, the speeds to the solver's tolerance, and the Python co-simulation's outputs to 1e-9."""
    from clutchlab.control import AmtController, closed_loop
    from clutchlab.driveline.description import load_driveline

    source = EXAMPLE.parent / "driveline_amt_tcu.toml"
    cls = DrivelineCoSimulation.for_description(source)
    assert [(v.name, v.unit) for v in cls.inputs] == [("torque_command", "N.m"), ("clutch_command", "1"),
                                                       ("fork", "N")]
    path = export_native_fmu(cls, tmp_path / "amt.fmu", platforms=["linux64"])
    _, svs = _variables(path)
    assert all(svs[name].get("causality") == "input" for name in ("torque_command", "clutch_command", "fork"))
    spec = load_driveline(source)
    tcu = AmtController.from_table(spec.tcu)
    n, dt = 1500, 1e-3                        # through the upshift (0.4-1.33 s)
    loop = closed_loop(spec.driveline.system(spec.rtol), tcu, dt, n * dt, actuate=list(tcu.actuated),
                       measure=[*tcu.measured, "input_shaft.w", "wheels.w"])
    inputs = {name: loop.frame[column].to_numpy() for name, column in
              zip(tcu.actuated, ("torque_command_Nm", "clutch_command_1", "fork_N"))}
    assert list(tcu.phases.phase)[-1] == "drive" and {600.0, -600.0} <= set(inputs["fork"])   # (1st, then 2nd)
    _a_host_drives(tmp_path, path, cls, loop, n, dt, inputs, modes=("s1.mode", "s2.mode"),
                   speeds=("input_shaft.w", "wheels.w"))


def test_a_dct_controller_drives_the_native_fmu_s_inputs_as_it_drives_the_network(tmp_path):
    """The dual-clutch transmission with its engine torque and its two clutches' factors as network inputs
    (``examples/driveline_dct_tcu.toml``) as a native FMU: the inputs clutchlab's DCT controller set in the loop
    through the power upshift, held by FMPy over the same 1 ms steps, give the FMU the closed loop's run (the
    clutches' modes sample for sample, the speeds to the solver's tolerance, the Python co-simulation's outputs to
    1e-9)."""
    from clutchlab.control import DctController, closed_loop
    from clutchlab.driveline.description import load_driveline

    source = EXAMPLE.parent / "driveline_dct_tcu.toml"
    cls = DrivelineCoSimulation.for_description(source)
    assert [v.name for v in cls.inputs] == ["torque_command", "c1_command", "c2_command"]
    path = export_native_fmu(cls, tmp_path / "dct.fmu", platforms=["linux64"])
    spec = load_driveline(source)
    tcu = DctController.from_table(spec.tcu)
    n, dt = 1200, 1e-3                        # through the upshift (0.5-1.1 s)
    loop = closed_loop(spec.driveline.system(spec.rtol), tcu, dt, n * dt, actuate=list(tcu.actuated),
                       measure=[*tcu.measured, "wheels.w"])
    inputs = {name: loop.frame[column].to_numpy() for name, column in
              zip(tcu.actuated, ("torque_command_Nm", "c1_command_1", "c2_command_1"))}
    assert list(tcu.phases.phase) == ["drive", "torque_phase", "inertia_phase", "lock", "drive"]
    _a_host_drives(tmp_path, path, cls, loop, n, dt, inputs, modes=("c1.mode", "c2.mode"),
                   speeds=("engine.w", "wheels.w"))


def _a_host_drives(tmp_path, path, cls, loop, n, dt, inputs, modes, speeds):
    """FMPy drives the native FMU at ``path`` with the ``inputs`` a controller set in the closed ``loop``, held over
    its ``n`` steps of ``dt``: its outputs equal the Python co-simulation's (1e-12), its ``modes`` the loop's sample
    for sample, its ``speeds`` the loop's to the solver's tolerance."""
    native = _fmpy_run(tmp_path, path, n, dt, inputs=inputs)
    python = _python_run(cls, n, dt, inputs=inputs)
    energy = max(float(np.max(np.abs(python[k]))) for k in ("input_work", "kinetic_energy"))
    for name in python:
        _close(native[name], python[name], name, floor=1e-12 * energy if name == "energy_error" else 1e-12)
    for name in modes:
        np.testing.assert_array_equal(native[name], loop.frame[f"{name}_1"].to_numpy(), err_msg=name)
    for name in speeds:
        np.testing.assert_allclose(native[name], loop.frame[f"{name}_rad_s"].to_numpy(), rtol=1e-7, err_msg=name)


def _a_host_sets(tmp_path, path, cls, n, dt, energy, name, value):
    """A host sets the network's parameter ``name`` (a component's declared number) to ``value``: it is a parameter
    of the FMU, and the native run equals the Python co-simulation built with it.  Returns that run's outputs and
    the unchanged network's."""
    _, svs = _variables(path)
    assert svs[name].get("causality") == "parameter"
    folder = tmp_path / name.replace(".", "_")
    folder.mkdir()
    native = _fmpy_run(folder, path, n, dt, {name: value})
    python = _python_run(cls, n, dt, {name: value})
    for out in python:
        _close(native[out], python[out], out, floor=1e-12 * energy if out == "energy_error" else 1e-12)
    return python, _python_run(cls, n, dt)


def _a_host_sets_the_coupling_s_own_parameters(tmp_path, path, cls, n, dt, line):
    """An EMTC coupling's actuator and coupling geometry (the ``[actuator]`` and ``[coupling]`` tables of the scenario
    file its ``bench`` names) are parameters of the network's FMU, ``emtc.actuator.<field>`` and
    ``emtc.coupling.<field>``; what the coupling derives from them (its current lags' rates, its controller's table
    at the engaged airgap ``d - sigma``, Eq. 12) the network's start derives again (``derive_actuator`` on its row,
    ``coupled_start``), so a host sets the airgaps too, and the run equals clutchlab's built with them; an airgap a
    host sets below the free travel is refused at the start with the coupling's message.  What stays fixed: the
    fixed step and the ideal final drives' efficiencies (an ideal gear is another element than a lossy one, as
    MSL's IdealGear and LossyGear)."""
    assert "41 parameters (3 fixed at export); left out, changing nothing in this model: engine.idle_kp, " \
           "engine.idle_ki, engine.idle_torque_max" in line, line   # (its engine has no idle controller)
    _, svs = _variables(path)
    assert [n for n, sv in svs.items() if sv.get("variability") == "constant"] == [
        "solver.fixed_step", "front_drive.efficiency", "rear_drive.efficiency"]
    start = {"emtc.actuator.airgap_open": 1.0e-3, "emtc.actuator.free_travel": 0.45e-3, "emtc.actuator.tau1": 0.012,
             "emtc.coupling.cam_ratio": 5.5}
    assert all(svs[name].get("causality") == "parameter" for name in start)
    (tmp_path / "coupling").mkdir()
    native = _fmpy_run(tmp_path / "coupling", path, n, dt, start)
    python = _python_run(cls, n, dt, start)
    for name in python:
        _close(native[name], python[name], name, floor=1e-9 if name == "energy_error" else 1e-12)
    plain = _python_run(cls, n, dt)
    for name in ("emtc.tau", "emtc.airgap"):
        assert np.max(np.abs(python[name] - plain[name])) > 1e-3 * np.max(np.abs(plain[name])), name
    for kind, what, detail in _start_values(tmp_path, path, [{"emtc.actuator.free_travel": 1.3e-3}], ["emtc.tau"]):
        assert what == "refused" and "emtc: actuator.airgap_open must exceed actuator.free_travel" in detail, \
            (kind, detail)


def _a_host_sets_the_wet_clutch_s_own_parameters(tmp_path, path, cls, n, dt, line):
    """A wet clutch's own parameter sets (its ``clutch`` and ``bench``, files the description names or their
    defaults) are parameters of the network's FMU, ``<component>.clutch.<field>`` and ``<component>.bench.<field>``
    (before, only the component's own fields were: the pack, the friction face, the film and the actuator were fixed
    in the file).  What the clutch derives from several of them (its pack's heat capacity from the masses and
    specific heats, Eq. 8; the Greenwood-Williamson scale from the roughness, Eq. 11; the effective radius, Eq.
    (1')) is derived again by the network's start (``wet_start`` on the clutch's row, ``coupled_start``), so a host
    sets those too, and the run equals clutchlab's built with them."""
    assert "41 parameters (1 fixed at export)" in line, line
    _, svs = _variables(path)
    # (the piston's travel was fixed until the fortieth session: its product with rtol is the piston position's
    # absolute tolerance, a number the FMU now writes from both, image.Target.partner)
    assert [n for n, sv in svs.items() if sv.get("variability") == "constant"] == ["solver.fixed_step"]
    assert "clutch.bench.gear_ratio" not in svs and "clutch.bench.noise_torque" not in svs   # (the bench's drive, rig)
    start = {"clutch.clutch.m_lining": 0.0019, "clutch.clutch.cp_core": 520.0, "clutch.clutch.r_outer": 0.085,
             "clutch.clutch.sigma": 2.2e-6, "clutch.clutch.n_c": 7.0, "clutch.bench.actuator_time_constant": 0.03,
             "clutch.clutch.mu_v1": 1.1e-4, "clutch.clutch.piston_h0": 0.013, "rtol": 5e-9}
    assert all(svs[name].get("causality") == "parameter" for name in start)
    (tmp_path / "sets").mkdir()
    native = _fmpy_run(tmp_path / "sets", path, n, dt, start)
    python = _python_run(cls, n, dt, start)
    for name in python:
        _close(native[name], python[name], name, floor=1e-12)
    plain = _python_run(cls, n, dt)
    for name in ("clutch.temperature", "dyno.w"):
        assert np.max(np.abs(python[name] - plain[name])) > 1e-3 * np.max(np.abs(plain[name])), name


def _a_host_sets_the_vehicle_s_initial_speed(tmp_path, path, cls, n, dt):
    """The AWD vehicle's initial speeds (the shafts, the axles and the drums, bound by the final drives and the
    drums' speed sources) are parameters of its FMU (they were fixed at export, each trial of one alone breaking
    a gear's ratio): a host sets the vehicle at 80 % of the file's speed, all of them together, and co-simulation
    equals clutchlab's run built with them; one speed set alone disagrees with its final drive, and the FMU
    refuses it at its initialisation with the gear's name, as clutchlab refuses it (kernel.kinematic_error)."""
    speeds = {v.name: float(v.start) for v in cls.parameters if v.name.endswith((".w0", "_drive.speed"))}
    _, svs = _variables(path)
    assert len(speeds) == 8 and all(svs[k].get("causality") == "parameter" for k in speeds), speeds
    slower = {k: 0.8 * v for k, v in speeds.items()}
    (tmp_path / "slow").mkdir()
    native = _fmpy_run(tmp_path / "slow", path, n, dt, slower)
    python = _python_run(cls, n, dt, slower)
    for name in python:
        _close(native[name], python[name], name, floor=1e-9 if name == "energy_error" else 1e-12)
    assert native["front_axle.w"][0] == pytest.approx(0.8 * speeds["front_axle.w0"], rel=1e-12)
    with pytest.raises(ParameterError, match=r"front_axle: w0 = [\d.]+ rad/s but front_drive from front_shaft gives"):
        cls(**{"front_axle.w0": 0.8 * speeds["front_axle.w0"]})
    for kind, what, detail in _start_values(tmp_path, path, [{"front_axle.w0": 0.8 * speeds["front_axle.w0"]}],
                                            ["front_axle.w"]):
        assert what == "refused" and re.search(r"front_drive: the initial speeds of its flanges disagree with its "
                                               r"ratio", detail), (kind, detail)


def test_trials_of_a_whole_number_are_relative_and_a_proportion_has_no_offset():
    """A whole-number start is tried at a quarter above and a fifth below it (whole) before one apart: trials one
    apart from 1175810 had taken a curve for a line; a law whose offset is the fit's rounding is a proportion."""
    from types import SimpleNamespace

    from clutchlab.fmu.native.image import _fit, _trials

    var = SimpleNamespace(start=1175810.0, minimum=0.0, maximum=None, positive=False)
    assert _trials(var)[:2] == [1469762.0, 940648.0]
    pairs = SimpleNamespace(start=6.0, minimum=1.0, maximum=20.0, positive=True)
    assert _trials(pairs)[:4] == [8.0, 5.0, 7.0, 4.0]   # (6 * 1.25 = 7.5 rounds to 8; 6 * 0.8 to 5)
    # y = 1e-8 v, with the rounding of the slope fitted from close points: no offset, exact near zero
    v0, v1, v2 = 8000.0, 10000.0, 6400.0
    a, b, reciprocal = _fit(v0, v1, v2, 1e-8 * v0, 1e-8 * v1, 1e-8 * v2)
    assert (b, reciprocal) == (0.0, False) and a == pytest.approx(1e-8, rel=1e-15)
    # a true offset stays
    a, b, _ = _fit(v0, v1, v2, 2.0 * v0 + 3.0, 2.0 * v1 + 3.0, 2.0 * v2 + 3.0)
    assert (a, b) == pytest.approx((2.0, 3.0), rel=1e-12)
    # a curve is no line
    assert _fit(v0, v1, v2, v0 ** 2, v1 ** 2, v2 ** 2) is None


def test_the_accepted_range_is_found_by_bisection_within_the_declared_one():
    """accepted_range: a model that refuses more than its declared range (a bound in its own code) gets the
    interval it accepts; a side it accepts to the declared bound keeps it; whole numbers stay whole."""
    calls = []

    def below_zero(v):
        calls.append(v)
        return v < 0.0

    low, high = accepted_range(below_zero, -0.0015, -100.0, 100.0)
    assert low == -100.0 and -1e-15 < high < 0.0 and len(calls) < 120
    assert accepted_range(lambda v: True, 2000.0, None, None, positive=True) == (0.0, None)
    assert accepted_range(lambda v: v <= 7, 3.0, 1.0, 100.0, whole=True) == (1.0, 7.0)
    low, high = accepted_range(lambda v: 0.5 < v < 4.0, 1.0)
    assert 0.5 < low < 0.5 + 1e-12 and 4.0 - 1e-12 < high < 4.0


_EMTC_PORT_TOML = """
[simulation]
t_end = "0.1 s"
output_step = "1 ms"

[inertia.f]
J = 0.05
w0 = "60 rad/s"

[inertia.r]
J = 0.05
w0 = "50 rad/s"

[speed.drive]
flange = "f"
speed = "60 rad/s"

[spring_damper.load]
a = "r"
b = "ground"
d = "0.5 N*m*s/rad"

[input.T]
start = "40 N*m"
description = "the EMTC's torque request"

[emtc.c]
a = "f"
b = "r"
torque_request = { input = "T" }
"""


def test_a_host_drives_an_emtc_port_through_the_native_fmu(tmp_path):
    """An EMTC coupling's torque request is an FMI input of the network's native FMU (issue #31, inputs are ports):
    FMPy, without clutchlab, steps the request from 40 to 150 N m halfway; the FMU equals the Python co-simulation
    and its controller's reference follows the request at its samples."""
    description = tmp_path / "emtc_port.toml"
    description.write_text(_EMTC_PORT_TOML)
    cls = DrivelineCoSimulation.for_description(description)
    path = export_native_fmu(cls, tmp_path / "port.fmu", platforms=["linux64"], report=None)
    _, svs = _variables(path)
    assert svs["T"].get("causality") == "input"
    n, dt = 100, 1e-3
    inputs = {"T": np.where(np.arange(n + 1) < 50, 40.0, 150.0)}
    native = _fmpy_run(tmp_path, path, n, dt, inputs=inputs)
    python = _python_run(cls, n, dt, inputs=inputs)
    for name in python:
        _close(native[name], python[name], name, floor=1e-9)
    ref = native["c.torque_reference"]
    assert np.all(ref[5:45] == 40.0) and np.all(ref[55:] == 150.0)


#: a wearing E-clutch (tests/driveline/test_wear.py): flange a driven at 100 rad/s, the clutch sliding on a free shaft
_WEAR_TOML = '''
[driveline]
name = "worn_clutch"
[simulation]
t_end = "1 s"
rtol = 1e-8
[inertia.e]
J = 1.0
w0 = "100 rad/s"
[inertia.v]
J = 1.0
[speed.drive]
flange = "e"
speed = "100 rad/s"
[eclutch.c]
a = "e"
b = "v"
position = "3 mm"
wear = "0.05 mm"
wear_rate = "1e-7 m/J"
'''


def test_a_host_sets_the_wear_of_an_e_clutch_in_a_native_fmu(tmp_path):
    """The wear fields of an E-clutch whose working point moves are FMU parameters from its declaration: the initial
    wear and the wear rate (copies into the element table) written by the FMU itself, the table's span (``wear_max``,
    ``expansion``: its levels are built from them) fixed at export.  A host (FMPy without clutchlab) sets a larger
    initial wear and another rate: the FMU equals the Python co-simulation built with them, which differs from the
    default."""
    path_toml = tmp_path / "worn.toml"
    path_toml.write_text(_WEAR_TOML)
    cls = DrivelineCoSimulation.for_description(path_toml)
    lines = []
    path = export_native_fmu(cls, tmp_path / "worn.fmu", platforms=["linux64"], report=lines.append)
    assert "(4 fixed at export)" in lines[0], lines
    _, svs = _variables(path)
    assert [(svs[q].get("causality"), svs[q].find("Real").get("unit")) for q in ("c.wear", "c.wear_rate")] == [
        ("parameter", "m"), ("parameter", "m/J")]
    assert [svs[q].get("variability") for q in ("c.wear_max", "c.expansion", "c.travel")] == ["constant"] * 3
    n, dt = 100, 0.01
    start = {"c.wear": 1e-4, "c.wear_rate": 5e-8}
    native = _fmpy_run(tmp_path, path, n, dt, start)
    python = _python_run(cls, n, dt, start)
    for name in python:
        _close(native[name], python[name], name)
    default = _python_run(cls, n, dt)
    assert native["c.fn"][0] < default["c.fn"][0] - 100.0   # (the host's initial wear took clamp force)
    assert np.max(np.abs(native["c.dissipated"] - default["c.dissipated"])) > 1.0
