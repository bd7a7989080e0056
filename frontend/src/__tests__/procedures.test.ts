import { afterEach, beforeEach, describe, expect, it, vi } from "vitest";
import { App } from "../app";
import { setMotionClient } from "../client/api";
import type { AxisControl } from "../client/control";
import type { JobInfo } from "../client/jobs";
import type { ProcedureInfo, ProcedureResult, ProceduresClient, StartRequest } from "../client/procedures";
import { createModel, refresh, refreshControl, type ControlClient } from "../components/procedures/model";
import { phasingResult } from "../components/procedures/results";
import { runnerPanel } from "../components/procedures/runner";
import { savedPanel } from "../components/procedures/saved";
import { tuningResult } from "../components/procedures/tuning-result";
import { h, Scope, state } from "../lib/dom";

const settled = () => new Promise((resolve) => setTimeout(resolve, 0));
const testid = (root: ParentNode, id: string) => root.querySelector<HTMLElement>(`[data-testid="${id}"]`);
const button = (root: ParentNode, id: string) => testid(root, id) as HTMLButtonElement;
const where = { bus: "sim", node: 1, project: "demo", axis: "X" };

function info(overrides: Partial<ProcedureInfo> = {}): ProcedureInfo {
  return {
    name: "auto_phasing", label: "Auto-phasing", moves: true, status: "never", ready: true,
    preconditions: [{ name: "i2t_fusing", label: "I²t mode Fusing", ok: true, reason: null }], ...overrides,
  };
}

/** A fake server: the procedures it lists, the start requests it got, the job it answers, its saved results. */
class FakeClient implements ProceduresClient {
  procedures: ProcedureInfo[] = [info()];
  starts: [string, StartRequest][] = [];
  undone: Record<string, number>[] = [];
  kept: ProcedureResult[] = [];
  refusal: Error | null = null;
  list = vi.fn(async () => this.procedures);
  start = vi.fn(async (_bus: string, _node: number, name: string, request: StartRequest) => {
    if (this.refusal) throw this.refusal;
    this.starts.push([name, request]);
    return { id: "job7", operation: `procedure:${name}`, state: "running", started: 0, result: null } as JobInfo<ProcedureResult>;
  });
  undo = vi.fn(async (_bus: string, _node: number, gains: Record<string, number>) => {
    this.undone.push(gains);
    return { gains };
  });
  saved = vi.fn(async () => this.kept);
}

function fakeControl(holder: string | null): ControlClient {
  const answer = async (): Promise<AxisControl> => ({ bus: "sim", node: 1, requests: [], holder: holder ? { client: holder, user: "local", since: 0 } : null } as AxisControl);
  return { get: answer, arm: answer, release: answer, request: answer, takeOver: answer };
}

async function setup(client: FakeClient, holder: string | null = "me") {
  const app = new App(document.createElement("div"));
  const scope = new Scope();
  const model = createModel(scope, app.live, where, client, fakeControl(holder));
  await refresh(model);
  await refreshControl(model);
  return { app, model, scope };
}

function tickAll(panel: HTMLElement, name: string): void {
  for (const box of panel.querySelectorAll<HTMLInputElement>(`[data-testid^="${name}-check-"]`)) {
    box.checked = true;
    box.dispatchEvent(new Event("change"));
  }
}

beforeEach(() => setMotionClient("me"));

afterEach(() => {
  vi.unstubAllGlobals();
  setMotionClient(null);
  document.body.textContent = "";
});

