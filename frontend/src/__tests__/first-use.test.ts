/** Issue 14 — nothing changes without the user knowing: bulk confirmations, live values, compare and backup lists. */

import { afterEach, beforeAll, describe, expect, it, vi } from "vitest";
import type { ProjectParameter } from "../client/api";
import { confirmChanges } from "../components/confirm/changes";
import { BulkActions } from "../components/parameters/bulk";
import { LiveValues, MAX_LIVE, isLive } from "../components/parameters/live";
import { ParameterStore, type DriveCell } from "../components/parameters/store";
import { state } from "../lib/dom";
import type { Dictionary, Entry } from "../lib/od";
import type { Location } from "../lib/router";
import { ParameterEditor } from "../pages/parameters";
import { projectChanges } from "../pages/backup";
import { shownRows, type Column } from "../pages/compare";
import { entry } from "./fixtures";

const kpv = entry(0x60f9, { subindex: 2, name: "KPv", group: "Servo Loops" }, { name: "Speed loop", kind: "RECORD" });
const kiv = entry(0x60f9, { subindex: 3, name: "KIv", group: "Servo Loops" }, { name: "Speed loop", kind: "RECORD" });
const rated = entry(0x6075, { name: "Motor rated current", unit: "A", scale: 0.001 });
const status = entry(0x6041, { name: "Statusword", access: "ro", save_type: "NONE" });
const phasing = entry(0x3413, { name: "Auto-phasing", access: "rw", save_type: "NONE", enum: { "2": "Running", "5": "Done" } });
const identity = entry(0x1000, { name: "Device type", access: "const", save_type: "NONE" });

function row(item: Entry, value: number, file: string | null = "DRIVEPAR.TXT"): ProjectParameter {
  return { index: item.object.index, subindex: item.variable.subindex, value, file, editable: true, access: item.variable.access } as ProjectParameter;
}

const dialog = () => document.querySelector<HTMLElement>(".dialog");
const inDialog = (id: string) => document.querySelectorAll<HTMLElement>(`.dialog [data-testid="${id}"]`);

afterEach(() => document.querySelector(".overlay")?.remove());
beforeAll(() => {
  // jsdom has no layout: the virtual list only needs the observer to exist.
  globalThis.ResizeObserver ??= class {
    observe(): void {}
    unobserve(): void {}
    disconnect(): void {}
  } as unknown as typeof ResizeObserver;
});

describe("Write changed → drive", () => {
  it("lists what it writes (drive → project) and what the filter hides, and writes nothing when cancelled", async () => {
    const store = new ParameterStore(true, null);
    store.setProjectRows([row(kpv, 300), row(kiv, 60), row(rated, 2500)]);
    for (const [item, raw] of [[kpv, 200], [kiv, 50], [rated, 2000]] as const) store.driveCell(item.key).val = { raw };
    const write = vi.fn(async (_entry: Entry, raw: number | string) => raw);
    const shown = state<Entry[]>([kpv, kiv]);
    const bulk = new BulkActions(store, { drive: { write }, project: { write: vi.fn(), reset: vi.fn() } }, shown, [kpv, kiv, rated]);
    document.body.replaceChildren(bulk.element);
    expect(bulk.element.querySelector('[data-testid="param-hidden-note"]')!.textContent).toBe("shown rows only: the filter hides 1 set values");
    bulk.element.querySelector<HTMLElement>('[data-testid="param-write-changed"]')!.click();
    await vi.waitFor(() => expect(dialog()).not.toBeNull());
    expect([...inDialog("confirm-change")].map((line) => line.textContent)).toEqual(["0x60F9.2KPv200→300", "0x60F9.3KIv50→60"]);
    expect(inDialog("confirm-note")[0].textContent).toContain("The filter hides 1 more entries the project sets (1 of them differ");
    inDialog("confirm-cancel")[0].click();
    await new Promise((resolve) => setTimeout(resolve, 0));
    expect(write).not.toHaveBeenCalled();
    bulk.element.querySelector<HTMLElement>('[data-testid="param-write-changed"]')!.click();
    await vi.waitFor(() => expect(dialog()).not.toBeNull());
    inDialog("confirm")[0].click();
    await vi.waitFor(() => expect(write).toHaveBeenCalledTimes(2));
    expect(write.mock.calls.map(([item, raw]) => [item, raw])).toEqual([[kpv, 300], [kiv, 60]]);
  });

  it("folds a long list behind its count", async () => {
    const answer = confirmChanges({ title: "t", text: "x", confirm: "ok", folded: true, changes: [{ address: "0x6075", name: "n", old: "1", new: "2" }] });
    expect(document.querySelector('[data-testid="confirm-details"] summary')!.textContent).toBe("Show the 1 changes");
    inDialog("confirm")[0].click();
    expect(await answer).toBe(true);
  });
});

