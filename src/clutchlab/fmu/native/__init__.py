"""Native FMUs: a clutchlab model as an FMI 2.0 FMU (co-simulation and model exchange) or an FMI 3.0 one
(co-simulation) with nothing of Python on the importing machine.

``clutchlab export-fmu MODEL [NETWORK.toml] -o X.fmu`` (:func:`export_native_fmu`) builds, from the model's
co-simulation class (a :class:`~clutchlab.fmu.cosim.CoSimulation` on the system contract, ``native = True``:
every driveline's, the EMTC's, the E-clutch's and the wet bench's, whose variables come from the component
declarations and parameter sets), a shared library per platform that holds

* the object code of the model's compiled session -- the integrator core with the model's equations, the
  same functions, compiled by the same numba, that run the model in Python -- and of its model-exchange
  entry (:mod:`clutchlab.numerics.exchange`) (:mod:`.codegen`);
* two *images* of the session: its parameters, state, modes, inputs, options and buffers as bytes, copied
  into each instance, one for co-simulation and one for model exchange (:mod:`.image`);
* numba's runtime (``nrt.cpp``) and the FMI 2.0 layer (``fmi2_native.c``, whose end includes the FMI 3.0
  entry points ``fmi3_native.c``: adapters onto the FMI 2.0 functions) with the generated tables of the
  model's variables (``model.h``) (:mod:`.toolchain`).

So a co-simulation step of the FMU is the step of ``clutchlab`` itself: the results equal the Python
co-simulation's at the same communication points; in model exchange the host's solver calls the model's own
hooks, and the FMU solves a model's algebraic states (the E-clutch's massless tip) at every evaluation, so the
host sees an ODE.  What the importing tool needs: nothing (the library links only the C library and libm).
Limits, stated in docs/fmu.md: parameters whose value the model stores other than as ``a * value + b`` or
``a / value + b`` (an initial speed that decides a start mode, a number derived from several parameters)
are fixed at export (``variability="constant"``); the FMI 3.0 FMU is for co-simulation.
"""

from __future__ import annotations

import dataclasses
import datetime
import hashlib
import io
import re
import tempfile
import uuid
import warnings
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

from ...errors import ClutchlabError, ParameterError
from ...numerics.layout import indices
from ...system import start_checked_later
from .image import NativeExportError, accepted_range, law_holds, parameter_map, session_image, word_indices

__all__ = ["export_native_fmu", "NativeExportError", "native_identifier", "PLATFORMS", "FMI_VERSIONS"]

#: the platforms a native FMU can carry
PLATFORMS = ("linux64", "win64")

#: the roles of a native FMU's variables (its C layer gets them as #defines)
ROLES = ("parameter", "constant", "input", "output", "state", "derivative")
_PARAMETER, _CONSTANT, _INPUT, _OUTPUT, _STATE, _DERIVATIVE = indices(
    ROLES, "parameter", "constant", "input", "output", "state", "derivative")


def native_identifier(name: str) -> str:
    """The FMI model identifier (and the library's name) of a model or network called ``name``: ``Clutchlab_``
    and the name with every character outside ``[A-Za-z0-9_]`` replaced by ``_``."""
    ident = re.sub(r"[^A-Za-z0-9_]", "_", str(name)) or "model"
    return "Clutchlab_" + ident


def _model_identifier(model: str) -> str:
    """A registered model's FMI identifier, as its pythonfmu FMU has it (``"emtc"`` -> ``"ClutchlabEmtc"``)."""
    from ..export import model_identifier
    from ..registry import COSIMULATIONS

    return model_identifier(model) if model in COSIMULATIONS else native_identifier(model)


def _c_string(text: str) -> str:
    out = []
    for ch in str(text).encode("utf-8"):
        if ch in (0x22, 0x5C):
            out.append("\\" + chr(ch))
        elif 0x20 <= ch < 0x7F and ch != 0x3F:   # (no '?': no trigraphs)
            out.append(chr(ch))
        else:
            out.append(f"\\{ch:03o}")
    return '"' + "".join(out) + '"'


def _c_double(x: float) -> str:
    return repr(float(x)) if x == x and abs(x) != float("inf") else "0.0"


def _range_text(var) -> str:
    lo, hi = var.fmi_bounds
    left = "(" if var.positive else "["
    return f"{left}{'-inf' if lo is None else f'{lo:g}'}, {'inf' if hi is None else f'{hi:g}'}]"


def _unit(unit: str) -> str:
    """A column suffix's FMI unit (``"rad_s"`` -> ``"rad/s"``), or the unit itself."""
    from ...units import COLUMN_UNITS
    from ..cosim import fmi_unit

    return fmi_unit(COLUMN_UNITS[unit][0]) if unit in COLUMN_UNITS else fmi_unit(unit) if unit else ""


