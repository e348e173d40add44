"""CSV dialects: read text tables the way rig software writes them, and say what was detected.

A press rig running German software exports ISO-8859-1 text with a title
line, ``;`` separators, decimal commas and a unit row under the column
names::

    Prüfstand 3 – Kennlinie Tellerfeder
    Zeit;Weg;Kraft
    s;mm;kN
    0,000;0,00;0,012
    ...

Other loggers write UTF-8 with a byte-order mark, UTF-16 (Excel's "Unicode
text"), tabs, or units in brackets after the names (``Zeit [s]``).
:func:`read_csv` reads all of these.  It detects, in this order,

1. the **encoding**: a byte-order mark (UTF-8, UTF-16 LE/BE), NUL bytes in
   every other position (UTF-16 without a mark), strict UTF-8, else
   Windows-1252 (which agrees with ISO-8859-1 on every printable character a
   rig writes: ``° µ ä ö ü ß``) and ISO-8859-1 for the bytes Windows-1252
   leaves undefined;
2. the **separator** (``,`` ``;`` tab ``|``) and the **decimal mark**
   (``.`` or ``,``, never the separator): of every pair, the one under which
   the rows below the header split into the same number of fields, the
   largest share of them numbers, with a header row of that many fields;
   a thousands separator ``.`` is recognised under a decimal comma
   (``1.234,5``);
3. the **rows**: the data start at the first row of that shape holding a
   number; of the (at most two) rows of that many fields just above, one is the
   column names and one, if every entry is a unit (``s``, ``[mm]``, ``(kN)``,
   ``°C``, ``-``), the units -- above or below the names; what lies further
   up is a title, kept as a comment.  Units in brackets after a name
   (``Kraft [kN]``, ``Weg (mm)``) are read as that column's unit, and the
   column is called by the name before them (``Kraft``).

Lines starting with ``#`` are comments wherever they are (clutchlab's own
files carry ``# units: a=s, b=N*m`` and ``# synthetic: ...`` there).  What
was detected is a :class:`CsvDialect`; :meth:`CsvDialect.describe` says it in
one line, and every field can be set instead of detected (the ``[csv]`` table
of a channel map, ``clutchlab convert --encoding/--separator/--decimal/
--header-row/--units-row``, ``read_measurement(csv=...)``).
"""

from __future__ import annotations

import csv as _csv
import io
import re
from collections import Counter
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import Mapping

import pandas as pd

from ..errors import DataError, ParameterError

__all__ = ["CsvDialect", "CsvTable", "SEPARATORS", "DECIMALS", "read_csv"]

#: separators tried, in order of preference when two fit equally well
SEPARATORS = (",", ";", "\t", "|")
#: decimal marks tried
DECIMALS = (".", ",")
#: how separators are spelled in messages, TOML and on the command line
_SEP_NAMES = {",": "','", ";": "';'", "\t": "tab", "|": "'|'"}
_SEP_WORDS = {"tab": "\t", "\\t": "\t", "comma": ",", "semicolon": ";", "pipe": "|"}
#: lines looked at to detect the dialect (title and header lie within them)
_SAMPLE_LINES = 400
_ENCODING_NAMES = {"utf-8": "UTF-8", "utf-8-sig": "UTF-8 with byte-order mark", "utf-16": "UTF-16 with byte-order mark",
                   "utf-16-le": "UTF-16 LE", "utf-16-be": "UTF-16 BE", "cp1252": "Windows-1252 (ISO-8859-1)",
                   "latin-1": "ISO-8859-1", "iso8859-1": "ISO-8859-1"}
_NUMBER = {
    ".": re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$"),
    ",": re.compile(r"^[+-]?(\d+,?\d*|,\d+)([eE][+-]?\d+)?$"),
}
_THOUSANDS = re.compile(r"^[+-]?\d{1,3}(\.\d{3})+(,\d*)?([eE][+-]?\d+)?$")   # 1.234,5 under a decimal comma
_SPECIAL = {"nan", "+nan", "-nan", "inf", "+inf", "-inf", "infinity", "-infinity", "+infinity"}
_BRACKET_UNIT = re.compile(r"^(?P<name>.*?)\s*(\[(?P<u1>[^\[\]]*)\]|\((?P<u2>[^()]*)\))\s*$")


