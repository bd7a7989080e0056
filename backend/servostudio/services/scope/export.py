"""A capture as one standalone interactive HTML file (Python ``plotly``, the library inlined): it opens offline,
without the server, with zoom, pan and a y-axis per channel, the trigger marked at time 0."""

from __future__ import annotations

import html

import plotly.graph_objects as go  # type: ignore[import-untyped]

from servostudio.services.scope.capture import Capture
from servostudio.services.scope.capturefile import microseconds_text

COLORS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd")
AXIS_GAP = 0.06  # share of the width each extra y-axis takes on the right


def capture_html(capture: Capture) -> str:
    """The HTML document of one capture."""
    figure = go.Figure(layout=_layout(capture))
    times = capture.times_s()
    for number, channel in enumerate(capture.channels):
        figure.add_trace(
            go.Scattergl(
                x=times,
                y=capture.physical(number),
                name=f"{channel.key} {channel.name}" + (f" [{channel.unit}]" if channel.unit else ""),
                yaxis="y" if number == 0 else f"y{number + 1}",
                line={"color": COLORS[number % len(COLORS)], "width": 1.5},
                mode="lines",
            )
        )
    return figure.to_html(full_html=True, include_plotlyjs=True, config={"displaylogo": False})


def _layout(capture: Capture) -> dict[str, object]:
    extra = max(0, len(capture.channels) - 1)
    layout: dict[str, object] = {
        "title": {"text": html.escape(_title(capture))},
        "xaxis": {"title": {"text": "time [s] (0 = trigger)"}, "domain": [0, 1 - AXIS_GAP * extra]},
        "hovermode": "x unified",
        "legend": {"orientation": "h", "y": -0.15},
        "shapes": [_trigger_marker()],
    }
    for number, channel in enumerate(capture.channels):
        layout["yaxis" if number == 0 else f"yaxis{number + 1}"] = _y_axis(number, channel.unit, extra)
    return layout


def _y_axis(number: int, unit: str, extra: int) -> dict[str, object]:
    axis: dict[str, object] = {"title": {"text": unit or "raw"}, "color": COLORS[number % len(COLORS)]}
    if number > 0:
        axis.update(overlaying="y", side="right", anchor="free", position=1 - AXIS_GAP * (extra - number))
    return axis


def _trigger_marker() -> dict[str, object]:
    return {"type": "line", "x0": 0, "x1": 0, "yref": "paper", "y0": 0, "y1": 1, "line": {"dash": "dot"}}


def _title(capture: Capture) -> str:
    drive = capture.drive
    period = microseconds_text(capture.period_ns)
    return (
        f"{drive.device} node {drive.node} ({drive.bus}) · {capture.captured_at} · {capture.samples} samples at "
        f"{period} µs · trigger {capture.trigger}"
    )