def _bind(image, variables, maps) -> tuple:
    """Per variable, where it lives in ``image`` (``(offset, first target, number of targets)``), and the
    targets; ``maps``: name -> targets in this image (parameters and inputs)."""
    x, r = image.arg("x"), image.arg("r")
    dx = image.arg("dx") if "dx" in image.names else None
    x_span = (image.offset(x), image.offset(x) + x.nbytes) if x.size else (0, 0)
    bindings, targets = [], []
    vr = {v["name"]: k for k, v in enumerate(variables)}
    for v in variables:
        kind = v["kind"]
        offset, first, n = 0, len(targets), 0
        if kind in (_PARAMETER, _INPUT):
            ts = maps[v["name"]] or ()
            # an input that also sets a state (the wet bench's actuator force starts at its reference) sets it
            # only until initialisation ends, as the model's own run takes it at its start; a product's partner
            # by its value reference
            targets.extend((dataclasses.replace(t, initial=kind == _INPUT and x_span[0] <= t.offset < x_span[1]),
                            -1 if t.partner is None else vr[t.partner]) for t in ts)
            n = len(ts)
        if kind == _INPUT and v.get("bound_at"):   # (the word its range follows: cl_follows_bound)
            offset = word_indices(image, ((v["bound_path"], 0, 1),))[0] * 8
        elif kind == _OUTPUT:
            offset = image.offset(r, v["index"])
        elif kind == _STATE:
            offset = image.offset(x, v["index"])
        elif kind == _DERIVATIVE and dx is not None:
            offset = image.offset(dx, v["index"])
        bindings.append((offset, first, n))
    return bindings, targets


def _layout(tag, image, bindings, targets) -> list:
    from ...numerics.core import SF_T, SF_T0, SI_MODEL_CODE

    sf, si = image.arg("sf"), image.arg("si")
    data = image.data
    lines = [f"static const unsigned char cl_image_{tag}[{len(data)}] = {{"]
    for k in range(0, len(data), 32):
        lines.append("    " + ",".join(str(b) for b in data[k:k + 32]) + ",")
    lines.append("};")
    lines.append(f"static const uint64_t cl_reloc_{tag}[{max(len(image.relocations), 1)}][2] = {{")
    lines += [f"    {{{s}u, {t}u}}," for s, t in image.relocations] or ["    {0u, 0u},"]
    lines.append("};")
    lines.append(f"static const cl_target cl_targets_{tag}[{max(len(targets), 1)}] = {{")
    lines += [f"    {{{t.offset}u, {_c_double(t.a)}, {_c_double(t.b)}, {int(t.reciprocal)}, {int(t.initial)}, "
              f"{partner}}},"
              for t, partner in targets] or ["    {0u, 0.0, 0.0, 0, 0, -1},"]
    lines.append("};")
    lines.append(f"static const cl_binding cl_bindings_{tag}[{len(bindings)}] = {{")
    lines += [f"    {{{o}u, {f}, {n}}}," for o, f, n in bindings]
    lines.append("};")
    exchange = image.method == "exchange"
    x = image.arg("x")
    me = (f"{image.offset(x) if x.size else 0}u, {image.offset(image.arg('dx')) if x.size else 0}u, "
          f"{image.offset(image.arg('g0')) if image.arg('g0').size else 0}u, "
          f"{image.offset(image.arg('g1')) if image.arg('g1').size else 0}u, {image.offset(image.arg('out'))}u"
          if exchange else "0u, 0u, 0u, 0u, 0u")
    lines.append(f"static const cl_layout cl_layout_{tag} = {{cl_image_{tag}, {len(data)}u, cl_reloc_{tag}, "
                 f"{len(image.relocations)}u, {image.function_slots[0]}u, {image.function_slots[1]}u, "
                 f"{image.offset(sf, SF_T)}u, {image.offset(sf, SF_T0)}u, {image.offset(si, SI_MODEL_CODE)}u, "
                 f"{me}, cl_targets_{tag}, cl_bindings_{tag}, {int(exchange)}}};")
    return lines


def model_exchange_possible(image) -> bool:
    """Whether a model can be given to an external integrator: always, since the algebraic states of a model
    with zeros in its mass matrix (the E-clutch's massless nodes) are solved inside the FMU at every evaluation
    (:mod:`clutchlab.numerics.exchange`) and only the differential states are the host's."""
    return image.arg("x").size > 0


def state_nominals(image):
    """The typical magnitude of each state (FMI's ``nominal``, which a host scales its absolute tolerance by:
    FMPy's CVode takes ``rtol * nominal``): the model's own absolute tolerance over its relative one, so that a
    host weighs the states as the core does (``atol + rtol |x|``); the difference scale where that is zero."""
    import numpy as np

    opt = image.arg("opt")
    atol = np.broadcast_to(np.asarray(opt.atol, dtype=float), image.arg("x").shape)
    nominal = atol / opt.rtol if opt.rtol > 0 else np.zeros_like(atol)
    scale = np.asarray(opt.fd_scale, dtype=float)
    for i in np.flatnonzero(~(nominal > 0) | ~np.isfinite(nominal)):
        nominal[i] = scale[i] if i < scale.size and scale[i] > 0 else 1.0
    return [float(v) for v in nominal]