@dataclass(frozen=True)
class CsvDialect:
    """How a text table is written; ``None`` fields are detected.

    Parameters
    ----------
    encoding : str, optional
        Python codec name (``"utf-8"``, ``"utf-8-sig"``, ``"utf-16"``,
        ``"cp1252"``, ``"latin-1"``, ``"iso-8859-1"``, ...).
    separator : str, optional
        Field separator: ``","``, ``";"``, ``"\\t"`` (or ``"tab"``), ``"|"``.
    decimal : str, optional
        Decimal mark: ``"."`` or ``","``.
    header_row : int, optional
        Line of the file (counted from 1, as an editor shows it) holding the
        column names; ``0`` for a file without names (the columns are then
        called ``column_1``, ``column_2``, ...).
    units_row : int, optional
        Line holding the units of the columns; ``0`` for none.
    thousands : str, optional
        Thousands separator (``"."`` under a decimal comma), or ``""`` for none.
    """

    encoding: str | None = None
    separator: str | None = None
    decimal: str | None = None
    header_row: int | None = None
    units_row: int | None = None
    thousands: str | None = None

    def __post_init__(self):
        if self.encoding is not None:
            if not isinstance(self.encoding, str):
                raise ParameterError(f"csv encoding = {self.encoding!r} must be a string such as 'utf-8' or 'cp1252'")
            import codecs

            try:
                codecs.lookup(self.encoding)
            except LookupError:
                raise ParameterError(f"csv encoding = {self.encoding!r}: unknown encoding (e.g. 'utf-8', "
                                     "'utf-8-sig', 'utf-16', 'cp1252', 'iso-8859-1')") from None
        if self.separator is not None:
            sep = _SEP_WORDS.get(self.separator, self.separator) if isinstance(self.separator, str) else None
            if sep not in SEPARATORS:
                raise ParameterError(f"csv separator = {self.separator!r}: expected one of ',', ';', 'tab', '|'")
            object.__setattr__(self, "separator", sep)
        if self.decimal is not None and self.decimal not in DECIMALS:
            raise ParameterError(f"csv decimal = {self.decimal!r}: expected '.' or ','")
        if self.thousands is not None and self.thousands not in ("", ".", ",", " ", "'"):
            raise ParameterError(f"csv thousands = {self.thousands!r}: expected '', '.', ',', ' ' or \"'\"")
        if self.separator is not None and self.separator == self.decimal:
            raise ParameterError(f"csv separator and decimal are both {self.decimal!r}")
        for key in ("header_row", "units_row"):
            value = getattr(self, key)
            if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value < 0):
                raise ParameterError(f"csv {key} = {value!r} must be a line number (from 1), or 0 for none")
        if self.header_row and self.units_row and self.header_row == self.units_row:
            raise ParameterError(f"csv header_row and units_row are both line {self.header_row}")

    @classmethod
    def coerce(cls, value, where: str = "csv") -> "CsvDialect":
        """Accept ``None``, a :class:`CsvDialect` or a mapping of its fields (a TOML ``[csv]`` table)."""
        if value is None:
            return cls()
        if isinstance(value, CsvDialect):
            return value
        if isinstance(value, Mapping):
            known = {f.name for f in fields(cls)}
            unknown = [k for k in value if k not in known]
            if unknown:
                raise ParameterError(f"{where}: unknown key {unknown[0]!r} (expected {', '.join(sorted(known))})")
            return cls(**dict(value))
        raise ParameterError(f"{where} = {value!r}: expected a CsvDialect or a table of its fields")

    def merged(self, other: "CsvDialect | None") -> "CsvDialect":
        """This dialect with the fields ``other`` sets replaced by ``other``'s."""
        if other is None:
            return self
        return replace(self, **{f.name: getattr(other, f.name) for f in fields(other)
                                if getattr(other, f.name) is not None})

    def to_dict(self) -> dict:
        """The fields that are set, as a ``[csv]`` table would hold them."""
        out = {f.name: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) is not None}
        if out.get("separator") == "\t":
            out["separator"] = "tab"
        return out

    def describe(self) -> str:
        """One line: ``ISO-8859-1, ';' separator, decimal comma, names in line 2, units in line 3``."""
        import codecs

        codec = codecs.lookup(self.encoding or "utf-8").name
        parts = [_ENCODING_NAMES.get(codec, self.encoding)]
        parts.append(f"{_SEP_NAMES.get(self.separator or ',', repr(self.separator))} separator")
        parts.append("decimal comma" if self.decimal == "," else "decimal point")
        if self.thousands:
            parts.append(f"thousands separator {self.thousands!r}")
        parts.append(f"names in line {self.header_row}" if self.header_row else "no names (column_1, ...)")
        if self.units_row:
            parts.append(f"units in line {self.units_row}")
        return ", ".join(parts)


