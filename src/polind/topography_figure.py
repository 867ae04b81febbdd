"""The figure of ``polind topography --plot``: a measured surface as a tribologist reads it.

Seven panels (:func:`topography_figure`):

1. the levelled map with its summits marked (and its outliers, if left in);
2. the summit-height histogram against the Gaussian of the same mean and
   standard deviation (the Greenwood–Williamson assumption), beside the
   heights of all points of the map;
3. the distribution of the summit radii ``R_i = 1 / kappa_i``, with the
   Greenwood–Williamson radius ``1 / mean(kappa)`` and the median;
4. the normal load ``N(d)`` of a rigid flat at separation ``d`` (from the
   mean summit height): the direct sum over the measured summits with their
   own radii, ``N(d) = (4/3) E* sum_{h_i > d} sqrt(R_i) (h_i - d)^(3/2)``,
   against the statistical sum of the Greenwood–Williamson equivalent,
   ``N(d) = (4/3) n E* sqrt(R) sigma_a^(3/2) F_{3/2}(d / sigma_a)`` with
   ``n`` the number of summits (:ref:`guide-pol-ind-summation`);
5. the presliding virgin curve ``F(u) = sum_j min(k_j u, W_j)`` of the
   Pol-Ind elements at a normal load (default 1 N, at most half of what the
   map's summits carry), normalised by ``mu_s N``: the direct summation over
   the measured summits (one element per summit in contact, ``k_j = 8 G*
   sqrt(R_j delta_j)``, ``W_j = mu_s P_j``) against the 256-element table of
   the Greenwood–Williamson equivalent (:ref:`guide-measured-surfaces`);
6. the power spectral density of the analysed map (SurfaceTopography's
   radially averaged areal PSD, :func:`polind.topography.power_spectrum`),
   with the pixel's Nyquist wavelength and the low-pass cut-off;
7. the cut-off study (:func:`polind.topography.cutoff_study`): summits and
   ``1 / mean(kappa)`` against ``short_cutoff``, with the white-noise summit
   count (one in nine points).

It draws a :class:`polind.topography.MeasuredSurface` (the map read and
analysed by :mod:`polind.topography`) and computes panels 4 and 5 with the
contact mechanics of :mod:`polind.contact`, which builds its surfaces from
that result; so it sits above both packages, and :mod:`polind.topography`
depends on nothing in :mod:`polind.contact`.

matplotlib is imported here only, on first use; nothing is written to disk
(the command line writes :func:`figure_png`'s bytes with its safe writer).
"""

from __future__ import annotations

import io as _bytes_io
import math
import os

import numpy as np

__all__ = ["topography_figure", "figure_png", "direct_normal_load", "statistical_normal_load",
           "virgin_curves"]

#: Normal load of the virgin-curve panel [N] (less if the map cannot carry twice it).
VIRGIN_LOAD = 1.0
#: mu_s of the virgin-curve panel (the default Pol-Ind value).
VIRGIN_STATIC_COEFFICIENT = 0.15

#: Most summits marked on the map; beyond it the highest ones are marked.
MARKED_SUMMITS = 4000
#: Longest side of the map as drawn [pixels]; a larger map is drawn subsampled.
DRAWN_PIXELS = 1024


def direct_normal_load(summit_heights, summit_radii, separations, effective_modulus):
    """``N(d) = (4/3) E* sum_{h_i > d} sqrt(R_i) (h_i - d)^(3/2)`` [N] for each ``d``.

    Hertz's law summed over the measured summits, each with its own radius.

    Parameters
    ----------
    summit_heights, summit_radii : numpy.ndarray
        ``h_i`` [m] and ``R_i`` [m].
    separations : array_like
        ``d`` [m], on the scale of the heights.
    effective_modulus : float
        ``E*`` [Pa].

    Returns
    -------
    numpy.ndarray
        ``N(d)`` [N], same shape as ``separations``.

    Examples
    --------
    >>> load = direct_normal_load(np.array([1e-8, -1e-9]), np.array([1e-6, 4e-6]), 0.0, 0.75)
    >>> print(f"{float(load):.6g}")                   # sqrt(1e-6) (1e-8)^1.5
    1e-15
    """
    order = np.argsort(summit_heights)[::-1]
    heights = np.asarray(summit_heights, dtype=np.float64)[order]
    roots = np.sqrt(np.asarray(summit_radii, dtype=np.float64)[order])
    separations = np.asarray(separations, dtype=np.float64)
    # Only the summits above d count: on the heights sorted downwards, a prefix.
    touching = np.searchsorted(-heights, -separations.ravel(), side="left")
    loads = np.array([roots[:k] @ (heights[:k] - d) ** 1.5
                      for k, d in zip(touching, separations.ravel())])
    return (4.0 / 3.0) * effective_modulus * loads.reshape(separations.shape)


