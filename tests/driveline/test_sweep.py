"""The sweep target ``driveline`` and the parameters of a description file, against closed forms.

Two inertias coupled by a clutch with a constant normal force (no source): the clutch slides with the
constant torque ``T = cgeo mu fn_max``, which brakes ``J1`` and drives ``J2``, so the relative speed
falls linearly and the clutch locks at ``t* = w0 / (T (1/J1 + 1/J2))``; then both turn at the speed
that conserves the momentum, ``J1 w0 / (J1 + J2)``, and the clutch has dissipated the kinetic energy
lost, ``w0^2 J1 J2 / (2 (J1 + J2))``, whatever ``T``.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cli_checks import one_line_error
from clutchlab.cli import main
from clutchlab.driveline import Driveline, Signal
from clutchlab.sweep import driveline as S
from clutchlab.driveline.variants import DrivelineDocument
from clutchlab.errors import ParameterError
from clutchlab.sweep import load_spec

from .test_friction import TWO_PI, _root, coupled_clutches

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

TWO = """
[driveline]
name = "two"

[simulation]
t_end = "1 s"
output_step = "1 ms"
rtol = 1e-10

[inertia.J1]
J = "2 kg m^2"
w0 = "100 rad/s"

[inertia.J2]
J = "1 kg m^2"

[clutch.clutch]
a = "J1"
b = "J2"
fn_max = "400 N"
mu = 0.5
peak = 1.2
"""


def _scenario(tmp_path, text=TWO, name="two.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path, {**tomllib.loads(text), "_source": str(path)}


def _design(**columns):
    """A full grid of the given parameter values, indexed by variant id."""
    index = pd.MultiIndex.from_product(list(columns.values()), names=list(columns))
    return index.to_frame(index=False).rename_axis("variant_id")


def test_parameters_are_the_numeric_fields_and_their_defaults():
    doc = DrivelineDocument.read(EXAMPLES / "driveline_test_friction.toml")
    p = doc.parameters
    assert (p["inertia.J"].value, p["inertia.J"].unit) == (1.0, "kg*m**2")
    assert (p["brake.fn_max"].value, p["brake.mu"].value, p["brake.peak"].value) == (1.0, 0.5, 1.0)  # peak: default
    assert (p["bearing_friction.torque"].value, p["bearing_friction.torque"].unit) == (1.0, "N*m")
    assert p["inertia3.w0"].value == 0.0 and p["clutch.cgeo"].value == 1.0
    for signal in ("torque.torque", "brake.normal", "clutch.normal", "brake.flange"):
        assert signal not in p  # signals and flange names are not numeric parameters
    with pytest.raises(ParameterError, match=r"'brake\.fn_maxx'.*did you mean 'brake\.fn_max'"):
        doc.load({"brake.fn_maxx": 2.0})
    with pytest.raises(ParameterError, match=r"driveline_test_friction\.toml with inertia\.J = -1\.0.*J"):
        doc.load({"inertia.J": -1.0})


def _coupled_clutches(J2, w0, fn_max3):
    """CoupledClutches written with the Python API, three of its numbers changed (independent of the file)."""
    d = Driveline("coupled_clutches")
    for name, J, w in (("J1", 1.0, w0), ("J2", J2, 0.0), ("J3", 1.0, 0.0), ("J4", 1.0, 0.0)):
        d.inertia(name, J=J, w0=w)
    d.torque("torque", "J1", Signal.sine(10.0, 5.0))
    d.clutch("clutch1", "J1", "J2", fn_max=20.0, mu=0.5, peak=1.1, normal=Signal.sine(1.0, 0.2, phase=math.pi / 2))
    d.clutch("clutch2", "J2", "J3", fn_max=20.0, mu=0.5, peak=1.1, normal=Signal.step(1.0, 0.4))
    d.clutch("clutch3", "J3", "J4", fn_max=fn_max3, mu=0.5, peak=1.1, normal=Signal.step(1.0, 0.9))
    return d


def test_a_changed_file_is_the_python_network_with_that_change():
    """The variant's run equals the same network written with the Python API, to the last bit."""
    doc = DrivelineDocument.read(EXAMPLES / "driveline_coupled_clutches.toml")
    spec = doc.load({"J2.J": 2.0, "clutch3.fn_max": 30.0, "J1.w0": 12.0})
    a = spec.driveline.simulate(1.5, rtol=1e-8, output_step=0.01).to_dataframe()
    b = _coupled_clutches(2.0, 12.0, 30.0).simulate(1.5, rtol=1e-8, output_step=0.01).to_dataframe()
    pd.testing.assert_frame_equal(a[b.columns], b)
    c = doc.load().driveline.simulate(1.5, rtol=1e-8, output_step=0.01).to_dataframe()
    assert abs(c["J4.w_rad_s"].iloc[-1] - b["J4.w_rad_s"].iloc[-1]) > 0.1  # the changes matter


