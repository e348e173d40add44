"""Figures of linear models: Bode diagrams over operating points, Nyquist diagrams of loops and pole maps."""

from __future__ import annotations

import numpy as np

from ..plotting import legend_outside, new_figure
from ..units import column_label


def _column_name(column: str) -> str:
    """``bearing_position_m`` -> ``bearing_position`` (the label without its unit)."""
    return column_label(column).split(" [")[0]


def _column_unit(column: str) -> str:
    label = column_label(column)
    return label[label.index("[") + 1:-1] if "[" in label else "1"

__all__ = ["bode_figure", "nyquist_figure", "pole_map_figure", "judder_figure", "shift_figure"]


def _fitted(label: str, fig, rows: int = 2, fontsize: float = 10.0) -> str:
    """A y label broken into lines that fit beside one of ``rows`` axes stacked in ``fig`` (at a word gap;
    a signal name is never broken, the unit in brackets starts a line of its own when the label is broken).

    A y label longer than its axes' height runs past the figure's edge, where no layout brings it back
    (#33: ``|clutch1.normal_force / actuator.motor_voltage| [dB re 1 N/V]`` was cut at the top)."""
    import textwrap

    # an axes' height in points, less the title and the x label, over a character's mean advance (~0.6 em)
    chars = max(12, int((fig.get_figheight() * 72.0 / rows - 40.0) / (0.6 * fontsize)))
    if len(label) <= chars:
        return label
    name, bracket, unit = label.partition(" [")
    lines = textwrap.wrap(name, chars, break_long_words=False, break_on_hyphens=False)
    return "\n".join(lines + ([bracket.strip() + unit] if bracket else []))


def bode_figure(models, frequencies_hz, *, title: str = "", over: str | None = None):
    """Bode diagram (magnitude in dB, phase in degrees) of linear models, one line per model and pair.

    Parameters
    ----------
    models : sequence of (str, control.StateSpace)
        Label (the operating point) and linear model (:func:`clutchlab.control.linearize`).
    frequencies_hz : array_like
        Frequencies [Hz].
    title : str
        Figure title.
    over : str, optional
        Plot every other output over this output (:func:`clutchlab.control.frequency_table`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .linear import frequency_table, signal_name

    f = np.asarray(frequencies_hz, dtype=float)
    over = None if over is None else signal_name(over)   # (a result column: clutch1.tau_Nm)
    # constrained layout: the y labels, the legends beside the axes and the title all stay inside the figure (#33)
    fig, (ax_m, ax_p) = new_figure(2, 1, width=7.5, height=6.0, sharex=True, layout="constrained")
    columns = getattr(models[0][1], "columns", {}) if models else {}

    def _name(signal):
        return _column_name(columns.get(signal, signal))

    def _unit(signal):
        return _column_unit(columns.get(signal, signal))

    def pairs(sys):
        if over is None:
            return [(o, i) for o in sys.output_labels for i in sys.input_labels]
        return [(o, over) for o in sys.output_labels if o != over]

    for label, sys in models:
        table = frequency_table(sys, f, over=over)
        for o, i in pairs(sys):
            name = label if len(pairs(sys)) == 1 else f"{label}: {_name(o)} / {_name(i)}"
            (line,) = ax_m.semilogx(f, table[f"gain_dB_{o}__{i}"], label=name)
            ax_p.semilogx(f, table[f"phase_deg_{o}__{i}"], color=line.get_color(), label=name)
    first = pairs(models[0][1])
    if len(first) == 1:
        o, i = first[0]
        ax_m.set_ylabel(_fitted(f"|{_name(o)} / {_name(i)}| [dB re 1 {_unit(o)}/{_unit(i)}]", fig))
    else:
        ax_m.set_ylabel("magnitude [dB]")
    ax_p.set_ylabel("phase [deg]")
    ax_p.set_xlabel("frequency [Hz]")
    for ax in (ax_m, ax_p):
        ax.grid(True, which="both", alpha=0.3)
    legend_outside(ax_m)
    legend_outside(ax_p)
    if title:
        fig.suptitle(title)
    return fig


def pole_map_figure(poles, value: str, *, title: str = "", scale: float = 1.0, unit: str = ""):
    """Poles over an operating range, coloured by the swept value.

    Parameters
    ----------
    poles : pandas.DataFrame
        From :func:`clutchlab.control.pole_sweep`.
    value : str
        Column of the swept value.
    title : str
        Figure title.
    scale : float
        Factor for the colour bar's values (1e3 for mm).
    unit : str
        Unit label of the colour bar.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = new_figure(1, 1, width=7.0, height=4.5)
    sc = ax.scatter(poles["pole_real_1_s"], poles["pole_imag_1_s"] / (2 * np.pi), c=poles[value] * scale, s=14,
                    cmap="viridis", label="poles")
    cb = fig.colorbar(sc, ax=ax)
    cb.set_label(f"{value} [{unit}]" if unit else value)
    ax.axvline(0.0, color="k", lw=0.8, label="stability boundary")
    ax.legend(loc="upper left", fontsize=8)
    ax.set_xscale("symlog", linthresh=10.0)
    ax.set_xlabel("real part [1/s]")
    ax.set_ylabel("imaginary part / 2π [Hz]")
    ax.grid(True, alpha=0.3)
    if title:
        ax.set_title(title)
    return fig


