import { describe, expect, it } from "vitest";
import { busNames, learnBuses, serverBus, type BusInfo } from "../client/drives";

const bus = (id: string, spec: string): BusInfo => ({ id, spec, kind: spec.split(":")[0], connected: true, error: null, nodes: [] });

describe("project bus → server bus", () => {
  it("maps by name first, else by spec, and leaves unknown buses as named", () => {
    learnBuses([bus("bus0", "sim"), bus("can0", "socketcan:can0")], [
      { name: "sim", interface: "sim" },
      { name: "can0", interface: "socketcan:can1" },
      { name: "line", interface: "serial:/dev/ttyUSB0" },
    ]);
    expect(serverBus("sim")).toBe("bus0");
    expect(serverBus("can0")).toBe("can0");
    expect(serverBus("line")).toBe("line");
    expect(busNames("bus0")).toEqual(["bus0", "sim"]);
    expect(busNames("can0")).toEqual(["can0"]);
  });

  it("forgets old mappings when the buses change", () => {
    learnBuses([bus("bus0", "sim")], [{ name: "sim", interface: "sim" }]);
    learnBuses([], [{ name: "sim", interface: "sim" }]);
    expect(serverBus("sim")).toBe("sim");
  });
});
