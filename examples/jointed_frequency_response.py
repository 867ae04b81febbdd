"""A jointed structure in the frequency domain: response curves, backbones and loops
==================================================================================

Two masses joined by a friction joint, the first one on a spring to the ground
with a little viscous damping, pushed by ``F cos(omega t)`` on the first mass
(the structure of the user guide, :ref:`guide-frequency-domain`).  The joint is
the structure's main damping: as the force grows it slips more, the first
resonance softens (its frequency falls) and its peak flattens (the joint
dissipates more per cycle than the force feeds in).  Once the joint slides
through the whole period (gross slip), the second mass no longer follows the
first, and the first mass resonates alone on its spring, at ``sqrt(k / m_1)``,
damped by the joint's capped force: the peak grows again.

Two joints, each in its own structure of the same shape (the first spring as
stiff as the stuck joint, ``m_1 = 1 kg``, ``m_2 = 0.5 kg``, 2 % damping of the
first mass on its spring):

* an ``iwan4`` joint (Segalman's four-parameter Iwan model: slides at 1 N,
  10 kN/m stuck);
* a Pol-Ind joint from the measured height map ``x3p-2.x3p`` installed with
  polind (:mod:`polind.datasets`): its summits, each with its own height and
  radius, at a normal load of 10 N, steel on steel with a hardness of 2 GPa
  (:ref:`guide-measured-surfaces-plasticity`).  Its stuck stiffness is about
  3e8 N/m and it breaks away at 1.5 N over some 12 nm, so its structure's first
  mode is at 2.1 kHz.

For each joint, at four force levels from microslip to gross slip (0.05, 0.25,
1 and 4 times the joint's break-away force, ``model.force_scale()``):

1. :func:`polind.frequency_response`: the frequency response curve by harmonic
   balance (7 harmonics) and continuation;
2. :func:`polind.harmonic_balance` at the peak of each curve (started from the
   curve's point there), whose contact coefficients ``[c_0, c_1, s_1, ...]``,
   evaluated on a time grid, give the joint's force against its relative
   displacement; :func:`polind.hysteresis_loop` gives the loop's energy per
   cycle, secant stiffness and equivalent damping ratio.  The loops are drawn
   scaled by their amplitudes, from a near line in microslip to a rectangle in
   gross slip; the ripple along the rectangle's sides is the 7-harmonic
   series of a force with corners (the energy is not affected: over a motion of
   7 harmonics only the force's first 7 do work);
3. :func:`polind.backbone`: the first mode's frequency and damping ratio against
   its modal amplitude (the extended periodic motion concept), with each
   curve's peak marked on it.  In microslip the peaks lie on the backbone; the
   more the joint damps, the further below it the forced peak falls, and the
   gross-slip peak, the first mass alone, is off it.

Run: ``python examples/jointed_frequency_response.py [OUT_DIR]``; writes
``OUT_DIR/jointed_frequency_response.png`` (default: the current directory)
and prints a table: per joint and level the peak's frequency and normalised
amplitude, the loop's energy, secant stiffness and damping ratio, and the
backbone's frequency and damping ratio at the smallest and largest amplitude.
About 15 s (a first run also compiles the contacts' periodic evaluation).
"""

import sys
from pathlib import Path

import numpy as np

import polind
from polind import datasets
from polind.models.pol_ind import default_table

MASSES = (1.0, 0.5)              # kg: the first mass (on the spring) and the second
DAMPING_RATIO = 0.02             # of the first mass on its spring
LEVELS = (0.05, 0.25, 1.0, 4.0)  # force amplitudes, in break-away forces of the joint
BAND = (0.5, 1.5)                # the frequency range, in units of sqrt(k / m_1)
HARMONICS = 7
STEP = 0.01                      # the continuation's first step: about 60-140 points a curve
LOOP_SAMPLES = 512               # per period, to draw a loop from its coefficients

IWAN = {"type": "iwan4", "slip_force": 1.0, "stiffness": 1e4, "chi": -0.5, "beta": 0.1}
MAP, NORMAL_LOAD, HARDNESS = "x3p-2.x3p", 10.0, 2e9      # -, N, Pa


def iwan_joint():
    return polind.model_from_dict({"model": IWAN})


def pol_ind_joint():
    """The default Pol-Ind model on the measured map, at NORMAL_LOAD, with plastic summits."""
    table = default_table()
    table["normal_load"] = NORMAL_LOAD
    table["surface"] = {"topography": str(datasets.height_map_path(MAP))}
    table["discretisation"] = {}               # direct summation over the map's summits
    table["materials"]["hardness"] = HARDNESS
    return polind.model_from_dict({"model": table})


