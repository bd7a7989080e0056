import { describe, expect, it } from "vitest";
import { AXIS_TABS, axisTab, axisTabs } from "../lib/axis-tabs";
import { AXIS_VIEWS } from "../lib/router";

const views = (features: string[]) => axisTabs({ features }).map((tab) => tab.view);

describe("axis tabs", () => {
  it("shows every tab to a device with every feature (an XtrapulsPac)", () => {
    expect(views(["scope", "current_loop", "phasing", "auto_tuning", "frequency_response", "sequences", "io"])).toEqual([...AXIS_VIEWS]);
  });

  it("shows a device without features (a TTA-PRO) only what every drive has", () => {
    expect(views([])).toEqual(["dashboard", "parameters", "commissioning", "backup"]);
  });

  it("decides each tab by the feature the server names, not by the device", () => {
    expect(views(["scope", "frequency_response", "io"])).toEqual(["dashboard", "parameters", "commissioning", "backup", "scope", "bode", "io"]);
    expect(views(["phasing", "auto_tuning"])).toEqual(["dashboard", "parameters", "commissioning", "backup", "phasing", "tuning"]);
    expect(views(["phasing"])).not.toContain("current-loop");
    expect(views(["something-new"])).toEqual(views([]));
  });

  it("has one tab per view, in the route's order", () => {
    expect(AXIS_TABS.map((tab) => tab.view)).toEqual([...AXIS_VIEWS]);
    expect(axisTab("io").label).toBe("I/O");
  });
});
