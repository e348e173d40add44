"""The driveline as a co-simulation slave and an FMU (``export-fmu driveline FILE.toml``) against
``Driveline.simulate`` of the same file.

Tolerance: the co-simulation stops the adaptive Dormand-Prince 5(4) at every communication point
(1 ms) while ``Driveline.simulate`` steps across them, so the two differ by the integration error.
CoupledClutches over 1.5 s, measured: at rtol 1e-8 the speeds differ by 5e-8 of their range and the
source's work by 4.5e-7 of its range; at rtol 1e-10 by 5e-10 and 6e-9 -- a hundred times less for a
hundred times tighter tolerance, which a model mismatch would not give.  The FMU runs the very same
co-simulation behind pythonfmu: equal to 1e-12.
"""

import math
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest

from cli_checks import one_line_error
from clutchlab.cli import main
from clutchlab.cli.fmu import PYTHON_BACKEND_WARNING
from clutchlab.driveline import Driveline, Signal
from clutchlab.fmu.driveline import DrivelineCoSimulation
from clutchlab.driveline.description import load_driveline
from clutchlab.errors import ParameterError
from clutchlab.fmu.cosim import load_cosimulation
from clutchlab.fmu.export import export_fmu

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "driveline_coupled_clutches.toml"
DT, N = 1e-3, 1500  # 1 ms communication steps through 1.5 s


def _native(network, rtol):
    res = network.simulate(N * DT, rtol=rtol, output_step=DT)
    system = network.system(rtol)
    names = [v.name for v in (*system.states, *system.outputs)]
    values = np.concatenate((res.states, res.outputs), axis=1)
    return {n: values[:, i] for i, n in enumerate(names)}, res.events


def _scale(ref, name):
    """The range a column's difference is measured against (the energy balance error: the input work's)."""
    return max(np.max(np.abs(ref["input_work" if name == "energy_error" else name])), 1e-12)


def _largest_difference(out, ref, names):
    return max(np.max(np.abs(out[n] - ref[n])) / _scale(ref, n) for n in names)


@pytest.fixture(scope="module")
def chains():
    """Co-simulation and native run of the example file at two tolerances."""
    cls = DrivelineCoSimulation.for_description(EXAMPLE)
    runs = {}
    for rtol in (1e-8, 1e-10):
        sim = cls(rtol=rtol)
        rows = [sim.initial_outputs({})]
        for k in range(N):
            t = k * DT
            rows.append(sim.do_step(t, (k + 1) * DT - t, {}))
        out = {v.name: np.array([r[v.name] for r in rows]) for v in cls.outputs}
        runs[rtol] = (sim, out, *_native(load_driveline(EXAMPLE).driveline, rtol))
    return cls, runs


def test_the_class_of_a_file_has_its_columns_and_parameters(chains):
    cls, _ = chains
    assert load_cosimulation("driveline") is DrivelineCoSimulation and cls.__name__.endswith("[coupled_clutches]")
    system = load_driveline(EXAMPLE).driveline.system()
    assert [v.name for v in cls.outputs] == [v.name for v in (*system.states, *system.outputs)]
    units = {v.name: v.unit for v in cls.outputs}
    assert (units["J1.phi"], units["J1.w"], units["clutch1.tau"], units["clutch1.mode"], units["clutch1.fn"],
            units["clutch1.dissipated"], units["kinetic_energy"]) == ("rad", "rad/s", "N.m", "1", "N", "J", "J")
    params = {v.name: v for v in cls.parameters}
    assert (params["rtol"].start, params["clutch1.fn_max"].unit, params["clutch1.fn_max"].start) == (1e-8, "N", 20.0)
    assert (params["J1.J"].unit, params["J1.w0"].start, params["clutch2.peak"].start) == ("kg.m2", 10.0, 1.1)
    assert "torque.torque" not in params and "clutch1.normal" not in params  # signals are not parameters
    assert cls.inputs == () and cls.experiment == (1.5, 1e-3)
    with pytest.raises(ParameterError, match="for_description"):
        DrivelineCoSimulation()
    with pytest.raises(ParameterError, match="clutch1.fn_maxx"):
        cls(**{"clutch1.fn_maxx": 1.0})
    with pytest.raises(ParameterError, match="rtol"):
        cls(rtol=2.0)


