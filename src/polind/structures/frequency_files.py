"""The harmonic-balance runs of a structure file (:ref:`formats-structure`).

``[structure.run]`` with ``kind = "frequency_response"`` follows the periodic
steady state over a frequency range (:func:`polind.frequency_response`)::

    [structure.run]
    kind = "frequency_response"
    omega_range = [60.0, 200.0]      # rad/s: first and last frequency, positive, different
    force = [1.0, 0.0]               # N: f_i(t) = force_i cos(omega t), one per coordinate
    harmonics = 7                    # optional (default 7)
    samples = 128                    # optional: samples per period, at least 4 harmonics + 1
    max_points = 2000                # optional: the most points of the curve

and ``kind = "backbone"`` gives a mode's frequency and damping ratio against
its amplitude (:func:`polind.backbone`)::

    [structure.run]
    kind = "backbone"
    amplitudes = [1e-5, 1e-4, 1e-3]  # m kg^0.5: modal amplitudes, positive
    mode = 0                         # optional: the linear mode, by increasing frequency
    harmonics = 7                    # optional
    samples = 128                    # optional

:func:`harmonic_run` reads such a table into a :class:`FrequencyResponseRun`
or a :class:`BackboneRun`; :func:`polind.load_structure` calls it for these
kinds.  Every key is declared (:data:`FREQUENCY_RESPONSE_KEYS`,
:data:`BACKBONE_KEYS`): an unknown key is an :class:`~polind.InputError`
naming it, its table and the kind's keys, and a bad value names its dotted
key (``structure.run.omega_range``).  Each run has the methods
``polind structure`` calls whatever the kind: ``solve`` (the run itself),
``columns`` (its table), ``figure`` (its PNG) and ``summary`` (one line).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from polind.errors import InputError, describe

__all__ = ["BACKBONE_KEYS", "FREQUENCY_RESPONSE_KEYS", "HARMONIC_KINDS", "BackboneRun",
           "FrequencyResponseRun", "harmonic_run"]

#: The keys of ``[structure.run]`` for ``kind = "frequency_response"``.
FREQUENCY_RESPONSE_KEYS = ("kind", "omega_range", "force", "harmonics", "samples",
                           "max_points")
#: The keys of ``[structure.run]`` for ``kind = "backbone"``.
BACKBONE_KEYS = ("kind", "amplitudes", "mode", "harmonics", "samples")
#: The kinds of run solved by harmonic balance, and their keys.
HARMONIC_KINDS = {"frequency_response": FREQUENCY_RESPONSE_KEYS, "backbone": BACKBONE_KEYS}
#: The keys a kind cannot do without.
_REQUIRED = {"frequency_response": ("omega_range", "force"), "backbone": ("amplitudes",)}
_NEEDS = {"frequency_response": "omega_range [rad/s] and force [N]",
          "backbone": "amplitudes [m kg^0.5]"}


@dataclass(frozen=True)
class FrequencyResponseRun:
    """A ``kind = "frequency_response"`` run of a structure file (:ref:`formats-structure`).

    Attributes
    ----------
    omega_range : (float, float)
        The first and last fundamental frequency [rad/s].
    force : ndarray
        ``(n,)`` each coordinate's force amplitude [N]: ``f_i(t) = force_i
        cos(omega t)``.
    harmonics : int
        ``H``, the harmonics balanced.
    samples : int or None
        Samples per period (None: the default of :func:`polind.harmonic_balance`).
    max_points : int
        The most points of the curve.
    kind : str
        ``"frequency_response"``.

    Examples
    --------
    >>> import numpy as np, polind
    >>> structure = polind.Structure(mass=1.0, damping=4.0)
    >>> structure.add_contact(polind.model_from_dict({"model": {
    ...     "type": "maxwell-slip", "stiffness": [1e4], "breakaway_force": [1.0]}}), dofs=(0,))
    >>> run = FrequencyResponseRun(omega_range=(60.0, 200.0), force=np.array([1.0]))
    >>> curve = run.solve(structure)
    >>> sorted(run.columns(curve))[:3]
    ['F_0_1', 'amplitude_q_0', 'omega']
    """

    omega_range: tuple
    force: np.ndarray
    harmonics: int = 7
    samples: int | None = None
    max_points: int = 2000
    kind: str = "frequency_response"

    #: What the progress of :meth:`solve` counts.
    progress_unit = "%"

    def solve(self, structure, *, progress=None):
        """Run it: :func:`polind.frequency_response` of ``structure``.

        ``progress(done, 100)`` is called after each point with the per cent
        of the frequency range behind it (it goes back where the curve
        folds).  Raises :class:`polind.ContinuationError` (its ``curve``:
        the points found) when the continuation stops before the end of the
        range.
        """
        from polind.structures.continuation import frequency_response

        first, last = self.omega_range
        advance = None
        if progress is not None:
            def advance(omega, count):
                fraction = (float(omega) - first) / (last - first)
                progress(int(100 * min(max(fraction, 0.0), 1.0)), 100)

        return frequency_response(structure, self.omega_range, force=self.force,
                                  harmonics=self.harmonics, samples=self.samples,
                                  max_points=self.max_points, progress=advance)

    def columns(self, curve) -> dict:
        """The table of a curve: ``omega, amplitude_q_i, q_i_0, q_i_c1, q_i_s1, ..., F_c_1``.

        ``amplitude_q_i`` is the largest ``|q_i - Q_0|`` over the period [m];
        ``q_i_*`` are coordinate i's harmonic coefficients [m] and ``F_c_1``
        contact c's first-harmonic force amplitude [N].
        """
        points, n, width = curve.harmonics.shape if len(curve) else (0, 0, 0)
        columns = {"omega": curve.omega}
        columns.update({f"amplitude_q_{i}": curve.amplitude(i) for i in range(n)})
        names = harmonic_names(width)
        for i in range(n):
            columns.update({f"q_{i}_{name}": curve.harmonics[:, i, k]
                            for k, name in enumerate(names)})
        for c in range(curve.contact_force.shape[1] if points else 0):
            columns[f"F_{c}_1"] = np.hypot(curve.contact_force[:, c, 1],
                                           curve.contact_force[:, c, 2])
        return columns

    def figure(self, curve, structure, *, source=None, stopped=False) -> bytes:
        """The PNG of a curve (:func:`polind.structures.plot_frequency_response`)."""
        from polind.structures.plot import plot_frequency_response

        title = f"{source}: " if source else ""
        title += "frequency response"
        if stopped:
            first, last = self.omega_range
            title += f": stopped before the end of {first:g} to {last:g} rad/s"
        return plot_frequency_response(curve, structure, title=title)

    def summary(self, curve) -> str:
        """One line: the points, the frequencies they span and the turning points."""
        if not len(curve):
            return "0 points"
        folds = len(curve.turning_points)
        return (f"{len(curve)} points, omega {curve.omega.min():.6g} to "
                f"{curve.omega.max():.6g} rad/s, {folds} turning point"
                f"{'' if folds == 1 else 's'}")


@dataclass(frozen=True)
class BackboneRun:
    """A ``kind = "backbone"`` run of a structure file (:ref:`formats-structure`).

    Attributes
    ----------
    amplitudes : ndarray
        The modal amplitudes [m kg^0.5], positive.
    mode : int
        The linear mode (contacts stuck), by increasing frequency.
    harmonics : int
        ``H``.
    samples : int or None
        Samples per period (None: the default).
    kind : str
        ``"backbone"``.
    """

    amplitudes: np.ndarray
    mode: int = 0
    harmonics: int = 7
    samples: int | None = None
    kind: str = "backbone"

    #: What the progress of :meth:`solve` counts.
    progress_unit = " amplitudes"

    def solve(self, structure, *, progress=None):
        """Run it: :func:`polind.backbone` of ``structure``.

        ``progress(done, total)`` is called after each amplitude.
        """
        from polind.structures.modes import backbone

        total = len(self.amplitudes)
        advance = None if progress is None else (lambda _, count: progress(count, total))
        return backbone(structure, self.amplitudes, mode=self.mode, harmonics=self.harmonics,
                        samples=self.samples, progress=advance)

    def columns(self, result) -> dict:
        """The table of a backbone: ``amplitude, frequency, damping_ratio, amplitude_q_i``.

        ``frequency`` is in rad/s; ``amplitude_q_i`` is coordinate i's
        largest ``|q_i - Q_0|`` over the period [m].
        """
        columns = {"amplitude": result.amplitude, "frequency": result.frequency,
                   "damping_ratio": result.damping_ratio}
        columns.update({f"amplitude_q_{i}": result.displacement_amplitude(i)
                        for i in range(result.harmonics.shape[1])})
        return columns

    def figure(self, result, structure, *, source=None) -> bytes:
        """The PNG of a backbone (:func:`polind.structures.plot_backbone`)."""
        from polind.structures.plot import plot_backbone

        title = (f"{source}: " if source else "") + f"backbone of mode {self.mode}"
        return plot_backbone(result, title=title)

    def summary(self, result) -> str:
        """One line: the amplitudes and the frequencies and damping ratios they span."""
        count = len(result.amplitude)
        return (f"{count} amplitude{'' if count == 1 else 's'} of mode {self.mode}, omega "
                f"{result.frequency.min():.6g} to {result.frequency.max():.6g} rad/s, damping "
                f"ratio {result.damping_ratio.min():.3g} to {result.damping_ratio.max():.3g}")


def harmonic_names(width):
    """The names of ``2H + 1`` coefficients: ``["0", "c1", "s1", ..., "cH", "sH"]``."""
    names = ["0"]
    for h in range(1, (width - 1) // 2 + 1):
        names += [f"c{h}", f"s{h}"]
    return names


# --- reading ------------------------------------------------------------------------------

def _integer(key, value, smallest, expected):
    if isinstance(value, bool) or not isinstance(value, int) or value < smallest:
        raise InputError(f"key '{key}': expected {expected}; got {describe(value)}")
    return value


def _omega_range(key, value):
    from polind.structures.files import key_number

    expected = "[first, last]: two different positive frequencies [rad/s]"
    if not isinstance(value, list) or len(value) != 2:
        raise InputError(f"key '{key}': expected {expected}; got {describe(value)}")
    first, last = (key_number(key, item, "positive", index=i) for i, item in enumerate(value))
    if first == last:
        raise InputError(f"key '{key}': expected {expected}; got the same frequency twice "
                         f"({first!r})")
    return first, last


def _amplitudes(key, value):
    from polind.structures.files import key_number

    expected = "a list of positive modal amplitudes [m kg^0.5]"
    if not isinstance(value, list) or not value:
        raise InputError(f"key '{key}': expected {expected}; got {describe(value)}")
    return np.array([key_number(key, item, "positive", index=i)
                     for i, item in enumerate(value)])


def _harmonics(table, prefix):
    harmonics = _integer(f"{prefix}harmonics", table.get("harmonics", 7), 1,
                         "a positive integer (the harmonics balanced)")
    samples = table.get("samples")
    if samples is not None:
        samples = _integer(f"{prefix}samples", samples, 4 * harmonics + 1,
                           f"an integer of at least 4 harmonics + 1 = {4 * harmonics + 1} "
                           f"(samples per period)")
    return harmonics, samples


def _check_memory(kind, harmonics, samples, unknowns, points, n, m):
    """Refuse a run whose Jacobians and curve would not fit in memory."""
    from polind.resources import check_memory
    from polind.structures.harmonic import default_samples

    samples = default_samples(harmonics) if samples is None else samples
    # Each factor clamped, so that an integer of hundreds of digits gives an estimate
    # beyond any memory rather than an overflow.
    H, N, P = (float(min(value, 10 ** 12)) for value in (harmonics, samples, points))
    size = unknowns * 2 * H + 2
    estimate = 8.0 * (6 * size * size + 4 * H * n * n + 4 * N * m + P * (n + 2 * m) * (2 * H + 1))
    count = f"max_points = {describe(points)}" if kind == "frequency_response" \
        else f"{points} amplitude{'' if points == 1 else 's'}"
    check_memory(estimate, f"The '{kind}' run of [structure.run] (harmonics = "
                           f"{describe(harmonics)}, samples = {describe(samples)}, {count})")


def harmonic_run(table, kind, n, m):
    """The run of a ``[structure.run]`` table of a harmonic-balance ``kind``.

    Parameters
    ----------
    table : dict
        The ``[structure.run]`` table.
    kind : str
        ``"frequency_response"`` or ``"backbone"`` (:data:`HARMONIC_KINDS`).
    n, m : int
        The structure's coordinates and contacts.

    Returns
    -------
    FrequencyResponseRun or BackboneRun

    Raises
    ------
    InputError
        Naming the dotted key (``structure.run.omega_range``) and what is expected.
    """
    from polind.structures.files import key_vector

    prefix = "structure.run."
    allowed = HARMONIC_KINDS[kind]
    for key in table:
        if key not in allowed:
            raise InputError(f"unknown key '{prefix}{key}' in [structure.run] (kind = "
                             f"'{kind}'); expected one of: {', '.join(allowed)}")
    for key in _REQUIRED[kind]:
        if key not in table:
            raise InputError(f"missing key '{prefix}{key}' in [structure.run]; a '{kind}' run "
                             f"needs {_NEEDS[kind]}")
    harmonics, samples = _harmonics(table, prefix)
    if kind == "backbone":
        amplitudes = _amplitudes(f"{prefix}amplitudes", table["amplitudes"])
        mode = _integer(f"{prefix}mode", table.get("mode", 0), 0,
                        f"a mode 0 to {n - 1} (by increasing frequency)")
        if mode >= n:
            raise InputError(f"key '{prefix}mode': expected a mode 0 to {n - 1} (by "
                             f"increasing frequency); got {mode}")
        _check_memory(kind, harmonics, samples, n, amplitudes.size, n, m)
        return BackboneRun(amplitudes=amplitudes, mode=mode, harmonics=harmonics,
                           samples=samples)
    omega_range = _omega_range(f"{prefix}omega_range", table["omega_range"])
    if isinstance(table["force"], dict):
        raise InputError(f"key '{prefix}force': expected a list of {n} force amplitude"
                         f"{'s' if n != 1 else ''} [N], one per coordinate (f_i = force_i "
                         f"cos(omega t)); got a table ([structure.run.force] is a time run's)")
    force = key_vector(f"{prefix}force", table["force"], n)
    if not force.any():
        raise InputError(f"key '{prefix}force': expected a force amplitude [N] on at least "
                         f"one coordinate; got {'0' if n == 1 else f'{n} zeros'} (the response "
                         f"would be zero)")
    max_points = _integer(f"{prefix}max_points", table.get("max_points", 2000), 1,
                          "a positive integer (the most points of the curve)")
    _check_memory(kind, harmonics, samples, m, max_points, n, m)
    return FrequencyResponseRun(omega_range=omega_range, force=force, harmonics=harmonics,
                                samples=samples, max_points=max_points)

