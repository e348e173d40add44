"""Figures for reports (matplotlib, imported lazily so that importing clutchlab stays light).

Every function returns a :class:`matplotlib.figure.Figure`; nothing is shown
or saved here (the report layer does that).
"""

from __future__ import annotations

import numpy as np

__all__ = ["new_figure", "press_characterization", "static_curves_vs_record"]

MODEL_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2")


def new_figure(nrows=1, ncols=1, *, width=7.0, height=4.5, **kw):
    """A figure and axes with the Agg backend (safe on machines without a display)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(nrows, ncols, figsize=(width, height), **kw)
    return fig, axes


def press_characterization(panels, *, title: str = "", ncols: int = 4):
    """Raw press records, averaged branches and the characterised curve (Haramina et al. 2024, Fig. 9 style).

    Parameters
    ----------
    panels : list of dict
        Each with ``title``, ``record`` (DataFrame with ``displacement_m``,
        ``force_N``), ``curve`` (a Curve or None), optional ``truth`` (Curve,
        drawn dashed) and ``channel`` (displacement column).
    """
    n = len(panels)
    nrows = int(np.ceil(n / ncols))
    fig, axes = new_figure(nrows, ncols, width=3.4 * ncols, height=2.9 * nrows, squeeze=False)
    for ax, panel in zip(axes.ravel(), panels):
        rec = panel["record"]
        ch = panel.get("channel", "displacement_m")
        ax.plot(rec[ch] * 1e3, rec["force_N"], color="#7fa7d9", lw=0.6, label="raw (synthetic)")
        curve = panel.get("curve")
        if curve is not None:
            ax.plot(curve.deflection * 1e3, curve.force, color="k", lw=1.6, label="characterised")
        truth = panel.get("truth")
        if truth is not None:
            x = np.linspace(*(curve.span if curve is not None else truth.span), 200)
            ax.plot(x * 1e3, truth(x), "--", color="#2ca02c", lw=1.0, label="virtual-clutch law")
        ax.set_title(panel["title"], fontsize=9)
        ax.set_xlabel(panel.get("xlabel", "displacement [mm]"), fontsize=8)
        ax.set_ylabel("force [N]", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
    for ax in axes.ravel()[n:]:
        ax.axis("off")
    axes.ravel()[0].legend(fontsize=7)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
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
    """
    fig, ax = new_figure(width=7.0, height=4.4)
    if record is not None:
        ax.plot(record["bearing_position_m"] * 1e3, record[quantity], color="0.55", lw=0.8,
                label="full-clutch record (synthetic)")
    for k, (label, df) in enumerate(curves.items()):
        ax.plot(df["bearing_position_m"] * 1e3, df[quantity], color=MODEL_COLORS[k % len(MODEL_COLORS)],
                lw=1.4, label=label)
    ax.set_xlabel("release bearing position [mm]")
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
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
    """
    fig, axes = new_figure(2, 2, width=9.0, height=6.0, sharex=True)
    t = frame["time_s"].to_numpy()
    ax = axes[0, 0]
    ax.plot(t, frame["bearing_position_m"] * 1e3, lw=1.3, label="bearing position")
    if "reference_m" in frame:
        ax.plot(t, frame["reference_m"] * 1e3, "--", color="0.4", lw=1.0, label="reference")
    if "master_position_m" in frame:
        ax.plot(t, frame["master_position_m"] * 1e3, lw=1.0, label="master piston")
    ax.set_ylabel("position [mm]")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    if "pressure_Pa" in frame:
        ax.plot(t, frame["pressure_Pa"] / 1e5, lw=1.3, label="CSC pressure")
        ax.plot(t, frame["master_pressure_Pa"] / 1e5, lw=0.9, label="master pressure")
    ax.set_ylabel("pressure [bar]")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    if "motor_current_A" in frame:
        ax.plot(t, frame["motor_current_A"], lw=1.2, label="current [A]")
        ax.plot(t, frame["motor_voltage_V"], lw=1.0, label="voltage [V]")
    ax.set_ylabel("motor")
    ax.set_xlabel("time [s]")
    ax.legend(fontsize=8)
    ax = axes[1, 1]
    ax.plot(t, frame["torque_Nm"], lw=1.3, color="C3")
    ax.set_ylabel("clutch torque [N m]")
    ax.set_xlabel("time [s]")
    for a in axes.flat:
        a.grid(alpha=0.3)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


def hysteresis_loop(loops: dict, static=None, *, title: str = ""):
    """Bearing force against bearing position for release/engage cycles (hysteresis loops).

    Parameters
    ----------
    loops : dict
        Label -> DataFrame with ``bearing_position_m`` and a force column
        (``bearing_force_N`` if present, else ``bearing_force_clutch_N``).
    static : DataFrame, optional
        Frictionless static curve (``bearing_position_m``, ``bearing_force_N``), drawn dashed.
    """
    fig, ax = new_figure(width=7.0, height=4.4)
    if static is not None:
        ax.plot(static["bearing_position_m"] * 1e3, static["bearing_force_N"], "--", color="0.3", lw=1.0,
                label="static curve, friction off")
    for k, (label, df) in enumerate(loops.items()):
        col = "bearing_force_N" if "bearing_force_N" in df else "bearing_force_clutch_N"
        ax.plot(df["bearing_position_m"] * 1e3, df[col], color=MODEL_COLORS[k % len(MODEL_COLORS)], lw=1.3,
                label=label)
    ax.set_xlabel("release bearing position [mm]")
    ax.set_ylabel("bearing force [N]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title, fontsize=10)
    fig.tight_layout()
    return fig