def differential_states(image):
    """The indices of the states with a derivative (a non-zero in the mass matrix): the FMU's continuous
    states, in this order."""
    import numpy as np

    return [int(i) for i in np.flatnonzero(np.asarray(image.arg("opt").mass) != 0.0)]


def _model_header(name, ident, guid, images, functions, variables, layouts, fixed_step, system,
                  step_grid_vr: int = -1) -> str:
    from ...numerics import exchange as X, status as st
    from ...numerics.session import ADVANCE, OUTPUTS, START
    from ...system import FIXED_STEP_BUDGET

    cs = images[0]
    exchange = len(images) > 1
    gdir = cs.arg("opt").gdir if exchange else cs.arg("opt").gdir[:0]
    lines = ["/* generated by clutchlab.fmu.native for one model; do not edit */", "#include <stddef.h>",
             "#include <stdint.h>",
             f"#define CL_MODEL_IDENTIFIER {_c_string(ident)}", f"#define CL_MODEL_NAME {_c_string(name)}",
             f"#define CL_GUID {_c_string(guid)}",
             f"#define CL_ADVANCE {ADVANCE}", f"#define CL_OUTPUTS {OUTPUTS}", f"#define CL_START {START}",
             f"#define CL_FIXED_STEP {_c_double(fixed_step)}", f"#define CL_FIXED_STEP_BUDGET {_c_double(FIXED_STEP_BUDGET)}",
             f"#define CL_STEP_GRID_VR {int(step_grid_vr)}",
             f"#define CL_STATUS_SUCCESS {st.SUCCESS}", f"#define CL_STATUS_TERMINATED {st.TERMINATED}",
             f"#define CL_STATUS_MODEL_ERROR {st.MODEL_ERROR}",
             f"#define CL_PARAMETER {_PARAMETER}", f"#define CL_CONSTANT {_CONSTANT}", f"#define CL_INPUT {_INPUT}",
             f"#define CL_OUTPUT {_OUTPUT}", f"#define CL_STATE {_STATE}", f"#define CL_DERIVATIVE {_DERIVATIVE}",
             f"#define CL_NVARIABLES {len(variables)}u",
             f"#define CL_NSTATES {len(differential_states(cs)) if exchange else 0}u",
             f"#define CL_ME_ALGEBRAIC_FAILED {X.ALGEBRAIC_FAILED}",
             f"#define CL_NINDICATORS {gdir.size}u", f"#define CL_HAS_ME {int(exchange)}",
             *(f"#define CL_{k} {getattr(X, k)}" for k in ("ME_DERIVATIVES", "ME_ACCEPT", "ME_EVENT", "ME_RESTART",
                                                         "ME_STORE", "ME_OUTPUTS", "ME_START")), ""]
    # the compiled functions (hidden symbols of the model's object code)
    lines += [f"extern int32_t cl_session_call(int64_t *, void **, void *, double, int64_t) "
              f"__asm__({_c_string(functions.session)});",
              f"extern int32_t cl_exchange_call(int64_t *, void **, void *, int64_t) "
              f"__asm__({_c_string(functions.exchange)});" if exchange else
              "static int32_t cl_exchange_call(int64_t *r, void **e, void *t, int64_t w) "
              "{ (void)r; (void)e; (void)t; (void)w; return -1; }   /* (no model exchange) */",
              f"extern char cl_advance_symbol[] __asm__({_c_string(functions.advance)});",
              f"extern char cl_outputs_symbol[] __asm__({_c_string(functions.outputs)});",
              "static void *cl_advance_address(void) { return (void *)cl_advance_symbol; }",
              "static void *cl_outputs_address(void) { return (void *)cl_outputs_symbol; }"]
    for k, (key, sym) in enumerate(sorted(functions.outlined.items())):
        lines.append(f"extern char cl_outlined_{k}[] __asm__({_c_string(sym)});")
    lines.append("static void *cl_outline_lookup(int64_t key) {")
    for k, (key, sym) in enumerate(sorted(functions.outlined.items())):
        lines.append(f"    if (key == (int64_t){key}LL) return (void *)cl_outlined_{k};")
    lines += ["    return NULL;", "}", ""]
    states = differential_states(cs) if exchange else []
    lines.append(f"static const uint32_t cl_states[{max(len(states), 1)}] = {{"
                 + (", ".join(f"{i}u" for i in states) or "0u") + "};   /* the host's states: the differential ones */")
    nominals = state_nominals(cs)
    lines.append(f"static const double cl_nominals[{max(len(states), 1)}] = {{"
                 + (", ".join(_c_double(nominals[i]) for i in states) or "1.0") + "};")
    lines.append("static const char *cl_status_message(int64_t code) {")
    for s_ in st.Status:
        lines.append(f"    if (code == {int(s_)}) return {_c_string(s_.message)};")
    lines += ['    return "unknown status";', "}", "static const char *cl_model_error(int64_t code) {",
              "    if (code == CL_ME_ALGEBRAIC_FAILED) return \"the algebraic equations (a massless node's force balance) "
              "could not be solved by Newton's method at the states the host set\";"]
    for code, text in sorted((getattr(system, "error_messages", None) or {}).items()):
        lines.append(f"    if (code == {int(code)}) return {_c_string(text)};")
    lines += ["    return NULL;", "}", ""]
    # which switching functions are events (a waypoint, |gdir| = 3 or 4, only guides the core's steps)
    lines.append(f"static const int cl_event_indicator[{max(gdir.size, 1)}] = {{"
                 + ", ".join(str(int(abs(int(d)) < 3)) for d in gdir) + ("" if gdir.size else "0") + "};")
    lines.append(f"static const int cl_gdir[{max(gdir.size, 1)}] = {{"
                 + ", ".join(str(int(d)) for d in gdir) + ("" if gdir.size else "0") + "};")
    lines += ["typedef struct { uint64_t offset; double a, b; int reciprocal, initial, partner; } cl_target;",
              "typedef struct { uint64_t offset; int first, ntargets; } cl_binding;",
              "typedef struct { const unsigned char *image; uint64_t bytes; const uint64_t (*reloc)[2]; uint64_t nreloc; "
              "uint64_t slot_advance, slot_outputs, off_time, off_t0, off_model_code, off_x, off_dx, off_g0, off_g1, off_out; "
              "const cl_target *targets; const cl_binding *bindings; int exchange; } cl_layout;",
              "typedef struct { const char *name; const char *unit; int kind; double start; int has_min, has_max, "
              "positive, whole; double min, max; const char *range_text; int bound_at; } cl_variable;"]
    for tag, image, (bindings, targets) in zip(("cs", "me"), images, layouts):
        lines += _layout(tag, image, bindings, targets)
    if not exchange:   # (never used: a model-exchange instantiation is refused)
        lines.append("#define cl_layout_me cl_layout_cs")
    lines.append(f"static const cl_variable cl_variables[{len(variables)}] = {{")
    for v in variables:
        lo, hi = v["bounds"]
        lines.append(f"    {{{_c_string(v['name'])}, {_c_string(v['unit'])}, {v['kind']}, {_c_double(v['start'])}, "
                     f"{int(lo is not None)}, {int(hi is not None)}, {int(v['positive'])}, {int(v.get('whole', False))}, "
                     f"{_c_double(lo if lo is not None else 0.0)}, {_c_double(hi if hi is not None else 0.0)}, "
                     f"{_c_string(v['range'])}, {int(v.get('bound_at', 0))}}},")
    lines.append("};")
    return "\n".join(lines) + "\n"


