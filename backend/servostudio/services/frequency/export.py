"""Saved frequency responses as one standalone HTML file (Python ``plotly``, plotly.js inlined): it opens offline,
without the server, with magnitude, phase and coherence over log frequency, one trace set per result overlaid, the
markers drawn (bandwidth, resonance, anti-resonance as vertical lines; gain and phase margins in the table) and a
table saying what each result is (loop, drive, time, who, excitation, plant fit, gains).

Everything that comes from a file is escaped: plotly reads trace names and annotations as markup.
"""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence
from typing import Any

import plotly.graph_objects as go  # type: ignore[import-untyped]
import plotly.offline  # type: ignore[import-untyped]
from plotly.subplots import make_subplots  # type: ignore[import-untyped]

STYLES = (("#1f77b4", "solid"), ("#d62728", "dash"), ("#2ca02c", "dot"), ("#9467bd", "dashdot"))
ROWS = (("magnitude_db", "magnitude [dB]"), ("phase_deg", "phase [°]"), ("coherence", "coherence"))
#: the markers drawn as vertical lines, with their label
LINES = (("bandwidth_hz", "bandwidth"), ("resonance_hz", "resonance"), ("antiresonance_hz", "anti-resonance"))
MARKERS = (
    ("bandwidth_hz", "bandwidth", "Hz"),
    ("gain_margin_db", "gain margin", "dB"),
    ("phase_margin_deg", "phase margin", "°"),
    ("resonance_hz", "resonance", "Hz"),
    ("antiresonance_hz", "anti-resonance", "Hz"),
)
LOOPS = {"plant": "plant", "closed": "closed loop", "open": "open loop"}
CONFIG = {"displaylogo": False, "responsive": True}
STYLE = (
    "body{font:14px system-ui,sans-serif;margin:20px;color:#222}table{border-collapse:collapse;margin:8px 0 16px}"
    "td,th{border:1px solid #ccc;padding:3px 8px;text-align:left;vertical-align:top}th{background:#f4f4f4}"
)


def frequency_html(results: Sequence[Mapping[str, Any]], place: str) -> str:
    """The HTML document of one or more saved results (the first is the reference, the others overlaid)."""
    title = html.escape(f"Frequency response · {place}")
    tables = "".join(_table(number, result) for number, result in enumerate(results))
    plot = _figure(results).to_html(full_html=False, include_plotlyjs=False, div_id="bode", config=CONFIG)
    return (
        f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>{title}</title>'
        f"<style>{STYLE}</style><script>{plotly.offline.get_plotlyjs()}</script></head>"
        f"<body><h1>{title}</h1>{tables}{plot}</body></html>\n"
    )


def trace_name(number: int, result: Mapping[str, Any]) -> str:
    """How a result is named in the legend: its number, loop and saved name (escaped)."""
    loop = LOOPS.get(str(result.get("loop")), "measured")
    return html.escape(f"{number + 1}: {loop} · {result.get('name', '')}")


def _figure(results: Sequence[Mapping[str, Any]]) -> go.Figure:
    figure = make_subplots(rows=3, cols=1, shared_xaxes=True, row_heights=[0.45, 0.35, 0.2], vertical_spacing=0.04)
    for number, result in enumerate(results):
        points = result.get("points") or []
        freq = [point["freq_hz"] for point in points]
        for row, (key, _) in enumerate(ROWS, 1):
            figure.add_trace(_trace(number, result, freq, [point[key] for point in points], row), row=row, col=1)
        for shape in _marker_lines(number, result):
            figure.add_shape(shape)
    figure.update_layout(height=760, margin={"l": 60, "r": 20, "t": 30, "b": 50}, hovermode="x unified",
                         legend={"orientation": "h", "y": 1.02, "yanchor": "bottom", "x": 0})  # fmt: skip
    figure.update_xaxes(type="log", showgrid=True)
    figure.update_xaxes(title_text="frequency [Hz]", row=3, col=1)
    for row, (_, title) in enumerate(ROWS, 1):
        figure.update_yaxes(title_text=title, showgrid=True, row=row, col=1)
    figure.update_yaxes(range=[0, 1.05], row=3, col=1)
    return figure


def _trace(number: int, result: Mapping[str, Any], freq: list[float], values: list[float], row: int) -> go.Scatter:
    color, dash = STYLES[number % len(STYLES)]
    name = trace_name(number, result)
    return go.Scatter(x=freq, y=values, name=name, legendgroup=name, showlegend=row == 1, mode="lines+markers",
                      marker={"size": 3}, line={"color": color, "dash": dash, "width": 1.5})  # fmt: skip


def _marker_lines(number: int, result: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Vertical lines over all three plots at the result's bandwidth, resonance and anti-resonance."""
    color = STYLES[number % len(STYLES)][0]
    markers = result.get("markers") or {}
    return [
        {"type": "line", "xref": "x", "yref": "paper", "x0": value, "x1": value, "y0": 0, "y1": 1,
         "line": {"color": color, "width": 1, "dash": "dot"},
         "label": {"text": f"{label} {value:.4g} Hz", "textposition": "end"}}
        for key, label in LINES
        if _finite(value := markers.get(key))
    ]  # fmt: skip


def _table(number: int, result: Mapping[str, Any]) -> str:
    rows = "".join(
        f"<tr><th>{html.escape(key)}</th><td>{html.escape(value)}</td></tr>" for key, value in _facts(result)
    )
    return f"<h2>{trace_name(number, result)}</h2><table>{rows}</table>"


def _facts(result: Mapping[str, Any]) -> list[tuple[str, str]]:
    excitation = result.get("excitation") or {}
    facts = [
        ("loop", LOOPS.get(str(result.get("loop")), str(result.get("loop")))),
        ("magnitude", _meaning(result)),
        ("drive", f"{result.get('device', '')} node {result.get('node', '')}"),
        ("axis", str(result.get("axis") or "")),
        ("measured (UTC)", str(result.get("time") or "")),
        ("by", str(result.get("user") or "")),
        ("excitation", ", ".join(f"{key}={value}" for key, value in excitation.items())),
    ]
    markers = result.get("markers") or {}
    facts += [(label, _number(markers.get(key), unit)) for key, label, unit in MARKERS]
    facts += [(key, _number(value, "")) for key, value in (result.get("plant_fit") or {}).items()]
    gains = result.get("gains") or {}
    facts.append(("gains", ", ".join(f"{key}={_number(value, '')}" for key, value in gains.items() if _finite(value))))
    if result.get("aborted"):
        facts.append(("aborted", str(result["aborted"])))
    return facts


def _meaning(result: Mapping[str, Any]) -> str:
    """The magnitude's unit: a plant per N·m, or per A where the drive gave no torque constant (``input``)."""
    if result.get("loop") == "plant":
        per_ampere = (result.get("excitation") or {}).get("input") == "current"
        return f"dB of (velocity in rad/s) / ({'current in A' if per_ampere else 'torque in N·m'})"
    return "dB of actual / demanded velocity"


def _finite(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _number(value: object, unit: str) -> str:
    if not _finite(value):
        return "—"
    return f"{value:.4g} {unit}".strip()
