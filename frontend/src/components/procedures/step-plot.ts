/**
 * The verification step of an auto-tuning, recorded by the drive: reference and response over time drawn with
 * plotly.js (loaded on first use, as on the scope), with its rise time, overshoot, settling time and bandwidth beside it.
 */

import type { StepMeasure } from "../../client/procedures";
import { h } from "../../lib/dom";
import { sig } from "../../lib/procedures";
import { loadPlotly } from "../scope/plot";

export interface StepFigure {
  data: { type: "scatter"; mode: "lines"; name: string; x: number[]; y: number[]; line: { color: string; width: number; dash?: string } }[];
  layout: Record<string, unknown>;
}

/** The figure of one step (pure: tested without plotly): reference dashed, response solid, settling time marked. */
export function stepFigure(step: StepMeasure, title: string): StepFigure {
  const { time_s: x, reference, response, unit } = step.capture;
  const shapes = step.settling_time_s === null ? [] : [{
    type: "line", x0: step.settling_time_s, x1: step.settling_time_s, yref: "paper", y0: 0, y1: 1, line: { color: "#888", width: 1, dash: "dot" },
  }];
  return {
    data: [
      { type: "scatter", mode: "lines", name: "reference", x, y: reference, line: { color: "#888", width: 1.5, dash: "dash" } },
      { type: "scatter", mode: "lines", name: "response", x, y: response, line: { color: "#1f77b4", width: 1.5 } },
    ],
    layout: {
      title: { text: title, font: { size: 13 } },
      xaxis: { title: { text: "time [s]" }, zeroline: false },
      yaxis: { title: { text: unit }, zeroline: false },
      margin: { l: 60, r: 20, t: 32, b: 44 },
      legend: { orientation: "h", y: -0.25 },
      shapes,
    },
  };
}

/** The measured figures of a step, as the table beside the plot shows them. */
export function stepFigures(step: StepMeasure): [string, string, string][] {
  return [
    ["rise", "Rise time (10–90 %)", sig(step.rise_time_s === null ? null : step.rise_time_s * 1000, "ms")],
    ["overshoot", "Overshoot", sig(step.overshoot_pct, "%")],
    ["settling", "Settling time (5 %)", sig(step.settling_time_s === null ? null : step.settling_time_s * 1000, "ms")],
    ["bandwidth", bandwidthLabel(step), sig(step.bandwidth_hz, "Hz")],
  ];
}

/** Measured from one step, or from the mean frequency response of the repeated speed steps that settled. */
function bandwidthLabel(step: StepMeasure): string {
  const steps = step.bandwidth_steps_hz ?? [];
  const settled = steps.filter((value) => value !== null).length;
  return steps.length > 1 ? `−3 dB bandwidth (${settled} of ${steps.length} steps)` : "−3 dB bandwidth";
}

export function stepView(step: StepMeasure, title: string, testid: string): HTMLElement {
  const graph = h("div", { "data-testid": `${testid}-plot`, style: { width: "100%", height: "260px" } });
  void loadPlotly().then(async (Plotly) => {
    const figure = stepFigure(step, title);
    await Plotly.react(graph, figure.data as never, figure.layout as never, { displaylogo: false, responsive: true });
    graph.dataset.drawn = String(figure.data[1].x.length);
  }).catch((error: unknown) => (graph.textContent = `The plot could not be drawn: ${String(error)}`));
  return h("div", { class: "grid", style: { gridTemplateColumns: "minmax(0, 1fr) 220px", gap: "10px", alignItems: "center" }, "data-testid": testid },
    graph,
    h("table", { class: "data kv" }, h("tbody", null, stepFigures(step).map(([key, label, value]) =>
      h("tr", null, h("td", null, label), h("td", { class: "num", "data-testid": `${testid}-${key}` }, value))))));
}
