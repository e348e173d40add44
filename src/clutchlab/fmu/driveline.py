"""A driveline network as a co-simulation slave (FMI 2.0 co-simulation semantics, :mod:`clutchlab.fmu`).

``clutchlab export-fmu driveline FILE.toml`` builds an FMU of the network that a driveline description
(:mod:`clutchlab.driveline.description`) describes.  The co-simulation is a
:class:`~clutchlab.fmu.cosim.ContractCoSimulation` of the :class:`~clutchlab.system.System` that
:meth:`Driveline.system <clutchlab.driveline.network.Driveline.system>` returns: each ``do_step``
continues the integrator core's run (``clutchlab.system.Simulation.advance``) from the stored angles,
speeds, energies, friction modes and step size.  Its inputs are the network's (``[input.NAME]`` of the
file, read by its signals as ``{ input = "NAME" }``: a throttle, a clutch's normal-force command, a load
torque), held between communication points; a change restarts the run, so the stick/slip modes are
decided again with the new value.  Its outputs are every state and output column of the driveline; its parameters
are ``rtol``, ``solver.fixed_step`` (> 0: the core's fixed-step mode, a HIL frame; 0: step-size
control) and the numeric fields of its components, ``<component>.<field>``
(:class:`~clutchlab.driveline.variants.DrivelineDocument`).

::

    Cls = DrivelineCoSimulation.for_description("examples/driveline_coupled_clutches.toml")
    sim = Cls(**{"clutch1.fn_max": 25.0})
    y = sim.do_step(0.0, 1e-3, {})      # {"J1.w": ..., "clutch1.tau": ..., "clutch1.mode": ..., ...}
    # a file with [input.throttle]: sim.do_step(t, dt, {"throttle": 0.4})
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..system import check_rtol
from ..fmu.cosim import (ContractCoSimulation, Variable, fixed_step_parameter, fixed_step_variable,
                         fmi_unit, rtol_variable)
from ..units import COLUMN_UNITS
from ..driveline.variants import DrivelineDocument

__all__ = ["DrivelineCoSimulation"]


def _fmi_unit(suffix: str) -> str:
    """FMI unit of a column suffix (``"rad_s"`` -> ``"rad/s"``, ``"Nm"`` -> ``"N.m"``)."""
    return fmi_unit(COLUMN_UNITS[suffix][0])


class DrivelineCoSimulation(ContractCoSimulation):
    """A driveline network described in a TOML file, stepped by a co-simulation master.

    Build the class of one file with :meth:`for_description`; this base class has no variables.
    Outputs: every column of the driveline -- the angle ``<inertia>.phi`` [rad] and speed
    ``<inertia>.w`` [rad/s] of each inertia, the work ``<source>.work`` of each source and the energy
    ``<element>.dissipated`` [J] dissipated in each other element, the torque ``<element>.tau`` [N.m]
    of each element and the relative speed ``<element>.w_rel`` [rad/s] of each non-source, the mode
    ``<friction>.mode`` (MSL codes: 1 forward, 0 stuck, -1 backward, 2 free) and normal force
    ``<friction>.fn`` [N] of each friction element, and the network's ``kinetic_energy``,
    ``spring_energy``, ``input_work``, ``dissipated_energy`` and ``energy_error`` [J].  Parameters:
    ``rtol`` (start: the file's ``[simulation] rtol``), ``solver.fixed_step`` [s] (start 0: step-size
    control; a step > 0 runs the core's fixed-step mode, Rodas3 steps on the grid ``k * fixed_step`` with
    the mode changes at step ends, a HIL frame) and every numeric component field,
    ``<component>.<field>`` in SI (``J1.J`` [kg.m2], ``J1.w0`` [rad/s], ``clutch1.fn_max`` [N],
    ``clutch1.mu`` [1], ...).  Inputs: the network's (:meth:`Driveline.input
    <clutchlab.driveline.network.Driveline.input>`), in SI, starting at their ``start`` values.

    Parameters
    ----------
    **parameter_values
        Parameter values by name (SI); the others keep the file's values.

    Notes
    -----
    The integration stops at every communication point, so a chain of steps differs from one
    :meth:`Driveline.simulate <clutchlab.driveline.network.Driveline.simulate>` run of the same
    file by the integration error (of order ``rtol``), not more; events inside a step are located as
    in that run (``events()`` of :attr:`simulation`).  In fixed-step mode the steps lie on the grid
    ``k * solver.fixed_step`` whatever the communication step (a communication point off the grid ends
    with a shorter step) and a mode change inside a step is taken at its end.
    """

    name = "driveline"
    description_file = "a driveline description (TOML, docs/driveline.md)"
    #: the description of the class built by :meth:`for_description` (None on this base class)
    document: DrivelineDocument | None = None
    #: the file's :class:`~clutchlab.driveline.description.DrivelineFile` (None on this base class)
    base = None

    @classmethod
    def for_description(cls, path, *, within=None) -> type:
        """The co-simulation class of the driveline described in the file at ``path``.

        Parameters
        ----------
        path : str or Path
            A driveline description (TOML).  The files it names (an E-clutch's or a wet clutch's
            parameter files) are read relative to its folder.
        within : str or Path, optional
            A folder that every file the description names must be in: the FMU passes its
            ``resources`` folder, so an FMU reads only the copies it carries.

        Returns
        -------
        type
            A subclass whose ``outputs`` and ``parameters`` are those of that driveline and whose
            ``experiment`` is the file's ``[simulation]`` ``t_end`` and ``output_step`` (default
            1 s and 1 ms).

        Raises
        ------
        ParameterError
            The file is not a valid driveline description, or names a file that does not exist (or lies
            outside ``within``) -- naming the file, key and value.
        """
        doc = DrivelineDocument.read(path)
        doc.referenced_files(within=within)  # every file it names is there (and inside within), before any is read
        base = doc.load()
        system = base.driveline.system(base.rtol)
        outputs = tuple(Variable(v.name, _fmi_unit(v.unit), 0.0, v.description)
                        for v in (*system.states, *system.outputs))
        inputs = tuple(Variable(v.name, _fmi_unit(v.unit), float(u), v.description)
                       for v, u in zip(system.inputs, system.u0 if system.inputs else ()))
        # (an initial speed the file leaves out that follows another through gears or a motion source is the
        # network start's to derive, kernel.derive_speeds: the host sets the speed it follows, not it)
        derived = {f"{nm}.{'v0' if base.driveline.domain == 'translational' else 'w0'}"
                   for nm in base.driveline.derived_speeds()}
        parameters = (rtol_variable("rtol", base.rtol, "relative tolerance of the Dormand-Prince 5(4) step control "
                                                     "([simulation] rtol)"),
                      fixed_step_variable(),
                      *(Variable(p.name, fmi_unit(p.unit), p.value, p.description, p.minimum, p.maximum, p.positive)
                        for p in doc.parameters.values() if p.name not in derived))
        names = [v.name for v in (*inputs, *outputs, *parameters)]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise ParameterError(f"{path}: {twice[0]!r} would name two FMU variables (rename that component)")
        experiment = (base.t_end if base.t_end is not None else 1.0,
                      base.output_step if base.output_step is not None else 1e-3)
        return type(f"{cls.__name__}[{base.driveline.name}]", (cls,),
                    {"document": doc, "base": base, "inputs": inputs, "outputs": outputs, "parameters": parameters,
                     "experiment": experiment, "__module__": cls.__module__, "__doc__": cls.__doc__})

    def __init__(self, **parameter_values):
        if self.document is None:
            raise ParameterError("DrivelineCoSimulation: build the class of a file first, "
                                 "DrivelineCoSimulation.for_description(path)")
        values = self.resolve_parameters(parameter_values)
        check_rtol(values["rtol"], "parameter rtol")
        self.fixed_step = fixed_step_parameter(values)
        self.simulation_options = {"fixed_step": self.fixed_step}
        if self.base.max_step is not None:
            self.simulation_options["max_step"] = self.base.max_step
        super().__init__(**parameter_values)

    # ---- the contract
    def build_system(self, values: dict):
        """The driveline's System with the parameter ``values`` (by name, SI) in place of the file's."""
        changes = {p.name: values[p.name] for p in self.document.parameters.values()
                   if p.name in values and values[p.name] != p.value}
        spec = self.document.load(changes) if changes else self.base
        system = spec.driveline.system(values["rtol"])
        return system

    def input_vector(self, inputs: dict) -> np.ndarray:
        """The network's held inputs ``u`` (SI, in the order of :attr:`inputs`)."""
        return np.array([float(inputs[v.name]) for v in self.inputs], dtype=float)

    def output_sources(self) -> list:
        """Every state and then every output of the driveline (the order of :attr:`outputs`)."""
        return ([("state", i) for i in range(len(self.system.states))]
                + [("output", i) for i in range(len(self.system.outputs))])
