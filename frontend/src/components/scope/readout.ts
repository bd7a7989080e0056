/**
 * What the capture measures: per channel min, max, mean, RMS, peak-to-peak, frequency and the step response from
 * the trigger (rise time, overshoot, settling time); the two cursors with each channel's value, Δt, Δy and 1/Δt;
 * the math trace's choice and the time / FFT view switch.
 */

import type { CaptureData } from "../../client/scope";
import { derive, h, type State } from "../../lib/dom";
import { cursorDelta, sampleAt, stats, stepResponse, type MathOperation } from "../../lib/measure";
import { formatNumber } from "../../lib/numbers";
import { COLORS, timesOf, valuesOf } from "./figure";
import type { Cursors, MathTrace, ScopeModel } from "./model";

const show = (value: number | null | undefined, digits = 6) => (value === null || value === undefined ? "–" : formatNumber(value, digits));
const seconds = (value: number | null | undefined) => (value === null || value === undefined ? "–" : `${formatNumber(value * 1000, 6)} ms`);

export function readoutView(model: ScopeModel): HTMLElement {
  const rows = derive(() => measureRows(model.capture.val));
  return h("section", { class: "panel" },
    h("div", { class: "panel-body grid", style: { gap: "8px" } },
      h("div", { class: "toolbar" }, viewSwitch(model.view), mathControls(model), cursorInputs(model.cursors)),
      h("div", { "data-testid": "scope-cursor-delta" }, () => deltaText(model.cursors.val)),
      h("table", { class: "data", "data-testid": "scope-measurements" },
        h("thead", null, h("tr", null, ["channel", "unit", "min", "max", "mean", "RMS", "p-p", "frequency", "rise", "overshoot", "settling", "A", "B", "Δy"].map((title) => h("th", null, title)))),
        h("tbody", null, () => rows.val.map((row, n) => measureRow(row, n, model))))));
}

interface Row {
  key: string;
  unit: string;
  values: number[];
  statistics: ReturnType<typeof stats>;
  step: ReturnType<typeof stepResponse>;
  t0: number;
  dt: number;
}

function measureRows(capture: CaptureData | null): Row[] {
  if (!capture) return [];
  const dt = capture.period_ns / 1e9, t0 = timesOf(capture)[0] ?? 0;
  return capture.channels.map((channel, n) => {
    const values = valuesOf(capture, n);
    return { key: channel.key, unit: channel.unit, values, statistics: stats(values, dt), step: stepResponse(values, dt, capture.trigger_index), t0, dt };
  });
}

function measureRow(row: Row, n: number, model: ScopeModel): HTMLElement {
  const s = row.statistics, step = row.step;
  const at = (t: number | null) => (t === null ? null : sampleAt(row.values, row.t0, row.dt, t));
  return h("tr", { "data-testid": `scope-row-${n + 1}` },
    h("td", { class: "mono", style: { color: COLORS[n % 4] } }, row.key),
    h("td", null, row.unit),
    [s?.min, s?.max, s?.mean, s?.rms, s?.peakToPeak].map((value) => h("td", { class: "num" }, show(value))),
    h("td", { class: "num" }, s?.frequency ? `${show(s.frequency, 5)} Hz` : "–"),
    h("td", { class: "num" }, seconds(step?.riseTime)),
    h("td", { class: "num" }, step ? `${show(step.overshootPct, 3)} %` : "–"),
    h("td", { class: "num" }, seconds(step?.settlingTime)),
    h("td", { class: "num", "data-testid": `scope-a-${n + 1}` }, () => show(at(model.cursors.val.a))),
    h("td", { class: "num", "data-testid": `scope-b-${n + 1}` }, () => show(at(model.cursors.val.b))),
    h("td", { class: "num" }, () => {
      const a = at(model.cursors.val.a), b = at(model.cursors.val.b);
      return a === null || b === null ? "–" : show(b - a);
    }));
}

function deltaText(cursors: Cursors): string {
  if (cursors.a === null || cursors.b === null) return "Click the plot to place cursor A, then B (Shift+click: B).";
  const delta = cursorDelta(cursors.a, cursors.b);
  return `Δt = ${seconds(delta.dt)}   1/Δt = ${delta.inverse === null ? "–" : `${show(delta.inverse, 6)} Hz`}`;
}

function cursorInputs(cursors: State<Cursors>): HTMLElement {
  const field = (name: "a" | "b") => {
    const input: HTMLInputElement = h("input", {
      "data-testid": `scope-cursor-${name}`, style: { width: "90px" }, placeholder: "s",
      value: () => (cursors.val[name] === null ? "" : formatNumber(cursors.val[name]!, 9)),
      onchange: () => {
        const value = input.value.trim() === "" ? null : Number(input.value);
        cursors.val = { ...cursors.rawVal, [name]: value !== null && Number.isFinite(value) ? value : null };
      },
    });
    return h("label", null, `Cursor ${name.toUpperCase()} `, input, " s");
  };
  return h("span", { class: "toolbar" }, field("a"), field("b"));
}

function viewSwitch(view: State<"time" | "fft">): HTMLElement {
  const button = (value: "time" | "fft", text: string) => h("button", {
    "data-testid": `scope-view-${value}`, class: () => (view.val === value ? "primary" : ""), onclick: () => (view.val = value),
  }, text);
  return h("span", { class: "toolbar" }, button("time", "Time"), button("fft", "FFT"));
}

function mathControls(model: ScopeModel): HTMLElement {
  const math = model.math;
  const set = (change: Partial<MathTrace>) => (math.val = { ...math.rawVal, ...change });
  const channelChoice = (which: "a" | "b") => {
    const select: HTMLSelectElement = h("select", { "data-testid": `scope-math-${which}`, value: () => String(math.val[which]), onchange: () => set({ [which]: Number(select.value) }) },
      [0, 1, 2, 3].map((n) => h("option", { value: String(n) }, `ch ${n + 1}`)));
    return select;
  };
  const operation: HTMLSelectElement = h("select", { "data-testid": "scope-math", value: () => math.val.operation, onchange: () => set({ operation: operation.value as MathOperation | "none" }) },
    [["none", "no math"], ["a-b", "a − b"], ["a*k", "a · k"], ["d/dt", "d/dt a"]].map(([value, text]) => h("option", { value }, text)));
  const k: HTMLInputElement = h("input", { "data-testid": "scope-math-k", style: { width: "60px" }, value: () => String(math.val.k), onchange: () => set({ k: Number(k.value) || 0 }) });
  return h("span", { class: "toolbar" }, "Math ", operation, " a ", channelChoice("a"), " b ", channelChoice("b"), " k ", k);
}
