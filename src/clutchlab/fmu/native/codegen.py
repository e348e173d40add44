"""Object code of a session's compiled functions, for a native FMU: no Python, no numba, no JIT.

numba keeps, with every compiled function (and in its cache), the LLVM module of the function and of
everything it calls (``CodeLibrary._get_module_for_linking``).  :func:`session_functions` gathers the modules
of a session's three entries -- ``session`` (:func:`clutchlab.numerics.session.call`), the model's ``advance``
and ``evaluate_outputs`` -- and of every function they call through an address
(:mod:`clutchlab.numerics.outline`, found by the keys their callers carry).  :func:`emit_object` links them
into one module, keeps only those entries visible (everything else internal, so two FMUs in one host never
share a symbol), drops the unused code -- numba's Python wrappers with their Python C-API references -- and
emits a position-independent object for the target, with the small code model and a generic CPU (the FMU
runs on any x86-64).  What is left undefined is numba's runtime (``NRT_*``, compiled from numba's own
``nrt.cpp`` by :mod:`~clutchlab.fmu.native.toolchain`), the outline resolver (generated C) and the C library.

The objects are cached in clutchlab's kernel folder by the entries' symbol names (which carry the model's
source stamp and argument types), the target and the versions of numba and llvmlite.
"""

from __future__ import annotations

import dataclasses
import hashlib
import os
import re
from pathlib import Path

from .image import NativeExportError

__all__ = ["SessionFunctions", "session_functions", "emit_object", "TARGETS", "CODEGEN_VERSION"]

#: a new version of this code generation takes new cache entries
CODEGEN_VERSION = 1

#: FMI platform -> LLVM target triple
TARGETS = {"linux64": "x86_64-unknown-linux-gnu", "win64": "x86_64-pc-windows-gnu"}

_OUTLINED = re.compile(r"clutchlab_outlined_([0-9a-f]{16})")


@dataclasses.dataclass
class SessionFunctions:
    """The native symbols of a session's entries and the LLVM modules that define them."""

    session: str
    advance: str
    outputs: str
    #: outline key -> native symbol of the function called through it
    outlined: dict
    #: (symbol, llvm module for linking) of every entry
    modules: list
    #: the model-exchange entry's symbol (:func:`exchange_function`), or None
    exchange: str | None = None

    def with_exchange(self, other: "SessionFunctions") -> "SessionFunctions":
        """These functions and the model-exchange entry of ``other`` (one object for both)."""
        have = {name for name, _ in self.modules}
        modules = self.modules + [(n, m) for n, m in other.modules if n not in have]
        return SessionFunctions(self.session, self.advance, self.outputs, {**self.outlined, **other.outlined},
                                modules, other.exchange)

    def cache_key(self, triple: str) -> str:
        import llvmlite
        import numba

        text = "\n".join([str(CODEGEN_VERSION), triple, numba.__version__, llvmlite.__version__,
                          *sorted(s for s, _ in self.modules)])
        return hashlib.sha256(text.encode()).hexdigest()[:32]


def _cres(dispatcher, sig):
    """numba's compile result of ``dispatcher``'s overload for the argument types ``sig`` (compiled, or loaded
    from numba's cache)."""
    sig = tuple(sig)
    cres = dispatcher.overloads.get(sig)
    if cres is None:
        dispatcher.compile(sig)
        cres = dispatcher.overloads.get(sig)
        if cres is None:
            for key, c in dispatcher.overloads.items():
                if tuple(key) == sig:
                    return c
            raise NativeExportError(f"{dispatcher.py_func.__qualname__}: no compiled overload for {sig}")
    return cres


