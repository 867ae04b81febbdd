"""Measured height maps in, heights in metres out (:ref:`guide-measured-surfaces`).

A height map is a regular grid of heights ``h[i, j]`` at ``x = i dx``,
``y = j dy`` (the first index runs along ``x``, as in SurfaceTopography's
``heights()``), heights and pixel sizes in metres, missing points ``NaN``.
Missing points stay missing: nothing here fills, interpolates or drops them.

Sources:

- every format SurfaceTopography reads (x3p, sur, plu, opd, datx, di, and
  about 35 more), with the file's own pixel size and units, converted to
  metres; SurfaceTopography is imported only when such a file is read.  The
  format is the one the file's extension names; only a file that is no
  readable file of that format, or has an extension no format claims, is
  recognised from its content, and then only by a format's signature
  (the bytes it starts with) or, without an extension of its own, by a
  reader that parses it: random or damaged bytes are "not a height map",
  never taken for a format that would read any bytes (a NASA SRTM ``.hgt``
  tile is any file of ``2 n^2`` bytes: read only from a ``.hgt`` file).  A
  file with several channels (an AFM's height, amplitude, phase, ...) gives
  the channel asked for by name, else SurfaceTopography's default channel if
  it holds heights, else the first height channel; the map records which
  (``HeightMap.channel``);
- a ``.npy`` array or a ``.csv`` grid (comma-separated, one row per ``i``,
  no header; an empty field or ``nan`` is a missing point), heights in
  metres, with the pixel size given by the caller.
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass

import numpy as np

from polind.errors import InputError, describe
from polind.resources import check_memory
from polind.validation import check_number

__all__ = ["BYTES_PER_POINT", "HeightMap", "LARGEST_HEIGHT", "SMALLEST_HEIGHT", "check_pixel_size",
           "read_height_map",
           "surface_topography", "GRID_SUFFIXES"]

#: What reading and analysing a map holds per grid point at its peak [bytes]: the heights,
#: the levelled and low-passed maps, the masks of the summit search and the figure (40
#: measured with a low-pass on a 2000 x 2000 map).
BYTES_PER_POINT = 64
#: The largest height [m] and the range of pixel sizes [m] a map may have: its heights
#: squared and summed, and divided by the square of its pixel sizes, stay finite doubles.
LARGEST_HEIGHT = 1e100
#: The smallest size [m] the largest height of a map with summits may have
#: (:func:`polind.topography.analyse`): the squares of its heights (the rms height, the
#: slopes, the power spectrum) stay normal doubles, not 0 (below about 1e-154 m they
#: underflow).  A map below it is not in metres.
SMALLEST_HEIGHT = 1e-100
_PIXEL_RANGE = (1e-100, 1e100)
# Bytes of memory per byte of a .csv grid read as text (the text, its lines, the parse).
_CSV_GRID_BYTES_PER_BYTE = 16

#: File name endings read by polind itself (the pixel size must be given).
GRID_SUFFIXES = (".npy", ".csv")

_OWNER = "topography"


@dataclass(frozen=True)
class HeightMap:
    """Heights on a regular grid, in metres; ``NaN`` marks a missing point.

    Build one with :meth:`from_array` (checks and converts) or
    :func:`read_height_map`; the constructor only stores.

    Parameters
    ----------
    heights : numpy.ndarray
        ``h[i, j]`` [m] at ``x = i dx``, ``y = j dy``, shape ``(nx, ny)``,
        float64, ``NaN`` where the instrument gave no value.
    pixel_size : tuple of float
        ``(dx, dy)`` [m].
    source : str
        What the map came from (a file name), used in messages.
    channel : str or None
        The channel of the file the heights are (SurfaceTopography's
        ``channel_id``: its name, with ``#n`` when several channels share
        it); ``None`` for an array or a ``.npy`` / ``.csv`` grid.
    """

    heights: np.ndarray
    pixel_size: tuple[float, float]
    source: str = "height map"
    channel: str | None = None

    @classmethod
    def from_array(cls, heights, pixel_size, source="height map", channel=None) -> "HeightMap":
        """A checked height map from an array of heights [m] and ``(dx, dy)`` [m].

        A masked array's masked points and ``NaN`` become missing points.

        Raises
        ------
        polind.InputError
            If the array is not two-dimensional with at least 3 x 3 points,
            holds an infinite value or a height beyond
            :data:`polind.topography.heightmap.LARGEST_HEIGHT` in size, has
            no valid point, or the pixel size is not two positive numbers
            from 1e-100 to 1e100 m; the message names ``source``.  (Heights
            too small to analyse, below
            :data:`polind.topography.heightmap.SMALLEST_HEIGHT`, are
            refused by :func:`polind.topography.analyse`.)

        Examples
        --------
        >>> m = HeightMap.from_array([[0.0, 1e-9, 0.0]] * 3, (1e-6, 2e-6), "demo")
        >>> m.grid, m.pixel_size, m.valid_points
        ((3, 3), (1e-06, 2e-06), 9)
        """
        dx, dy = check_pixel_size(pixel_size)
        if isinstance(heights, np.ma.MaskedArray):
            heights = np.ma.filled(heights.astype(np.float64), np.nan)
        try:
            array = np.array(heights, dtype=np.float64)
        except (TypeError, ValueError):
            raise InputError(f"{source}: the heights are not an array of numbers; expected a "
                             f"two-dimensional grid of heights in metres.") from None
        if array.ndim != 2:
            raise InputError(f"{source}: the heights have {array.ndim} dimension(s) (shape "
                             f"{array.shape}); expected a two-dimensional grid of heights.")
        if min(array.shape) < 3:
            raise InputError(f"{source}: the grid has {array.shape[0]} x {array.shape[1]} points; "
                             f"expected at least 3 x 3 (a summit needs 8 neighbours).")
        if np.isinf(array).any():
            raise InputError(f"{source}: {int(np.isinf(array).sum())} height(s) are infinite; "
                             f"expected finite heights, NaN for a missing point.")
        largest = float(np.nanmax(np.abs(array))) if not np.isnan(array).all() else 0.0
        if largest > LARGEST_HEIGHT:
            raise InputError(f"{source}: a height is {largest:.3g} m; expected heights in metres "
                             f"of a physical size, at most {LARGEST_HEIGHT:g} m (their squares "
                             f"and sums must stay within double precision).")
        valid = int(np.count_nonzero(~np.isnan(array)))
        if valid == 0:
            raise InputError(f"{source}: every one of the {array.size} points is missing; "
                             f"expected a height map with valid points.")
        return cls(array, (dx, dy), str(source), channel)

    @property
    def grid(self) -> tuple[int, int]:
        """``(nx, ny)``, the number of points along ``x`` and ``y``."""
        return tuple(int(n) for n in self.heights.shape)

    @property
    def valid_points(self) -> int:
        """Points that are not missing."""
        return int(np.count_nonzero(~np.isnan(self.heights)))


def check_pixel_size(pixel_size) -> tuple[float, float]:
    """``(dx, dy)`` [m] checked: two numbers from 1e-100 to 1e100 m, else InputError."""
    try:
        values = list(pixel_size)
    except TypeError:
        values = None
    if values is None or len(values) != 2:
        raise InputError(f"The 'pixel_size' parameter of {_OWNER} must be two numbers "
                         f"[dx, dy] in metres. Got {describe(pixel_size)} instead.")
    sizes = tuple(check_number(_OWNER, "pixel_size", value, "positive") for value in values)
    low, high = _PIXEL_RANGE
    for size in sizes:
        if not low <= size <= high:
            raise InputError(f"The 'pixel_size' parameter of {_OWNER} must be of a physical "
                             f"size, from {low:g} to {high:g} m (its square divides the "
                             f"heights). Got {size!r} instead.")
    return sizes


def read_height_map(path, pixel_size=None, channel=None) -> HeightMap:
    """Read a measured height map; heights and pixel sizes in metres.

    Parameters
    ----------
    path : str or os.PathLike
        A file SurfaceTopography reads (in the format its extension names,
        else the one its content shows, see the module notes), or a
        ``.npy`` / ``.csv`` grid of heights in metres.
    pixel_size : pair of float, optional
        ``(dx, dy)`` [m]: required for a ``.npy`` / ``.csv`` grid and for a
        file that gives no physical size; refused for a file that gives its
        own.
    channel : str, optional
        The channel to read from a file with several (an AFM's ``Height``
        beside its ``Amplitude`` and ``Phase``): its name, or
        SurfaceTopography's ``channel_id`` (``Height#2`` for the second of
        two channels named ``Height``).  Default: SurfaceTopography's default
        channel if it holds heights, else the first height channel.

    Returns
    -------
    HeightMap
        Missing points of the file (masked or ``NaN``) are ``NaN``;
        ``HeightMap.channel`` names the channel read.

    Raises
    ------
    polind.InputError
        One line naming the file and what was expected: the file is
        missing or unreadable, is not a height map (random or damaged
        bytes: no readable file of the format its name gives, and no other
        format's signature), is a line scan, gives no unit, a grid has no
        pixel size, every point is missing, the file has no channel of that
        name (the message lists its channels) or the channel holds no
        heights, ...

    Examples
    --------
    >>> import pathlib, tempfile
    >>> grid = pathlib.Path(tempfile.mkdtemp()) / "map.csv"
    >>> _ = grid.write_text("0,1e-9,0\\n1e-9,3e-9,nan\\n0,,0\\n")
    >>> m = read_height_map(grid, pixel_size=(1e-6, 1e-6))
    >>> m.grid, m.valid_points
    ((3, 3), 7)
    """
    name = os.fspath(path)
    if pixel_size is not None:  # checked before a long read
        check_pixel_size(pixel_size)
    if channel is not None and (not isinstance(channel, str) or not channel):
        raise InputError(f"The 'channel' parameter of {_OWNER} must be a channel's name. Got "
                         f"{describe(channel)} instead.")
    if not os.path.exists(name):
        raise InputError(f"{name}: no such file; expected a height map.")
    if os.path.isdir(name):
        raise InputError(f"{name}: is a directory; expected a height map file.")
    if os.path.isfile(name) and os.path.getsize(name) == 0:
        raise InputError(f"{name}: the file is empty; expected a height map.")
    if name.lower().endswith(GRID_SUFFIXES):
        if pixel_size is None:
            raise InputError(f"{name}: a {os.path.splitext(name)[1]} grid holds no pixel size; "
                             f"expected the pixel size [dx, dy] in metres to be given with it.")
        if channel is not None:
            raise InputError(f"{name}: a {os.path.splitext(name)[1]} grid has one channel, the "
                             f"heights; expected no 'channel' with it (that is for files with "
                             f"several). Got {describe(channel)}.")
        heights = _read_npy(name) if name.lower().endswith(".npy") else _read_csv_grid(name)
        return HeightMap.from_array(heights, pixel_size, name)
    return _read_with_surface_topography(name, pixel_size, channel)


def _check_map_memory(name, nx, ny):
    """Refuse, before reading, a map whose reading and analysis would pass the memory limit."""
    check_memory(float(nx) * float(ny) * BYTES_PER_POINT,
                 f"{name}: a height map of {nx} x {ny} points")


def _npy_shape(name):
    """The shape a .npy file's header declares, checked against the file's size and the memory.

    Read before the array, so that a header declaring more than the file
    holds (a truncated file) or more than the memory limit allows is refused
    before anything is allocated.
    """
    from numpy.lib import format as npy

    try:
        with open(name, "rb") as stream:
            version = npy.read_magic(stream)
            reader = npy.read_array_header_1_0 if version == (1, 0) else \
                npy.read_array_header_2_0
            shape, _, dtype = reader(stream)
            offset = stream.tell()
            size = os.fstat(stream.fileno()).st_size
    except (OSError, ValueError, EOFError) as error:
        raise InputError(f"{name}: not a height map: cannot be read as a NumPy .npy array "
                         f"({_first_line(error)}); expected a two-dimensional array of heights "
                         f"in metres.") from None
    if len(shape) == 2:
        _check_map_memory(name, *shape)
    declared = math.prod(shape) * dtype.itemsize
    if not dtype.hasobject and size - offset < declared:
        raise InputError(f"{name}: the .npy header declares {' x '.join(map(str, shape))} "
                         f"values ({declared:,} bytes) but the file holds {size - offset:,}; "
                         f"expected a complete .npy file.")
    return shape


def _read_npy(name) -> np.ndarray:
    _npy_shape(name)
    try:
        array = np.load(name, allow_pickle=False)
    except (OSError, ValueError, EOFError) as error:
        raise InputError(f"{name}: not a height map: cannot be read as a NumPy .npy array "
                         f"({_first_line(error)}); expected a two-dimensional array of heights "
                         f"in metres.") from None
    if not isinstance(array, np.ndarray) or not (np.issubdtype(array.dtype, np.floating)
                                                 or np.issubdtype(array.dtype, np.integer)):
        kind = getattr(array, "dtype", type(array).__name__)
        raise InputError(f"{name}: holds {kind} values; expected real heights in metres.")
    return array


def _read_csv_grid(name) -> np.ndarray:
    try:
        size = os.path.getsize(name)
    except OSError:
        size = 0                      # the read below names the problem
    check_memory(size * _CSV_GRID_BYTES_PER_BYTE,
                 f"{name}: reading a .csv height map of {size / 1e6:.3g} MB")
    try:
        with open(name, encoding="utf-8-sig") as handle:
            text = handle.read()
    except UnicodeDecodeError as error:
        raise InputError(f"{name}: not a height map: not UTF-8 text ({_first_line(error)}); "
                         f"expected a CSV grid of heights in metres.") from None
    except OSError as error:
        raise InputError(f"{name}: cannot be read ({_first_line(error)}); expected a CSV grid "
                         f"of heights in metres.") from None
    try:
        # The fast path: a complete grid of numbers (NaN spelt 'nan').
        grid = np.loadtxt(text.splitlines(), delimiter=",", dtype=np.float64, ndmin=2,
                          comments="#")
    except ValueError:
        grid = _parse_csv_grid(name, text)
    if grid.size == 0:
        raise InputError(f"{name}: holds no heights; expected a CSV grid of heights in metres.")
    return grid


def _parse_csv_grid(name, text) -> np.ndarray:
    """The careful path: empty fields are missing points; a bad cell is named."""
    rows, width = [], None
    for number, line in enumerate(text.splitlines(), start=1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        cells = line.split(",")
        if width is None:
            width = len(cells)
        elif len(cells) != width:
            raise InputError(f"{name}: line {number} has {len(cells)} values; expected {width} "
                             f"like the first row (a rectangular grid; an empty field is a "
                             f"missing point).")
        row = []
        for column, cell in enumerate(cells, start=1):
            cell = cell.strip()
            if cell == "" or cell.lower() == "nan":
                row.append(math.nan)
                continue
            try:
                value = float(cell)
            except ValueError:
                raise InputError(f"{name}: line {number}, column {column}: {describe(cell)} is not "
                                 f"a number; expected a height in metres, or an empty field or "
                                 f"'nan' for a missing point.") from None
            row.append(value)
        rows.append(row)
    return np.array(rows, dtype=np.float64).reshape(len(rows), width or 0)


def _first_line(error) -> str:
    text = str(error).strip() or type(error).__name__
    return text.splitlines()[0].strip()


def _import_surface_topography(name):
    """The SurfaceTopography package, imported on first use (``name``: for the message)."""
    try:
        with warnings.catch_warnings():
            # NuMPI (under SurfaceTopography) warns that it runs without MPI: that is intended.
            warnings.filterwarnings("ignore", message="Could not import mpi4py",
                                    category=ImportWarning)
            import SurfaceTopography
            import SurfaceTopography.Exceptions  # noqa: F401 - the readers' errors
    except ImportError:  # pragma: no cover - a dependency of polind
        raise InputError(f"{name}: this needs the package SurfaceTopography, which is not "
                         f"installed; expected it (pip install SurfaceTopography), or a "
                         f".npy/.csv grid.") from None
    return SurfaceTopography


def surface_topography(height_map: HeightMap):
    """The map as a SurfaceTopography ``Topography`` (non-periodic, metres, missing points masked).

    What :mod:`polind.topography` hands to SurfaceTopography's own analysis
    (scan-line alignment, roughness parameters, the power spectral density).

    Parameters
    ----------
    height_map : HeightMap

    Returns
    -------
    SurfaceTopography.Topography
        Physical size ``(nx dx, ny dy)`` [m], so that its pixel size is
        ``(dx, dy)``; heights a masked array where points are missing.
    """
    SurfaceTopography = _import_surface_topography(height_map.source)
    heights = height_map.heights
    missing = np.isnan(heights)
    if missing.any():
        heights = np.ma.masked_array(np.where(missing, 0.0, heights), mask=missing)
    (nx, ny), (dx, dy) = height_map.grid, height_map.pixel_size
    return SurfaceTopography.Topography(heights, (nx * dx, ny * dy), unit="m", periodic=False)


# Formats without any signature in their content, read only from a file named for them: a
# NASA SRTM tile (.hgt) is any file of 2 n^2 bytes, which random bytes often are.
_BY_NAME_ONLY = ("hgt",)
# What the format detection reads of a file (SurfaceTopography's magic buffer).
_MAGIC_BYTES = 512
_READABLE = ("expected a height map in a format SurfaceTopography reads (x3p, sur, plu, opd, "
             "datx, di, ...) or a .npy/.csv grid with a pixel size")


def _named_formats(name, readers) -> list:
    """The readers whose file extension ``name`` ends in (``.dat``: two formats)."""
    suffix = os.path.splitext(name)[1].lower().lstrip(".")
    if not suffix:
        return []
    named = []
    for reader in readers:
        try:
            extensions = [extension.lower() for extension in reader.file_extensions() or ()]
        except Exception:  # noqa: BLE001 - a reader that names no extension
            continue
        if suffix in extensions:
            named.append(reader)
    return named


def _open_reader(SurfaceTopography, name):
    """An open SurfaceTopography reader of the file, or InputError: it is not a height map.

    The file's name decides first: a name ending in a format's extension is
    read as that format (``.dat``, either of its two).  Only if it is no
    readable file of that format does its content decide, and then only a
    format whose signature (the bytes it starts with) the file carries: a
    damaged ``.x3p`` is not passed off as a format that reads any bytes.  A
    file of another name is detected from its content, among every format
    but those without a signature (:data:`_BY_NAME_ONLY`), which need their
    own name.
    """
    from SurfaceTopography.IO import MagicMatch, readers

    try:
        with open(name, "rb") as stream:
            magic = stream.read(_MAGIC_BYTES)
    except OSError as error:
        raise InputError(f"{name}: cannot be read ({_first_line(error)}); expected a height "
                         f"map.") from None
    named = _named_formats(name, readers)
    failures = []
    for reader in named:
        if reader.can_read(magic) == MagicMatch.NO:
            failures.append(f"its first bytes are no {reader.format()} signature")
            continue
        try:
            return SurfaceTopography.open_topography(name, format=reader.format())
        except MemoryError:
            raise
        except Exception as error:  # noqa: BLE001 - a reader's failure is a fault of the file
            failures.append(_first_line(error))
    for reader in readers:
        if reader in named or reader.format() in _BY_NAME_ONLY:
            continue
        match = reader.can_read(magic)
        if match == MagicMatch.NO or (named and match != MagicMatch.YES):
            continue
        try:
            return SurfaceTopography.open_topography(name, format=reader.format())
        except MemoryError:
            raise
        except Exception:  # noqa: BLE001 - not this format; the next may read it
            continue
    if named:
        formats = " or ".join(f"{reader.name()} ({reader.format()})" for reader in named)
        raise InputError(f"{name}: SurfaceTopography recognises no height-map format in this "
                         f"file, which is not a height map: it is no readable {formats} file, "
                         f"the format its name gives ({'; '.join(failures)}), and carries no "
                         f"other format's signature; {_READABLE}.")
    raise InputError(f"{name}: SurfaceTopography recognises no height-map format in this file, "
                     f"which is not a height map; {_READABLE}.")


def _read_with_surface_topography(name, pixel_size, channel) -> HeightMap:
    SurfaceTopography = _import_surface_topography(name)
    reader = _open_reader(SurfaceTopography, name)
    try:
        return _height_map_of(reader, name, pixel_size, channel)
    finally:
        reader.close()


def _channel_list(channels) -> str:
    """``'Height' (height, nm), 'Phase' (phase, deg)``: a file's channels for a message."""
    def kind(channel):
        data_kind = getattr(channel, "data_kind", None)
        return getattr(data_kind, "name", "height").lower()
    return ", ".join(f"{channel.channel_id!r} ({kind(channel)}, "
                     f"{channel.data_unit or 'no unit'})" for channel in channels)


def _choose_channel(reader, name, wanted):
    """The channel to read: ``wanted`` (a name or channel id), else the default height channel."""
    channels = list(reader.channels)
    if wanted is None:
        default = reader.default_channel
        if default.is_height_channel:
            return default
        heights = [channel for channel in channels if channel.is_height_channel]
        if not heights:
            raise InputError(f"{name}: none of its channels holds heights "
                             f"({_channel_list(channels)}); expected a height map.")
        return heights[0]
    found = ([channel for channel in channels if channel.channel_id == wanted]
             or [channel for channel in channels if channel.name == wanted])
    if not found:
        raise InputError(f"{name}: has no channel {wanted!r}; expected the 'channel' to be one "
                         f"of its channels: {_channel_list(channels)}.")
    channel = found[0]
    if not channel.is_height_channel:
        heights = [other for other in channels if other.is_height_channel]
        choice = (f"one of its height channels: {_channel_list(heights)}" if heights
                  else "a file with a height channel")
        raise InputError(f"{name}: channel {wanted!r} holds {_channel_list([channel])} data, not "
                         f"heights; expected {choice}.")
    return channel


def _height_map_of(reader, name, pixel_size, wanted=None) -> HeightMap:
    """A height channel of an open SurfaceTopography reader, in metres."""
    channel = _choose_channel(reader, name, wanted)
    if channel.dim != 2:
        raise InputError(f"{name}: not a height map: read as {_format_name(reader)} data, it "
                         f"is a line scan ({channel.dim}-dimensional data); expected a "
                         f"two-dimensional height map.")
    nx, ny = (int(n) for n in channel.nb_grid_pts)
    # The format SurfaceTopography took the file for: a damaged file may pass for another.
    taken = f"read as {_format_name(reader)} data of {nx} x {ny} points"
    if min(nx, ny) < 3:
        raise InputError(f"{name}: not a height map: {taken}; expected a height map of at "
                         f"least 3 x 3 points (is the file truncated or damaged?).")
    if channel.unit is None:
        raise InputError(f"{name}: {taken}, the file gives no length unit, so its heights "
                         f"cannot be converted to metres; expected a height map with units, "
                         f"or the heights in metres saved as a .npy/.csv grid.")
    _check_map_memory(name, nx, ny)
    options = {}
    if channel.physical_sizes is None:
        if pixel_size is None:
            raise InputError(f"{name}: the file gives no physical size; expected the pixel "
                             f"size [dx, dy] in metres to be given with it.")
        from SurfaceTopography.Support.UnitConversion import get_unit_conversion_factor

        dx, dy = check_pixel_size(pixel_size)
        nx, ny = channel.nb_grid_pts
        metres_per_unit = get_unit_conversion_factor(channel.unit, "m")
        options["physical_sizes"] = (nx * dx / metres_per_unit, ny * dy / metres_per_unit)
    elif pixel_size is not None:
        raise InputError(f"{name}: the file gives its own physical size "
                         f"({_sizes_text(channel.physical_sizes, channel.unit)}); expected no "
                         f"pixel size with it (that is only for .npy/.csv grids).")
    try:
        topography = channel.topography(**options).to_unit("m")
        heights = topography.heights()
        dx, dy = (float(size) for size in topography.pixel_size)
    except MemoryError:
        raise
    except Exception as error:  # noqa: BLE001 - a reader's failure is a fault of the file
        raise InputError(f"{name}: not a height map: SurfaceTopography cannot read the heights "
                         f"of this file ({_first_line(error)}); expected a readable height "
                         f"map.") from None
    return HeightMap.from_array(heights, (dx, dy), name, channel.channel_id)


def _format_name(reader) -> str:
    """The name of the format a SurfaceTopography reader reads (``"NASA SRTM (hgt)"``)."""
    try:
        return f"{reader.name()} ({reader.format()})"
    except Exception:  # noqa: BLE001 - a reader without names: its class says it
        return type(reader).__name__.removesuffix("Reader")


def _sizes_text(sizes, unit) -> str:
    return " x ".join(f"{float(size):.6g}" for size in sizes) + f" {unit}"