@pytest.fixture(scope="module")
def two_sweep(tmp_path_factory):
    _, scenario = _scenario(tmp_path_factory.mktemp("two"))
    variants = _design(**{"clutch.fn_max": [300.0, 450.0, 600.0], "J2.J": [1.0, 3.0], "clutch.mu": [0.3, 0.5]})
    outputs = list(S.describe(scenario)["outputs"])
    return variants, S.run_batch(variants, scenario, outputs)


def test_two_inertias_lock_at_the_closed_form_time(two_sweep):
    variants, out = two_sweep
    J1, w0, t_end = 2.0, 100.0, 1.0
    J2, T = variants["J2.J"].to_numpy(), (variants["clutch.mu"] * variants["clutch.fn_max"]).to_numpy()
    k = 1 / J1 + 1 / J2
    lock = w0 / (T * k)
    slid = np.minimum(lock, t_end)  # how long the clutch slid: w_rel = -w0 + T k t until it is 0
    assert np.sum(lock > t_end) == 1  # one variant does not lock within the run: no stick event, NaN
    np.testing.assert_allclose(out["clutch.last_stick_s"], np.where(lock < t_end, lock, np.nan), rtol=0, atol=1e-9)
    np.testing.assert_allclose(out["J1.w_final_rad_s"], w0 - T * slid / J1, rtol=1e-9)
    np.testing.assert_allclose(out["J2.w_final_rad_s"], T * slid / J2, rtol=1e-9)
    locked = lock < t_end  # locked: the speed that conserves the momentum
    np.testing.assert_allclose(out["J2.w_final_rad_s"][locked], (J1 * w0 / (J1 + J2))[locked], rtol=1e-9)
    lost = T * (w0 * slid - 0.5 * T * k * slid**2)  # integral of T |w_rel|
    np.testing.assert_allclose(lost[locked], (0.5 * w0**2 * J1 * J2 / (J1 + J2))[locked], rtol=1e-12)
    np.testing.assert_allclose(out["clutch.dissipated_J"], lost, rtol=1e-8)
    np.testing.assert_allclose(out["dissipated_energy_J"], lost, rtol=1e-8)
    np.testing.assert_allclose(out["clutch.peak_tau_Nm"], T, rtol=1e-12)
    assert (out["status"] == 0).all() and (out["energy_error_J"] < 1e-8 * lost).all()


def test_the_batch_gives_each_variant_its_own_run(tmp_path, two_sweep):
    """One variant alone, and in another order among others: the same numbers, bit for bit."""
    variants, out = two_sweep
    _, scenario = _scenario(tmp_path)
    alone = S.run_batch(variants.iloc[[4]], scenario, list(out.columns))
    pd.testing.assert_frame_equal(alone, out.iloc[[4]])
    shuffled = variants.iloc[::-1]
    pd.testing.assert_frame_equal(S.run_batch(shuffled, scenario, list(out.columns)), out.iloc[::-1])


def test_a_variant_with_more_events_than_the_batch_keeps_runs_again(tmp_path, monkeypatch):
    """CoupledClutches has nine events; with room for one per variant the variants run again alone."""
    text = (EXAMPLES / "driveline_coupled_clutches.toml").read_text()
    _, scenario = _scenario(tmp_path, text, "cc.toml")
    variants = _design(**{"clutch1.fn_max": [20.0, 22.0]})
    outputs = ["clutch1.last_stick_s", "clutch3.last_stick_s", "J4.w_final_rad_s"]
    full = S.run_batch(variants, scenario, outputs)
    monkeypatch.setattr(S, "EVENT_CAPACITY", 1)
    pd.testing.assert_frame_equal(S.run_batch(variants, scenario, outputs), full)
    ref = coupled_clutches().simulate(1.5, rtol=1e-8, output_step=1e-3)
    stick = ref.events[(ref.events.event == "stick")]
    assert full["clutch1.last_stick_s"].iloc[0] == stick[stick.element == "clutch1"].time_s.max()
    assert full["clutch3.last_stick_s"].iloc[0] == stick[stick.element == "clutch3"].time_s.max()


