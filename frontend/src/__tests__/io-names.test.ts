import { describe, expect, it } from "vitest";
import { configuredName } from "../components/dashboard/io";
import { bitName } from "../components/sequences/pattern";
import { settingValue } from "../components/io/model";
import { ioNames, lineLabel } from "../lib/io-names";

const functions = [
  { key: "none", label: "No function" },
  { key: "positive_limit", label: "Positive limit switch" },
  { key: "condition_7", label: "Sequence condition bit 7 (0x3601,3)", condition_bit: 7 },
];
const outputFunctions = [{ key: "none", label: "No function" }, { key: "sequence_output_3", label: "Sequence output 4" }];

describe("the names of the I/O configuration", () => {
  const names = ioNames({
    routing: "pointer",
    functions,
    output_functions: outputFunctions,
    inputs: [{ name: "IN1", function: "none", bit: 16 }, { name: "IN2", function: "positive_limit", bit: 17 }, { name: "IN3", function: "condition_7", bit: 18 }],
    outputs: [{ name: "OUT1", function: "sequence_output_3", bit: 16 }, { name: "OUT2", function: "other", bit: 17 }],
  });

  it("labels the 0x60FD and 0x60FE,1 bits with the line and its function", () => {
    expect(names.inputs.get(16)).toBe("IN1");
    expect(names.inputs.get(17)).toBe("IN2: Positive limit switch");
    expect(names.outputs.get(17)).toBe("OUT2");
    expect(configuredName("IN2: Positive limit switch")).toBe("IN2 LIM+");
    expect(configuredName("INPUT0 / LS+")).toBe("INPUT0");
    expect(configuredName("INHIBIT: Inhibit")).toBe("INHIBIT");  // a terminal named after its function: once
    expect(lineLabel({ name: "IN9", function: "unknown", bit: 24 }, functions)).toBe("IN9: unknown");
  });

  it("names the sequence editor's pattern bits by the input and output routed to them", () => {
    expect(bitName("StartCond", 7, names)).toBe("IN3");
    expect(bitName("StartCond", 6, names)).toBe("IN7"); // not routed: the manual's "logic input n+1"
    expect(bitName("Output", 3, names)).toBe("OUT1");
    expect(bitName("Output", 0, names)).toBe("OUT1");
    expect(bitName("Output", 0)).toBe("OUT1");
    expect(bitName("EndCond", 0)).toBe("IN1");
  });

  it("sends a setting as a number when it is one", () => {
    expect([settingValue(" 12 "), settingValue("-3"), settingValue("0x30F80100"), settingValue("abc")]).toEqual([12, -3, 0x30f80100, "abc"]);
  });
});
