import { describe, expect, it } from "vitest";
import type { Motor } from "../client/api";
import { differs, shownRows, type Column } from "../pages/compare";
import { matching } from "../pages/motors";
import { axesRefusal, itemOf, newLine } from "../pages/terminal";
import { entry } from "./fixtures";

describe("terminal lines", () => {
  const targets = [{ label: "demo/X", bus: "sim", node: 1 }, { label: "demo/Y", bus: "sim", node: 2 }];

  it("names an object of the line's axis once an object is typed", () => {
    const line = newLine(1, "  ");
    expect(itemOf(targets, line)).toBeNull();
    line.object.val = " 0x6041 ";
    expect(itemOf(targets, line)).toEqual({ bus: "sim", node: 2, object: "0x6041" });
    expect(itemOf([], line)).toBeNull();
  });

  it("refuses more than four axes at once", () => {
    const items = [1, 2, 3, 4].map((node) => ({ bus: "sim", node, object: "statusword" }));
    expect(axesRefusal([...items, { bus: "sim", node: 4, object: "0x6061" }])).toBeNull();
    expect(axesRefusal([...items, { bus: "can0", node: 4, object: "statusword" }]))
      .toBe("The terminal works on up to 4 axes at once; these lines use 5.");
  });
});

describe("compare rows", () => {
  const speed = entry(0x6081, { name: "Profile velocity", default: 100 });
  const accel = entry(0x6083, { name: "Profile acceleration", default: 500 });
  const brake = entry(0x6084, { name: "Profile deceleration", default: 500 });
  const columns: Column[] = [
    { title: "X project", values: new Map([[speed.key, 100], [accel.key, 800]]) },
    { title: "default", values: new Map([[speed.key, 100], [accel.key, 500], [brake.key, 500]]) },
  ];
  const loaded = { status: "ready" as const, value: { list: [speed, accel, brake], columns } };

  it("marks a row whose columns disagree", () => {
    expect(differs(columns, accel)).toBe(true);
    expect(differs(columns, speed)).toBe(false);
    expect(differs(columns, brake)).toBe(false);
  });

  it("filters by name or index and shows only the differences when asked", () => {
    expect(shownRows(loaded, "", true)).toMatchObject({ shown: [accel], differing: 1 });
    expect(shownRows(loaded, "", false)?.shown).toEqual([speed, accel, brake]);
    expect(shownRows(loaded, "0x6084", false)?.shown).toEqual([brake]);
    expect(shownRows(loaded, "velocity", false)?.shown).toEqual([speed]);
    expect(shownRows({ status: "loading" }, "", true)).toBeNull();
  });
});

describe("motor filter", () => {
  const motor = (reference: string, description: string): Motor =>
    ({ reference, description, source: "catalog", motor_data: {}, objects: {}, builtin: true });

  it("matches reference, description or source in any case", () => {
    const motors = [motor("BMH0701", "Servo motor 0.7 Nm"), motor("SH3", "Brushless")];
    expect(matching(motors, " bmh ").map((m) => m.reference)).toEqual(["BMH0701"]);
    expect(matching(motors, "brushless").map((m) => m.reference)).toEqual(["SH3"]);
    expect(matching(motors, "CATALOG")).toHaveLength(2);
    expect(matching(motors, "")).toHaveLength(2);
  });
});