def test_bad_names_values_and_scenarios_are_refused(tmp_path):
    _, scenario = _scenario(tmp_path)
    with pytest.raises(ParameterError, match=r"'clutch\.fn_maxx'.*did you mean 'clutch\.fn_max'"):
        S.run_batch(_design(**{"clutch.fn_maxx": [1.0]}), scenario, ["status"])
    with pytest.raises(ParameterError, match=r"variant 1: .*two\.toml with J2\.J = -1\.0: inertia\.J2\.J = -1\.0: must be > 0"):
        S.check_variants(_design(**{"J2.J": [1.0, -1.0]}), scenario)
    with pytest.raises(ParameterError, match="unknown output 'J3.w_final_rad_s'"):
        S.run_batch(_design(**{"J2.J": [1.0]}), scenario, ["J3.w_final_rad_s"])
    with pytest.raises(ParameterError, match="needs a scenario"):
        S.describe(None)
    _, no_end = _scenario(tmp_path, TWO.replace('t_end = "1 s"\n', ""), "no_end.toml")
    with pytest.raises(ParameterError, match=r"no_end\.toml: \[simulation\] t_end"):
        S.describe(no_end)
    spec = tmp_path / "spec.toml"
    head = '[sweep]\nmodel = "driveline"\nscenario = "two.toml"\noutputs = ["status"]\n[grid]\n'
    spec.write_text(head + '"clutch.fn_maxx" = [1, 2]\n')
    with pytest.raises(ParameterError, match=r"spec\.toml.*clutch\.fn_maxx"):  # refused before anything runs
        load_spec(spec)
    spec.write_text(head + '"clutch.normal" = [0.5, 1]\n')  # a constant normal force (default 1) is a parameter
    assert load_spec(spec).n_variants == 2


def test_sweep_command_runs_the_example_and_an_edit_of_the_driveline_is_a_new_sweep(tmp_path, capsys):
    """examples/sweep_driveline.toml through the CLI: lock times in closed form (TestFriction, fn = 100 fn_max,
    mu = 0.5); an edited driveline file is another sweep (the resume is refused)."""
    for name in ("sweep_driveline.toml", "driveline_test_friction.toml"):
        (tmp_path / name).write_bytes((EXAMPLES / name).read_bytes())
    spec, out = tmp_path / "sweep_driveline.toml", tmp_path / "res"
    assert main(["sweep", str(spec), "-o", str(out), "--no-progress", "--no-plot"]) == 0
    frame = pd.read_parquet(out / "results.parquet")
    assert len(frame) == 12
    for row in frame.to_dict("records"):
        Tc, Tb = 50.0 * row["clutch.fn_max"], 50.0 * row["brake.fn_max"]
        # clutch from 0.5 s: w_rel = -10/pi at 0.5, w_rel' = 2 Tc - 10 sin 2pi t (two unit inertias)
        t_clutch = _root(lambda t: -10 / math.pi + 2 * Tc * (t - 0.5) + 5 / math.pi * (math.cos(TWO_PI * t) + 1),
                         0.5001, 0.9)
        # brake from 0.5 s: w = (10/2pi)(1 - cos 2pi t) - Tb (t - 0.5)
        t_brake = _root(lambda t: 5 / math.pi * (1 - math.cos(TWO_PI * t)) - Tb * (t - 0.5), 0.5001, 0.9)
        assert abs(row["clutch.last_stick_s"] - t_clutch) < 1e-8 and abs(row["brake.last_stick_s"] - t_brake) < 1e-8
        assert row["clutch.peak_tau_Nm"] == pytest.approx(Tc, rel=1e-12)  # the sliding torque
    # locked, the pair shares the drive's momentum: (5/2pi)(1 - cos 2pi t_end) each, for every force
    np.testing.assert_allclose(frame["inertia3.w_final_rad_s"], 5 / math.pi / 2 * (1 - math.cos(TWO_PI * 1.1)),
                               rtol=1e-8)
    capsys.readouterr()
    assert main(["sweep", str(spec), "-o", str(out), "--no-progress", "--no-plot"]) == 0
    assert "0 chunks computed, 2 reused" in capsys.readouterr().err
    scen = tmp_path / "driveline_test_friction.toml"
    scen.write_text(scen.read_text().replace('J = "1 kg m^2"', 'J = "1.0 kg m^2"', 1))
    err = one_line_error(capsys, ["sweep", str(spec), "-o", str(out), "--no-progress"])
    assert "different sweep" in err and "driveline_test_friction.toml" in err


