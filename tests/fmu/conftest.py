"""Shared helpers of the FMU tests: build an FMU once per session, run it with FMPy (a real FMI importer)."""

import numpy as np
import pytest


@pytest.fixture(scope="session")
def fmu_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("fmus")


@pytest.fixture(scope="session")
def build_fmu(fmu_dir):
    """``build_fmu(model)`` -> path of the FMU exported for ``model`` (built once per session)."""
    from clutchlab.fmu.export import export_fmu

    cache = {}

    def build(model):
        if model not in cache:
            cache[model] = export_fmu(model, fmu_dir / f"{model}.fmu")
        return cache[model]

    return build


_RUNNER = """
import json, sys
import numpy as np
import fmpy
spec = json.load(open(sys.argv[1]))
names = list(spec["inputs"])
n, dt = spec["n"], spec["dt"]
table = None
if names:
    table = np.zeros(n + 1, dtype=[("time", float)] + [(k, float) for k in names])
    table["time"] = np.arange(n + 1) * dt
    for k in names:
        table[k] = spec["inputs"][k]
res = fmpy.simulate_fmu(spec["path"], start_time=0.0, stop_time=n * dt, step_size=dt, output_interval=dt,
                        input=table, output=spec["outputs"], start_values=spec["start_values"])
np.savez(spec["result"], time=res["time"], **{k: res[k] for k in spec["outputs"]})
"""


def _run_fmu(path, inputs, dt, n, outputs, start_values=None):
    """Simulate ``path`` with FMPy over ``n`` communication steps of ``dt``, as a host does.

    A plain script file run by a fresh Python, which exits normally (interpreter
    finalisation included); its return code must be 0 -- a crash at exit fails.
    ``inputs`` maps input names to arrays of length ``n + 1`` (value held over
    ``[k dt, (k+1) dt]``; FMPy samples the table at the communication points).
    Returns a dict of output arrays at ``0, dt, ..., n dt``.
    """
    import json
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory(prefix="clutchlab_fmpy_") as tmp:
        spec = {"path": str(path), "n": int(n), "dt": float(dt), "outputs": list(outputs),
                "inputs": {k: [float(x) for x in v] for k, v in inputs.items()},
                "start_values": dict(start_values or {}), "result": str(Path(tmp) / "result.npz")}
        (Path(tmp) / "spec.json").write_text(json.dumps(spec))
        (Path(tmp) / "host.py").write_text(_RUNNER)
        proc = subprocess.run([sys.executable, str(Path(tmp) / "host.py"), str(Path(tmp) / "spec.json")],
                              capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, f"return code {proc.returncode}: {proc.stderr[-3000:]}"
        with np.load(spec["result"]) as data:
            res = {k: np.asarray(data[k], float) for k in data.files}
    tk = np.arange(n + 1) * dt
    assert res["time"].shape == tk.shape, res["time"]
    np.testing.assert_allclose(res["time"], tk, rtol=0, atol=1e-9)
    return {k: res[k] for k in outputs}


def _run_cosim(cosim, inputs, dt, n):
    """The same input table through the in-process co-simulation object.

    Communication points as FMPy computes them: ``t_k = k dt`` and the step
    ``t_k+1 - t_k`` (not ``dt``: the two differ by rounding, and a model whose
    step control depends on ``t + dt`` would see the difference).
    """
    names = list(inputs)
    u = lambda k: {name: float(inputs[name][k]) for name in names}  # noqa: E731
    rows = [cosim.initial_outputs(u(0))]
    for k in range(n):
        t = 0.0 + k * dt
        rows.append(cosim.do_step(t, (0.0 + (k + 1) * dt) - t, u(k)))
    return {name: np.array([r[name] for r in rows]) for name in rows[0]}


@pytest.fixture(scope="session")
def run_fmu():
    """The FMPy runner :func:`_run_fmu`."""
    return _run_fmu


@pytest.fixture(scope="session")
def run_cosim():
    """The in-process runner :func:`_run_cosim`."""
    return _run_cosim
