"""The component contract (clutchlab.component): declarations, the file format, parameters and docs generated
from them, and a component added from outside -- the toy cone clutch of tests/_support/cone_clutch.py, one
file and one registration -- used in a TOML driveline, simulate, a sweep and control.linearize (its FMU:
tests/fmu/test_cone_clutch_fmu.py).

Closed form of the cone clutch between two free inertias (Shigley Sec. 16-4): it slides with the constant
torque ``T = mu F_a r_m / sin(alpha)``, braking J1 and driving J2, so the relative speed falls linearly and
it locks at ``t* = w0 / (T (1/J1 + 1/J2))``; then both turn at ``J1 w0 / (J1 + J2)`` and it has dissipated
``w0^2 J1 J2 / (2 (J1 + J2))``.
"""

from __future__ import annotations

import inspect
import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import cone_clutch
from cli_checks import one_line_error
from clutchlab import component as C
from clutchlab.cli import main
from clutchlab.driveline import BUILTIN, Driveline
from clutchlab.driveline.description import load_driveline, parse_driveline
from clutchlab.driveline.variants import DrivelineDocument
from clutchlab.errors import ParameterError

DOCS = Path(__file__).resolve().parents[2] / "docs" / "components.md"

J1, J2, W0, F, R, ALPHA, MU = 0.1, 0.3, 100.0, 500.0, 0.05, math.radians(12.0), 0.3

CONE = cone_clutch.EXAMPLE


def lock_time(force=F, r_mean=R, alpha=ALPHA, mu=MU):
    torque = mu * force * r_mean / math.sin(alpha)
    return W0 / (torque * (1 / J1 + 1 / J2))


@pytest.fixture
def cone():
    """The cone clutch registered for one test (the one line a user writes), and gone after it."""
    C.register_component(cone_clutch.CONE_CLUTCH)
    yield cone_clutch.CONE_CLUTCH
    C.unregister_component("cone_clutch")


# ---- the declarations of the built-in kinds

#: fields the component's build function reads into another argument of the method (a spring's rows and their
#: interpolation are its curve; a friction map file is its mu; an EMTC scenario file its scenario, vehicle, options)
BUILDER_ONLY = {("spring", "interpolation"), ("clutch", "mu_map"), ("brake", "mu_map"), ("emtc", "bench")}

def test_every_builtin_kind_is_declared_with_the_defaults_of_its_method():
    kinds = {c.kind for c in BUILTIN}
    assert kinds == {"inertia", "spring_damper", "spring", "backlash", "gear", "torque", "speed", "position", "clutch",
                     "brake", "bearing_friction", "one_way_clutch", "eclutch", "engine", "wet_clutch", "emtc",
                     "torque_converter", "planetary", "speed_torque", "synchronizer",
                     "thermal_mass", "thermal_conductor"}
    for comp in BUILTIN:
        sig = inspect.signature(getattr(Driveline, comp.kind)).parameters
        for f in comp.fields:
            if (comp.kind, f.name) in BUILDER_ONLY:
                continue
            # the file's keys are the method's arguments (a source's signal is its table's own name)
            arg = "signal" if f.name == comp.kind and comp.kind in ("torque", "speed", "position") else f.name
            assert arg in sig, (comp.kind, f.name)
            p = sig[arg]
            if f.required:
                assert p.default is inspect.Parameter.empty or f.kind == "signal", (comp.kind, f.name)
            elif f.name in ("w0", "phi0"):
                assert p.default is None and f.default == 0.0  # left out: worked out; varied from 0
            elif isinstance(p.default, (int, float)) and not isinstance(p.default, bool) and f.kind != "flange":
                assert f.default == p.default, (comp.kind, f.name, f.default, p.default)
            if f.default is not None and f.is_numeric:
                assert f.range_problem(float(f.default)) is None


def test_the_docs_tables_are_generated_from_the_declarations():
    text = DOCS.read_text()
    start, end = "<!-- generated: components -->", "<!-- end generated -->"
    assert start in text and end in text
    generated = text.split(start)[1].split(end)[0].strip()
    want = "\n".join(C.component_table(c.kind) for c in BUILTIN).strip()
    assert generated == want, "docs/components.md is out of date: regenerate it (docs/components.md, top)"


