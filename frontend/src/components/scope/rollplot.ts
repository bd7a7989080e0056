/**
 * The roll's plot. While the roll runs: one 2D canvas (`rollcanvas.ts`), redrawn at most once per animation frame
 * and only when samples (or a gap) arrived, showing the last `ROLL_WINDOW_S` seconds of each channel decimated to
 * the plot's pixel columns (min/max per column: display only) on its own y-axis, gaps as breaks and shaded bands.
 * Once it stops: the same window as a plotly figure (zoom, pan, hover over what was rolled), drawn once.
 *
 * The plot's element keeps the samples drawn in `data-samples`, the last frame's drawing time in `data-draw-ms`,
 * the frames drawn in the last second in `data-fps`, and the display latency (the newest drawn sample's SYNC → its
 * frame, the server's clock and this one being the same host's) in `data-latency-ms`.
 */

import type { CaptureChannel } from "../../client/scope";
import { effect, h, state, type Scope, type State } from "../../lib/dom";
import type { RollBuffer, RollGap } from "../../lib/roll";
import { rollFrame, rollWindow } from "../../lib/rollframe";
import { axesLayout, COLORS, trace, type Figure } from "./figure";
import { loadPlotly } from "./plot";
import { paintRoll, plotBox, type Palette } from "./rollcanvas";
import type { RollModel } from "./rollmodel";

const HEIGHT_PX = 320;
/** How often the status line follows the plot (its text is laid out anew each time). */
const PROGRESS_MS = 250;
/** Pixels per time tick, about. */
const TICK_SPACING_PX = 100;

/** What the status line shows. */
export interface RollProgress {
  received: number;
  lost: number;
  latencyMs: number;
}

/** The plotly figure of the buffer's window (the stopped roll), `columns` pixel columns wide. */
export function rollFigure(channels: CaptureChannel[], buffer: RollBuffer, period: number, columns: number): Figure {
  const window = rollWindow(buffer);
  const frame = rollFrame(buffer, period, columns, 1);
  const data = frame.series.map((series, n) => trace(channelLabel(channels[n]), series.x, series.y, n));
  const layout = axesLayout(channels, "time [s] since the roll's start", "roll");
  (layout.xaxis as Record<string, unknown>).range = [window.from * period, window.end * period];
  layout.legend = { orientation: "h", y: -0.3 }; // below the axis title on the lower plot
  layout.shapes = frame.gaps.map((gap) => ({
    type: "rect", x0: gap.from, x1: gap.to, yref: "paper", y0: 0, y1: 1, fillcolor: "rgba(214,39,40,0.12)", line: { width: 0 }, layer: "below",
  }));
  return { data, layout };
}

function channelLabel(channel: CaptureChannel): string {
  return `${channel.key} ${channel.name}${channel.unit ? ` [${channel.unit}]` : ""}`;
}

export interface RollPlotHandle {
  element: HTMLElement;
  progress: State<RollProgress>;
  gaps: State<RollGap[]>;
  dispose(): void;
}

export function rollPlot(roll: RollModel, scope: Scope): RollPlotHandle {
  const frozen = state(false);
  const canvas = h("canvas", { "data-testid": "scope-roll-canvas", style: { display: "block", width: "100%", height: `${HEIGHT_PX}px` } });
  const still = h("div", { style: { width: "100%", height: `${HEIGHT_PX}px` } });
  const graph = scope.run(() => h("div", { "data-testid": "scope-roll-plot" },
    h("div", { hidden: frozen }, canvas, legend(roll.channels)),
    h("div", { hidden: () => !frozen.val, "data-testid": "scope-roll-frozen" }, still)));
  const progress = state<RollProgress>({ received: 0, lost: 0, latencyMs: NaN });
  const gaps = state<RollGap[]>([]);
  const report = (buffer: RollBuffer, latencyMs: number) => {
    progress.val = { received: buffer.received, lost: buffer.lost, latencyMs };
    if (buffer.gaps.length !== gaps.rawVal.length) gaps.val = [...buffer.gaps];
  };
  const live = liveCanvas(canvas, graph, roll, report);
  let freezing = 0, plotted = false;
  const unfreeze = () => {
    freezing++;
    if (plotted) void loadPlotly().then((Plotly) => Plotly.purge(still));
    plotted = false;
  };
  scope.run(() => effect(() => {
    const running = roll.running.val, buffer = roll.buffer;
    unfreeze();
    if (running) {
      frozen.val = false;
      live.start();
      return;
    }
    live.stop();
    if (!buffer || buffer.received === 0) return;
    const mine = freezing;
    [frozen.val, plotted] = [true, true];
    void freeze(still, graph, roll, buffer, () => mine === freezing).then((shown) => shown && report(buffer, progress.rawVal.latencyMs));
  }));
  return {
    element: graph,
    progress,
    gaps,
    dispose: () => {
      unfreeze();
      live.stop();
    },
  };
}