@pytest.mark.parametrize("rtol,bound", [(1e-8, 2e-6), (1e-10, 2e-8)])
def test_chain_of_steps_follows_simulate_within_solver_tolerance(chains, rtol, bound):
    _, runs = chains
    sim, out, ref, events = runs[rtol]
    assert _largest_difference(out, ref, list(ref)) < bound
    for name in ref:
        if name.endswith(".mode"):
            np.testing.assert_array_equal(out[name], ref[name], err_msg=name)
    got = sim.simulation.events()
    assert list(zip(got.element, got.event)) == list(zip(events.element, events.event)) and len(got) == 9
    np.testing.assert_allclose(got.time_s, events.time_s, rtol=0, atol=1e-7)


def test_the_difference_is_integration_error(chains):
    _, runs = chains
    speeds = [n for n in runs[1e-8][2] if n.endswith(".w") or n.endswith("work")]
    coarse = _largest_difference(runs[1e-8][1], runs[1e-8][2], speeds)
    fine = _largest_difference(runs[1e-10][1], runs[1e-10][2], speeds)
    assert fine < coarse / 20


def _network(J2, fn_max1, w0):
    """CoupledClutches written in Python with three of its numbers changed (independent of the file)."""
    d = Driveline("coupled_clutches")
    for name, J, w in (("J1", 1.0, w0), ("J2", J2, 0.0), ("J3", 1.0, 0.0), ("J4", 1.0, 0.0)):
        d.inertia(name, J=J, w0=w)
    d.torque("torque", "J1", Signal.sine(10.0, 5.0))
    d.clutch("clutch1", "J1", "J2", fn_max=fn_max1, mu=0.5, peak=1.1, normal=Signal.sine(1.0, 0.2, phase=math.pi / 2))
    d.clutch("clutch2", "J2", "J3", fn_max=20.0, mu=0.5, peak=1.1, normal=Signal.step(1.0, 0.4))
    d.clutch("clutch3", "J3", "J4", fn_max=20.0, mu=0.5, peak=1.1, normal=Signal.step(1.0, 0.9))
    return d


def test_parameters_change_the_run_as_the_python_network(chains, run_cosim):
    cls, _ = chains
    params = {"J2.J": 2.0, "clutch1.fn_max": 25.0, "J1.w0": 12.0}
    out = run_cosim(cls(**params), {}, DT, N)
    ref, _ = _native(_network(2.0, 25.0, 12.0), 1e-8)
    assert _largest_difference(out, ref, list(ref)) < 2e-6
    default, _ = _native(load_driveline(EXAMPLE).driveline, 1e-8)
    assert _largest_difference(ref, default, list(ref)) > 1e-2  # the change matters (5000 times the bound)


def test_the_fmu_carries_its_description_and_runs_it(tmp_path, chains, run_fmu, run_cosim):
    import fmpy
    import fmpy.validation

    cls, _ = chains
    copy = tmp_path / "src" / "my_driveline.toml"
    copy.parent.mkdir()
    shutil.copy(EXAMPLE, copy)
    path = export_fmu("driveline", tmp_path / "dl.fmu", description=copy)
    shutil.rmtree(copy.parent)  # the FMU needs only itself
    assert fmpy.validation.validate_fmu(str(path)) == []
    md = fmpy.read_model_description(str(path), validate=True)
    assert md.coSimulation.modelIdentifier == "ClutchlabDriveline" and "coupled_clutches" in md.description
    assert (float(md.defaultExperiment.stopTime), float(md.defaultExperiment.stepSize)) == (1.5, 1e-3)
    got = {v.name: v for v in md.modelVariables}
    for var, causality in [*((v, "output") for v in cls.outputs), *((v, "parameter") for v in cls.parameters)]:
        assert (got[var.name].causality, got[var.name].unit) == (causality, var.unit), var.name
    with zipfile.ZipFile(path) as z:
        assert z.read("resources/description.toml") == EXAMPLE.read_bytes()
        assert 'description_file = "description.toml"' in z.read("resources/clutchlabdriveline_slave.py").decode()
    names = ["J1.w", "J4.w", "clutch1.tau", "clutch1.mode", "clutch3.dissipated", "energy_error"]
    start = {"clutch1.fn_max": 25.0, "J2.J": 2.0}
    fmu = run_fmu(path, {}, DT, N, names, start)
    ref = run_cosim(cls(**start), {}, DT, N)
    for name in names:
        np.testing.assert_allclose(fmu[name], ref[name], rtol=1e-12, atol=1e-12 * np.max(np.abs(ref[name])),
                                   err_msg=name)


