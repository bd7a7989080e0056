/**
 * The roll's plot: the last `ROLL_WINDOW_S` seconds of each channel as a WebGL (`scattergl`) trace on its own
 * y-axis, decimated to the plot's pixel columns (min/max per column: display only), gaps as breaks in the lines and
 * shaded; redrawn at most once per animation frame while new samples arrive (`Plotly.react`). The samples drawn
 * and the last redraw's time are kept in `data-samples` and `data-draw-ms`; the display latency (the newest drawn
 * sample's SYNC → the end of its redraw, the server's clock and this one being the same host's) in
 * `data-latency-ms`.
 */

import type { CaptureChannel } from "../../client/scope";
import { h, state, type State } from "../../lib/dom";
import { decimate, type RollBuffer, type RollGap } from "../../lib/roll";
import { axesLayout, trace, type Figure } from "./figure";
import { loadPlotly } from "./plot";
import type { RollModel } from "./rollmodel";

/** What the status line shows, refreshed with each redraw. */
export interface RollProgress {
  received: number;
  lost: number;
  gaps: RollGap[];
  latencyMs: number;
}

/** The figure of the buffer's window, `columns` pixel columns wide. */
export function rollFigure(channels: CaptureChannel[], buffer: RollBuffer, period: number, columns: number): Figure {
  const to = buffer.last + 1, from = Math.max(0, to - buffer.keep);
  const data = channels.map((channel, n) => {
    const series = decimate(buffer.seqs, buffer.values[n], period, from, to, columns);
    return trace(`${channel.key} ${channel.name}${channel.unit ? ` [${channel.unit}]` : ""}`, series.x, series.y, n);
  });
  const layout = axesLayout(channels, "time [s] since the roll's start", "roll");
  (layout.xaxis as Record<string, unknown>).range = [from * period, Math.max(to, buffer.keep) * period];
  layout.legend = { orientation: "h", y: -0.3 }; // below the axis title on the lower plot
  layout.shapes = buffer.gaps.filter((gap) => gap.to > from).map((gap) => ({
    type: "rect", x0: gap.from * period, x1: gap.to * period, yref: "paper", y0: 0, y1: 1,
    fillcolor: "rgba(214,39,40,0.12)", line: { width: 0 }, layer: "below",
  }));
  return { data, layout };
}

export interface RollPlotHandle {
  element: HTMLElement;
  progress: State<RollProgress>;
  dispose(): void;
}

export function rollPlot(roll: RollModel): RollPlotHandle {
  const graph = h("div", { "data-testid": "scope-roll-plot", style: { width: "100%", height: "320px" } });
  const progress = state<RollProgress>({ received: 0, lost: 0, gaps: [], latencyMs: NaN });
  let frame = 0, drawing = false, drawn: RollBuffer | null = null, drawnCount = -1;
  const tick = () => {
    frame = requestAnimationFrame(tick);
    const buffer = roll.buffer;
    if (!buffer || drawing || (buffer === drawn && buffer.received + buffer.gaps.length === drawnCount)) return;
    drawing = true;
    drawn = buffer;
    drawnCount = buffer.received + buffer.gaps.length;
    const shown = { received: buffer.received, lost: buffer.lost, gaps: [...buffer.gaps] };
    void draw(graph, roll, buffer).then((latencyMs) => (progress.val = { ...shown, latencyMs })).finally(() => (drawing = false));
  };
  frame = requestAnimationFrame(tick);
  return {
    element: graph,
    progress,
    dispose: () => {
      cancelAnimationFrame(frame);
      if (drawn) void loadPlotly().then((Plotly) => Plotly.purge(graph));
    },
  };
}

/** Redraw; the display latency of the newest sample drawn (ms). */
async function draw(graph: HTMLElement, roll: RollModel, buffer: RollBuffer): Promise<number> {
  const Plotly = await loadPlotly();
  const synced = roll.syncedMs;
  const figure = rollFigure(roll.channels.rawVal, buffer, roll.periodS, Math.max(graph.clientWidth, 200));
  const started = performance.now();
  await Plotly.react(graph, figure.data as never, figure.layout as never, { displaylogo: false, responsive: true });
  graph.dataset.drawMs = (performance.now() - started).toFixed(1);
  graph.dataset.samples = String(buffer.received);
  const latency = Date.now() - synced;
  graph.dataset.latencyMs = latency.toFixed(0);
  return latency;
}