def two_masses(joint, stiffness):
    """``m_1`` on a spring ``stiffness`` to the ground, ``m_2`` held by ``joint`` to ``m_1``."""
    m1, m2 = MASSES
    damping = 2.0 * DAMPING_RATIO * np.sqrt(stiffness * m1)
    structure = polind.Structure(mass=[[m1, 0.0], [0.0, m2]],
                                 stiffness=[[stiffness, 0.0], [0.0, 0.0]],
                                 damping=[[damping, 0.0], [0.0, 0.0]])
    structure.add_contact(joint, dofs=(0, 1))      # its relative displacement u = q_0 - q_1
    return structure


def series(coefficients, omega, periods=2):
    """``(t, x)``: the Fourier series ``[c_0, c_1, s_1, ..., c_H, s_H]`` on a time grid."""
    harmonics = (len(coefficients) - 1) // 2
    theta = 2.0 * np.pi * np.arange(periods * LOOP_SAMPLES + 1) / LOOP_SAMPLES
    x = np.full(theta.shape, coefficients[0])
    for h in range(1, harmonics + 1):
        x += coefficients[2 * h - 1] * np.cos(h * theta) + coefficients[2 * h] * np.sin(h * theta)
    return theta / omega, x


def modal_amplitude(harmonics, mass):
    """The first harmonic's ``sqrt(Q_c1^T M Q_c1 + Q_s1^T M Q_s1)`` [m kg^0.5] (``backbone``'s ``a``)."""
    c, s = harmonics[:, 1], harmonics[:, 2]
    return float(np.sqrt(c @ mass @ c + s @ mass @ s))


def study(name, joint):
    """Every level's curve, peak and loop, and the first mode's backbone, of one joint."""
    scales = joint.characteristic_scales()
    stiffness = scales["presliding_stiffness"]      # the stuck joint [N/m]
    slip = scales["presliding_range"]               # the displacement it slides at [m]
    breakaway = joint.force_scale()                 # its break-away force [N]
    structure = two_masses(joint, stiffness)
    reference = np.sqrt(stiffness / MASSES[0])      # rad/s
    omega_range = (BAND[0] * reference, BAND[1] * reference)
    print(f"\n{name}: stuck {stiffness:.4g} N/m, breaks away at {breakaway:.4g} N over "
          f"{slip:.4g} m; sqrt(k/m_1) = {reference:.5g} rad/s")

    levels = []
    for level in LEVELS:
        force = level * breakaway
        try:
            curve = polind.frequency_response(structure, omega_range, force=[force, 0.0],
                                              harmonics=HARMONICS, step=STEP)
        except polind.ContinuationError as error:
            # Not hidden: the points found are drawn, and the message says where it stopped.
            print(f"  {level:g} F_S: {error}")
            curve = error.curve
        amplitude = curve.amplitude(0)
        peak = int(np.argmax(amplitude))
        point = polind.harmonic_balance(structure, curve.omega[peak], force=[force, 0.0],
                                        harmonics=HARMONICS, initial=curve.points[peak])
        t, u = series(point.contact_displacement[0], point.omega)
        _, contact_force = series(point.contact_force[0], point.omega)
        loop = polind.hysteresis_loop(u, contact_force)
        levels.append({"level": level, "force": force, "curve": curve, "peak": peak,
                       "point": point, "loop": loop,
                       "modal": modal_amplitude(point.harmonics, structure.mass)})

    amplitudes = np.sqrt(MASSES[0]) * slip * np.logspace(-1.3, 0.5, 24)
    try:
        modes = polind.backbone(structure, amplitudes, mode=0, harmonics=HARMONICS)
    except polind.InputError as error:
        print(f"  backbone: {error}")
        modes = None
    return {"name": name, "reference": reference, "breakaway": breakaway, "slip": slip,
            "levels": levels, "backbone": modes}


