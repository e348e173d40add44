"""The first compilation of a clutchlab kernel is announced once; a cache hit is silent."""

import os
import subprocess
import sys

from clutchlab._compile_notice import NOTICE

SCRIPT = """
import numpy as np
from clutchlab import _compile_notice
from clutchlab.numerics.interp import bracket
from clutchlab.numerics.dopri import error_norm
x = np.linspace(0.0, 1.0, 11)
assert bracket(x, 0.55)[0] == 5
error_norm(np.ones(3), np.ones(3), np.ones(3), 1e-3, np.full(3, 1e-6))
print("compile_seconds", _compile_notice.compile_seconds())
"""


def _run(cache_dir, **env):
    full = {**os.environ, "NUMBA_CACHE_DIR": str(cache_dir), **env}
    return subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=full, timeout=300)


def _seconds(out):
    return float(out.stdout.split("compile_seconds")[1])


def test_first_compile_is_announced_once_and_a_cache_hit_is_silent(tmp_path):
    first = _run(tmp_path)
    assert first.returncode == 0, first.stderr
    assert first.stderr.count(NOTICE) == 1  # two kernels compiled, one line
    assert _seconds(first) > 0.0
    second = _run(tmp_path)
    assert second.returncode == 0, second.stderr
    assert NOTICE not in second.stderr
    assert _seconds(second) == 0.0


def test_notice_can_be_silenced(tmp_path):
    out = _run(tmp_path, CLUTCHLAB_COMPILE_NOTICE="0")
    assert out.returncode == 0, out.stderr
    assert NOTICE not in out.stderr
    assert _seconds(out) > 0.0


def test_a_function_without_a_module_does_not_break_the_listener(tmp_path):
    """numbalsoda compiles functions made by ``exec``, whose ``__module__`` is None: the listener must
    let them compile (it raised AttributeError) and stay silent about them."""
    script = """
import numba
from clutchlab import _compile_notice
_compile_notice.install()
ns = {"__name__": None}
exec("def f(x):\\n    return x + 1", ns)
ns["f"].__module__ = None
print("value", numba.njit(ns["f"])(1))
print("compile_seconds", _compile_notice.compile_seconds())
"""
    full = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=full, timeout=300)
    assert out.returncode == 0, out.stderr
    assert "value 2" in out.stdout
    assert NOTICE not in out.stderr
    assert _seconds(out) == 0.0
