"""Assertions on what the command line prints, shared by the tests of every subsystem."""

from clutchlab.cli import main


def one_line_error(capsys, argv):
    """Run ``clutchlab ARGV``; assert exit code 2 and one ``clutchlab: error:`` line on stderr; return it."""
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("clutchlab: error: "), err
    return lines[0]


def fixed_step_frames(fixed, adaptive, rows):
    """Check a ``--fixed-step "1 ms"`` output file against the adaptive one: the synthetic header with the
    solver line (the adaptive file has none) and the same sample times; return both as DataFrames."""
    import numpy as np
    import pandas as pd

    header = [line for line in fixed.read_text().splitlines() if line.startswith("#")]
    assert header[0].startswith("# synthetic:")
    assert "# solver: fixed-step (real-time) mode, step 0.001 s (Rodas3 on the grid k * step)" in header
    assert "fixed-step" not in adaptive.read_text()
    a, f = pd.read_csv(adaptive, comment="#"), pd.read_csv(fixed, comment="#")
    assert len(a) == len(f) == rows
    np.testing.assert_array_equal(f.time_s, a.time_s)
    return a, f
