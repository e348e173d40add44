"""Hysteresis operators: the classical Preisach model (forward, inverse, identification).

References
----------
.. [1] Electromagnetic hysteresis based dynamics model of an electromagnetic
   torque controlled coupling (EMTC), Processes 7 (2019) 557,
   doi:10.3390/pr7090557
"""

from .preisach import InverseResult, Preisach, PreisachState, forc_table_from_masses
from .identify import ForcIdentification, forc_input, identify_forc, identify_forc_family

__all__ = [
    "Preisach",
    "PreisachState",
    "InverseResult",
    "forc_table_from_masses",
    "ForcIdentification",
    "forc_input",
    "identify_forc",
    "identify_forc_family",
]
