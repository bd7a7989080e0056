import { describe, expect, it } from "vitest";
import { merged, stepBit, toText } from "../components/sequences/text";

const pos = (sequence: number, next: number) => ({
  sequence,
  type: "POS",
  values: { PosType: "REL", Pos: 1024, Speed: 100, Accel: 5, Decel: null, Trigger: null, Output: "..001000", SeqNext: next },
});

describe("sequence text", () => {
  it("writes SEQUENCE.TXT by number, leaving out what the file cannot spell, and maps every line", () => {
    const { text, lines } = toText([pos(2, -1), pos(1, 2)]);
    expect(text.split("\n").slice(0, 8)).toEqual([
      "SeqNb=1", "SeqType=POS", "PosType=REL", "Pos=1024", "Speed=100", "Accel=5", 'Output="..001000"', "SeqNext=2",
    ]);
    expect(lines.get(7)).toEqual({ sequence: 1, keyword: "Output" });
    expect(lines.get(9)).toEqual({ sequence: 2, keyword: "SeqNb" });
  });

  it("merges by sequence number or loads the file alone", () => {
    expect(merged([pos(1, 2), pos(3, -1)], [pos(3, 1)], "merge").map((row) => [row.sequence, row.values.SeqNext])).toEqual([[1, 2], [3, 1]]);
    expect(merged([pos(1, 2)], [pos(3, 1)], "load").map((row) => row.sequence)).toEqual([3]);
  });

  it("steps a pattern bit through . 1 0", () => {
    expect(stepBit("........", 7)).toBe("1.......");
    expect(stepBit("1.......", 7)).toBe("0.......");
    expect(stepBit("0.......", 7)).toBe("........");
    expect(stepBit("........", 0)).toBe(".......1");
  });
});
