"""What the API pages (docs/api/*.md) document, read as autodoc reads it, and what is a compiled internal.

An API page documents a module with ``.. automodule::``; with the site's default ``members`` option autodoc
takes the module's ``__all__`` (or, without one, every public name the module defines), less
``:exclude-members:``; ``:no-members:`` documents the docstring alone.  A *compiled internal* is not API and
is on no page (:func:`compiled_internal`): a ``_``-prefixed module, a kernel module, a module holding a
model's registered hooks and nothing else (the driveline with wet clutches), the integrator core's compiled
pieces (Dormand-Prince, Rosenbrock, table look-up); and, by name, the compiled hooks a model registers with
:func:`clutchlab.numerics.dispatch.register` and the parameter class they take (``driveline_rhs``,
``DrivelineParams``, ``EClutchParams``, ...).
"""

from __future__ import annotations

import importlib
import inspect
import pathlib
import pkgutil
import re

import clutchlab

API = pathlib.Path(__file__).resolve().parents[2] / "docs" / "api"
_DIRECTIVE = re.compile(r"^\.\. automodule:: (\S+)[ \t]*\n((?:[ \t]+:[\w-]+:.*\n)*)", re.M)
_OPTION = re.compile(r"^[ \t]+:([\w-]+):[ \t]*(.*)$", re.M)
#: options that document more than a module's public API
WIDENING = ("private-members", "special-members", "undoc-members", "imported-members", "ignore-module-all",
            "inherited-members")


def entries():
    """``(page name, module name, {option: value})`` of every ``automodule`` on the API pages."""
    for page in sorted(API.glob("*.md")):
        for match in _DIRECTIVE.finditer(page.read_text(encoding="utf-8")):
            yield page.name, match.group(1), dict(_OPTION.findall(match.group(2)))


def all_modules() -> dict:
    """Every module of clutchlab, imported (which registers every model's hooks; it compiles nothing)."""
    out = {}
    for info in pkgutil.walk_packages(clutchlab.__path__, "clutchlab."):
        if info.name.rsplit(".", 1)[-1] != "__main__":
            out[info.name] = importlib.import_module(info.name)
    return out


def _is_kernel(obj) -> bool:
    from numba.core.dispatcher import Dispatcher

    return isinstance(obj, Dispatcher)


def compiled_internal(name: str) -> str | None:
    """Why the module ``name`` is a compiled internal (not API), or None.

    Compiled physics (the friction laws of :mod:`clutchlab.eclutch.friction`, ...) is API: pure functions
    people call.  Internal are the compiled machinery's modules: ``_`` modules, kernel modules, modules of a
    model's registered hooks and nothing else of their own, and the integrator core's compiled pieces."""
    if any(part.startswith("_") for part in name.split(".")):
        return "a private module"
    if name.rsplit(".", 1)[-1] in ("kernel", "kernels"):
        return "a kernel module"
    module = importlib.import_module(name)
    own = [v for k, v in vars(module).items() if not k.startswith("_") and getattr(v, "__module__", None) == name
           and (inspect.isfunction(v) or inspect.isclass(v) or _is_kernel(v))]
    internals = registered_internals()
    hooks = [v for v in own if id(v) in internals]
    if hooks and all(id(v) in internals or _is_kernel(v) for v in own):
        return "the registered compiled hooks of a model and nothing else of its own"
    functions = [v for v in own if not inspect.isclass(v)]
    if name.startswith("clutchlab.numerics.") and functions and all(_is_kernel(f) for f in functions):
        return "a compiled piece of the integrator core (every public function it defines is a numba kernel)"
    return None


def registered_internals() -> dict:
    """``id(object) -> description`` of every model's registered compiled hooks and their parameter class."""
    from clutchlab.numerics import dispatch

    all_modules()
    out = {}
    for params, hooks in dispatch._MODELS.items():
        out[id(params)] = f"the hooks' parameter class {params.__module__}.{params.__name__}"
        for hook, fn in hooks.items():
            out[id(fn)] = f"the compiled {hook!r} hook of {params.__name__}"
    return out


def documented_names(module, options: dict) -> list[str]:
    """The names autodoc documents for ``.. automodule::`` of ``module`` with ``options`` (default: members)."""
    if "no-members" in options:
        return []
    listed = options.get("members", "").strip()
    if listed:
        names = [n.strip() for n in listed.split(",") if n.strip()]
    elif hasattr(module, "__all__"):
        names = list(module.__all__)
    else:
        names = [k for k, v in vars(module).items()
                 if not k.startswith("_") and getattr(v, "__module__", None) == module.__name__]
    excluded = {n.strip() for n in options.get("exclude-members", "").split(",")}
    return [n for n in names if n not in excluded]
