import { afterEach, describe, expect, it, vi } from "vitest";
import { learnBuses } from "../client/drives";
import type { SavedResult, SpeedLoop } from "../client/frequency";
import { figureInputs } from "../components/bode/curves";
import { bodeFigure, stepFigure } from "../components/bode/figure";
import { markerColumns } from "../components/bode/markers";
import { createModel, loadLoop, refreshSaved, type BodeModel } from "../components/bode/model";
import { bodeFigureOf } from "../components/bode/panels";
import { savedPanel } from "../components/bode/saved";
import { whatIfPanel } from "../components/bode/whatif";
import { measurePanel, measureState } from "../components/bode/measure";
import { App } from "../app";
import { barePlant, changeOf, draftOf, filterAt, filterPosition, gainAt, positionOf, predict, paramsWith, SLIDER_STEPS, usablePoints } from "../lib/bode";
import { Scope, state } from "../lib/dom";
import { db } from "../lib/whatif/complex";

const settled = () => new Promise((resolve) => setTimeout(resolve, 0));
const testid = (root: ParentNode, id: string) => root.querySelector<HTMLElement>(`[data-testid="${id}"]`);
const T = 250e-6, J = 3.6e-4, B = 2e-4;

/** 1/(J·s + B) with the speed sampled one period late: a rigid plant as a measurement gives it. */
function plantPoints(count = 50) {
  return Array.from({ length: count }, (_, n) => {
    const f = 5 * (400 / 5) ** (n / (count - 1)), w = 2 * Math.PI * f;
    const magnitude = 1 / Math.hypot(B, w * J);
    const phase = -Math.atan2(w * J, B) - w * T;
    return { freq_hz: f, magnitude_db: 20 * Math.log10(magnitude), phase_deg: (phase * 180) / Math.PI, coherence: 0.97 };
  });
}

const LOOP = {
  device: "xtrapulspac", control_period_s: T, torque_constant_nm_per_a: 0.6, gain_multiplier: 1, kp_a_per_rad_s: 0.2303,
  ki_a_per_rad: 22.11, ki_leak_hz: 0, kc_a_per_rad_s: 0, kd_a_per_rad_s2: 0, current_filters_hz: [0, 0, 0], speed_filter_s: 0.0005,
  speed_filter_choices_s: [0.0005, 0.001, 0.002], writable: ["kp_a_per_rad_s", "ki_a_per_rad", "current_filter_1_hz", "current_filter_2_hz", "current_filter_3_hz", "speed_filter_s"],
  raw: {},
} as unknown as SpeedLoop;

const PLANT = {
  name: "plant", kind: "frequency_response", loop: "plant", node: 1, points: plantPoints(),
  markers: { bandwidth_hz: null, resonance_hz: 150, antiresonance_hz: 90 },
  plant_fit: { inertia_kgm2: J, viscous_friction_nms_per_rad: B }, gains: { current_filters_hz: [0, 0, 0] },
} as unknown as SavedResult;

const CLOSED = { ...PLANT, name: "closed", loop: "closed", markers: { bandwidth_hz: 70 }, plant_fit: null } as unknown as SavedResult;

afterEach(() => {
  vi.unstubAllGlobals();
  document.body.textContent = "";
});

