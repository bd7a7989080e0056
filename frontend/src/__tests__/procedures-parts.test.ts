import fc from "fast-check";
import { afterEach, describe, expect, it, vi } from "vitest";
import { App } from "../app";
import type { FaultReport } from "../client/drives";
import type { JobInfo } from "../client/jobs";
import { learnBuses } from "../client/drives";
import { procedureProgress, savedTime, type ProcedureResult, type ProceduresClient, type StartRequest, type StepMeasure } from "../client/procedures";
import { phasingNotice } from "../components/dashboard/phasing-notice";
import { calcFields, currentValues, i2tPanel, limitsFields } from "../components/procedures/current";
import { createModel } from "../components/procedures/model";
import { stepFigure, stepFigures } from "../components/procedures/step-plot";
import { Scope, state } from "../lib/dom";
import type { Dictionary } from "../lib/od";
import { changeRows, currentLimits, i2tTimes, limitProblems, needsMotorPhasing, offsetText, phaseOrderText, startBlock } from "../lib/procedures";
import { variable } from "./fixtures";

const settled = () => new Promise((resolve) => setTimeout(resolve, 0));
const testid = (root: ParentNode, id: string) => root.querySelector<HTMLElement>(`[data-testid="${id}"]`);

afterEach(() => {
  vi.unstubAllGlobals();
  document.body.textContent = "";
});

describe("procedure logic", () => {
  const ready = { name: "auto_tuning", label: "Auto-tuning", moves: true, status: "never" as const, ready: true, preconditions: [] };

  it("gives the first reason Start is blocked, in the order: running, unknown, drive, checklist, arming", () => {
    expect(startBlock(ready, true, [], true)).toBe("The procedure is running.");
    expect(startBlock(undefined, true, [], false)).toBe("The drive does not offer this procedure.");
    const unmet = { ...ready, ready: false, preconditions: [
      { name: "brake", label: "Brake", ok: false, reason: "the brake is engaged" }, { name: "dc", label: "DC bus", ok: false, reason: null }] };
    expect(startBlock(unmet, false, ["x"], false)).toBe("Brake: the brake is engaged; DC bus: not met");
    expect(startBlock(ready, false, ["a", "b"], false)).toBe("Tick the safety checklist first (2 left: a).");
    expect(startBlock(ready, false, [], false)).toBe("Arm the axis first: this procedure turns the motor.");
    expect(startBlock({ ...ready, moves: false }, false, [], false)).toBeNull();
    expect(startBlock(ready, true, [], false)).toBeNull();
  });

  it("lists every value of either side once, in the order of the after values", () => {
    fc.assert(fc.property(fc.dictionary(fc.string(), fc.integer()), fc.dictionary(fc.string(), fc.integer()), (before, after) => {
      const rows = changeRows(before, after);
      const names = rows.map((row) => row.name);
      expect(new Set(names).size).toBe(names.length);
      expect(new Set(names)).toEqual(new Set([...Object.keys(before), ...Object.keys(after)]));
      for (const row of rows) expect(row.changed).toBe(row.before !== row.after);
      for (const row of rows) expect(row.after).toBe(Object.hasOwn(after, row.name) ? after[row.name] : undefined);
    }));
  });

  it("names the phase order and turns the offset into electrical degrees", () => {
    expect(phaseOrderText(0x5555)).toBe("0x5555 (240°, U-V-W)");
    expect(phaseOrderText(0xaaaa)).toBe("0xAAAA (120°, U-W-V)");
    expect(phaseOrderText(1)).toBe("1");
    expect(offsetText(16384, 4)).toBe("16384 (0.0° el.)"); // a quarter turn is 4 × 90° = one electrical turn
    expect(offsetText(8192, 3)).toBe("8192 (135.0° el.)");
    expect(offsetText(undefined)).toBe("—");
  });

  it("computes the manual's I²t times and the current-limit rule", () => {
    const times = i2tTimes(300)!; // I_max = 3 × I_rated
    expect(times.r).toBeCloseTo(1 / 3);
    expect(times.lockedWarning).toBeCloseTo(3.3 / 9);
    expect(times.runningLimit).toBeCloseTo(12 / 9);
    expect(i2tTimes(0)).toBeNull();
    expect(currentLimits(3, 9, 10, 5)).toEqual({ rated: 3, maxPercent: 300 });
    expect(currentLimits(6, 9, 8, 5)).toEqual({ rated: 5, maxPercent: 160 });
    expect(currentLimits(0, 9, 8, 0)).toBeNull();
    expect(limitProblems(3, 300, 10)).toEqual([]);
    expect(limitProblems(6, 200, 10)).toEqual(["max current is 120 % of the drive rating (20–100 %)", "rated current is 60 % of the drive rating (20–50 %)"]);
  });

  it("sees the motor-phasing warning by its name", () => {
    expect(needsMotorPhasing([{ code: 31, name: "Motor phasing init not OK" }])).toBe(true);
    expect(needsMotorPhasing([{ code: 19, name: "I²t" }])).toBe(false);
  });
});

