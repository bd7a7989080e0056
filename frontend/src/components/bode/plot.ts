/**
 * A plotly.js graph (loaded on first use, as on the scope) that redraws whenever the figure it follows changes.
 * The last redraw's duration is kept in `data-draw-ms` and a counter in `data-drawn`, for the page's readout and
 * the browser test.
 */

import { effect, h, state, type Scope, type State } from "../../lib/dom";
import { loadPlotly } from "../scope/plot";
import type { Figure } from "./figure";

export interface PlotHandle {
  element: HTMLElement;
  /** how long the last redraw took (ms), null before the first */
  drawMs: State<number | null>;
  dispose(): void;
}

export function plotView(scope: Scope, figure: () => Figure | null, testid: string, height: string): PlotHandle {
  const graph = h("div", { "data-testid": testid, style: { width: "100%", height } });
  const drawMs = state<number | null>(null);
  let pending: Figure | null = null, drawing = false, disposed = false, used = false, drawn = 0;
  // One draw at a time, always of the newest figure: a slider dragged faster than plotly draws skips the figures
  // in between instead of queueing them.
  const drawNext = async (): Promise<void> => {
    const Plotly = await loadPlotly();
    while (pending && !disposed) {
      const wanted = pending;
      pending = null;
      const started = performance.now();
      await Plotly.react(graph, wanted.data as never, wanted.layout as never, { displaylogo: false, responsive: true });
      used = true;
      drawMs.val = performance.now() - started;
      graph.dataset.drawMs = drawMs.rawVal!.toFixed(1);
      graph.dataset.drawn = String(++drawn);
    }
  };
  scope.run(() => effect(() => {
    pending = figure();
    if (!pending || drawing) return;
    drawing = true;
    drawNext().catch((error: unknown) => (graph.textContent = `The plot could not be drawn: ${String(error)}`))
      .finally(() => (drawing = false));
  }));
  return {
    element: graph,
    drawMs,
    dispose: () => {
      disposed = true;
      if (used) void loadPlotly().then((Plotly) => Plotly.purge(graph));
    },
  };
}
