import fc from "fast-check";
import { describe, expect, it } from "vitest";
import { rollFigure } from "../components/scope/rollplot";
import { decimate, RollBuffer, type RollSamples } from "../lib/roll";

const batch = (seq: number, ...columns: number[][]): RollSamples => ({ type: "samples", seq, count: columns[0].length, values: columns, synced_at: [0, 0] });
const range = (from: number, to: number) => Array.from({ length: to - from }, (_, i) => from + i);

describe("the roll's decimation (display only)", () => {
  it("keeps each pixel column's minimum and maximum, in the order they occur", () => {
    const seqs = range(0, 1000);
    const values = seqs.map((k) => (k === 437 ? 1000 : k === 812 ? -1000 : Math.sin(k / 50)));
    const shown = decimate(seqs, values, 0.001, 0, 1000, 100);
    expect(shown.x.length).toBeLessThanOrEqual(200);
    expect(Math.max(...shown.y)).toBe(1000); // a one-sample spike survives
    expect(Math.min(...shown.y)).toBe(-1000);
    expect(shown.x).toEqual([...shown.x].sort((a, b) => a - b)); // in time order
    expect(shown.x[shown.y.indexOf(1000)]).toBeCloseTo(0.437, 9);
  });

  it("returns every sample when there are fewer than the columns, and only those in the window", () => {
    const shown = decimate(range(0, 10), range(0, 10), 0.5, 3, 7, 800);
    expect(shown.x).toEqual([1.5, 2, 2.5, 3]);
    expect(shown.y).toEqual([3, 4, 5, 6]);
  });

  it("is the extremes of every column for any signal (property)", () => {
    fc.assert(fc.property(fc.array(fc.integer({ min: -1000, max: 1000 }), { minLength: 1, maxLength: 3000 }), fc.integer({ min: 1, max: 400 }), (values, columns) => {
      const shown = decimate(range(0, values.length), values, 1, 0, values.length, columns);
      expect(shown.y.length).toBeLessThanOrEqual(2 * columns + 2);
      expect(Math.max(...shown.y)).toBe(Math.max(...values));
      expect(Math.min(...shown.y)).toBe(Math.min(...values));
      expect(shown.x.every((x, i) => values[x] === shown.y[i])).toBe(true); // only real samples, never made up
    }));
  });

  it("draws a gap as a break: a NaN point, no line across the missing numbers", () => {
    const seqs = [...range(0, 100), ...range(300, 400)];
    const shown = decimate(seqs, seqs.map(() => 1), 0.001, 0, 400, 400);
    const breaks = shown.y.flatMap((y, i) => (Number.isNaN(y) ? [shown.x[i]] : []));
    expect(breaks).toEqual([0.1]);
    const before = shown.x.filter((x) => x < 0.1), after = shown.x.filter((x) => x > 0.1);
    expect(Math.max(...before)).toBeCloseTo(0.099, 9);
    expect(Math.min(...after)).toBeCloseTo(0.3, 9);
  });
});

describe("the roll's buffer", () => {
  it("keeps the samples by sequence number and lists the gaps the roll reported", () => {
    const buffer = new RollBuffer(2, 1000);
    buffer.add(batch(0, [1, 2, 3], [10, 20, 30]));
    buffer.gap({ from: 3, to: 50, reason: "link lost: cut" });
    buffer.add(batch(50, [4], [40]));
    expect(buffer.seqs).toEqual([0, 1, 2, 50]);
    expect(buffer.values).toEqual([[1, 2, 3, 4], [10, 20, 30, 40]]);
    expect(buffer.gaps).toEqual([{ from: 3, to: 50, reason: "link lost: cut" }]);
    expect(buffer.lost).toBe(47);
    expect(buffer.received).toBe(4);
  });

  it("makes a jump in the numbers a gap too, with the reason of a gap event that had no numbers", () => {
    const buffer = new RollBuffer(1, 1000);
    buffer.add(batch(0, [1, 2]));
    buffer.add(batch(5, [3]));
    buffer.gap({ reason: "this client fell behind: 3 batches dropped" });
    buffer.add(batch(9, [4]));
    expect(buffer.gaps).toEqual([
      { from: 2, to: 5, reason: "samples not received" },
      { from: 6, to: 9, reason: "this client fell behind: 3 batches dropped" },
    ]);
  });

  it("keeps about the last `keep` samples, the gaps all", () => {
    const buffer = new RollBuffer(1, 100);
    for (let k = 0; k < 50; k++) buffer.add(batch(k * 10, range(k * 10, k * 10 + 10)));
    expect(buffer.seqs.length).toBeLessThan(126);
    expect(buffer.seqs.length).toBeGreaterThanOrEqual(100);
    expect(buffer.last).toBe(499);
    expect(buffer.values[0][buffer.values[0].length - 1]).toBe(499);
    expect(buffer.received).toBe(500);
  });
});

describe("the roll's figure", () => {
  it("draws the window's samples per channel on its own axis, a gap as a break and a shaded band", () => {
    const buffer = new RollBuffer(2, 1000);
    buffer.add(batch(0, range(0, 100), range(0, 100)));
    buffer.gap({ from: 100, to: 300, reason: "link lost" });
    buffer.add(batch(300, range(300, 400), range(300, 400)));
    const channel = (key: string) => ({ key, name: key, unit: "", data_type: "INTEGER16", scale: 1, offset: 0 });
    const figure = rollFigure([channel("0x6041,0"), channel("0x6078,0")], buffer, 0.001, 800);
    expect(figure.data.map((trace) => [trace.type, trace.yaxis])).toEqual([["scattergl", "y"], ["scattergl", "y2"]]);
    expect(figure.data[0].y.filter(Number.isNaN).length).toBe(1);
    expect((figure.layout.shapes as { x0: number; x1: number }[]).map((shape) => [shape.x0, shape.x1])).toEqual([[0.1, 0.3]]);
    expect((figure.layout.xaxis as { range: number[] }).range).toEqual([0, 1]);
  });
});
