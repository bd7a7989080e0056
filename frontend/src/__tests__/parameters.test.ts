import { beforeEach, describe, expect, it, vi } from "vitest";
import type { ProjectParameter } from "../client/api";
import { BulkActions } from "../components/parameters/bulk";
import { detailPane, type DetailContext } from "../components/parameters/detail";
import { APPLICATION_GROUPS, filterEntries, groupRows } from "../components/parameters/rows";
import { ParameterStore, type DriveCell } from "../components/parameters/store";
import { WriteTargets } from "../components/parameters/write";
import { state } from "../lib/dom";
import type { Dictionary, Entry } from "../lib/od";
import { buildIndex } from "../lib/search";
import { entry, press, type } from "./fixtures";

const kpv = entry(0x60f9, { subindex: 2, name: "KPv", group: "Servo Loops", low: 0, high: 1000 }, { name: "Speed loop", kind: "RECORD" });
const kiv = entry(0x60f9, { subindex: 3, name: "KIv", group: "Servo Loops" }, { name: "Speed loop", kind: "RECORD" });
const rated = entry(0x6075, { name: "Motor rated current", group: "Motor", unit: "A", scale: 0.001, data_type: "INTEGER32" });
const status = entry(0x6041, { name: "Statusword", group: "Device Control", access: "ro", save_type: "NONE" });
kiv.object = kpv.object;
kpv.object.subs = [kpv.variable, kiv.variable];
const all = [status, rated, kpv, kiv];
const dictionary = { groups: ["Device Control", "Servo Loops", "Motor"], objects: [status.object, rated.object, kpv.object] } as Dictionary;

function projectRow(item: Entry, value: number | null, file: string | null = "DRIVEPAR.TXT", editable = true): ProjectParameter {
  return { index: item.object.index, subindex: item.variable.subindex, value, file, editable, not_editable_reason: editable ? null : "not saved" } as ProjectParameter;
}

describe("parameter store", () => {
  it("compares drive and project values and lists what each bulk action would take", () => {
    const store = new ParameterStore(true, null);
    store.setProjectRows([projectRow(kpv, 300), projectRow(kiv, 50, null), projectRow(rated, 2500)]);
    store.driveCell(kpv.key).val = { raw: 200 };
    store.driveCell(kiv.key).val = { raw: 60 };
    store.driveCell(rated.key).val = { raw: null, error: "timeout" };
    expect(all.filter((item) => store.differs(item))).toEqual([kpv, kiv]);
    expect(store.toDrive(all)).toEqual([kpv]); // KIv differs but the files do not set it
    expect(store.toProject(all)).toEqual([kpv, kiv]);
    expect(store.explicit(all)).toEqual([rated, kpv]);
    expect(store.unread(all)).toEqual([status]);
    expect(store.current(kpv)).toBe(200);
    expect(store.current(rated)).toBe(2500);
  });

  it("reads in batches of 40, marking a failed batch's entries with the error", async () => {
    const many = Array.from({ length: 45 }, (_, n) => entry(0x2000 + n));
    const reader = vi.fn(async (list: Entry[]) => {
      if (list.length < 40) throw new Error("bus off");
      return new Map<string, DriveCell>(list.map((item) => [item.key, { raw: item.object.index }]));
    });
    const store = new ParameterStore(true, reader);
    const progress: number[] = [];
    await store.read(many, new AbortController().signal, (done) => progress.push(done));
    expect(reader.mock.calls.map(([list]) => list.length)).toEqual([40, 5]);
    expect(progress).toEqual([40, 45]);
    expect(store.driveCell(many[0].key).val).toEqual({ raw: 0x2000 });
    expect(store.driveCell(many[44].key).val).toEqual({ raw: null, error: "bus off" });
  });
});

describe("parameter rows", () => {
  it("groups as in the manual, compound objects with a header row, and filters by group and search", () => {
    const rows = groupRows(dictionary, all);
    expect(rows.map((row) => (row.kind === "entry" ? row.entry.variable.name : row.kind === "group" ? `[${row.name}]` : `<${row.object.name}>`))).toEqual([
      "[Device Control]", "Statusword", "[Servo Loops]", "<Speed loop>", "KPv", "KIv", "[Motor]", "Motor rated current",
    ]);
    const index = buildIndex(all);
    const filter = { text: "", group: APPLICATION_GROUPS, applicationGroups: new Set(["Motor"]), only: null };
    expect(filterEntries(index, filter)).toEqual([rated]);
    expect(filterEntries(index, { ...filter, group: "Servo Loops", only: (item: Entry) => item === kiv })).toEqual([kiv]);
    expect(filterEntries(index, { ...filter, group: "", text: "kpv" })).toEqual([kpv]);
  });
});

