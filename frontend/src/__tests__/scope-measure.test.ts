import { describe, expect, it } from "vitest";
import { hann, spectrum } from "../lib/fft";
import { cursorDelta, derivative, difference, sampleAt, scaled, stats, stepResponse } from "../lib/measure";

const DT = 250e-6;
const times = (n: number) => Array.from({ length: n }, (_, i) => i * DT);

describe("per-channel statistics", () => {
  it("gives min, max, mean, RMS, peak-to-peak and frequency of a sine with an offset", () => {
    // 50 Hz, amplitude 2, offset 1: 2048 samples at 4 kHz = 25.6 periods
    const values = times(2048).map((t) => 1 + 2 * Math.sin(2 * Math.PI * 50 * t));
    const result = stats(values, DT)!;
    expect(result.min).toBeCloseTo(-1, 2);
    expect(result.max).toBeCloseTo(3, 2);
    expect(result.peakToPeak).toBeCloseTo(4, 2);
    expect(result.mean).toBeCloseTo(1, 1);
    expect(result.rms).toBeCloseTo(Math.sqrt(1 + 2), 1); // offset² + amplitude²/2
    expect(result.frequency!).toBeCloseTo(50, 6);
  });

  it("finds no frequency in a constant or a ramp, and the RMS of a constant is itself", () => {
    expect(stats([3, 3, 3, 3], DT)).toEqual({ min: 3, max: 3, mean: 3, rms: 3, peakToPeak: 0, frequency: null });
    expect(stats(times(100), DT)!.frequency).toBeNull();
    expect(stats([], DT)).toBeNull();
  });

  it("is not fooled by noise around the mean (hysteresis)", () => {
    const values = times(4000).map((t, i) => Math.sign(Math.sin(2 * Math.PI * 20 * t)) + (i % 2 ? 0.01 : -0.01));
    expect(stats(values, DT)!.frequency!).toBeCloseTo(20, 1); // edges fall on samples: 1 sample of 200 per period
  });
});

describe("step response", () => {
  it("measures a first-order step: rise time τ·ln 9, no overshoot, 2 % settling at τ·ln 50", () => {
    const tau = 0.01, start = 100;
    const values = times(4000).map((_, i) => (i < start ? 0 : 5 * (1 - Math.exp(-((i - start) * DT) / tau))));
    const step = stepResponse(values, DT, start)!;
    expect(step.initial).toBe(0);
    expect(step.final).toBeCloseTo(5, 6);
    expect(step.riseTime!).toBeCloseTo(tau * Math.log(9), 4);
    expect(step.overshootPct).toBe(0);
    expect(step.settlingTime!).toBeCloseTo(tau * Math.log(50), 3);
  });

  it("measures the overshoot of a second-order step: exp(−πζ/√(1−ζ²))", () => {
    const zeta = 0.3, omega = 2 * Math.PI * 40, start = 50;
    const wd = omega * Math.sqrt(1 - zeta * zeta);
    const response = (t: number) =>
      1 - Math.exp(-zeta * omega * t) * (Math.cos(wd * t) + (zeta / Math.sqrt(1 - zeta * zeta)) * Math.sin(wd * t));
    const values = times(8000).map((_, i) => (i < start ? -2 : -2 + 4 * response((i - start) * DT)));
    const step = stepResponse(values, DT, start)!;
    expect(step.overshootPct).toBeCloseTo(100 * Math.exp((-Math.PI * zeta) / Math.sqrt(1 - zeta * zeta)), 1);
    expect(step.settlingTime!).toBeGreaterThan(3 / (zeta * omega)); // about 4/(ζω) for 2 %
    expect(step.settlingTime!).toBeLessThan(5 / (zeta * omega));
  });

  it("measures a falling step the same way, and nothing without a step", () => {
    const values = [10, 10, 10, 7, 4, 1, 0, 0, 0, 0, 0, 0];
    const step = stepResponse(values, 1, 3)!;
    expect(step.final).toBe(0);
    expect(step.riseTime).toBe(2); // 30 % at the step sample already, 90 % two samples later
    expect(stepResponse([1, 1, 1, 1, 1], 1)).toBeNull();
  });
});

describe("math traces", () => {
  it("a − b, a · k and d/dt", () => {
    expect(difference([5, 7, 9], [1, 2, 3])).toEqual([4, 5, 6]);
    expect(scaled([1, -2], 2.5)).toEqual([2.5, -5]);
    const ramp = times(10).map((t) => 3 * t + 1);
    for (const slope of derivative(ramp, DT)) expect(slope).toBeCloseTo(3, 9);
  });
});

describe("cursors", () => {
  it("read the nearest sample and give Δt and 1/Δt", () => {
    const values = [10, 11, 12, 13];
    expect(sampleAt(values, -0.5e-3, DT, 0)).toBe(12); // sample 2 is at t = 0
    expect(sampleAt(values, -0.5e-3, DT, 0.1)).toBeNull();
    const delta = cursorDelta(-0.001, 0.004);
    expect(delta.dt).toBeCloseTo(0.005, 12);
    expect(delta.inverse!).toBeCloseTo(200, 9);
    expect(cursorDelta(1, 1).inverse).toBeNull();
  });
});

describe("FFT view", () => {
  it("shows a sine on a bin at its frequency with its amplitude (Hann window)", () => {
    const n = 1024, f = (64 / (n * DT)); // exactly bin 64
    const values = times(n).map((t) => 0.5 + 3 * Math.sin(2 * Math.PI * f * t));
    const result = spectrum(values, DT);
    const peak = result.magnitude.indexOf(Math.max(...result.magnitude.slice(1)));
    expect(result.frequency[peak]).toBeCloseTo(f, 9);
    expect(result.magnitude[peak]).toBeCloseTo(3, 1);
    expect(result.magnitude[0]).toBeCloseTo(0.5, 2);
    expect(result.frequency.length).toBe(n / 2 + 1);
  });

  it("pads to a power of two and the Hann window is symmetric with zero ends", () => {
    const window = hann(5);
    expect(window).toEqual([0, 0.5, 1, 0.5, 0].map((w) => expect.closeTo(w, 12)));
    expect(spectrum(new Array(100).fill(1), DT).frequency.length).toBe(65);
  });
});
