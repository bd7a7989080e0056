import { describe, expect, it } from "vitest";
import { LiveHub, axisStateText } from "../client/live";

describe("live axis state", () => {
  it("follows NMT, EMCY and heartbeat events of the axis's bus and node", () => {
    const hub = new LiveHub();
    let changes = 0;
    hub.onChange(() => changes++);
    hub.emit({ type: "nmt_state", bus: "bus0", node: 2, nmt_state: "OPERATIONAL" });
    expect(hub.axis("bus0", 2)).toMatchObject({ online: true, nmt: "OPERATIONAL" });
    expect(axisStateText(hub.axis("bus0", 2))).toEqual({ text: "operational", tone: "warn" });

    hub.updateAxis("bus0", 2, { statusword: 0x0227 });
    expect(axisStateText(hub.axis("bus0", 2))).toEqual({ text: "Operation enabled", tone: "ok" });

    hub.emit({ type: "emcy", bus: "bus0", node: 2, cleared: false, cia402_code: 0x8611, faults: [{ name: "Position following error" }] });
    expect(axisStateText(hub.axis("bus0", 2))).toEqual({ text: "Fault: Position following error", tone: "bad" });
    hub.emit({ type: "emcy", bus: "bus0", node: 2, cleared: true, faults: [] });
    expect(hub.axis("bus0", 2)?.fault).toBe(false);

    hub.emit({ type: "heartbeat_lost", bus: "bus0", node: 2, period_ms: 100 });
    expect(axisStateText(hub.axis("bus0", 2))).toEqual({ text: "offline", tone: "idle" });
    expect(hub.axis("bus0", 3)).toBeUndefined();
    expect(axisStateText(undefined).text).toBe("…");
    expect(changes).toBe(5);
  });

  it("a status word in fault marks the axis faulty until a status word without fault", () => {
    const hub = new LiveHub();
    hub.updateAxis("sim", 1, { online: true, statusword: 0x0208, faultText: "I²t error" });
    expect(axisStateText(hub.axis("sim", 1))).toEqual({ text: "Fault: I²t error", tone: "bad" });
    hub.updateAxis("sim", 1, { statusword: 0x0240 });
    expect(axisStateText(hub.axis("sim", 1))).toEqual({ text: "Switch on disabled", tone: "warn" });
  });
});