def session_functions(image) -> SessionFunctions:
    """The compiled functions a session (:class:`~clutchlab.fmu.native.image.Image`) calls, with their LLVM
    modules; for a model-exchange image, its ``model_exchange`` entry (``exchange``)."""
    from numba.core import types

    from ...numerics import outline, session as S

    module, outputs_module, _ = image.entry_modules
    args = image.args
    args_ty = module.session.typeof_pyval(args)
    a = args_ty.types
    if image.method == "exchange":
        firsts = [_cres(outputs_module.model_exchange, (S.SessionType(args_ty), types.int64))]
    else:
        firsts = [_cres(module.session, (S.SessionType(args_ty), types.float64, types.int64)),
                  _cres(module.advance, a[:4] + (types.float64,) + a[4:14]),
                  _cres(outputs_module.evaluate_outputs, (a[0], types.float64, a[1], a[3], a[2], a[14]))]
    modules = []
    seen = set()
    todo = set()

    def add(cres):
        name = cres.fndesc.llvm_func_name
        mod = cres.library._get_module_for_linking()
        modules.append((name, mod))
        todo.update(int(k, 16) for k in _OUTLINED.findall(str(mod)))
        return name

    names = [add(c) for c in firsts]
    outlined = {}
    while todo:
        key = todo.pop()
        if key in seen:
            continue
        seen.add(key)
        entry = outline._entry_of(key)
        if entry is None:
            raise NativeExportError(f"the compiled code calls an outlined function (key {key:016x}) that this "
                                    "clutchlab does not define (clear numba's cache: clutchlab was updated)")
        if not S.native_address(entry.dispatcher, entry.sig(), entry.returns):
            raise NativeExportError(f"{entry.label}{entry.sig()} does not return {entry.returns}")
        outlined[key] = add(_cres(entry.dispatcher, entry.sig()))
    if image.method == "exchange":
        return SessionFunctions("", "", "", outlined, modules, names[0])
    return SessionFunctions(names[0], names[1], names[2], outlined, modules)


def _object_cache(key: str) -> Path:
    from ...numerics.entry import kernel_dir

    return kernel_dir() / "native" / f"{key}.o"


def emit_object(functions: SessionFunctions, platform: str) -> bytes:
    """The object code of ``functions`` for the FMI ``platform`` (``"linux64"``, ``"win64"``); cached."""
    import llvmlite.binding as ll

    triple = TARGETS[platform]
    key = functions.cache_key(triple)
    cached = _object_cache(key)
    try:
        return cached.read_bytes()
    except OSError:
        pass
    entries = {name for name, _ in functions.modules}
    clones = []
    for name, mod in functions.modules:
        clone = ll.parse_bitcode(mod.as_bitcode())
        clone.get_function(name).linkage = "external"   # (linkonce_odr: the IR linker would drop it unused)
        clones.append(clone)
    main = clones[0]
    for clone in clones[1:]:
        main.link_in(clone)
    for fn in main.functions:
        if not fn.is_declaration:
            if fn.name in entries:
                fn.linkage = "external"
                fn.visibility = "hidden"
            else:
                fn.linkage = "internal"
    for gv in main.global_variables:
        if not gv.is_declaration:
            gv.linkage = "internal"
    try:
        target = ll.Target.from_triple(triple)
    except RuntimeError as exc:
        raise NativeExportError(f"LLVM has no target {triple} ({exc})") from None
    tm = target.create_target_machine(cpu="x86-64", features="", opt=2, reloc="pic", codemodel="small")
    main.triple = triple
    main.data_layout = str(tm.target_data)
    pm = ll.create_new_module_pass_manager()
    pm.add_global_dead_code_eliminate_pass()
    pm.add_strip_dead_prototype_pass()
    pm.run(main, ll.create_pass_builder(tm, ll.create_pipeline_tuning_options(speed_level=0)))
    unknown = sorted(f.name for f in main.functions
                     if f.is_declaration and f.name.startswith(("Py", "_Py", "numba_")))
    if unknown:
        raise NativeExportError(f"the compiled code still calls Python ({', '.join(unknown[:4])}): it cannot "
                                "run without Python")
    obj = tm.emit_object(main)
    try:
        cached.parent.mkdir(parents=True, exist_ok=True)
        tmp = cached.with_name(f".{cached.name}.{os.getpid()}")
        tmp.write_bytes(obj)
        os.replace(tmp, cached)
    except OSError:
        pass   # (no cache: emitted again next time)
    return obj
