"""clutchlab's cache folders: one place that decides where a cache lives (the compiled kernels' entry modules,
:func:`clutchlab.numerics.entry.kernel_dir`; the unit conversions a file used, :mod:`clutchlab.units`).

A cache is never an input: deleting it costs only time, and what is read from it is checked (a kernel folder must be
this user's own; a conversion must be a finite number).  Without numba or pint: it is read before either is imported.
"""

from __future__ import annotations

import functools
import hashlib
import os
import re
import stat
import tempfile
from pathlib import Path

__all__ = ["cache_folder", "guard_stale_indexes", "guard_cross_module_constants", "dependency_stamp"]


def cache_folder(name: str) -> Path:
    """The writable folder of cache ``name`` (created if needed), the first of: ``$NUMBA_CACHE_DIR/clutchlab-NAME``
    (numba's cache and clutchlab's together: one variable empties both), ``$XDG_CACHE_HOME/clutchlab/NAME``
    (``~/.cache`` without it), a private ``clutchlab-NAME-UID`` in the temporary folder (refused if it is a link or
    belongs to another user: a kernel folder's modules are imported from it).

    Raises
    ------
    OSError
        None of them can be written.
    """
    candidates = []
    if os.environ.get("NUMBA_CACHE_DIR"):
        candidates.append(Path(os.environ["NUMBA_CACHE_DIR"]) / f"clutchlab-{name}")
    xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    candidates.append(Path(xdg) / "clutchlab" / name)
    shared = Path(tempfile.gettempdir()) / f"clutchlab-{name}-{os.getuid() if hasattr(os, 'getuid') else 0}"
    candidates.append(shared)
    refused = ""
    for path in candidates:
        try:
            if path == shared:
                # in a folder every user writes to, another user could have made it first, or a link: its modules
                # are imported and numba's pickles read from it, so it must be this user's own and private
                refused = _private_folder(path)
                if refused:
                    continue
            else:
                path.mkdir(parents=True, exist_ok=True)
            if os.access(path, os.W_OK):
                return path
        except OSError:
            continue
    raise OSError(f"no writable folder for clutchlab's {name} cache (tried: "
                  + ", ".join(str(c) for c in candidates) + ")" + (f"; {refused}" if refused else "")
                  + ": set NUMBA_CACHE_DIR to a folder of your own")


def guard_stale_indexes() -> None:
    """Read a numba cache index that cannot be unpickled as an empty one (idempotent; compiles nothing).

    numba loads a cached function's index by unpickling it whole and only then compares the source file's stamp
    (``numba.core.caching.IndexDataCacheFile._load_index``), so an index written by an older clutchlab whose
    signatures name a class since removed or renamed raised instead of being the stale cache it is: ``AttributeError:
    Can't get attribute 'VehicleData' on <module 'clutchlab.emtc.system'>`` after an upgrade over an existing cache
    (an editable install after a pull, ``NUMBA_CACHE_DIR`` kept across versions; found when the EMTC's vehicle
    record replaced its NamedTuple).  Such an index is now a miss: numba compiles the function again and writes a
    fresh index over it.  The same for a cached function's data (``IndexDataCacheFile.load``): a function whose own
    file is unchanged keeps its index, and its data names the modules of the compiled functions it calls, whose
    environments numba rebuilds by importing them; a module an upgrade renamed raised ``ModuleNotFoundError: No
    module named 'clutchlab.hysteresis._kernels'`` (found when the Preisach kernels became
    ``clutchlab.hysteresis.kernels``: the wet clutch's network function, in an unchanged file, called them).  Such
    data is now a miss too.  Applies to every numba cache of the process, which gains the same robustness."""
    import pickle

    from numba.core import caching

    load_index = caching.IndexDataCacheFile._load_index
    if getattr(load_index, "_clutchlab_guard", False):
        return
    load = caching.IndexDataCacheFile.load
    stale = (AttributeError, ImportError, pickle.UnpicklingError, EOFError, IndexError, TypeError, ValueError)

    def _load_index(self):
        try:
            return load_index(self)
        except stale:
            return {}   # (an index of classes that no longer exist: stale, compiled again and overwritten)

    def _load(self, key):
        try:
            return load(self, key)
        except stale:
            return None   # (data naming a module or class that no longer exists: compiled again and overwritten)

    _load_index._clutchlab_guard = True
    _load_index.__doc__ = load_index.__doc__
    _load.__doc__ = load.__doc__
    caching.IndexDataCacheFile._load_index = _load_index
    caching.IndexDataCacheFile.load = _load


# ---- numba's cache and the constants one module reads from another
# (not anchored at a line's start: six times faster, and a match inside a string only adds a dependency)
_IMPORT_FROM = re.compile(r"from[ \t]+(\.+[\w.]*|clutchlab(?:\.\w+)*)[ \t]+import[ \t]+(\([^)]*\)|[^\n#;]*)")
_IMPORT = re.compile(r"import[ \t]+(clutchlab(?:\.\w+)*)")


def _module_file(files: dict, parts) -> str | None:
    """The source file of the module ``parts`` (its names below the package) among ``files`` (the package's, by
    their names relative to it), or None."""
    name = "/".join(parts)
    for candidate in ((name + ".py") if parts else None, (name + "/__init__.py") if parts else "__init__.py"):
        if candidate is not None and candidate in files:
            return candidate
    return None


