"""The public API polices itself: every public callable has a docstring naming each of its arguments."""

import enum
import importlib
import inspect

import pytest

from clutchlab.cli import _optional_module

MODULES = ["clutchlab", "clutchlab.curves", "clutchlab.units", "clutchlab.eclutch", "clutchlab.params",
           "clutchlab.io", "clutchlab.report", "clutchlab.wet", "clutchlab.emtc", "clutchlab.hysteresis",
           "clutchlab.system", "clutchlab.component", "clutchlab.result", "clutchlab.numerics.core", "clutchlab.numerics.status",
           "clutchlab.driveline", "clutchlab.driveline.bench", "clutchlab.trim", "clutchlab.emtc.params", "clutchlab.wet.bench"]


def public_callables():
    for name in MODULES:
        mod = _optional_module(name)
        if mod is None:
            continue
        for attr in getattr(mod, "__all__", []):
            obj = getattr(mod, attr)
            if inspect.isfunction(obj) or inspect.isclass(obj):
                yield f"{name}.{attr}", obj


def documented_parameters(obj):
    doc = inspect.getdoc(obj) or ""
    if inspect.isclass(obj) and issubclass(obj, enum.Enum):
        return doc, []  # an enumeration's call signature is Enum's functional API, not its own
    if inspect.isclass(obj):
        # a subclass may rely on its bases' documentation of inherited fields
        doc += "".join("\n" + (inspect.getdoc(base) or "") for base in obj.__mro__[1:] if base is not object)
        try:
            sig = inspect.signature(obj)
        except (TypeError, ValueError):
            return doc, []
    else:
        sig = inspect.signature(obj)
    names = [p.name for p in sig.parameters.values()
             if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and p.name not in ("self", "cls")]
    return doc, names


@pytest.mark.parametrize("qualname, obj", list(public_callables()), ids=lambda v: v if isinstance(v, str) else "")
def test_public_callable_is_documented(qualname, obj):
    doc, names = documented_parameters(obj)
    assert doc.strip(), f"{qualname} has no docstring"
    if inspect.isclass(obj) and hasattr(obj, "__dataclass_fields__"):
        # dataclasses document their fields as attributes/parameters or via field metadata (units, doc)
        info = getattr(obj, "field_info", None)
        documented = set(info()) if callable(info) else set()
        missing = [n for n in names if n not in doc and n not in documented]
    else:
        missing = [n for n in names if n not in doc]
    assert not missing, f"{qualname}: arguments not documented: {missing}"


def test_api_pages_document_only_public_api():
    """#33 R8: docs/api/driveline.md documented ``clutchlab.driveline.kernel`` (``driveline_rhs``,
    ``DrivelineParams``, ...).  An API page documents no compiled internal (a kernel module, a ``_`` module, a
    registered hook or its parameter class), only names of a module's ``__all__``, and widens nothing."""
    import api_pages

    internals = api_pages.registered_internals()
    problems = []
    for page, name, options in api_pages.entries():
        why = api_pages.compiled_internal(name)
        if why:
            problems.append(f"{page}: {name} is {why}")
            continue
        problems += [f"{page}: {name} has :{o}:" for o in api_pages.WIDENING if o in options]
        module = importlib.import_module(name)
        names = api_pages.documented_names(module, options)
        public = getattr(module, "__all__", None)
        if names and public is None:
            problems.append(f"{page}: {name} declares no __all__, so the page lists whatever it defines: {names}")
            continue
        problems += [f"{page}: {name}.{n} is not in its __all__" for n in names if n not in (public or [])]
        problems += [f"{page}: {name}.{n} is {internals[id(getattr(module, n))]}" for n in names
                     if id(getattr(module, n, None)) in internals]
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize("module", ["clutchlab.driveline.kernel", "clutchlab.numerics.dopri",
                                    "clutchlab.numerics.rosenbrock", "clutchlab.hysteresis.kernels"])
def test_compiled_internals_are_recognised(module):
    """The check above knows a kernel module when it sees one (else it could not fail)."""
    import api_pages

    assert api_pages.compiled_internal(module)
    assert not api_pages.compiled_internal("clutchlab.driveline.network")
    internals = api_pages.registered_internals()
    from clutchlab.driveline import kernel

    assert id(kernel.driveline_rhs) in internals and id(kernel.DrivelineParams) in internals
