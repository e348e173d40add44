"""Figures of driveline runs."""

from __future__ import annotations

from ..plotting import legend_outside, new_figure

__all__ = ["driveline_figure"]


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
