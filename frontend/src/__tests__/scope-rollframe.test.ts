import fc from "fast-check";
import { describe, expect, it } from "vitest";
import { paintRoll, plotBox } from "../components/scope/rollcanvas";
import { RollBuffer, type RollSamples } from "../lib/roll";
import { niceStep, rollFrame, tickLabel, ticksWithin, toPixel, valueScale } from "../lib/rollframe";

const batch = (seq: number, ...columns: number[][]): RollSamples => ({ type: "samples", seq, count: columns[0].length, values: columns, synced_at: [0, 0] });
const range = (from: number, to: number) => Array.from({ length: to - from }, (_, i) => from + i);

describe("the live roll's scales", () => {
  it("steps ticks by 1, 2 or 5 × 10ⁿ, the smallest at least the rough step", () => {
    expect([0.7, 1, 1.3, 3, 7, 0.013, 4500].map(niceStep)).toEqual([1, 1, 2, 5, 10, 0.02, 5000]);
    expect(niceStep(0)).toBe(1);
    expect(niceStep(NaN)).toBe(1);
  });

  it("widens a channel's range to whole ticks around all its finite values", () => {
    const scale = valueScale([-3.2, NaN, 17.9, 4]);
    expect(scale).toMatchObject({ low: -5, high: 20, step: 5 });
    expect(scale.ticks).toEqual([-5, 0, 5, 10, 15, 20]);
  });

  it("gives a constant signal a small range of its own and no signal 0..1", () => {
    const constant = valueScale([567, 567]);
    expect(constant.low).toBeLessThan(567);
    expect(constant.high).toBeGreaterThan(567);
    expect(constant.high - constant.low).toBeLessThanOrEqual(20);
    expect(valueScale([NaN])).toMatchObject({ low: 0, high: 1 });
    expect(valueScale([0, 0])).toMatchObject({ low: -1, high: 1 });
  });

  it("holds every value and at most a few ticks, for any signal (property)", () => {
    const values = fc.array(fc.double({ min: -1e9, max: 1e9, noNaN: true }), { minLength: 1, maxLength: 200 });
    fc.assert(fc.property(values, (signal) => {
      const scale = valueScale(signal);
      expect(scale.low).toBeLessThanOrEqual(Math.min(...signal));
      expect(scale.high).toBeGreaterThanOrEqual(Math.max(...signal));
      expect(scale.high).toBeGreaterThan(scale.low);
      expect(scale.ticks.length).toBeGreaterThanOrEqual(2);
      expect(scale.ticks.length).toBeLessThanOrEqual(12);
    }));
  });

  it("puts ticks on round values and labels them with the step's decimals", () => {
    expect(ticksWithin(0.05, 0.95, 0.1)).toEqual([0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]);
    expect(ticksWithin(2.3, 7.3, 1)).toEqual([3, 4, 5, 6, 7]);
    expect([tickLabel(0.30000000000000004, 0.1), tickLabel(1500, 500), tickLabel(0.25, 0.05)]).toEqual(["0.3", "1500", "0.25"]);
  });

  it("maps values to pixels linearly, y growing downwards", () => {
    expect(toPixel(0, 0, 10, 100, 200)).toBe(100);
    expect(toPixel(7.5, 0, 10, 100, 200)).toBe(175);
    expect(toPixel(10, -10, 10, 300, 20)).toBe(20);
  });
});

describe("a frame of the live roll", () => {
  it("shows the whole window from the start on, each channel within the pixel columns, on its own scale", () => {
    const buffer = new RollBuffer(2, 5000);
    buffer.add(batch(0, range(0, 3000).map((k) => Math.sin(k / 100)), range(0, 3000).map((k) => 1000 * k)));
    const frame = rollFrame(buffer, 0.001, 600, 6);
    expect([frame.time.low, frame.time.high]).toEqual([0, 5]);
    expect(frame.time.ticks).toEqual([0, 1, 2, 3, 4, 5]);
    expect(frame.series.map((series) => series.x.length <= 2 * 600 + 2)).toEqual([true, true]);
    expect(frame.scales[0]).toMatchObject({ low: -1, high: 1 });
    expect(frame.scales[1].high).toBeGreaterThanOrEqual(2_999_000);
    expect(frame.gaps).toEqual([]);
  });

  it("scrolls with the newest samples and shows the gaps in the window as bands, in seconds", () => {
    const buffer = new RollBuffer(1, 1000);
    buffer.add(batch(0, range(0, 500)));
    buffer.gap({ from: 500, to: 900, reason: "link lost" });
    buffer.add(batch(900, range(900, 1800)));
    const frame = rollFrame(buffer, 0.001, 400, 5);
    expect(frame.time.low).toBeCloseTo(0.8, 9);
    expect(frame.time.high).toBeCloseTo(1.8, 9);
    expect(frame.time.ticks.every((tick) => tick >= frame.time.low && tick <= frame.time.high)).toBe(true);
    expect(frame.gaps.length).toBe(1);
    expect(frame.gaps[0].from).toBeCloseTo(0.8, 9); // clipped to the window
    expect(frame.gaps[0].to).toBeCloseTo(0.9, 9);
    expect(frame.series[0].y.filter(Number.isNaN).length).toBe(0); // the window holds no break: the gap is before
  });
});

/** A 2D context that records the calls made on it (jsdom has no canvas). */
function recorder(): { context: CanvasRenderingContext2D; calls: [string, number[]][] } {
  const calls: [string, number[]][] = [];
  const context = new Proxy({} as Record<string | symbol, unknown>, {
    get: (target, key) => (key in target ? target[key] : (...args: number[]) => void calls.push([String(key), args])),
    set: (target, key, value) => {
      target[key] = value;
      return true;
    },
  });
  return { context: context as unknown as CanvasRenderingContext2D, calls };
}

describe("the live roll's painter", () => {
  it("lifts the pen at a gap and shades it inside the plot", () => {
    const buffer = new RollBuffer(1, 1000);
    buffer.add(batch(0, range(0, 100)));
    buffer.gap({ from: 100, to: 300, reason: "link lost" });
    buffer.add(batch(300, range(300, 400)));
    const size = { width: 600, height: 300 }, box = plotBox(600, 300, 1);
    const { context, calls } = recorder();
    paintRoll(context, rollFrame(buffer, 0.001, box.right - box.left, 5), ["rpm"], size, { text: "#000", grid: "#888" });
    const line = calls.slice(calls.findIndex(([name]) => name === "clip") + 1).filter(([name]) => name === "moveTo" || name === "lineTo");
    expect(line.filter(([name]) => name === "moveTo").length).toBe(2); // the start and once after the gap
    const restart = line.findIndex(([name], i) => i > 0 && name === "moveTo");
    expect(line[restart][1][0]).toBeGreaterThan(line[restart - 1][1][0] + 10); // no line across the missing numbers
    const band = calls.find(([name, args]) => name === "fillRect" && args[1] === box.top);
    expect(band?.[1][0]).toBeGreaterThanOrEqual(box.left);
    expect((band?.[1][0] ?? 0) + (band?.[1][2] ?? 0)).toBeLessThanOrEqual(box.right);
  });

  it("leaves room for every y-axis beyond the first on the right", () => {
    const one = plotBox(1000, 320, 1), four = plotBox(1000, 320, 4);
    expect(one.right - four.right).toBe(3 * 56);
    expect(four.left).toBe(one.left);
  });
});