@dataclass(frozen=True)
class CsvTable:
    """What :func:`read_csv` read.

    Parameters
    ----------
    frame : pandas.DataFrame
        The columns under their names as written (values as parsed: numbers
        as float or int, text as str).
    units : dict of str to str
        Column -> unit the file states (unit row, ``Name [unit]``, or a
        ``# units:`` comment line), as written.
    comments : tuple of str
        ``#`` comment lines and title lines above the header, in order.
    dialect : CsvDialect
        The dialect read (every field set).
    first_data_line : int
        Line of the file (from 1) holding the first data row.
    """

    frame: pd.DataFrame
    units: dict
    comments: tuple
    dialect: CsvDialect
    first_data_line: int


# ---------------------------------------------------------------- encoding

def _mostly_ascii(text: str) -> bool:
    """True for the text of a measurement table (digits, separators, names), not bytes decoded as UTF-16."""
    head = text[:4096]
    return sum(1 for ch in head if ch < "\x7f") >= 0.5 * len(head)


def _decode(raw: bytes, encoding: str | None, label: str) -> tuple[str, str]:
    """(text, encoding) of the file's bytes."""
    if encoding is not None:
        try:
            text = raw.decode(encoding)
        except UnicodeDecodeError as exc:
            raise DataError(f"{label}: cannot read as CSV (not {encoding} text: byte {exc.start} is "
                            f"{raw[exc.start:exc.start + 1]!r})") from None
        import codecs

        if codecs.lookup(encoding).name.startswith("utf-16") and not _mostly_ascii(text):
            raise DataError(f"{label}: cannot read as CSV (not {encoding} text: mostly characters no table holds)")
        return text.lstrip("\ufeff"), encoding
    boms = ((b"\xef\xbb\xbf", "utf-8-sig"), (b"\xff\xfe", "utf-16"), (b"\xfe\xff", "utf-16"))
    for bom, enc in boms:
        if raw.startswith(bom):
            try:
                text = raw.decode(enc).lstrip("\ufeff")
                if enc == "utf-16" and not _mostly_ascii(text):
                    raise UnicodeDecodeError(enc, raw, 0, 2, "not text")
                return text, enc
            except UnicodeDecodeError:
                raise DataError(f"{label}: cannot read as CSV (starts with a {_ENCODING_NAMES[enc].split(' with')[0]} "
                                "byte-order mark but is not text in that encoding)") from None
    head = raw[:4096]
    if head.count(b"\x00") > len(head) // 4:
        # UTF-16 without byte-order mark: ASCII characters have their NUL byte on one side
        odd, even = head[1::2].count(b"\x00"), head[0::2].count(b"\x00")
        enc = "utf-16-le" if odd > even else "utf-16-be"
        try:
            text = raw.decode(enc)
            if not _mostly_ascii(text):
                raise UnicodeDecodeError(enc, raw, 0, 2, "not text")
            return text, enc
        except UnicodeDecodeError:
            raise DataError(f"{label}: cannot read as CSV (binary data: NUL bytes, and not UTF-16 text)") from None
    if b"\x00" in head:
        raise DataError(f"{label}: cannot read as CSV (binary data: NUL bytes in a text file)")
    try:
        return raw.decode("utf-8"), "utf-8"
    except UnicodeDecodeError:
        pass
    try:
        return raw.decode("cp1252"), "cp1252"
    except UnicodeDecodeError:
        return raw.decode("latin-1"), "latin-1"


# ---------------------------------------------------------------- fields

