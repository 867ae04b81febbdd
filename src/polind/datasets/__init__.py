"""The measured records polind's documentation uses, installed with the package.

Examples, tests and the documentation read their data here, never from a path
outside the project::

    from polind import datasets
    record = datasets.tribometer()          # {"t", "x", "F", "normal_load"}: s, m, N, N
    surface = datasets.height_map("x3p-2.x3p")   # a polind.topography.HeightMap [m]

- :func:`tribometer`: a reciprocating-tribometer record (ball on flat,
  strokes of 0.24 mm at 0.25 mm/s under 5 N), the loaded part in SI units with
  friction resisting positive motion; :func:`tribometer_path` is its raw file
  and :func:`tribometer_description_path` the data description of that file
  (columns, units, sign, zeroed position, loaded window).
- :func:`height_map`: two measured surface height maps (:data:`HEIGHT_MAPS`),
  read by :func:`polind.topography.read_height_map`; :func:`height_map_path`
  is the file.

None of the records was made by the polind developers.  The tribometer record
is example data of the Julia package FrictionModels.jl, the maps are test files
of the SurfaceTopography project, both MIT-licensed; each licence is a file
beside its data, and ``README.md`` in the folder of :func:`data_folder` says
where each record came from and what it holds.

Importing this module imports NumPy only; the tribometer record imports the
unit library pint when it is first read (:func:`polind.io.read_record`), a
height map SurfaceTopography.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from polind.errors import InputError

__all__ = ["HEIGHT_MAPS", "data_folder", "height_map", "height_map_path", "tribometer",
           "tribometer_description_path", "tribometer_path"]

_DATA = Path(__file__).resolve().parent / "data"

#: The names of the measured height maps :func:`height_map` reads: an ISO 25178-72
#: (x3p) map of 650 x 650 points at 0.128 x 0.315 µm, about 77 nm rms, and a Digital
#: Surf (sur) map of 563 x 484 points at 3.48 µm with missing points, about 17 nm rms.
HEIGHT_MAPS = ("x3p-2.x3p", "sur-2.sur")

_TRIBOMETER_FILE = "tribometer_reciprocating.tsv"
_TRIBOMETER_DESCRIPTION = "tribometer_reciprocating.toml"


def data_folder() -> Path:
    """The folder of the installed data files, with their licences and ``README.md``.

    Returns
    -------
    pathlib.Path
        ``.../polind/datasets/data``.
    """
    return _DATA


def tribometer_path() -> Path:
    """The raw file of the reciprocating-tribometer record.

    Tab-separated text with one header row, ``Time [s]``, ``Normal [uN]``,
    ``Position [mm]``, ``Friction [uN]``: 42,579 samples over 213.8 s (every
    5 ms once loaded), µN and mm, the position absolute and the friction in
    the instrument's sign (``-Friction`` resists positive motion).  The load
    is near 0 before 5.8 s and after 211.8 s.  Its licence (MIT, from
    FrictionModels.jl) is ``tribometer_reciprocating.LICENSE`` beside it.

    Returns
    -------
    pathlib.Path
        The path of ``tribometer_reciprocating.tsv``.
    """
    return _DATA / _TRIBOMETER_FILE


def tribometer_description_path() -> Path:
    """The data description of :func:`tribometer_path`, a TOML file beside it.

    Its ``[data]`` table names the file (relative to the description), the
    delimiter, the column of each of ``t``, ``x``, ``F``, ``normal_load``,
    their units (``mm``, ``uN``), the sign of ``F`` (-1), the columns zeroed at
    the first kept sample (``x``) and the window of time kept [s]: what
    :func:`tribometer` reads.  Give it to ``polind fit --data`` or
    ``polind compare --data``, or to :func:`polind.io.read_record`.

    Returns
    -------
    pathlib.Path
        The path of ``tribometer_reciprocating.toml``.
    """
    return _DATA / _TRIBOMETER_DESCRIPTION


@functools.lru_cache(maxsize=1)
def _tribometer() -> dict[str, np.ndarray]:
    from polind.io import read_record

    record = read_record(tribometer_description_path(), require=("t", "x", "F", "normal_load"))
    for array in record.values():
        array.flags.writeable = False
    return record


def tribometer() -> dict[str, np.ndarray]:
    """The reciprocating-tribometer record, its loaded part in SI units.

    A ball-on-flat reciprocating test: strokes of about 0.24 mm at about
    0.25 mm/s with a dwell of about 1 s at each end, under a normal load of
    5.0 N (the median; it is ramped up and released at the ends), friction
    about +-2.5 N.  Kept: the samples from 6.789 s to 210.784 s, the first
    and the last with a normal load of at least half its median (40,800
    samples every 5 ms).  The raw file is read once, through its data
    description (:func:`tribometer_description_path`) by
    :func:`polind.io.read_record`; each call returns new arrays.

    Returns
    -------
    dict of str to numpy.ndarray
        float64 arrays of one length:

        - ``"t"``: time [s], strictly increasing, from 6.789 s;
        - ``"x"``: position [m], zero at the first sample;
        - ``"F"``: friction force [N], resisting positive motion (the
          instrument's ``Friction`` column with its sign flipped);
        - ``"normal_load"``: normal load [N].

    See Also
    --------
    tribometer_path : the raw file, in µN and mm.
    tribometer_description_path : the data description this reading follows.

    Examples
    --------
    >>> from polind import datasets
    >>> record = datasets.tribometer()
    >>> record["t"].size, float(record["x"][0])
    (40800, 0.0)
    """
    return {key: array.copy() for key, array in _tribometer().items()}


def height_map_path(name: str) -> Path:
    """The file of a measured height map.

    Parameters
    ----------
    name : str
        One of :data:`HEIGHT_MAPS`: ``"x3p-2.x3p"`` or ``"sur-2.sur"``.

    Returns
    -------
    pathlib.Path
        The map's file; its licence (MIT, from SurfaceTopography) is
        ``LICENSE`` beside it.

    Raises
    ------
    polind.InputError
        ``name`` is not one of :data:`HEIGHT_MAPS`; the message lists them.
    """
    if name not in HEIGHT_MAPS:
        raise InputError(f"height map {name!r}: no such map in polind.datasets; expected "
                         f"one of {', '.join(repr(known) for known in HEIGHT_MAPS)}.")
    return _DATA / "topography" / name


def height_map(name: str):
    """A measured height map, read by :func:`polind.topography.read_height_map`.

    Parameters
    ----------
    name : str
        One of :data:`HEIGHT_MAPS`: ``"x3p-2.x3p"`` (650 x 650 points, pixel
        0.128 x 0.315 µm) or ``"sur-2.sur"`` (563 x 484 points, pixel
        3.48 µm, some missing points).

    Returns
    -------
    polind.topography.HeightMap
        Heights and pixel size in metres, missing points ``NaN``.

    Raises
    ------
    polind.InputError
        ``name`` is not one of :data:`HEIGHT_MAPS`.

    Examples
    --------
    >>> from polind import datasets
    >>> datasets.height_map("sur-2.sur").grid
    (563, 484)
    """
    path = height_map_path(name)
    from polind.topography import read_height_map

    return read_height_map(path)
