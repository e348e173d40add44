"""Write a report folder: PNG figures, CSV tables and a self-contained ``index.html``.

The HTML page embeds every figure as a base64 PNG so it can be read offline
and mailed as one file; the PNGs and CSVs are written beside it for reuse in
other documents.  Synthetic data is marked as such in every section that uses it.
"""

from __future__ import annotations

import base64
import datetime as _dt
import html
import io
import os
import secrets
import shutil
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

__all__ = ["Figure", "Table", "Text", "Section", "write_report", "check_report_folder"]

#: the file that marks a folder as a report clutchlab wrote (only such a folder is replaced, with overwrite)
MARKER = ".clutchlab-report"   # (clutchlab.io.files.REPORT_MARKER: a temporary folder holding it is clutchlab's)
#: what a report folder holds (folders written before the marker hold these only)
_REPORT_ENTRIES = {"index.html", "figures", "tables", MARKER}
_MARKER_TEXT = "a report written by clutchlab: `--force` may replace this folder\n"


def check_report_folder(outdir, overwrite: bool = False) -> Path:
    """Check, before any work, that the report folder ``outdir`` can be written: new, or replaceable.

    An existing folder is replaced only with ``overwrite`` and only if clutchlab wrote it (it holds the
    :data:`MARKER` file, or only a report's ``index.html``, ``figures`` and ``tables``): ``--force`` never
    deletes a folder of the user's, the folder a command runs in or one that holds it.

    Raises
    ------
    OutputExistsError
        ``outdir`` exists and ``overwrite`` is false.
    ParameterError
        ``outdir`` is a file, the working folder or one holding it, or a folder clutchlab did not write.
    """
    from ..errors import ParameterError
    from ..io.files import OutputExistsError

    outdir = Path(outdir)
    if not (outdir.exists() or outdir.is_symlink()):
        return outdir
    if not overwrite:
        raise OutputExistsError(outdir, "folder")
    where = outdir.resolve()
    if outdir.is_symlink() or not outdir.is_dir():
        raise ParameterError(f"{outdir}: is {'a link' if outdir.is_symlink() else 'a file'}, not a report folder: "
                             "not replaced (even with --force); give a folder name")
    cwd = Path.cwd().resolve()
    if where == cwd or where in cwd.parents:
        raise ParameterError(f"{outdir}: is the folder this command runs in{'' if where == cwd else ' or holds it'}: "
                             "not replaced (even with --force); give a new folder, e.g. -o report")
    entries = sorted(e.name for e in where.iterdir())
    foreign = [e for e in entries if e not in _REPORT_ENTRIES]
    if MARKER not in entries and foreign:
        raise ParameterError(f"{outdir}: holds {foreign[0]!r}, which clutchlab did not write: not replaced (even "
                             "with --force); give a new folder or empty this one")
    return outdir


@dataclass
class Figure:
    """A matplotlib ``figure`` with a file stem ``name`` and a ``caption``."""

    name: str
    figure: object
    caption: str = ""


@dataclass
class Table:
    """A table: DataFrame ``frame``, file stem ``name``, ``caption`` and the ``float_format`` of its cells."""

    name: str
    frame: pd.DataFrame
    caption: str = ""
    float_format: str = "{:.4g}"


@dataclass
class Text:
    """A paragraph of plain text (escaped in the HTML)."""

    text: str