#: causality, variability and initial of each kind of variable (FMI 2.0 and 3.0 alike)
_CAUSALITY = {
    _PARAMETER: {"causality": "parameter", "variability": "fixed", "initial": "exact"},
    _CONSTANT: {"causality": "local", "variability": "constant", "initial": "exact"},
    _INPUT: {"causality": "input", "variability": "continuous"},
    _OUTPUT: {"causality": "output", "variability": "continuous", "initial": "calculated"},
    _STATE: {"causality": "local", "variability": "continuous", "initial": "calculated"},
    _DERIVATIVE: {"causality": "local", "variability": "continuous", "initial": "calculated"},
}


def _attributes(vr, v, nominal: bool) -> tuple:
    """``(variable, value)``: a variable's attributes (name, value reference, description, causality,
    variability, initial) and its value's (unit, nominal where ``nominal``, start, min, max)."""
    attrs = {"name": v["name"], "valueReference": str(vr)}
    if v["description"]:
        attrs["description"] = v["description"]
    attrs.update(_CAUSALITY[v["kind"]])
    value = {}
    if v["unit"]:
        value["unit"] = v["unit"]
    if nominal and "nominal" in v:
        value["nominal"] = repr(float(v["nominal"]))
    if v["kind"] in (_PARAMETER, _CONSTANT, _INPUT):
        value["start"] = repr(float(v["start"]))
        lo, hi = v["bounds"]
        if lo is not None:
            value["min"] = repr(float(lo))
        if hi is not None:
            value["max"] = repr(float(hi))
    return attrs, value