describe("the what-if logic of the Bode page", () => {
  it("maps slider positions to gains on a log scale and back, the middle being the drive's value", () => {
    expect(gainAt(SLIDER_STEPS / 2, 0.23)).toBeCloseTo(0.23, 12);
    expect(gainAt(0, 0.23)).toBeCloseTo(0.023, 12);
    expect(gainAt(SLIDER_STEPS, 0.23)).toBeCloseTo(2.3, 12);
    for (const position of [0, 17, 200, 333, SLIDER_STEPS]) expect(positionOf(gainAt(position, 5), 5)).toBe(position);
    expect(filterAt(0)).toBe(0);
    expect(filterAt(1)).toBe(20);
    expect(filterAt(SLIDER_STEPS)).toBe(2000);
    expect(filterAt(filterPosition(500))).toBeCloseTo(500, -1);
  });

  it("drops points that are not finite; divides the filters out of a plant that says it includes them", () => {
    const points = [...plantPoints(5), { freq_hz: 500, magnitude_db: null, phase_deg: 0, coherence: null }];
    expect(usablePoints(points)).toHaveLength(5);
    const gains = { current_filters_hz: [300] };
    const plain = barePlant({ points: plantPoints(5), gains }, T);
    const bare = barePlant({ points: plantPoints(5), gains, plant_includes_filters: true }, T);
    expect(db(plain.value[4])).toBeCloseTo(plantPoints(5)[4].magnitude_db, 9);
    expect(db(bare.value[4])).toBeGreaterThan(db(plain.value[4]));
  });

  it("asks to write only what differs from the drive and what the drive takes", () => {
    const draft = { ...draftOf(LOOP as never), kp: 0.3, filtersHz: [400, 0, 0] };
    expect(changeOf(LOOP as never, draft)).toEqual({ kp_a_per_rad_s: 0.3, current_filter_1_hz: 400 });
    expect(changeOf({ ...(LOOP as never as object), writable: ["ki_a_per_rad"] } as never, draft)).toEqual({});
  });

  it("predicts a wider bandwidth for a higher KPv, and a step that settles at the reference", () => {
    const plant = barePlant(PLANT, T);
    const slow = predict(plant, { inertia_kgm2: J, viscous_friction_nms_per_rad: B }, paramsWith(LOOP as never, draftOf(LOOP as never)));
    const fast = predict(plant, null, paramsWith(LOOP as never, { ...draftOf(LOOP as never), kp: 0.5 }));
    expect(fast.markers.bandwidth_hz!).toBeGreaterThan(1.5 * slow.markers.bandwidth_hz!);
    expect(slow.gainCrossoverHz).not.toBeNull();
    expect(slow.markers.phase_margin_deg!).toBeGreaterThan(20);
    expect(slow.step!.speed.at(-1)!).toBeCloseTo(1, 1);
    expect(fast.step).toBeNull(); // no rigid fit, no step
  });

  it("predicts from the plant's coherent points only: an incoherent spike moves no predicted marker", () => {
    const params = paramsWith(LOOP as never, draftOf(LOOP as never));
    const clean = predict(barePlant({ points: plantPoints() }, T), null, params);
    const points = plantPoints().map((p, n) => (n % 7 === 3 ? { ...p, magnitude_db: p.magnitude_db + 15, coherence: 0.5 } : p));
    const spiked = predict(barePlant({ points }, T), null, params);
    expect(spiked.markers).toEqual(clean.markers);
    expect(spiked.gainCrossoverHz).toBe(clean.gainCrossoverHz);
    expect(spiked.closed.freq).toHaveLength(50); // the curve still shows every point
    expect(predict(barePlant({ points: points.map((p) => ({ ...p, coherence: 0.5 })) }, T), null, params).markers.bandwidth_hz).toBeNull();
  });
});

describe("the Bode figure", () => {
  const plant = barePlant(PLANT, T);
  const predicted = predict(plant, null, paramsWith(LOOP as never, draftOf(LOOP as never)));

  it("draws the closed loop: measured, predicted with the drive's and the what-if gains, the bandwidths", () => {
    const inputs = figureInputs("closed", [{ name: "plant", result: PLANT }, { name: "closed", result: CLOSED }], predicted, predicted);
    expect(inputs.curves.map((curve) => curve.label)).toEqual(["closed (measured)", "closed loop, drive's gains (predicted)", "closed loop, what-if gains (predicted)"]);
    expect(inputs.lines.map((line) => line.label)).toEqual(["bandwidth 70 Hz", expect.stringMatching(/^what-if bandwidth \d/)]);
    const figure = bodeFigure(inputs.curves, inputs.lines, inputs.magnitudeTitle);
    expect(figure.data.map((trace) => trace.yaxis)).toEqual(["y", "y2", "y3", "y", "y2", "y", "y2"]);
    expect((figure.layout.shapes as { x0: number }[])[0].x0).toBe(70);
  });

  it("marks the margins on the open loop and the resonances on the plant, coherence only where measured", () => {
    const open = figureInputs("open", [], predicted, null);
    expect(open.lines.map((line) => line.label)).toEqual([expect.stringMatching(/^phase margin \d/), expect.stringMatching(/^gain margin \d/)]);
    expect(bodeFigure(open.curves, open.lines, open.magnitudeTitle).layout.yaxis3).toBeUndefined();
    const measured = figureInputs("plant", [{ name: "plant", result: PLANT }], predicted, predicted);
    expect(measured.lines.map((line) => line.label)).toEqual(["resonance 150 Hz", "anti-resonance 90 Hz"]);
    expect(measured.curves).toHaveLength(1);
    expect(stepFigure([{ label: "a", step: { time_s: [0.001], speed: [0.5] }, color: "#000" }]).data[0].x).toEqual([1]);
  });
});

/** The server as the page sees it: the saved results and the drive's speed loop; the writes it got. */
function fakeServer(writes: string[]) {
  let loop = LOOP;
  vi.stubGlobal("fetch", vi.fn(async (url: string, init: RequestInit = {}) => {
    if (url.endsWith("/frequency-response")) {
      writes.push(String(init.body));
      const result = { ...CLOSED, saved: "closed", markers: { bandwidth_hz: 71 } };
      return Response.json({ id: "j1", operation: "frequency-response", started: 0, state: "done", result }, { status: 202 });
    }
    if (url.endsWith("/frequency")) return Response.json([{ ...PLANT, points: undefined }, { ...CLOSED, points: undefined }]);
    if (url.endsWith("/frequency/plant")) return Response.json(PLANT);
    if (url.endsWith("/frequency/closed")) return Response.json(CLOSED);
    if (url.endsWith("/speed-loop") && init.method === "PUT") {
      writes.push(String(init.body));
      const before = loop;
      loop = { ...loop, ...(JSON.parse(String(init.body)) as object) };
      return Response.json({ before, after: loop, written: [["kp_speed", 3000]] });
    }
    if (url.endsWith("/speed-loop")) return Response.json(loop);
    return new Response("{}", { status: 404 });
  }));
}

