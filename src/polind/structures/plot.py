"""The figure of a structure run (``polind structure --plot``): :func:`plot_structure`.

Two rows: the coordinates against time, and each contact's friction force
against its relative displacement ``u_c = q_i - q_j`` (its hysteresis loop:
the area of a closed loop is the energy the joint dissipates per cycle).
matplotlib is imported here, with its Agg canvas only (no display needed).
"""

from __future__ import annotations

import numpy as np

__all__ = ["plot_structure"]

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
    from io import BytesIO

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    contacts = structure.contacts
    m = len(contacts)
    columns = min(max(m, 1), 3)
    rows = 1 + -(-m // columns)
    figure = Figure(figsize=(4.2 * max(columns, 2), 3.4 * rows), layout="constrained")
    FigureCanvasAgg(figure)
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
    buffer = BytesIO()
    figure.savefig(buffer, dpi=dpi, format="png", metadata={"Software": None})
    if path is None:
        return buffer.getvalue()
    from polind import io

    io.atomic_write_bytes(path, buffer.getvalue())
    return None
