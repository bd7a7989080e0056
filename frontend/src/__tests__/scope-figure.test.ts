import { describe, expect, it } from "vitest";
import type { CaptureData } from "../client/scope";
import { fftFigure, mathValues, timeFigure, timesOf } from "../components/scope/figure";
import { applyDefinition, createModel, request } from "../components/scope/model";
import { moveCursor } from "../components/scope/plot";
import { LiveHub } from "../client/live";
import type { Dictionary } from "../lib/od";

const channel = (key: string, unit: string) => ({ key, name: key, unit, data_type: "INTEGER32", scale: 1, offset: 0 });
const capture: CaptureData = {
  id: "c1", name: null, definition: { channels: ["0x60FF,0", "0x606C,0"], period_us: 500, mode: "single", pre_trigger_pct: 25, auto_timeout_ms: 100, source: "auto" },
  channels: [channel("0x60FF,0", "user unit/s"), channel("0x6041,0", "")],
  period_ns: 500_000, samples: 4, trigger_index: 1, trigger: "0x60FF,0 rising 100 user unit/s",
  values: [[0, 500, 500, 500], [1, 2, null, 4]],
  drive: { bus: "sim", node: 1, device: "xtrapulspac", product_name: "", vendor_id: null, product_code: null, revision: null, serial_number: null, software_version: null },
  captured_at: "2025-05-01T12:30:05Z", source: "recorder",
};
const none = { a: null, b: null, next: "a" as const };

describe("the scope's figure", () => {
  it("puts time 0 at the trigger sample, one WebGL trace per channel on its own y-axis in its unit", () => {
    expect(timesOf(capture)).toEqual([-0.0005, 0, 0.0005, 0.001]);
    const figure = timeFigure(capture, { operation: "none", a: 0, b: 1, k: 1 }, none);
    expect(figure.data.map((trace) => [trace.type, trace.yaxis])).toEqual([["scattergl", "y"], ["scattergl", "y2"]]);
    expect(figure.data[1].y[2]).toBeNaN(); // a sample JSON could not carry is a gap
    expect((figure.layout.yaxis as { title: { text: string } }).title.text).toBe("user unit/s");
    expect((figure.layout.yaxis2 as { title: { text: string }; overlaying: string }).overlaying).toBe("y");
    const shapes = figure.layout.shapes as { type: string; x0: number; x1: number }[];
    expect(shapes.slice(0, 2).map((shape) => [shape.type, shape.x0, shape.x1])).toEqual([["rect", -0.0005, 0], ["line", 0, 0]]);
  });

  it("adds the math trace on the axis of its first operand and the cursors as lines", () => {
    const figure = timeFigure(capture, { operation: "a-b", a: 0, b: 1, k: 1 }, { a: 0, b: 0.001, next: "a" });
    expect(figure.data[2]).toMatchObject({ name: "0x60FF,0 − 0x6041,0", yaxis: "y" });
    expect(figure.data[2].y.slice(0, 2)).toEqual([-1, 498]);
    expect((figure.layout.shapes as unknown[]).length).toBe(4);
    expect(mathValues(capture, { operation: "d/dt", a: 0, b: 0, k: 1 })!.y[1]).toBeCloseTo(500 / 0.001, 6);
    expect(mathValues(capture, { operation: "a*k", a: 0, b: 0, k: 2 })!.y).toEqual([0, 1000, 1000, 1000]);
    expect(mathValues(capture, { operation: "a-b", a: 0, b: 3, k: 1 })).toBeNull();
  });

  it("shows the spectrum of each channel in the FFT view", () => {
    const figure = fftFigure(capture);
    expect(figure.data).toHaveLength(2);
    expect(figure.data[0].x).toEqual([0, 500, 1000]); // 4 samples at 2 kHz: bins of 500 Hz up to Nyquist
  });
});

describe("cursors and the definition", () => {
  it("moves cursor A then B, and B with Shift", () => {
    const first = moveCursor(none, 0.1);
    const second = moveCursor(first, 0.2);
    expect([first.a, second.b, second.next]).toEqual([0.1, 0.2, "a"]);
    expect(moveCursor(second, 0.3, true)).toMatchObject({ a: 0.1, b: 0.3 });
  });

  it("turns the form into the server's definition and a preset back into the form", () => {
    const model = createModel(new LiveHub(), {} as Dictionary, { bus: "sim", node: 1, project: "demo", axis: "X" });
    expect(request(model.draft)).toMatchObject({ channels: ["0x6064,0", "0x606C,0", "0x6078,0", "0x6041,0"], trigger: { source: null }, pre_trigger_pct: 0 });
    applyDefinition(model.draft, { ...capture.definition, samples: 400, trigger: { source: "0x60FF,0", edge: "either", level: 1 } });
    expect(request(model.draft)).toMatchObject({ channels: ["0x60FF,0", "0x606C,0"], samples: 400, period_us: 500, trigger: { source: "0x60FF,0", edge: "either", level: 1 }, pre_trigger_pct: 25 });
    model.draft.period.val = "2,5";
    expect(() => request(model.draft)).toThrow('Period: "2,5" is not a number (use "." as decimal point)');
  });
});