def statistical_normal_load(summits, radius, height_std, separations, effective_modulus):
    """``N(d) = (4/3) n E* sqrt(R) sigma_a^(3/2) F_{3/2}(d / sigma_a)`` [N].

    The Greenwood–Williamson sum of ``n`` summits of radius ``R`` whose
    heights are Gaussian with standard deviation ``sigma_a`` about the
    reference of ``d``; ``F_{3/2}`` is
    :func:`polind.contact.greenwood.gw_integral`, valid for ``d / sigma_a``
    in [-5, 10] (``NaN`` outside).
    """
    from polind.contact.greenwood import VALID_RANGE, gw_integral

    s = np.asarray(separations, dtype=np.float64) / height_std
    inside = (s >= VALID_RANGE[0]) & (s <= VALID_RANGE[1])
    value = np.full(s.shape, np.nan)
    value[inside] = gw_integral(1.5, s[inside])
    return (4.0 / 3.0) * summits * effective_modulus * math.sqrt(radius) * height_std**1.5 * value


def _default_moduli() -> tuple[float, float]:
    """``(E*, G*)`` of the default Pol-Ind material pair (steel on steel)."""
    from polind.contact.materials import effective_moduli
    from polind.models import PolInd

    materials = PolInd.example_parameters()["materials"]
    (E1, E2), (nu1, nu2) = materials["youngs_modulus"], materials["poisson_ratio"]
    return effective_moduli(E1, nu1, E2, nu2)


def _default_effective_modulus() -> float:
    """``E*`` of the default Pol-Ind material pair (steel on steel)."""
    return _default_moduli()[0]


def virgin_curves(surface, normal_load=VIRGIN_LOAD, static_coefficient=VIRGIN_STATIC_COEFFICIENT,
                  moduli=None, points=200):
    """Presliding virgin curves of a map's direct summation and of its statistical equivalent.

    Parameters
    ----------
    surface : MeasuredSurface
        The analysed map.
    normal_load : float, optional
        ``N`` [N]; lowered to half of what the map's summits carry if it is
        more than that.
    static_coefficient : float, optional
        ``mu_s``.
    moduli : pair of float, optional
        ``(E*, G*)`` [Pa]; default steel on steel.
    points : int, optional
        Displacements on the curve.

    Returns
    -------
    dict or None
        None when the summits carry no load above the lowest of them (one
        summit, or all of one height: the flat cannot press on them without
        passing below every one).  Else ``displacement`` [m] (0 to 1.2 times the largest element slip
        distance of the two), ``direct`` and ``statistical`` [N] (None when
        the summits are all of one height: the equivalent has no height
        spread, so no statistical surface), the ``normal_load`` used [N], and
        ``separation`` and ``real_area`` of the direct contact [m, m^2].
    """
    from polind.contact.elements import element_table
    from polind.contact.separation import solve_separation
    from polind.contact.surface import DirectSurface, StatisticalSurface

    E_star, G_star = _default_moduli() if moduli is None else moduli
    direct = DirectSurface.from_topography(surface, E_star, G_star)
    if not direct.load_range[1] > 0.0:
        return None
    load = min(float(normal_load), 0.5 * direct.load_range[1])
    gw = direct.greenwood_williamson
    surfaces = [(direct, 0)]
    if gw["height_std"] > 0.0:
        surfaces.append((StatisticalSurface(gw["asperity_density"], gw["nominal_area"],
                                            gw["asperity_radius"], gw["height_std"], E_star,
                                            G_star), 256))
    tables = []
    for each, elements in surfaces:
        d = solve_separation(each, load)
        tables.append((d, element_table(each, d, static_coefficient, elements or 64,
                                        normal_load=load)))
    reach = max(float(np.max(table.breakaway_force / table.stiffness)) for _, table in tables)
    u = np.linspace(0.0, 1.2 * reach, points)
    d_direct, direct_table = tables[0]
    return {"displacement": u, "direct": direct_table.virgin_force(u),
            "statistical": tables[1][1].virgin_force(u) if len(tables) > 1 else None,
            "normal_load": load, "separation": float(d_direct),
            "real_area": float(direct.real_area(d_direct))}