def nyquist_figure(loops, frequencies_hz=None, *, title: str = "", radius: float = 3.0):
    """Nyquist diagram of SISO open loops ``L(jw)`` around the critical point -1.

    Parameters
    ----------
    loops : sequence of (str, control.LTI)
        Label and open loop (e.g. ``control.ss(pi.tf()) * G``).
    frequencies_hz : array_like, optional
        Frequencies [Hz] (default: 400 from 0.01 Hz to 10 kHz); the curve runs through the negative
        frequencies (the mirror image) and then the positive ones.
    title : str
        Figure title.
    radius : float
        Half-width of the view around the origin (a loop with an integrator goes to infinity at low
        frequency; what matters is near -1).

    Returns
    -------
    matplotlib.figure.Figure
    """
    f = np.logspace(-2, 4, 400) if frequencies_hz is None else np.asarray(frequencies_hz, dtype=float)
    fig, ax = new_figure(1, 1, width=6.5, height=5.5)
    for label, L in loops:
        g = np.asarray(L(2j * np.pi * f)).reshape(-1)
        g = np.concatenate([np.conj(g[::-1]), g])  # negative frequencies (the mirror image), then positive
        ax.plot(g.real, g.imag, label=label)
    circle = np.exp(1j * np.linspace(0.0, 2 * np.pi, 361))
    ax.plot(circle.real, circle.imag, ":", color="0.5", lw=0.8, label="|L| = 1")
    ax.plot([-1.0], [0.0], "rx", ms=9, mew=2, label="critical point -1")
    ax.set_xlim(-radius, radius)
    ax.set_ylim(-radius, radius)
    ax.set_aspect("equal")
    ax.set_xlabel("Re L(jω) [1]")
    ax.set_ylabel("Im L(jω) [1]")
    ax.grid(True, alpha=0.3)
    legend_outside(ax)
    if title:
        ax.set_title(title)
    return fig


