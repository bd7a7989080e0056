/**
 * The Bode figure as plotly data and layout (pure, no plotly import: unit-tested without a browser): magnitude,
 * phase and coherence over log frequency in three rows sharing the frequency axis, one colour per curve (measured
 * solid, predicted dashed), the markers as labelled vertical lines across the rows; and the predicted step.
 */

import type { Trace as BodeTrace } from "../../lib/bode";
import type { StepResponse } from "../../lib/whatif/step";

export const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"];

export interface Curve {
  label: string;
  trace: BodeTrace;
  color: string;
  dash?: "dash" | "dot";
}

/** A marker drawn as a vertical line: bandwidth, a margin's crossover, a resonance. */
export interface MarkerLine {
  freq: number;
  label: string;
  color: string;
  /** where the label sits on the line: measured markers at the bottom, predicted ones at the top (default) */
  at?: "start" | "end";
}

export interface PlotTrace {
  type: "scatter";
  mode: "lines" | "lines+markers";
  name: string;
  x: number[];
  y: (number | null)[];
  xaxis: "x";
  yaxis: "y" | "y2" | "y3";
  legendgroup: string;
  showlegend: boolean;
  line: { color: string; width: number; dash?: string };
  marker?: { size: number };
}

export interface Figure {
  data: PlotTrace[];
  layout: Record<string, unknown>;
}

function curveTraces(curve: Curve): PlotTrace[] {
  const base = { type: "scatter" as const, xaxis: "x" as const, legendgroup: curve.label, x: curve.trace.freq,
    line: { color: curve.color, width: 1.5, dash: curve.dash } };
  const mode = curve.dash ? "lines" as const : "lines+markers" as const;
  const traces: PlotTrace[] = [
    { ...base, mode, marker: { size: 3 }, name: curve.label, y: curve.trace.magnitudeDb, yaxis: "y", showlegend: true },
    { ...base, mode, marker: { size: 3 }, name: curve.label, y: curve.trace.phaseDeg, yaxis: "y2", showlegend: false },
  ];
  if (curve.trace.coherence) traces.push({ ...base, mode, marker: { size: 3 }, name: curve.label, y: curve.trace.coherence, yaxis: "y3", showlegend: false });
  return traces;
}

export function markerShape(line: MarkerLine): Record<string, unknown> {
  return {
    type: "line", xref: "x", yref: "paper", x0: line.freq, x1: line.freq, y0: 0, y1: 1,
    line: { color: line.color, width: 1, dash: "dot" },
    label: { text: line.label, textposition: line.at ?? "end", font: { size: 11, color: line.color }, textangle: -90, xanchor: "right" },
  };
}

/** Magnitude and phase; a coherence row under them only when a curve has coherence (measured ones). */
export function bodeFigure(curves: Curve[], lines: MarkerLine[], magnitudeTitle: string): Figure {
  const coherence = curves.some((curve) => curve.trace.coherence);
  return {
    data: curves.flatMap(curveTraces),
    layout: {
      xaxis: { type: "log", title: { text: "frequency [Hz]" }, anchor: coherence ? "y3" : "y2", showgrid: true },
      yaxis: { domain: coherence ? [0.5, 1] : [0.42, 1], title: { text: magnitudeTitle }, showgrid: true },
      yaxis2: { domain: coherence ? [0.2, 0.46] : [0, 0.38], title: { text: "phase [°]" }, showgrid: true },
      ...(coherence ? { yaxis3: { domain: [0, 0.15], title: { text: "coherence" }, range: [0, 1.05], showgrid: true } } : {}),
      shapes: lines.map(markerShape),
      margin: { l: 64, r: 16, t: 16, b: 44 },
      legend: { orientation: "h", y: 1.02, yanchor: "bottom", x: 0 },
      hovermode: "x",
    },
  };
}

export function stepFigure(steps: { label: string; step: StepResponse; color: string; dash?: "dash" }[]): Figure {
  return {
    data: steps.map(({ label, step, color, dash }) => ({
      type: "scatter", mode: "lines", name: label, x: step.time_s.map((t) => t * 1000), y: step.speed,
      xaxis: "x", yaxis: "y", legendgroup: label, showlegend: true, line: { color, width: 1.5, dash },
    })),
    layout: {
      xaxis: { title: { text: "time [ms]" }, showgrid: true },
      yaxis: { title: { text: "speed / step" }, showgrid: true },
      margin: { l: 56, r: 16, t: 16, b: 44 },
      legend: { orientation: "h", y: 1.02, yanchor: "bottom", x: 0 },
    },
  };
}