def _split(line: str, sep: str) -> list[str]:
    if '"' not in line:
        return [f.strip() for f in line.split(sep)]
    return [f.strip() for f in next(_csv.reader([line], delimiter=sep, quotechar='"'))]


def _is_number(field: str, decimal: str) -> bool:
    if _NUMBER[decimal].match(field):
        return True
    if decimal == "," and _THOUSANDS.match(field):
        return True
    return field.lower() in _SPECIAL


def _unit_of(field: str) -> str | None:
    """The unit an entry of a unit row states (brackets stripped), or None if it is not a unit."""
    text = field.strip()
    if len(text) >= 2 and text[0] + text[-1] in ("[]", "()", "{}"):
        text = text[1:-1].strip()
    if not text:
        return ""
    if _NUMBER["."].match(text) or _NUMBER[","].match(text):
        return None  # a number is data, not a unit
    from ..units import affine_conversion

    try:
        affine_conversion(text, text)
    except Exception:  # pint's tokenizer raises assorted errors: whatever it cannot read is no unit
        return None
    return text


def _bracketed(cells: list[str]) -> int:
    return sum(1 for c in cells if len(c) >= 2 and c[0] + c[-1] in ("[]", "()", "{}"))


def _units_row(cells: list[str]) -> list[str] | None:
    units = [_unit_of(c) for c in cells]
    if any(u is None for u in units) or not any(units):
        return None
    return units


@dataclass
class _Candidate:
    separator: str
    decimal: str
    width: int            # fields per data row
    start: int            # index (in the sample) of the first data row
    rows: int             # data rows of that width
    coverage: float       # share of the lines from the first data row on that are data rows
    numeric: float        # share of the non-empty fields of data rows that are numbers
    header_ok: bool       # the line above the data has as many fields (or there is none)
    thousands: bool

    def score(self):
        return (self.coverage >= 0.9, self.header_ok, round(self.numeric, 2), self.width, self.rows,
                self.decimal == ".", -SEPARATORS.index(self.separator))


def _candidate(lines: list[tuple[int, str]], sep: str, dec: str) -> _Candidate | None:
    split = [_split(text, sep) for _, text in lines]
    numeric_rows = [(i, cells) for i, cells in enumerate(split)
                    if any(c and _is_number(c, dec) for c in cells)]
    if not numeric_rows:
        return None
    width = Counter(len(cells) for _, cells in numeric_rows).most_common(1)[0][0]
    data = [(i, cells) for i, cells in numeric_rows if len(cells) == width]
    # which columns hold numbers in most rows; a title of the same width ("Versuch;7;Prüfer") does not fit it
    flags = [tuple(_is_number(c, dec) if c else None for c in cells) for _, cells in data]
    full = [f for f in flags if None not in f] or [tuple(bool(v) for v in f) for f in flags]
    pattern = Counter(full).most_common(1)[0][0]
    data = [row for row, f in zip(data, flags) if all(v is None or v == p for v, p in zip(f, pattern))]
    start = data[0][0]
    after = len(split) - start
    nonempty = sum(1 for _, cells in data for c in cells if c)
    numbers = sum(1 for _, cells in data for c in cells if c and _is_number(c, dec))
    thousands = dec == "," and any(_THOUSANDS.match(c) and "." in c for _, cells in data for c in cells if c)
    header_ok = start == 0 or len(split[start - 1]) == width
    return _Candidate(sep, dec, width, start, len(data), len(data) / max(after, 1), numbers / max(nonempty, 1),
                      header_ok, thousands)


def _best_reading(lines: list[tuple[int, str]], given: CsvDialect, label: str) -> _Candidate:
    """The best (separator, decimal) for the sample ``lines`` ((line number, text), comments removed)."""
    seps = [given.separator] if given.separator else list(SEPARATORS)
    decs = [given.decimal] if given.decimal else list(DECIMALS)
    found = []
    for sep in seps:
        for dec in decs:
            if sep == dec:
                continue
            cand = _candidate(lines, sep, dec)
            if cand is not None:
                found.append(cand)
    if not found:
        what = "; ".join(f"{k} {v!r}" for k, v in given.to_dict().items() if k in ("separator", "decimal"))
        raise DataError(f"{label}: cannot read as CSV (no rows of numbers found{' with ' + what if what else ''}; "
                        "is it a table of measurements?)")
    return max(found, key=_Candidate.score)


