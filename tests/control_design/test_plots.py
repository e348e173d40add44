"""Figures of linear models: everything they draw is inside the figure (no compiled model needed)."""

from __future__ import annotations

import control
import numpy as np
import pytest
from matplotlib.text import Text

from clutchlab.control.linear import signal_name
from clutchlab.control.plots import bode_figure


def _model(gain: float, output: str, input_: str):
    """A second-order model whose signals stand for the result columns ``output`` and ``input_``, as
    :func:`clutchlab.control.linearize` names them."""
    sys = control.ss(control.tf([gain * 100.0], [1.0, 2.0, 100.0]), inputs=[signal_name(input_)],
                     outputs=[signal_name(output)])
    sys.columns = {signal_name(output): output, signal_name(input_): input_}
    return sys


def _drawn_texts(fig, monkeypatch):
    """The text artists drawn (ticks outside the view are not drawn and not counted)."""
    drawn = []
    draw = Text.draw

    def recording(self, renderer):
        if self.get_visible() and self.get_text().strip():
            drawn.append(self)
        return draw(self, renderer)

    monkeypatch.setattr(Text, "draw", recording)
    fig.canvas.draw()
    return drawn, fig.canvas.get_renderer()


@pytest.mark.parametrize("output, input_", [("clutch1.normal_force_N", "actuator.motor_voltage_V"),
                                            ("bearing_position_m", "motor_voltage_V")])
def test_bode_figure_draws_every_text_inside_the_figure(output, input_, monkeypatch):
    """#33 R5: the magnitude's y label (signal names with units) ran past the figure's edge and was cut;
    every text drawn (labels, tick labels, legends, title) lies inside the figure."""
    models = [(f"bearing at {k:g} mm", _model(k, output, input_)) for k in (1.0, 2.0, 5.0, 8.0)]
    fig = bode_figure(models, np.logspace(-1, 3, 200), title="E-clutch: motor voltage to normal force")
    drawn, renderer = _drawn_texts(fig, monkeypatch)
    label = fig.axes[0].yaxis.label
    assert label in drawn and fig.axes[1].xaxis.label in drawn and len(drawn) > 20
    # the label names both signals, with underscores, and the unit of the ratio
    flat = " ".join(label.get_text().split())
    assert output.rsplit("_", 1)[0] in flat and input_.rsplit("_", 1)[0] in flat and "[dB re 1 " in flat
    fig_box = fig.bbox
    extents = [(t.get_text(), t.get_window_extent(renderer)) for t in drawn]
    outside = [(text, b) for text, b in extents if not (fig_box.x0 <= b.x0 and b.x1 <= fig_box.x1
                                                        and fig_box.y0 <= b.y0 and b.y1 <= fig_box.y1)]
    assert not outside, outside
