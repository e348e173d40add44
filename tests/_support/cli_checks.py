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
