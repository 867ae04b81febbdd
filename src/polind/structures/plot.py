"""The figures of a structure run (``polind structure --plot``), one per kind of run.

:func:`plot_structure` (a run in time): two rows, the coordinates against
time, and each contact's friction force against its relative displacement
``u_c = q_i - q_j`` (its hysteresis loop: the area of a closed loop is the
energy the joint dissipates per cycle).  :func:`plot_frequency_response`: each
coordinate's amplitude against the frequency, turning points marked.
:func:`plot_backbone`: a mode's frequency and damping ratio against its
amplitude.  matplotlib is imported here, with its Agg canvas only (no display
needed).
"""

from __future__ import annotations

import numpy as np

__all__ = ["plot_backbone", "plot_frequency_response", "plot_structure"]

# Length units by the largest value shown: (factor, label).
_LENGTHS = ((1.0, "m"), (1e-3, "mm"), (1e-6, "µm"), (1e-9, "nm"))


def _length_unit(values):
    largest = float(np.nanmax(np.abs(values))) if np.size(values) else 0.0
    for factor, label in _LENGTHS:
        if largest >= factor:
            return factor, label
    return _LENGTHS[-1] if largest > 0.0 else (1.0, "m")


def _relative(contact, q):
    if contact.second is None:
        return q[:, contact.first]
    return q[:, contact.first] - q[:, contact.second]


def _label(contact):
    if contact.second is None:
        return f"u = q_{contact.first}"
    return f"u = q_{contact.first} − q_{contact.second}"


