"""Every command's --help describes it in a paragraph and names its documentation page, never a module."""

import argparse
import pathlib
import re

import pytest

from clutchlab.cli import build_parser, main

DOCS = pathlib.Path(__file__).parents[1] / "docs"
#: a dotted clutchlab module path such as clutchlab.eclutch.scenario (what a user cannot open)
MODULE = re.compile(r"\bclutchlab\.[a-z_]+")


def _walk(parser, path):
    yield path, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _walk(sub, path + [name])


PARSERS = list(_walk(build_parser(), []))


def test_the_tree_has_every_command():
    names = {" ".join(p) for p, _ in PARSERS}
    assert {"eclutch characterize", "eclutch static", "wet simulate", "emtc preisach identify", "params show",
            "convert", "sweep", "report", "export-fmu", "demo"} <= names


@pytest.mark.parametrize("path, parser", PARSERS, ids=lambda v: " ".join(v) if isinstance(v, list) else "")
def test_help_has_a_description_and_a_docs_page(path, parser):
    where = "clutchlab " + " ".join(path)
    assert parser.description and len(parser.description.split()) >= 8, f"{where}: no one-paragraph description"
    pages = re.findall(r"docs/([a-z_]+\.md)", parser.epilog or "")
    assert pages, f"{where}: the epilog names no docs/<page>.md"
    for page in pages:
        assert (DOCS / page).is_file() or page == "index.md" and (DOCS / page).is_file(), f"{where}: docs/{page} missing"
    texts = [parser.description, parser.epilog] + [a.help or "" for a in parser._actions]
    for text in texts:
        assert not MODULE.search(text or ""), f"{where}: help names a source module: {text!r}"


@pytest.mark.parametrize("argv, page", [
    (["eclutch", "static", "--help"], "docs/eclutch.md"),
    (["wet", "simulate", "--help"], "docs/wet.md"),
    (["params", "show", "--help"], "docs/parameters.md"),
])
def test_help_output_names_the_page(capsys, argv, page):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 0
    assert page in capsys.readouterr().out


def test_the_top_level_lines_are_the_commands_own():
    """``clutchlab --help`` lists each subsystem command with a line of its own (its module is not imported);
    that line is the one the command's module registers."""
    from clutchlab.cli import COMMANDS

    full = {a.dest: a.help for action in build_parser()._actions if isinstance(action, argparse._SubParsersAction)
            for a in action._choices_actions}
    light = {a.dest: a.help for action in build_parser("")._actions
             if isinstance(action, argparse._SubParsersAction) for a in action._choices_actions}
    assert list(full) == list(light)
    assert full == light
    assert set(COMMANDS) == set(full) - {"demo", "warmup"}


HEAVY = ("numba", "pandas", "scipy", "matplotlib", "pyarrow", "clutchlab.eclutch", "clutchlab.wet", "clutchlab.emtc",
         "clutchlab.driveline", "clutchlab.numerics", "clutchlab.curves", "clutchlab.system")


def test_top_level_help_imports_no_model():
    """``clutchlab --help`` (and ``--version``) import no model, numba, pandas or SciPy: the CLI starts in the time
    of Python's own start (benchmarks/README.md); a command imports only its own subsystem."""
    import subprocess
    import sys

    code = ("import sys\nfrom clutchlab.cli import main\n"
            "try:\n    main(sys.argv[1:])\nexcept SystemExit:\n    pass\n"
            "print('MODULES', ' '.join(sorted(sys.modules)), file=sys.stderr)\n")
    for args in (["--help"], ["--version"], ["driveline", "--help"]):
        out = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, timeout=120)
        mods = out.stderr.split("MODULES", 1)[1].split()
        loaded = {h for h in HEAVY if any(m == h or m.startswith(h + ".") for m in mods)}
        if args[0] == "driveline":
            # the command's own module is read (the check sees imports), no other model's
            assert "clutchlab.cli.driveline" in mods and not loaded & {"clutchlab.eclutch", "clutchlab.wet"}, loaded
        else:
            assert not loaded, (args, loaded)
            assert "usage: clutchlab" in out.stdout or "clutchlab 0" in out.stdout


def _compiling_packages():
    """The top-level modules and packages of clutchlab whose source defines compiled functions."""
    root = pathlib.Path(__file__).parents[1] / "src" / "clutchlab"
    marks = ("njit", "numba.jit", "@overload", "@intrinsic")
    found = set()
    for path in root.rglob("*.py"):
        if any(m in path.read_text(encoding="utf-8") for m in marks):
            rel = path.relative_to(root)
            found.add("clutchlab." + (rel.parts[0] if len(rel.parts) > 1 else rel.stem))
    return sorted(found)


@pytest.mark.parametrize("package", _compiling_packages())
def test_every_compiling_package_installs_the_compile_notice(package):
    """The one-line compile notice is installed by clutchlab.numerics, not at ``import clutchlab``: each package
    with compiled functions imports it, so the notice is in place before its first compilation."""
    import subprocess
    import sys

    code = (f"import importlib, sys\nimportlib.import_module({package!r})\n"
            "from clutchlab import _compile_notice\nprint(_compile_notice._state['installed'])\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.stdout.strip() == "True", out.stderr