describe("live values in the editor", () => {
  it("watch the live entries in view and the selected one (at most 32), while online, and store the samples", () => {
    const store = new ParameterStore(true, null);
    const watcher = vi.fn();
    const live = new LiveValues(store, watcher);
    expect([status, phasing, identity, kpv].map(isLive)).toEqual([true, true, false, false]);
    live.show([kpv, status, identity], phasing);
    expect(watcher.mock.calls[0][0]).toEqual([phasing, status]);
    live.show([kpv, status, identity], phasing);
    expect(watcher).toHaveBeenCalledTimes(1); // same list: the watch goes on
    const onCells = watcher.mock.calls[0][1] as (cells: Map<string, DriveCell>) => void;
    onCells(new Map([[phasing.key, { raw: 2 }]]));
    expect(store.driveCell(phasing.key).val).toEqual({ raw: 2 });
    onCells(new Map([[phasing.key, { raw: 5 }]]));
    expect(store.driveCell(phasing.key).val).toEqual({ raw: 5 });
    const many = Array.from({ length: 40 }, (_, n) => entry(0x2000 + n, { access: "ro", save_type: "NONE" }));
    live.show(many, null);
    expect(watcher.mock.calls[1][0]).toHaveLength(MAX_LIVE);
    store.online.val = false;
    live.show(many, null);
    expect(watcher.mock.calls[2][0]).toEqual([]);
  });
});

describe("Drive → project", () => {
  it("lists the project values it replaces before storing them", async () => {
    const store = new ParameterStore(true, null);
    store.setProjectRows([row(kpv, 300), row(kiv, 60)]);
    store.driveCell(kpv.key).val = { raw: 200 };
    store.driveCell(kiv.key).val = { raw: 60 };
    const write = vi.fn(async () => [] as ProjectParameter[]);
    const bulk = new BulkActions(store, { drive: { write: vi.fn() }, project: { write, reset: vi.fn() } }, state<Entry[]>([kpv, kiv]));
    document.body.replaceChildren(bulk.element);
    bulk.element.querySelector<HTMLElement>('[data-testid="param-revert"]')!.click();
    await vi.waitFor(() => expect(dialog()).not.toBeNull());
    expect([...inDialog("confirm-change")].map((line) => line.textContent)).toEqual(["0x60F9.2KPv300→200"]);
    inDialog("confirm")[0].click();
    await vi.waitFor(() => expect(write).toHaveBeenCalledWith([{ entry: kpv, raw: 200 }]));
  });
});

describe("the editor's live values", () => {
  it("watches the live entries in view through its source and shows each sample", async () => {
    phasing.object.group = "Servo Loops";
    const dictionary = { groups: ["Servo Loops"], objects: [kpv.object, phasing.object] } as Dictionary;
    const watch = vi.fn();
    const editor = new ParameterEditor(dictionary, {
      drive: { online: () => true, read: async () => new Map(), write: vi.fn(), watch },
      project: null, onQuery: vi.fn(),
    }, { route: { page: "axis" }, query: { q: "3413" } } as unknown as Location);
    document.body.replaceChildren(editor.element);
    await vi.waitFor(() => expect(watch).toHaveBeenCalled());
    const [watched, onCells] = watch.mock.calls.at(-1)! as [Entry[], (cells: Map<string, DriveCell>) => void];
    expect(watched).toEqual([phasing]);
    onCells(new Map([[phasing.key, { raw: 2 }]]));
    expect(document.querySelector('[data-testid="detail-drive-value"]')!.textContent).toBe("Running (2)");
    onCells(new Map([[phasing.key, { raw: 5 }]]));
    expect(document.querySelector('[data-testid="detail-drive-value"]')!.textContent).toBe("Done (5)");
    editor.dispose();
    expect(watch.mock.calls.at(-1)![0]).toEqual([]); // the watch stops with the editor
  });
});

describe("compare", () => {
  it("counts only the entries the project holds and sets read-only entries apart", () => {
    const columns: Column[] = [
      { title: "X project", values: new Map([[kpv.key, 300], [status.key, 0]]) },
      { title: "X drive", values: new Map([[kpv.key, 200], [status.key, 0x237]]) },
    ];
    const loaded = { status: "ready" as const, value: { list: [status, kpv], columns, counted: new Set([kpv.key]) } };
    const shown = shownRows(loaded, "", false)!;
    expect(shown.rows).toEqual([kpv]);
    expect(shown.differing).toBe(1);
    expect(shown.readOnly).toEqual([status]);
  });
});

describe("backup into the project", () => {
  it("lists the project values it replaces, project → drive", () => {
    const values = { "0x60F9,2": 250, "0x60F9,3": 60, "0x6075,0": 3000 };
    expect(projectChanges([kpv, kiv, rated], values, [row(kpv, 300), row(kiv, 60), row(rated, 2500, null)])).toEqual([
      { address: "0x60F9,2", name: "KPv", old: "300", new: "250" },
      { address: "0x6075,0", name: "Motor rated current", old: "2.5 A", new: "3 A" },
    ]);
  });
});
