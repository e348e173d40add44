"""The public API of clutchlab.wet: importable, documented, no compilation at import."""

import inspect
import subprocess
import sys

import clutchlab.wet as wet


def test_every_public_function_documents_its_arguments():
    for name in wet.__all__:
        obj = getattr(wet, name)
        assert obj.__doc__, name
        if inspect.isfunction(obj):
            doc = obj.__doc__
            for arg in inspect.signature(obj).parameters:
                assert arg in doc, f"{name}: argument {arg!r} not documented"


def test_import_compiles_nothing():
    code = ("import numba, clutchlab.wet, clutchlab.demo.wet, clutchlab.cli.wet\n"
            "from clutchlab.wet import film, friction, system\n"
            "from clutchlab.numerics import entry\n"
            "fns = [system.wet_rhs, film.film_scalar, friction.mu_kernel]\n"
            "print(sum(len(f.signatures) for f in fns) + len(entry._LOADED))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "0"
