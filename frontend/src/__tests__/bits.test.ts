import { describe, expect, it } from "vitest";
import { decodeBits, extractBits, fieldLabel, insertBits } from "../lib/bits";
import { decodePointer, encodePointer, formatPointer } from "../lib/pointer";

describe("bit fields", () => {
  it("decodes the status word of an enabled drive field by field", () => {
    const fields = decodeBits(0x0227, [
      { first: 9, last: 9, name: "Remote" },
      { first: 0, last: 0, name: "Ready to switch on" },
      { first: 2, last: 2, name: "Operation enabled" },
      { first: 3, last: 3, name: "Fault" },
      { first: 12, last: 13, name: "Mode specific" },
    ]);
    expect(fields.map((field) => [field.name, field.value])).toEqual([
      ["Ready to switch on", 1],
      ["Operation enabled", 1],
      ["Fault", 0],
      ["Remote", 1],
      ["Mode specific", 0],
    ]);
  });

  it("handles bit 31 and ranges without 32-bit sign errors", () => {
    expect(extractBits(0x80000000, 31, 31)).toBe(1);
    expect(extractBits(0xffff0000, 16, 31)).toBe(0xffff);
    expect(extractBits(0b1101_0000, 4, 7)).toBe(0b1101);
    expect(insertBits(0, 31, 31, 1)).toBe(0x80000000);
    expect(insertBits(0xff, 4, 7, 0)).toBe(0x0f);
    expect(() => insertBits(0, 0, 1, 4)).toThrow(RangeError);
  });

  it("labels single bits and ranges", () => {
    expect(fieldLabel({ first: 3, last: 3, name: "" })).toBe("3");
    expect(fieldLabel({ first: 8, last: 9, name: "" })).toBe("8-9");
  });
});

describe("dataflow pointers", () => {
  it("encodes index<<16 | sub<<8 | bit, also above index 0x7FFF", () => {
    expect(encodePointer({ index: 0x60fd, subindex: 0, bit: 16 })).toBe(0x60fd0010);
    expect(encodePointer({ index: 0x60fe, subindex: 1, bit: 17 })).toBe(0x60fe0111);
    expect(encodePointer({ index: 0xffff, subindex: 0xff, bit: 0xff })).toBe(0xffffffff);
  });

  it("decodes what it encodes", () => {
    for (const target of [{ index: 0x6064, subindex: 0, bit: 32 }, { index: 0x3022, subindex: 2, bit: 5 }]) {
      expect(decodePointer(encodePointer(target))).toEqual(target);
    }
    expect(decodePointer(0x60fe0111)).toEqual({ index: 0x60fe, subindex: 1, bit: 17 });
  });

  it("rejects fields that do not fit and shows unlinked pointers as such", () => {
    expect(() => encodePointer({ index: 0x10000, subindex: 0, bit: 0 })).toThrow(RangeError);
    expect(() => encodePointer({ index: 1, subindex: 256, bit: 0 })).toThrow(RangeError);
    expect(() => decodePointer(-1)).toThrow(RangeError);
    expect(formatPointer(0)).toBe("not linked");
    expect(formatPointer(0x60fd0010)).toBe("0x60FD.0 / 16");
  });
});
