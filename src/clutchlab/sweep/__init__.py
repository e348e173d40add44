"""Parameter sweeps of any clutchlab model: grid or Monte Carlo, in resumable Parquet chunks.

- :func:`load_spec` -- read and validate a sweep spec TOML, build the deterministic design
- :func:`run_sweep` -- run (or resume) it locally, in worker processes or on a Dask cluster
- :func:`read_results`, :func:`summarize` -- read a results folder, statistics per output
- :func:`available_targets`, :func:`register_target` -- the targets a spec may name: built-in,
  registered in this process, or installed plugins (entry points ``clutchlab.sweep_targets``);
  a spec never names code

See ``docs/sweeps.md``.
"""

from .targets import BUILTIN, ENTRY_POINT_GROUP, Target, available_targets, register_target, resolve_target, \
    unregister_target
from .spec import SweepSpec, load_spec, spec_from_dict
from .runner import SweepResult, compute_chunk, read_results, run_sweep, summarize

__all__ = [
    "BUILTIN",
    "ENTRY_POINT_GROUP",
    "Target",
    "available_targets",
    "register_target",
    "unregister_target",
    "resolve_target",
    "SweepSpec",
    "load_spec",
    "spec_from_dict",
    "SweepResult",
    "run_sweep",
    "read_results",
    "summarize",
    "compute_chunk",
]
