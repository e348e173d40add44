"""Figures of driveline runs.

:func:`driveline_figure` draws a whole run on one page (``clutchlab driveline simulate --plot``); the
demo report draws one figure per quantity: :func:`speeds_figure`, :func:`friction_torques_figure`,
:func:`modes_figure` and :func:`energy_figure`, and a torque converter's operating points
(:func:`converter_figure`).
"""

from __future__ import annotations

import numpy as np

from ..plotting import legend_outside, new_figure

__all__ = ["driveline_figure", "speeds_figure", "friction_torques_figure", "modes_figure", "energy_figure",
           "converter_figure", "converter_points", "EVENT_STYLES", "MODE_COLORS"]

#: line style of an event mark per event (the mode entered): colour, line style
EVENT_STYLES = {"stick": ("#2ca02c", "-"), "forward": ("#1f77b4", "--"), "backward": ("#d62728", "--"),
                "free": ("#7f7f7f", ":")}
#: colour of a friction element's mode in :func:`modes_figure`
MODE_COLORS = {"stuck": "#2ca02c", "forward": "#1f77b4", "backward": "#d62728", "free": "#d9d9d9"}


def driveline_figure(frame, events=None, *, title: str = ""):
    """Speeds of the inertias, torques and modes of the friction elements, and the energies.

    Parameters
    ----------
    frame : pandas.DataFrame
        ``SimulationResult.to_dataframe()`` of a driveline run.
    events : pandas.DataFrame, optional
        Events (``time_s``, ``component``, ``event``), marked as vertical lines.
    title : str
        Figure title.
    """
    fig, axes = new_figure(4, 1, width=8.0, height=9.0, sharex=True)
    t = frame["time_s"]
    for col in frame.columns:
        if col.endswith(".w_rad_s"):
            axes[0].plot(t, frame[col], label=col[:-len(".w_rad_s")])
        elif col.endswith(".mode_1"):
            name = col[:-len(".mode_1")]
            axes[1].plot(t, frame[f"{name}.tau_Nm"], label=name)
            axes[2].step(t, frame[col], where="post", label=name)
    for name, label in (("input_work_J", "input work"), ("dissipated_energy_J", "dissipated"),
                        ("kinetic_energy_J", "kinetic"), ("spring_energy_J", "springs")):
        axes[3].plot(t, frame[name], label=label)
    axes[0].set_ylabel("speed [rad/s]")
    axes[1].set_ylabel("friction torque [N·m]")
    axes[2].set_ylabel("mode [-]")
    axes[2].set_yticks([-1, 0, 1, 2], ["backward", "stuck", "forward", "free"])
    axes[3].set_ylabel("energy [J]")
    axes[3].set_xlabel("time [s]")
    if events is not None:
        for tt in events["time_s"]:
            for ax in axes:
                ax.axvline(tt, color="0.8", lw=0.6, zorder=0)
    for ax in axes:
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            legend_outside(ax)
    if title:
        fig.suptitle(title)
    return fig


def _finish(fig, axes, title):
    for ax in axes:
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            legend_outside(ax)
    if title:
        axes[0].set_title(title, fontsize=10)
    fig.tight_layout()
    return fig


def speeds_figure(frame, events=None, *, columns=None, title: str = ""):
    """Speeds of the inertias against time, the events marked by vertical lines (one style per event).

    Parameters
    ----------
    frame : pandas.DataFrame
        ``SimulationResult.to_dataframe()`` of a driveline run.
    events : pandas.DataFrame, optional
        Events with ``time_s`` and ``event`` (the mode entered: stick, forward, backward, free).
    columns : list of str, optional
        Speed columns to draw [rad/s] (default: every column ending in ``.w_rad_s``).
    title : str
        Title of the axes.
    """
    fig, ax = new_figure(width=8.0, height=3.8)
    t = frame["time_s"]
    columns = [c for c in frame.columns if c.endswith(".w_rad_s")] if columns is None else list(columns)
    for col in columns:
        ax.plot(t, frame[col], lw=1.4, label=col.removesuffix(".w_rad_s"))
    if events is not None:
        for tt, kind in zip(events["time_s"], events["event"]):
            color, style = EVENT_STYLES.get(kind, ("k", "-."))
            ax.axvline(tt, color=color, ls=style, lw=0.9, zorder=0, label=f"event: {kind}")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("speed [rad/s]")
    ax.grid(True, alpha=0.3)
    handles = {}  # one legend entry per label: every event line of a kind has the same style
    for h in ax.get_lines():
        handles.setdefault(h.get_label(), h)
    legend_outside(ax, list(handles.values()))
    if title:
        ax.set_title(title, fontsize=10)
    fig.tight_layout()
    return fig


