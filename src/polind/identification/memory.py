"""The memory an identification holds per sample of its data, estimated before it runs.

The command line multiplies it by the rows of a data file to refuse a fit
before reading the file; :func:`polind.identify` checks it against the limit
of :mod:`polind.resources`.
"""

from __future__ import annotations

import os

import numpy as np

from polind.identification.parameters import param_value
from polind.models import FrictionModel

__all__ = ["fit_bytes_per_sample"]

# What a fit holds per sample of the data [bytes] (tracemalloc's peak: 528 bytes at 8 free
# values, 1873 at 32): the data's checked copies and paths, one simulation with its
# residual on each Jacobian thread, and per free value the Jacobian's column, its stacked
# copy and the solver's scaled copies and factors.
_FIT_BYTES = 96.0
_FIT_BYTES_PER_THREAD = 40.0
_FIT_BYTES_PER_VALUE = 64.0


def fit_bytes_per_sample(model: FrictionModel, free) -> float:
    """The memory :func:`identify` holds per sample of the data [bytes], an estimate.

    ``model`` and ``free`` as :func:`parse_fit` returns them: each free key
    counts its values (an element list each element), and the Jacobian's
    threads are counted as if every core ran one.
    """
    values = sum(np.atleast_1d(np.asarray(param_value(model.params, key))).size for key in free)
    threads = max(1, min(os.cpu_count() or 1, values))
    return _FIT_BYTES + _FIT_BYTES_PER_THREAD * threads + _FIT_BYTES_PER_VALUE * values
