/**
 * What the plot shows, as plotly data and layout, from the capture, the math trace, the cursors and the view: pure
 * functions (no plotly import), so the figure is unit-tested without a browser and plotly.js loads only to draw it.
 *
 * Time view: one WebGL (`scattergl`) trace per channel on its own y-axis in its unit, the math trace on the axis of
 * its first operand, the trigger at t = 0 marked with a line and "T", the pre-trigger part shaded, the two
 * cursors as vertical lines. FFT view: the magnitude spectrum (Hann window) of each channel on its own y-axis.
 */

import type { CaptureChannel, CaptureData } from "../../client/scope";
import { spectrum } from "../../lib/fft";
import { derivative, difference, scaled } from "../../lib/measure";
import type { Cursors, MathTrace } from "./model";

export const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"];
const AXIS_GAP = 0.07;

export interface Trace {
  type: "scattergl";
  mode: "lines";
  name: string;
  x: number[];
  y: number[];
  yaxis: string;
  line: { color: string; width: number; dash?: string };
}

export interface Figure {
  data: Trace[];
  layout: Record<string, unknown>;
}

/** Seconds of each sample: (i − trigger_index) × period. */
export function timesOf(capture: CaptureData): number[] {
  const period = capture.period_ns / 1e9;
  return Array.from({ length: capture.samples }, (_, i) => (i - capture.trigger_index) * period);
}

/** A channel's physical values as numbers (a sample JSON could not carry is NaN: plotly leaves a gap). */
export function valuesOf(capture: CaptureData, channel: number): number[] {
  return capture.values[channel].map((value) => (value === null ? NaN : value));
}

export function label(capture: CaptureData, channel: number): string {
  const info = capture.channels[channel];
  return `${info.key} ${info.name}${info.unit ? ` [${info.unit}]` : ""}`;
}

/** The math trace's values and name, or null when none is chosen (or its operands are not in the capture). */
export function mathValues(capture: CaptureData, math: MathTrace): { name: string; y: number[] } | null {
  const count = capture.channels.length;
  if (math.operation === "none" || math.a >= count || (math.operation === "a-b" && math.b >= count)) return null;
  const a = valuesOf(capture, math.a), key = (n: number) => capture.channels[n].key;
  if (math.operation === "a-b") return { name: `${key(math.a)} − ${key(math.b)}`, y: difference(a, valuesOf(capture, math.b)) };
  if (math.operation === "a*k") return { name: `${key(math.a)} · ${math.k}`, y: scaled(a, math.k) };
  return { name: `d/dt ${key(math.a)} [/s]`, y: derivative(a, capture.period_ns / 1e9) };
}

export function timeFigure(capture: CaptureData, math: MathTrace, cursors: Cursors): Figure {
  const x = timesOf(capture);
  const data = capture.channels.map((_, n) => trace(label(capture, n), x, valuesOf(capture, n), n));
  const extra = mathValues(capture, math);
  if (extra) data.push({ ...trace(extra.name, x, extra.y, math.a), line: { color: COLORS[4], width: 1.5, dash: "dot" } });
  const layout = axesLayout(capture.channels, "time [s] (0 = trigger)", capture.captured_at);
  layout.shapes = [preTriggerShade(x), marker(0, "#888", "dash"), ...cursorLines(cursors)];
  layout.annotations = [
    { x: 0, y: 1, yref: "paper", text: "T", showarrow: false, yanchor: "bottom", font: { color: "#888" } },
    ...cursorLabels(cursors),
  ];
  return { data, layout };
}

export function fftFigure(capture: CaptureData): Figure {
  const dt = capture.period_ns / 1e9;
  const data = capture.channels.map((_, n) => {
    const result = spectrum(valuesOf(capture, n).map((value) => (Number.isNaN(value) ? 0 : value)), dt);
    return trace(`|FFT| ${label(capture, n)}`, result.frequency, result.magnitude, n);
  });
  return { data, layout: axesLayout(capture.channels, "frequency [Hz] (Hann window)", capture.captured_at) };
}

export function trace(name: string, x: number[], y: number[], axis: number): Trace {
  return { type: "scattergl", mode: "lines", name, x, y, yaxis: axis === 0 ? "y" : `y${axis + 1}`, line: { color: COLORS[axis % 4], width: 1.5 } };
}

/** The x-axis and one y-axis per channel: the first on the left, the others stacked on the right; zoom and pan
 * survive a redraw of the same `revision`. */
export function axesLayout(channels: CaptureChannel[], xTitle: string, revision: string): Record<string, unknown> {
  const extra = Math.max(0, channels.length - 1);
  const layout: Record<string, unknown> = {
    xaxis: { title: { text: xTitle }, domain: [0, 1 - AXIS_GAP * extra], zeroline: false },
    margin: { l: 60, r: 50, t: 24, b: 44 },
    legend: { orientation: "h", y: -0.18 },
    hovermode: "x",
    dragmode: "zoom",
    uirevision: revision,
  };
  channels.forEach((channel, n) => {
    const axis: Record<string, unknown> = { title: { text: channel.unit || channel.key }, color: COLORS[n % 4], zeroline: false };
    if (n > 0) Object.assign(axis, { overlaying: "y", side: "right", anchor: "free", position: 1 - AXIS_GAP * (extra - n) });
    layout[n === 0 ? "yaxis" : `yaxis${n + 1}`] = axis;
  });
  return layout;
}

function marker(x: number, color: string, dash: string): Record<string, unknown> {
  return { type: "line", x0: x, x1: x, yref: "paper", y0: 0, y1: 1, line: { color, width: 1, dash } };
}

function preTriggerShade(x: number[]): Record<string, unknown> {
  return { type: "rect", x0: x[0] ?? 0, x1: 0, yref: "paper", y0: 0, y1: 1, fillcolor: "rgba(128,128,128,0.08)", line: { width: 0 }, layer: "below" };
}

function cursorLines(cursors: Cursors): Record<string, unknown>[] {
  return (["a", "b"] as const).filter((name) => cursors[name] !== null).map((name) => marker(cursors[name]!, "#e36209", name === "a" ? "solid" : "dot"));
}

function cursorLabels(cursors: Cursors): Record<string, unknown>[] {
  return (["a", "b"] as const).filter((name) => cursors[name] !== null).map((name) => (
    { x: cursors[name], y: 1, yref: "paper", text: name.toUpperCase(), showarrow: false, yanchor: "bottom", font: { color: "#e36209" } }));
}