def friction_torques_figure(frame, names, *, title: str = ""):
    """Torques of the friction elements ``names`` against time (``<name>.tau_Nm``, on flange a).

    Parameters
    ----------
    frame : pandas.DataFrame
        ``SimulationResult.to_dataframe()`` of a driveline run.
    names : list of str
        The friction elements (``SimulationResult.mode_names``).
    title : str
        Title of the axes.
    """
    fig, ax = new_figure(width=8.0, height=3.4)
    t = frame["time_s"]
    for name in names:
        ax.plot(t, frame[f"{name}.tau_Nm"], lw=1.2, label=name)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("friction torque [N·m]")
    return _finish(fig, [ax], title)


def modes_figure(intervals, *, title: str = ""):
    """Modes of the friction elements as lanes: one row per element, coloured by mode over time.

    Parameters
    ----------
    intervals : dict
        Element name -> list of ``(start [s], stop [s], mode)`` covering the run, mode one of stuck,
        forward, backward, free (:func:`clutchlab.demo.driveline.mode_intervals`).
    title : str
        Title of the axes.
    """
    from matplotlib.patches import Patch

    names = list(intervals)
    fig, ax = new_figure(width=8.0, height=0.9 + 0.55 * max(len(names), 1))
    seen = []
    for row, name in enumerate(reversed(names)):
        for start, stop, mode in intervals[name]:
            ax.broken_barh([(start, stop - start)], (row - 0.35, 0.7), facecolors=MODE_COLORS.get(mode, "k"),
                           edgecolor="none")
            if mode not in seen:
                seen.append(mode)
    ax.set_yticks(np.arange(len(names)), list(reversed(names)))
    ax.set_ylim(-0.6, len(names) - 0.4)
    if names and intervals[names[0]]:
        ends = [iv[-1][1] for iv in intervals.values() if iv]
        starts = [iv[0][0] for iv in intervals.values() if iv]
        ax.set_xlim(min(starts), max(ends))
    ax.set_xlabel("time [s]")
    ax.set_ylabel("friction element")
    ax.grid(True, axis="x", alpha=0.3)
    order = [m for m in MODE_COLORS if m in seen] + [m for m in seen if m not in MODE_COLORS]
    legend_outside(ax, [Patch(facecolor=MODE_COLORS.get(m, "k"), label=m) for m in order])
    if title:
        ax.set_title(title, fontsize=10)
    fig.tight_layout()
    return fig


def energy_figure(frame, *, title: str = ""):
    """Energies of a run (input work, dissipated per element, stored) and the energy-balance error.

    The upper axes: the work of the sources, the energy dissipated in every element and in all, and the
    stored energy (kinetic + springs); the lower axes: ``input work - dissipated - change of the stored
    energy`` [µJ], which is zero for an exact solution.

    Parameters
    ----------
    frame : pandas.DataFrame
        ``SimulationResult.to_dataframe()`` of a driveline run.
    title : str
        Title of the upper axes.
    """
    fig, axes = new_figure(2, 1, width=8.0, height=5.6, sharex=True, gridspec_kw={"height_ratios": [2.2, 1.0]})
    t = frame["time_s"]
    ax = axes[0]
    ax.plot(t, frame["input_work_J"], "k", lw=1.6, label="input work")
    for col in frame.columns:
        if col.endswith(".dissipated_J"):
            ax.plot(t, frame[col], "--", lw=1.1, label=f"dissipated in {col[:-len('.dissipated_J')]}")
    ax.plot(t, frame["dissipated_energy_J"], color="#8c564b", lw=1.6, label="dissipated, all")
    ax.plot(t, frame["kinetic_energy_J"] + frame["spring_energy_J"], color="#9467bd", lw=1.6,
            label="stored (kinetic + springs)")
    ax.set_ylabel("energy [J]")
    axes[1].plot(t, frame["energy_error_J"] * 1e6, color="#d62728", lw=1.0, label="energy-balance error")
    axes[1].axhline(0.0, color="0.5", lw=0.6, label="zero (exact balance)")
    axes[1].set_ylabel("balance error [µJ]")
    axes[1].set_xlabel("time [s]")
    return _finish(fig, list(axes), title)


