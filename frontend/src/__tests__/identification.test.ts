import { afterEach, beforeEach, describe, expect, it, vi } from "vitest";
import { App } from "../app";
import { setMotionClient } from "../client/api";
import type { AxisControl } from "../client/control";
import type { IdentificationClient, IdentificationOptions, IdentificationResult } from "../client/identification";
import type { JobInfo } from "../client/jobs";
import type { ProceduresClient } from "../client/procedures";
import { identificationPanel } from "../components/identification/panel";
import { createModel, refreshControl, type ControlClient } from "../components/procedures/model";
import { Scope } from "../lib/dom";

const settled = () => new Promise((resolve) => setTimeout(resolve, 0));
const testid = (root: ParentNode, id: string) => root.querySelector<HTMLElement>(`[data-testid="${id}"]`);
const where = { bus: "sim", node: 1, project: "demo", axis: "X" };

const procedures: ProceduresClient = { list: async () => [], start: vi.fn(), undo: vi.fn(), saved: async () => [] };

function control(holder: string | null): ControlClient {
  const answer = async (): Promise<AxisControl> => ({ bus: "sim", node: 1, requests: [], holder: holder ? { client: holder, user: "local", since: 0 } : null } as AxisControl);
  return { get: answer, arm: answer, release: answer, request: answer, takeOver: answer };
}

class FakeIdentification implements IdentificationClient {
  starts: IdentificationOptions[] = [];
  bandwidths: (number | null)[] = [];
  start = vi.fn(async (_bus: string, _node: number, options: IdentificationOptions, bandwidth: number | null) => {
    this.starts.push(options);
    this.bandwidths.push(bandwidth);
    return { id: "job9", operation: "identification", state: "running", started: 0, result: null } as JobInfo<IdentificationResult>;
  });
}

async function panelWith(holder: string | null) {
  const app = new App(document.createElement("div"));
  const model = createModel(new Scope(), app.live, where, procedures, control(holder));
  await refreshControl(model);
  const fake = new FakeIdentification();
  const panel = identificationPanel(model, fake);
  document.body.append(panel);
  return { app, panel, fake };
}

const RESULT: IdentificationResult = {
  kind: "identification", status: "done", node: 1, device: "encotrive", time: "2026-12-02T10:00:00Z",
  identified: { inertia_kgm2: 0.0012566, viscous_friction_nms_per_rad: 0.000112, coulomb_friction_nm: 0.0733, load_torque_nm: -0.0004, residual: 0.024, inertia_ratio: null },
  experiment: { speed_rpm: 800, samples: 5950, source: "tpdo" },
};

beforeEach(() => setMotionClient("me"));
afterEach(() => {
  setMotionClient(null);
  document.body.textContent = "";
});

describe("identification panel", () => {
  it("keeps Identify disabled until this page armed the axis", async () => {
    const { panel } = await panelWith(null);
    expect((testid(panel, "identification-start") as HTMLButtonElement).disabled).toBe(true);
    expect(testid(panel, "identification-reason")!.textContent).toContain("Arm the axis first");
  });

  it("starts the job with the options typed in, follows its progress and shows the identified plant", async () => {
    const { app, panel, fake } = await panelWith("me");
    const speed = testid(panel, "identification-speed_rpm") as HTMLInputElement;
    speed.value = "600";
    speed.dispatchEvent(new Event("change"));
    const bandwidth = testid(panel, "identification-bandwidth") as HTMLInputElement;
    bandwidth.value = "75";
    bandwidth.dispatchEvent(new Event("change"));
    testid(panel, "identification-start")!.click();
    await settled();
    expect(fake.starts).toEqual([{ speed_rpm: 600, position_window_rev: 6, cycles: 2 }]);
    expect(fake.bandwidths).toEqual([75]);
    app.live.emit({ type: "progress", job: "job9", operation: "identification", phase: "running", fraction: 0.2, message: "speed 600 rpm" });
    expect(testid(panel, "identification-reason")!.textContent).toBe("speed 600 rpm");
    const tuning = { bandwidth_hz: 75, gains: { before: {}, after: {} }, verification: { speed_step: { bandwidth_hz: 72.1, overshoot_pct: 13.9 } } };
    app.live.emit({ type: "job", id: "job9", operation: "identification", state: "done", started: 0, result: { ...RESULT, tuning } });
    await settled();
    expect(testid(panel, "identified-inertia_kgm2")!.textContent).toContain("0.001257");
    expect(testid(panel, "identified-inertia_ratio")!.textContent).toContain("—");
    expect(testid(panel, "identification-tuning")!.textContent).toContain("measured 72.10 Hz");
    expect((testid(panel, "identification-start") as HTMLButtonElement).disabled).toBe(false);
  });

  it("says why a run failed", async () => {
    const { app, panel } = await panelWith("me");
    testid(panel, "identification-start")!.click();
    await settled();
    app.live.emit({ type: "job", id: "job9", operation: "identification", state: "failed", started: 0, error: "node 1: limit exceeded: position 6.2 rev" });
    await settled();
    expect(testid(panel, "identification-failed")?.textContent ?? panel.textContent).toContain("limit exceeded");
  });
});
