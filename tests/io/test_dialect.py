"""CSV dialects (#33): files written as rig software writes them are read, and what was detected is said.

Each dialect is written here from one record (the E-clutch virtual press rig, synthetic, fixed seed) and must
read back to the same SI values: the German press-rig export of the issue (ISO-8859-1, a title line, ';',
decimal commas, Zeit;Weg;Kraft in s/mm/kN), UTF-8 with a byte-order mark, UTF-16 with and without one,
Windows-1252, tab separators, units in brackets after the names or in a row above them.
"""

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings, strategies as st
from hypothesis_budget import examples

from clutchlab.cli import main
from clutchlab.errors import DataError, ParameterError
from clutchlab.io import ChannelMap, read_measurement, read_table
from clutchlab.io.dialect import CsvDialect, read_csv

MAP = {"time_s": "Zeit", "displacement_m": "Weg", "force_N": "Kraft"}


@pytest.fixture(scope="module")
def record():
    """A press-rig record in SI (time_s, displacement_m, force_N), from the virtual press rig."""
    from clutchlab.eclutch.pressrig import simulate_press_test

    frame = simulate_press_test(lambda x: 2e5 * x + 4e7 * x ** 2, 8e-3, friction_N=25.0, friction_rel=0.0,
                                force_noise_N=2.0, lvdt_noise_m=2e-6, seed=3)
    return frame[["time_s", "displacement_m", "force_N"]].iloc[::7].reset_index(drop=True)


def _german(frame, *, title=True, units=True, time=True, decimal=",", sep=";", unit_style="row") -> str:
    """The text a German rig program writes: values in s, mm, kN."""
    cols = [("Zeit", "s", frame["time_s"].to_numpy()), ("Weg", "mm", frame["displacement_m"].to_numpy() * 1e3),
            ("Kraft", "kN", frame["force_N"].to_numpy() * 1e-3)]
    if not time:
        cols = cols[1:]
    lines = ["Prüfstand 3 - Tellerfeder, 21.11.2026, 23 °C (synthetisch)"] if title else []
    if unit_style == "bracket":
        lines.append(sep.join(f"{n} [{u}]" for n, u, _ in cols))
    elif unit_style == "above":
        lines.append(sep.join(f"[{u}]" for _, u, _ in cols))
        lines.append(sep.join(n for n, _, _ in cols))
    else:
        lines.append(sep.join(n for n, _, _ in cols))
        if units:
            lines.append(sep.join(u for _, u, _ in cols))
    for k in range(len(frame)):
        lines.append(sep.join(f"{v[k]:.9g}".replace(".", decimal) for _, _, v in cols))
    return "\r\n".join(lines) + "\r\n"


def _check_si(meas, record, time=True):
    np.testing.assert_allclose(meas["displacement_m"], record["displacement_m"], rtol=1e-8, atol=1e-15)
    np.testing.assert_allclose(meas["force_N"], record["force_N"], rtol=1e-8, atol=1e-9)
    if time:
        np.testing.assert_allclose(meas["time_s"], record["time_s"], rtol=1e-8, atol=1e-15)


def test_the_german_press_rig_export_of_the_issue_reads_to_si(tmp_path, record):
    path = tmp_path / "feder.csv"
    path.write_bytes(_german(record).encode("iso-8859-1"))
    meas = read_measurement(path, MAP)
    _check_si(meas, record)
    d = meas.source.dialect
    assert (d.encoding, d.separator, d.decimal, d.header_row, d.units_row) == ("cp1252", ";", ",", 2, 3)
    assert meas.source.comments[0].startswith("Prüfstand 3")          # the title is kept, decoded right
    assert meas.source.channels["force_N"].source_unit == "kN"        # the unit row's unit was converted
    text = meas.source.describe()
    assert "read as Windows-1252 (ISO-8859-1), ';' separator, decimal comma, names in line 2, units in line 3" in text


@pytest.mark.parametrize("encoding", ["utf-8", "utf-8-sig", "utf-16", "utf-16-le", "utf-16-be", "cp1252"])
@pytest.mark.parametrize("style", [dict(), dict(sep="\t"), dict(sep=",", decimal="."), dict(unit_style="bracket"),
                                   dict(unit_style="above", title=False), dict(sep="|", title=False)])