def _units_logs_experiment(root, variables, experiment, extra_units=()) -> None:
    """A model description's ``UnitDefinitions`` (of the variables' units and ``extra_units``), ``LogCategories``
    and ``DefaultExperiment`` (the same in FMI 2.0 and 3.0)."""
    from ..export import unit_definition

    units = sorted({v["unit"] for v in variables if v["unit"]} | set(extra_units))
    if units:
        ud = ET.SubElement(root, "UnitDefinitions")
        for u in units:
            ud.append(unit_definition(u))
    cats = ET.SubElement(root, "LogCategories")
    for c in ("logEvents", "logStatusDiscard", "logStatusError"):
        ET.SubElement(cats, "Category", {"name": c})
    stop, step = experiment
    ET.SubElement(root, "DefaultExperiment", {"startTime": "0", "stopTime": repr(float(stop)),
                                              "stepSize": repr(float(step))})


def _description(cls, name, ident, guid, variables, experiment, n_indicators, exchange=True) -> bytes:
    from ... import __version__

    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "2.0", "modelName": name, "guid": guid,
        "description": f"clutchlab {cls.name or 'model'} {name} (native FMU: no Python needed)",
        "generationTool": f"clutchlab {__version__} (native)",
        "generationDateAndTime": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "variableNamingConvention": "structured", "numberOfEventIndicators": str(n_indicators)})
    if exchange:
        ET.SubElement(root, "ModelExchange", {
            "modelIdentifier": ident, "completedIntegratorStepNotNeeded": "false",
            "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions": "true",
            "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true",
            "providesDirectionalDerivative": "false"})
    ET.SubElement(root, "CoSimulation", {
        "modelIdentifier": ident, "canHandleVariableCommunicationStepSize": "true",
        "canInterpolateInputs": "false", "maxOutputDerivativeOrder": "0", "canRunAsynchronuously": "false",
        "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions": "true",
        "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true",
        "providesDirectionalDerivative": "false"})
    _units_logs_experiment(root, variables, experiment)
    mv = ET.SubElement(root, "ModelVariables")
    outputs, derivatives, states = [], [], []
    for vr, v in enumerate(variables):
        attrs, real = _attributes(vr, v, nominal=exchange)
        if v["kind"] == _OUTPUT:
            outputs.append(vr + 1)
        elif v["kind"] == _DERIVATIVE:
            real["derivative"] = str(v["state_vr"] + 1)
            derivatives.append(vr + 1)
        sv = ET.SubElement(mv, "ScalarVariable", attrs)
        ET.SubElement(sv, "Real", real)
    ms = ET.SubElement(root, "ModelStructure")
    if outputs:
        out = ET.SubElement(ms, "Outputs")
        for i in outputs:
            ET.SubElement(out, "Unknown", {"index": str(i)})
    if derivatives:
        der = ET.SubElement(ms, "Derivatives")
        for i in derivatives:
            ET.SubElement(der, "Unknown", {"index": str(i)})
    init = ET.SubElement(ms, "InitialUnknowns")
    states = [v["state_vr"] + 1 for v in variables if v["kind"] == _DERIVATIVE and variables[v["state_vr"]]["kind"] == _STATE]
    for i in sorted(set(outputs) | set(derivatives) | set(states)):
        ET.SubElement(init, "Unknown", {"index": str(i)})
    ET.indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8")


def _description3(cls, name, ident, guid, variables, experiment) -> bytes:
    """The FMI 3.0 model description (co-simulation) of the same variables as :func:`_description`'s: Float64
    variables with the same value references, the independent variable ``time`` after them."""
    from ... import __version__

    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "3.0", "modelName": name, "instantiationToken": guid,
        "description": f"clutchlab {cls.name or 'model'} {name} (native FMU: no Python needed)",
        "generationTool": f"clutchlab {__version__} (native)",
        "generationDateAndTime": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "variableNamingConvention": "structured"})
    ET.SubElement(root, "CoSimulation", {
        "modelIdentifier": ident, "canHandleVariableCommunicationStepSize": "true",
        "canBeInstantiatedOnlyOncePerProcess": "false", "canGetAndSetFMUState": "true",
        "canSerializeFMUState": "true", "providesDirectionalDerivatives": "false",
        "providesAdjointDerivatives": "false", "hasEventMode": "false", "maxOutputDerivativeOrder": "0",
        "canReturnEarlyAfterIntermediateUpdate": "false", "providesIntermediateUpdate": "false"})
    _units_logs_experiment(root, variables, experiment, extra_units=("s",))
    mv = ET.SubElement(root, "ModelVariables")
    outputs = []
    for vr, v in enumerate(variables):
        if v["kind"] in (_STATE, _DERIVATIVE):   # (model exchange's: the FMI 3.0 FMU is for co-simulation)
            raise NativeExportError(f"{name}: {v['name']}: a state variable in an FMI 3.0 co-simulation FMU")
        attrs, value = _attributes(vr, v, nominal=False)
        attrs.update(value)   # (FMI 3.0: the value's attributes on the variable itself)
        if v["kind"] == _OUTPUT:
            outputs.append(vr)
        ET.SubElement(mv, "Float64", attrs)
    ET.SubElement(mv, "Float64", {"name": "time", "valueReference": str(len(variables)), "causality": "independent",
                                  "variability": "continuous", "description": "simulation time", "unit": "s"})
    ms = ET.SubElement(root, "ModelStructure")
    for vr in outputs:
        ET.SubElement(ms, "Output", {"valueReference": str(vr)})
    for vr in outputs:
        ET.SubElement(ms, "InitialUnknown", {"valueReference": str(vr)})
    ET.indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8")