/** The channels' names in their colours, under the canvas (the plotly view has its own legend). */
function legend(channels: State<CaptureChannel[]>): HTMLElement {
  return h("div", { class: "toolbar", style: { fontSize: "12px" }, "data-testid": "scope-roll-legend" }, () => channels.val.map((channel, n) =>
    h("span", null, h("span", { style: { display: "inline-block", width: "14px", height: "2px", verticalAlign: "middle", background: COLORS[n % 4] } }), " ", channelLabel(channel))));
}

/** The stopped roll's window drawn by plotly, unless a new roll started meanwhile (then false). */
async function freeze(still: HTMLElement, graph: HTMLElement, roll: RollModel, buffer: RollBuffer, current: () => boolean): Promise<boolean> {
  const Plotly = await loadPlotly();
  if (!current()) return false;
  const figure = rollFigure(roll.channels.rawVal, buffer, roll.periodS, Math.max(still.clientWidth, 200));
  await Plotly.react(still, figure.data as never, figure.layout as never, { displaylogo: false, responsive: true });
  graph.dataset.samples = String(buffer.received);
  return true;
}

/** The canvas's animation loop while the roll runs: a frame only when something new is to be shown. */
function liveCanvas(canvas: HTMLCanvasElement, graph: HTMLElement, roll: RollModel, report: (buffer: RollBuffer, latencyMs: number) => void) {
  const context = canvas.getContext("2d");
  let request = 0, drawn: RollBuffer | null = null, drawnCount = -1, frames = 0, counted = 0, reported = 0;
  let size = { width: 0, height: 0 }, palette: Palette = { text: "#000", grid: "#ccc" };
  const resized = new ResizeObserver(() => {
    size = { width: canvas.clientWidth, height: canvas.clientHeight };
    const ratio = window.devicePixelRatio || 1;
    [canvas.width, canvas.height] = [Math.round(size.width * ratio), Math.round(size.height * ratio)];
    context?.setTransform(ratio, 0, 0, ratio, 0, 0);
    palette = themePalette(canvas);
    drawnCount = -1;
  });
  const tick = (now: number) => {
    request = requestAnimationFrame(tick);
    if (now - counted >= 1000) {
      graph.dataset.fps = ((frames * 1000) / (now - counted)).toFixed(1);
      [frames, counted] = [0, now];
    }
    const buffer = roll.buffer;
    if (!context || !buffer || size.width === 0 || (buffer === drawn && buffer.received + buffer.gaps.length === drawnCount)) return;
    [drawn, drawnCount] = [buffer, buffer.received + buffer.gaps.length];
    const latencyMs = drawFrame(context, graph, roll, buffer, size, palette);
    frames++;
    if (now - reported >= PROGRESS_MS) {
      reported = now;
      report(buffer, latencyMs);
    }
  };
  return {
    start: () => {
      if (request) return;
      resized.observe(canvas);
      [frames, counted, drawnCount] = [0, performance.now(), -1];
      request = requestAnimationFrame(tick);
    },
    stop: () => {
      cancelAnimationFrame(request);
      request = 0;
      resized.disconnect();
    },
  };
}

/** One frame on the canvas; the display latency of its newest sample (ms). */
function drawFrame(context: CanvasRenderingContext2D, graph: HTMLElement, roll: RollModel, buffer: RollBuffer, size: { width: number; height: number }, palette: Palette): number {
  const started = performance.now();
  const channels = roll.channels.rawVal, box = plotBox(size.width, size.height, channels.length);
  const frame = rollFrame(buffer, roll.periodS, Math.max(1, Math.round(box.right - box.left)), (box.right - box.left) / TICK_SPACING_PX);
  paintRoll(context, frame, channels.map((channel) => channel.unit || channel.key), size, palette);
  graph.dataset.drawMs = (performance.now() - started).toFixed(1);
  graph.dataset.samples = String(buffer.received);
  const latency = Date.now() - roll.syncedMs;
  graph.dataset.latencyMs = latency.toFixed(0);
  return latency;
}

/** The page's text and muted colours (light or dark theme), read when the canvas is (re)sized. */
function themePalette(element: HTMLElement): Palette {
  const style = getComputedStyle(element);
  const muted = style.getPropertyValue("--muted").trim() || "#888";
  return { text: style.color || "#000", grid: muted };
}