def test_every_dialect_reads_to_the_same_si_values(tmp_path, record, encoding, style):
    path = tmp_path / "r.txt"
    path.write_bytes(_german(record.iloc[:40], **style).encode(encoding))
    meas = read_measurement(path, MAP)
    _check_si(meas, record.iloc[:40])
    d = meas.source.dialect
    assert d.separator == style.get("sep", ";") and d.decimal == style.get("decimal", ",")
    ascii_only = not style.get("title", True)      # the title holds the only non-ASCII characters
    assert d.encoding == ("utf-8" if ascii_only and encoding == "cp1252" else encoding)


def test_a_csv_the_detection_cannot_settle_is_read_with_the_options_given(tmp_path, record):
    # one column of decimal-comma numbers under a name row that is also a number-free line: ';' or ','?
    # Without a header line, "0,5" is either two integer columns or one decimal-comma column.
    path = tmp_path / "ambiguous.csv"
    path.write_text("0,5\n1,5\n2,5\n")
    t = read_csv(path)
    assert list(t.frame.shape) == [3, 2] and t.dialect.separator == ","   # the plain reading: two columns
    t = read_csv(path, dialect=CsvDialect(separator=";", decimal=","))
    np.testing.assert_allclose(t.frame.iloc[:, 0], [0.5, 1.5, 2.5])
    assert t.dialect.header_row == 0 and list(t.frame.columns) == ["column_1"]
    # the same through a channel map's [csv] table and through the command line
    cmap = ChannelMap.from_dict({"csv": {"separator": ";", "decimal": ",", "header_row": 0},
                                 "channels": {"force_N": {"source": "column_1", "source_unit": "kN"}}})
    meas = read_measurement(path, cmap, time=None)
    np.testing.assert_allclose(meas["force_N"], [500.0, 1500.0, 2500.0])
    assert ChannelMap.from_dict(cmap.to_dict()).csv == cmap.csv
    # an explicit argument wins over the map's table
    meas = read_measurement(path, {"channels": {"a": {"source": "column_1", "unit": "1"}}, "csv": {"separator": ";"}},
                            time=None, csv={"separator": ",", "header_row": 0})
    np.testing.assert_allclose(meas["a"], [0, 1, 2])


def test_header_and_unit_rows_can_be_set_by_line(tmp_path):
    path = tmp_path / "rows.csv"
    # a title of the table's width, holding a number: not a data row, because its text stands where numbers do
    path.write_text("Versuch;7;Prüfer\nt;x;F\ns;mm;N\n0;1;2\n1;2;3\n", encoding="utf-8")
    for rows in ({}, {"header_row": 2}):
        t = read_csv(path, dialect=rows)
        assert list(t.frame.columns) == ["t", "x", "F"] and t.units == {"t": "s", "x": "mm", "F": "N"}
        assert t.dialect.units_row == 3 and t.comments == ("Versuch;7;Prüfer",)
    # a title of numbers only is data to the detection: the header row says where the names are
    path.write_text("2026;11;28\nt;x;F\ns;mm;N\n0;1;2\n1;2;3\n", encoding="utf-8")
    assert read_csv(path).dialect.header_row == 0
    t = read_csv(path, dialect={"header_row": 2})
    assert list(t.frame.columns) == ["t", "x", "F"] and t.units == {"t": "s", "x": "mm", "F": "N"}
    assert t.dialect.units_row == 3 and t.comments == ("2026;11;28",)
    t = read_csv(path, dialect={"header_row": 2, "units_row": 0, "separator": ";"})
    with pytest.raises(DataError, match=r"non-finite or non-numeric value 's' at row 0"):
        read_table(t.frame, ["t"], name="rows.csv")
    with pytest.raises(DataError, match=r"rows\.csv: csv header_row = 9: line 9 is blank, a comment or beyond"):
        read_csv(path, label="rows.csv", dialect={"header_row": 9})
    with pytest.raises(ParameterError, match=r"csv header_row = -1"):
        read_csv(path, dialect={"header_row": -1})
    with pytest.raises(ParameterError, match=r"csv separator = ':'"):
        CsvDialect(separator=":")
    with pytest.raises(ParameterError, match=r"unknown encoding"):
        CsvDialect(encoding="klingon")
    with pytest.raises(ParameterError, match=r"unknown key 'sep'"):
        ChannelMap.from_dict({"csv": {"sep": ";"}, "channels": {"force_N": "F"}})