# ---------------------------------------------------------------- reading

def _parse_units_comment(text: str, label: str) -> dict[str, str]:
    units = {}
    for item in text.strip()[len("units:"):].split(","):
        item = item.strip()
        if not item:
            continue
        if "=" not in item:
            raise DataError(f"{label}: cannot read the '# units:' line at {item!r} (expected name=unit)")
        k, v = item.split("=", 1)
        units[k.strip()] = v.strip()
    return units


def read_csv(path, label: str | None = None, dialect=None) -> CsvTable:
    """Read a text table in any dialect of :mod:`clutchlab.io.dialect`.

    Parameters
    ----------
    path : str or Path
        The file.
    label : str, optional
        How to call it in error messages (default: the path).
    dialect : CsvDialect or mapping, optional
        Fields to take as given instead of detecting them.

    Returns
    -------
    CsvTable
        Frame, units, comments and the dialect read.

    Raises
    ------
    DataError
        Not text in the encoding, no table of numbers, a name row or unit row
        of the wrong width, a column named twice, rows pandas cannot split --
        naming the file and the line.
    """
    from .._limits import check_allocation

    path = Path(path)
    label = label or str(path)
    given = CsvDialect.coerce(dialect)
    size = path.stat().st_size
    check_allocation(size, 3 / 8, f"{label}: CSV file of {size} bytes")  # text + parsed floats
    raw = path.read_bytes()
    text, encoding = _decode(raw, given.encoding, label)
    del raw
    comments, units = [], {}
    body: list[tuple[int, str]] = []   # (line number from 1, text) of the non-comment, non-blank lines
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            note = stripped[1:].strip()
            if note.lower().startswith("units:"):
                units.update(_parse_units_comment(note, label))
            elif note:
                comments.append(note)
            continue
        body.append((number, line.rstrip("\r\n")))
    del text
    if not body:
        raise DataError(f"{label}: cannot read as CSV (no lines besides comments)")
    sample = body[:_SAMPLE_LINES]
    if len(body) == 1 and not any(_is_number(c, d) for d in DECIMALS for sep in SEPARATORS
                                  for c in _split(body[0][1], sep)):
        # names only, no data rows: an empty table (its readers say "no samples")
        sep = given.separator or max(SEPARATORS, key=lambda c: len(_split(body[0][1], c)))
        names = _split(body[0][1], sep)
        read = CsvDialect(encoding=encoding, separator=sep, decimal=given.decimal or ".", header_row=body[0][0],
                          units_row=0, thousands="")
        return CsvTable(pd.DataFrame({n: pd.Series(dtype=float) for n in names}), units, tuple(comments), read,
                        body[0][0] + 1)
    best = _best_reading(sample, given, label)
    sep, dec = best.separator, best.decimal
    width = best.width
    by_line = {n: i for i, (n, _) in enumerate(body)}

    # ---- name and unit rows
    def row_at(line_no: int, what: str) -> list[str]:
        if line_no not in by_line:
            raise DataError(f"{label}: csv {what} = {line_no}: line {line_no} is blank, a comment or beyond the file")
        return _split(body[by_line[line_no]][1], sep)

    start = best.start
    header_line = units_line = 0
    if given.header_row is not None or given.units_row is not None:
        header_line, units_line = given.header_row, given.units_row
        if header_line and units_line is None:
            # names given, units not: the line below the names, if it has the width and is all units
            below = by_line[header_line] + 1 if header_line in by_line else len(body)
            cells = _split(body[below][1], sep) if below < len(body) else []
            units_line = body[below][0] if len(cells) == width and _units_row(cells) is not None else 0
        if units_line and header_line is None:
            # units given, names not: the line above the units, if it has the width and is not units
            above = by_line[units_line] - 1 if units_line in by_line else -1
            cells = _split(body[above][1], sep) if above >= 0 else []
            header_line = body[above][0] if len(cells) == width and _units_row(cells) is None else 0
        header_line, units_line = header_line or 0, units_line or 0
        last = max(header_line, units_line)
        if last:
            if last not in by_line:
                row_at(last, "header_row" if last == header_line else "units_row")
            start = by_line[last] + 1
            if start >= len(body):
                raise DataError(f"{label}: no data rows below line {last}")
    else:
        above = [i for i in range(max(start - 2, 0), start) if len(_split(body[i][1], sep)) == width]
        above = [i for i in above if i == start - 1 or (i == start - 2 and start - 1 in above)]
        if len(above) == 2:
            upper, lower = (_split(body[i][1], sep) for i in above)
            up, low = _units_row(upper) is not None, _units_row(lower) is not None
            if up and low:
                # both read as units ("t;F" is tonne and farad): the bracketed row holds the units, else the lower
                up = _bracketed(upper) > _bracketed(lower)
                low = not up
            if low:
                header_line, units_line = body[above[0]][0], body[above[1]][0]
            elif up:
                units_line, header_line = body[above[0]][0], body[above[1]][0]
            else:
                header_line = body[above[1]][0]
        elif len(above) == 1:
            header_line = body[above[0]][0]
    for i in range(start):
        n, line = body[i]
        if n not in (header_line, units_line):
            comments.append(line.strip().strip(sep).strip())
    names = row_at(header_line, "header_row") if header_line else [f"column_{k + 1}" for k in range(width)]
    if len(names) != width:
        raise DataError(f"{label}: line {header_line} has {len(names)} names for {width} columns "
                        f"(separator {_SEP_NAMES[sep]})")
    row_units: list[str] = [""] * width
    if units_line:
        cells = row_at(units_line, "units_row")
        if len(cells) != width:
            raise DataError(f"{label}: the unit row (line {units_line}) has {len(cells)} entries for {width} columns")
        parsed = [_unit_of(c) for c in cells]
        bad = [c for c, u in zip(cells, parsed) if u is None]
        if bad:
            raise DataError(f"{label}: unknown unit {bad[0]!r} in the unit row (line {units_line})")
        row_units = parsed
    clean_names = []
    file_units: dict[str, str] = {}
    for name, unit in zip(names, row_units):
        m = _BRACKET_UNIT.match(name)
        if m is not None and m.group("name"):
            bracket = (m.group("u1") if m.group("u1") is not None else m.group("u2")).strip()
            if bracket and _unit_of(bracket):
                name, unit = m.group("name"), unit or _unit_of(bracket)   # "Kraft [kN]": Kraft, in kN
        clean_names.append(name)
        if unit:
            file_units[name] = unit
    seen = set()
    for name in clean_names:
        if name and name in seen:
            raise DataError(f"{label}: column {name!r} appears twice in the header: rename one")
        seen.add(name)
    file_units.update(units)   # an explicit '# units:' line wins

    # ---- the data, parsed by pandas
    thousands = given.thousands if given.thousands is not None else ("." if best.thousands else "")
    data = "\n".join(line for _, line in body[start:])
    try:
        frame = pd.read_csv(io.StringIO(data), sep=sep, decimal=dec, thousands=thousands or None, header=None,
                            names=[n if n else f"column_{k + 1}" for k, n in enumerate(clean_names)],
                            quotechar='"', skipinitialspace=True, index_col=False)
    except Exception as exc:  # pandas' parser errors
        text = " ".join(str(exc).split())
        m = re.search(r"line (\d+), saw (\d+)", text)
        if m:
            k = int(m.group(1)) - 1
            line_no = body[start + k][0] if start + k < len(body) else "?"
            raise DataError(f"{label}: line {line_no} has {m.group(2)} fields, expected {width} "
                            f"(separator {_SEP_NAMES[sep]})") from None
        raise DataError(f"{label}: cannot read as CSV ({text})") from None
    # a trailing separator leaves an unnamed, empty column: drop it
    for k, name in enumerate(clean_names):
        col = frame.columns[k]
        if not name and frame[col].isna().all():
            frame = frame.drop(columns=[col])
    # text columns come back with the spaces the separator left
    for col in frame.columns:
        if not pd.api.types.is_numeric_dtype(frame[col]):
            frame[col] = frame[col].map(lambda v: v.strip() if isinstance(v, str) else v)
    read = CsvDialect(encoding=encoding, separator=sep, decimal=dec, header_row=header_line, units_row=units_line,
                      thousands=thousands)
    return CsvTable(frame, file_units, tuple(comments), read, body[start][0])
