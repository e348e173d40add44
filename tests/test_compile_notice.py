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
    full = {**os.environ, "NUMBA_CACHE_DIR": str(cache_dir), "CLUTCHLAB_COMPILE_NOTICE": "1", **env}
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
    full = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path), "CLUTCHLAB_COMPILE_NOTICE": "1"}
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=full, timeout=300)
    assert out.returncode == 0, out.stderr
    assert "value 2" in out.stdout
    assert NOTICE not in out.stderr
    assert _seconds(out) == 0.0


def test_every_later_compilation_says_what_compiles_and_how_long_it_took(tmp_path):
    """#33: the notice came once per process, so a second model kind compiling for a minute looked like a
    hang. A compilation still running after ANNOUNCE_AFTER seconds says what it is, and when it ends how long
    it took (here ANNOUNCE_AFTER = 0 s, so that a short compilation is announced)."""
    script = SCRIPT.replace("from clutchlab import _compile_notice",
                            "from clutchlab import _compile_notice\n_compile_notice.ANNOUNCE_AFTER = 0.0")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300,
                         env={**os.environ, "NUMBA_CACHE_DIR": str(tmp_path), "CLUTCHLAB_COMPILE_NOTICE": "1"})
    assert out.returncode == 0, out.stderr
    lines = out.stderr.splitlines()
    assert lines.count(NOTICE) == 1 and lines[0] == NOTICE            # the first: the explanation, once
    assert "clutchlab: compiling numerics.dopri.error_norm ..." in lines
    done = [line for line in lines if line.startswith("clutchlab: compiled numerics.dopri.error_norm in ")]
    assert len(done) == 1 and done[0].endswith(" s; numba caches it for later runs")
    assert 0.0 < float(done[0].split(" in ")[1].split(" s")[0]) < 300
    # from the cache: nothing compiles, nothing is said
    again = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300,
                           env={**os.environ, "NUMBA_CACHE_DIR": str(tmp_path), "CLUTCHLAB_COMPILE_NOTICE": "1"})
    assert again.returncode == 0 and "clutchlab:" not in again.stderr, again.stderr


def test_generated_kernels_are_named_for_people():
    from clutchlab._compile_notice import describe

    def advance():
        pass

    advance.__qualname__ = "advance"
    advance.__module__ = "clutchlab.numerics._kernels.k_clutchlab_driveline_kernel_DrivelineParams_dopri_990cc79"
    assert describe(advance) == "driveline kernel (dopri): advance"
    advance.__module__ = "clutchlab.wet.system"
    assert describe(advance) == "wet.system.advance"
