"""The report's plots, made with Python ``plotly`` from the saved data: step responses from the verification
recordings, Bode plots from the saved frequency responses. plotly.js goes into the page once, inline
(:func:`library`), so the file opens offline. The plots hold no project text (titles are the page's headings), and
they read in black and white: the traces differ by dash as well as by colour."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import plotly.graph_objects as go  # type: ignore[import-untyped]
import plotly.offline  # type: ignore[import-untyped]
from plotly.subplots import make_subplots  # type: ignore[import-untyped]

#: dark colours and distinct dashes: a black-and-white print tells the traces apart
STYLES = (("#000000", "solid"), ("#1f4e9c", "dash"), ("#9c1f1f", "dot"), ("#2d6a2d", "dashdot"))
CONFIG = {"displaylogo": False, "responsive": True, "modeBarButtonsToRemove": ["select2d", "lasso2d"]}
HEIGHT_PX = 340


def library() -> str:
    """plotly.js, to inline once in the page's head."""
    return f"<script>{plotly.offline.get_plotlyjs()}</script>"


def numbers(values: object) -> list[float] | None:
    """A saved series as floats, or None when it is not a list of numbers (a damaged file is not plotted)."""
    if not isinstance(values, list) or not values:
        return None
    if not all(isinstance(value, (int, float)) and not isinstance(value, bool) for value in values):
        return None
    return [float(value) for value in values]


def step_plot(capture: Mapping[str, Any], div_id: str) -> str | None:
    """Reference and response of a saved step over time; None when the recording cannot be plotted."""
    times, reference, response = (numbers(capture.get(key)) for key in ("time_s", "reference", "response"))
    if times is None or reference is None or response is None or not len(times) == len(reference) == len(response):
        return None
    unit = str(capture.get("unit") or "")
    figure = go.Figure(layout=_layout("time [s] (0 = trigger)", unit))
    for number, (name, series) in enumerate((("reference", reference), ("response", response))):
        figure.add_trace(go.Scatter(x=times, y=series, name=name, mode="lines", line=_line(number)))
    return _div(figure, div_id)


def bode_plot(results: Sequence[Mapping[str, Any]], div_id: str) -> str | None:
    """Magnitude, phase and coherence of saved frequency responses overlaid (log frequency); None without points."""
    drawn = [(result, points) for result in results if (points := _points(result)) is not None]
    if not drawn:
        return None
    figure = make_subplots(rows=3, cols=1, shared_xaxes=True, row_heights=[0.45, 0.35, 0.2], vertical_spacing=0.04)
    for number, (result, points) in enumerate(drawn):
        label = f"{number + 1}: {_loop(result)}"
        for row, key in enumerate(("magnitude_db", "phase_deg", "coherence"), 1):
            figure.add_trace(
                go.Scatter(x=points["freq_hz"], y=points[key], name=label, legendgroup=label, showlegend=row == 1,
                           mode="lines+markers", marker={"size": 3}, line=_line(number)),
                row=row, col=1,
            )  # fmt: skip
    figure.update_layout(template="simple_white", height=HEIGHT_PX * 1.6, margin=_margin(), legend=_legend())
    figure.update_xaxes(type="log", showgrid=True)
    figure.update_xaxes(title_text="frequency [Hz]", row=3, col=1)
    for row, title in enumerate(("magnitude [dB]", "phase [°]", "coherence"), 1):
        figure.update_yaxes(title_text=title, showgrid=True, row=row, col=1)
    figure.update_yaxes(range=[0, 1.05], row=3, col=1)  # coherence is 0..1 whatever the data
    return _div(figure, div_id)


def _loop(result: Mapping[str, Any]) -> str:
    """The trace's name: which loop, from a fixed set (plotly reads trace names as markup; no file text goes in)."""
    return {"plant": "plant", "closed": "closed loop", "open": "open loop"}.get(str(result.get("loop")), "measured")


def _points(result: Mapping[str, Any]) -> dict[str, list[float]] | None:
    points = result.get("points")
    if not isinstance(points, list) or not points or not all(isinstance(point, dict) for point in points):
        return None
    columns = {key: numbers([point.get(key) for point in points]) for key in ("freq_hz", "magnitude_db", "phase_deg")}
    coherence = [point.get("coherence") for point in points]
    if any(series is None for series in columns.values()):
        return None
    shown = {key: series for key, series in columns.items() if series is not None}
    shown["coherence"] = numbers(coherence) or [float("nan")] * len(points)
    return shown


def _layout(x_title: str, y_title: str) -> dict[str, object]:
    return {
        "template": "simple_white",
        "height": HEIGHT_PX,
        "margin": _margin(),
        "xaxis": {"title": {"text": x_title}, "showgrid": True},
        "yaxis": {"title": {"text": y_title}, "showgrid": True},
        "legend": _legend(),
    }


def _line(number: int) -> dict[str, object]:
    color, dash = STYLES[number % len(STYLES)]
    return {"color": color, "dash": dash, "width": 1.5}


def _margin() -> dict[str, int]:
    return {"l": 60, "r": 20, "t": 20, "b": 50}


def _legend() -> dict[str, object]:
    return {"orientation": "h", "y": 1.02, "yanchor": "bottom", "x": 0}


def _div(figure: go.Figure, div_id: str) -> str:
    body = figure.to_html(full_html=False, include_plotlyjs=False, div_id=div_id, config=CONFIG)
    return f'<div class="plot">{body}</div>'
