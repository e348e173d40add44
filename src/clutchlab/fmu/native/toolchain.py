"""Compilers and linking of a native FMU's shared library (:mod:`clutchlab.fmu.native`).

The exporting machine needs a C and a C++ compiler for each platform it builds: ``cc``/``c++`` (gcc or clang)
for linux64 on a Linux x86-64 machine, ``x86_64-w64-mingw32-gcc``/``-g++`` (Debian's gcc-mingw-w64-x86-64) for
win64.  numba's runtime, ``numba/core/runtime/nrt.cpp`` as shipped in numba's wheel, is compiled once per
compiler and numba version and cached in clutchlab's kernel folder.  The importing machine needs nothing:
the library depends only on the C library and libm (libstdc++ and libgcc linked statically on win64).
"""

from __future__ import annotations

import hashlib
import os
import platform as _platform
import shutil
import subprocess
import sys
from pathlib import Path

from .image import NativeExportError

__all__ = ["Toolchain", "toolchain", "available_platforms", "library_name"]

#: the FMI 2.0 headers (shipped with clutchlab, the Modelica Association's, BSD-2-clause)
HEADERS = Path(__file__).resolve().parent.parent / "shim"
RUNTIME = Path(__file__).resolve().parent / "fmi2_native.c"


class Toolchain:
    """The compilers of one FMI platform."""

    def __init__(self, platform: str, cc: str, cxx: str):
        self.platform = platform
        self.cc = cc
        self.cxx = cxx

    def _run(self, cmd, what: str) -> None:
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        except (OSError, subprocess.SubprocessError) as exc:
            raise NativeExportError(f"{what}: {cmd[0]} failed to run ({exc})") from None
        if proc.returncode != 0:
            lines = [ln for ln in proc.stderr.strip().splitlines() if ln.strip()] or ["no message"]
            raise NativeExportError(f"{what}: {Path(cmd[0]).name} failed (return code {proc.returncode}): "
                                    f"{lines[-1][:300]}")

    def runtime_object(self) -> Path:
        """numba's runtime compiled for this platform (cached)."""
        import numba

        from ...numerics.entry import kernel_dir

        source = Path(numba.__file__).resolve().parent / "core" / "runtime" / "nrt.cpp"
        if not source.is_file():
            raise NativeExportError(f"numba's runtime source is missing ({source})")
        key = hashlib.sha256(b"\n".join([numba.__version__.encode(), self.cxx.encode(), self.platform.encode(),
                                         source.read_bytes()])).hexdigest()[:24]
        out = kernel_dir() / "native" / f"nrt-{self.platform}-{key}.o"
        if out.is_file():
            return out
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = out.with_name(f".{out.name}.{os.getpid()}")
        root = source.parent.parent.parent.parent   # (site-packages: nrt.cpp includes "numba/_numba_common.h")
        self._run([self.cxx, "-O2", "-fPIC", "-fvisibility=hidden", "-fno-exceptions", "-fno-rtti",
                   f"-I{root}", f"-I{source.parent}", "-c", str(source), "-o", str(tmp)], "numba's runtime")
        os.replace(tmp, out)
        return out

    def link(self, workdir: Path, objects: list, model_header: Path, ident: str, benchmark: bool = False) -> Path:
        """The FMU's shared library from the model's object code and the FMI layer with ``model.h``
        (``benchmark``: with ``cl_benchmark_session`` exported, for ``benchmarks/bench_native_fmu.py`` only)."""
        ext = ".dll" if self.platform == "win64" else ".so"
        layer = workdir / f"fmi2_native_{self.platform}.o"
        self._run([self.cc, "-O2", "-fPIC", "-fvisibility=hidden", "-std=c99", "-D_POSIX_C_SOURCE=200809L",
                   *(["-DCL_BENCHMARK"] if benchmark else []),
                   f"-I{HEADERS}", f"-I{model_header.parent}", "-c", str(RUNTIME), "-o", str(layer)],
                  "the FMI layer")
        out = workdir / f"{ident}{ext}"
        cmd = [self.cc, "-shared", "-o", str(out), str(layer), *map(str, objects), self.runtime_object()]
        if self.platform == "win64":
            cmd += ["-static-libgcc", "-Wl,-Bstatic", "-lstdc++", "-lpthread", "-Wl,-Bdynamic", "-lm"]
        else:
            script = workdir / "exports.map"
            script.write_text("{ global: fmi2*; fmi3*;%s local: *; };\n" % (" cl_benchmark_*;" if benchmark else ""))
            cmd += [f"-Wl,--version-script={script}", "-Wl,-z,defs", "-Wl,-z,noexecstack", "-lm"]
        self._run([str(c) for c in cmd], "linking the FMU's library")
        return out


#: the binaries' folder of a platform in an FMI 3.0 FMU (FMI 3.0, 2.5.1.4: architecture-os)
FMI3_PLATFORMS = {"linux64": "x86_64-linux", "win64": "x86_64-windows"}


def library_name(platform: str, ident: str, fmi_version: str = "2.0") -> str:
    """Path of the library inside the FMU (``binaries/linux64/<ident>.so``; FMI 3.0:
    ``binaries/x86_64-linux/<ident>.so``)."""
    folder = FMI3_PLATFORMS[platform] if fmi_version.startswith("3") else platform
    return f"binaries/{folder}/{ident}{'.dll' if platform == 'win64' else '.so'}"


def toolchain(platform: str) -> Toolchain:
    """The compilers for ``platform``; raises :class:`NativeExportError` naming what is missing."""
    if platform == "linux64":
        if not (sys.platform.startswith("linux") and _platform.machine() in ("x86_64", "AMD64")):
            raise NativeExportError(f"linux64 binaries are built on Linux x86-64 (this is {sys.platform} "
                                    f"{_platform.machine()})")
        cc, cxx = shutil.which("cc") or shutil.which("gcc"), shutil.which("c++") or shutil.which("g++")
        if not (cc and cxx):
            raise NativeExportError("a native FMU needs a C and a C++ compiler on the exporting machine "
                                    "('cc' and 'c++'; Debian: apt install build-essential), or export with "
                                    "--backend python (the importing machine then needs Python and clutchlab)")
        return Toolchain(platform, cc, cxx)
    if platform == "win64":
        cc, cxx = shutil.which("x86_64-w64-mingw32-gcc"), shutil.which("x86_64-w64-mingw32-g++")
        if not (cc and cxx):
            raise NativeExportError("win64 binaries need the MinGW-w64 cross compilers "
                                    "(x86_64-w64-mingw32-gcc and -g++; Debian: apt install gcc-mingw-w64-x86-64 "
                                    "g++-mingw-w64-x86-64)")
        return Toolchain(platform, cc, cxx)
    raise NativeExportError(f"platform {platform!r}: native FMUs are built for linux64 and win64")


def available_platforms() -> list:
    """The platforms this machine can build binaries for."""
    out = []
    for p in ("linux64", "win64"):
        try:
            toolchain(p)
        except NativeExportError:
            continue
        out.append(p)
    return out
