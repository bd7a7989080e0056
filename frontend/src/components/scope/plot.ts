/**
 * The plot: plotly.js, imported on first use (its own chunk, so no other page loads it), drawing the figure of
 * `figure.ts` whenever the capture, the math trace, the cursors or the view change. A click on the time plot moves
 * a cursor (A, then B, alternately; Shift+click moves B). The time of the last redraw is kept in `data-draw-ms`.
 */

import type { PlotlyHTMLElement } from "plotly.js-dist-min";
import { effect, h, type Scope } from "../../lib/dom";
import { fftFigure, timeFigure } from "./figure";
import type { Cursors, ScopeModel } from "./model";

type Plotly = (typeof import("plotly.js-dist-min"))["default"];

let loading: Promise<Plotly> | null = null;

/** plotly.js, loaded once. */
export function loadPlotly(): Promise<Plotly> {
  loading ??= import("plotly.js-dist-min").then((module) => module.default);
  return loading;
}

export interface PlotHandle {
  element: HTMLElement;
  /** The drawn graph (null until the first capture is drawn). */
  graph(): PlotlyHTMLElement | null;
  dispose(): void;
}

export function plotView(model: ScopeModel, scope: Scope): PlotHandle {
  const graph = h("div", { class: "scope-plot", "data-testid": "scope-plot", style: { width: "100%", height: "440px" } });
  const element = h("div", { class: "panel", style: { padding: "4px" } },
    h("div", { class: "empty-state", "data-testid": "scope-empty", hidden: () => model.capture.val !== null }, "No capture yet: arm the recorder."),
    graph);
  let drawn: PlotlyHTMLElement | null = null;
  let token = 0;
  scope.run(() => effect(() => {
    const capture = model.capture.val, view = model.view.val, math = model.math.val, cursors = model.cursors.val;
    const mine = ++token;
    if (!capture) return;
    void loadPlotly().then(async (Plotly) => {
      if (mine !== token) return;
      const figure = view === "fft" ? fftFigure(capture) : timeFigure(capture, math, cursors);
      const started = performance.now();
      drawn = await Plotly.react(graph, figure.data as never, figure.layout as never, { displaylogo: false, responsive: true });
      graph.dataset.drawMs = (performance.now() - started).toFixed(1);
      graph.dataset.drawn = `${capture.captured_at} ${view} ${figure.data.length}`;
      listenOnce(drawn, model);
    });
  }));
  return {
    element,
    graph: () => drawn,
    dispose: () => {
      token++;
      if (drawn) void loadPlotly().then((Plotly) => Plotly.purge(graph));
    },
  };
}

const listening = new WeakSet<object>();

/** Clicks on the time plot move the cursors (registered once per graph element). */
function listenOnce(graph: PlotlyHTMLElement, model: ScopeModel): void {
  if (listening.has(graph)) return;
  listening.add(graph);
  graph.on("plotly_click", (event) => {
    const point = event.points[0];
    if (!point || model.view.rawVal !== "time" || typeof point.x !== "number") return;
    const shift = (event.event as MouseEvent | undefined)?.shiftKey ?? false;
    model.cursors.val = moveCursor(model.cursors.rawVal, point.x, shift);
  });
}

/** A click at time `t`: the cursor due next moves there (B with Shift), and the other one is due after it. */
export function moveCursor(cursors: Cursors, t: number, shift = false): Cursors {
  const which = shift ? "b" : cursors.next;
  return { ...cursors, [which]: t, next: which === "a" ? "b" : "a" };
}
