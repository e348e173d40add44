"""Compiled numerical building blocks shared by the subsystem kernels.

numba cannot cache a kernel that receives another compiled function as an
argument (the dispatcher type is new in every process), so each subsystem
writes its own integration loop around its own right-hand side and uses the
cached pieces here: the Dormand-Prince 5(4) tableau, the error norm, the step
controller and the dense-output interpolant used to locate events.
"""

from .dopri import (
    A21, A31, A32, A41, A42, A43, A51, A52, A53, A54, A61, A62, A63, A64, A65,
    B1, B3, B4, B5, B6, C2, C3, C4, C5, E1, E3, E4, E5, E6, E7,
    error_norm, next_step, dense_hermite, initial_step,
)

__all__ = [
    "error_norm", "next_step", "dense_hermite", "initial_step",
]

#: LLVM fast-math flags for the hot kernels: reassociation, contraction (FMA), reciprocal and
#: approximate functions, no signed zeros -- but *not* 'nnan'/'ninf', so NaN and infinity checks
#: (infeasible targets, NaN lock-up times) keep their meaning.
FASTMATH = {"reassoc", "contract", "arcp", "afn", "nsz"}
