"""The size-effect figure: nominal strength against size on log-log axes with Bazant's size effect law.

Units: sizes D [mm], nominal strengths [MPa].
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter

from fracid.report.figures import COMPUTED, ESTIMATE, MEASURED, float_array, new_figure

__all__ = ["size_effect_figure"]



def size_effect_figure(sizes, sigma_computed, fit=None, sigma_measured=None, measured_std=None,
                       calibrated=None) -> Figure:
    """Nominal strength against size on log-log axes, with Bazant's size effect law when fitted.

    Parameters
    ----------
    sizes : array_like
        Specimen sizes D [mm].
    sigma_computed : array_like
        Computed nominal strengths at ``sizes`` [MPa]; nan (a failed run) is left out.
    fit : SizeEffectFit, optional
        Drawn as the law over the sizes' range, with its asymptotes: the strength criterion
        sigma_N = B f_t and LEFM sigma_N = B f_t sqrt(D0 / D) (slope -1/2), which cross at D0.
    sigma_measured, measured_std : array_like, optional
        Measured nominal strengths at ``sizes`` and their standard deviations [MPa] (error bars of
        +/- 1 std); nan where a size was not tested.
    calibrated : array_like of bool, optional
        True for the sizes whose data calibrated the model: their computed points are filled,
        those of the other (predicted) sizes hollow. None: no distinction.
    """
    D = float_array(sizes, np.nan)
    computed = float_array(sigma_computed, np.nan)
    if computed.shape != D.shape:
        raise ValueError(f"sigma_computed has {computed.size} values but sizes has {D.size}")
    fig = new_figure(6.4, 4.6)
    ax = fig.subplots()
    shown = [computed]
    if fit is not None:
        _size_effect_law(ax, fit, D)
    if sigma_measured is not None:
        measured = float_array(sigma_measured, np.nan)
        std = None if measured_std is None else float_array(measured_std, np.nan)
        shown.append(measured)
        ax.errorbar(D, measured, yerr=std, fmt="s", color=MEASURED, mfc="none", ms=9, capsize=3,
                    label="measured" + (" +/- 1 std" if std is not None else ""))
    if calibrated is None:
        ax.plot(D, computed, "o", color=COMPUTED, ms=7, label="computed")
    else:
        used = np.asarray(calibrated, dtype=bool)
        if used.shape != D.shape:
            raise ValueError(f"calibrated has {used.size} values but sizes has {D.size}; give one flag per size")
        ax.plot(D[used], computed[used], "o", color=COMPUTED, ms=7, label="computed, calibration sizes")
        ax.plot(D[~used], computed[~used], "o", mfc="white", mec=COMPUTED, mew=1.6, ms=7,
                label="computed, predicted sizes")
    ax.set_xscale("log")
    ax.set_yscale("log")
    _plain_log_ticks(ax.xaxis)
    _plain_log_ticks(ax.yaxis)
    if fit is not None:
        # the LEFM line grows without bound as D -> 0: cap the axis just above the law and the points
        ax.set_ylim(top=1.6 * np.nanmax(np.concatenate([[fit.B_ft], *shown])))
    ax.set_xlabel("size D [mm]")
    ax.set_ylabel("nominal strength sigma_N [MPa]")
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize="small", loc="best")
    return fig


def _plain_log_ticks(axis) -> None:
    """Plain numbers (0.8, 2, 1000) on a log axis rather than powers of ten; the minor ticks are
    labelled only when the axis spans less than a decade (a strength axis often does), as there
    are then at most eight of them."""
    axis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))

    def minor(value, _):
        low, high = axis.get_view_interval()
        return f"{value:g}" if high < 10.0 * low else ""

    axis.set_minor_formatter(FuncFormatter(minor))


def _size_effect_law(ax, fit, D) -> None:
    """The fitted law and its two asymptotes over a range wide enough to show where they meet."""
    data = D[np.isfinite(D) & (D > 0)]
    # show the transition at D0 when it is near the data, never decades of empty axis
    span = np.concatenate([data, [np.clip(fit.D0, data.min() / 10.0, data.max() * 10.0)]])
    grid = np.geomspace(span.min() / 2.0, span.max() * 2.0, 200)
    ax.plot(grid, fit.predict(grid), "-", color=ESTIMATE, lw=1.6,
            label=f"size effect law: B f_t = {fit.B_ft:.3g} MPa, D0 = {fit.D0:.3g} mm")
    ax.axhline(fit.B_ft, color="k", lw=0.9, ls="--", label="strength criterion")
    ax.plot(grid, fit.B_ft * np.sqrt(fit.D0 / grid), "k-.", lw=0.9, label="LEFM, slope -1/2")