async function loadedModel(): Promise<BodeModel> {
  const model = createModel(new Scope(), { bus: "sim", node: 1, project: "demo", axis: "X" });
  await refreshSaved(model);
  await loadLoop(model);
  return model;
}

describe("the Bode page's panels", () => {
  learnBuses([], []);

  it("moving the KPv slider changes the prediction at once and writes nothing until asked", async () => {
    const writes: string[] = [];
    fakeServer(writes);
    const model = await loadedModel();
    const panel = whatIfPanel(model, { mayWrite: () => true, written: () => undefined });
    document.body.append(panel);
    expect(model.plantName.rawVal).toBe("plant");
    const before = testid(panel, "whatif-bandwidth")!.textContent;
    expect(testid(panel, "whatif-bandwidth-drive")!.textContent).toBe(before);
    expect((testid(panel, "whatif-write") as HTMLButtonElement).disabled).toBe(true);
    const slider = testid(panel, "whatif-kp") as HTMLInputElement;
    slider.value = String(Number(slider.value) + 80);
    slider.dispatchEvent(new Event("input"));
    expect(testid(panel, "whatif-bandwidth")!.textContent).not.toBe(before);
    expect(testid(panel, "whatif-bandwidth-drive")!.textContent).toBe(before);
    expect(Number.parseFloat(testid(panel, "whatif-ms")!.textContent!)).toBeGreaterThanOrEqual(0); // measured: bench/whatif_update.py
    expect(slider.isConnected).toBe(true); // the panel was not rebuilt under the user's drag
    expect(writes).toEqual([]);
    testid(panel, "whatif-write")!.click();
    testid(document.body, "confirm")!.click();
    await settled();
    await settled();
    expect(JSON.parse(writes[0]) as object).toEqual({ kp_a_per_rad_s: expect.closeTo(0.2303 * 10 ** 0.4, 6) });
    expect(model.message.rawVal?.testid).toBe("bode-written");
  });

  it("lists the saved sets, overlays one and compares their markers; deleting needs the Expert level", async () => {
    fakeServer([]);
    const model = await loadedModel();
    const panel = savedPanel(model, () => false);
    document.body.append(panel);
    const rows = panel.querySelectorAll<HTMLElement>('[data-testid="bode-saved-row"]');
    expect([...rows].map((row) => row.dataset.name)).toEqual(["plant", "closed"]);
    expect((testid(rows[0], "saved-delete") as HTMLButtonElement).disabled).toBe(true);
    expect(testid(rows[0], "saved-csv")!.getAttribute("href")).toBe("/api/projects/demo/axes/X/frequency/plant/csv");
    const show = testid(rows[1], "saved-show") as HTMLInputElement;
    show.checked = true;
    show.dispatchEvent(new Event("change"));
    await settled();
    expect(model.shown.rawVal).toEqual(["plant", "closed"]);
    expect(testid(panel, "overlay-html")!.getAttribute("href")).toBe("/api/projects/demo/axes/X/frequency/plant/html?compare=closed");
    expect(markerColumns(model).map((column) => column.title)).toEqual(["plant", "closed", "predicted, drive's gains", "predicted, what-if"]);
    expect(bodeFigureOf(model)!.data[0].name).toBe("closed (measured)");
  });

  it("measures only when this page holds the axis, with the panel's settings, and shows the saved result", async () => {
    const writes: string[] = [];
    fakeServer(writes);
    const model = await loadedModel();
    const run = measureState();
    const armed = state(false); // the axis's holder is a state in the page (procedures model)
    const panel = measurePanel(model, new App(document.createElement("div")).live, run, () => armed.val);
    document.body.append(panel);
    const start = testid(panel, "measure-start") as HTMLButtonElement;
    expect(start.disabled).toBe(true);
    expect(start.title).toMatch(/^Arm the axis first/);
    armed.val = true;
    const loop = panel.querySelector<HTMLSelectElement>('[data-testid="measure-loop"]')!;
    loop.value = "closed";
    loop.dispatchEvent(new Event("change"));
    const window = testid(panel, "measure-position_window") as HTMLInputElement;
    window.value = "3";
    window.dispatchEvent(new Event("input"));
    expect(start.disabled).toBe(false);
    start.click();
    await settled();
    await settled();
    expect(JSON.parse(writes[0]) as object).toMatchObject({ loop: "closed", position_window: 3, base_speed_rad_s: 10, project: "demo", axis: "X" });
    expect(model.shown.rawVal).toContain("closed");
  });
});
