"""What a reviewer checks on a report figure, as code: used by the demo-report and report tests.

:func:`figure_problems` draws a matplotlib figure and returns a list of
sentences, one per problem: an axes with data but no axis label, a label
without a unit in brackets or with a raw column suffix (``[rad_s]``,
``slip_speed_rad_s``), several lines without a legend, an unlabelled line,
a legend covering data, a title cut with "..." or wider than its axes.
"""

from __future__ import annotations

import re

import numpy as np

from clutchlab.units import COLUMN_UNITS

# a raw column suffix: "_rad_s", "_Nm", ... at the end of a word, or a bracket holding an underscore
_RAW = re.compile(r"\w_(?:%s)\b" % "|".join(re.escape(s) for s in sorted(COLUMN_UNITS, key=len, reverse=True)))
_RAW_BRACKET = re.compile(r"\[[^\]]*_[^\]]*\]")
_UNIT = re.compile(r"\[[^\]]+\]")


def _data_lines(ax):
    out = []
    for line in ax.get_lines():
        if not line.get_visible():
            continue
        x = np.asarray(line.get_xdata(), dtype=float)
        if x.size >= 2:
            out.append(line)
    return out


def _data_collections(ax):
    """Scatter plots (point clouds); meshes and contours are explained by a colour bar, not a legend."""
    from matplotlib.collections import PathCollection

    return [c for c in ax.collections if isinstance(c, PathCollection) and c.get_visible() and len(c.get_offsets())]


def _has_data(ax) -> bool:
    return bool(_data_lines(ax) or _data_collections(ax) or ax.images)


def _label_problem(where: str, label: str) -> str | None:
    if not label:
        return f"{where}: no axis label"
    if not _UNIT.search(label):
        return f"{where}: label {label!r} has no unit in brackets"
    if _RAW.search(label) or _RAW_BRACKET.search(label):
        return f"{where}: label {label!r} shows a raw column suffix instead of a unit"
    return None


def _display_points(ax, line) -> np.ndarray:
    """Points along a drawn line in display coordinates (segments sampled, markers only: vertices)."""
    xy = np.column_stack([np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)])
    xy = xy[np.isfinite(xy).all(axis=1)]
    if xy.shape[0] == 0:
        return np.zeros((0, 2))
    x0, x1 = sorted(ax.get_xlim())
    y0, y1 = sorted(ax.get_ylim())
    pts = line.get_transform().transform(xy)
    if line.get_linestyle() not in ("None", "", " ") and pts.shape[0] > 1:
        s = np.linspace(0.0, 1.0, 9)[None, :, None]
        pts = (pts[:-1, None, :] + (pts[1:] - pts[:-1])[:, None, :] * s).reshape(-1, 2)
    # only what is inside the axes is drawn
    inv = ax.transData.inverted().transform(pts)
    inside = (inv[:, 0] >= x0) & (inv[:, 0] <= x1) & (inv[:, 1] >= y0) & (inv[:, 1] <= y1)
    return pts[inside]


def _covered(legend, axes_list) -> int:
    box = legend.get_window_extent()
    box = box.expanded((box.width - 2) / max(box.width, 1), (box.height - 2) / max(box.height, 1))
    n = 0
    for ax in axes_list:
        if not box.overlaps(ax.get_window_extent()):
            continue
        for line in _data_lines(ax):
            p = _display_points(ax, line)
            n += int(((p[:, 0] > box.x0) & (p[:, 0] < box.x1) & (p[:, 1] > box.y0) & (p[:, 1] < box.y1)).sum())
        for coll in _data_collections(ax):
            p = coll.get_offset_transform().transform(coll.get_offsets())
            n += int(((p[:, 0] > box.x0) & (p[:, 0] < box.x1) & (p[:, 1] > box.y0) & (p[:, 1] < box.y1)).sum())
    return n


def figure_problems(fig, name: str = "figure") -> list[str]:
    """Problems a reviewer would flag on ``fig`` (an empty list if none)."""
    fig.canvas.draw()
    problems = []
    axes = [a for a in fig.axes if a.get_visible() and a.axison and not hasattr(a, "_colorbar")]
    fig_legend_texts = {t.get_text() for lg in fig.legends for t in lg.get_texts()}
    # axes drawn on top of each other (twinx) form one group: one legend may serve them all
    groups: list[list] = []
    for ax in axes:
        pos = ax.get_position().bounds
        for g in groups:
            if np.allclose(g[0].get_position().bounds, pos):
                g.append(ax)
                break
        else:
            groups.append([ax])
    for g in groups:
        if not any(_has_data(a) for a in g):
            continue
        where = f"{name}, axes {g[0].get_title() or axes.index(g[0])!r}"
        for ax in g:
            if not _has_data(ax):
                continue
            siblings = ax.get_shared_x_axes().get_siblings(ax) + g
            xlabel = ax.get_xlabel() or next((s.get_xlabel() for s in siblings if s.get_xlabel()), "")
            for problem in (_label_problem(where + " x", xlabel), _label_problem(where + " y", ax.get_ylabel())):
                if problem:
                    problems.append(problem)
            title = ax.get_title()
            if title.rstrip().endswith(("...", "…")):
                problems.append(f"{where}: title {title!r} is cut")
            if title and ax.title.get_window_extent().width > 1.15 * ax.get_window_extent().width:
                problems.append(f"{where}: title {title!r} is wider than its axes")
        lines = [ln for a in g for ln in _data_lines(a)] + [c for a in g for c in _data_collections(a)]
        if len(lines) > 1:
            legend_texts = {t.get_text() for a in g if a.get_legend() for t in a.get_legend().get_texts()}
            legend_texts |= fig_legend_texts
            if not legend_texts:
                problems.append(f"{where}: {len(lines)} lines but no legend")
            for ln in lines:
                label = ln.get_label()
                if label.startswith("_") or label not in legend_texts:
                    problems.append(f"{where}: a line is not labelled in a legend ({label!r})")
    for legend in [a.get_legend() for a in axes if a.get_legend()] + list(fig.legends):
        n = _covered(legend, axes)
        if n:
            problems.append(f"{name}: a legend covers data ({n} drawn points under it)")
    if fig._suptitle is not None and fig._suptitle.get_text().rstrip().endswith(("...", "…")):
        problems.append(f"{name}: title {fig._suptitle.get_text()!r} is cut")
    return problems