ECLUTCH = """
[driveline]
name = "eclutch"

[simulation]
t_end = "0.3 s"
output_step = "1 ms"

[inertia.J2]
J = "0.1 kg m^2"
w0 = "100 rad/s"

[eclutch.e]
a = "ground"
b = "J2"
position = { ramp = { height = "-8 mm", duration = "0.2 s", offset = "8 mm" } }
parameters = "eclutch/my_clutch.toml"   # relative to this file
"""


def test_the_files_a_description_names_are_read_beside_it_and_hashed(tmp_path, monkeypatch, capsys):
    """A spec in one folder, its driveline description in another, run from a third that holds a decoy of the same
    name: the E-clutch parameter file the description names is read relative to the description (the sweep equals
    ``Driveline.simulate`` of the file), and an edit of the curve file that parameter file names in turn is another
    sweep (the resume is refused)."""
    from clutchlab.driveline.description import load_driveline

    model, specs, work = tmp_path / "model", tmp_path / "specs", tmp_path / "work"
    for folder in (model, specs, work):
        (folder / "eclutch").mkdir(parents=True)
        for name in ("my_clutch.toml", "my_diaphragm.csv"):
            (folder / "eclutch" / name).write_bytes((EXAMPLES / name).read_bytes())
    for decoy in (specs, work):  # same names, another clutch: read from here, the sweep would differ
        path = decoy / "eclutch" / "my_clutch.toml"
        path.write_text(path.read_text().replace('r_eff = "102.6 mm"', 'r_eff = "80 mm"'))
    (model / "dl.toml").write_text(ECLUTCH)
    (work / "dl.toml").write_text(ECLUTCH)
    (specs / "sweep.toml").write_text(
        '[sweep]\nmodel = "driveline"\nscenario = "../model/dl.toml"\n'
        'outputs = ["e.last_stick_s", "e.dissipated_J", "J2.w_final_rad_s"]\n'
        '[grid]\n"J2.J" = ["0.1 kg m^2", "0.2 kg m^2"]\n')
    monkeypatch.chdir(work)
    assert main(["sweep", "../specs/sweep.toml", "-o", "res", "--no-progress", "--no-plot"]) == 0
    got = pd.read_parquet(work / "res" / "results.parquet").sort_values("J2.J").iloc[0]
    assert got["J2.J"] == 0.1

    def native(path):
        res = load_driveline(path).driveline.simulate(0.3, rtol=1e-8, output_step=1e-3)
        return res.events[res.events.event == "stick"].time_s.max(), res.to_dataframe()["e.dissipated_J"].iloc[-1]

    stick, dissipated = native(model / "dl.toml")
    assert abs(got["e.last_stick_s"] - stick) < 1e-9 and got["e.dissipated_J"] == pytest.approx(dissipated, rel=1e-9)
    assert abs(native(work / "dl.toml")[0] - stick) > 1e-3  # the decoy is another clutch
    capsys.readouterr()
    assert main(["sweep", "../specs/sweep.toml", "-o", "res", "--no-progress", "--no-plot"]) == 0
    assert "0 chunks computed" in capsys.readouterr().err
    curve = model / "eclutch" / "my_diaphragm.csv"
    curve.write_text(curve.read_text() + "\n")  # the same curve, other bytes: the sweep's inputs changed
    err = one_line_error(capsys, ["sweep", "../specs/sweep.toml", "-o", "res", "--no-progress"])
    assert "different sweep" in err and "my_diaphragm.csv" in err