describe("procedure events and saved names", () => {
  it("reads a procedure's progress event and ignores any other event, whatever it holds", () => {
    expect(procedureProgress({ type: "progress", job: "j", procedure: "auto_tuning", phase: "running", status: "running", elapsed_s: 2, fraction: 0.5, message: "pulses" }))
      .toEqual({ job: "j", procedure: "auto_tuning", phase: "running", status: "running", elapsed_s: 2, fraction: 0.5, message: "pulses" });
    expect(procedureProgress({ type: "progress", job: "j", operation: "upload", done: 1 })).toBeNull();
    fc.assert(fc.property(fc.dictionary(fc.string(), fc.jsonValue()), (fields) => {
      const event: Record<string, unknown> & { type: string } = { ...fields, type: "progress" };
      const progress = procedureProgress(event);
      const valid = typeof event.job === "string" && typeof event.procedure === "string" && typeof event.phase === "string";
      expect(progress === null).toBe(!valid);
      if (progress) expect(typeof progress.elapsed_s).toBe("number");
    }));
  });

  it("finds the time in a saved result's file name", () => {
    expect(savedTime({ status: "done", file: "auto_tuning-20261202T013000.250000Z.json" })).toBe("2026-12-02 01:30:00");
    expect(savedTime({ status: "done", saved: "X/procedures/motor_phasing-20261202T013000Z.json" })).toBe("2026-12-02 01:30:00");
    expect(savedTime({ status: "done", saved: null })).toBe("");
  });
});

describe("verification step figure", () => {
  const step: StepMeasure = { rise_time_s: 0.004, overshoot_pct: null, settling_time_s: 0.01, bandwidth_hz: null,
    capture: { time_s: [0, 0.005, 0.01], reference: [0, 1, 1], response: [0, 0.8, 1], unit: "rpm" } };

  it("draws reference and response in the capture's unit and marks the settling time", () => {
    const figure = stepFigure(step, "speed step");
    expect(figure.data.map((trace) => [trace.name, trace.y])).toEqual([["reference", [0, 1, 1]], ["response", [0, 0.8, 1]]]);
    expect((figure.layout.yaxis as { title: { text: string } }).title.text).toBe("rpm");
    expect((figure.layout.shapes as { x0: number }[])[0].x0).toBe(0.01);
    expect(stepFigures(step).map(([, , value]) => value)).toEqual(["4 ms", "—", "10 ms", "—"]);
  });

  it("says how many of the repeated speed steps the bandwidth comes from", () => {
    const repeated = { ...step, bandwidth_hz: 74.2, bandwidth_steps_hz: [73.0, null] };
    expect(stepFigures(repeated)[3]).toEqual(["bandwidth", "−3 dB bandwidth (1 of 2 steps)", "74.2 Hz"]);
  });
});

const dictionary = {
  device: "xtrapulspac", product_name: "XtrapulsPac",
  objects: [
    { index: 0x340f, subs: [variable({ subindex: 0, unit: "mH", scale: 0.1 })] },
    { index: 0x6510, subs: [variable({ subindex: 1, unit: "A" }), variable({ subindex: 2, unit: "A" })] },
    { index: 0x6410, subs: [variable({ subindex: 9, unit: "A" }), variable({ subindex: 10, unit: "A" })] },
    { index: 0x6073, subs: [variable({ subindex: 0, unit: "% rated current" })] },
    { index: 0x6075, subs: [variable({ subindex: 0, unit: "A" })] },
    { index: 0x3404, subs: [variable({ subindex: 1, enum: { "0": "Limiting", "1": "Fusing" } })] },
  ],
} as unknown as Dictionary;

/** The drive's values as `POST …/read` answers them, and the writes it got. */
function fakeDrive(values: Record<string, number>, writes: string[] = []) {
  vi.stubGlobal("fetch", vi.fn(async (url: string, init: RequestInit) => {
    if (url.endsWith("/read")) {
      const objects = (JSON.parse(String(init.body)) as { objects: string[] }).objects;
      return Response.json(objects.map((object) => ({ object, value: object in values ? { physical: values[object], raw: values[object] } : null, error: null })));
    }
    writes.push(`${init.method} ${url} ${String(init.body)}`);
    return Response.json({ raw: 1, text: "Fusing", physical: 1 });
  }));
}

