"""Figures for reports (matplotlib, imported lazily so that importing clutchlab stays light).

Every function returns a :class:`matplotlib.figure.Figure`; nothing is shown
or saved here (the report layer does that).
"""

from __future__ import annotations

import numpy as np

__all__ = ["new_figure", "mark_synthetic", "is_marked_synthetic", "press_characterization", "static_curves_vs_record",
           "eclutch_response", "hysteresis_loop", "legend_outside"]

MODEL_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2")


def new_figure(nrows=1, ncols=1, *, width=7.0, height=4.5, **kw):
    """A figure and axes with the Agg backend (safe on machines without a display)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(nrows, ncols, figsize=(width, height), **kw)
    return fig, axes


#: gid of the "synthetic data" stamp of :func:`mark_synthetic`
SYNTHETIC_GID = "clutchlab-synthetic-data"


def _content_box(fig, stamp, renderer):
    """The display box of everything ``fig`` draws except ``stamp`` and the figure's background, with its
    right edge held inside the figure (where the stamp is right-aligned)."""
    from matplotlib.transforms import Bbox

    boxes = []
    for artist in fig.get_children():
        if artist is stamp or artist is fig.patch or not artist.get_visible() or not artist.get_in_layout():
            continue
        box = artist.get_tightbbox(renderer)
        if box is not None and np.isfinite(box.width) and np.isfinite(box.height) and (box.width or box.height):
            boxes.append(box)
    if not boxes:
        return fig.bbox
    box = Bbox.union(boxes)
    return Bbox.from_extents(box.x0, box.y0, min(box.x1, fig.bbox.x1), box.y1)


def mark_synthetic(fig, note: str = "SYNTHETIC DATA (not measured)"):
    """Stamp a figure as drawn from synthetic data (virtual rigs, simulations, bundled synthetic records).

    The stamp is a small red text right-aligned just below everything else the
    figure draws (axes, their labels and tick labels, legends, texts), placed
    anew at every drawing, after the layout: it never covers an axis label or a
    tick label (#33).  A constrained or tight layout engine of the figure is
    told to leave a strip for it at the bottom; where a figure laid out once
    has no room below its axes, the stamp lies below the figure's edge and a
    figure saved with ``bbox_inches="tight"`` (as clutchlab saves every figure)
    grows to hold it.
    It is added once (calling it again changes nothing), so the mark travels
    with the image wherever it is copied.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    note : str
        Text of the stamp.

    Returns
    -------
    matplotlib.figure.Figure
        ``fig``.
    """
    if not is_marked_synthetic(fig):
        from matplotlib.text import Annotation

        def below_the_rest(renderer):   # a callable anchor: matplotlib asks it at every drawing
            return _content_box(fig, stamp, renderer)

        stamp = Annotation(note, xy=(1.0, 0.0), xycoords=below_the_rest, xytext=(0.0, -3.0),
                           textcoords="offset points", ha="right", va="top", fontsize=7, color="#b00020",
                           gid=SYNTHETIC_GID, annotation_clip=False)
        fig.add_artist(stamp)
        _leave_a_strip(fig, (7.0 * 1.5 + 3.0) / 72.0)   # the stamp's line and its offset [in]
    return fig


def _leave_a_strip(fig, height_in: float) -> None:
    """Make a figure's layout engine (constrained or tight) leave ``height_in`` inches free at the bottom, so
    the stamp placed below the axes stays inside the figure; other figures keep their layout."""
    from matplotlib.layout_engine import ConstrainedLayoutEngine, TightLayoutEngine

    engine = fig.get_layout_engine()
    strip = min(0.2, height_in / max(fig.get_figheight(), 1e-6))
    if isinstance(engine, ConstrainedLayoutEngine):     # rect = (left, bottom, width, height)
        x, y, w, h = engine.get()["rect"]
        engine.set(rect=(x, y + strip, w, h - strip))
    elif isinstance(engine, TightLayoutEngine):         # rect = (left, bottom, right, top)
        left, bottom, right, top = engine.get()["rect"] or (0.0, 0.0, 1.0, 1.0)
        engine.set(rect=(left, bottom + strip, right, top))


def is_marked_synthetic(fig) -> bool:
    """Whether :func:`mark_synthetic` stamped ``fig``."""
    return any(a.get_gid() == SYNTHETIC_GID for a in (*fig.texts, *fig.artists))


def legend_outside(ax_or_fig, handles=None, *, where: str = "right", ncol: int = 1, fontsize: float = 8):
    """A legend beside the axes (``where="right"``) or above them (``"top"``), never over the data.

    Parameters
    ----------
    ax_or_fig : matplotlib.axes.Axes
        Axes whose lines are listed (with ``handles``: the axes the legend is attached to).
    handles : list, optional
        Artists to list (default: the labelled lines of the axes).
    where : {"right", "top"}
        Beside the axes or in a row above them.
    ncol : int
        Columns of the legend.
    fontsize : float
        Font size [pt].
    """
    ax = ax_or_fig
    if handles is None:
        handles, _ = ax.get_legend_handles_labels()
    labels = [h.get_label() for h in handles]
    if where == "top":
        return ax.legend(handles, labels, loc="lower left", bbox_to_anchor=(0.0, 1.02), ncol=ncol, fontsize=fontsize,
                         borderaxespad=0.0, frameon=False)
    return ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.02, 1.0), ncol=ncol, fontsize=fontsize,
                     borderaxespad=0.0)


def press_characterization(panels, *, title: str = "", ncols: int = 4):
    """Raw press records, averaged branches and the characterised curve (Haramina et al. 2024, Fig. 9 style).

    The raw record is drawn first and the characterised curve over it as a
    thin line with markers at its samples, so the raw hysteresis stays
    visible; one legend for all panels sits below them.

    Parameters
    ----------
    panels : list of dict
        Each with ``title``, ``record`` (DataFrame with ``displacement_m``,
        ``force_N``), ``curve`` (a Curve or None), optional ``truth`` (Curve,
        drawn dashed), ``channel`` (displacement column) and ``xlabel``.
    title : str
        Figure title.
    ncols : int
        Panels per row.
    """
    import textwrap

    n = len(panels)
    ncols = max(1, min(ncols, n))
    nrows = int(np.ceil(n / ncols))
    fig, axes = new_figure(nrows, ncols, width=3.4 * ncols, height=3.0 * nrows + 0.4, squeeze=False)
    handles = {}
    for ax, panel in zip(axes.ravel(), panels):
        rec = panel["record"]
        ch = panel.get("channel", "displacement_m")
        (h,) = ax.plot(rec[ch] * 1e3, rec["force_N"], color="#6f9fd8", lw=1.3, zorder=1, label="raw record")
        handles.setdefault("raw", h)
        curve = panel.get("curve")
        if curve is not None:
            (h,) = ax.plot(curve.deflection * 1e3, curve.force, color="k", lw=0.7, marker="o", ms=2.0, mfc="none",
                           mew=0.5, markevery=2, zorder=3, label="characterised curve")
            handles.setdefault("curve", h)
        truth = panel.get("truth")
        if truth is not None:
            x = np.linspace(*(curve.span if curve is not None else truth.span), 200)
            (h,) = ax.plot(x * 1e3, truth(x), "--", color="#2ca02c", lw=1.0, zorder=2, label="virtual-clutch law")
            handles.setdefault("truth", h)
        ax.set_title(textwrap.fill(str(panel["title"]), 40), fontsize=8.5)
        ax.set_xlabel(panel.get("xlabel", "displacement [mm]"), fontsize=8)
        ax.set_ylabel("force [N]", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
    for ax in axes.ravel()[n:]:
        ax.axis("off")
    top = 0.93 if title else 1.0
    if title:
        fig.suptitle(title, fontsize=10)
    if len(handles) > 1:
        fig.legend(list(handles.values()), [h.get_label() for h in handles.values()], loc="lower center",
                   ncol=len(handles), fontsize=8, frameon=False)
        fig.tight_layout(rect=(0.0, 0.06 if nrows > 1 else 0.1, 1.0, top))
    else:
        fig.tight_layout(rect=(0.0, 0.0, 1.0, top))
    return fig


def static_curves_vs_record(curves: dict, record=None, *, quantity: str = "bearing_force_N",
                            ylabel: str = "bearing force [N]", title: str = ""):
    """Static curves of several models against a recorded release/engagement (Fig. 12 style).

    Parameters
    ----------
    curves : dict
        Label -> DataFrame with ``bearing_position_m`` and ``quantity``.
    record : DataFrame, optional
        Recorded ``bearing_position_m`` and ``quantity`` (drawn in grey).
    quantity : str
        Column drawn (``bearing_force_N``, ``torque_Nm``, ...).
    ylabel : str
        Label of the y axis, with its unit.
    title : str
        Axes title.
    """
    fig, ax = new_figure(width=8.2, height=4.4)
    if record is not None:
        ax.plot(record["bearing_position_m"] * 1e3, record[quantity], color="0.55", lw=0.8,
                label="full-clutch record")
    for k, (label, df) in enumerate(curves.items()):
        ax.plot(df["bearing_position_m"] * 1e3, df[quantity], color=MODEL_COLORS[k % len(MODEL_COLORS)],
                lw=1.4, label=label)
    ax.set_xlabel("release bearing position [mm]")
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    if len(ax.get_lines()) > 1:
        legend_outside(ax)
    if title:
        ax.set_title(title, fontsize=10)
    fig.tight_layout()
    return fig


def static_curves_panels(curves: dict, record=None, *, title: str = ""):
    """Static curves in three panels over the bearing position: bearing force, normal force, torque.

    Parameters
    ----------
    curves : dict
        Label -> DataFrame of :meth:`~clutchlab.eclutch.ClutchModel.static_curve`
        (``bearing_position_m`` [m], ``bearing_force_N`` [N], ``normal_force_N``
        [N], ``torque_Nm`` [N·m]).
    record : DataFrame, optional
        A full-clutch record (``bearing_position_m`` and whichever of the three
        quantities it has), drawn in grey.
    title : str
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
        Three axes sharing the x axis, labelled with units.
    """
    panels = (("bearing_force_N", "bearing force [N]", 1.0), ("normal_force_N", "normal (clamp) force [kN]", 1e-3),
              ("torque_Nm", "clutch torque [N·m]", 1.0))
    fig, axes = new_figure(3, 1, width=7.0, height=8.0, sharex=True)
    for ax, (col, ylabel, factor) in zip(axes, panels):
        if record is not None and col in record:
            ax.plot(record["bearing_position_m"] * 1e3, record[col] * factor, color="0.55", lw=0.8,
                    label="full-clutch record (synthetic)")
        for k, (label, df) in enumerate(curves.items()):
            ax.plot(df["bearing_position_m"] * 1e3, df[col] * factor, color=MODEL_COLORS[k % len(MODEL_COLORS)],
                    lw=1.4, label=label)
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[-1].set_xlabel("release bearing position [mm]")
    if title:
        axes[0].set_title(title, fontsize=10)
    fig.tight_layout()
    return fig


def eclutch_response(frame, *, title: str = ""):
    """E-clutch time response: bearing position (and reference), pressure and bearing force, motor current, torque.

    Parameters
    ----------
    frame : DataFrame
        Outputs of :meth:`clutchlab.eclutch.EClutch.simulate` (``time_s``, ``bearing_position_m``,
        ``pressure_Pa``, ``bearing_force_N``, ``motor_current_A``, ``motor_voltage_V``, ``torque_Nm``).
    title : str
        Figure title.
    """
    fig, axes = new_figure(2, 2, width=10.0, height=6.4, sharex=True)
    t = frame["time_s"].to_numpy()
    ax = axes[0, 0]
    ax.plot(t, frame["bearing_position_m"] * 1e3, lw=1.3, label="bearing position")
    if "reference_m" in frame:
        ax.plot(t, frame["reference_m"] * 1e3, "--", color="0.4", lw=1.0, label="reference")
    if "master_position_m" in frame:
        ax.plot(t, frame["master_position_m"] * 1e3, lw=1.0, label="master piston")
    ax.set_ylabel("position [mm]")
    ax = axes[0, 1]
    if "pressure_Pa" in frame:
        ax.plot(t, frame["pressure_Pa"] / 1e5, lw=1.3, label="CSC pressure")
    if "master_pressure_Pa" in frame:
        ax.plot(t, frame["master_pressure_Pa"] / 1e5, lw=0.9, label="master pressure")
    ax.set_ylabel("pressure [bar]")
    ax = axes[1, 0]
    if "motor_current_A" in frame:
        ax.plot(t, frame["motor_current_A"], lw=1.2, color="C0", label="motor current (left axis)")
        ax.set_ylabel("motor current [A]")
    if "motor_voltage_V" in frame:
        tw = ax.twinx()
        tw.plot(t, frame["motor_voltage_V"], lw=1.0, color="C1", label="motor voltage (right axis)")
        tw.set_ylabel("motor voltage [V]")
        legend_outside(ax, ax.get_lines() + tw.get_lines(), where="top", ncol=2)
    ax.set_xlabel("time [s]")
    ax = axes[1, 1]
    ax.plot(t, frame["torque_Nm"], lw=1.3, color="C3", label="clutch torque")
    ax.set_ylabel("clutch torque [N·m]")
    ax.set_xlabel("time [s]")
    for a in axes.flat:
        a.grid(alpha=0.3)
        if len(a.get_lines()) > 1 and a.get_legend() is None:
            legend_outside(a, where="top", ncol=3)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


def hysteresis_loop(loops: dict, static=None, *, title: str = ""):
    """Bearing force against bearing position for release/engage cycles, with a zoom on the peak.

    The left panel shows the whole cycle; the right panel zooms on the force
    peak, where the friction hysteresis (release branch above, engage branch
    below the static curve) is a few percent of the force and invisible at
    full scale.  A rectangle on the left panel marks the zoomed region.

    Parameters
    ----------
    loops : dict
        Label -> DataFrame with ``bearing_position_m`` and a force column
        (``bearing_force_N`` if present, else ``bearing_force_clutch_N``).
    static : DataFrame, optional
        Frictionless static curve (``bearing_position_m``, ``bearing_force_N``), drawn dashed.
    title : str
        Figure title.
    """
    fig, (ax, zoom) = new_figure(1, 2, width=11.0, height=4.6, gridspec_kw={"width_ratios": [1.25, 1.0]})
    series = []
    if static is not None:
        series.append(("static curve, friction off", static["bearing_position_m"].to_numpy() * 1e3,
                       static["bearing_force_N"].to_numpy(), dict(ls="--", color="k", lw=1.0, zorder=4)))
    for k, (label, df) in enumerate(loops.items()):
        col = "bearing_force_N" if "bearing_force_N" in df else "bearing_force_clutch_N"
        series.append((label, df["bearing_position_m"].to_numpy() * 1e3, df[col].to_numpy(),
                       dict(color=MODEL_COLORS[k % len(MODEL_COLORS)], lw=1.3)))
    for a in (ax, zoom):
        for label, x, y, style in series:
            a.plot(x, y, label=label, **style)
        a.set_xlabel("release bearing position [mm]")
        a.set_ylabel("bearing force [N]")
        a.grid(alpha=0.3)
    # zoom window: around the highest force of all series, wide enough to hold the loop there
    peaks = [(y.max(), x[int(np.argmax(y))]) for _, x, y, _ in series if y.size]
    if peaks:
        f_peak, x_peak = max(peaks)
        span_x = max(np.ptp(np.concatenate([x for _, x, _, _ in series])), 1e-9)
        x0, x1 = x_peak - 0.12 * span_x, x_peak + 0.12 * span_x
        inside = [y[(x >= x0) & (x <= x1)] for _, x, y, _ in series]
        lo = min(float(v.min()) for v in inside if v.size)
        hi = max(float(v.max()) for v in inside if v.size)
        pad = 0.08 * max(hi - lo, 1e-9)
        zoom.set_xlim(x0, x1)
        zoom.set_ylim(lo - pad, hi + pad)
        ax.indicate_inset_zoom(zoom, edgecolor="0.3")
        zoom.set_title("zoom on the force peak", fontsize=9)
        ax.set_title("whole cycle", fontsize=9)
    if title:
        fig.suptitle(title, fontsize=10)
    if len(series) > 1:
        fig.legend(ax.get_lines()[:len(series)], [s[0] for s in series], loc="lower center", ncol=len(series),
                   fontsize=8, frameon=False)
        fig.tight_layout(rect=(0.0, 0.08, 1.0, 0.95 if title else 1.0))
    else:
        fig.tight_layout()
    return fig
