/**
 * The live roll's painter: one frame (`lib/rollframe.ts`) onto a 2D canvas — the gaps as shaded bands, the time
 * axis with its ticks and grid, each channel's own y-axis in its colour and unit (the first on the left, the others
 * stacked on the right, as the capture plot places them), and each channel's decimated line, broken at every gap.
 * One-pixel lines: the canvas draws them as hairlines, the cheapest stroke of a software rasteriser.
 */

import type { RollFrame, Scale } from "../../lib/rollframe";
import { tickLabel, toPixel } from "../../lib/rollframe";
import type { Series } from "../../lib/roll";
import { COLORS } from "./figure";

const FONT = "11px system-ui, sans-serif";
/** Width of a y-axis beyond the first (its labels), and the plot's margins, in CSS pixels. */
const AXIS_WIDTH = 56;
const MARGIN = { left: 70, right: 8, top: 10, bottom: 36 };
const GAP_FILL = "rgba(214,39,40,0.12)";
/** The room of an axis's vertical unit title. */
const TITLE_WIDTH = 14;
/** The grid: the theme's muted colour, faint. */
const GRID_ALPHA = 0.35;

/** The plot area inside a canvas of `width` × `height` CSS pixels with `axes` y-axes. */
export interface PlotBox {
  left: number;
  right: number;
  top: number;
  bottom: number;
}

export interface Palette {
  text: string;
  grid: string;
}

export function plotBox(width: number, height: number, axes: number): PlotBox {
  const right = width - MARGIN.right - AXIS_WIDTH * Math.max(0, axes - 1);
  return { left: MARGIN.left, right: Math.max(MARGIN.left + 1, right), top: MARGIN.top, bottom: Math.max(MARGIN.top + 1, height - MARGIN.bottom) };
}

/** Paint `frame`; `units` label the y-axes (one per channel), the canvas is `width` × `height` CSS pixels. */
export function paintRoll(context: CanvasRenderingContext2D, frame: RollFrame, units: string[], size: { width: number; height: number }, palette: Palette): void {
  const box = plotBox(size.width, size.height, frame.series.length);
  context.clearRect(0, 0, size.width, size.height);
  context.font = FONT;
  context.lineWidth = 1;
  paintGaps(context, frame, box);
  paintTimeAxis(context, frame.time, box, palette);
  frame.scales.forEach((scale, n) => paintValueAxis(context, scale, n, units[n] ?? "", box, palette));
  context.save();
  context.beginPath();
  context.rect(box.left, box.top, box.right - box.left, box.bottom - box.top);
  context.clip();
  frame.series.forEach((series, n) => paintLine(context, series, frame.time, frame.scales[n], box, COLORS[n % 4]));
  context.restore();
}

function paintGaps(context: CanvasRenderingContext2D, frame: RollFrame, box: PlotBox): void {
  context.fillStyle = GAP_FILL;
  for (const gap of frame.gaps) {
    const x0 = Math.max(box.left, toPixel(gap.from, frame.time.low, frame.time.high, box.left, box.right));
    const x1 = Math.min(box.right, toPixel(gap.to, frame.time.low, frame.time.high, box.left, box.right));
    if (x1 > x0) context.fillRect(x0, box.top, Math.max(1, x1 - x0), box.bottom - box.top);
  }
}

function paintTimeAxis(context: CanvasRenderingContext2D, time: Scale, box: PlotBox, palette: Palette): void {
  context.strokeStyle = palette.grid;
  context.fillStyle = palette.text;
  context.textAlign = "center";
  context.textBaseline = "top";
  context.beginPath();
  for (const tick of time.ticks) {
    const x = Math.round(toPixel(tick, time.low, time.high, box.left, box.right)) + 0.5;
    context.moveTo(x, box.top);
    context.lineTo(x, box.bottom + 4);
    context.fillText(tickLabel(tick, time.step), x, box.bottom + 6);
  }
  stroke(context, GRID_ALPHA);
  context.fillText("time [s] since the roll's start", (box.left + box.right) / 2, box.bottom + 21);
}

function stroke(context: CanvasRenderingContext2D, alpha: number): void {
  context.globalAlpha = alpha;
  context.stroke();
  context.globalAlpha = 1;
}

/** Channel `n`'s axis: a line in its colour with its ticks, its unit above; the first axis also draws the grid. */
function paintValueAxis(context: CanvasRenderingContext2D, scale: Scale, n: number, unit: string, box: PlotBox, palette: Palette): void {
  const x = n === 0 ? box.left - 0.5 : box.right + AXIS_WIDTH * (n - 1) + 0.5;
  const side = n === 0 ? -1 : 1;
  context.strokeStyle = n === 0 ? palette.grid : COLORS[n % 4];
  context.beginPath();
  for (const tick of scale.ticks) {
    const y = Math.round(toPixel(tick, scale.low, scale.high, box.bottom, box.top)) + 0.5;
    context.moveTo(x, y);
    context.lineTo(n === 0 ? box.right : x + 4, y);
  }
  stroke(context, n === 0 ? GRID_ALPHA : 1);
  context.strokeStyle = COLORS[n % 4];
  context.beginPath();
  context.moveTo(x, box.top);
  context.lineTo(x, box.bottom);
  context.stroke();
  context.fillStyle = COLORS[n % 4];
  context.textAlign = side < 0 ? "right" : "left";
  context.textBaseline = "middle";
  const room = (n === 0 ? MARGIN.left : AXIS_WIDTH) - TITLE_WIDTH - 6;
  for (const tick of scale.ticks) context.fillText(tickLabel(tick, scale.step), x + side * 6, toPixel(tick, scale.low, scale.high, box.bottom, box.top), room);
  paintTitle(context, unit, n === 0 ? TITLE_WIDTH / 2 : x + AXIS_WIDTH - TITLE_WIDTH / 2, box);
}

/** An axis's unit, vertical beside its tick labels (as the capture plot writes it). */
function paintTitle(context: CanvasRenderingContext2D, unit: string, x: number, box: PlotBox): void {
  context.save();
  context.translate(x, (box.top + box.bottom) / 2);
  context.rotate(-Math.PI / 2);
  context.textAlign = "center";
  context.fillText(unit, 0, 0, box.bottom - box.top);
  context.restore();
}

/** The decimated points joined in time order; a NaN point lifts the pen (a gap is a break, never a line across). */
function paintLine(context: CanvasRenderingContext2D, series: Series, time: Scale, scale: Scale, box: PlotBox, color: string): void {
  context.strokeStyle = color;
  context.beginPath();
  let pen = false;
  for (let i = 0; i < series.x.length; i++) {
    const value = series.y[i];
    if (Number.isNaN(value)) {
      pen = false;
      continue;
    }
    const x = toPixel(series.x[i], time.low, time.high, box.left, box.right), y = toPixel(value, scale.low, scale.high, box.bottom, box.top);
    if (pen) context.lineTo(x, y);
    else context.moveTo(x, y);
    pen = true;
  }
  context.stroke();
}
