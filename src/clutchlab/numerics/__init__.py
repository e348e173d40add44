"""Compiled numerical building blocks shared by the subsystem kernels.

numba cannot cache a kernel that receives another compiled function as an
argument (the dispatcher type is new in every process), so each subsystem
writes its own integration loop around its own right-hand side and uses the
cached pieces here: the Dormand-Prince 5(4) tableau, the error norm, the step
controller and the dense-output interpolant used to locate events.
"""

from .dopri import dense_hermite, error_norm, initial_step, next_step
from .interp import bracket

__all__ = ["error_norm", "next_step", "dense_hermite", "initial_step", "bracket", "FASTMATH"]

#: LLVM fast-math flags for the hot kernels: reassociation, contraction (FMA), reciprocal and
#: approximate functions, no signed zeros -- but *not* 'nnan'/'ninf', so NaN and infinity checks
#: (infeasible targets, NaN lock-up times) keep their meaning.
FASTMATH = {"reassoc", "contract", "arcp", "afn", "nsz"}
