"""Native FMUs (issue #32): export time, instantiation, and what the FMI layer adds to a step.

Run: ``python benchmarks/bench_native_fmu.py`` (needs ``cc`` and ``c++``).

Model: ``examples/driveline_coupled_clutches.toml`` (MSL's CoupledClutches: 4 inertias, 3 clutches, 30
outputs).  Figures, each the median of 7 repeats with min-max:

* **export**: ``export_native_fmu`` with the object code already cached (warm: what a second export of a
  changed parameter file costs) and after removing it (cold: the LLVM emission of the session's functions);
  the model's kernels themselves are numba's cached ones (``clutchlab warmup``).
* **instantiate**: ``fmi2Instantiate`` + setup + initialisation mode, in a C host (no Python), per instance.
* **step**: a C host steps the FMU over 1.5 s with a 1 ms communication step (1,500 ``fmi2DoStep`` + a
  ``fmi2GetReal`` of every output), and a second instance of a benchmark build of the same library calls the
  compiled session entry directly (``cl_benchmark_session``: the same advance and outputs without the FMI
  layer); the difference per step is what the layer adds.  Beside them, the Python co-simulation's
  ``do_step_array`` chain (the same compiled calls through ``clutchlab.system.Simulation``) and FMPy's
  ``simulate_fmu`` of the native FMU.
"""

from __future__ import annotations

import os
import platform
import statistics
import subprocess
import tempfile
import time
import zipfile
from pathlib import Path

from clutchlab.fmu.driveline import DrivelineCoSimulation
from clutchlab.fmu.native import export_native_fmu

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "driveline_coupled_clutches.toml"
HEADERS = ROOT / "src" / "clutchlab" / "fmu" / "shim"
N, DT, REPEAT = 1500, 1e-3, 7

HOST = r"""
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "fmi2Functions.h"
static void logger(fmi2ComponentEnvironment e, fmi2String n, fmi2Status s, fmi2String c, fmi2String m, ...) {}
static const fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
int main(int argc, char **argv) {
    void *lib = dlopen(argv[1], RTLD_NOW);
    const char *guid = argv[2];
    int n = atoi(argv[3]), nout = atoi(argv[5]), k, r;
    double dt = atof(argv[4]), t0, t_inst, t_step, t_bare, sink = 0.0;
    fmi2InstantiateTYPE *inst = dlsym(lib, "fmi2Instantiate");
    fmi2FreeInstanceTYPE *fr = dlsym(lib, "fmi2FreeInstance");
    fmi2SetupExperimentTYPE *setup = dlsym(lib, "fmi2SetupExperiment");
    fmi2EnterInitializationModeTYPE *enter = dlsym(lib, "fmi2EnterInitializationMode");
    fmi2ExitInitializationModeTYPE *leave = dlsym(lib, "fmi2ExitInitializationMode");
    fmi2DoStepTYPE *step = dlsym(lib, "fmi2DoStep");
    fmi2GetRealTYPE *get = dlsym(lib, "fmi2GetReal");
    int (*bare)(fmi2Component, double) = dlsym(lib, "cl_benchmark_session");
    fmi2ValueReference *vr = malloc(sizeof *vr * nout);
    double *y = malloc(sizeof *y * nout);
    fmi2Component c;
    for (k = 0; k < nout; k++) vr[k] = (fmi2ValueReference)atoi(argv[6]) + k;
    t0 = now();
    for (r = 0; r < 1000; r++) {
        c = inst("b", fmi2CoSimulation, guid, "", &cb, 0, 0);
        setup(c, 0, 0.0, 0.0, 0, 0.0); enter(c); leave(c);
        fr(c);
    }
    t_inst = (now() - t0) / 1000;
    c = inst("b", fmi2CoSimulation, guid, "", &cb, 0, 0);
    setup(c, 0, 0.0, 0.0, 0, 0.0); enter(c); leave(c);
    t0 = now();
    for (k = 0; k < n; k++) {
        if (step(c, k * dt, dt, 1) != fmi2OK) return 5;
        get(c, vr, nout, y);
        sink += y[0];
    }
    t_step = (now() - t0) / n;
    fr(c);
    c = inst("b", fmi2CoSimulation, guid, "", &cb, 0, 0);
    setup(c, 0, 0.0, 0.0, 0, 0.0); enter(c); leave(c);
    t0 = now();
    for (k = 0; k < n; k++) {
        if (bare(c, (k + 1) * dt) != 0) return 6;
        sink += y[0];
    }
    t_bare = (now() - t0) / n;
    fr(c);
    printf("%.9g %.9g %.9g %g\n", t_inst, t_step, t_bare, sink);
    return 0;
}
"""