def test_an_input_start_is_a_sweep_parameter_held_through_each_run(tmp_path):
    """``[input.engage] start`` is the parameter ``engage.start`` (in the unit of the fields reading it), held
    through each variant's run: the clutch of :data:`TWO` pressed by ``engage * fn_max`` locks at the closed
    form ``w0 / (mu engage fn_max (1/J1 + 1/J2))``.  A torque input's start is in N m.  The FMU keeps them out of
    its parameters (each is its FMI input's start)."""
    text = TWO + 'normal = { input = "engage" }\n\n[input.engage]\nstart = 1.0\n' \
        + '\n[torque.load]\nflange = "J2"\ntorque = { input = "load" }\n\n[input.load]\nstart = "0 kN m"\n'
    _, scenario = _scenario(tmp_path, text)
    doc = DrivelineDocument(scenario, scenario["_source"])
    assert {n: (p.unit, p.value) for n, p in doc.input_starts.items()} == {"engage.start": ("1", 1.0),
                                                                          "load.start": ("N*m", 0.0)}
    assert "engage.start" not in doc.parameters   # (the FMU's parameters)
    described = S.describe(scenario)["parameters"]
    assert described["engage.start"] == "1" and described["load.start"] == "N*m"
    variants = _design(**{"engage.start": [0.5, 0.75, 1.0], "clutch.fn_max": [400.0]})
    out = S.run_batch(variants, scenario, ["clutch.last_stick_s", "J2.w_final_rad_s", "status"])
    T = 0.5 * 400.0 * variants["engage.start"].to_numpy()
    np.testing.assert_allclose(out["clutch.last_stick_s"], 100.0 / (T * (1 / 2.0 + 1 / 1.0)), rtol=0, atol=1e-9)
    np.testing.assert_allclose(out["J2.w_final_rad_s"], 2.0 * 100.0 / 3.0, rtol=1e-9)
    assert (out["status"] == 0).all()
    loaded = doc.load({"load.start": 5.0}).driveline
    assert loaded.system().u0.tolist() == [1.0, 5.0]
    with pytest.raises(ParameterError, match=r"'engage\.strat'.*did you mean 'engage\.start'"):
        doc.load({"engage.strat": 2.0})


SINE = """
[driveline]
name = "sine"

[simulation]
t_end = "1.25 s"
output_step = "1 ms"
rtol = 1e-10

[inertia.J1]
J = "2 kg m^2"

[torque.T]
flange = "J1"
torque = { sine = { amplitude = "10 N m", frequency = "1 Hz" } }

[inertia.J2]
J = "1 kg m^2"

[torque.R]
flange = "J2"
torque = { table = { times = ["0 s", "1 s"], values = ["0 N m", "10 N m"] } }
"""


def test_metrics_and_signal_parameters_against_closed_forms(tmp_path):
    """Sweep outputs over a run (#33: minimum speeds, peaks, jerk) and the numbers of signals as parameters (the
    force profiles engineers vary).  J1 from rest under ``A sin(W t)``: ``w = A (1 - cos W t) / (J W)``, least 0,
    largest ``2 A / (J W)`` at half a period, jerk ``d2w/dt2 = A W cos(W t) / J``, whose peak ``A W / J`` is reached
    again at a full period (inside the run).  J2 (1 kg m^2) under the table ramp to 10 N m in 1 s, stretched in time by
    ``s`` and scaled by ``k``: the integral of ``10 k t / s`` up to ``s``, then of ``10 k``, to 1.25 s."""
    _, scenario = _scenario(tmp_path, SINE, "sine.toml")
    doc = DrivelineDocument(scenario, scenario["_source"])
    sp = doc.signal_parameters
    assert (sp["T.torque.amplitude"].unit, sp["T.torque.amplitude"].value) == ("N*m", 10.0)
    assert (sp["T.torque.frequency"].unit, sp["T.torque.frequency"].value) == ("Hz", 1.0)
    assert sp["R.torque.time_scale"].value == sp["R.torque.value_scale"].value == 1.0
    described = S.describe(scenario)
    assert {"T.torque.amplitude", "R.torque.time_scale"} <= set(described["parameters"])
    outputs = ["J1.w_min_rad_s", "J1.w_max_rad_s", "J1.w_final_rad_s", "J1.w_jerk_rad_s3", "J2.w_final_rad_s",
               "T.tau_max_Nm", "status"]
    assert described["outputs"]["J1.w_jerk_rad_s3"] == "rad/s**3"
    variants = _design(**{"T.torque.amplitude": [5.0, 20.0], "T.torque.frequency": [1.0, 2.0],
                          "R.torque.time_scale": [1.0, 2.0], "R.torque.value_scale": [0.5]})
    out = S.run_batch(variants, scenario, outputs)
    assert (out["status"] == 0).all()
    for vid, row in variants.iterrows():
        a, f, s, k = (row[c] for c in variants.columns)
        w = 2 * math.pi * f
        got = out.loc[vid]
        assert abs(got["J1.w_min_rad_s"]) < 1e-9
        assert got["J1.w_max_rad_s"] == pytest.approx(2 * a / (2.0 * w), rel=1e-5)
        assert got["J1.w_final_rad_s"] == pytest.approx(a * (1 - math.cos(w * 1.25)) / (2.0 * w), rel=1e-6, abs=1e-9)
        assert got["J1.w_jerk_rad_s3"] == pytest.approx(a * w / 2.0, rel=2e-3)
        ramp = 10 * k / s   # N m/s, the stretched and scaled ramp, held at 10 k from t = s on
        w2 = ramp * 1.25 ** 2 / 2 if s >= 1.25 else ramp * s ** 2 / 2 + 10 * k * (1.25 - s)
        assert got["J2.w_final_rad_s"] == pytest.approx(w2, rel=1e-6)
        assert got["T.tau_max_Nm"] == pytest.approx(a, rel=1e-6)


