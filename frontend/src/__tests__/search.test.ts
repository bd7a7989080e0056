import { describe, expect, it } from "vitest";
import type { Dictionary, OdObject, OdVariable } from "../lib/od";
import { address, entries } from "../lib/od";
import { buildIndex, parseQuery, search } from "../lib/search";

function variable(subindex: number, name: string, extra: Partial<OdVariable> = {}): OdVariable {
  return {
    subindex, name, data_type: "UNSIGNED16", access: "rw", pdo_mappable: false, low: null, high: null, default: 0,
    unit: "", scale: 1, offset: 0, save_type: "NONE", group: "", description: "", enum: {}, bits: [],
    is_pointer: false, reference: "", write_level: null, ...extra,
  };
}

function object(index: number, name: string, kind: string, subs: OdVariable[], group = "General"): OdObject {
  return { index, name, kind, group, subs };
}

const dictionary: Dictionary = {
  device: "test", product_name: "Test", vendor_id: 1, product_code: 2, revision: 3, groups: ["General", "Servo Loops"], builtin: true, object_count: 8,
  names: { statusword: [0x6041, 0], modes_of_operation: [0x6060, 0] }, fieldbus: "CANopen", files: ["DRIVEPAR.TXT"], features: [], store: null,
  objects: [
    object(0x6041, "Statusword", "VAR", [variable(0, "Statusword", { bits: [{ first: 3, last: 3, name: "Fault" }] })]),
    object(0x6060, "Modes of operation", "VAR", [variable(0, "Modes of operation", { enum: { "1": "Profile position" } })]),
    object(0x60f9, "Velocity control parameter set", "RECORD", [
      variable(0, "Highest sub-index supported"),
      variable(1, "Regulator type"),
      variable(2, "Speed loop proportional gain", { description: "KPv, speed loop proportional gain" }),
      variable(3, "Speed loop integral gain", { description: "KIv, speed loop integral gain" }),
    ], "Servo Loops"),
    object(0xfeed, "Feed constant", "VAR", [variable(0, "Feed constant")]),
  ],
};
const index = buildIndex(entries(dictionary));
const addresses = (text: string) => search(index, text).map(address);

describe("search", () => {
  it("finds KPv by its description: 0x60F9 sub 2", () => {
    expect(addresses("KPv")).toEqual(["0x60F9.2"]);
    expect(addresses("kpv")).toEqual(["0x60F9.2"]);
  });

  it("finds objects by address in the usual spellings", () => {
    expect(addresses("60F9")).toEqual(["0x60F9.0", "0x60F9.1", "0x60F9.2", "0x60F9.3"]);
    for (const text of ["0x60F9.2", "60f9sub2", "60F9,2", "60F9:2", "0x60f9 2", "60F9s2"]) {
      expect(addresses(text)).toEqual(["0x60F9.2"]);
    }
    expect(addresses("0x6041")).toEqual(["0x6041"]);
  });

  it("searches hex-letter words as text, not as an address", () => {
    expect(parseQuery("feed")).toEqual({ kind: "text", tokens: ["feed"] });
    expect(addresses("feed")).toEqual(["0xFEED"]);
  });

  it("requires every word, ranks name matches before description matches", () => {
    expect(addresses("speed gain")).toEqual(["0x60F9.2", "0x60F9.3"]);
    expect(addresses("integral")).toEqual(["0x60F9.3"]);
    expect(addresses("modes")[0]).toBe("0x6060");
    expect(addresses("nothing-like-this")).toEqual([]);
  });

  it("searches enumeration texts and bit names", () => {
    expect(addresses("profile position")).toEqual(["0x6060"]);
    expect(addresses("fault")).toEqual(["0x6041"]);
  });

  it("returns everything in dictionary order for an empty query", () => {
    expect(search(index, "  ").length).toBe(7);
  });

  it("filters a 1,000-object dictionary", () => {
    const big: Dictionary = {
      ...dictionary,
      objects: Array.from({ length: 1000 }, (_, i) =>
        object(0x2000 + i, `Object ${i}`, "RECORD", [variable(0, "Count"), variable(1, `Value ${i}`, { description: `gain ${i % 7}` })]),
      ),
    };
    const bigIndex = buildIndex(entries(big));
    expect(search(bigIndex, "gain 3").length).toBeGreaterThan(100);
    expect(search(bigIndex, "0x23E7.1").map(address)).toEqual(["0x23E7.1"]);
  });
});

import { dashboardSignals } from "../lib/dashboard-objects";

describe("dashboard signals", () => {
  it("takes the CiA 402 measurements the dictionary has and finds temperatures by unit", () => {
    const withSignals: Dictionary = {
      ...dictionary,
      names: { ...dictionary.names, position_actual: [0x6064, 0], velocity_actual: [0x606c, 0], dc_bus_voltage: [0x3408, 1] },
      objects: [
        ...dictionary.objects,
        object(0x6064, "Position actual value", "VAR", [variable(0, "Position actual value", { access: "ro" })]),
        object(0x606c, "Velocity actual value", "VAR", [variable(0, "Velocity actual value", { access: "ro" })]),
        object(0x3328, "IGBT temperature", "VAR", [variable(0, "IGBT temperature", { access: "ro", unit: "°C" })]),
        object(0x3324, "Probe", "RECORD", [variable(4, "Warning threshold", { access: "rw", unit: "°C" })]),
      ],
    };
    const signals = dashboardSignals(withSignals);
    expect(signals.measurements.map(address)).toEqual(["0x6064", "0x606C", "0x3328"]);
    expect(signals.statusword && address(signals.statusword)).toBe("0x6041");
    expect(signals.inputs).toBeNull();
    expect(signals.nmt).toBe(true);
  });

  it("finds a PROFIBUS drive's entries by the names the server gives, without NMT", () => {
    const pnu = (index: number, name: string) => object(index, name, "VAR", [variable(0, name, { access: "ro" })]);
    const ttapro: Dictionary = {
      ...dictionary, device: "ttapro", fieldbus: "PROFIBUS-DP",
      names: { statusword: [0x801, 0], position_actual: [774, 0], dc_bus_voltage: [706, 0], speed_monitor: [776, 0], following_error_actual: [749, 0] },
      objects: [pnu(0x801, "Status word ZSW"), pnu(706, "DC bus voltage"), pnu(749, "Following error"), pnu(774, "Position"), pnu(776, "Speed monitor"), pnu(0x6041, "Not a status word")],
    };
    const signals = dashboardSignals(ttapro);
    expect(signals.statusword?.object.index).toBe(0x801);
    expect(signals.measurements.map((entry) => entry.object.index)).toEqual([774, 776, 749, 706]);
    expect([signals.mode, signals.targetVelocity, signals.nmt]).toEqual([null, null, false]);
  });

  it("takes CiA 402's DC link voltage before a device's own DC bus voltage", () => {
    const both: Dictionary = {
      ...dictionary, names: { dc_link_voltage: [0x6079, 0], dc_bus_voltage: [0x3408, 1] },
      objects: [object(0x3408, "DC voltage", "RECORD", [variable(1, "DC voltage", { access: "ro" })]), object(0x6079, "DC link", "VAR", [variable(0, "DC link", { access: "ro" })])],
    };
    expect(dashboardSignals(both).measurements.map(address)).toEqual(["0x6079"]);
  });
});