def _median(xs):
    return f"{statistics.median(xs):.3g} (min {min(xs):.3g}, max {max(xs):.3g})"


def main():
    cls = DrivelineCoSimulation.for_description(EXAMPLE)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = tmp / "cc.fmu"
        export_native_fmu(cls, path, platforms=["linux64"], _benchmark=True)   # (kernels and objects cached)
        warm, cold = [], []
        for _ in range(REPEAT):
            t = time.perf_counter()
            export_native_fmu(cls, path, platforms=["linux64"], overwrite=True)
            warm.append(time.perf_counter() - t)
        from clutchlab.numerics.entry import kernel_dir

        for _ in range(3):
            for obj in (kernel_dir() / "native").glob("*.o"):
                if not obj.name.startswith("nrt-"):
                    obj.unlink()
            t = time.perf_counter()
            export_native_fmu(cls, path, platforms=["linux64"], overwrite=True, _benchmark=True)
            cold.append(time.perf_counter() - t)
        with zipfile.ZipFile(path) as z:
            z.extractall(tmp / "fmu")
            md = z.read("modelDescription.xml").decode()
        import xml.etree.ElementTree as ET

        root = ET.fromstring(md)
        outs = [int(sv.get("valueReference")) for sv in root.iter("ScalarVariable") if sv.get("causality") == "output"]
        assert outs == list(range(outs[0], outs[0] + len(outs)))
        lib = tmp / "fmu" / "binaries" / "linux64" / "Clutchlab_coupled_clutches.so"
        (tmp / "host.c").write_text(HOST)
        subprocess.run(["cc", "-O2", f"-I{HEADERS}", str(tmp / "host.c"), "-o", str(tmp / "host"), "-ldl"], check=True)
        inst, step, bare = [], [], []
        for _ in range(REPEAT):
            out = subprocess.run([str(tmp / "host"), str(lib), root.get("guid"), str(N), str(DT), str(len(outs)),
                                  str(outs[0])], capture_output=True, text=True, check=True).stdout.split()
            inst.append(float(out[0]) * 1e6)
            step.append(float(out[1]) * 1e6)
            bare.append(float(out[2]) * 1e6)
        py = []
        for _ in range(REPEAT):
            sim = cls()
            t = time.perf_counter()
            for k in range(N):
                sim.do_step_array(k * DT, DT, ())
            py.append((time.perf_counter() - t) / N * 1e6)
        import fmpy

        fm = []
        for _ in range(REPEAT):
            t = time.perf_counter()
            fmpy.simulate_fmu(str(path), stop_time=N * DT, output_interval=DT)
            fm.append((time.perf_counter() - t) / N * 1e6)
    layer = [a - b for a, b in zip(step, bare)]
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, {platform.platform()}")
    print(f"model: {EXAMPLE.name}, {N} communication steps of {DT * 1e3:g} ms, {len(outs)} outputs read per step")
    print(f"export, object code cached   [s]  {_median(warm)}")
    print(f"export, object code emitted  [s]  {_median(cold)}")
    print(f"instantiate + initialise    [us]  {_median(inst)}")
    print(f"fmi2DoStep + fmi2GetReal    [us]  {_median(step)} per step (C host)")
    print(f"session call alone          [us]  {_median(bare)} per step")
    print(f"what the FMI layer adds     [us]  {_median(layer)} per step")
    print(f"Python co-simulation        [us]  {_median(py)} per step (ContractCoSimulation.do_step_array)")
    print(f"FMPy simulate_fmu           [us]  {_median(fm)} per step (FMPy's Python loop included)")


if __name__ == "__main__":
    main()
