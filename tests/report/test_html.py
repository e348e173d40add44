"""HTML report writer: self-contained page, files beside it, atomic, no silent overwrite."""

import base64
import re

import pandas as pd
import pytest

from clutchlab.plotting import new_figure
from clutchlab.report import Figure, Section, Table, Text, write_report


def section():
    fig, ax = new_figure()
    ax.plot([0, 1], [0, 1])
    return Section("Test", [Text("hello <b>"), Figure("line", fig, "a line"), Table("t", pd.DataFrame({"a": [1.5]}))],
                   provenance="synthetic: test data", parameters={"k": "1 N/m"})


def test_report_is_self_contained(tmp_path):
    index = write_report([section()], tmp_path / "rep")
    html = index.read_text()
    imgs = re.findall(r"data:image/png;base64,([A-Za-z0-9+/=]+)", html)
    assert len(imgs) == 1 and base64.b64decode(imgs[0])[:4] == b"\x89PNG"
    assert "synthetic: test data" in html and "hello &lt;b&gt;" in html
    assert (tmp_path / "rep" / "figures" / "line.png").exists()
    assert (tmp_path / "rep" / "tables" / "t.csv").exists()
    with pytest.raises(FileExistsError):
        write_report([section()], tmp_path / "rep")
    write_report([section()], tmp_path / "rep", overwrite=True)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_report_folder_has_the_usual_permissions(tmp_path):
    import os
    import stat

    index = write_report([section()], tmp_path / "rep2")
    umask = os.umask(0)
    os.umask(umask)
    mode = stat.S_IMODE(os.stat(index.parent).st_mode)
    assert mode == 0o777 & ~umask


def test_synthetic_badge(tmp_path):
    sections = [Section("A", [Text("a")], provenance="synthetic: virtual rig"),
                Section("B", [Text("b")], provenance="rig 3, measured"),
                Section("C", [Text("c")], provenance="rig 3", synthetic=True),
                Section("D", [Text("d")], provenance="made with a synthetic oil", synthetic=False)]
    html = write_report(sections, tmp_path / "rep").read_text()
    heads = re.findall(r"<h2 id='s\d'>(.*?)</h2>", html)
    assert ["SYNTHETIC DATA" in h for h in heads] == [True, False, True, False]


def test_progress_per_figure(tmp_path):
    messages = []
    write_report([section(), section()], tmp_path / "rep", progress=messages.append)
    assert [m for m in messages if m.startswith("rendering figure")] == ["rendering figure 1/2: line",
                                                                         "rendering figure 2/2: line"]
    # two figures (and tables) of the same name: both kept beside the page
    assert sorted(p.name for p in (tmp_path / "rep" / "figures").iterdir()) == ["line.png", "line_2.png"]
    assert sorted(p.name for p in (tmp_path / "rep" / "tables").iterdir()) == ["t.csv", "t_2.csv"]


def test_force_replaces_only_a_folder_clutchlab_wrote(tmp_path, monkeypatch, capsys):
    """``--force`` replaced any folder (#33): ``report RUN -o mydata --force`` deleted the user's files, and
    ``-o .`` ended in a traceback.  Now only a report folder (its marker, or only a report's entries) is
    replaced; a folder with anything else, a file, the working folder and its parents are refused by name, the
    files untouched."""
    from clutchlab.cli import main
    from clutchlab.errors import ParameterError
    from clutchlab.report.html import MARKER

    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep me")
    with pytest.raises(ParameterError, match=r"holds 'notes\.txt', which clutchlab did not write"):
        write_report([section()], mine, overwrite=True)
    assert (mine / "notes.txt").read_text() == "keep me" and len(list(mine.iterdir())) == 1
    (tmp_path / "afile").write_text("x")
    with pytest.raises(ParameterError, match="a file, not a report folder"):
        write_report([section()], tmp_path / "afile", overwrite=True)
    old = tmp_path / "old_report"            # a report written before the marker: only its own entries
    (old / "figures").mkdir(parents=True)
    (old / "index.html").write_text("old")
    write_report([section()], old, overwrite=True)
    assert (old / MARKER).exists() and "old" != (old / "index.html").read_text()
    monkeypatch.chdir(mine)
    with pytest.raises(ParameterError, match="the folder this command runs in"):
        write_report([section()], ".", overwrite=True)
    with pytest.raises(ParameterError, match="or holds it"):
        write_report([section()], tmp_path, overwrite=True)
    run = tmp_path / "run"
    run.mkdir()
    (run / "r.csv").write_text("time_s,x_1\n0,1\n1,2\n")
    for argv in (["report", str(run), "-o", ".", "--force"], ["report", str(run), "-o", str(mine), "--force"],
                 ["demo", "-o", str(mine), "--force"]):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("clutchlab: error: ") and "not replaced" in err[0], err
    assert (mine / "notes.txt").read_text() == "keep me" and (run / "r.csv").exists()


@pytest.mark.parametrize("killed_at", ["rendering", "moving into place"])
def test_a_killed_run_leaves_nothing_the_next_run_does_not_remove(tmp_path, killed_at):
    """#33: a killed ``clutchlab demo`` left its hidden ``.NAME.*`` folders (2.9 MB each) beside the report, and
    no later run removed them.  A run killed (SIGKILL has no ``finally``) while it renders a figure, or between
    moving the old report aside and the new one in, leaves folders; the next report written there removes
    them -- its own kind only: named ``.NAME.PID.XXXXXXXX.tmp``, holding the marker, process PID gone.  A
    look-alike folder of the user's (no marker) and one of a writer still running stay."""
    import os
    import subprocess
    import sys
    import textwrap
    from pathlib import Path

    import clutchlab
    from clutchlab.report.html import MARKER

    out = tmp_path / "rep"
    if killed_at == "moving into place":
        write_report([section()], out)
    die = ("h._figure_png = lambda fig: os._exit(9)" if killed_at == "rendering" else
           "real = os.replace\nh.os.replace = lambda a, b: os._exit(9) if os.path.basename(b) != 'rep' else real(a, b)")
    script = textwrap.dedent(f"""
        import os
        import clutchlab.report.html as h
        from clutchlab.plotting import new_figure
        from clutchlab.report import Figure, Section
        """) + die + textwrap.dedent(f"""
        fig, ax = new_figure()
        ax.plot([0, 1], [0, 1])
        h.write_report([Section("A", [Figure("f", fig)])], {str(out)!r}, overwrite=True)
        """)
    env = dict(os.environ, PYTHONPATH=str(Path(clutchlab.__file__).resolve().parents[1]), MPLBACKEND="Agg")
    assert subprocess.run([sys.executable, "-c", script], env=env, timeout=300).returncode == 9
    left = [p for p in tmp_path.iterdir() if p.name.startswith(".rep.")]
    assert left and all(p.is_dir() for p in left)          # what the killed run left: its folder(s)
    mine = tmp_path / ".rep.4194305.abcdefgh.tmp"           # the pattern, a pid above any Linux pid_max, no marker
    (mine / "figures").mkdir(parents=True)
    (mine / "notes.txt").write_text("keep me")
    running = tmp_path / f".rep.{os.getpid()}.abcdefgh.tmp"  # a writer still running (this process)
    running.mkdir()
    (running / MARKER).write_text("")
    write_report([section()], out, overwrite=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["rep", mine.name, running.name])
    assert (mine / "notes.txt").read_text() == "keep me" and (mine / "figures").is_dir()
    assert (out / "index.html").exists() and (out / "figures" / "line.png").exists()