def test_clutchlabs_own_files_and_text_columns_read_as_before(tmp_path):
    path = tmp_path / "events.csv"
    path.write_text('# synthetic: virtual rig\n# units: time_s=s\ntime_s,element,event\n0.1,g1,locked\n'
                    '0.25,"a,b",free\n')
    t = read_csv(path)
    assert t.frame["element"].tolist() == ["g1", "a,b"] and t.frame["time_s"].tolist() == [0.1, 0.25]
    assert t.comments == ("synthetic: virtual rig",) and t.units == {"time_s": "s"}
    # a trailing separator leaves no empty column; thousands separators under a decimal comma
    path.write_text("a;b;\n1.234,5;2;\n3;4;\n")
    t = read_csv(path)
    assert list(t.frame.columns) == ["a", "b"] and t.frame["a"].tolist() == [1234.5, 3.0]
    assert "thousands separator '.'" in t.dialect.describe()
    # names only: an empty table, which the record readers call "no samples"
    path.write_text("time_s;force_N\n")
    with pytest.raises(DataError, match="no samples"):
        read_measurement(path)


def test_bad_text_files_are_one_clear_error(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_bytes(b"\xff\xfe\x00garbage\x00\x81")
    with pytest.raises(DataError, match=r"bad\.csv: cannot read as CSV \(starts with a UTF-16 byte-order mark"):
        read_csv(bad)
    bad.write_bytes(b"PK\x03\x04\x00\x00binary\x00zip")
    with pytest.raises(DataError, match=r"bad\.csv: cannot read as CSV \(binary data"):
        read_csv(bad)
    bad.write_text("just some words\nand more words\n")
    with pytest.raises(DataError, match=r"bad\.csv: cannot read as CSV \(no rows of numbers found"):
        read_csv(bad)
    bad.write_text("a;b\n1;2\n3;4;5;6\n")
    with pytest.raises(DataError, match=r"bad\.csv: line 3 has 4 fields, expected 2 \(separator ';'\)"):
        read_csv(bad)
    bad.write_text("a;b;a\n1;2;3\n")
    with pytest.raises(DataError, match=r"column 'a' appears twice"):
        read_csv(bad)
    bad.write_bytes("Weg;Kraft\nmm;kN\n0,1;1,0\n".encode("utf-8"))
    with pytest.raises(DataError, match=r"not utf-16 text"):
        read_csv(bad, dialect={"encoding": "utf-16"})
    bad.write_text("Weg;Kraft\nmm;Hallo Welt\n0,1;1,0\n")
    t = read_csv(bad)   # not a unit row: the names are the line next to the data, the first line a title
    assert (t.dialect.header_row, t.dialect.units_row, t.comments) == (2, 0, ("Weg;Kraft",))
    with pytest.raises(DataError, match=r"unknown unit 'Hallo Welt' in the unit row \(line 2\)"):
        read_csv(bad, dialect={"header_row": 1, "units_row": 2})


def test_convert_and_characterize_read_the_german_export_from_the_command_line(tmp_path, record, capsys):
    src = tmp_path / "feder.csv"
    src.write_bytes(_german(record).encode("iso-8859-1"))
    cmap = tmp_path / "map.toml"
    cmap.write_text("[channels.time_s]\nsource = 'Zeit'\n[channels.displacement_m]\nsource = 'Weg'\n"
                    "[channels.force_N]\nsource = 'Kraft'\n")
    assert main(["convert", str(src), "--channel-map", str(cmap), "-o", str(tmp_path / "si.csv")]) == 0
    out = capsys.readouterr().out
    assert "read as Windows-1252 (ISO-8859-1), ';' separator, decimal comma" in out
    _check_si(read_measurement(tmp_path / "si.csv"), record)
    # the same file from the command line options alone, without detection of the separator or decimal
    assert main(["convert", str(src), "--channel-map", str(cmap), "--separator", ";", "--decimal", ",",
                 "--encoding", "iso-8859-1", "--header-row", "2", "--units-row", "3",
                 "-o", str(tmp_path / "si2.csv")]) == 0
    assert "read as ISO-8859-1" in capsys.readouterr().out
    # a press record without a time column (#33): the characterisation needs only the order of the samples
    notime = tmp_path / "ohne_zeit.csv"
    notime.write_bytes(_german(record, time=False).encode("iso-8859-1"))
    timeless = tmp_path / "map2.toml"
    timeless.write_text("[channels.displacement_m]\nsource = 'Weg'\n[channels.force_N]\nsource = 'Kraft'\n")
    assert main(["eclutch", "characterize", str(notime), "--channel-map", str(timeless), "-o",
                 str(tmp_path / "c1.csv")]) == 0
    assert main(["eclutch", "characterize", str(src), "--channel-map", str(cmap), "-o",
                 str(tmp_path / "c2.csv")]) == 0
    c1, c2 = pd.read_csv(tmp_path / "c1.csv", comment="#"), pd.read_csv(tmp_path / "c2.csv", comment="#")
    pd.testing.assert_frame_equal(c1, c2)
    assert main(["eclutch", "characterize", str(notime), "--channel-map", str(timeless), "--sample-rate", "0",
                 "-o", str(tmp_path / "c3.csv")]) != 0
    assert "sample_rate = 0.0 Hz: must be a positive number" in capsys.readouterr().err


def test_a_record_without_time_takes_a_sample_rate(record):
    from clutchlab.eclutch.characterize import characterize

    frame = record[["displacement_m", "force_N"]]
    with_time = characterize(record)
    without = characterize(frame)
    np.testing.assert_array_equal(with_time.force, without.force)
    assert without.branches["time_s"].isna().all()
    rated = characterize(frame, sample_rate=2.0)
    t = rated.branches["time_s"].to_numpy()
    np.testing.assert_array_equal(t, np.round(2 * t) / 2)        # sample index / 2 Hz
    assert t.max() <= (len(frame) - 1) / 2 and np.diff(np.unique(t)).min() == 0.5
    with pytest.raises(ParameterError, match="has its own time column"):
        characterize(record, sample_rate=2.0)
    bad = record.copy()
    bad.loc[5, "time_s"] = bad.loc[4, "time_s"]
    with pytest.raises(DataError, match=r"time_s must increase strictly, but row 5"):
        characterize(bad)


@settings(max_examples=examples(25), deadline=None)
@given(values=st.lists(st.lists(st.floats(-1e6, 1e6, allow_nan=False).map(lambda v: round(v, 6)),
                                min_size=3, max_size=3), min_size=1, max_size=12),
       sep=st.sampled_from([",", ";", "\t", "|"]), decimal=st.sampled_from([".", ","]),
       encoding=st.sampled_from(["utf-8", "utf-8-sig", "utf-16", "cp1252"]), title=st.booleans(),
       units=st.booleans())
def test_detection_reads_back_what_any_dialect_wrote(tmp_path_factory, values, sep, decimal, encoding, title, units):
    """Property: a table of numbers written in any dialect (decimal never equal to the separator) reads back
    to the same numbers, under the names and units it was written with."""
    if sep == decimal:
        decimal = "."
    lines = (["Prüfung Nr. 3"] if title else []) + [sep.join(["Zeit", "Weg", "Kraft"])]
    if units:
        lines.append(sep.join(["s", "mm", "kN"]))
    lines += [sep.join(repr(v).replace(".", decimal) for v in row) for row in values]
    path = tmp_path_factory.mktemp("d") / "t.csv"
    path.write_bytes("\n".join(lines).encode(encoding))
    t = read_csv(path)
    np.testing.assert_array_equal(t.frame.to_numpy(dtype=float), np.array(values))
    assert list(t.frame.columns) == ["Zeit", "Weg", "Kraft"]
    assert t.units == ({"Zeit": "s", "Weg": "mm", "Kraft": "kN"} if units else {})
    assert t.comments == (("Prüfung Nr. 3",) if title else ())


def test_the_report_reads_a_rig_export_and_says_how(tmp_path, record):
    from clutchlab.report.run import find_datasets, metrics_table

    run = tmp_path / "run"
    run.mkdir()
    (run / "feder.csv").write_bytes(_german(record).encode("iso-8859-1"))
    (ds,), failed = find_datasets(run)
    # the units of the unit row travel in the names, where the report's figures find them
    assert not failed and list(ds.frame.columns) == ["Zeit [s]", "Weg [mm]", "Kraft [kN]"]
    assert ds.provenance[0].startswith("Prüfstand 3")
    assert ds.provenance[-1].startswith("read as Windows-1252 (ISO-8859-1), ';' separator, decimal comma")
    m = metrics_table(ds).set_index("channel")
    np.testing.assert_allclose(m.loc["Kraft [kN]", "max"], record["force_N"].max() / 1e3, rtol=1e-8)
    assert m.loc["Kraft [kN]", "unit"] == "kN" and m.loc["Weg [mm]", "unit"] == "mm"