def test_export_fmu_command_for_a_driveline(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["export-fmu", "driveline", str(EXAMPLE), "--backend", "python"]) == 0
    captured = capsys.readouterr()
    out = captured.out.strip().splitlines()
    assert captured.err.strip().splitlines() == [f"clutchlab: warning: {PYTHON_BACKEND_WARNING}"]
    assert out[-1] == "driveline_coupled_clutches.fmu"  # named after the file
    # what of the user's went in is said (#33): here the description alone
    assert out[:-1] == [f"driveline_coupled_clutches.fmu: packed {EXAMPLE} as resources/description.toml"]
    assert "exists" in one_line_error(capsys, ["export-fmu", "driveline", str(EXAMPLE), "--backend", "python"])
    assert "needs a description file" in one_line_error(capsys, ["export-fmu", "driveline", "-o", "x.fmu"])
    assert "takes no description file" in one_line_error(capsys, ["export-fmu", "wet", str(EXAMPLE)])
    bad = tmp_path / "bad.toml"
    bad.write_text('[inertia.J1]\nJ = "-1 kg m^2"\n')
    err = one_line_error(capsys, ["export-fmu", "driveline", str(bad), "-o", "bad.fmu"])
    assert "bad.toml" in err and "J" in err
    with pytest.raises(ParameterError, match="takes no description file"):
        export_fmu("wet", tmp_path / "w.fmu", description=EXAMPLE)
    with pytest.raises(ParameterError, match="description file"):
        export_fmu("driveline", tmp_path / "d.fmu")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml", "driveline_coupled_clutches.fmu"]


# ----------------------------------------------------------------- the files a description names
EXAMPLES = EXAMPLE.parent
#: the wet example's wet clutch with a parameter file of its own clutch and of its bench (both named wet.toml,
#: one outside the description's folder) and an E-clutch with examples/my_clutch.toml, which names its curve
WET_FILES = {"clutch": 'clutch = "wet/wet.toml"   # N_c = 6, not the paper\'s 8\n',
             "bench": "bench = '../shared/wet.toml'\n"}
ECLUTCH = """
[inertia.J2]
J = "0.1 kg m^2"
w0 = "100 rad/s"

[eclutch.e]
a = "ground"
b = "J2"
position = { ramp = { height = "-8 mm", duration = "0.2 s", offset = "8 mm" } }
parameters = "eclutch/my_clutch.toml"   # with its own diaphragm curve
"""
SHORT = 300  # 0.3 s of 1 ms steps


def _files_description(folder: Path, without=()) -> Path:
    """``folder/model/dl.toml``: the wet example over 0.3 s with the files of WET_FILES and ECLUTCH (less those
    named in ``without``)."""
    from clutchlab.wet.params import Bench, WetClutch

    model = folder / "model"
    for sub in (model / "wet", model / "eclutch", folder / "shared"):
        sub.mkdir(parents=True, exist_ok=True)
    if not (model / "wet" / "wet.toml").exists():
        WetClutch.paper(n_c=6).to_toml(model / "wet" / "wet.toml")
        Bench(actuator_time_constant=0.03).to_toml(folder / "shared" / "wet.toml")
        for name in ("my_clutch.toml", "my_diaphragm.csv"):
            shutil.copy(EXAMPLES / name, model / "eclutch" / name)
    text = (EXAMPLES / "driveline_wet_sae2.toml").read_text().replace('t_end = "1.2 s"', 't_end = "0.3 s"')
    last = 'housing_temperature0 = "70 degC"\n'
    text = text.replace(last, last + "".join(line for key, line in WET_FILES.items() if key not in without))
    text += ECLUTCH.replace('parameters = "eclutch/my_clutch.toml"', "#") if "parameters" in without else ECLUTCH
    path = model / ("dl.toml" if not without else f"dl_without_{'_'.join(without)}.toml")
    path.write_text(text)
    return path