describe("write targets", () => {
  it("go to the project unless the user picks the drive, and to the one place an entry can go", () => {
    const targets = new WriteTargets();
    expect(targets.resolve(true, true)).toEqual({ drive: false, project: true });
    expect(targets.resolve(true, false)).toEqual({ drive: true, project: false }); // not held by the project
    targets.chosen.val = "drive";
    expect(targets.resolve(true, true)).toEqual({ drive: true, project: false });
    expect(targets.resolve(false, true)).toEqual({ drive: false, project: true }); // drive offline
    targets.chosen.val = "both";
    expect(targets.resolve(true, true)).toEqual({ drive: true, project: true });
    expect(new WriteTargets().resolve(true, true)).toEqual({ drive: false, project: true }); // never remembered
  });
});

function detailContext(overrides: Partial<DetailContext> = {}) {
  const store = new ParameterStore(true, null);
  const context: DetailContext = {
    store, targets: new WriteTargets(), hasDrive: true, hasProject: true,
    selected: state<Entry | null>(null), shown: state<Entry[]>(all), entries: all,
    write: vi.fn(async () => ["drive", "project"]), leave: vi.fn(), ...overrides,
  };
  return { context, store, element: detailPane(context) };
}

const find = (root: HTMLElement, id: string) => root.querySelector<HTMLElement>(`[data-testid="${id}"]`);
/** Choose a radio button as the user does (checked, then the change event). */
function pick(radio: HTMLElement | null): void {
  (radio as HTMLInputElement).checked = true;
  radio!.dispatchEvent(new Event("change"));
}

describe("detail pane and value editor", () => {
  beforeEach(() => localStorage.clear());

  it("shows the selected entry and the values as they arrive, keeping what the user typed", () => {
    const { context, store, element } = detailContext();
    expect(element.textContent).toBe("Select an entry.");
    context.selected.val = kpv;
    expect(find(element, "detail-name")!.textContent).toBe("KPv");
    expect(element.textContent).toContain("reading…");
    const editor = find(element, "param-editor") as HTMLInputElement;
    type(editor, "42");
    store.driveCell(kpv.key).val = { raw: 200 };
    store.setProjectRows([projectRow(kpv, 300)]);
    expect(find(element, "detail-drive-value")!.textContent).toBe("200");
    expect(find(element, "detail-project-value")!.textContent).toBe("300 (DRIVEPAR.TXT)");
    expect(find(element, "param-editor")).toBe(editor);
    expect(editor.value).toBe("42");
  });

  it("refuses an out-of-range value under the editor, writes a valid one raw and then shows what was written", async () => {
    const { context, store, element } = detailContext();
    store.setProjectRows([projectRow(rated, 2500)]);
    context.selected.val = rated;
    const editor = find(element, "param-editor") as HTMLInputElement;
    expect(editor.value).toBe("2.5");
    type(editor, "2,5");
    press(editor, "Enter");
    expect(find(element, "param-error")!.textContent).toBe('"2,5": use "." as decimal separator');
    expect(context.write).not.toHaveBeenCalled();
    pick(find(element, "target-both"));
    expect(find(element, "param-write")!.textContent).toBe("Write to drive and project");
    expect(find(element, "editor-holds")!.textContent).toBe("The field holds the drive value.");
    type(editor, "3.25");
    find(element, "param-write")!.click();
    expect(context.write).toHaveBeenCalledWith(rated, 3250, { drive: true, project: true });
    store.driveCell(rated.key).val = { raw: 3250 };
    await vi.waitFor(() => expect(element.querySelector("[data-status]")!.textContent).toBe("0x6075 = 3.25 written to the drive and the project"));
    expect(find(element, "param-error")).toBeNull();
    store.driveCell(rated.key).val = { raw: 4000 };
    expect(editor.value).toBe("4"); // follows the drive again after the write
  });

  it("writes to the project by default and then holds the project value, showing what the drive still holds", async () => {
    const { context, store, element } = detailContext({ write: vi.fn(async () => ["project"]) });
    store.setProjectRows([projectRow(rated, 2500)]);
    store.driveCell(rated.key).val = { raw: 2000 };
    context.selected.val = rated;
    const editor = find(element, "param-editor") as HTMLInputElement;
    expect(editor.value).toBe("2.5"); // the project's value, not the drive's 2
    expect(find(element, "param-write")!.textContent).toBe("Write to project");
    expect(find(element, "detail-project-label")!.textContent).toBe("Project ◂ field");
    expect(find(element, "detail-drive-label")!.textContent).toBe("Drive");
    type(editor, "3");
    press(editor, "Enter");
    expect(context.write).toHaveBeenCalledWith(rated, 3000, { drive: false, project: true });
    store.setProjectRows([projectRow(rated, 3000)]);
    await vi.waitFor(() => expect(find(element, "param-status")!.textContent).toBe("0x6075 = 3 written to the project; the drive still holds 2"));
    expect(editor.value).toBe("3"); // the written value stays in the field
    expect(find(element, "detail-drive-value")!.textContent).toBe("2 A  (raw 2000)");
    expect(find(element, "detail-project-value")!.textContent).toBe("3 A (DRIVEPAR.TXT)");
    pick(find(element, "target-drive"));
    expect(editor.value).toBe("2"); // now it holds the drive's
    expect(find(element, "param-write")!.className).toContain("danger");
  });

  it("shows the server's refusal and keeps the text", async () => {
    const { element, context } = detailContext({ write: vi.fn(async () => Promise.reject(new Error("value refused by the drive"))) });
    context.selected.val = kpv;
    const editor = find(element, "param-editor") as HTMLInputElement;
    type(editor, "7");
    press(editor, "Enter");
    await vi.waitFor(() => expect(find(element, "param-error")!.textContent).toBe("value refused by the drive"));
    expect(editor.value).toBe("7");
  });

  it("offers no editor for a read-only entry, and only the project when the drive goes offline", () => {
    const { context, store, element } = detailContext();
    context.selected.val = status;
    expect(find(element, "param-editor")).toBeNull();
    expect(element.textContent).toContain("Read-only (ro).");
    store.setProjectRows([projectRow(kpv, 300)]);
    context.selected.val = kpv;
    expect((find(element, "target-project") as HTMLInputElement).checked).toBe(true);
    store.online.val = false;
    expect(find(element, "target-drive")).toBeNull();
    expect(element.textContent).toContain("Writes to the project.");
    expect(element.textContent).toContain("drive offline");
  });
});