def topography_figure(surface, effective_modulus=None):
    """The seven-panel figure of a :class:`~polind.topography.analysis.MeasuredSurface`.

    Parameters
    ----------
    surface : MeasuredSurface
        The analysed map.
    effective_modulus : float, optional
        ``E*`` [Pa] for the ``N(d)`` panel; default the steel pair of the
        default Pol-Ind parameters (210 GPa, 0.3 on both sides).

    Returns
    -------
    matplotlib.figure.Figure
        Not attached to pyplot (no global state); save it or pass it to
        :func:`figure_png`.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    if effective_modulus is None:
        effective_modulus = _default_effective_modulus()
    figure = Figure(figsize=(25, 11), layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplot_mosaic([["map", "heights", "radii", "psd"],
                                  ["map", "loads", "virgin", "cutoff"]],
                                 width_ratios=[1.15, 1, 1, 1])
    _draw_map(figure, axes["map"], surface)
    _draw_heights(axes["heights"], surface)
    _draw_radii(axes["radii"], surface)
    _draw_loads(axes["loads"], surface, effective_modulus)
    _draw_virgin(axes["virgin"], surface, effective_modulus)
    _draw_psd(axes["psd"], surface)
    _draw_cutoff_study(axes["cutoff"], surface)
    nx, ny = surface.grid
    dx, dy = surface.pixel_size
    cutoff = ("" if surface.short_cutoff is None
              else f", low-pass cut-off {surface.short_cutoff * 1e6:.3g} µm")
    channel = "" if surface.channel is None else f" (channel {surface.channel})"
    rough = surface.roughness
    outliers = ("no outlier" if not surface.outliers else f"{surface.outliers:,} outliers "
                f"{'marked missing' if surface.outliers_removed else 'left in'}")
    name = os.path.basename(surface.source)
    figure.suptitle(f"{name}{channel}: {nx} x {ny} points, pixel {dx * 1e6:.3g} x "
                    f"{dy * 1e6:.3g} µm, {surface.valid_points:,} valid, {outliers}, "
                    f"levelling '{surface.levelling}'{cutoff}\n"
                    f"Sa {rough['Sa'] * 1e9:.3g} nm, Sq {rough['Sq'] * 1e9:.3g} nm, "
                    f"Ssk {rough['Ssk']:.3g}, Sku {rough['Sku']:.3g}, Sdq {rough['Sdq']:.3g}, "
                    f"rms curvature {rough['rms_curvature']:.3g} 1/m")
    return figure


def figure_png(surface, effective_modulus=None, dpi=110) -> bytes:
    """:func:`topography_figure` as PNG bytes (no software tag in the metadata)."""
    buffer = _bytes_io.BytesIO()
    topography_figure(surface, effective_modulus).savefig(buffer, format="png", dpi=dpi,
                                                          metadata={"Software": None})
    return buffer.getvalue()


def _draw_map(figure, axes, surface):
    import matplotlib

    nx, ny = surface.grid
    dx, dy = surface.pixel_size
    stride = max(1, math.ceil(max(nx, ny) / DRAWN_PIXELS))
    shown = surface.heights[::stride, ::stride] * 1e9
    colours = matplotlib.colormaps["viridis"].with_extremes(bad="#bbbbbb")
    # A few deep pits or spikes must not wash the map out: 0.5-99.5 % of the heights.
    low, high = _central_range(shown)
    image = axes.imshow(shown.T, origin="lower", cmap=colours, interpolation="nearest",
                        extent=_cell_extent(shown.shape, stride, (dx, dy)), aspect="equal",
                        vmin=low, vmax=high)
    # A map wider than tall gets its colour bar below it, not beside it (much taller than it).
    wide = nx * dx > ny * dy
    figure.colorbar(image, ax=axes, label="height above the mean plane [nm]",
                    shrink=0.8 if wide else 0.9, extend="both",
                    location="bottom" if wide else "right")
    i, j = surface.summit_index
    marked = np.argsort(surface.summit_heights)[::-1][:MARKED_SUMMITS]
    few = marked.size < 300
    axes.scatter(i[marked] * dx * 1e6, j[marked] * dy * 1e6, s=14.0 if few else 5.0,
                 c="red", marker="^" if few else "o", edgecolors="white",
                 linewidths=0.5 if few else 0.2)
    what = (f"all {surface.summits:,} summits marked" if marked.size == surface.summits
            else f"the {marked.size:,} highest of {surface.summits:,} summits marked")
    if surface.outliers and not surface.outliers_removed:
        oi, oj = surface.outlier_index
        axes.scatter(oi * dx * 1e6, oj * dy * 1e6, s=30.0, marker="x", c="magenta",
                     linewidths=1.2, label=f"{surface.outliers:,} outliers (left in)")
        axes.legend(loc="upper right", fontsize=8)
    grey = ", grey: missing" if surface.valid_points < nx * ny else ""
    axes.set(xlabel="x [µm]", ylabel="y [µm]", title=f"Levelled map ({what}{grey})")


def _cell_extent(shape, stride, pixel_size):
    """imshow's extent [µm] of every ``stride``-th point, cell ``k`` centred on ``k stride dx``."""
    (mx, my), (dx, dy) = shape, pixel_size
    step_x, step_y = stride * dx * 1e6, stride * dy * 1e6
    return (-0.5 * step_x, (mx - 0.5) * step_x, -0.5 * step_y, (my - 0.5) * step_y)