def summary(results):
    print(f"\n{'joint':<9}{'F / F_S':>8}{'F [N]':>9}{'peak w/w_ref':>13}{'|q_0|/F [m/N]':>15}"
          f"{'u_0 / slip':>11}{'D [J]':>11}{'k_sec [N/m]':>13}{'zeta_loop':>10}")
    for result in results:
        for row in result["levels"]:
            curve, peak, loop = row["curve"], row["peak"], row["loop"]
            print(f"{result['name']:<9}{row['level']:>8g}{row['force']:>9.3g}"
                  f"{curve.omega[peak] / result['reference']:>13.4f}"
                  f"{curve.amplitude(0)[peak] / row['force']:>15.4g}"
                  f"{0.5 * np.ptp(loop.u) / result['slip']:>11.3g}{loop.energy:>11.4g}"
                  f"{loop.secant_stiffness:>13.4g}{loop.damping_ratio:>10.4f}")
    print(f"\n{'joint':<9}{'backbone: a [m kg^0.5]':>24}{'w / w_0':>9}{'zeta':>8}"
          f"{'a [m kg^0.5]':>14}{'w / w_0':>9}{'zeta':>8}")
    for result in results:
        modes = result["backbone"]
        if modes is None:
            print(f"{result['name']:<9}{'did not converge (printed above)':>24}")
            continue
        w0 = modes.linear_frequency
        print(f"{result['name']:<9}{modes.amplitude[0]:>24.3g}{modes.frequency[0] / w0:>9.4f}"
              f"{modes.damping_ratio[0]:>8.4f}{modes.amplitude[-1]:>14.3g}"
              f"{modes.frequency[-1] / w0:>9.4f}{modes.damping_ratio[-1]:>8.4f}")


def draw(results, path):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter

    figure = Figure(figsize=(18, 9), layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(len(results), 4)
    colors = ["#1f77b4", "#2ca02c", "#ff7f0e", "#d62728"]
    for row, result in zip(axes, results):
        curves, frequency, damping, loops = row
        unit, scale = ("rad/s", 1.0) if result["reference"] < 1e3 else ("10³ rad/s", 1e-3)
        for color, level in zip(colors, result["levels"]):
            curve, peak = level["curve"], level["peak"]
            curves.semilogy(curve.omega * scale, curve.amplitude(0) / level["force"], color=color,
                            lw=1.6, label=f"F = {level['level']:g} F_S = {level['force']:.3g} N")
            curves.plot(curve.omega[peak] * scale, curve.amplitude(0)[peak] / level["force"],
                        "o", color=color, ms=5)
        curves.set(xlabel=f"ω [{unit}]", ylabel="|q_0| / F [m/N]",
                   title=f"{result['name']}: response of the first mass")
        curves.legend(fontsize=8, loc="lower left")

        modes = result["backbone"]
        if modes is not None:
            frequency.semilogx(modes.amplitude, modes.frequency * scale, color="k", lw=1.6,
                               label="backbone (mode 1)")
            damping.loglog(modes.amplitude, modes.damping_ratio, color="k", lw=1.6,
                           label="backbone (mode 1)")
        else:
            for panel in (frequency, damping):
                panel.text(0.55, 0.5, "polind.backbone did not converge here\n(its message is "
                           "printed)",
                           transform=panel.transAxes, ha="center", va="center", color="C3")
        for color, level in zip(colors, result["levels"]):
            frequency.semilogx(level["modal"], level["point"].omega * scale, "o", color=color,
                               ms=6, label=f"peak at {level['level']:g} F_S")
        frequency.set(xlabel="modal amplitude a [m kg^0.5]", ylabel=f"frequency [{unit}]",
                      title="first mode: frequency, and each curve's peak")
        frequency.legend(fontsize=8, loc="upper left")
        damping.set(xlabel="modal amplitude a [m kg^0.5]", ylabel="damping ratio ζ",
                    title="first mode: damping ratio (joint and C)")
        if modes is not None:
            damping.legend(fontsize=8, loc="upper left")
            damping.set_xlim(frequency.get_xlim())
            damping.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
            damping.yaxis.set_major_formatter(FormatStrFormatter("%g"))
            damping.yaxis.set_minor_formatter(NullFormatter())

        for color, level in zip(colors, result["levels"]):
            loop = level["loop"]
            u0, f0 = 0.5 * np.ptp(loop.u), 0.5 * np.ptp(loop.F)
            loops.plot(loop.u / u0, loop.F / f0, color=color, lw=1.4,
                       label=f"{level['level']:g} F_S: D = {loop.energy:.3g} J, ζ = "
                             f"{loop.damping_ratio:.3f}")
        loops.set(xlabel="u / u_0 (u = q_0 − q_1)", ylabel="joint force / its amplitude",
                  ylim=(-1.12, 1.8), xticks=[-1.0, -0.5, 0.0, 0.5, 1.0],
                  title="the joint's loop at each peak, scaled\n(7 harmonics: the ripple is "
                        "their truncation)")
        loops.legend(fontsize=8, loc="upper left")
        for panel in row:
            panel.grid(alpha=0.3, which="both")
    figure.savefig(path, dpi=100, metadata={"Software": None})


def main(out_dir="."):
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    results = [study("iwan4", iwan_joint()), study("Pol-Ind", pol_ind_joint())]
    summary(results)
    path = out / "jointed_frequency_response.png"
    draw(results, path)
    print(f"\nwrote {path}")
    return results


if __name__ == "__main__":
    main(*sys.argv[1:])