def test_the_fmu_carries_the_files_its_description_names(tmp_path, run_fmu):
    """An FMU of a description that names parameter files (a wet clutch's clutch and bench, two files both named
    wet.toml, one in a folder beside the description's; an E-clutch's, which names its own curve file) runs them
    from its resources: with the originals deleted it equals ``Driveline.simulate`` of the original description
    to the solver's tolerance, and every one of those files changes the run."""
    path = _files_description(tmp_path)
    originals = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}

    names = [v.name for v in DrivelineCoSimulation.for_description(path).outputs]

    def native(description):
        res = load_driveline(description).driveline.simulate(SHORT * DT, rtol=1e-8, output_step=DT)
        return dict(zip(names, np.concatenate((res.states, res.outputs), axis=1).T))

    ref = native(path)
    fmu_path = export_fmu("driveline", tmp_path / "dl.fmu", description=path)
    assert {p: p.read_bytes() for p in originals} == originals  # nothing the user wrote is touched
    with zipfile.ZipFile(fmu_path) as z:
        copies = sorted(n for n in z.namelist() if n.startswith("resources/description"))
        assert copies == ["resources/description.toml", "resources/description_files/my_clutch.toml",
                          "resources/description_files/my_diaphragm.csv", "resources/description_files/wet.toml",
                          "resources/description_files/wet_2.toml"]
        carried = z.read("resources/description.toml").decode()
        files = {n.rsplit("/", 1)[1]: z.read(n) for n in copies[1:]}
    # the description's text is kept: only the three file names change, to the copies (comments kept)
    changed = [(a, b) for a, b in zip(path.read_text().splitlines(), carried.splitlines(), strict=True) if a != b]
    assert changed == [('clutch = "wet/wet.toml"   # N_c = 6, not the paper\'s 8',
                        'clutch = "description_files/wet.toml"   # N_c = 6, not the paper\'s 8'),
                       ("bench = '../shared/wet.toml'", 'bench = "description_files/wet_2.toml"'),
                       ('parameters = "eclutch/my_clutch.toml"   # with its own diaphragm curve',
                        'parameters = "description_files/my_clutch.toml"   # with its own diaphragm curve')]
    assert files["wet.toml"] == originals[tmp_path / "model" / "wet" / "wet.toml"]
    assert files["wet_2.toml"] == originals[tmp_path / "shared" / "wet.toml"]
    assert files["my_diaphragm.csv"] == (EXAMPLES / "my_diaphragm.csv").read_bytes()
    assert files["my_clutch.toml"] == (EXAMPLES / "my_clutch.toml").read_bytes()  # names its curve beside it
    for p in tmp_path.iterdir():  # the FMU needs only itself
        if p != fmu_path:
            shutil.rmtree(p)
    out = run_fmu(fmu_path, {}, DT, SHORT, names)
    # the integration error at rtol 1e-8 (measured: 2.6e-6 of its range in the squeeze force, below 1e-6 elsewhere;
    # no source: the energy balance is measured against the initial kinetic energy, 2e-8)
    assert _largest_difference(out, ref, [n for n in names if n != "energy_error"]) < 1e-5
    assert np.max(np.abs(out["energy_error"] - ref["energy_error"])) < 1e-7 * ref["kinetic_energy"][0]
    for name in names:
        if name.endswith(".mode"):
            np.testing.assert_array_equal(out[name], ref[name], err_msg=name)
    # every file changes the run: without it (the defaults) the columns move by far more than the bound
    for without, columns in ((("clutch",), ["dyno.w", "clutch.tau"]), (("bench",), ["dyno.w", "clutch.tau"]),
                             (("parameters",), ["J2.w", "e.fn", "e.tau"])):
        other = native(_files_description(tmp_path / "again", without))
        assert _largest_difference(other, ref, columns) > 1e-2, without


def test_a_missing_file_or_one_outside_the_resources_is_refused(tmp_path, capsys):
    """Export refuses a description (or an E-clutch parameter file) naming a file that does not exist, naming
    the file, the key and the value, and writes nothing; the FMU's class refuses a name leading out of its
    resources folder."""
    last = 'housing_temperature0 = "70 degC"\n'
    wet = (EXAMPLES / "driveline_wet_sae2.toml").read_text()
    desc = tmp_path / "dl.toml"
    desc.write_text(wet.replace(last, last + 'friction = "laws/law.toml"\n'))
    with pytest.raises(ParameterError,
                       match=r"dl\.toml: wet_clutch\.clutch\.friction = 'laws/law\.toml': no such file"):
        export_fmu("driveline", tmp_path / "dl.fmu", description=desc)
    err = one_line_error(capsys, ["export-fmu", "driveline", str(desc), "-o", str(tmp_path / "dl.fmu")])
    assert "dl.toml" in err and "wet_clutch.clutch.friction = 'laws/law.toml'" in err
    (tmp_path / "ec.toml").write_text('[eclutch]\nr_eff = "0.1 m"\n\n[eclutch.curves]\n'
                                      'diaphragm = { file = "gone.csv" }\n')
    desc.write_text(ECLUTCH.replace("eclutch/my_clutch.toml", "ec.toml"))
    with pytest.raises(ParameterError, match=r"dl\.toml: eclutch\.e\.parameters = 'ec\.toml': .*ec\.toml: "
                                             r"eclutch\.curves\.diaphragm\.file = 'gone\.csv': no such file"):
        export_fmu("driveline", tmp_path / "dl.fmu", description=desc)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dl.toml", "ec.toml"]
    resources = tmp_path / "resources"
    resources.mkdir()
    (resources / "description.toml").write_text(ECLUTCH.replace("eclutch/my_clutch.toml", "../ec.toml"))
    with pytest.raises(ParameterError, match=r"eclutch\.e\.parameters = '\.\./ec\.toml': names .*ec\.toml, outside "
                                             r"the folder .*resources"):
        DrivelineCoSimulation.for_description(resources / "description.toml", within=resources)


