import { describe, expect, it } from "vitest";
import { formatHex, formatNumber, fromPhysical, parseNumber, toPhysical } from "../lib/numbers";

describe("parseNumber", () => {
  it("reads decimal, exponent, hex and binary input with '.' as separator", () => {
    expect(parseNumber("12.5")).toEqual({ ok: true, value: 12.5 });
    expect(parseNumber(" -0.25 ")).toEqual({ ok: true, value: -0.25 });
    expect(parseNumber("1e-3")).toEqual({ ok: true, value: 0.001 });
    expect(parseNumber(".5")).toEqual({ ok: true, value: 0.5 });
    expect(parseNumber("0x60F9")).toEqual({ ok: true, value: 0x60f9 });
    expect(parseNumber("-0x10")).toEqual({ ok: true, value: -16 });
    expect(parseNumber("0b1010")).toEqual({ ok: true, value: 10 });
    expect(parseNumber("1_000")).toEqual({ ok: true, value: 1000 });
  });

  it("rejects a decimal comma whatever the browser locale, and says why", () => {
    const parsed = parseNumber("12,5");
    expect(parsed.ok).toBe(false);
    if (!parsed.ok) expect(parsed.error).toContain('use "." as decimal separator');
  });

  it("rejects thousands separators, empty input and words", () => {
    expect(parseNumber("1,000,000").ok).toBe(false);
    expect(parseNumber("1 000").ok).toBe(false);
    expect(parseNumber("").ok).toBe(false);
    expect(parseNumber("abc").ok).toBe(false);
    expect(parseNumber("1.2.3").ok).toBe(false);
  });
});

describe("formatNumber", () => {
  it("uses '.' and drops float noise and trailing zeros", () => {
    expect(formatNumber(0.1 + 0.2)).toBe("0.3");
    expect(formatNumber(1234.5)).toBe("1234.5");
    expect(formatNumber(-2)).toBe("-2");
    expect(formatNumber(1 / 3)).toBe("0.3333333333");
    expect(formatNumber(1 / 3, 4)).toBe("0.3333");
    expect(formatNumber(123456789.123)).toBe("123456789.1");
    expect(formatNumber(2.5e-9)).toBe("2.5e-9");
  });

  it("round-trips through parseNumber", () => {
    for (const value of [0, 1, -1, 0.001, 12.345, -98765.4321, 65535, 4294967295]) {
      const parsed = parseNumber(formatNumber(value));
      expect(parsed.ok && parsed.value).toBeCloseTo(value, 6);
    }
  });
});

describe("hex and scaling", () => {
  it("formats indices as 0x plus upper-case digits", () => {
    expect(formatHex(0x60f9)).toBe("0x60F9");
    expect(formatHex(0x1a, 2)).toBe("0x1A");
    expect(formatHex(0x227, 8)).toBe("0x00000227");
  });

  it("converts raw ⇄ physical with scale and offset, rounding integers", () => {
    expect(toPhysical(1500, 0.001)).toBe(1.5);
    expect(toPhysical(10, 0.1, -40)).toBe(-39);
    expect(fromPhysical(1.5, 0.001)).toBe(1500);
    expect(fromPhysical(-39, 0.1, -40)).toBe(10);
    expect(fromPhysical(0.0015, 0.001)).toBe(2);
    expect(fromPhysical(1.25, 1, 0, false)).toBe(1.25);
  });
});
