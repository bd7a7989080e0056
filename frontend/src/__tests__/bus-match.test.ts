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

  it("lets drive calls wait for an answer the mapping took, and keeps the server's mapping while it asks again", async () => {
    const pending: ((response: Response) => void)[] = [];
    vi.stubGlobal("fetch", vi.fn(() => new Promise<Response>((resolve) => pending.push(resolve))));
    vi.resetModules(); // a fresh start of the app: the mapping not yet learned
    const { learnBuses, serverBus, whenMapped } = await import("../client/drives");
    const answer = (bus: string) => new Response(JSON.stringify([{ name: "rig", spec: "socketcand:h:1", bus, by: "spec" }]),
      { status: 200, headers: { "Content-Type": "application/json" } });
    const server = [bus("bus7", "socketcand:h:1/can0")];
    const project = [{ name: "rig", interface: "socketcand:h:1" }];
    learnBuses(server, project);
    learnBuses(server, project); // a bus event asks again before the first answer came
    let mapped: string | null = null;
    const call = whenMapped(async () => (mapped = serverBus("rig")));
    await new Promise((resolve) => setTimeout(resolve, 10));
    expect(mapped).toBeNull(); // no answer yet: the call waits (the spec's spelling alone does not match)
    pending[1](answer("bus7")); // the later question's answer comes first
    await call;
    expect(mapped).toBe("bus7");
    pending[0](answer("stale")); // the earlier question's answer, late: dropped
    await new Promise((resolve) => setTimeout(resolve, 10));
    expect(serverBus("rig")).toBe("bus7");
    learnBuses(server, project); // and again: meanwhile the server's answer stands, not a guess from the spelling
    expect(serverBus("rig")).toBe("bus7");
    pending[2](answer("bus7"));
  });
});