#: FMI versions of a native FMU: the FMI 2.0 one has co-simulation and model exchange, the FMI 3.0 one
#: co-simulation (the same library: its FMI 3.0 functions adapt onto the FMI 2.0 ones, fmi3_native.c)
FMI_VERSIONS = ("2.0", "3.0")


def export_native_fmu(cls, path, *, overwrite: bool = False, platforms=None, name: str | None = None,
                      report=None, fmi_version: str = "2.0", _benchmark: bool = False) -> Path:
    """Build a native FMU of the co-simulation class ``cls``: FMI 2.0 co-simulation and model exchange, or
    FMI 3.0 co-simulation.

    Parameters
    ----------
    cls : type
        A co-simulation class with ``native = True`` (a driveline's:
        :meth:`DrivelineCoSimulation.for_description <clutchlab.fmu.driveline.DrivelineCoSimulation.for_description>`).
    path : path-like
        The ``.fmu`` file to write (atomically).
    overwrite : bool
        Replace an existing file.
    platforms : sequence of str, optional
        ``"linux64"``, ``"win64"``; default: linux64, and win64 where its cross compiler is installed.
    name : str, optional
        The model's name (default: the driveline's network name, else ``cls.name``).  The FMU's
        ``modelIdentifier`` (and its library's name) is :func:`native_identifier` of a network's name
        (``Clutchlab_coupled_clutches``), a registered model's as with pythonfmu (``ClutchlabEmtc``).
    report : callable, optional
        ``report(text)`` for one line on what was built (the CLI prints it).
    fmi_version : {"2.0", "3.0"}
        ``"2.0"`` (default): co-simulation and model exchange; ``"3.0"``: co-simulation, the library in
        ``binaries/x86_64-linux`` and ``binaries/x86_64-windows``.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    NativeExportError
        A compiler is missing for a platform asked for, the model's session has a form the native FMU does not
        know, an input reaches the model in a way the FMU cannot repeat, or a compilation failed (the message
        says which).
    ParameterError
        The path does not end in ``.fmu``, or exists and ``overwrite`` is false.
    """
    from ...io.files import atomic_write_bytes, check_writable
    from ..cosim import CoSimulation
    from .codegen import emit_object, session_functions
    from .toolchain import available_platforms, library_name, toolchain

    path = Path(path)
    if path.suffix.lower() != ".fmu":
        raise ParameterError(f"output {str(path)!r}: the file name must end in .fmu")
    check_writable(path, overwrite)
    if not (isinstance(cls, type) and issubclass(cls, CoSimulation) and cls.native):
        raise NativeExportError(f"{getattr(cls, '__name__', cls)!r}: a native FMU is built from a co-simulation "
                                "class on the system contract (CoSimulation.native; the wet clutch's is not yet)")
    if platforms is None:
        platforms = ["linux64"] + [p for p in available_platforms() if p != "linux64"]
    fmi_version = {"2": "2.0", "3": "3.0"}.get(str(fmi_version), str(fmi_version))
    if fmi_version not in FMI_VERSIONS:
        raise ParameterError(f"fmi_version {fmi_version!r}: expected one of {', '.join(FMI_VERSIONS)}")
    platforms = list(dict.fromkeys(platforms))
    for p in platforms:
        if p not in PLATFORMS:
            raise ParameterError(f"platform {p!r}: expected one of {', '.join(PLATFORMS)}")
    chains = [toolchain(p) for p in platforms]   # (a missing compiler is refused before anything is built)
    cls = cls.for_native()   # (a model whose buffers grow at run time starts with larger ones)
    base_obj = cls()
    base_obj.hold_inputs({})   # (a model that starts its run at the first inputs starts it here)
    network = getattr(getattr(getattr(cls, "base", None), "driveline", None), "name", None)
    if name is None:
        name = network or cls.name or "model"
    ident = native_identifier(name) if network is not None or name != cls.name else _model_identifier(cls.name)
    cs_image = session_image(base_obj.simulation)
    exchange = fmi_version == "2.0" and model_exchange_possible(cs_image)
    kinds = (False, True) if exchange else (False,)   # (images: co-simulation, model exchange)
    images = tuple(cs_image if not k else session_image(base_obj.simulation, exchange=True) for k in kinds)
    built = {}

    def build(parameters=None, inputs=None):
        """Both images of the model with these parameters and inputs (None: refused)."""
        key = (tuple(sorted((parameters or {}).items())), tuple(sorted((inputs or {}).items())))
        if key == ((), ()):   # (built afresh: two builds of the same values tell the model's uninitialised memory)
            built.pop(key, None)
        if key not in built:
            try:
                # (values far out: overflow warnings of a model that takes them; an initial state the model's start
                # refuses is refused by the FMU at its start, not by the ranges: start_checked_later)
                with warnings.catch_warnings(), start_checked_later():
                    warnings.simplefilter("ignore", RuntimeWarning)
                    obj = cls(**(parameters or {}))
                    obj.hold_inputs(inputs or {})
            except (ClutchlabError, ValueError, ArithmeticError):   # (refused, or a build that fails there)
                built[key] = None
            else:
                built[key] = tuple(session_image(obj.simulation, exchange=k) for k in kinds)
        return built[key]

    def pick(images_or_none, k):
        return None if images_or_none is None else images_or_none[k]

    where = [parameter_map(cls.parameters, images[k], lambda v, k=k: pick(build(parameters=v), k), cls.__name__,
                           one_sided=True) for k in range(len(kinds))]
    inputs_at = [parameter_map(cls.inputs, images[k], lambda v, k=k: pick(build(inputs=v), k), cls.__name__)
                 for k in range(len(kinds))]
    built.clear()
    for v in cls.inputs:
        if any(m[v.name] is None for m in inputs_at):
            raise NativeExportError(f"{cls.__name__}: input {v.name} reaches the model in a way a native FMU "
                                    "cannot repeat (not a * value + b)")
    # inputs whose range follows the parameters (the wet bench's actuator and drive limits): the model's number that
    # bounds each, read by the FMU from its memory (cl_follows_bound)
    followed = dict(getattr(base_obj, "input_bound_words", lambda: {})())
    functions = session_functions(images[0])
    if exchange:
        functions = functions.with_exchange(session_functions(images[1]))
    simulation = base_obj.simulation
    system = simulation.system
    fixed_step = float(simulation.fixed_step)
    variables = []
    # a parameter whose change reaches no number of the model (an engine's idle gains where it has no idle
    # controller): left out of the FMU, where a host's value would change nothing (the grid parameter the FMU's
    # own step logic reads stays)
    idle = [v.name for v in cls.parameters
            if all(m.get(v.name) == () for m in where) and v.name != cls.step_grid_parameter]
    for v in cls.parameters:
        if v.name in idle:
            continue
        writable = all(m.get(v.name) is not None for m in where)
        whole = False
        if writable and float(v.start).is_integer():
            # a whole number the model refuses halves of (a count of friction pairs): the FMU refuses them too
            half = float(v.start) + 0.5 if v.maximum is None or float(v.start) + 0.5 <= v.maximum else float(v.start) - 0.5
            whole = build(parameters={v.name: half}) is None
        if writable:
            # the interval the model accepts (where its own code refuses more than the declared range) and where
            # the laws found near the start hold (an absolute tolerance with a floor: rtol's range ends there)
            def takes(x, name=v.name):
                got = build(parameters={name: x})
                return got is not None and all(law_holds(images[k], where[k], got[k], {name: x})
                                               for k in range(len(kinds)))

            low, high = accepted_range(takes, float(v.start), v.minimum, v.maximum, v.positive, whole)
            built.clear()
            # (a positive one's lower end 0 is its strict > 0, already declared)
            minimum = v.minimum if low is None or v.positive and low == 0.0 else low
            maximum = v.maximum if high is None else high
            if (minimum, maximum) != (v.minimum, v.maximum):
                v = dataclasses.replace(v, minimum=minimum, maximum=maximum)
        variables.append({"name": v.name, "unit": v.unit, "start": float(v.start), "description": v.description,
                          "bounds": v.fmi_bounds, "positive": v.positive, "range": _range_text(v),
                          "kind": _PARAMETER if writable else _CONSTANT, "whole": whole})
    for v in cls.inputs:
        entry = {"name": v.name, "unit": v.unit, "start": float(v.start), "description": v.description,
                 "bounds": v.fmi_bounds, "positive": v.positive, "range": _range_text(v), "kind": _INPUT}
        if v.name in followed:   # (no max in the description: it follows a parameter a host may set)
            word, symmetric, label = followed[v.name]
            entry.update(bound_at=2 if symmetric else 1, bound_path=word, range=label,
                         bounds=(None, None) if symmetric else (v.fmi_bounds[0], None),
                         description=f"{v.description} (within " + (f"+-{label}" if symmetric else
                                                                     f"[{v.fmi_bounds[0]:g}, {label}]")
                         + ", a parameter the FMU checks it against)")
        variables.append(entry)
    r = images[0].arg("r")
    if r.shape[0] != len(cls.outputs):
        raise NativeExportError(f"{cls.__name__}: {r.shape[0]} reported values for {len(cls.outputs)} outputs")
    report_spec = images[0].arg("report")
    state_vr = {}
    for k, v in enumerate(cls.outputs):
        if int(report_spec[k, 0]) == 1 and int(report_spec[k, 1]) not in state_vr:   # (REPORT_STATE)
            state_vr[int(report_spec[k, 1])] = len(variables)
        variables.append({"name": v.name, "unit": v.unit, "start": 0.0, "description": v.description,
                          "bounds": (None, None), "positive": False, "range": "", "kind": _OUTPUT, "index": k})
    names = {v["name"] for v in variables}
    for i, sv in enumerate(system.states):   # the states no output reports: locals of their own
        if i not in state_vr:
            state_vr[i] = len(variables)
            label = f"state.{sv.name}" if f"state.{sv.name}" not in names else f"state[{i + 1}]"
            variables.append({"name": label, "unit": _unit(sv.unit), "start": 0.0, "description": sv.description,
                              "bounds": (None, None), "positive": False, "range": "", "kind": _STATE, "index": i})
    nominals = state_nominals(images[0])
    for i in differential_states(images[0]):   # (an algebraic state has none: the FMU solves it)
        state = variables[state_vr[i]]
        state["nominal"] = nominals[i]
        unit = f"{state['unit']}/s" if state["unit"] not in ("", "1") else "1/s"
        variables.append({"name": f"der({state['name']})", "unit": unit, "start": 0.0,
                          "description": f"time derivative of {state['name']}", "bounds": (None, None),
                          "positive": False, "range": "", "kind": _DERIVATIVE, "index": i, "state_vr": state_vr[i]})
    if not exchange:   # (no model exchange: no states and derivatives listed, no second image)
        variables = [v for v in variables if v["kind"] not in (_STATE, _DERIVATIVE)]
    layouts = [_bind(images[k], variables, {**where[k], **inputs_at[k]}) for k in range(len(kinds))]
    objects = {p: emit_object(functions, p) for p in platforms}
    digest = hashlib.sha256(b"".join(i.data for i in images) + repr([(v["name"], v["kind"]) for v in variables]).encode()
                            + b"".join(hashlib.sha256(o).digest() for o in objects.values()))
    guid = "{" + str(uuid.UUID(bytes=digest.digest()[:16])) + "}"
    # the grid a step's end snaps to (CoSimulation.step_grid_parameter): that parameter's current value
    grid = cls.step_grid_parameter
    step_grid_vr = -1 if grid is None else next((k for k, v in enumerate(variables) if v["name"] == grid), None)
    if step_grid_vr is None:
        raise NativeExportError(f"{cls.__name__}: step_grid_parameter {grid!r} is not one of its parameters")
    header = _model_header(name, ident, guid, images, functions, variables, layouts, fixed_step, system,
                           step_grid_vr)
    experiment = cls.experiment or (1.0, 1e-3)
    if fmi_version == "3.0":
        description = _description3(cls, name, ident, guid, variables, experiment)
    else:
        description = _description(cls, name, ident, guid, variables, experiment,
                                   images[1].arg("g1").size if exchange else 0, exchange)
    buf = io.BytesIO()
    with tempfile.TemporaryDirectory(prefix="clutchlab_native_") as tmp:
        tmp = Path(tmp)
        (tmp / "model.h").write_text(header)
        libs = {}
        for p, chain in zip(platforms, chains):
            folder = tmp / p
            folder.mkdir()
            obj = folder / "model.o"
            obj.write_bytes(objects[p])
            libs[p] = chain.link(folder, [obj], tmp / "model.h", ident, benchmark=_benchmark).read_bytes()
        with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("modelDescription.xml", description)
            for p, data in libs.items():
                info = zipfile.ZipInfo(library_name(p, ident, fmi_version), date_time=(2020, 1, 1, 0, 0, 0))
                info.external_attr = 0o755 << 16
                info.compress_type = zipfile.ZIP_DEFLATED
                z.writestr(info, data)
    if report is not None:
        n_fixed = sum(v["kind"] == _CONSTANT for v in variables)
        kind = "co-simulation and model exchange" if exchange else "co-simulation"
        report(f"native FMU {ident} ({', '.join(platforms)}; FMI {fmi_version} {kind}): "
               f"{len(cls.inputs)} inputs, {len(cls.outputs)} outputs, "
               f"{sum(v['kind'] == _PARAMETER for v in variables)} parameters ({n_fixed} fixed at export)"
               + (f"; left out, changing nothing in this model: {', '.join(idle)}" if idle else ""))
    return atomic_write_bytes(path, buf.getvalue(), overwrite=overwrite)
