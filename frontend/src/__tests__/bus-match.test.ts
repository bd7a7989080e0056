import { afterEach, describe, expect, it, vi } from "vitest";
import { busMatches, learnBuses, serverBus, whenMapped, type BusInfo } from "../client/drives";

const bus = (id: string, spec: string): BusInfo => ({ id, spec, kind: spec.split(":")[0], connected: true, error: null, nodes: [] });

afterEach(() => vi.unstubAllGlobals());

describe("project buses matched by the server", () => {
  it("maps a project bus whose spec the server opened under another name and spelling", async () => {
    const asked: unknown[] = [];
    vi.stubGlobal("fetch", vi.fn(async (_url: string, init: RequestInit) => {
      asked.push(JSON.parse(String(init.body)));
      const answer = [{ name: "socketcand-127.0.0.1-18433", spec: "socketcand:127.0.0.1:18433", bus: "socketcand", by: "spec" }];
      return new Response(JSON.stringify(answer), { status: 200, headers: { "Content-Type": "application/json" } });
    }));
    learnBuses([bus("socketcand", "socketcand:127.0.0.1:18433/can0")], [{ name: "socketcand-127.0.0.1-18433", interface: "socketcand:127.0.0.1:18433" }]);
    await whenMapped(async () => undefined);
    await vi.waitFor(() => expect(serverBus("socketcand-127.0.0.1-18433")).toBe("socketcand"));
    expect(busMatches.rawVal.get("socketcand-127.0.0.1-18433")?.by).toBe("spec");
    expect(asked).toEqual([{ buses: [{ name: "socketcand-127.0.0.1-18433", spec: "socketcand:127.0.0.1:18433" }] }]);
  });
});