describe("procedure runner", () => {
  it("keeps Start disabled with the reason until the checklist is ticked, the drive is ready and the axis armed", async () => {
    const client = new FakeClient();
    client.procedures = [info({ ready: false, preconditions: [{ name: "limit_switch", label: "Limit switches", ok: false, reason: "the positive limit switch is active" }] })];
    const { model } = await setup(client, null);
    const panel = runnerPanel({ model, name: "auto_phasing", title: "Auto-phasing", intro: "", result: phasingResult });
    const start = button(panel, "auto_phasing-start");
    expect(start.disabled).toBe(true);
    expect(testid(panel, "auto_phasing-reason")!.textContent).toBe("Limit switches: the positive limit switch is active");
    expect(testid(panel, "auto_phasing-pre-limit_switch")!.dataset.ok).toBe("false");

    client.procedures = [info()];
    await refresh(model);
    expect(testid(panel, "auto_phasing-reason")!.textContent).toMatch(/^Tick the safety checklist first \(5 left: The motor is free/);
    tickAll(panel, "auto_phasing");
    expect(testid(panel, "auto_phasing-reason")!.textContent).toBe("Arm the axis first: this procedure turns the motor.");
    expect(start.disabled).toBe(true);
    model.holder.val = { bus: "sim", node: 1, requests: [], holder: { client: "me", user: "local", since: 0 } } as AxisControl;
    expect(start.disabled).toBe(false);
    expect(testid(panel, "auto_phasing-reason")!.textContent).toBe("Ready.");
  });

  it("needs no arming for a procedure that does not move, and sends the options read at Start", async () => {
    const client = new FakeClient();
    client.procedures = [info({ name: "current_loop", moves: false })];
    const { model } = await setup(client, null);
    const inductance = state("12.5");
    const panel = runnerPanel({
      model, name: "current_loop", title: "calc", intro: "", result: () => null,
      options: () => ({ inductance_mh: Number(inductance.rawVal), regulator: "low" }),
    });
    expect(button(panel, "current_loop-start").disabled).toBe(false);
    button(panel, "current_loop-start").click();
    await settled();
    expect(client.starts).toEqual([["current_loop", { options: { inductance_mh: 12.5, regulator: "low" }, verify: true, project: "demo", axis: "X" }]]);
  });

  it("refuses bad options before anything is sent, with the reason", async () => {
    const client = new FakeClient();
    client.procedures = [info({ name: "current_loop", moves: false })];
    const { model } = await setup(client);
    const panel = runnerPanel({ model, name: "current_loop", title: "calc", intro: "", result: () => null, options: () => { throw new Error("Inductance: 2,5 is not a number"); } });
    document.body.append(panel);
    button(panel, "current_loop-start").click();
    await settled();
    expect(client.starts).toEqual([]);
    expect(testid(panel, "current_loop-invalid")!.textContent).toBe("Inductance: 2,5 is not a number");
  });

  it("shows the live progress, aborts through the job's cancel, and shows the result when the job ends", async () => {
    const client = new FakeClient();
    const { app, model } = await setup(client);
    const requests: string[] = [];
    vi.stubGlobal("fetch", vi.fn(async (url: string, init: RequestInit) => {
      requests.push(`${init.method} ${url}`);
      return Response.json({ id: "job7", operation: "procedure:auto_phasing", state: "running", started: 0 });
    }));
    const panel = runnerPanel({ model, name: "auto_phasing", title: "Auto-phasing", intro: "", result: phasingResult });
    tickAll(panel, "auto_phasing");
    button(panel, "auto_phasing-start").click();
    await settled();
    expect(button(panel, "auto_phasing-start").disabled).toBe(true);
    expect(button(panel, "auto_phasing-abort").disabled).toBe(false);
    app.live.emit({ type: "progress", job: "job7", procedure: "auto_phasing", phase: "running", status: "running", elapsed_s: 1.25, fraction: 0.4, message: "turning the field" });
    app.live.emit({ type: "progress", job: "other", procedure: "auto_phasing", phase: "reading", status: "running", elapsed_s: 9, fraction: null, message: "not ours" });
    expect(testid(panel, "procedure-phase")!.textContent).toBe("running");
    expect(testid(panel, "procedure-message")!.textContent).toBe("turning the field");
    expect((panel.querySelector("progress") as HTMLProgressElement).value).toBeCloseTo(0.4);
    button(panel, "auto_phasing-abort").click();
    await settled();
    expect(requests).toEqual(["POST /api/jobs/job7/cancel"]);

    app.live.emit({
      type: "job", id: "job7", operation: "procedure:auto_phasing", state: "done", started: 0, error: null,
      result: { status: "done", procedure: "auto_phasing", saved: null, pole_pairs: 4, phase_order: 0xaaaa, sensor_offset: 10752,
        before: { pole_pairs: 1, phase_order: 0x5555, sensor_offset: 0 }, verification: { torque_per_ampere_ratio: 0.995, passed: true } },
    });
    await settled();
    await settled();
    expect(testid(panel, "result-pole-pairs")!.textContent).toBe("Pole pairs1→4");
    expect(testid(panel, "result-phase-order")!.textContent).toContain("0xAAAA (120°, U-W-V)");
    expect(testid(panel, "result-sensor-offset")!.textContent).toBe("Sensor offset0 (0.0° el.)→10752 (236.3° el.)");
    expect(testid(panel, "phasing-verification")!.dataset.passed).toBe("true");
    expect(testid(panel, "phasing-verification")!.textContent).toContain("99.5 %");
    expect(button(panel, "auto_phasing-abort").disabled).toBe(true);
    expect(client.list).toHaveBeenCalledTimes(2); // the preconditions are read again after the run
  });

  it("says how an aborted or failed job ended, and shows a refusal to start", async () => {
    const client = new FakeClient();
    const { app, model } = await setup(client);
    const panel = runnerPanel({ model, name: "auto_phasing", title: "Auto-phasing", intro: "", result: phasingResult });
    document.body.append(panel);
    tickAll(panel, "auto_phasing");
    button(panel, "auto_phasing-start").click();
    await settled();
    app.live.emit({ type: "job", id: "job7", operation: "procedure:auto_phasing", state: "cancelled", started: 0, result: { status: "aborted" } });
    await settled();
    expect(testid(panel, "procedure-aborted")!.textContent).toContain("the drive is left disabled and the gains as they were before");
    button(panel, "auto_phasing-start").click();
    await settled();
    app.live.emit({ type: "job", id: "job7", operation: "procedure:auto_phasing", state: "failed", started: 0, error: "Procedure error (64): a limit switch is active" });
    await settled();
    expect(testid(panel, "procedure-failed")!.textContent).toBe("Procedure error (64): a limit switch is active");
    client.refusal = new Error("the axis is not armed by this client");
    button(panel, "auto_phasing-start").click();
    await settled();
    await settled();
    expect(testid(panel, "auto_phasing-refused")!.textContent).toBe("the axis is not armed by this client");
  });
});

const tuned: ProcedureResult = {
  status: "done", procedure: "auto_tuning", saved: "procedures/auto_tuning-20261202T013000.250000Z.json",
  identified: { inertia_kgm2: 3.6e-4, viscous_friction_nms_per_rad: 2.1e-4, coulomb_friction_nm: 0.05, load_torque_nm: 0, inertia_ratio: 3 },
  gains: { before: { kp_speed: 100, ki_speed: 10 }, after: { kp_speed: 240, ki_speed: 10 } },
  verification: {
    speed_step: { rise_time_s: 0.0042, overshoot_pct: 3.1, settling_time_s: 0.012, bandwidth_hz: 74.2,
      capture: { time_s: [0, 0.001, 0.002], reference: [0, 100, 100], response: [0, 60, 99], unit: "rpm" } },
    position_step: null,
  },
};

describe("auto-tuning result", () => {
  it("shows the identified plant, the gains before → after with their meaning, and undoes them", async () => {
    const client = new FakeClient();
    const { model } = await setup(client);
    const element = h("div", null, tuningResult(model, tuned));
    document.body.append(element);
    expect(testid(element, "identified-inertia")!.textContent).toBe("3.6e-4 kg·m²");
    expect(testid(element, "identified-ratio")!.textContent).toBe("3 ×");
    expect(testid(element, "identified-viscous")!.textContent).toBe("2.1e-4 N·m·s/rad");
    const perAmpere = { ...tuned, identified: { inertia_kgm2: null, viscous_friction_nms_per_rad: null, coulomb_friction_nm: null,
      load_torque_nm: null, inertia_ratio: null, per_ampere: { inertia_as2_per_rad: 1.2e-3, viscous_friction_as_per_rad: 4e-4,
        coulomb_friction_a: 0.1, load_torque_a: 0 } } };
    const cd1k = h("div", null, tuningResult(model, perAmpere));
    expect(testid(cd1k, "identified-inertia")!.textContent).toBe("0.0012 A·s²/rad"); // never labelled kg·m²
    expect(testid(cd1k, "identified-ratio")).toBeNull();
    const kp = testid(element, "tuning-gains-kp_speed")!;
    expect(kp.className).toBe("differs");
    expect(kp.textContent).toContain("KPv100240speed loop proportional gain");
    expect(testid(element, "tuning-gains-ki_speed")!.className).toBe("");
    expect(testid(element, "verify-speed-rise")!.textContent).toBe("4.2 ms");
    expect(testid(element, "verify-speed-overshoot")!.textContent).toBe("3.1 %");
    expect(testid(element, "verify-speed-bandwidth")!.textContent).toBe("74.2 Hz");
    expect(testid(element, "verify-position")).toBeNull();
    expect(testid(element, "result-status")!.textContent).toContain("procedures/auto_tuning-20261202T013000.250000Z.json");
    button(element, "tuning-undo").click();
    await settled();
    expect(client.undone).toEqual([{ kp_speed: 100, ki_speed: 10 }]);
    expect(testid(element, "undo-done")!.textContent).toContain("kp_speed 100");
  });

  it("lists the results kept in the project and opens one into its procedure's result", async () => {
    const client = new FakeClient();
    client.kept = [tuned, { status: "done", procedure: "auto_phasing", pole_pairs: 3, sensor_offset: 5 }];
    const { model, scope } = await setup(client);
    const list = scope.run(() => savedPanel(model, ["auto_tuning"], "kept"));
    await settled();
    const rows = list.querySelectorAll('[data-testid="saved-row"]');
    expect(rows.length).toBe(1);
    expect(rows[0].textContent).toContain("2026-12-02 01:30:00");
    expect(rows[0].textContent).toContain("J 3.6e-4 kg·m², B 2.1e-4 N·m·s/rad, 74.2 Hz");
    rows[0].querySelector("button")!.click();
    expect(model.runs.get("auto_tuning")!.result.rawVal).toBe(tuned);
  });
});
