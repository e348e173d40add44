"""The public API polices itself: every public callable has a docstring naming each of its arguments."""

import enum
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