def plot_structure(result, structure, path=None, *, title=None, last_cycle=None, dpi=110):
    """A PNG of a structure run: the coordinates against time, each contact's loop.

    Parameters
    ----------
    result : StructureResult
        What :func:`polind.simulate_structure` returned for ``structure``.
    structure : Structure
        The structure it ran (its contacts say which coordinates each joins).
    path : str, os.PathLike or None
        The PNG to write (atomically, :func:`polind.io.atomic_write_bytes`);
        None returns its bytes instead, to be written with a command's other
        outputs (:func:`polind.io.write_together`).
    title : str, optional
    last_cycle : float, optional
        The period [s] of a periodic drive: each loop's last period is drawn
        bold over the whole run (drawn light), so that a settled loop reads
        apart from the transient before it.
    dpi : int

    Returns
    -------
    bytes or None
        The PNG when ``path`` is None.
    """
    contacts = structure.contacts
    m = len(contacts)
    columns = min(max(m, 1), 3)
    rows = 1 + -(-m // columns)
    figure = _figure(4.2 * max(columns, 2), 3.4 * rows)
    grid = figure.add_gridspec(rows, columns)
    over_time = figure.add_subplot(grid[0, :])
    factor, unit = _length_unit(result.q)
    for i in range(result.q.shape[1]):
        over_time.plot(result.t, result.q[:, i] / factor, lw=1.0, label=f"q_{i}")
    over_time.set(xlabel="time t [s]", ylabel=f"coordinate q [{unit}]",
                  title=title or f"{structure.size} coordinates, {m} contact"
                                 f"{'s' if m != 1 else ''}: the response")
    over_time.grid(alpha=0.3)
    over_time.legend(loc="best", fontsize=8)
    for c, contact in enumerate(contacts):
        axes = figure.add_subplot(grid[1 + c // columns, c % columns])
        u = _relative(contact, result.q)
        scale, label = _length_unit(u)
        force = result.contact_forces[:, c]
        colour = f"C{c % 10}"
        if last_cycle is not None and result.t[-1] - result.t[0] > last_cycle > 0.0:
            settled = result.t >= result.t[-1] - last_cycle * (1.0 + 1e-9)
            axes.plot(u / scale, force, lw=0.6, color=colour, alpha=0.3, label="whole run")
            axes.plot(u[settled] / scale, force[settled], lw=1.4, color=colour,
                      label="last period")
            axes.legend(loc="best", fontsize=8)
        else:
            axes.plot(u / scale, force, lw=0.8, color=colour)
        axes.set(xlabel=f"{_label(contact)} [{label}]", ylabel=f"friction force F_{c} [N]",
                 title=f"contact {c}: {contact.model.type} (hysteresis loop)")
        axes.grid(alpha=0.3)
    return _finish(figure, path, dpi)


def _figure(width, height):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(figure)
    return figure


def _finish(figure, path, dpi):
    """The PNG's bytes (``path`` None), or written atomically to ``path``."""
    from io import BytesIO

    buffer = BytesIO()
    figure.savefig(buffer, dpi=dpi, format="png", metadata={"Software": None})
    if path is None:
        return buffer.getvalue()
    from polind import io

    io.atomic_write_bytes(path, buffer.getvalue())
    return None


def plot_frequency_response(curve, structure=None, path=None, *, title=None, dpi=110):
    """A PNG of a frequency response curve: each coordinate's amplitude against ``omega``.

    The amplitude is the largest ``|q_i - Q_0|`` over the period
    (:meth:`polind.FrequencyResponse.amplitude`); the curve is drawn in its
    own order, so that a fold reads as one line, and its turning points are
    marked.

    Parameters
    ----------
    curve : FrequencyResponse
        What :func:`polind.frequency_response` returned (or the ``curve`` of
        its :class:`polind.ContinuationError`: the points found).
    structure : Structure, optional
        The structure it ran: its coordinates and contacts make the default title.
    path : str, os.PathLike or None
        The PNG to write (atomically); None returns its bytes.
    title : str, optional
    dpi : int

    Returns
    -------
    bytes or None
        The PNG when ``path`` is None.
    """
    figure = _figure(7.0, 4.4)
    axes = figure.add_subplot()
    count = curve.harmonics.shape[1] if len(curve) else 0
    amplitudes = np.array([curve.amplitude(i) for i in range(count)]).reshape(count, -1)
    factor, unit = _length_unit(amplitudes)
    folds = curve.turning_points
    for i in range(count):
        colour = f"C{i % 10}"
        axes.plot(curve.omega, amplitudes[i] / factor, lw=1.2, color=colour,
                  marker="." if len(curve) < 40 else None, ms=4, label=f"q_{i}")
        if folds.size:
            axes.plot(curve.omega[folds], amplitudes[i, folds] / factor, ls="none",
                      marker="o", ms=7, mfc="none", mec="k",
                      label="turning points" if i == 0 else None)
    if title is None:
        title = "frequency response"
        if structure is not None:
            m = len(structure.contacts)
            title = (f"{structure.size} coordinate{'s' if structure.size != 1 else ''}, {m} "
                     f"contact{'s' if m != 1 else ''}: the frequency response")
    points = f"{len(curve)} points, {folds.size} turning point{'' if folds.size == 1 else 's'}"
    axes.set(xlabel="frequency ω [rad/s]", ylabel=f"amplitude max |q − Q₀| [{unit}]",
             title=f"{title}\n({points})")
    axes.grid(alpha=0.3)
    if count:
        axes.legend(loc="best", fontsize=8)
    return _finish(figure, path, dpi)


def _decade_label(value, position=None):
    """``2×10^-5`` (mathtext) for a minor tick of a logarithmic axis."""
    if not value > 0:
        return ""
    exponent = int(np.floor(np.log10(value) + 1e-9))
    mantissa = value / 10.0 ** exponent
    return f"${mantissa:.0f}\\times10^{{{exponent}}}$"


def plot_backbone(result, path=None, *, title=None, dpi=110):
    """A PNG of a backbone: the frequency and the damping ratio against the modal amplitude.

    Two panels over the modal amplitude ``a`` [m kg^0.5] (a logarithmic axis
    when the amplitudes span more than a decade): ``omega(a)`` with the
    linear frequency (contacts stuck) dashed, and ``zeta(a)``.

    Parameters
    ----------
    result : Backbone
        What :func:`polind.backbone` returned.
    path : str, os.PathLike or None
        The PNG to write (atomically); None returns its bytes.
    title : str, optional
    dpi : int

    Returns
    -------
    bytes or None
        The PNG when ``path`` is None.
    """
    figure = _figure(7.0, 6.0)
    top, bottom = figure.subplots(2, 1, sharex=True)
    a = result.amplitude
    marker = "o" if a.size < 40 else None
    top.plot(a, result.frequency, lw=1.2, marker=marker, ms=4, color="C0",
             label="ω(a)")
    top.axhline(result.linear_frequency, ls="--", lw=0.8, color="0.4",
                label=f"contacts stuck: {result.linear_frequency:.6g} rad/s")
    top.set(ylabel="frequency ω [rad/s]", title=title or "backbone")
    top.legend(loc="best", fontsize=8)
    bottom.plot(a, result.damping_ratio, lw=1.2, marker=marker, ms=4, color="C3")
    bottom.set(xlabel="modal amplitude a [m kg^0.5]", ylabel="damping ratio ζ")
    if a.size and a.min() > 0 and a.max() > 10.0 * a.min():
        from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

        bottom.set_xscale("log")
        if a.max() < 1e3 * a.min():
            # Labels at 2 and 5 of each decade (all nine overlap; one a decade is too few).
            bottom.xaxis.set_minor_locator(LogLocator(10.0, subs=(2.0, 5.0)))
            bottom.xaxis.set_minor_formatter(FuncFormatter(_decade_label))
        else:
            bottom.xaxis.set_minor_formatter(NullFormatter())
    for axes in (top, bottom):
        axes.grid(alpha=0.3)
    return _finish(figure, path, dpi)