def _central_range(values, percent=0.5):
    """The ``percent`` and ``100 - percent`` percentiles of the finite values."""
    finite = values[np.isfinite(values)]
    low, high = np.percentile(finite, (percent, 100.0 - percent))
    return (float(low), float(high)) if high > low else (float(low) - 1.0, float(high) + 1.0)


def _draw_heights(axes, surface):
    heights = surface.summit_heights * 1e9
    mean, std = heights.mean(), heights.std()
    all_points = surface.heights[~np.isnan(surface.heights)] * 1e9
    if all_points.size > 1_000_000:
        all_points = all_points[:: all_points.size // 1_000_000]
    bins = int(np.clip(np.sqrt(heights.size), 10, 80))
    low, high = _central_range(all_points, 0.1)
    summit_low, summit_high = _central_range(heights, 0.1)
    low, high = min(low, summit_low, mean - 4 * std), max(high, summit_high, mean + 4 * std)
    outside = int(np.count_nonzero((heights < low) | (heights > high)))
    # Density of all points over the whole map, drawn over the range where the summits are.
    counts, edges = np.histogram(all_points, bins=np.linspace(low, high, 2 * bins + 1))
    axes.stairs(counts / (all_points.size * np.diff(edges)), edges, color="#888888",
                label=f"all points of the map (rms {surface.rms_height * 1e9:.3g} nm)")
    counts, edges = np.histogram(heights, bins=np.linspace(low, high, bins + 1))
    beyond = f", {outside:,} beyond the axis" if outside else ""
    axes.stairs(counts / (heights.size * np.diff(edges)), edges, fill=True, color="#1f77b4",
                alpha=0.7, label=f"summit heights ({heights.size:,} summits{beyond})")
    span = np.linspace(low, high, 400)
    if std > 0:
        gauss = np.exp(-0.5 * ((span - mean) / std) ** 2) / (math.sqrt(2 * math.pi) * std)
        axes.plot(span, gauss, color="#d62728", lw=1.8,
                  label=f"Gaussian, same mean {mean:.3g} nm and σ {std:.3g} nm")
    axes.set(xlim=(low, high), xlabel="height above the mean plane [nm]",
             ylabel="probability density [1/nm]",
             title="Summit heights against the Greenwood–Williamson Gaussian")
    axes.legend(loc="upper left", fontsize=8)
    axes.grid(alpha=0.3)


def _draw_radii(axes, surface):
    radii = surface.summit_radii * 1e6
    low, high = radii.min(), radii.max()
    if high > low:
        bins = np.geomspace(low, high, int(np.clip(np.sqrt(radii.size), 10, 80)) + 1)
    else:
        bins = np.geomspace(low / 1.1, high * 1.1, 3)
    axes.hist(radii, bins=bins, color="#2ca02c", alpha=0.75,
              label=f"summit radii R = 1/κ ({radii.size:,})")
    axes.axvline(surface.summit_radius_mean * 1e6, color="#d62728", lw=1.8,
                 label=f"1 / mean κ = {surface.summit_radius_mean * 1e6:.3g} µm "
                       f"(Greenwood–Williamson R)")
    axes.axvline(surface.summit_radius_median * 1e6, color="black", ls="--", lw=1.2,
                 label=f"median = {surface.summit_radius_median * 1e6:.3g} µm")
    axes.set(xscale="log", xlabel="summit radius R [µm]", ylabel="summits",
             title="Summit radii, κ = -(h_xx + h_yy)/2 by central differences")
    axes.legend(loc="upper right", fontsize=8)
    axes.grid(alpha=0.3, which="both")


def _draw_loads(axes, surface, effective_modulus):
    heights = surface.summit_heights
    mean = heights.mean()
    std = heights.std()
    relative = heights - mean
    top = np.sort(relative)[-2] if relative.size > 1 else relative[-1]
    # The summits' spread, or with summits of one height the map's: d runs below them all.
    spread = std if std > 0 else surface.rms_height
    separations = np.linspace(-2.5 * spread, max(top, 0.0) if std > 0 else top, 160)
    direct = direct_normal_load(relative, surface.summit_radii, separations, effective_modulus)
    one_radius = direct_normal_load(relative, np.full(relative.shape, surface.summit_radius_mean),
                                    separations, effective_modulus)
    d_nm = separations * 1e9
    axes.plot(d_nm, direct, color="#1f77b4", lw=2.0,
              label="direct sum over the measured summits, their own radii")
    axes.plot(d_nm, one_radius, color="#1f77b4", lw=1.0, ls=":",
              label="direct sum, every summit with R = 1 / mean κ")
    if std > 0:
        statistical = statistical_normal_load(surface.summits, surface.summit_radius_mean, std,
                                              separations, effective_modulus)
        axes.plot(d_nm, statistical, color="#d62728", lw=1.6, ls="--",
                  label="Greenwood–Williamson equivalent (η, R, σ of the map)")
    axes.set(yscale="log", xlabel="separation d from the mean summit height [nm]",
             ylabel="normal load N [N]",
             title=f"Rigid flat on the map ({surface.nominal_area * 1e6:.3g} mm², "
                   f"E* = {effective_modulus / 1e9:.4g} GPa)")
    axes.legend(loc="upper right", fontsize=8)
    axes.grid(alpha=0.3, which="both")


def _draw_virgin(axes, surface, effective_modulus):
    moduli = _default_moduli()
    if effective_modulus != moduli[0]:
        moduli = (effective_modulus, moduli[1] * effective_modulus / moduli[0])
    curves = virgin_curves(surface, moduli=moduli)
    if curves is None:
        axes.text(0.5, 0.5, "no presliding curve: the summits carry no load above the lowest "
                  "of them\n(the map has one summit, or all of one height)",
                  ha="center", va="center", transform=axes.transAxes, fontsize=9)
        axes.set(title="Presliding virgin curve", xticks=[], yticks=[])
        return
    scale = VIRGIN_STATIC_COEFFICIENT * curves["normal_load"]
    u_nm = curves["displacement"] * 1e9
    axes.plot(u_nm, curves["direct"] / scale, color="#1f77b4", lw=2.0,
              label="direct summation over the measured summits")
    if curves["statistical"] is not None:
        axes.plot(u_nm, curves["statistical"] / scale, color="#d62728", lw=1.6, ls="--",
                  label="Greenwood–Williamson equivalent (256 elements)")
    axes.set(xlabel="tangential displacement from rest u [nm]", ylabel="F / (μs N)",
             ylim=(0.0, 1.05),
             title=f"Presliding virgin curve at N = {curves['normal_load']:.3g} N, "
                   f"μs = {VIRGIN_STATIC_COEFFICIENT:g}")
    axes.legend(loc="lower right", fontsize=8)
    axes.grid(alpha=0.3)


def _draw_psd(axes, surface):
    from polind.topography import power_spectrum

    q, C, filled = power_spectrum(surface.height_map)
    wavelength = 2.0 * np.pi / q * 1e6
    note = "\n(missing points filled, harmonic)" if filled else ""
    axes.loglog(wavelength, C, color="#1f77b4", lw=1.8,
                label=f"areal PSD, radially averaged{note}")
    nyquist = 2.0 * max(surface.pixel_size) * 1e6
    axes.axvline(nyquist, color="black", ls=":", lw=1.2,
                 label=f"2 max(dx, dy) = {nyquist:.3g} µm")
    if surface.short_cutoff is not None:
        axes.axvline(surface.short_cutoff * 1e6, color="#d62728", ls="--", lw=1.4,
                     label=f"low-pass cut-off {surface.short_cutoff * 1e6:.3g} µm")
    axes.invert_xaxis()
    axes.set(xlabel="wavelength 2π/q [µm] (short wavelengths to the right)",
             ylabel="C(q) [m⁴]",
             title="Power spectral density (SurfaceTopography, Hann window)")
    axes.legend(loc="lower left", fontsize=8)
    axes.grid(alpha=0.3, which="both")


def _draw_cutoff_study(axes, surface):
    rows = surface.cutoff_study
    filtered = [row for row in rows if row["short_cutoff"] is not None and row["summits"]]
    unfiltered = rows[0]
    cutoffs = np.array([row["short_cutoff"] for row in filtered]) * 1e6
    counts = np.array([row["summits"] for row in filtered], dtype=float)
    radii = np.array([row["summit_radius_mean"] for row in filtered]) * 1e6
    white = surface.summit_candidates / 9.0
    axes.loglog(cutoffs, counts, "o-", color="#1f77b4", lw=1.8, label="summits")
    axes.axhline(unfiltered["summits"], color="#1f77b4", ls=":", lw=1.2,
                 label=f"summits without low-pass ({unfiltered['summits']:,})")
    axes.axhline(white, color="black", ls="--", lw=1.0,
                 label=f"white-noise rate, 1 in 9 points ({white:,.0f})")
    axes.set(xlabel="low-pass cut-off short_cutoff [µm]", ylabel="summits",
             title="Cut-off study: summits and radius against short_cutoff")
    axes.grid(alpha=0.3, which="both")
    right = axes.twinx()
    right.loglog(cutoffs, radii, "s-", color="#d62728", lw=1.8, label="1 / mean κ")
    if unfiltered["summit_radius_mean"] is not None:
        right.axhline(unfiltered["summit_radius_mean"] * 1e6, color="#d62728", ls=":", lw=1.2,
                      label="1 / mean κ without low-pass")
    right.set_ylabel("1 / mean κ [µm]", color="#d62728")
    from matplotlib.ticker import FixedLocator, NullFormatter, NullLocator

    # One labelled tick per cut-off studied (log axes would crowd minor labels).
    axes.xaxis.set_major_locator(FixedLocator(cutoffs))
    axes.xaxis.set_minor_locator(NullLocator())
    axes.xaxis.set_minor_formatter(NullFormatter())
    axes.set_xticklabels([f"{value:.3g}" for value in cutoffs])
    handles = axes.get_legend_handles_labels()
    more = right.get_legend_handles_labels()
    axes.legend(handles[0] + more[0], handles[1] + more[1], loc="upper center",
                bbox_to_anchor=(0.5, -0.13), ncol=2, fontsize=8)