def _imports(files: dict, name: str, text: str) -> set:
    """The package's source files the file ``name`` imports (anywhere in it: a function's import too), from its
    text."""
    own = name.split("/")[:-1]   # (the package the file is in; an __init__ is in its own)
    found = set()
    for source, names in _IMPORT_FROM.findall(text):
        if source.startswith("."):
            level = len(source) - len(source.lstrip("."))
            if level - 1 > len(own):
                continue
            base = own[:len(own) - (level - 1)]
            rest = [q for q in source.lstrip(".").split(".") if q]
        else:
            base, rest = [], source.split(".")[1:]
        parts = base + rest
        module = _module_file(files, parts)
        if module is not None:
            found.add(module)
        for imported in names.strip("()").replace("\n", " ").split(","):
            imported = imported.strip().split(" ")[0]
            if imported.isidentifier():
                sub = _module_file(files, parts + [imported])
                if sub is not None:
                    found.add(sub)
    for source in _IMPORT.findall(text):
        module = _module_file(files, source.split(".")[1:])
        if module is not None:
            found.add(module)
    found.discard(name)
    return found


@functools.lru_cache(maxsize=4)
def _package_graph(root: Path) -> tuple:
    """``(digests, imports)`` of every source file below ``root`` by its name relative to it (``a/b.py``): its
    content's digest and the names of the files it imports."""
    files = {}
    for path in root.rglob("*.py"):
        files[path.relative_to(root).as_posix()] = path.read_bytes()
    digests = {name: hashlib.sha1(data).hexdigest() for name, data in files.items()}
    imports = {name: _imports(files, name, data.decode("utf-8", "replace")) for name, data in files.items()}
    return digests, imports


def dependency_stamp(path, root=None) -> str:
    """A digest of the contents of every source file of the package (``root``: clutchlab's own folder) that ``path``
    imports, directly or through others (not of ``path`` itself): it changes when a module whose names the file's
    compiled functions read changes.  "" for a file outside the package.

    numba keys a cached function by its own source file alone, so a compiled function that reads another module's
    constant (an index or a count from a component's declaration: the EMTC's number of switching functions, which
    the driveline's coupled network lays its buffers out by) or calls another file's compiled function kept the
    code compiled with the old value after that module changed, in an editable install after a pull: a worker
    crashed on such a stale kernel until the cache was cleared (the forty-second session).  The package's graph is
    read once per process (about 170 files), when numba first asks for a stamp."""
    root = Path(root).resolve() if root is not None else Path(__file__).resolve().parent
    try:
        name = Path(path).resolve().relative_to(root).as_posix()
    except ValueError:
        return ""
    digests, imports = _package_graph(root)
    if name not in digests:
        return ""
    seen, todo = set(), [name]
    while todo:
        for dep in imports.get(todo.pop(), ()):
            if dep not in seen and dep != name:
                seen.add(dep)
                todo.append(dep)
    digest = hashlib.sha1()
    for dep in sorted(seen):
        digest.update(f"{dep}|{digests[dep]}\n".encode())
    return digest.hexdigest()


_GUARDED_ROOTS: list = []


def guard_cross_module_constants(root=None) -> None:
    """Key numba's cache of every compiled function in a clutchlab file by the contents of the package's files it
    imports too (:func:`dependency_stamp`), so that a change of one module renews the cached kernels of every file
    that reads it (idempotent; compiles nothing; files outside the package keep numba's own stamp).  ``root``:
    another package's folder to guard the same way (a test's)."""
    from numba.core import caching

    root = Path(root).resolve() if root is not None else Path(__file__).resolve().parent
    if root not in _GUARDED_ROOTS:
        _GUARDED_ROOTS.append(root)
    stamp = caching._SourceFileBackedLocatorMixin.get_source_stamp
    if getattr(stamp, "_clutchlab_guard", False):
        return

    def get_source_stamp(self):
        own = stamp(self)
        for folder in _GUARDED_ROOTS:
            deps = dependency_stamp(self._py_file, folder)
            if deps:
                return (own, deps)
        return own

    get_source_stamp._clutchlab_guard = True
    get_source_stamp.__doc__ = stamp.__doc__
    caching._SourceFileBackedLocatorMixin.get_source_stamp = get_source_stamp


def _private_folder(path: Path) -> str:
    """Make ``path`` (in the shared temporary folder) this user's private folder: created with mode 0700, or,
    if it exists, a real folder (not a link) owned by this user, then set to 0700.  Returns "" if it is, else
    why it is refused."""
    try:
        path.mkdir(mode=0o700)
    except FileExistsError:
        pass
    st = os.lstat(path)
    if stat.S_ISLNK(st.st_mode) or not stat.S_ISDIR(st.st_mode):
        return f"{path} is not a folder of its own (a link or a file): refused"
    if hasattr(os, "getuid") and st.st_uid != os.getuid():
        return f"{path} belongs to another user (uid {st.st_uid}): refused"
    if stat.S_IMODE(st.st_mode) != 0o700:
        os.chmod(path, 0o700)
    return ""
