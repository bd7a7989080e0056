import { describe, expect, it } from "vitest";
import type { OdVariable } from "../lib/od";
import { editText, formatRange, formatValue, LIVE_DIGITS, parseValue, sameValue } from "../lib/values";

function variable(extra: Partial<OdVariable>): OdVariable {
  return {
    subindex: 0, name: "x", data_type: "UNSIGNED16", access: "rw", pdo_mappable: false, low: null, high: null,
    default: 0, unit: "", scale: 1, offset: 0, save_type: "NONE", group: "", description: "", enum: {}, bits: [],
    is_pointer: false, reference: "", write_level: null, ...extra,
  };
}

describe("values", () => {
  const current = variable({ data_type: "INTEGER32", unit: "A", scale: 0.001, low: -20000, high: 20000 });

  it("shows physical values with the entry's scale", () => {
    expect(formatValue(current, 1500)).toBe("1.5");
    expect(formatValue(current, -250)).toBe("-0.25");
    expect(editText(current, 1500)).toBe("1.5");
    expect(formatValue(current, null)).toBe("");
  });

  it("shows a scaled integer at its resolution, and an edit keeps every digit", () => {
    const monitor = variable({ data_type: "INTEGER16", unit: "A", scale: 0.0061038881767686015 });
    expect(formatValue(monitor, 127)).toBe("0.775"); // one step is 0.0061 A: three decimals tell steps apart
    expect(formatValue(monitor, 128)).toBe("0.781");
    expect(editText(monitor, 127)).toBe("0.7751937985");
    expect(parseValue(monitor, editText(monitor, 127))).toEqual({ ok: true, raw: 127 });
    const fine = variable({ data_type: "INTEGER32", scale: 1.52587890625e-5 });
    expect(formatValue(fine, 51005)).toBe("0.77827");
    const offset = variable({ data_type: "UNSIGNED8", scale: 1, offset: 2.5 });
    expect(formatValue(offset, 3)).toBe("5.5");
    expect(formatValue(variable({ data_type: "UNSIGNED32" }), 123456789)).toBe("123456789");
  });

  it("shows a REAL without the float's noise, a live readout with LIVE_DIGITS, and edits at full precision", () => {
    const real = variable({ data_type: "REAL32", unit: "A" });
    expect(formatValue(real, 0.7782819016)).toBe("0.7782819");
    expect(formatValue(real, Math.fround(0.1))).toBe("0.1"); // 0.10000000149 as a REAL32 holds it
    expect(formatValue(real, 0.7782819016, LIVE_DIGITS)).toBe("0.77828");
    expect(editText(real, 0.7782819016)).toBe("0.7782819016");
    expect(parseValue(real, editText(real, 0.7782819016))).toEqual({ ok: true, raw: 0.7782819016 });
    const position = variable({ data_type: "INTEGER32", scale: 0.001 });
    expect(formatValue(position, 123456789)).toBe("123456.789"); // a stored value keeps its resolution
    expect(formatValue(position, 123456789, LIVE_DIGITS)).toBe("123457");
    expect(formatValue(variable({ data_type: "INTEGER32" }), 123456789, LIVE_DIGITS)).toBe("123456789"); // counts stay whole
  });

  it("parses typed physical values back to raw, '.' only", () => {
    expect(parseValue(current, "1.5")).toEqual({ ok: true, raw: 1500 });
    expect(parseValue(current, "-0.001")).toEqual({ ok: true, raw: -1 });
    expect(parseValue(current, "1,5").ok).toBe(false);
  });

  it("checks the range in physical units and names it", () => {
    const result = parseValue(current, "25");
    expect(result.ok).toBe(false);
    if (!result.ok) expect(result.error).toBe("25 is outside -20 … 20 A");
    expect(formatRange(current)).toBe("-20 … 20 A");
  });

  it("uses the data type's range when the dictionary gives none", () => {
    const u8 = variable({ data_type: "UNSIGNED8" });
    expect(parseValue(u8, "255")).toEqual({ ok: true, raw: 255 });
    expect(parseValue(u8, "256").ok).toBe(false);
    expect(parseValue(u8, "-1").ok).toBe(false);
    expect(parseValue(u8, "2.5").ok).toBe(false);
  });

  it("shows enumerations by text and words and pointers in hex", () => {
    const mode = variable({ data_type: "INTEGER8", enum: { "1": "Profile position", "-3": "Sequence" } });
    expect(formatValue(mode, -3)).toBe("Sequence (-3)");
    expect(formatValue(mode, 9)).toBe("9");
    const status = variable({ bits: [{ first: 0, last: 0, name: "Ready" }] });
    expect(formatValue(status, 0x227)).toBe("0x0227");
    expect(parseValue(status, "0x0227")).toEqual({ ok: true, raw: 0x227 });
    const pointer = variable({ data_type: "UNSIGNED32", is_pointer: true });
    expect(formatValue(pointer, 0x60fd0010)).toBe("0x60FD0010");
    expect(editText(pointer, 0x60fd0010)).toBe("0x60FD0010");
  });

  it("passes texts through and compares values exactly", () => {
    const name = variable({ data_type: "VISIBLE_STRING" });
    expect(parseValue(name, "Axis 1")).toEqual({ ok: true, raw: "Axis 1" });
    expect(sameValue(1, 1)).toBe(true);
    expect(sameValue(1, 2)).toBe(false);
    expect(sameValue(null, undefined)).toBe(false);
    expect(sameValue("a", "a")).toBe(true);
  });
});

import { unstorableReason } from "../lib/values";

describe("what a project can store", () => {
  it("refuses out-of-range numbers and blank or padded texts, accepts the rest", () => {
    const limited = variable({ data_type: "UNSIGNED16", low: 10, high: 210 });
    expect(unstorableReason(limited, 0)).toBe("0 is outside 10..210");
    expect(unstorableReason(limited, 100)).toBeNull();
    const text = variable({ data_type: "VISIBLE_STRING" });
    expect(unstorableReason(text, "")).not.toBeNull();
    expect(unstorableReason(text, " mm")).not.toBeNull();
    expect(unstorableReason(text, "mm")).toBeNull();
    expect(unstorableReason(text, null)).toBe("no value");
  });
});