def converter_points(frame, name, *, share=1e-3):
    """A torque converter's operating points in drive, from its columns only (a run's, or a rig's record mapped to
    those names): ``<name>.tau_Nm`` (-T_p), ``<name>.tau_b_Nm`` (T_t), ``<name>.w_rel_rad_s`` (w_t - w_p) and
    ``<name>.speed_ratio_1`` (SR).

    Returns a DataFrame with ``time_s``, ``speed_ratio_1``, ``capacity_factor_rpm_sqrtNm`` (K = w_p / sqrt(T_p),
    w_p = -w_rel / (1 - SR)), ``torque_ratio_1`` (T_t / T_p) and ``efficiency_1`` (TR SR), at the samples where the
    impeller drives (0 <= SR < 1) with an impeller torque above ``share`` of its largest.

    Parameters
    ----------
    frame : pandas.DataFrame
        The columns above and ``time_s``.
    name : str
        The converter.
    share : float
        The smallest impeller torque drawn, a share of the largest [-] (a point near no torque has no K).
    """
    import pandas as pd

    tp = -frame[f"{name}.tau_Nm"].to_numpy(dtype=float)
    tt = frame[f"{name}.tau_b_Nm"].to_numpy(dtype=float)
    sr = frame[f"{name}.speed_ratio_1"].to_numpy(dtype=float)
    w_rel = frame[f"{name}.w_rel_rad_s"].to_numpy(dtype=float)
    keep = (sr >= 0.0) & (sr < 1.0) & (tp > share * max(float(np.max(np.abs(tp), initial=0.0)), 1e-300))
    wp = -w_rel[keep] / (1.0 - sr[keep])
    tr = tt[keep] / tp[keep]
    return pd.DataFrame({"time_s": frame["time_s"].to_numpy()[keep], "speed_ratio_1": sr[keep],
                         "capacity_factor_rpm_sqrtNm": wp / np.sqrt(tp[keep]) * 30.0 / np.pi,
                         "torque_ratio_1": tr, "efficiency_1": tr * sr[keep]})


def converter_figure(frame, name, *, title: str = ""):
    """A torque converter's characteristic as the run (or a record) went through it: capacity factor K
    [rpm/sqrt(N m)], torque ratio and efficiency over the speed ratio, each point coloured by its time
    (:func:`converter_points`).

    Parameters
    ----------
    frame : pandas.DataFrame
        ``SimulationResult.to_dataframe()`` of a driveline run with the converter ``name``.
    name : str
        The converter.
    title : str
        Title of the figure.
    """
    pts = converter_points(frame, name)
    fig, axes = new_figure(width=8.0, height=6.4, nrows=3, sharex=True)
    quantities = (("capacity_factor_rpm_sqrtNm", "K [rpm/√(N·m)]"), ("torque_ratio_1", "torque ratio TR [-]"),
                  ("efficiency_1", "efficiency TR·SR [-]"))
    for ax, (col, label) in zip(axes, quantities):
        art = ax.scatter(pts["speed_ratio_1"], pts[col], c=pts["time_s"], s=8, cmap="viridis")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    low = pts["capacity_factor_rpm_sqrtNm"][pts["speed_ratio_1"] <= 0.95]
    if len(low):   # (K grows without bound as the slip vanishes: the axis shows the table's range)
        axes[0].set_ylim(0.0, 1.5 * float(low.max()))
    axes[-1].set_xlabel("speed ratio SR = ω_t/ω_p [-]")
    axes[-1].set_xlim(0.0, 1.0)
    fig.colorbar(art, ax=list(axes), label="time [s]")
    if title:
        axes[0].set_title(title, fontsize=10)
    return fig
