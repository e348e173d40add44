"""The integrator core and its compiled building blocks.

:mod:`clutchlab.numerics.core` holds the one hybrid integrator every model runs on
(Dormand-Prince 5(4) and Rodas3 with events, resumable stepping and the batch
runner, ``docs/architecture.md``); :mod:`~clutchlab.numerics.dispatch` registers
a model's compiled hooks and :mod:`~clutchlab.numerics.entry` generates its cached
entry points.  The pieces exported here: the Dormand-Prince tableau's error norm,
step controller, dense output (cubic Hermite and its order-4 term) and the
first step; a grid bracketing helper.
"""

from .. import _cache, _compile_notice

_compile_notice.install()  # one stderr line when kernels are compiled (never at import); every compiled module
# imports this package (its interpolation and step helpers), so the notice is in place before any compilation
_cache.guard_stale_indexes()  # an index an older clutchlab cached with classes since renamed is a miss, not a crash
_cache.guard_cross_module_constants()  # a kernel is compiled again when a module it imports changes

from .dopri import dense_correction, dense_hermite, error_norm, initial_step, next_step  # noqa: E402
from .interp import bracket  # noqa: E402

__all__ = ["error_norm", "next_step", "dense_hermite", "dense_correction", "initial_step", "bracket", "FASTMATH"]

#: LLVM fast-math flags for the hot kernels: reassociation, contraction (FMA), reciprocal and
#: approximate functions, no signed zeros -- but *not* 'nnan'/'ninf', so NaN and infinity checks
#: (infeasible targets, NaN lock-up times) keep their meaning.
FASTMATH = {"reassoc", "contract", "arcp", "afn", "nsz"}
