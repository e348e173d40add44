"""A Preisach grid must be 1-D: a 2-D array is refused, never flattened."""

import json

import numpy as np
import pandas as pd
import pytest

from clutchlab.cli import main
from clutchlab.errors import DataError
from clutchlab.hysteresis import Preisach, forc_table_from_masses
from clutchlab.hysteresis.identify import forc_input, identify_forc

GRID = np.linspace(0.0, 4.5, 10)


def model():
    rng = np.random.default_rng(1)
    n = GRID.size - 1
    return Preisach(GRID, forc_table_from_masses(GRID, np.tril(rng.uniform(0, 5, (n, n))), rng.uniform(0, 2, n)))


def test_constructor_refuses_a_2d_grid():
    table = model().tables[0]
    with pytest.raises(DataError, match=r"grid: expected a 1-D list of values, got an array of shape \(2, 5\)"):
        Preisach(GRID.reshape(2, 5), table)
    assert Preisach(GRID, table).grid.shape == (10,)


def test_identification_refuses_a_2d_grid():
    cur = forc_input(GRID)
    force = model().simulate(cur)
    assert identify_forc(cur, force, GRID).model.grid.size == GRID.size
    with pytest.raises(DataError, match=r"FORC record: grid must be a 1-D list of currents \[A\], got an array of "
                                        r"shape \(2, 5\)"):
        identify_forc(cur, force, GRID.reshape(2, 5))


def test_model_file_with_a_2d_grid(tmp_path, capsys):
    path = model().to_json(tmp_path / "m.json")
    body = json.loads(path.read_text())
    body["grid_A"] = np.reshape(body["grid_A"], (2, 5)).tolist()
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(body))
    with pytest.raises(DataError, match=rf"{bad}: grid_A must be a 1-D list of currents \[A\], got an array of "
                                        r"shape \(2, 5\)"):
        Preisach.from_json(bad)
    inp = tmp_path / "in.csv"
    pd.DataFrame({"current": [0.5, 1.0]}).to_csv(inp, index=False)
    code = main(["emtc", "preisach", "run", str(bad), str(inp), "-o", str(tmp_path / "out.csv")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1
    assert err[0].startswith(f"clutchlab: error: {bad}: grid_A must be a 1-D list") and "(2, 5)" in err[0]
    assert not (tmp_path / "out.csv").exists()
