import { describe, expect, it } from "vitest";
import { objectFiles, realBits, unwritableText } from "../lib/objectfile";

describe("object files from project values", () => {
  it("spells each file's values as the drive's file syntax, one file per save type", () => {
    const { files, left } = objectFiles([
      { index: 0x60f9, subindex: 2, data_type: "UNSIGNED16", value: 120, file: "DRIVEPAR.TXT" },
      { index: 0x2004, subindex: 0, data_type: "VISIBLE_STRING", value: "Axis X", file: "USER_PAR.TXT" },
      { index: 0x6068, subindex: 0, data_type: "UNSIGNED16", value: 7, file: null },
      { index: 0x3410, subindex: 1, data_type: "REAL32", value: 1.5, file: "DRIVEPAR.TXT" },
    ]);
    expect([...files]).toEqual([
      ["DRIVEPAR.TXT", "0x60F9,2=120\n0x3410,1=1069547520\n"],
      ["USER_PAR.TXT", "0x2004,0=Axis X\n"],
    ]);
    expect(left).toEqual([]);
  });

  it("leaves out and names what the syntax cannot carry", () => {
    const { files, left } = objectFiles([
      { index: 0x2004, subindex: 0, data_type: "VISIBLE_STRING", value: " padded", file: "DRIVEPAR.TXT" },
      { index: 0x2005, subindex: 0, data_type: "VISIBLE_STRING", value: "12 mm", file: "DRIVEPAR.TXT" },
      { index: 0x2006, subindex: 1, data_type: "VISIBLE_STRING", value: "a;b", file: "DRIVEPAR.TXT" },
    ]);
    expect(files.size).toBe(0);
    expect(left).toEqual(["0x2004,0: empty or padded text", "0x2005,0: text that starts like a number", "0x2006,1: text with ';' or a line break"]);
  });

  it("writes REAL values as their IEEE-754 bit pattern", () => {
    expect(realBits(1, "REAL32")).toBe("1065353216");
    expect(realBits(-2.5, "REAL64")).toBe("13836183955189006336");
    expect(unwritableText("ok")).toBeNull();
  });
});
