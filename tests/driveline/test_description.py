"""Driveline TOML descriptions, the ``clutchlab driveline`` command and the shipped examples."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cli_checks import one_line_error
from clutchlab.cli import main
from clutchlab.driveline.description import load_driveline
from clutchlab.errors import ParameterError

from .test_friction import coupled_clutches, friction_network

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_the_examples_describe_the_python_networks():
    """The example files are the networks the friction tests build in Python: the same events, and the
    same trajectories column by column (the file groups its components by kind, so the order differs)."""
    for name, network, t_end in (("driveline_coupled_clutches.toml", coupled_clutches(), 1.5),
                                 ("driveline_test_friction.toml", friction_network(), 1.1)):
        spec = load_driveline(EXAMPLES / name)
        a = spec.driveline.simulate(t_end, rtol=1e-10, output_step=0.01)
        b = network.simulate(t_end, rtol=1e-10, output_step=0.01)
        ea, eb = a.events, b.events
        assert sorted(zip(ea.element, ea.event)) == sorted(zip(eb.element, eb.event))
        np.testing.assert_allclose(np.sort(ea.time_s.to_numpy()), np.sort(eb.time_s.to_numpy()), atol=1e-12)
        fa, fb = a.to_dataframe(), b.to_dataframe()
        assert set(fa.columns) == set(fb.columns)
        for col in fb.columns:
            if not pd.api.types.is_numeric_dtype(fb[col]):  # the modes by name
                assert list(fa[col]) == list(fb[col]), col
            else:
                np.testing.assert_allclose(fa[col].to_numpy(), fb[col].to_numpy(), rtol=1e-9, atol=1e-9, err_msg=col)


def test_simulate_writes_states_outputs_and_events(tmp_path, capsys):
    out, ev, fig = tmp_path / "tf.csv", tmp_path / "ev.csv", tmp_path / "tf.png"
    assert main(["driveline", "simulate", str(EXAMPLES / "driveline_test_friction.toml"), "-o", str(out),
                 "--events", str(ev), "--plot", str(fig)]) == 0
    assert "energy balance" in capsys.readouterr().out
    frame = pd.read_csv(out)
    for col in ("time_s", "inertia.w_rad_s", "inertia.phi_rad", "clutch.tau_Nm", "clutch.w_rel_rad_s",
                "clutch.mode_1", "brake.mode_1", "bearing_friction.tau_Nm", "energy_error_J"):
        assert col in frame, col
    assert len(frame) == 1101 and frame.time_s.iloc[-1] == pytest.approx(1.1)
    events = pd.read_csv(ev)
    assert list(events.columns) == ["time_s", "component", "event"]
    got = {(r.component, r.event): r.time_s for r in events.itertuples()}
    assert got[("bearing_friction", "forward")] == pytest.approx(math.asin(0.1) / (2 * math.pi), abs=1e-6)
    assert got[("clutch", "stick")] == pytest.approx(0.5315198891, abs=1e-6)
    assert fig.stat().st_size > 10_000
    # nothing is overwritten without --force, and a refused command writes nothing
    before = out.read_bytes()
    one_line_error(capsys, ["driveline", "simulate", str(EXAMPLES / "driveline_test_friction.toml"), "-o", str(out)])
    assert out.read_bytes() == before
    assert main(["driveline", "simulate", str(EXAMPLES / "driveline_test_friction.toml"), "-o", str(out),
                 "--output-step", "10 ms", "--t-end", "0.2 s", "--force"]) == 0
    assert len(pd.read_csv(out)) == 21


def test_describe_prints_the_schematic(capsys):
    assert main(["driveline", "describe", str(EXAMPLES / "driveline_coupled_clutches.toml")]) == 0
    text = capsys.readouterr().out
    assert "coupled_clutches: 4 inertias, 4 elements (3 friction)" in text
    assert "[J1] --(clutch1: friction fn_max = 20 N, mu 0.5, peak 1.1" in text
    assert "ground --(torque: torque 10 N m sine at 5 Hz" in text


BASE = """
[inertia.J1]
J = "1 kg m^2"
[inertia.J2]
J = "2 kg m^2"
"""


@pytest.mark.parametrize("body, fragments", [
    ('[clutch.c]\na = "J1"\nb = "J9"\nfn_max = "1 N"\n', ["clutch.c", "'J9' is not an inertia"]),
    ('[clutch.c]\na = "J1"\nb = "J1"\nfn_max = "1 N"\n', ["clutch.c", "both flanges are 'J1'"]),
    ('[clutch.c]\na = "J1"\nfn_max = "1 N"\n', ["clutch.c", "missing field 'b'"]),
    ('[inertia.J3]\nJ = "-1 kg m^2"\n', ["inertia.J3", "J = -1.0 must be > 0"]),
    ('[gearbox.g]\nratio = 3\n', ["unknown table [gearbox]"]),
    ('[clutch.c]\na = "J1"\nb = "J2"\nfn_max = "1 N m"\n', ["clutch.c.fn_max", "wrong unit"]),
    ('[clutch.c]\na = "J1"\nb = "J2"\nfn_max = "1 N"\ncolour = "red"\n', ["clutch.c.colour", "unknown field"]),
    ('[torque.T]\nflange = "J1"\ntorque = { square = { amplitude = 1 } }\n', ["torque.T.torque", "unknown signal 'square'"]),
    ('[torque.T]\nflange = "J1"\ntorque = { sine = { amplitude = "1 N m" } }\n', ["torque.T.torque", "needs an amplitude and a frequency"]),
    ('[simulation]\nt_end = "soon"\n', ["simulation.t_end", "cannot parse"]),
])
def test_bad_descriptions_name_file_key_and_value(tmp_path, capsys, body, fragments):
    path = tmp_path / "bad.toml"
    path.write_text(BASE + body)
    with pytest.raises(ParameterError) as exc:
        load_driveline(path)
    for fragment in fragments + [str(path)]:
        assert fragment in str(exc.value), str(exc.value)
    line = one_line_error(capsys, ["driveline", "simulate", str(path), "-o", str(tmp_path / "out.csv"),
                                   "--t-end", "1 s"])
    assert fragments[-1] in line and not (tmp_path / "out.csv").exists()