def test_declarations_are_checked():
    with pytest.raises(ParameterError, match="kind = 'number'"):
        C.Field("x", "number")
    with pytest.raises(ParameterError, match="default 3.0 is above its range"):
        C.Field("mu", "quantity", default=3.0, maximum=2.0)
    with pytest.raises(ParameterError, match="minimum 2 > maximum 1"):
        C.Field("x", minimum=2, maximum=1)
    with pytest.raises(ParameterError, match="a choice needs its words"):
        C.Field("law", "choice")
    with pytest.raises(ParameterError, match="field 'a' is declared twice"):
        C.Component("twice", "", (C.Field("a", "flange"), C.Field("a", "flange")), print)
    with pytest.raises(ParameterError, match="kind 'clutch' is registered already"):
        C.register_component(C.Component("clutch", "another clutch", (), print))
    with pytest.raises(ParameterError, match="did you mean 'clutch'"):
        C.component("clutc")
    for reserved in ("input", "mass"):   # a table of every file; the translational form of the inertia
        with pytest.raises(ParameterError, match=f"component kind '{reserved}'"):
            C.register_component(C.Component(reserved, "", (), print))
    with pytest.raises(ParameterError, match="default 7 is above its range"):
        C.Field("model", "int", default=7, maximum=4)
    clutch = C.component("clutch")
    assert [f.name for f in clutch.ports] == ["a", "b"] and clutch.field("fn_max").unit == "N"
    assert [f.name for f in clutch.parameters] == ["fn_max", "mu", "mu_scale", "peak", "cgeo", "normal", "radius",
                                                        "temperature"]
    f = C.Field("eta", positive=True, maximum=1.0)
    assert (f.range_text(), f.range_problem(0.0), f.range_problem(1.0)) == ("(0, 1]", "must be > 0 [1]", None)
    assert C.Field("T", unit="N*m", minimum=0.0).range_text() == ">= 0 N*m"


@pytest.mark.parametrize("body, fragments", [
    ('[clutch.c]\na = "J1"\nb = "J2"\nfn_max = "1 N"\nmu = 3\n', ["clutch.c.mu = 3", "above its range [0, 2]"]),
    ('[clutch.c]\na = "J1"\nb = "J2"\nfn_max = "1 N"\nmu = [[0, 0.5], [1, -0.1]]\n',
     ["clutch.c.mu[1][1] = -0.1", "below its range [0, 2]"]),
    ('[clutch.c]\na = "J1"\nb = "J2"\nfn_max = "1 N"\npeak = 0.5\n', ["clutch.c.peak = 0.5", "below its range"]),
    ('[gear.g]\na = "J1"\nb = "J2"\nratio = 2\nefficiency = 1.5\n', ["gear.g.efficiency = 1.5", "(0, 1]"]),
    ('[clutch.c]\na = "J1"\nb = "J2"\nfn_max = "-1 N"\n', ["clutch.c.fn_max = '-1 N'", ">= 0 N"]),
    ('[wet_clutch.w]\na = "J1"\nb = "J2"\nforce = "1 kN"\ntemperature0 = "-300 degC"\n',
     ["wet_clutch.w.temperature0 = '-300 degC'", "below its range [-60, 600] degC"]),
])
def test_values_outside_their_declared_range_are_refused_naming_file_key_value_and_range(tmp_path, body, fragments):
    path = tmp_path / "bad.toml"
    path.write_text('[inertia.J1]\nJ = 1\n[inertia.J2]\nJ = 1\n' + body)
    with pytest.raises(ParameterError) as exc:
        load_driveline(path)
    for fragment in [str(path), *fragments]:
        assert fragment in str(exc.value), str(exc.value)