describe("bulk actions", () => {
  it("count what they would take from the shown entries and follow the values", () => {
    const store = new ParameterStore(true, null);
    const shown = state<Entry[]>(all);
    const bulk = new BulkActions(store, { drive: { write: vi.fn() }, project: { write: vi.fn(), reset: vi.fn() } }, shown);
    const text = (id: string) => find(bulk.element, id)!.textContent;
    expect(text("param-write-changed")).toBe("Write changed → drive (0+)");
    store.setProjectRows(all.map((item) => projectRow(item, 5)));
    store.driveCell(kpv.key).val = { raw: 6 };
    for (const item of [kiv, rated, status]) store.driveCell(item.key).val = { raw: 5 };
    expect([text("param-write-changed"), text("param-revert"), text("param-reset")]).toEqual([
      "Write changed → drive (1)", "Drive → project (1)", "Reset to defaults (4)",
    ]);
    shown.val = [rated];
    expect(text("param-write-changed")).toBe("Write changed → drive (0)");
    expect((find(bulk.element, "param-write-changed") as HTMLButtonElement).disabled).toBe(true);
    store.online.val = false;
    expect((find(bulk.element, "param-refresh") as HTMLButtonElement).disabled).toBe(true);
  });

  it("replace their buttons by a progress bar with Cancel while one runs", async () => {
    const store = new ParameterStore(true, null);
    const bulk = new BulkActions(store, { drive: null, project: null }, state<Entry[]>([]));
    let finish: () => void = () => undefined;
    const running = bulk.run("Reading", 10, async (signal, progress) => {
      progress(4);
      await new Promise<void>((resolve) => (finish = resolve));
      expect(signal.aborted).toBe(true);
    });
    expect(bulk.element.textContent).toContain("Reading 4/10");
    find(bulk.element, "bulk-cancel")!.click();
    finish();
    expect(await running).toBe(false);
    expect(find(bulk.element, "bulk-cancel")).toBeNull();
  });
});
