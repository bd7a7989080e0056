import { beforeEach, describe, expect, it, vi } from "vitest";
import type { WatchRow } from "../client/terminal-socket";
import { DashboardModel } from "../components/dashboard/model";
import { dashboardSignals } from "../lib/dashboard-objects";
import { Scope } from "../lib/dom";
import type { Dictionary } from "../lib/od";
import type { AxisContext } from "../pages/axis";
import { entry } from "./fixtures";

const api = vi.hoisted(() => ({
  state: vi.fn(), setState: vi.fn(), faults: vi.fn(), resetFaults: vi.fn(), read: vi.fn(), writeKey: vi.fn(), nmt: vi.fn(), openBus: vi.fn(),
}));
const sockets = vi.hoisted(() => [] as { onRows: ((rows: WatchRow[]) => void) | null; watch: ReturnType<typeof vi.fn>; close: ReturnType<typeof vi.fn> }[]);
vi.mock("../client/drives", () => ({ driveApi: api, serverBus: (bus: string) => bus }));
vi.mock("../client/terminal-socket", () => ({
  TerminalSocket: class {
    onRows = null;
    onError = null;
    onConnection = null;
    watch = vi.fn();
    close = vi.fn();
    constructor() {
      sockets.push(this as never);
    }
  },
}));
vi.mock("../components/ui", () => ({ toast: vi.fn(), errorText: (error: unknown) => (error instanceof Error ? error.message : String(error)) }));

const statusword = entry(0x6041, { name: "Statusword", access: "ro" });
const voltage = entry(0x6079, { name: "DC link circuit voltage", access: "ro", unit: "V" });
const dictionary = {
  groups: [], objects: [statusword.object, voltage.object], names: { statusword: [0x6041, 0], dc_link_voltage: [0x6079, 0] }, fieldbus: "CANopen", files: ["DRIVEPAR.TXT"],
} as unknown as Dictionary;
const noFaults = { faults: [], warnings: [], fault: false, error_code: 0, error_text: "" };

function model(shown: Dictionary = dictionary) {
  const live = { axis: vi.fn(() => undefined), onChange: vi.fn(() => () => undefined), on: vi.fn(() => () => undefined), updateAxis: vi.fn() };
  const context = {
    axis: { bus: "sim", node_id: 2, name: "Y" },
    project: { name: "demo", buses: [{ name: "sim", interface: "sim" }] },
    dictionary: shown,
    page: { app: { live } },
  } as unknown as AxisContext;
  const scope = new Scope();
  const signals = dashboardSignals(shown);
  return { model: new DashboardModel(context, signals, scope), signals, live, scope };
}

beforeEach(() => {
  vi.clearAllMocks();
  sockets.length = 0;
  api.faults.mockResolvedValue(noFaults);
});

describe("dashboard model", () => {
  it("takes the state from REST, then watches the live values and follows the status word", async () => {
    api.state.mockResolvedValue({ statusword: 0x0240, nmt_state: "OPERATIONAL" });
    const { model: dashboard, live } = model();
    await dashboard.start();
    expect([dashboard.statusword.val, dashboard.nmt.val]).toEqual([0x0240, "NMT OPERATIONAL"]);
    expect(live.updateAxis).toHaveBeenCalledWith("sim", 2, { online: true, statusword: 0x0240 });
    expect(sockets[0].watch).toHaveBeenCalledWith([
      { bus: "sim", node: 2, object: "0x6041,0" }, { bus: "sim", node: 2, object: "0x6079,0" },
    ], 200);
    expect(api.faults).toHaveBeenCalledTimes(1);
    sockets[0].onRows!([
      { bus: "sim", node: 2, object: "0x6041,0", value: { raw: 0x0248 } as never },
      { bus: "sim", node: 2, object: "0x6079,0", value: { raw: 325 } as never },
    ]);
    expect(dashboard.statusword.val).toBe(0x0248);
    expect(dashboard.cell(voltage).val.value?.raw).toBe(325);
    expect(api.faults).toHaveBeenCalledTimes(2); // the fault bit changed
    sockets[0].onRows!([{ bus: "sim", node: 2, object: "0x6079,0", error: "timeout" }]);
    expect(dashboard.cell(voltage).val).toEqual({ value: { raw: 325 }, error: "timeout" });
  });

  it("says a drive without NMT fields (a PROFIBUS-DP drive) has no NMT instead of an unknown NMT state", async () => {
    api.state.mockResolvedValue({ statusword: 0x0240 });
    const { model: dashboard } = model();
    await dashboard.start();
    expect(dashboard.nmt.val).toBe("no NMT (PROFIBUS-DP)");
  });

  it("shows a drive it cannot reach with the project's bus to open, and is no longer reachable once offline", async () => {
    api.state.mockRejectedValue(new Error("no bus 'sim'"));
    const { model: dashboard } = model();
    expect(dashboard.reachable.val).toBe(true);
    await dashboard.start();
    expect(dashboard.message.val).toEqual({ kind: "offline", text: "Drive not reachable: no bus 'sim'", bus: { name: "sim", interface: "sim" } });
    expect(dashboard.reachable.val).toBe(false);
    expect(dashboard.nmt.val).toBe("NMT —");
  });

  it("walks the state machine for a command, busy meanwhile, and shows a refusal with the command's name", async () => {
    api.setState.mockResolvedValue({ statusword: 0x0221 });
    const { model: dashboard } = model();
    const running = dashboard.runCommand("shutdown");
    expect(dashboard.busy.val).toBe(true);
    expect(await running).toBe(true);
    expect(api.setState).toHaveBeenCalledWith("sim", 2, "ready-to-switch-on");
    expect([dashboard.statusword.val, dashboard.busy.val]).toEqual([0x0221, false]);
    api.setState.mockRejectedValue(new Error("refused: no motion client"));
    expect(await dashboard.runCommand("enable_operation")).toBe(false);
    expect(dashboard.message.val).toEqual({ kind: "error", text: "Enable operation: refused: no motion client", testid: "dashboard-error" });
  });

  it("writes mode, ramps and target for the quick test, and target 0 on stop", async () => {
    const dictionaryWithTest = { groups: [], objects: [
      entry(0x6060, { data_type: "INTEGER8" }).object, entry(0x60ff, { data_type: "INTEGER32" }).object,
    ], names: { modes_of_operation: [0x6060, 0], target_velocity: [0x60ff, 0] } } as unknown as Dictionary;
    const { model: dashboard, signals } = model(dictionaryWithTest);
    api.read.mockResolvedValue({ raw: 900 });
    const target = dashboard.quickValue(signals.targetVelocity!);
    await vi.waitFor(() => expect(target.val).toBe(900));
    await dashboard.runQuickTest([{ entry: signals.targetVelocity!, raw: 1500, text: "1500" }]);
    expect(api.writeKey.mock.calls).toEqual([["sim", 2, "0x6060,0", 3], ["sim", 2, "0x60FF,0", 1500]]);
    expect(await dashboard.stopQuickTest()).toBe(true);
    expect(api.writeKey).toHaveBeenLastCalledWith("sim", 2, "0x60FF,0", 0);
    expect(target.val).toBe(0);
  });

  it("closes the live socket with the page", () => {
    const { scope } = model();
    scope.dispose();
    expect(sockets[0].close).toHaveBeenCalledOnce();
  });
});