def test_an_unknown_metric_is_refused_with_the_closest_name(tmp_path):
    _, scenario = _scenario(tmp_path, SINE, "sine.toml")
    with pytest.raises(ParameterError, match=r"unknown output 'J1\.w_minn_rad_s'; did you mean 'J1\.w_min_rad_s'"):
        S.run_batch(_design(**{"J1.J": [1.0]}), scenario, ["J1.w_minn_rad_s"])


def test_a_friction_map_s_level_is_a_sweep_parameter(tmp_path):
    """#33 "sweeps over friction coefficients or maps": ``<clutch>.mu_scale`` scales a clutch's or brake's friction
    coefficient, a number, a table or a map alike.  A brake with a uniform map (mu 0.1) stops J (0.5 kg m^2 from
    100 rad/s) under 200 N at ``J w0 / (fn mu s)``: 2.5 s / s; the same with the coefficient as a number."""
    from clutchlab.wet.friction import FrictionMap

    FrictionMap([0.0, 10.0], [20.0, 120.0], np.full((2, 2), 0.1)).to_json(tmp_path / "map.json")
    text = ('[inertia.J]\nJ = "0.5 kg m^2"\nw0 = "100 rad/s"\n'
            '[brake.brake]\nflange = "J"\nfn_max = "200 N"\nmu_map = "map.json"\nradius = "100 mm"\n'
            'temperature = "80 degC"\n[simulation]\nt_end = "4 s"\n')
    _, scenario = _scenario(tmp_path, text, "map.toml")
    described = S.describe(scenario)
    assert "brake.mu_scale" in described["parameters"]
    variants = _design(**{"brake.mu_scale": [0.8, 1.0, 1.25, 2.0]})
    out = S.run_batch(variants, scenario, ["brake.last_stick_s", "status"])
    assert (out["status"] == 0).all()
    for vid, row in variants.iterrows():
        assert out.loc[vid, "brake.last_stick_s"] == pytest.approx(2.5 / row["brake.mu_scale"], rel=1e-7)
    _, number = _scenario(tmp_path, text.replace('mu_map = "map.json"\nradius = "100 mm"\ntemperature = "80 degC"\n',
                                                 "mu = 0.1\n"), "number.toml")
    again = S.run_batch(variants, number, ["brake.last_stick_s"])
    np.testing.assert_allclose(again["brake.last_stick_s"], out["brake.last_stick_s"], rtol=1e-9)
    # a factor beyond its range is refused by name
    with pytest.raises(ParameterError, match=r"brake: mu_scale = 30 is above 2"):
        Driveline("x").inertia("J", J=1.0).brake("brake", "J", fn_max=1.0, mu=0.1, mu_scale=30.0)