@dataclass
class Section:
    """One chapter of the report, usually one subsystem: a ``title``, its ``items``
    (Figure, Table, Text), the data ``provenance`` and the ``parameters`` used.

    ``provenance`` says where the data come from; sections built on data from
    clutchlab's virtual rigs must say "synthetic" there.  ``synthetic=True``
    adds a "SYNTHETIC DATA" badge to the section heading; the default
    (``None``) adds it when the provenance mentions "synthetic".
    """

    title: str
    items: list = field(default_factory=list)
    provenance: str = ""
    parameters: dict[str, str] = field(default_factory=dict)
    synthetic: bool | None = None


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}
h1{border-bottom:2px solid #335}h2{margin-top:2em;border-bottom:1px solid #ccd}
.prov{background:#fff6d6;border-left:4px solid #e0a800;padding:.5em 1em;margin:1em 0}
figure{margin:1.5em 0}figure img{max-width:100%;border:1px solid #ddd}
figcaption{font-size:.9em;color:#444}
table{border-collapse:collapse;margin:1em 0;font-size:.9em}
th,td{border:1px solid #ccc;padding:.25em .6em;text-align:right}th{background:#eef}
caption{caption-side:top;text-align:left;font-weight:600;padding:.3em 0}
.meta{color:#666;font-size:.85em}
.synthetic{background:#b00020;color:#fff;font-size:.6em;padding:.15em .5em;border-radius:3px;vertical-align:middle;margin-left:.6em}
"""


#: resolution of the embedded figures [dots per inch]: print quality at the figure's size
DPI = 150


def _figure_png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, bbox_inches="tight")
    return buf.getvalue()


def _table_html(tab: Table) -> str:
    frame = tab.frame
    fmt = {c: (lambda v, f=tab.float_format: f.format(v)) for c in frame.columns if pd.api.types.is_float_dtype(frame[c])}
    body = frame.to_html(index=False, formatters=fmt, border=0, escape=True)
    cap = f"<p><b>{html.escape(tab.caption)}</b></p>" if tab.caption else ""
    return cap + body


def _unique(used: set, folder: str, name: str) -> str:
    stem, k = name, 1
    while (folder, stem) in used:
        k += 1
        stem = f"{name}_{k}"
    used.add((folder, stem))
    return stem


def write_report(sections: list[Section], outdir, *, title: str = "clutchlab report", overwrite: bool = False,
                 progress=None) -> Path:
    """Write ``index.html`` with embedded figures plus PNG/CSV files into ``outdir``.

    ``sections`` are the report's chapters, ``title`` its heading; ``progress``
    (a callable taking a message) is told about every figure rendered.
    The page is self-contained: figures are embedded as base64 PNG ``data:``
    URIs (:data:`DPI` dots per inch) and the style sheet is inline, so it
    loads nothing from elsewhere.  Every figure of a synthetic section is
    stamped "synthetic data" (:func:`clutchlab.plotting.mark_synthetic`), so
    it stays marked when copied out of the page.

    The folder is assembled in a hidden temporary sibling (``.NAME.PID.XXXXXXXX.tmp``, holding
    :data:`MARKER` from the start) and moved into place, so an interrupted run never leaves half a
    report; the temporary folders of a run that was killed are removed by the next report written to
    ``outdir`` (:func:`clutchlab.io.files.remove_stale_temporaries`).  An existing ``outdir`` is
    replaced only with ``overwrite=True``, and only if clutchlab wrote it
    (:func:`check_report_folder`).

    Returns
    -------
    pathlib.Path
        Path of ``index.html``.
    """
    import matplotlib.pyplot as plt

    from .. import __version__

    from ..io.files import temporary_folder

    outdir = check_report_folder(outdir, overwrite)
    target = outdir.resolve()   # (a name to build the temporary and backup names from, also for "-o ..")
    # a hidden .NAME.PID.XXXXXXXX.tmp holding the marker from the start: if this process is killed, the next
    # report written to the same folder removes it (and those of earlier killed runs now)
    tmp = temporary_folder(target, MARKER, _MARKER_TEXT)
    try:
        (tmp / "figures").mkdir()
        (tmp / "tables").mkdir()
        parts = [
            "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
            f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>",
            f"<h1>{html.escape(title)}</h1>",
            f"<p class='meta'>clutchlab {html.escape(__version__)} &middot; generated "
            f"{_dt.datetime.now().isoformat(timespec='seconds')}</p>",
            "<nav><ul>" + "".join(f"<li><a href='#s{i}'>{html.escape(s.title)}</a></li>" for i, s in enumerate(sections)) + "</ul></nav>",
        ]
        used: set = set()  # file names given out: a repeated name gets _2, _3, ... instead of overwriting
        n_figures = sum(isinstance(item, Figure) for sec in sections for item in sec.items)
        done = 0
        for i, sec in enumerate(sections):
            synthetic = sec.synthetic if sec.synthetic is not None else "synthetic" in sec.provenance.lower()
            badge = "<span class='synthetic'>SYNTHETIC DATA</span>" if synthetic else ""
            parts.append(f"<h2 id='s{i}'>{html.escape(sec.title)}{badge}</h2>")
            if sec.provenance:
                parts.append(f"<div class='prov'><b>Data provenance:</b> {html.escape(sec.provenance)}</div>")
            for item in sec.items:
                if isinstance(item, Figure):
                    done += 1
                    if progress is not None:
                        progress(f"rendering figure {done}/{n_figures}: {item.name}")
                    if synthetic:
                        from ..plotting import mark_synthetic

                        mark_synthetic(item.figure)
                    png = _figure_png(item.figure)
                    plt.close(item.figure)
                    (tmp / "figures" / f"{_unique(used, 'figures', item.name)}.png").write_bytes(png)
                    b64 = base64.b64encode(png).decode("ascii")
                    parts.append(
                        f"<figure><img alt='{html.escape(item.name)}' src='data:image/png;base64,{b64}'>"
                        f"<figcaption>{html.escape(item.caption)}</figcaption></figure>"
                    )
                elif isinstance(item, Table):
                    item.frame.to_csv(tmp / "tables" / f"{_unique(used, 'tables', item.name)}.csv", index=False)
                    parts.append(_table_html(item))
                elif isinstance(item, Text):
                    parts.append(f"<p>{html.escape(item.text)}</p>")
                else:
                    raise TypeError(f"unsupported report item {type(item).__name__}")
            if sec.parameters:
                rows = "".join(
                    f"<tr><td style='text-align:left'>{html.escape(k)}</td><td style='text-align:left'>{html.escape(v)}</td></tr>"
                    for k, v in sec.parameters.items()
                )
                parts.append(f"<details><summary>Parameters used</summary><table><tr><th>name</th><th>value</th></tr>{rows}</table></details>")
        parts.append("</body></html>")
        (tmp / "index.html").write_text("\n".join(parts), encoding="utf-8")
        if target.exists():
            check_report_folder(outdir, overwrite)   # (again: it may have changed during the rendering)
            # the old report moves aside under a temporary name of this process, marked, so that a kill before
            # it is removed leaves nothing a later run does not remove
            if not (target / MARKER).exists():
                (target / MARKER).write_text(_MARKER_TEXT, encoding="utf-8")
            backup = target.with_name(f".{target.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp")
            os.replace(target, backup)
            os.replace(tmp, target)
            shutil.rmtree(backup)
        else:
            os.replace(tmp, target)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return outdir / "index.html"
