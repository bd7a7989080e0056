/** Property-based tests of the parsers and codecs (fast-check): round trips and "never throws" over any input. */

import fc from "fast-check";
import { describe, expect, it } from "vitest";
import { extractBits, insertBits } from "../lib/bits";
import { formatHex, formatNumber, parseNumber } from "../lib/numbers";
import { decodePointer, encodePointer } from "../lib/pointer";
import { AXIS_VIEWS, buildPath, parsePath, type Route } from "../lib/router";
import { parseQuery } from "../lib/search";

describe("properties", () => {
  it("formatNumber → parseNumber gives the value back (10 significant digits)", () => {
    fc.assert(fc.property(fc.double({ noNaN: true, noDefaultInfinity: true, min: -1e14, max: 1e14 }), (value) => {
      const parsed = parseNumber(formatNumber(value));
      expect(parsed.ok).toBe(true);
      if (parsed.ok) expect(Math.abs(parsed.value - value)).toBeLessThanOrEqual(Math.max(1e-6, Math.abs(value) * 1e-9));
    }));
  });

  it("integers and hex round-trip exactly", () => {
    fc.assert(fc.property(fc.integer({ min: -(2 ** 31), max: 2 ** 32 - 1 }), (value) => {
      expect(parseNumber(String(value))).toEqual({ ok: true, value });
      expect(parseNumber(formatHex(value, 8))).toEqual({ ok: true, value });
    }));
  });

  it("parseNumber never throws and never accepts a decimal comma", () => {
    fc.assert(fc.property(fc.string(), (text) => {
      const parsed = parseNumber(text);
      if (parsed.ok) expect(Number.isFinite(parsed.value) || /e/i.test(text)).toBe(true);
      if (/^\s*-?\d+,\d+\s*$/.test(text)) expect(parsed.ok).toBe(false);
    }));
  });

  it("pointers decode to what was encoded", () => {
    fc.assert(fc.property(fc.integer({ min: 0, max: 0xffff }), fc.integer({ min: 0, max: 0xff }), fc.integer({ min: 0, max: 0xff }),
      (index, subindex, bit) => {
        const value = encodePointer({ index, subindex, bit });
        expect(value).toBeGreaterThanOrEqual(0);
        expect(value).toBeLessThanOrEqual(0xffffffff);
        expect(decodePointer(value)).toEqual({ index, subindex, bit });
      }));
  });

  it("a bit field written is the bit field read, and the other bits stay", () => {
    fc.assert(fc.property(fc.integer({ min: 0, max: 2 ** 32 - 1 }), fc.integer({ min: 0, max: 31 }), fc.integer({ min: 0, max: 31 }), fc.nat(),
      (word, a, b, seed) => {
        const [first, last] = a <= b ? [a, b] : [b, a];
        const value = seed % 2 ** (last - first + 1);
        const written = insertBits(word, first, last, value);
        expect(extractBits(written, first, last)).toBe(value);
        for (let bit = 0; bit < 32; bit++) {
          if (bit < first || bit > last) expect(extractBits(written, bit, bit)).toBe(extractBits(word, bit, bit));
        }
      }));
  });

  it("every route survives buildPath → parsePath, whatever the names", () => {
    const name = fc.string({ minLength: 1, maxLength: 20 });
    const route: fc.Arbitrary<Route> = fc.oneof(
      fc.constant<Route>({ page: "home" }),
      name.map((project): Route => ({ page: "project", project })),
      name.map((project): Route => ({ page: "compare", project })),
      fc.tuple(name, name, fc.constantFrom(...AXIS_VIEWS)).map(([project, axis, view]): Route => ({ page: "axis", project, axis, view })),
      name.map((device): Route => ({ page: "dictionary", device })),
    );
    fc.assert(fc.property(route, fc.string(), (target, q) => {
      const [path, search] = buildPath(target, { q }).split("?");
      const parsed = parsePath(path, search ? `?${search}` : "");
      expect(parsed.route).toEqual(target);
      expect(parsed.query.q ?? "").toBe(q);
    }));
  });

  it("parseQuery never throws and reads any 4-digit hex address", () => {
    fc.assert(fc.property(fc.string(), (text) => void parseQuery(text)));
    fc.assert(fc.property(fc.integer({ min: 0x1000, max: 0xffff }), fc.integer({ min: 0, max: 255 }), (index, sub) => {
      const hex = index.toString(16).toUpperCase();
      expect(parseQuery(`0x${hex}.${sub}`)).toEqual({ kind: "address", index, subindex: sub });
      expect(parseQuery(`${hex}sub${sub}`).kind).toBe(/\d/.test(hex) ? "address" : "text");
    }));
  });
});
