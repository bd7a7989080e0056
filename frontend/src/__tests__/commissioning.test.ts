import { describe, expect, it } from "vitest";
import { STEPS, stepKeys, stepStatus } from "../lib/commissioning";
import type { Dictionary, OdVariable } from "../lib/od";

function sub(subindex: number, access = "rw", save_type = "DRIVEPAR"): OdVariable {
  return {
    subindex, name: `s${subindex}`, data_type: "UNSIGNED16", access, pdo_mappable: false, low: null, high: null, default: 0,
    unit: "", scale: 1, offset: 0, save_type, group: "", description: "", enum: {}, bits: [], is_pointer: false, reference: "", write_level: null,
  };
}

const dictionary: Dictionary = {
  device: "t", product_name: "T", vendor_id: 0, product_code: 0, revision: 0, groups: [], builtin: true, object_count: 3, names: {}, fieldbus: "CANopen", files: ["DRIVEPAR.TXT"], features: [], store: null,
  objects: [
    { index: 0x6073, name: "Max current", kind: "VAR", group: "Motor", subs: [sub(0)] },
    { index: 0x6075, name: "Rated current", kind: "VAR", group: "Motor", subs: [sub(0)] },
    { index: 0x60f6, name: "Current loop", kind: "RECORD", group: "Servo Loops", subs: [sub(0, "ro", "NONE"), sub(1), sub(2)] },
  ],
};
const current = STEPS.find((step) => step.key === "current")!;

describe("commissioning checklist", () => {
  it("lists the manual's order", () => {
    expect(STEPS.map((step) => step.key)).toEqual([
      "config", "motor", "sensors", "current", "thermal", "phasing", "scaling", "tuning", "quicktest", "io", "braking", "save",
    ]);
  });

  it("checks the saved, writable entries of a step that the dictionary has", () => {
    expect(stepKeys(current, dictionary)).toEqual([`${0x6073}.0`, `${0x6075}.0`, `${0x60f6}.1`, `${0x60f6}.2`]);
    expect(stepKeys(STEPS.find((step) => step.key === "sensors")!, dictionary)).toEqual([]);
  });

  it("is done when the project sets every entry, partial when some", () => {
    const keys = stepKeys(current, dictionary);
    expect(stepStatus(current, keys, new Set(), false).state).toBe("open");
    expect(stepStatus(current, keys, new Set([keys[0]]), false)).toEqual({ state: "partial", set: 1, total: 4 });
    expect(stepStatus(current, keys, new Set(keys), false).state).toBe("done");
  });

  it("treats steps without objects as not applicable and manual steps by their tick", () => {
    const sensors = STEPS.find((step) => step.key === "sensors")!;
    expect(stepStatus(sensors, [], new Set(), false).state).toBe("not-applicable");
    const save = STEPS.find((step) => step.key === "save")!;
    expect(stepStatus(save, [], new Set(), false).state).toBe("open");
    expect(stepStatus(save, [], new Set(), true).state).toBe("done");
  });
});