def test_parameters_carry_their_declared_range():
    doc = DrivelineDocument(__import__("tomllib").loads(
        '[inertia.J1]\nJ = 1\n[gear.g]\na = "J1"\nb = "ground"\nratio = 2\n'), "mem.toml")
    eff = doc.parameters["g.efficiency"]
    assert (eff.value, eff.minimum, eff.maximum, eff.positive) == (1.0, None, 1.0, True)
    assert doc.parameters["J1.J"].positive and doc.parameters["J1.w0"].range_problem(-5.0) is None
    assert "range" not in (doc.parameters["g.efficiency"].range_problem(0.5) or "")
    with pytest.raises(ParameterError, match=r"mem\.toml with g\.efficiency = 1\.2: gear\.g\.efficiency = 1\.2: "
                                             r"is above its range \(0, 1\]"):
        doc.load({"g.efficiency": 1.2})


def test_the_components_command_lists_the_kinds_and_prints_a_kinds_fields(capsys, cone):
    assert main(["driveline", "components"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^clutch +A clutch between two flanges", out, re.M)
    assert re.search(r"^cone_clutch +A cone clutch.*\[cone_clutch\]$", out, re.M)  # where it comes from
    assert main(["driveline", "components", "cone_clutch"]) == 0
    out = capsys.readouterr().out
    assert "| `alpha` | quantity | rad | 0.20944 | (0, 1.5708] rad | cone half-angle" in out
    err = one_line_error(capsys, ["driveline", "components", "cone"])
    assert "unknown component kind 'cone'" in err and "did you mean 'cone_clutch'" in err


# ---- a component from outside: the cone clutch

def test_an_unregistered_kind_is_an_unknown_table(tmp_path):
    path = tmp_path / "cone.toml"
    path.write_text(CONE)
    with pytest.raises(ParameterError, match=r"unknown table \[cone_clutch\]"):
        load_driveline(path)


def test_the_cone_clutch_in_a_file_follows_its_closed_form(tmp_path, cone):
    path = tmp_path / "cone.toml"
    path.write_text(CONE)
    spec = load_driveline(path)
    res = spec.driveline.simulate(spec.t_end, output_step=spec.output_step, rtol=spec.rtol)
    ev = res.events
    assert list(zip(ev.element, ev.event)) == [("c", "stick")]
    t_lock = lock_time()
    assert abs(ev.time_s.iloc[0] - t_lock) < 1e-9 * t_lock + 1e-12
    df = res.to_dataframe()
    torque = MU * F * R / math.sin(ALPHA)
    slip = df.time_s < t_lock - 1e-3
    np.testing.assert_allclose(np.abs(df["c.tau_Nm"][slip]), torque, rtol=1e-12)
    np.testing.assert_allclose(df["c.fn_N"], F, rtol=1e-15)   # the axial force is the element's normal force
    last = df.iloc[-1]
    w_end = J1 * W0 / (J1 + J2)
    assert abs(last["J1.w_rad_s"] - w_end) < 1e-8 and abs(last["J2.w_rad_s"] - w_end) < 1e-8
    assert last["c.dissipated_J"] == pytest.approx(W0**2 * J1 * J2 / (2 * (J1 + J2)), rel=1e-9)
    assert abs(last["energy_error_J"]) < 1e-8
    # its parameters are the declaration's: defaults, units and ranges, for sweeps and FMUs
    doc = DrivelineDocument.read(path)
    p = doc.parameters
    assert (p["c.alpha"].value, p["c.alpha"].unit, p["c.alpha"].maximum) == (pytest.approx(ALPHA), "rad", math.pi / 2)
    assert (p["c.r_mean"].value, p["c.peak"].value, p["c.force"].value) == (pytest.approx(R), 1.0, F)
    # and the command line runs it
    assert main(["driveline", "simulate", str(path), "-o", str(tmp_path / "out.csv"),
                 "--events", str(tmp_path / "ev.csv")]) == 0
    ev_cli = pd.read_csv(tmp_path / "ev.csv")
    assert abs(ev_cli.time_s.iloc[0] - t_lock) < 1e-9


def test_the_element_listing_names_a_file_s_component_types(tmp_path, cone):
    """Driveline.elements: a component of a file is listed with its file's type (the cone clutch, built by the
    network's clutch), its flanges and its describe() line."""
    path = tmp_path / "cone.toml"
    path.write_text(CONE)
    d = load_driveline(path).driveline
    (e,) = d.elements
    assert (e.name, e.kind, e.flange_a, e.flange_b, e.support) == ("c", "cone_clutch", "J1", "J2", None)
    assert "  " + e.summary in d.describe().splitlines()
    direct = Driveline("cone").inertia("J1", J1, w0=W0).inertia("J2", J2)
    cone_clutch.CONE_CLUTCH.build(direct, "c", a="J1", b="J2", force=F, r_mean=R)
    assert direct.elements[0].kind == "clutch"   # built through the method: the method's name
    # changed in a copy (Driveline.replace: through the method it built with, its arguments): still a cone clutch
    twice = d.replace("c", cgeo=2.0 * e.arguments["cgeo"])
    assert twice.elements[0].kind == "cone_clutch" and twice.elements[0].arguments["cgeo"] == 2.0 * e.arguments["cgeo"]


def test_a_flat_disc_is_the_networks_clutch(tmp_path, cone):
    """alpha = 90 deg: the cone is a disc, T = mu F r_m: the network's own clutch with cgeo = r_m."""
    path = tmp_path / "cone.toml"
    path.write_text(CONE.replace('alpha = "12 deg"', 'alpha = "90 deg"'))
    a = load_driveline(path).driveline.simulate(0.4, output_step=1e-3, rtol=1e-10).to_dataframe()
    d = Driveline("disc")
    d.inertia("J1", J1, w0=W0).inertia("J2", J2).clutch("c", "J1", "J2", fn_max=F, mu=MU, cgeo=R)
    b = d.simulate(0.4, output_step=1e-3, rtol=1e-10).to_dataframe()
    for col in ("J1.w_rad_s", "J2.w_rad_s", "c.tau_Nm", "c.dissipated_J"):
        np.testing.assert_allclose(a[col], b[col], rtol=1e-12, atol=1e-12, err_msg=col)


SWEEP = """
[sweep]
model = "driveline"
scenario = "cone.toml"
outputs = ["c.last_stick_s", "c.dissipated_J", "J2.w_final_rad_s", "c.peak_tau_Nm"]
chunk_size = 2

[grid]
"c.alpha" = ["10 deg", "15 deg"]
"c.r_mean" = ["40 mm", "60 mm"]
"""


def test_a_sweep_over_the_cone_in_worker_processes_follows_the_closed_form(tmp_path, capsys, cone):
    """Two worker processes (spawned: they import the modules of the parent's registered components)."""
    (tmp_path / "cone.toml").write_text(CONE)
    (tmp_path / "sweep.toml").write_text(SWEEP)
    out = tmp_path / "res"
    assert main(["sweep", str(tmp_path / "sweep.toml"), "-o", str(out), "--workers", "2", "--no-progress",
                 "--no-plot"]) == 0
    frame = pd.read_parquet(out / "results.parquet")
    assert len(frame) == 4
    for row in frame.to_dict("records"):
        t_lock = lock_time(r_mean=row["c.r_mean"], alpha=row["c.alpha"])
        assert abs(row["c.last_stick_s"] - t_lock) < 1e-8, row
        assert row["c.peak_tau_Nm"] == pytest.approx(MU * F * row["c.r_mean"] / math.sin(row["c.alpha"]), rel=1e-9)
        assert row["J2.w_final_rad_s"] == pytest.approx(J1 * W0 / (J1 + J2), rel=1e-9)
        assert row["c.dissipated_J"] == pytest.approx(W0**2 * J1 * J2 / (2 * (J1 + J2)), rel=1e-8)
    # a value outside the declared range is refused before anything runs, naming it and the range
    capsys.readouterr()
    (tmp_path / "bad.toml").write_text(SWEEP.replace('"c.alpha" = ["10 deg", "15 deg"]', '"c.alpha" = ["100 deg"]'))
    err = one_line_error(capsys, ["sweep", str(tmp_path / "bad.toml"), "-o", str(tmp_path / "bad"), "--no-progress"])
    assert "c.alpha" in err and "above its range (0, 1.5708] rad" in err


def test_the_cone_clutch_linearises_in_its_two_modes(tmp_path, cone):
    """A load torque on J1 (a network input): locked, the pair is one inertia, 1 / ((J1 + J2) s) to either
    speed; slipping (constant mu), the clutch torque does not depend on the speeds, so J1 alone answers,
    1 / (J1 s), and J2 not at all."""
    import control as ct

    from clutchlab.control import linearize

    text = CONE.replace("[inertia.J2]", "[torque.load]\nflange = \"J1\"\ntorque = { input = \"load\" }\n\n"
                                        "[input.load]\nstart = \"1 N m\"\n\n[inertia.J2]")
    for w2, want in ((W0, {"J1.w": 1 / (J1 + J2), "J2.w": 1 / (J1 + J2)}), (0.0, {"J1.w": 1 / J1, "J2.w": 0.0})):
        path = tmp_path / "lin.toml"
        path.write_text(text.replace(f'[inertia.J2]\nJ = "{J2} kg m^2"', f'[inertia.J2]\nJ = "{J2} kg m^2"\n'
                                                                         f'w0 = "{w2} rad/s"'))
        system = load_driveline(path).driveline.system(1e-10)
        lin = linearize(system, inputs=["load"], outputs=["J1.w", "J2.w"])
        assert set(lin.mode.values()) == ({"stuck"} if w2 == W0 else {"backward"}), lin.mode
        for i, (name, gain) in enumerate(want.items()):
            # an integrator: s G(s) is the gain at every frequency
            for s in (0.1j, 10j):
                got = complex(ct.evalfr(lin[i, 0], s)) * s
                assert abs(got - gain) < 1e-6 * max(1.0, abs(gain)), (name, s, got, gain)


def test_a_component_of_an_installed_package_is_found_by_its_entry_point(tmp_path, monkeypatch):
    """The entry-point group clutchlab.components: a package's dist-info names the declaration; nothing is
    registered by hand."""
    site = tmp_path / "site"
    info = site / "clutchlab_cone_example-1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: clutchlab-cone-example\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text("[clutchlab.components]\ncone_clutch = cone_clutch:CONE_CLUTCH\n")
    monkeypatch.syspath_prepend(str(site))
    monkeypatch.setattr(C, "_ENTRY_POINTS_READ", False)
    C.unregister_component("cone_clutch")
    try:
        assert C.component("cone_clutch") is cone_clutch.CONE_CLUTCH
        spec = parse_driveline(__import__("tomllib").loads(CONE), str(tmp_path / "cone.toml"))
        assert "c" in spec.driveline.friction_names
    finally:
        C.unregister_component("cone_clutch")
    (info / "entry_points.txt").write_text("[clutchlab.components]\nbroken = cone_clutch:NOTHING\n")
    monkeypatch.setattr(C, "_ENTRY_POINTS_READ", False)
    with pytest.raises(ParameterError, match=r"entry point broken = 'cone_clutch:NOTHING'.*does not load"):
        C.components()
    monkeypatch.setattr(C, "_ENTRY_POINTS_READ", True)


# ---- the declarations agree with the network: a value in its declared range is one the component takes

from hypothesis import HealthCheck, given, settings, strategies as st  # noqa: E402

from hypothesis_budget import examples, pinned  # noqa: E402

#: kinds whose fields are all numbers, signals and flanges (the others need files, tables or maps)
SIMPLE = ("spring_damper", "backlash", "gear", "torque", "clutch", "brake", "bearing_friction", "one_way_clutch")


def _value(f):
    lo = f.minimum if f.minimum is not None else (1e-6 if f.positive else -1e3)
    hi = f.maximum if f.maximum is not None else max(lo, 0.0) + 1e3
    if f.positive:
        lo = max(lo, 1e-6)
    return st.floats(min_value=lo, max_value=hi, allow_nan=False)


@st.composite
def declared_tables(draw):
    """A driveline file with one component of a simple kind whose numeric fields are drawn from their declared
    ranges (J1 and J2 both at rest, so a one-way clutch starts legally)."""
    comp = C.component(draw(st.sampled_from(SIMPLE)))
    table = {}
    for f in comp.fields:
        if f.name in ("radius", "temperature"):
            continue   # where a friction map is read: they go with mu_map (a file), refused without one
        if f.kind == "flange":
            table[f.name] = {"a": "J1", "b": "J2", "flange": "J1"}.get(f.name, "ground")
        elif f.is_numeric and f.kind != "signal" and (f.required or draw(st.booleans())):
            table[f.name] = draw(_value(f))
        elif f.kind == "signal" and f.required:
            table[f.name] = draw(st.floats(-1e3, 1e3, allow_nan=False))
    return comp.kind, table


@settings(max_examples=examples(60), deadline=None, derandomize=pinned(),
          suppress_health_check=[HealthCheck.too_slow])
@given(declared_tables())
def test_every_value_in_a_declared_range_is_taken_by_the_component(spec):
    """What a declaration accepts, the component accepts: a sweep or an FMU's importer given a value within the
    published range (the FMU's min and max) never meets a refusal the range did not announce.  (A gear's ratio
    must also be non-zero: its one condition that is not a range, named by the network.)"""
    kind, table = spec
    doc = {"inertia": {"J1": {"J": 1.0}, "J2": {"J": 2.0}}, kind: {"x": table}}
    try:
        net = parse_driveline(doc, "random.toml").driveline
    except ParameterError as exc:
        assert kind == "gear" and table["ratio"] == 0.0, (kind, table, exc)
        return
    net.system(1e-8)   # and it packs


def test_each_kinds_layout_names_every_switching_function_of_the_kernel():
    """The network's switching functions are named and given their directions from the kernel's declarations, one
    entry per function the kernel writes (``FRICTION_LAYOUT`` beside ``FRICTION_SWITCHING``, and the gear's and the
    engine's): a function added to one and not the other would shift every name after it."""
    from clutchlab.driveline import kernel as K

    for layout, functions in ((K.FRICTION_LAYOUT, K.FRICTION_SWITCHING), (K.GEAR_LAYOUT, K.GEAR_SWITCHING),
                              (K.ENGINE_LAYOUT, K.ENGINE_SWITCHING), (K.BACKLASH_LAYOUT, K.SPRING_SWITCHING),
                              (K.CURVE_LAYOUT, K.SPRING_SWITCHING)):
        assert len(layout) == len(functions), (layout, functions)
        assert all(d in (-3, -2, -1, 0, 1, 4, 5) for _, d in layout)
    d = (Driveline("names").inertia("J0", 1.0).inertia("J1", 1.0)
         .clutch("c", "J0", "J1", fn_max=1.0).gear("g", "J0", "J1", 2.0, efficiency=0.9)
         .engine("e", "J0", [[0.0, 10.0], [100.0, 20.0]]))
    names = [n for n, _ in d.system(1e-8).switching]
    assert names[:6] == ["c.stick", "c.breakaway", "c.normal", "c.turn", "c.near", "c.row"]
    assert names[-7:] == ["g.stick", "g.quadrant", "g.turn", "g.piece", "e.speed_row", "e.throttle_row", "e.idle_clip"]
    springs = (Driveline("springs").inertia("J0", 1.0).inertia("J1", 1.0).inertia("J2", 1.0)
               .backlash("k", "J0", "J1", c=10.0, b_gap=0.1).spring("s", "J1", "J2", [[-1.0, -2.0], [0.0, 0.0], [1.0, 3.0]]))
    assert springs.system(1e-8).switching == (
        ("k.gap_upper", -2), ("k.gap_lower", -2), ("k.turn", 1), ("k.near", 5),
        ("s.segment_below", -1), ("s.segment_above", -1), ("s.turn", -1), ("s.near", -3))