describe("current loop parts", () => {
  learnBuses([], []); // the app learns the bus mapping at start; drive calls wait for it
  const where = { bus: "sim", node: 1, project: "demo", axis: "X" };
  const model = () => createModel(new Scope(), new App(document.createElement("div")).live, where);

  it("prefills the drive's inductance, refuses a bad one and sends a typed one in mH", async () => {
    fakeDrive({ "0x340F,0": 6.5, "0x6510,1": 10, "0x6510,2": 5 });
    const current = currentValues(model(), dictionary);
    const fields = calcFields(current);
    await current.reload();
    const input = testid(fields.element, "cl-inductance") as HTMLInputElement;
    expect(input.value).toBe("6.5");
    expect(testid(fields.element, "cl-drive-current")!.textContent).toBe("10 A / 5 A");
    expect(fields.options()).toEqual({ inductance_mh: 6.5, regulator: "high" });
    input.value = "2,5";
    input.dispatchEvent(new Event("input"));
    expect(() => fields.options()).toThrow(/Inductance/);
    input.value = "-1";
    input.dispatchEvent(new Event("input"));
    expect(() => fields.options()).toThrow("Inductance: -1 mH is not a positive inductance");
    input.value = "12.25";
    input.dispatchEvent(new Event("input"));
    await current.reload(); // a reload does not overwrite what the user typed
    expect(fields.options()).toEqual({ inductance_mh: 12.25, regulator: "high" });
  });

  it("shows the limits on the drive beside the manual's rule, and the I²t times; applies Fusing", async () => {
    const writes: string[] = [];
    fakeDrive({ "0x6510,1": 10, "0x6510,2": 5, "0x6410,9": 3, "0x6410,10": 9, "0x6073,0": 300, "0x6075,0": 6, "0x3404,1": 0 }, writes);
    const procedures = model();
    const current = currentValues(procedures, dictionary);
    const limits = limitsFields(current);
    const i2t = i2tPanel(procedures, current);
    await current.reload();
    expect(testid(limits, "limits-now")!.textContent).toBe("6 A / 300 % rated current");
    expect(testid(limits, "limits-rule")!.textContent).toBe("3 A / 300 %");
    expect(testid(limits, "limits-problems")!.textContent).toContain("rated current is 60 % of the drive rating");
    expect(testid(i2t, "i2t-mode")!.textContent).toBe("Limiting (0)");
    expect(testid(i2t, "i2t-times")!.textContent).toContain("r = 0.3333 → warning after 0.3667 s locked / 1.111 s running");
    (testid(i2t, "i2t-apply") as HTMLButtonElement).click();
    await settled();
    expect(writes).toEqual(['PUT /api/buses/sim/nodes/1/objects/0x3404%2C1 {"value":1,"physical":false}']);
    expect(testid(i2t, "i2t-written")!.textContent).toBe("I²t mode is now Fusing.");
  });
});

describe("dashboard notice: motor phasing needed (warning bit 30)", () => {
  const report = (names: string[]) => ({ node: 1, state: null, statusword: 0, fault: false, error_code: 0, error_text: "", faults: [],
    warnings: names.map((name, i) => ({ code: 31 + i, cia402_code: 0, name, remedy: "" })) }) as unknown as FaultReport;

  it("appears with the warning, runs motor phasing in one click once armed, and says how it ended", async () => {
    const app = new App(document.createElement("div"));
    const faults = state<FaultReport | string | null>(null);
    const armed = state(false);
    const starts: [string, StartRequest][] = [];
    const client = {
      start: vi.fn(async (_bus: string, _node: number, name: string, request: StartRequest) => {
        starts.push([name, request]);
        return { id: "job9", operation: "procedure:motor_phasing", state: "running", started: 0 } as JobInfo<ProcedureResult>;
      }),
    } as unknown as ProceduresClient;
    const notice = phasingNotice({ live: app.live, where: { bus: "sim", node: 2, project: "demo", axis: "Y" }, faults, armed, phasingHref: "/p", client });
    expect(testid(notice, "phasing-warning")).toBeNull();
    faults.val = report(["Motor phasing init not OK"]);
    const remedy = testid(notice, "phasing-remedy") as HTMLButtonElement;
    expect(remedy.disabled).toBe(true);
    expect(remedy.title).toContain("Arm the axis first");
    armed.val = true;
    expect(remedy.disabled).toBe(false);
    remedy.click();
    await settled();
    expect(starts).toEqual([["motor_phasing", { options: {}, verify: false, project: "demo", axis: "Y" }]]);
    expect(remedy.disabled).toBe(true);
    app.live.emit({ type: "job", id: "job9", operation: "procedure:motor_phasing", state: "done", started: 0, result: { status: "done" } });
    await settled();
    expect(testid(notice, "phasing-remedy-done")!.textContent).toBe("Motor phasing done: the drive can be enabled.");
    faults.val = report([]);
    expect(testid(notice, "phasing-warning")).toBeNull();
  });
});