def judder_figure(timeline, *, title: str = ""):
    """The judder analysis along a run (:func:`clutchlab.control.judder_timeline`): the least damped oscillating
    mode's damping ratio and frequency over time, the times where it grows shaded, and each sliding friction
    element's damping ``d tau/d w_rel`` (negative: it feeds the modes).

    Parameters
    ----------
    timeline : pandas.DataFrame
        From :func:`clutchlab.control.judder_timeline`.
    title : str
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(3, 1, width=7.5, height=7.5, sharex=True)
    t = timeline["time_s"].to_numpy(dtype=float)
    unstable = timeline["unstable"].to_numpy(dtype=bool)
    ax = axes[0]
    ax.plot(t, 100.0 * timeline["damping_1"].to_numpy(dtype=float), "o-", ms=3, label="least damped mode")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_ylabel("damping ratio [%]")
    axes[1].plot(t, timeline["frequency_Hz"].to_numpy(dtype=float), "o-", ms=3, color="C1")
    axes[1].set_ylabel("its frequency [Hz]")
    elements = [c for c in timeline.columns if c.endswith(".damping_Nms_rad")]
    for k, column in enumerate(elements):
        axes[2].plot(t, timeline[column].to_numpy(dtype=float), "o-", ms=3, color=f"C{k + 2}",
                     label=column.removesuffix(".damping_Nms_rad"))
    axes[2].axhline(0.0, color="k", lw=0.8)
    axes[2].set_ylabel("d tau/d w_rel [N m s/rad]")
    axes[2].set_xlabel("time [s]")
    for a in axes:
        a.grid(True, alpha=0.3)
        for k in np.flatnonzero(unstable):   # (the span to the next analysis time, or half the spacing at the end)
            right = t[k + 1] if k + 1 < t.size else t[k] + 0.5 * (t[k] - t[k - 1] if k else 1.0)
            a.axvspan(t[k], right, color="C3", alpha=0.12, lw=0)
    axes[0].legend(loc="best", fontsize=8, title="shaded: a mode grows (judder)", title_fontsize=8)
    if elements:
        axes[2].legend(loc="best", fontsize=8)
    if title:
        axes[0].set_title(title)
    return fig


def shift_figure(quality, *, title: str = ""):
    """A gear shift and its phases (:func:`clutchlab.control.shift_quality`): the engine's speed and the
    clutches' slip speeds [rpm], their torques, the output's acceleration (its level before the shift and its dip
    marked) and its jerk, with the torque phase and the inertia phase shaded (bounded by the start, the hand-over
    and the lock-up).  An interrupted (AMT) shift's: the clutch's and the synchronisers' slips and torques, with the
    release, the neutral and synchronisation, and the closing shaded (bounded by the start, the clutch's opening,
    the dogs' engagement and the clutch's lock-up).

    Parameters
    ----------
    quality : ShiftQuality
        From :func:`clutchlab.control.shift_quality` (its ``trace``).
    title : str
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    q = quality
    tr = q.trace
    t = tr["time_s"].to_numpy(dtype=float)
    span = max(q.end_s - q.start_s, 0.05)   # (drawn: a quarter of the shift before it, half of it after)
    keep = (t >= q.start_s - 0.25 * span) & (t <= q.end_s + 0.5 * span)
    t = t[keep]
    acc = next(c for c in tr.columns if c.startswith("acceleration_"))
    jerk = next(c for c in tr.columns if c.startswith("jerk_"))
    a_unit, j_unit = acc.removeprefix("acceleration_"), jerk.removeprefix("jerk_")
    pretty = {"m_s2": "m/s²", "rad_s2": "rad/s²", "m_s3": "m/s³", "rad_s3": "rad/s³"}
    rpm = 30.0 / np.pi
    fig, axes = new_figure(4, 1, width=7.5, height=9.0, sharex=True)
    off, on = q.columns["offgoing"], q.columns["oncoming"]
    interrupted = q.kind == "interrupted"
    if "engine_speed_rad_s" in tr.columns:
        axes[0].plot(t, rpm * tr["engine_speed_rad_s"].to_numpy(float)[keep], color="k", label="engine")
    axes[0].plot(t, rpm * tr["offgoing_slip_rad_s"].to_numpy(float)[keep], color="C0", label=f"{off} slip (off-going)")
    axes[0].plot(t, rpm * tr["oncoming_slip_rad_s"].to_numpy(float)[keep], color="C1", label=f"{on} slip (on-coming)")
    if interrupted:
        axes[0].plot(t, rpm * tr["clutch_slip_rad_s"].to_numpy(float)[keep], color="C3",
                     label=f"{q.columns['clutch']} slip (clutch)")
    axes[0].set_ylabel("speed [rpm]")
    axes[1].plot(t, tr["offgoing_torque_Nm"].to_numpy(float)[keep], color="C0", label=off)
    axes[1].plot(t, tr["oncoming_torque_Nm"].to_numpy(float)[keep], color="C1", label=on)
    if interrupted:
        axes[1].plot(t, tr["clutch_torque_Nm"].to_numpy(float)[keep], color="C3", label=q.columns["clutch"])
    axes[1].set_ylabel("|clutch torque| [N m]")
    before = q.metrics[f"acceleration_before_{a_unit}"]
    dip = q.metrics[f"acceleration_dip_{a_unit}"]
    axes[2].plot(t, tr[acc].to_numpy(float)[keep], color="C2", label="acceleration")
    axes[2].axhline(before, color="0.4", lw=0.8, ls="--", label="before the shift")
    axes[2].axhline(before - dip, color="C3", lw=0.8, ls=":", label=f"dip {dip:.3g} {pretty.get(a_unit, a_unit)}")
    axes[2].set_ylabel(f"acceleration [{pretty.get(a_unit, a_unit)}]")
    axes[3].plot(t, tr[jerk].to_numpy(float)[keep], color="C4")
    axes[3].set_ylabel(f"jerk [{pretty.get(j_unit, j_unit)}]")
    axes[3].set_xlabel("time [s]")
    if interrupted:
        spans = ((q.start_s, q.handover_s), (q.handover_s, q.lockup_s), (q.lockup_s, q.end_s))
        legend = "shaded:\nrelease (blue),\nneutral and\nsynchronisation\n(orange),\nclosing (green)"
    else:
        spans = ((q.start_s, q.handover_s), (q.handover_s, q.lockup_s)) if q.sequence == "torque_first" else (
            (q.lockup_s, max(q.handover_s, q.lockup_s)), (q.start_s, q.lockup_s))
        legend = "shaded:\ntorque phase (blue),\ninertia phase (orange)"
    for a in axes:
        a.grid(True, alpha=0.3)
        for k, span in enumerate(spans):
            a.axvspan(*span, color=f"C{k}", alpha=0.10, lw=0)
    for a in axes[:3]:
        legend_outside(a)
    axes[3].text(1.02, 0.5, legend, transform=axes[3].transAxes, fontsize=8, va="center")
    if title:
        axes[0].set_title(title)
    return fig