def test_bundle_names_every_copy_apart_and_the_copy_loads_as_the_original(tmp_path):
    """``bundle_description``: two E-clutch parameter files both named clutch.toml (one with a curve folder, one
    with a curve file) and a path also used as another string value (the copy is then written anew from its
    values): the bundle holds every file under a name of its own and, with the originals gone, reads as the
    same network."""
    from importlib import resources

    from clutchlab.fmu.export import bundle_description

    src = tmp_path / "src"
    for sub in ("a/curves", "b"):
        (src / sub).mkdir(parents=True)
    with resources.as_file(resources.files("clutchlab.eclutch") / "data" / "curves") as bundled:
        for csv in Path(bundled).glob("*.csv"):
            shutil.copy(csv, src / "a" / "curves" / csv.name)
    (src / "a" / "clutch.toml").write_text('[eclutch]\nr_eff = "95 mm"\n\n[eclutch.curves]\nfolder = "curves"\n')
    (src / "b" / "clutch.toml").write_text('[eclutch]\n\n[eclutch.curves]\ndiaphragm = "my_diaphragm.csv"\n')
    shutil.copy(EXAMPLES / "my_diaphragm.csv", src / "b" / "my_diaphragm.csv")
    text = ECLUTCH.replace("eclutch/my_clutch.toml", "a/clutch.toml") + ECLUTCH.replace(
        "J2", "J3").replace("[eclutch.e]", '[eclutch.e2]').replace("eclutch/my_clutch.toml", "b/clutch.toml")
    desc = src / "dl.toml"
    desc.write_text('[driveline]\nname = "a/clutch.toml"\n' + text)
    told = []
    out = bundle_description(desc, tmp_path / "bundle", report=lambda source, name: told.append((source, name)))
    files = sorted(str(p.relative_to(tmp_path / "bundle")) for p in (tmp_path / "bundle").rglob("*") if p.is_file())
    # every file written is reported once, with the user's file it came from
    assert sorted(name for _, name in told) == files
    sources = dict((name, source) for source, name in told)
    assert sources["description.toml"] == desc and sources["description_files/my_diaphragm.csv"] == \
        src / "b" / "my_diaphragm.csv"
    assert sources["description_files/curves/cushion.csv"] == src / "a" / "curves" / "cushion.csv"
    assert files == ["description.toml", "description_files/clutch.toml", "description_files/clutch_2.toml",
                     *(f"description_files/curves/{c}.csv" for c in sorted(
                         ("cushion", "diaphragm", "pp_spring", "return_springs", "support_ring", "yoke_spring"))),
                     "description_files/my_diaphragm.csv"]
    assert out.read_text().startswith("# driveline description dl.toml, written anew")  # the name is a path too
    with pytest.raises(FileExistsError, match="description.toml"):
        bundle_description(desc, tmp_path / "bundle")  # replaces nothing
    original = load_driveline(desc).driveline
    shutil.rmtree(src)
    copy = load_driveline(out).driveline
    assert copy.name == "a/clutch.toml"
    assert [(e.name, e.summary) for e in copy.elements] == [(e.name, e.summary) for e in original.elements]

    def forces(d):   # the clamp forces from the clutches' static curves as the bearings close (0.2 s)
        df = d.simulate(0.3, sample_times=np.linspace(0.0, 0.3, 31)).to_dataframe()
        return df[["e.fn_N", "e2.fn_N"]].to_numpy()

    np.testing.assert_array_equal(forces(copy), forces(original))
    assert np.max(np.abs(np.diff(forces(original), axis=1))) > 1.0   # the two parameter files differ


