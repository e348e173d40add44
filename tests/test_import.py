"""Importing clutchlab (every module, the CLI included) compiles no numba kernel."""

import subprocess
import sys

CODE = """
import importlib, pkgutil, numba
import clutchlab
from numba.core.registry import CPUDispatcher
names = [m.name for m in pkgutil.walk_packages(clutchlab.__path__, 'clutchlab.') if not m.name.endswith('__main__')]
mods = [importlib.import_module(n) for n in names]
import clutchlab.cli
clutchlab.cli.build_parser()
dispatchers = {id(v): v for m in mods for v in vars(m).values() if isinstance(v, CPUDispatcher)}
print(len(dispatchers), sum(len(d.signatures) for d in dispatchers.values()))
"""


def test_import_compiles_nothing():
    out = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, check=True)
    n_kernels, n_compiled = map(int, out.stdout.split())
    assert n_kernels > 20, "the kernels of all subsystems were found"
    assert n_compiled == 0


PLAIN = """
import sys
from pathlib import Path
from clutchlab.driveline.description import load_driveline
f = load_driveline(Path({examples!r}) / "driveline_coupled_clutches.toml")
f.driveline.pack()
f.driveline._wet_parameters(), f.driveline._emtc_parameters()
print(sorted(m for m in ("clutchlab.wet", "clutchlab.emtc", "clutchlab.eclutch", "scipy.special") if m in sys.modules))
"""


def test_a_plain_network_loads_no_model_package():
    """A driveline file of plain elements (CoupledClutches) is read and packed without importing the wet, EMTC or
    E-clutch packages (the wet one brings SciPy's special functions: 0.13 s of every start of the command line)."""
    from pathlib import Path

    examples = Path(__file__).resolve().parents[1] / "examples"
    out = subprocess.run([sys.executable, "-c", PLAIN.format(examples=str(examples))], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"
