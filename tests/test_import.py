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