def test_an_emtc_driveline_fmu_runs_from_its_resources(tmp_path, run_fmu):
    """The EMTC drum-bench example (it names the EMTC scenario file beside it) as an FMU, the originals deleted:
    the coupling's states, its controller's samples and the network equal ``Driveline.simulate`` of the original
    within the solver's tolerance, through 0.1 s of 1 ms steps (the armature leaves its rest stop and presses)."""
    for name in ("driveline_emtc_awd.toml", "emtc_scenario.toml"):
        shutil.copy(EXAMPLES / name, tmp_path / name)
    path = tmp_path / "driveline_emtc_awd.toml"
    names = [v.name for v in DrivelineCoSimulation.for_description(path).outputs]
    res = load_driveline(path).driveline.simulate(100 * DT, rtol=1e-8, output_step=DT)
    ref = dict(zip(names, np.concatenate((res.states, res.outputs), axis=1).T))
    fmu_path = export_fmu("driveline", tmp_path / "awd.fmu", description=path)
    with zipfile.ZipFile(fmu_path) as z:
        assert "resources/description_files/emtc_scenario.toml" in z.namelist()
    for name in ("driveline_emtc_awd.toml", "emtc_scenario.toml"):
        (tmp_path / name).unlink()
    out = run_fmu(fmu_path, {}, DT, 100, names)
    # (a gear's dissipation is drift, zero but for rounding: measured against the input work, as the energy error)
    drift = ("energy_error", "front_drive.dissipated", "rear_drive.dissipated")
    steady = [n for n in names if n not in drift + ("emtc.current_command", "emtc.torque_reference",
                                                    "emtc.command_feasible", "emtc.throttle")]
    worst = {n: np.max(np.abs(out[n][1:] - ref[n][1:])) / _scale(ref, n) for n in steady}
    # the integration error at rtol 1e-8, the FMU restarting every 1 ms (measured: 1.4e-5 of its range in the
    # armature speed, which the contact stops; below 1e-6 in the shaft speeds and the coupling torque)
    assert max(worst.values()) < 1e-4, sorted(worst.items(), key=lambda kv: -kv[1])[:4]
    assert max(worst[n] for n in ("front_shaft.w", "rear_shaft.w", "emtc.tau", "emtc.i2")) < 1e-5
    for n in drift:
        assert np.max(np.abs(out[n] - ref[n])) < 1e-7 * np.max(np.abs(ref["input_work"]))
    for n in ("emtc.x_armature", "emtc.i2", "emtc.magnet_force", "front_shaft.w", "emtc.tau"):
        assert np.ptp(ref[n]) > 0.0, n   # the coupling moved: the comparison is not of constants
    # the controller's held outputs from its first sample on (the FMU's row at t = 0 is before the first step)
    for n in ("emtc.current_command", "emtc.torque_reference"):
        assert np.max(np.abs(out[n][1:] - ref[n][1:])) < 1e-5 * np.max(np.abs(ref[n]))


# ----------------------------------------------------------------- network inputs as FMI inputs
def test_the_fmu_has_the_networks_inputs_and_a_host_drives_them(tmp_path, run_fmu, run_cosim):
    """A host holds the load and opens the clutch at 0.5 s through FMI inputs: the FMU is the co-simulation, and
    J2 decelerates alone at 2 N m / 1 kg m^2 from the locked speed (closed form)."""
    import xml.etree.ElementTree as ET

    from driveline_networks import INPUTS_TOML

    description = tmp_path / "inputs.toml"
    description.write_text(INPUTS_TOML)
    path = export_fmu("driveline", tmp_path / "inputs.fmu", description=description)
    with zipfile.ZipFile(path) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    found = {v.get("name"): v.get("causality") for v in root.iter("ScalarVariable")}
    assert found["load"] == "input" and found["press"] == "input"
    dt, n = 0.01, 100
    inputs = {"load": np.full(n + 1, 2.0), "press": np.where(np.arange(n + 1) < 50, 1.0, 0.0)}
    names = ["J1.w", "J2.w", "c.mode"]
    fmu = run_fmu(path, inputs, dt, n, names)
    ref = run_cosim(DrivelineCoSimulation.for_description(description)(), inputs, dt, n)
    for name in names:
        np.testing.assert_allclose(fmu[name], ref[name], rtol=1e-12, atol=1e-12, err_msg=name)
    w_lock = 10.0 - 30.0 * 10.0 / 58.0 - 1.0 * (0.5 - 10.0 / 58.0)
    assert fmu["J2.w"][-1] == pytest.approx(w_lock - 2.0 * 0.5, rel=1e-7)
