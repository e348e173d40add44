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
